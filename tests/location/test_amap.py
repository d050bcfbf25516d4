"""Tests of microg.location.amap: the acceleration map (Eqs. 2.20b/3.1), point peaks, locate()."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microg import defaults
from microg.dynamics.crew import CrewPushoff, acceleration_a
from microg.dynamics.forces import REPORT_F0_N
from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.location.amap import (
    DEFAULTS,
    acceleration_map,
    best_location,
    locate,
    point_peak,
)
from microg.location.peaks import elastic_modes
from microg.models.toml import load_station
from microg.structure.discretize import discretize
from microg.units import G0

CREW = CrewPushoff(REPORT_F0_N)


@pytest.fixture(scope="module")
def ioc():
    # the location stage's structure: the one entry, free-free (locate's pipeline)
    station = load_station("ioc")
    structure = discretize(station, "ritz", plane="xz", n=1)
    return station, structure, solve_modes(structure)


@pytest.fixture(scope="module")
def ioc_map(ioc):
    _, structure, modes = ioc
    return acceleration_map(structure, modes, "crew", "x", CREW)


def _sample_at(amap, position):
    i = int(np.argmin(np.linalg.norm(amap.positions - position, axis=1)))
    assert np.linalg.norm(amap.positions[i] - position) < 1e-9
    return i


def test_per_mode_map_is_eq_3_1_at_the_lab(ioc, ioc_map):
    # independent route: the named point's own map (not the samples), and [A]max as the
    # maximum of the closed-form A(t) of Eq. 2.19 over a dense grid (not the crest formula)
    _, structure, modes = ioc
    lab = structure.point("lab")
    i = _sample_at(ioc_map, lab.position)
    phi_lab = (lab.translation @ modes.phi)[0]  # x translation, mass-normalised (M_jj = 1)
    el = elastic_modes(modes)
    # A(t) jumps at t1, t13 (force jumps): the sup there is the one-sided limit, so the grid
    # also holds the instants just after each jump
    jumps = np.array([CREW.t1, CREW.t13, CREW.t14]) + 1e-12
    t = np.sort(np.r_[np.linspace(0.0, 200.0, 400_001), jumps])
    for j in np.flatnonzero(el):
        w = modes.omega[j]
        amax = np.max(np.abs(acceleration_a(w, t, CREW)))
        direct = phi_lab[j] ** 2 * CREW.f0 / (w * CREW.t1) * amax
        # an interior crest is sampled within (w dt)^2/8 = 4e-7 relative (w <= 3.7 rad/s,
        # dt = 5e-4 s); a one-sided limit at a jump within slope x 1e-12 s; 1e-6 covers both
        assert ioc_map.per_mode[j, i] == pytest.approx(direct, rel=1e-6, abs=1e-30)


def test_rigid_translation_is_f0_over_total_mass_everywhere():
    # with gravity gradient the rotation is restrained (libration), so the only exact rigid
    # mode is the translation: mass-normalised, it gives f0 / M at every point (Newton)
    station = load_station("ioc")
    structure = discretize(station, "ritz", plane="xz", n=1, gravity_gradient=True)
    modes = solve_modes(structure)
    amap = acceleration_map(structure, modes, "crew", "x", CREW)
    total, _, _ = station.mass_properties()
    (j,) = np.flatnonzero(modes.rigid)
    np.testing.assert_allclose(amap.per_mode[j], CREW.f0 / total, rtol=1e-10)


def test_rigid_part_is_newton_euler_of_the_free_body(ioc, ioc_map):
    # reference: the rigid-body motion of the free structure without modes, by projecting on
    # the exact rigid vectors R = [r_x, r_ry]: a(s) = T_s R (R^T M R)^-1 R^T T_a^T f0 (Newton
    # and Euler in generalized coordinates).  It does not depend on how the eigensolver
    # chose its basis of the two-dimensional rigid subspace; the map's rigid_peak must not.
    _, structure, _ = ioc
    m, _ = structure.dense()
    r = np.column_stack([structure.rigid_body[k] for k in ("x", "ry")])
    crew = structure.point("crew").translation[0]
    proj = r @ np.linalg.solve(r.T @ m @ r, r.T @ crew)
    i = _sample_at(ioc_map, structure.point("lab").position)
    ref = abs(structure.point("lab").translation[0] @ proj) * CREW.f0
    # both are a few products of O(1) numbers: rounding only
    assert ioc_map.rigid_peak[i] == pytest.approx(ref, rel=1e-10)
    # f0/M alone is the translation; the lab (12 ft from the centre of mass, with the crew)
    # also gets the rotation's share, which has the same sign there
    assert ioc_map.rigid_peak[i] > CREW.f0 / structure.total_mass


def test_total_peak_matches_direct_integration_and_bound(ioc, ioc_map):
    # reference: scipy's RK45 integration of M q'' + K q = b f(t) in generalized
    # coordinates (no modal decomposition), interval by interval over the force's pieces
    _, structure, _ = ioc
    m, k = structure.dense()
    lab = structure.point("lab")
    b = lab.translation[0]  # generalized force per newton along x at the crew point
    minv = np.linalg.inv(m)
    n = m.shape[0]
    t_end = ioc_map.window[1]
    pieces = [(0.0, CREW.t1, 0.0, CREW.f0), (CREW.t1, CREW.t13, 0.0, 0.0)]
    pieces += [(CREW.t13, CREW.t14, -CREW.f0, 0.0), (CREW.t14, t_end, 0.0, 0.0)]
    y = np.zeros(2 * n)
    peak = 0.0
    for a, c, f_a, f_c in pieces:

        def force(t, a=a, c=c, f_a=f_a, f_c=f_c):
            return f_a + (f_c - f_a) * (t - a) / (c - a)

        def rhs(t, yy, force=force):
            q, v = yy[:n], yy[n:]
            return np.concatenate([v, minv @ (b * force(t) - k @ q)])

        ts = np.linspace(a, c, max(2, int((c - a) / 2e-3)))
        sol = solve_ivp(rhs, (a, c), y, t_eval=ts, rtol=1e-10, atol=1e-14, method="DOP853")
        q = sol.y[:n]
        acc = b @ (minv @ (np.outer(b, force(ts)) - k @ q))
        peak = max(peak, float(np.max(np.abs(acc))))
        y = sol.y[:, -1]
    i = _sample_at(ioc_map, lab.position)
    # the map samples at least 32 points per shortest period (crest error <= 0.48 %), the
    # reference every 2 ms; 0.6 % covers both grids
    assert ioc_map.total_peak[i] == pytest.approx(peak, rel=6e-3)
    # a peak of a sum never exceeds the sum of the peaks (tiny slack for rounding)
    assert np.all(ioc_map.total_peak <= ioc_map.peak_bound * (1 + 1e-12))
    assert np.all(ioc_map.long_time_peak >= ioc_map.total_peak)
    assert np.all(ioc_map.long_time_peak <= ioc_map.peak_bound * (1 + 1e-12))


def test_best_location_is_the_minimum_of_the_map(ioc_map):
    for measure in ("total", "elastic", "bound"):
        values = ioc_map.measure(measure)
        loc = best_location(ioc_map, measure=measure)
        assert loc.peak == np.min(values)
        on_main = best_location(ioc_map, component="main", measure=measure)
        assert on_main.component == "main"
        assert on_main.peak == np.min(values[ioc_map.component == "main"])
    with pytest.raises(InputError, match="known components") as exc:
        best_location(ioc_map, component="nowhere")
    assert exc.value.where == "on"


def test_best_elastic_location_on_the_body_is_next_to_the_node(ioc_map):
    # conclusion 7: the quietest place on the main body is the fundamental's node (within
    # the densified sample spacing, 1/120 of the body)
    ft = 0.3048
    loc = best_location(ioc_map, component="main", measure="elastic")
    node = [n for n in ioc_map.nodes if n.component == "main"][0]
    assert abs(loc.position[2] - node.position[2]) < 2.0 * 127 * ft / 120


def test_map_validation(ioc):
    _, structure, modes = ioc
    with pytest.raises(InputError, match="known points"):
        acceleration_map(structure, modes, "nowhere", "x", CREW)
    with pytest.raises(InputError, match="zeta"):
        acceleration_map(structure, modes, "crew", "x", CREW, zeta=1.0)
    with pytest.raises(InputError, match="direction"):
        acceleration_map(structure, modes, "crew", "w", CREW)
    with pytest.raises(InputError, match="force"):
        acceleration_map(structure, modes, "crew", "x", object())


def test_time_grid_path_agrees_with_exact_amax(ioc, ioc_map):
    # a vanishing damping ratio forces the time-grid path (exact piecewise-linear response on
    # a grid with both sides of every jump); it must agree with the closed-form [A]max to the
    # grid's crest error, <= 1 - cos(pi/32) = 0.48 % (from below)
    _, structure, modes = ioc
    grid = acceleration_map(structure, modes, "crew", "x", CREW, zeta=1e-12)
    assert not grid.exact_per_mode and ioc_map.exact_per_mode
    el = ioc_map.elastic
    ratio = grid.per_mode[el] / np.where(ioc_map.per_mode[el] > 0, ioc_map.per_mode[el], 1.0)
    big = ioc_map.per_mode[el] > 1e-12 * ioc_map.per_mode[el].max()
    assert np.all(ratio[big] <= 1 + 1e-9) and np.all(ratio[big] >= 1 - 4.9e-3)
    assert grid.long_time_peak is None  # defined for undamped models only
    damped = acceleration_map(structure, modes, "crew", "x", CREW, zeta=0.05)
    assert np.all(damped.total_peak <= damped.peak_bound * (1 + 1e-12))


def test_point_peak_is_the_map_at_the_point(ioc, ioc_map):
    # one kernel: the site's peaks must be the map's at the sample on the same position (the
    # named point's map and the sample's are the same Ritz field; same time grid)
    _, structure, modes = ioc
    site = point_peak(structure, modes, "lab", "crew", "x", CREW)
    i = _sample_at(ioc_map, structure.point("lab").position)
    for name in ("total", "elastic", "rigid", "bound"):
        assert site.measure(name) == pytest.approx(ioc_map.measure(name)[i], rel=1e-12)
    np.testing.assert_allclose(site.per_mode_mps2, ioc_map.per_mode[:, i], rtol=1e-12)
    d = site.to_dict()
    assert d["total_g"] == pytest.approx(site.total_mps2 / G0, rel=1e-15)
    assert len(d["per_mode_g"]) == int(site.elastic.sum())
    with pytest.raises(InputError, match="measure"):
        site.measure("loudest")


def test_locate_is_the_one_pipeline(ioc, ioc_map):
    # locate() = discretize (free-free) -> solve_modes -> acceleration_map -> best_location,
    # with the model's first crew point by default; the report's settings as ioc_map's
    res = locate("ioc", on="main", method="ritz", plane="xz", zeta=0.0)
    assert res.amap.crew_point == "crew"
    np.testing.assert_array_equal(res.amap.total_peak, ioc_map.total_peak)
    ref = best_location(ioc_map, component="main")
    assert (res.best.index, res.best.peak, res.best.measure) == (ref.index, ref.peak, ref.measure)
    assert res.amap.method == "ritz" and res.amap.plane == "xz"
    # the defaults are microg.defaults' (those of microg analyze)
    assert (DEFAULTS["method"], DEFAULTS["plane"], DEFAULTS["zeta"]) == (
        defaults.METHOD,
        defaults.PLANE,
        defaults.DAMPING,
    )
    assert res.warnings == ()


def test_locate_validation():
    with pytest.raises(InputError) as exc:
        locate("ioc", "nowhere")
    assert exc.value.where == "crew" and "known points" in str(exc.value)
    with pytest.raises(InputError) as exc:
        locate("ioc", direction="z", method="ritz", plane="xz")
    assert exc.value.where == "direction"
    with pytest.raises(InputError) as exc:
        locate("ioc", measure="loudest")
    assert exc.value.where == "measure"
    with pytest.raises(InputError) as exc:
        locate("ioc", method="bem")
    assert exc.value.where == "method"


def test_to_dict_to_xarray_and_plot(ioc_map):
    from matplotlib.figure import Figure

    d = ioc_map.to_dict()
    assert len(d["samples"]) == ioc_map.n_samples
    assert d["samples"][3]["total_peak_g"] == pytest.approx(ioc_map.total_peak[3] / G0)
    assert d["samples"][3]["rigid_peak_g"] == pytest.approx(ioc_map.rigid_peak[3] / G0)
    ds = ioc_map.to_xarray()
    assert ds["position"].dims == ("sample", "axis") and ds["position"].attrs["units"] == "m"
    assert ds["total_peak"].attrs["units"] == "m/s^2"
    assert ds["per_mode"].dims == ("mode", "sample")
    assert ds["omega"].attrs["units"] == "rad/s"
    np.testing.assert_array_equal(ds["elastic_peak"].values, ioc_map.elastic_peak)
    import matplotlib

    backend = matplotlib.get_backend()
    fig = ioc_map.plot(best=best_location(ioc_map))
    assert isinstance(fig, Figure) and matplotlib.get_backend() == backend
