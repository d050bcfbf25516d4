"""The summary (one pass over the store) against xarray's own reductions of the Dataset."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

from microg.errors import InputError
from microg.study import CASE_DIMS, loads_study, sweep
from microg.study.summary import default_heatmap

TEXT = """
[study]
model = "ioc"
[axes]
force = ["foot-pushoff-max", "hand-pushoff-mean"]
at = ["crew", "vertical-lab", "boom-tip"]
direction = ["x", "y", "z"]
observe = ["lab", "keel-tip", "boom-tip"]
damping = [0.002, 0.01]
[record]
duration = "40 s"
dt = "0.1 s"
max_freq = "2 Hz"
[[case]]
at = ["crew", "vertical-lab"]
[[case]]
at = "boom-tip"
direction = "z"
"""


@pytest.fixture(scope="module")
def result():
    return sweep(loads_study(TEXT, filename="s.toml"))


def test_counts_and_fraction(result) -> None:
    ds = result.dataset.load()
    s = result.summary()
    assert s.cases == int(ds.computed.sum()) == result.study.n_cases == 2 * 2 * (2 * 3 + 1) * 3
    assert s.complying == int((ds.complies & ds.computed).sum())
    assert s.complying_fraction == pytest.approx(s.complying / s.cases, rel=1e-15)


def test_heatmap_is_the_min_over_the_other_axes(result) -> None:
    ds = result.dataset.load()
    for dims in (("at", "observe"), ("force", "direction"), ("observe", "damping")):
        s = result.summary(heatmap=dims)
        other = [d for d in CASE_DIMS if d not in dims]
        ref = ds.margin.where(ds.computed).min(other).transpose(*dims).values
        np.testing.assert_array_equal(s.heatmap, ref)
    assert np.isnan(result.summary(heatmap=("at", "direction")).heatmap[2, 0])  # not planned


def test_worst_cases_per_point(result) -> None:
    ds = result.dataset.load()
    s = result.summary(n_worst=3)
    for o in result.study.observe:
        m = ds.margin.sel(observe=o).where(ds.computed.sel(observe=o))
        ref = np.sort(m.values[np.isfinite(m.values)])[:3]
        got = [w["margin"] for w in s.worst[o]]
        np.testing.assert_array_equal(got, ref)
        for w in s.worst[o]:
            assert w["case"]["observe"] == o
            point = ds.sel({k: v for k, v in w["case"].items()})
            assert float(point.margin) == w["margin"]
    assert s.worst_list()[0]["margin"] == min(w["margin"] for w in s.worst_list())


def test_fraction_by_axis(result) -> None:
    ds = result.dataset.load()
    s = result.summary()
    for d, rows in s.fraction_by.items():
        other = [x for x in CASE_DIMS if x != d]
        n = ds.computed.sum(other).values
        ok = (ds.complies & ds.computed).sum(other).values
        for (label, fr), ni, oki in zip(rows, n, ok, strict=True):
            assert fr == (None if ni == 0 else pytest.approx(oki / ni, rel=1e-15)), (d, label)


def test_default_heatmap_and_bad_axes(result) -> None:
    assert default_heatmap(result.study) == ("at", "observe")
    with pytest.raises(InputError) as info:
        result.summary(heatmap=("at", "at"))
    assert info.value.where == "heatmap"


def test_plot_returns_a_figure(result) -> None:
    assert isinstance(result.plot(), Figure)
    from microg.plotting.study import fraction_figure, worst_bands_figure

    s = result.summary()
    assert isinstance(fraction_figure(s), Figure) and isinstance(worst_bands_figure(s), Figure)


def test_to_dict_is_json_ready(result) -> None:
    from microg._io import dumps

    d = result.to_dict()
    text = dumps(d)
    assert '"cases"' in text and d["cases"] == result.study.n_cases


def test_summary_to_xarray_and_plot(result) -> None:
    # reference: the dataset's own reduction (xarray), as test_heatmap_is_... does
    ds = result.dataset.load()
    s = result.summary(heatmap=("at", "observe"))
    hx = s.to_xarray()
    ref = ds.margin.where(ds.computed).min([d for d in CASE_DIMS if d not in ("at", "observe")])
    np.testing.assert_array_equal(hx.margin.values, ref.transpose("at", "observe").values)
    assert hx.margin.attrs["units"] == "1" and hx.attrs["cases"] == s.cases
    assert list(hx.observe.values) == [str(o) for o in ref.observe.values]
    assert isinstance(s.plot(), Figure)


def test_heatmap_colours_the_margin_on_a_labelled_log_scale_with_the_limit_line(result) -> None:
    from matplotlib.colors import LogNorm

    from microg.plotting.common import png_bytes
    from microg.plotting.study import heatmap_figure

    s = result.summary(heatmap=("at", "observe"))
    fig = heatmap_figure(s)
    ax = fig.axes[0]
    im = ax.images[0]
    m = np.asarray(s.heatmap, float)
    # the image holds the margins themselves (not their log10), on a log norm centred on 1
    assert isinstance(im.norm, LogNorm)
    assert im.norm.vmin * im.norm.vmax == pytest.approx(1.0, rel=1e-12)
    shown = np.ma.filled(im.get_array(), np.nan)
    ok = np.isfinite(m)
    np.testing.assert_allclose(
        shown[ok], np.clip(m[ok], im.norm.vmin, im.norm.vmax), rtol=0, atol=0
    )
    assert "margin" in fig.axes[1].get_ylabel() and "log" in fig.axes[1].get_ylabel()
    # the margin-1 line: one unit segment per pair of neighbouring cells on either side of 1
    fail, good = ok & (m < 1), ok & (m >= 1)
    pairs = int(np.sum(fail[:, :-1] & good[:, 1:] | good[:, :-1] & fail[:, 1:]))
    pairs += int(np.sum(fail[:-1] & good[1:] | good[:-1] & fail[1:]))
    assert fail.any() and good.any() and pairs > 0  # the study has both sides
    lines = [c for c in ax.collections if c.get_label() == "margin 1"]
    assert len(lines) == 1 and len(lines[0].get_segments()) == pairs
    assert png_bytes(fig)[:4] == b"\x89PNG"


def test_sweep_page_says_each_thing_once(result) -> None:
    import re

    from microg.report.study import figures, render_sweep

    s = result.summary()
    page = render_sweep(s, figures(s))
    notes = [re.sub(r"\s+", " ", re.sub(r"<[^>]+>", "", p)).strip()
             for p in re.findall(r'<p class="note">(.*?)</p>', page, flags=re.S)]  # fmt: skip
    sentences = [x.strip() for n in notes for x in re.split(r"(?<=\.)\s", n) if x.strip()]
    assert len(sentences) == len(set(sentences))
    # the heat map's caption adds what its title does not say: the scale and the limit line
    cap = next(n for n in notes if "--heatmap" in n)
    assert "log scale of the margin" in cap and "black line" in cap
    assert "worst margin over every other axis" not in cap  # the figure's title says it


def test_summary_shows_itself_in_a_notebook(result) -> None:
    import re

    s = result.summary(heatmap=("at", "observe"))
    page = s._repr_html_()
    frac = f"{100 * s.complying_fraction:.1f} %"
    assert f"{s.cases} cases" in page and f"{s.complying} comply with {s.requirement}" in page
    assert frac in page
    # one row per observed point: its worst case's margin (to_dict's number) and verdict
    for name, worst in s.worst.items():
        m = re.search(rf"<tr><td>{re.escape(name)}</td><td>([^<]*)</td><td>([^<]*)</td>", page)
        assert m is not None, name
        assert m.group(1) == f"{worst[0]['margin']:.3g}"
        assert m.group(2) == ("complies" if worst[0]["complies"] else "does not comply")
    # the heat map's cells, row by row, are Summary.heatmap's
    for label, row in zip(s.heatmap_labels[0], np.asarray(s.heatmap, float), strict=True):
        cells = "".join("<td>-</td>" if np.isnan(v) else f"<td>{v:.3g}</td>" for v in row)
        assert f"<tr><th>{label}</th>{cells}</tr>" in page
