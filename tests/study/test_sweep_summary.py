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
