"""What every figure shares (microg.plotting.common), and figures drawn where the caller says.

References: a brute-force slice-by-slice min/max for the drawing envelope; matplotlib's own
objects (the caller's axes, their visible axis, their tick labels' size after
``tick_params``, ``Figure.savefig``'s PNG file) for the drawing into a caller's axes;
matplotlib's measured text extents for the layout of the report's figures.
"""

from __future__ import annotations

import inspect
import io

import matplotlib.pyplot as plt
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from matplotlib.figure import Figure
from PIL import Image

from microg.errors import InputError
from microg.plotting.common import envelope, figure_axes, figure_grid, png_bytes


@pytest.fixture(scope="module")
def result():
    import microg

    return microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02)


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


def test_an_observation_draws_into_the_callers_axes(result):
    # reference: the caller's own pyplot figure and axes, and matplotlib's own Axis objects
    ob = result.observations["lab"]
    fig, ax = plt.subplots()
    try:
        out = ob.plot(ax=ax)
        assert out is fig  # the caller's figure, not a new one
        assert len(fig.axes) == 1 and ax.get_lines()  # drawn into that axes, nothing added
        assert ax.get_title().startswith("Acceleration at lab")
        assert ax.xaxis.get_visible() and ax.yaxis.get_visible()  # matplotlib's axes, shown
        ax.tick_params(labelsize=5)
        fig.canvas.draw()
        sizes = {t.get_fontsize() for t in ax.get_xticklabels() + ax.get_yticklabels()}
        assert sizes == {5.0}  # tick_params takes effect on the labels drawn
        ob.plot(ax=ax, kind="bands")  # a second panel's kind into another caller axes
        assert ax.get_xscale() == "log"
    finally:
        plt.close(fig)


def test_a_two_panel_figure_draws_into_two_caller_axes(result):
    ob = result.observations["lab"]
    fig, (top, bottom) = plt.subplots(2, 1)
    try:
        assert ob.plot(ax=[top, bottom]) is fig
        assert top.get_xscale() == "linear" and bottom.get_xscale() == "log"
        assert len(fig.axes) == 2
        with pytest.raises(InputError, match="ax"):
            ob.plot(ax=[top, bottom, top])  # three axes for two panels
        with pytest.raises(InputError, match="kind"):
            ob.plot(kind="spectrum")
    finally:
        plt.close(fig)


def test_without_axes_a_new_figure_is_made_and_saved_as_matplotlib_saves_it(result):
    # reference: Figure.savefig's own PNG file of the same figure, decoded by PIL (pixel for
    # pixel: the same drawing)
    fig = result.observations["lab"].plot()
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    assert fig.get_layout_engine() is not None  # matplotlib places the axes (constrained)
    assert all(a.xaxis.get_visible() for a in fig.axes)
    png = png_bytes(fig, dpi=60)
    buf = io.BytesIO()  # the same figure made afresh (a layout engine's first draw), saved
    result.observations["lab"].plot().savefig(buf, format="png", dpi=60)
    ours = np.asarray(Image.open(io.BytesIO(png)))
    theirs = np.asarray(Image.open(io.BytesIO(buf.getvalue())))
    assert ours.shape == theirs.shape and np.array_equal(ours, theirs)


#: public names of the figure modules that draw no figure
NOT_FIGURES = {
    "KINDS",
    "active_figures",
    "limit_steps",
    "live_axes",
    "sample_displacements",
    "write_png_atomic",
}


def test_every_plot_function_takes_ax():
    # reference: the signatures of the public plot functions of every figure module
    import importlib

    names = ["active", "analysis", "environment", "frequency", "intervals", "isolation"]
    names += ["location", "modes", "quasisteady", "seed", "study"]
    missing = []
    for name in names:
        mod = importlib.import_module(f"microg.plotting.{name}")
        for fn_name in mod.__all__:
            fn = getattr(mod, fn_name)
            if fn_name in NOT_FIGURES:
                continue
            if "ax" not in inspect.signature(fn).parameters:
                missing.append(f"{name}.{fn_name}")
    assert missing == []


def test_figure_helpers_check_the_callers_axes():
    fig, ax = figure_axes(None, 4.0, 3.0)
    assert tuple(fig.get_size_inches()) == (4.0, 3.0) and fig.axes == [ax]
    assert figure_axes(ax)[0] is fig  # the caller's axes: their figure, unchanged
    with pytest.raises(InputError, match="ax"):
        figure_axes("not an axes")  # type: ignore[arg-type]
    fig2, grid = figure_grid(None, 2, 3)
    assert grid.shape == (2, 3) and len(fig2.axes) == 6
    assert figure_grid(list(grid.ravel()), 3, 2)[1].shape == (3, 2)  # read row by row
    with pytest.raises(InputError, match="6 matplotlib Axes"):
        figure_grid(list(grid.ravel())[:5], 2, 3)
    sub = Figure().subfigures(1, 2)[0].add_subplot()
    assert isinstance(figure_axes(sub)[0], Figure)  # a subfigure's axes: the root figure


def test_line2d_set_is_matplotlibs_own(tmp_path):
    # reference: Line2D.set's signature and docstring in a plain interpreter; the other
    # interpreter runs ``microg analyze`` first (matplotlib imported by microg), then reads them
    import json
    import subprocess
    import sys

    read = (
        "import inspect, json, matplotlib.lines as ml\n"
        "print(json.dumps([str(inspect.signature(ml.Line2D.set)), ml.Line2D.set.__doc__]))\n"
    )
    run = (
        "import sys\n"
        "from microg.cli import main\n"
        f"assert main(['analyze', '--duration', '40', '--dt', '0.02', '--no-progress', "
        f"'--out', {str(tmp_path / 'out')!r}]) == 0\n"
        "assert 'matplotlib.lines' in sys.modules\n"
    )

    def py(code: str) -> list[str]:
        out = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=300
        )
        return json.loads(out.stdout.strip().splitlines()[-1])

    plain, after = py(read), py(run + read)
    assert after == plain
    assert "linewidth" in plain[0] and len(plain[1]) > 1000  # the generated set() signature


def test_report_figures_keep_every_label_inside():
    # reference: matplotlib's own text extents, measured after drawing
    import microg
    from microg.report.analysis import figure_builders

    result = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02, isolation=False)
    assert list(figure_builders(result)) == [
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
