"""The lean figure machinery of microg.plotting.common (issue 8, "Speed of the main job").

References: a brute-force slice-by-slice min/max for the drawing envelope; matplotlib's own
LogFormatterSciNotation labels for the Unicode log labels; matplotlib's own Axis objects (the
same figure drawn both ways) for the lean axes; matplotlib's PNG writer and PIL's decoder for
the PNG encoder; matplotlib's measured text extents for the fixed margins.
"""

from __future__ import annotations

import io

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from matplotlib.figure import Figure
from matplotlib.ticker import LogFormatterSciNotation
from PIL import Image

from microg.plotting.common import (
    PlainLogFormatter,
    encode_png,
    envelope,
    finish,
    new_figure,
    plain_axes,
    png_bytes,
)


def _brute_envelope_values(y: np.ndarray, bins: int) -> list[tuple[float, float]]:
    """Min and max of each slice, as envelope() slices the record (a Python loop)."""
    n = y.size
    k = -(-n // bins)
    return [(float(y[i : i + k].min()), float(y[i : i + k].max())) for i in range(0, n, k)]


def test_envelope_keeps_every_slice_extreme_and_the_ends():
    rng = np.random.default_rng(7)
    n, bins = 20_001, 100
    t = np.linspace(0.0, 200.0, n)
    y = np.cumsum(rng.standard_normal(n))
    y[12_345] = 80.0  # a spike: one sample
    xe, ye = envelope(t, y, bins=bins)
    assert xe.size <= 2 * bins + 4
    assert np.all(np.diff(xe) > 0)  # time order, no duplicates
    # every kept point is a sample of the record, at its own time
    idx = np.searchsorted(t, xe)
    assert np.array_equal(t[idx], xe) and np.array_equal(y[idx], ye)
    assert xe[0] == t[0] and xe[-1] == t[-1]
    assert ye.max() == 80.0 and ye.min() == y.min()  # the peak is drawn exactly
    # reference: each slice's min and max, by brute force, are among the kept values
    k = -(-n // bins)
    for s, (lo, hi) in enumerate(_brute_envelope_values(y, bins)):
        inside = ye[(idx >= s * k) & (idx < (s + 1) * k)]
        assert inside.min() == lo and inside.max() == hi  # exact: the same samples


def test_envelope_leaves_short_lines_alone():
    t = np.arange(100.0)
    y = np.sin(t)
    xe, ye = envelope(t, y, bins=2000)
    assert xe is t and ye is y


@given(arrays(np.float64, st.integers(3, 3000), elements=st.floats(-1e6, 1e6)))
def test_envelope_property_extremes_kept(y):
    # invariant: the drawn range equals the record's range, and only samples are drawn
    t = np.arange(y.size, dtype=float)
    xe, ye = envelope(t, y, bins=7)
    assert ye.max() == y.max() and ye.min() == y.min()
    assert np.array_equal(y[xe.astype(int)], ye)


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (1e-5, "10\u207b\u2075"),
        (1.0, "10\u2070"),
        (1e3, "10\u00b3"),
        (1e-12, "10\u207b\u00b9\u00b2"),
    ],
)
def test_log_labels_are_matplotlibs_in_unicode(value, expected):
    # reference: matplotlib's mathtext label for the same tick, $\mathdefault{10^{k}}$
    fig = Figure()
    ax = fig.add_subplot()
    ax.loglog([1e-13, 1e4], [1.0, 2.0])
    ours, theirs = PlainLogFormatter(), LogFormatterSciNotation()
    for f in (ours, theirs):
        f.set_axis(ax.xaxis)
        f.set_locs([value])
    exponent = round(np.log10(value))
    assert theirs(value) == rf"$\mathdefault{{10^{{{exponent}}}}}$"
    assert ours(value) == expected


def test_log_labels_non_decade():
    # reference: matplotlib's mathtext labels on a narrow log axis (labelled between decades)
    fig = Figure()
    ax = fig.add_subplot()
    ax.loglog([1.0, 5.0], [1.0, 2.0])
    values = [2.0, 3.0, 30.0, 0.02]
    ours, theirs = (
        PlainLogFormatter(labelOnlyBase=False),
        LogFormatterSciNotation(labelOnlyBase=False),
    )
    for f in (ours, theirs):
        f.set_axis(ax.xaxis)
        f.set_locs(values)
    assert [theirs(v) for v in values] == [
        r"$\mathdefault{2\times10^{0}}$",
        r"$\mathdefault{3\times10^{0}}$",
        r"$\mathdefault{3\times10^{1}}$",
        r"$\mathdefault{2\times10^{-2}}$",
    ]
    assert [ours(v) for v in values] == [
        "2\u00d710\u2070",
        "3\u00d710\u2070",
        "3\u00d710\u00b9",
        "2\u00d710\u207b\u00b2",
    ]


def _pixels(fig: Figure) -> np.ndarray:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    return np.asarray(Image.open(io.BytesIO(buf.getvalue())).convert("RGB"), int)


def _loglog_figure() -> Figure:
    fig = new_figure(6.0, 4.0)
    ax = fig.add_subplot()
    f = np.logspace(-2, 2.5, 200)
    ax.loglog(f, 1e-3 / (1 + f**2), lw=0.8, label="x")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("PSD [g^2/Hz]")
    ax.set_title("a log-log figure")
    ax.legend()
    return fig


def _linear_figure() -> Figure:
    fig = new_figure(6.0, 4.0)
    ax = fig.add_subplot()
    t = np.linspace(0.0, 200.0, 500)
    ax.plot(t, 60.0 * np.sin(t / 7.0), lw=0.8, label="x")
    ax.plot(t, -40.0 * np.cos(t / 3.0), lw=0.8, label="y")
    ax.grid(True, alpha=0.3)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("acceleration [micro-g]")
    ax.set_title("a linear figure")
    ax.legend(fontsize=8)
    return fig


def _narrow_log_and_offset_figure() -> Figure:
    # minor log labels (less than 1.5 decades) above, an offset text ("1e5") below
    fig = new_figure(6.0, 6.0)
    ax1, ax2 = fig.subplots(2, 1)
    ax1.loglog([1.0, 5.0], [2.0, 30.0], "o-")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.set_xlabel("f [Hz]")
    ax1.set_ylabel("rms")
    t = np.linspace(0.0, 1.0, 50)
    ax2.plot(t, 1e5 + t, label="drift")
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("counts")
    ax2.set_title("an offset text")
    return fig


def _rotated_labels_figure() -> Figure:
    # bars with fixed, slanted tick labels (as the source-contribution figure draws them)
    fig = new_figure(6.0, 4.0, margins={"bottom": 1.0})
    ax = fig.add_subplot()
    x = np.arange(12)
    ax.bar(x, np.linspace(0.1, 1.0, 12), label="pump")
    ax.set_xticks(x[::3], [f"{c:.3g}" for c in np.logspace(-1, 1, 12)[::3]], rotation=60)
    ax.set_xlabel("band centre [Hz]")
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def _matplotlibs(build):  # the same figure, finished, drawn by matplotlib's own Axis objects
    return plain_axes(finish(build()))


@pytest.mark.parametrize(
    "build",
    [_loglog_figure, _linear_figure, _narrow_log_and_offset_figure, _rotated_labels_figure],
)
def test_lean_axes_draw_as_matplotlibs(build):
    # reference: the same figure drawn by matplotlib's own Axis (Tick objects), same margins
    lean, plain = finish(build()), _matplotlibs(build)
    assert not lean.axes[0].xaxis.get_visible()  # ours: the Axis is hidden, no Tick drawn
    assert plain.axes[0].xaxis.get_visible()
    ours, theirs = _pixels(lean), _pixels(plain)
    assert ours.shape == theirs.shape
    diff = np.abs(ours - theirs).max(axis=2)
    # anti-aliasing of grid lines drawn by one collection rather than one Line2D per tick
    # may differ by a grey level or two; no pixel may differ visibly, and text (tick labels,
    # axis labels, offset text, title) lands on the same pixels
    assert diff.max() <= 8, diff.max()
    assert np.count_nonzero(diff) <= 1e-3 * diff.size


def test_lean_axes_follow_later_changes():
    # reference: matplotlib's own Axis after the same changes made after finish()
    def changed(fig: Figure) -> Figure:
        ax = fig.axes[0]
        ax.set_xlim(0.1, 10.0)
        ax.set_xticks([0.2, 1.0, 5.0])
        ax.set_xlabel("new label")
        return fig

    ours = _pixels(changed(finish(_loglog_figure())))
    theirs = _pixels(changed(_matplotlibs(_loglog_figure)))
    diff = np.abs(ours - theirs).max(axis=2)
    assert diff.max() <= 8 and np.count_nonzero(diff) <= 1e-3 * diff.size


def test_png_bytes_are_matplotlibs_pixels():
    # reference: matplotlib's own PNG writer (savefig), decoded by PIL, pixel for pixel
    fig = finish(_linear_figure())
    png = png_bytes(fig, dpi=80)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    ours = np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), int)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    theirs = np.asarray(Image.open(io.BytesIO(buf.getvalue())).convert("RGBA"), int)
    assert np.array_equal(ours, theirs)
    assert fig.dpi == 100 and type(fig.canvas).__name__ == "FigureCanvasBase"  # left as found


@given(
    arrays(np.uint8, st.tuples(st.integers(1, 9), st.integers(1, 9), st.just(4))),
    st.booleans(),
    st.integers(0, 9),
)
def test_encode_png_round_trips(rgba, opaque, level):
    # reference: PIL's PNG decoder; every pixel comes back (RGBA, or RGB when opaque)
    if opaque:
        rgba = rgba.copy()
        rgba[:, :, 3] = 255
    back = np.asarray(Image.open(io.BytesIO(encode_png(rgba, level))).convert("RGBA"))
    assert np.array_equal(back, rgba)
    assert Image.open(io.BytesIO(encode_png(rgba))).mode == ("RGB" if opaque else "RGBA")


def test_report_figures_keep_every_label_inside():
    # reference: matplotlib's own text extents, measured after drawing
    import microg
    from microg.report.analysis import figure_jobs

    result = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02, isolation=False)
    jobs = figure_jobs(result)
    assert [j.name for j in jobs] == [
        "model.png",
        "modes.png",
        "forces.png",
        "lab-bands.png",
        "lab-psd.png",
        "lab-integrated.png",
    ]
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from microg.plotting.analysis import (
        force_figure,
        model_figure,
        modes_figure,
        observation_figure,
    )
    from microg.plotting.environment import plot_integrated_acceleration, plot_psd

    ob = result.observations["lab"]
    r = ob.response
    forces = {d.point: d.unit_direction for d in result.options.disturbances}
    figs = [
        model_figure(result.structure, result.modes, forces, ["lab"]),
        modes_figure(result),
        force_figure(list(result.options.disturbances), result.options.duration_s),
        observation_figure(ob),
        plot_psd(ob.assessment.spectrum),
        plot_integrated_acceleration(r.timepts, r.acceleration),
    ]
    for fig in figs:
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        renderer = canvas.get_renderer()
        box = fig.bbox
        for ax in fig.axes:
            # the drawn tick labels, axis labels, title and legend of each axes
            e = ax.get_tightbbox(renderer)
            assert e.x0 >= box.x0 - 1 and e.x1 <= box.x1 + 1, (ax.get_title(), e, box)
            assert e.y0 >= box.y0 - 1 and e.y1 <= box.y1 + 1, (ax.get_title(), e, box)
        # and the axes of a two-row figure do not overlap each other's labels
        if len(fig.axes) == 2:
            top, bottom = (a.get_tightbbox(renderer) for a in fig.axes)
            assert bottom.y1 <= top.y0 + 1


def test_the_model_figure_draws_every_sample_of_every_component_once():
    # reference: the structure's own sample positions; each component (beam, body) is one
    # run of the line between NaN breaks, so no segment joins two components
    import microg
    from microg.plotting.analysis import _groups, _views, model_figure, sample_displacements

    result = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02, isolation=False)
    pos, _ = sample_displacements(result.structure, result.modes.phi[:, :1])
    groups = [g for g in _groups(result.structure, pos.shape[0]) if g.size]
    assert len(groups) > 1  # the IOC model has several components
    fig = model_figure(result.structure, result.modes, {}, [])
    for ax, (h, v) in zip(fig.axes[:2], _views(pos), strict=True):
        line = ax.get_lines()[0]  # the model, drawn first
        xy = np.column_stack([line.get_xdata(), line.get_ydata()])
        runs = np.split(xy, np.flatnonzero(np.isnan(xy[:, 0])))
        runs = [r[~np.isnan(r[:, 0])] for r in runs]
        assert len(runs) == len(groups)
        for run, g in zip(runs, groups, strict=True):
            # the same points (sorted along the component), exactly: they are copied
            got = np.unique(run, axis=0)
            want = np.unique(pos[g][:, [h, v]], axis=0)
            assert np.array_equal(got, want)
