"""Tests of microg.location.amap: acceleration map (Eqs. 2.20b/3.1), nodes, optimiser."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microg.dynamics.crew import CrewPushoff, acceleration_a
from microg.dynamics.dense import solve_dense
from microg.dynamics.forces import REPORT_F0_N
from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.location.amap import (
    acceleration_map,
    best_location,
    conclusion7,
    elastic_mask,
    layout_objective,
    movable_masses,
    move_masses,
    optimize_layout,
    resolve_mass,
)
from microg.models.station import NamedPoint
from microg.models.toml import load_station, loads_station
from microg.seed.ioc import report_matrices
from microg.structure.ritz import build_ritz

FT = 0.3048
CREW = CrewPushoff(REPORT_F0_N)

SMALL = """
[station]
name = "small"
units = "SI"
[orbit]
altitude = "500 km"
[[body]]
name = "core"
  [[body.mass]]
  name = "hab"
  mass = "20000 kg"
  at = ["0 m", "0 m", "-4 m"]
  [[body.mass]]
  name = "lab-module"
  mass = "15000 kg"
  at = ["0 m", "0 m", "-12 m"]
  [[body.mass]]
  name = "dock"
  mass = "30000 kg"
  at = ["0 m", "0 m", "-20 m"]
[[beam]]
name = "keel"
parent = "core"
root = ["0 m", "0 m", "0 m"]
direction = "+z"
length = "60 m"
ei = "4e8 N*m^2"
gj = "1e8 N*m^2"
mass_per_length = "20 kg/m"
  [[beam.mass]]
  name = "tip"
  mass = "8000 kg"
  s = "60 m"
[[point]]
name = "lab"
on = "core"
at = ["0 m", "0 m", "-12 m"]
[[point]]
name = "crew"
on = "core"
at = ["0 m", "0 m", "-12 m"]
"""


@pytest.fixture(scope="module")
def ioc():
    station = load_station("ioc")
    structure = build_ritz(station, "xz", 1)
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
    el = elastic_mask(modes.omega, modes.rigid)
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


def test_rigid_translation_is_f0_over_total_mass_everywhere(ioc, ioc_map):
    # a mass-normalised rigid translation gives f0 / M at every point (Newton's second law)
    station, _, modes = ioc
    total, _, _ = station.mass_properties()
    j = int(np.flatnonzero(modes.rigid)[0])
    np.testing.assert_allclose(ioc_map.per_mode[j], CREW.f0 / total, rtol=1e-10)


def test_total_peak_matches_direct_integration_and_bound(ioc, ioc_map):
    # reference: scipy's RK45 integration of M q'' + K q = b f(t) in generalized
    # coordinates (no modal decomposition), interval by interval over the force's pieces
    _, structure, _ = ioc
    m, k = structure.dense()
    lab = structure.point("lab")
    b = lab.translation[0]  # generalized force per newton along x at the crew point
    tb, fb = CREW.breakpoints()
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


def _station_with_point(station, name, on, position):
    pts = (*station.points, NamedPoint(name, on, np.asarray(position, float)))
    return dataclasses.replace(station, points=pts)


def test_nodes_are_zeros_of_the_fundamental(ioc, ioc_map):
    station, _, modes = ioc
    assert ioc_map.nodes, "the IOC fundamental has nodes"
    j = ioc_map.fundamental
    assert modes.omega[j] == pytest.approx(1.0175, rel=1e-3)  # the lowest excited mode
    scale = np.max(np.abs(ioc_map.fundamental_shape))
    for node in ioc_map.nodes:
        # reference: a named point placed at the node, its map built by the Ritz engine
        st = _station_with_point(station, "probe", node.component, node.position)
        s = build_ritz(st, "xz", 1)
        value = (s.point("probe").translation @ modes.phi[:, j])[0]
        carrier = st.component(node.component)
        if hasattr(carrier, "length"):
            # beam: linear interpolation of a cubic between samples 1/40 of the beam apart,
            # error <= (h/L)^2 max|psi''|/8 ~ 2e-4 of the peak; 2e-3 leaves margin
            assert abs(value) < 2e-3 * scale
        else:
            # rigid body: the displacement is affine, interpolation is exact to rounding
            assert abs(value) < 1e-10 * scale


def test_best_location_is_the_minimum_of_the_map(ioc_map):
    for measure in ("total", "elastic", "bound"):
        values = ioc_map.measure(measure)
        loc = best_location(ioc_map, measure=measure)
        assert loc.peak == np.min(values)
        on_main = best_location(ioc_map, component="main", measure=measure)
        assert on_main.component == "main"
        assert on_main.peak == np.min(values[ioc_map.component == "main"])
    with pytest.raises(InputError, match="known components"):
        best_location(ioc_map, component="nowhere")


def test_best_elastic_location_on_the_body_is_next_to_the_node(ioc_map):
    # conclusion 7: the quietest place on the main body is the fundamental's node (within
    # the densified sample spacing, 1/120 of the body)
    loc = best_location(ioc_map, component="main", measure="elastic")
    node = [n for n in ioc_map.nodes if n.component == "main"][0]
    assert abs(loc.position[2] - node.position[2]) < 2.0 * 127 * FT / 120


def test_ritz_one_function_is_the_reports_four_coordinate_model():
    # the report's q4 ties both half-booms; the fifth Ritz mode is the antisymmetric boom
    # mode, which the report's model cannot represent.  Same matrices -> same eigenvalues.
    station = load_station("ioc")
    rm = report_matrices(station, "xz")
    w4, _, _ = solve_dense(rm.mass, rm.stiffness, np.eye(4)[:, :2])
    s = build_ritz(station, "xz", 1, gravity_gradient=False)
    w5 = solve_modes(s).omega
    for w in w4[2:]:
        assert np.min(np.abs(w5 - w)) < 1e-9 * w


def test_conclusion7_what_holds():
    c = conclusion7()
    a, b = c.orbiter, c.no_orbiter
    # the no-orbiter fundamental has its node near the lab (z = -55 ft): within 5 ft
    assert len(b.body_nodes_z) == 1 and abs(b.body_nodes_z[0] - (-55 * FT)) < 5 * FT
    # with the orbiter the node is far below the lab (more than 30 ft)
    assert abs(a.body_nodes_z[0] - (-55 * FT)) > 30 * FT
    # the reduction at the lab is real but about one order, not the report's three
    assert 3.0 < c.ratio_mode1 < 100.0 < c.printed_ratio_mode1
    # with the rigid translation (f0/M: lighter station, larger) the no-orbiter lab is worse
    assert b.rigid_translation > a.rigid_translation
    assert c.ratio_total < 1.0
    # the lab is farther from the centre of mass without the orbiter (the report: 59.9 ft)
    assert c.moved > 0


def test_map_validation(ioc):
    _, structure, modes = ioc
    with pytest.raises(InputError, match="known points"):
        acceleration_map(structure, modes, "nowhere", "x", CREW)
    with pytest.raises(InputError, match="zeta"):
        acceleration_map(structure, modes, "crew", "x", CREW, zeta=1.0)
    with pytest.raises(InputError, match="direction"):
        acceleration_map(structure, modes, "crew", "w", CREW)


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


# --------------------------------------------------------------------------- layout


@pytest.fixture(scope="module")
def small():
    return loads_station(SMALL, filename="small.toml")


def test_resolve_and_validate_movable(small):
    station = load_station("ioc")
    with pytest.raises(InputError, match="ambiguous"):
        resolve_mass(station, "TDM 2010")
    comp, pm = resolve_mass(station, "boom-y/TDM 2010")
    assert comp.name == "boom-y" and pm.name == "TDM 2010"
    with pytest.raises(InputError, match="known masses"):
        resolve_mass(station, "Piano")
    with pytest.raises(InputError, match="leaves"):
        movable_masses(small, {"tip": (10.0, 70.0)})
    with pytest.raises(InputError, match="does not contain"):
        movable_masses(small, {"dock": (-10.0, -5.0)})
    with pytest.raises(InputError, match="LO < HI"):
        movable_masses(small, {"dock": (-5.0, -25.0)})
    (mm,) = movable_masses(small, {"tip": (30.0, 60.0)})
    assert mm.key == "keel/tip" and mm.kind == "beam" and mm.value == pytest.approx(60.0)


def test_move_masses_moves_mass_and_carried_point(small):
    (mm,) = movable_masses(small, {"lab-module": (-20.0, -4.0)})
    moved = move_masses(small, [mm], np.array([-6.0]), carry={"lab": mm.key})
    pm = [p for p in moved.bodies[0].masses if p.name == "lab-module"][0]
    np.testing.assert_allclose(pm.position, [0.0, 0.0, -6.0])
    np.testing.assert_allclose(moved.point("lab").position, [0.0, 0.0, -6.0])
    np.testing.assert_allclose(moved.point("crew").position, [0.0, 0.0, -12.0])
    assert small.bodies[0].masses[1].position[2] == -12.0  # the input is untouched


def test_optimizer_matches_brute_force_grid_in_1d(small):
    bounds = (-20.0, -4.0)
    res = optimize_layout(
        small, "lab", "crew", CREW, movable={"dock": bounds}, maxiter=25, popsize=8
    )
    (mm,) = res.masses
    grid = np.linspace(*bounds, 161)
    values = np.array(
        [
            layout_objective(move_masses(small, [mm], np.array([x])), "lab", "crew", CREW)[0]
            for x in grid
        ]
    )
    assert bounds[0] <= res.optimal[0] <= bounds[1]
    assert res.objective_optimal <= res.objective_initial
    # the optimiser works in the continuum: it must do at least as well as the 0.1 m grid,
    # up to the grid's own resolution (1e-3 relative of the grid minimum)
    assert res.objective_optimal <= values.min() * (1 + 1e-3)
    assert abs(res.optimal[0] - grid[np.argmin(values)]) <= 2 * (grid[1] - grid[0])
    assert res.n_evaluations > 10
    assert res.objective_optimal == pytest.approx(
        layout_objective(res.station, "lab", "crew", CREW)[0], rel=1e-12
    )


def test_optimizer_improves_and_respects_bounds_in_2d(small):
    movable = {"dock": (-20.0, -14.0), "tip": (40.0, 60.0)}
    res = optimize_layout(small, "lab", "crew", CREW, movable=movable, maxiter=15, popsize=6)
    lo = np.array([-20.0, 40.0])
    hi = np.array([-14.0, 60.0])
    assert np.all(res.optimal >= lo - 1e-12) and np.all(res.optimal <= hi + 1e-12)
    assert res.objective_optimal < res.objective_initial
    with pytest.raises(InputError, match="no movable"):
        optimize_layout(small, "lab", "crew", CREW)
    with pytest.raises(InputError, match="not movable"):
        optimize_layout(small, "lab", "crew", CREW, movable=movable, carry={"lab": "hab"})
