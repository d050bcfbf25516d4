"""locate over imported models: a modal model's grids (UFF, own .npz) and a NASTRAN deck's nodes.

References:

* the IOC FE model's own acceleration map (:func:`acceleration_map` on microg's frame FE) at
  the nodes it exported as grids (``write_uff_modes``, double precision);
* the exact free-free Euler-Bernoulli beam: the nodes of its first bending mode at
  ``x/L = 0.22416, 0.77584`` (``cos(bL) cosh(bL) = 1``, ``bL = 4.730041``);
* the exact modal response at the deck's grids from
  :func:`microg.dynamics.response.response_at_points` and the certified exact peak of
  :func:`microg.dynamics.response.peak_response` (other kernels than the map's).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from microg.dynamics.crew import CrewPushoff
from microg.dynamics.forces import REPORT_F0_N, ForceHistory
from microg.dynamics.modes import solve_modes
from microg.dynamics.response import generalized_force_vector, peak_response, response_at_points
from microg.errors import InputError
from microg.location.amap import POINTS_COMPONENT, acceleration_map, locate, point_peak
from microg.location.peaks import force_breakpoints, time_grid
from microg.models.load import load_model
from microg.models.modal import save_modal_model
from microg.models.toml import load_station
from microg.models.uff import write_uff_modes
from microg.structure.discretize import discretize
from microg.structure.modal import GRID_COMPONENT

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "validation"))
from test_frame_closed_loop import _f8, write_deck  # noqa: E402  (the tests' own deck writer)

pytestmark = pytest.mark.nastran

N_MODES = 30


@pytest.fixture(scope="module")
def ioc_fe():
    s = discretize(load_station("ioc"))
    md = solve_modes(s, N_MODES)
    ref = acceleration_map(s, md, "crew", "x", CrewPushoff(REPORT_F0_N))
    return s, md, ref


@pytest.fixture(scope="module")
def exported(ioc_fe, tmp_path_factory):
    s, md, _ = ioc_fe
    d = tmp_path_factory.mktemp("ioc")
    uff = write_uff_modes(md, d / "ioc.unv", precision="double", points_path=d / "ioc.toml")
    return uff, d / "ioc.toml"


def test_modal_map_at_grids_equals_the_fe_map(ioc_fe, exported):
    s, md, ref = ioc_fe
    uff, pts = exported
    res = locate(uff, points=pts, crew="crew", direction="x", zeta=0.0)  # ref is undamped
    amap = res.amap
    p = len(s.samples.labels)  # the FE samples, written as grids 1..p (then the named points)
    assert amap.method == "modal" and amap.n_samples == p + 5 + 5  # + 5 point grids + 5 points
    assert list(amap.labels[:3]) == ["grid:1", "grid:2", "grid:3"]
    assert set(amap.component[:p]) == {GRID_COMPONENT}
    np.testing.assert_array_equal(amap.positions[:p], ref.positions[:p])
    # the same 30 modes through a lossless (E25.16) file; the rigid modes come back as an
    # exact rigid basis of the same subspace, on which every measure but the per-mode rigid
    # rows is invariant: equal to rounding (1e-10 of the largest value leaves 1e4 ulps)
    for m in ("total", "elastic", "rigid", "bound", "long_time"):
        a, b = amap.measure(m)[:p], ref.measure(m)[:p]
        assert np.max(np.abs(a - b)) <= 1e-10 * b.max(), m
    el = amap.elastic
    assert np.allclose(amap.per_mode[el][:, :p], ref.per_mode[ref.elastic][:, :p], rtol=1e-9)
    assert amap.omega[amap.fundamental] == pytest.approx(ref.omega[ref.fundamental], rel=1e-12)
    # no element connectivity, grids not collinear: no lines, no nodes, and a warning
    assert amap.lines == () and amap.nodes == ()
    assert any("no beam line" in w for w in res.warnings)
    # the best grid is the FE map's best sample among the same samples
    i = int(np.argmin(ref.total_peak[:p]))
    assert res.best.label == f"grid:{i + 1}" and res.best.component == GRID_COMPONENT
    d = res.to_dict()
    assert d["best_location"]["label"] == res.best.label
    assert d["samples"][0]["label"] == "grid:1"


def test_named_points_are_mapped_with_their_own_peaks(ioc_fe, exported):
    s, md, ref = ioc_fe
    uff, pts = exported
    res = locate(uff, points=pts, crew="crew", direction="x", on="points", zeta=0.0)
    amap = res.amap
    sel = amap.component == POINTS_COMPONENT
    names = list(amap.labels[sel])
    assert names == ["lab", "crew", "vertical-lab", "keel-tip", "boom-tip"]
    # reference: the FE model's peaks at the same named points (same kernel at one point,
    # FE point maps with their rigid offsets); to rounding as above
    for name, total in zip(names, amap.total_peak[sel], strict=True):
        fe = point_peak(s, md, name, "crew", "x", CrewPushoff(REPORT_F0_N))
        assert total == pytest.approx(fe.total_mps2, rel=1e-9), name
    best = names[int(np.argmin(amap.total_peak[sel]))]
    assert res.best.label == best and res.best.component == POINTS_COMPONENT


def test_own_npz_file_gives_the_same_map(exported, tmp_path):
    uff, pts = exported
    a = locate(uff, points=pts, crew="crew").amap
    npz = save_modal_model(load_model(uff), tmp_path / "ioc.npz")
    b = locate(npz, points=pts, crew="crew").amap
    # the own file stores the model's arrays bit for bit
    np.testing.assert_array_equal(a.total_peak, b.total_peak)
    np.testing.assert_array_equal(a.per_mode, b.per_mode)
    # the model object itself (microg.load_model's result) takes the same path
    c = locate(load_model(uff, points=pts), crew="crew").amap
    np.testing.assert_array_equal(a.total_peak, c.total_peak)
    ds = c.to_xarray()
    assert list(ds["label"].values[:2]) == ["grid:1", "grid:2"]


def test_crew_grid_and_errors(exported):
    uff, pts = exported
    res = locate(uff, crew="grid:3", direction="z")
    assert res.amap.crew_point == "grid:3"
    assert res.amap.labels is not None and POINTS_COMPONENT not in set(res.amap.component)
    with pytest.raises(InputError, match="nearest grids") as exc:
        locate(uff, crew="grid:100000")
    assert exc.value.where == "crew"
    with pytest.raises(InputError, match="no crew point"):
        locate(uff)  # no points file: no crew point named
    with pytest.raises(InputError) as exc:
        locate(load_model(uff), units="m, N, s")
    assert exc.value.where == "units"


# --------------------------------------------------------------------------- NASTRAN decks


def _beam_deck(path: Path, n: int = 40, length: float = 10.0) -> Path:
    """A free-free uniform CBAR beam along x, consistent mass, and a 1-mg CONM2 off the line.

    The CONM2 (1e-6 kg against the beam's 27 kg, 0.5 m off its end) puts a sample off the
    line, so the deck's nodes are not all collinear and the lines come from the elements;
    its effect on the modes is ~1e-8 relative.
    """
    lines = ["SOL 103", "CEND", "BEGIN BULK", "PARAM,COUPMASS,1"]
    for i in range(n + 1):
        lines.append(f"GRID    {i + 1:>8d}        " + _f8(length * i / n) + _f8(0.0) + _f8(0.0))
    lines.append("MAT1,1,7.0e10,,0.33,2700.")
    lines.append("PBAR,10,1,1.0e-3,2.0e-6,3.0e-6,4.0e-6")
    for i in range(n):
        lines.append(
            f"CBAR    {i + 1:>8d}{10:>8d}{i + 1:>8d}{i + 2:>8d}" + _f8(0) + _f8(0) + _f8(1)
        )
    lines.append(f"CONM2,900,{n + 1},0,1.0e-6,0.,0.,0.5")
    lines.append("ENDDATA")
    path.write_text("\n".join(lines) + "\n")
    return path


def _free_free_beam():
    """bL of the first free-free bending mode and the shape psi(x/L), exact (Euler-Bernoulli)."""
    bl = brentq(lambda b: np.cos(b) * np.cosh(b) - 1.0, 4.0, 5.0, xtol=1e-15)
    sig = (np.cosh(bl) - np.cos(bl)) / (np.sinh(bl) - np.sin(bl))

    def psi(x, k=0):
        b = bl
        if k == 0:
            return np.cosh(b * x) + np.cos(b * x) - sig * (np.sinh(b * x) + np.sin(b * x))
        if k == 1:
            return b * (np.sinh(b * x) - np.sin(b * x) - sig * (np.cosh(b * x) + np.cos(b * x)))
        return b * b * (np.cosh(b * x) - np.cos(b * x) - sig * (np.sinh(b * x) - np.sin(b * x)))

    return bl, psi


def test_deck_beam_nodes_are_the_exact_free_free_nodes(tmp_path):
    n, length = 40, 10.0
    # the 12 lowest modes: the fundamental's shape does not depend on the others
    res = locate(
        _beam_deck(tmp_path / "beam.bdf", n, length),
        units="m, N, s",
        crew="grid:1",
        direction="y",
        n_modes=12,
    )
    amap = res.amap
    assert amap.method == "fem" and res.warnings == ()
    # one line: the chain of 40 collinear CBARs (the off-line CONM2 sample is not on it)
    assert [ln.component for ln in amap.lines] == ["grid:1..grid:41"]
    assert amap.lines[0].index.size == n + 1
    _, psi = _free_free_beam()
    exact = [brentq(psi, 0.1, 0.4, xtol=1e-15), brentq(psi, 0.6, 0.9, xtol=1e-15)]
    got = sorted(nd.position[0] / length for nd in amap.nodes)
    assert len(got) == 2
    h = 1.0 / n
    for x0, g in zip(exact, got, strict=True):
        # linear interpolation of the shape between grids h apart misplaces a zero by at most
        # h^2 |psi''| / (8 |psi'|) at it (the interpolant's error over its slope); the FE
        # shape itself is O(h^4) from the exact one, the CONM2 ~1e-8: bound with 10 % margin
        bound = 1.1 * h * h * abs(psi(x0, 2)) / (8.0 * abs(psi(x0, 1)))
        assert abs(g - x0) <= bound, (g, x0, bound)


@pytest.fixture(scope="module")
def truss(tmp_path_factory):
    deck = write_deck(tmp_path_factory.mktemp("truss") / "truss.bdf")
    return deck, load_model(deck, units="mm, N, s")


def test_deck_map_equals_the_exact_response_at_its_grids(truss):
    deck, graph = truss
    res = locate(deck, units="mm, N, s", crew="grid:1", direction="x", n_modes=12, zeta=0.0)
    amap = res.amap
    st = discretize(graph)
    md = solve_modes(st, 12)
    np.testing.assert_allclose(md.omega, amap.omega, rtol=1e-12)
    # reference 1: the exact modal response (response_at_points) at the map's own time grid
    force = CrewPushoff(REPORT_F0_N)
    tb, fb = force_breakpoints(force)
    t = time_grid(tb, md.omega, md.elastic, None)
    assert t.size == amap.n_timepts
    b = generalized_force_vector(st.point("grid:1").translation, np.array([1.0, 0.0, 0.0]))
    grids = [f"grid:{g}" for g in range(1, 10)]
    maps = {g: st.point(g).translation for g in grids}
    fh = ForceHistory(tb, fb)
    resp = response_at_points(md.omega, np.zeros(md.n_modes), md.phi, maps, fh, b, t)
    exact = peak_response(md.omega, np.zeros(md.n_modes), md.phi, maps, [(fh, b)], t)
    for g in grids:
        i = int(np.flatnonzero(amap.labels == g)[0])
        sampled = float(np.max(np.abs(resp[g].acceleration[0])))
        # same samples, two kernels: rounding (1e-9 of the peak)
        assert amap.total_peak[i] == pytest.approx(sampled, rel=1e-9), g
        # reference 2: the certified exact x peak; the grid has >= 32 points per period of
        # the fastest mode, so sampling loses at most 1 - cos(pi/32) = 0.48 % of a crest
        top = float(exact[g].peak_accel_mps2_axis[0])
        assert top * (1 - 0.0049) <= amap.total_peak[i] <= top * (1 + 1e-9), g


def test_deck_lines_and_nodes_follow_the_elements(truss):
    deck, graph = truss
    res = locate(deck, units="mm, N, s", crew="grid:1", direction="x")
    amap = res.amap
    # the GraphModel object takes the same path as its deck
    np.testing.assert_array_equal(locate(graph, crew="grid:1").amap.total_peak, amap.total_peak)
    # 12 CBARs + 5 CRODs, no two collinear through a node: 17 one-element lines
    assert len(amap.lines) == 17
    ends = {tuple(sorted(amap.labels[ln.index[[0, -1]]])) for ln in amap.lines}
    elems = {tuple(sorted((f"grid:{a}", f"grid:{b}"))) for a, b in (*_bars(), *_rods())}
    assert ends == elems
    # every node of the fundamental is where its shape changes sign along an element,
    # located by linear interpolation between the two grids
    shape = amap.fundamental_shape
    assert amap.nodes
    for nd in amap.nodes:
        ln = next(ln for ln in amap.lines if ln.component == nd.component)
        ya, yb = shape[ln.index[0]], shape[ln.index[-1]]
        assert ya * yb < 0
        pa, pb = amap.positions[ln.index[0]], amap.positions[ln.index[-1]]
        np.testing.assert_allclose(nd.position, pa + ya / (ya - yb) * (pb - pa), atol=1e-12)


def _bars():
    from test_frame_closed_loop import BARS

    return [(a, b) for a, b, _ in BARS.values()]


def _rods():
    from test_frame_closed_loop import RODS

    return list(RODS.values())
