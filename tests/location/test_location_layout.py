"""Tests of microg.location.layout: movable masses, the objective, the optimiser (conclusion 9)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff
from microg.dynamics.forces import REPORT_F0_N
from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.location.amap import point_peak
from microg.location.layout import (
    MAX_GENERATIONS,
    _RitzLayout,
    layout_objective,
    movable_masses,
    move_masses,
    optimize_layout,
    parse_movable,
    resolve_mass,
)
from microg.models.toml import load_station, loads_station
from microg.structure.discretize import discretize
from microg.units import FT, G0

CREW = CrewPushoff(REPORT_F0_N)
X = np.array([1.0, 0.0, 0.0])

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
kind = "experiment"
[[point]]
name = "crew"
on = "core"
at = ["0 m", "0 m", "-12 m"]
kind = "crew"
"""


@pytest.fixture(scope="module")
def small():
    return loads_station(SMALL, filename="small.toml")


def test_resolve_and_validate_movable(small):
    station = load_station("ioc")
    with pytest.raises(InputError, match="ambiguous"):
        resolve_mass(station, "TDM 2010")
    comp, pm = resolve_mass(station, "boom-y/TDM 2010")
    assert comp.name == "boom-y" and pm.name == "TDM 2010"
    with pytest.raises(InputError, match="known masses") as exc:
        resolve_mass(station, "Piano")
    assert exc.value.where == "movable"
    with pytest.raises(InputError, match="leaves"):
        movable_masses(small, {"tip": (10.0, 70.0)})
    with pytest.raises(InputError, match="does not contain"):
        movable_masses(small, {"dock": (-10.0, -5.0)})
    with pytest.raises(InputError, match="LO < HI") as exc:
        movable_masses(small, {"dock": (-5.0, -25.0)})
    assert exc.value.where == "movable core/dock"
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


def test_parse_movable():
    assert parse_movable("Horizontal lab=-91ft:-5ft") == ("Horizontal lab", "-91ft", "-5ft")
    assert parse_movable("boom+y/TDM 2010 = 10 : 120") == ("boom+y/TDM 2010", "10", "120")
    for bad in ("x", "=1:2", "a=1", "a=1:2:3", "a=:2"):
        with pytest.raises(InputError, match="NAME=LO:HI") as exc:
            parse_movable(bad)
        assert exc.value.where == "movable"


def test_bare_numbers_take_the_models_unit_system(small):
    # SI model: bare numbers are m (the dock sits at -20 m: in ft the range would miss it)
    (mm,) = movable_masses(small, {"dock": ("-20", "-4")}, unit_system="SI")
    assert mm.bounds == (-20.0, -4.0)
    # US model: ft
    ioc = load_station("ioc")
    (mm,) = movable_masses(ioc, {"Horizontal lab": ("-91", "-5")}, unit_system="US")
    assert mm.bounds == pytest.approx((-91 * FT, -5 * FT), rel=1e-15)
    # a unit always means what it says
    (mm,) = movable_masses(small, {"dock": ("-20 m", "-13.12 ft")}, unit_system="SI")
    assert mm.bounds == pytest.approx((-20.0, -13.12 * FT), rel=1e-15)
    # no unit system: a bare number is an error naming the parameter and the fix
    with pytest.raises(InputError, match="no unit") as exc:
        movable_masses(dataclasses.replace(small, unit_system=None), {"dock": ("-20", "-4")})
    assert exc.value.where == "movable core/dock" and 'units = "SI"' in exc.value.fix
    # the station's own unit system (the loader records [station] units) is the default
    st = dataclasses.replace(small, unit_system="SI")
    (mm,) = movable_masses(st, {"dock": ("-20", "-4")})
    assert mm.bounds == (-20.0, -4.0)


def test_fast_path_equals_the_one_entry():
    # the optimiser's incremental assembly against discretize + solve_modes + point_peak on
    # the moved station, for body and beam masses, carried points, random layouts: the two
    # differ by the order of floating-point sums only, 1e-9 relative
    station = load_station("ioc")
    cases = [
        ({"Horizontal lab": (-91 * FT, -5 * FT)}, {}),
        ({"Horizontal lab": (-91 * FT, -5 * FT)}, {"lab": "Horizontal lab"}),
        ({"boom+y/TDM 2010": (10 * FT, 120 * FT), "boom-y/TDM 2010": (10 * FT, 120 * FT)}, {}),
    ]
    rng = np.random.default_rng(7)
    for movable, carry in cases:
        masses = movable_masses(station, movable)
        carry_full = {p: f"main/{m}" for p, m in carry.items()}
        fast = _RitzLayout(station, masses, carry_full, ("lab", "crew"), "xz", None, X)
        lo = np.array([mm.bounds[0] for mm in masses])
        hi = np.array([mm.bounds[1] for mm in masses])
        for x in [
            np.array([mm.value for mm in masses]),
            *(lo + rng.random((3, lo.size)) * (hi - lo)),
        ]:
            s = fast.structure(x)
            got = point_peak(s, solve_modes(s), "lab", "crew", X, CREW)
            moved = move_masses(station, masses, x, carry=carry_full)
            ref = layout_objective(moved, "lab", "crew", plane="xz", zeta=0.0)
            for name in ("total", "elastic", "rigid", "bound"):
                assert got.measure(name) == pytest.approx(ref.measure(name), rel=1e-9)
            big = ref.per_mode_mps2 > 1e-12 * ref.per_mode_mps2.max()
            np.testing.assert_allclose(got.per_mode_mps2[big], ref.per_mode_mps2[big], rtol=1e-9)
            np.testing.assert_allclose(got.omega, ref.omega, rtol=1e-9, atol=1e-12)


def test_optimizer_matches_brute_force_grid_in_1d(small):
    bounds = (-20.0, -4.0)
    res = optimize_layout(
        small, "lab", "crew", CREW, movable={"dock": bounds}, maxiter=25, popsize=8
    )
    (mm,) = res.masses
    grid = np.linspace(*bounds, 161)
    values = np.array(
        [
            layout_objective(
                move_masses(small, [mm], np.array([x])), "lab", "crew", CREW
            ).total_mps2
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
        layout_objective(res.station, "lab", "crew", CREW).total_mps2, rel=1e-12
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


@pytest.mark.parametrize(
    "carry",
    [{}, {"lab": "Horizontal lab", "crew": "Horizontal lab"}],
    ids=["readme", "docs-carry"],
)
def test_readme_example_gain_is_physical(carry):
    # README: microg optimize ioc --preset report --observe lab
    #         --movable "Horizontal lab=-91ft:-5ft"   (docs/locate.md adds both --carry)
    # An earlier version reported "1.162e-05 g -> 2.295e-37 g (x5.06e+31 lower)": the
    # objective left out the rigid-body acceleration.  The total now includes it, and is
    # bounded below independently of the modes: at the jump of the push-off at t1 the
    # acceleration jumps by f0 T_e M^-1 T_a^T (all modes of the model together,
    # Phi Phi^T = M^-1), so the peak over a window holding both sides of the jump is at
    # least half that (M from the moved station's own discretisation, not from the
    # optimiser).
    station = load_station("ioc")
    res = optimize_layout(
        station, "lab", "crew", movable={"Horizontal lab": ("-91 ft", "-5 ft")}, carry=carry
    )
    a, b = res.initial_peak, res.optimal_peak
    assert res.measure == "total"
    assert res.improvement == pytest.approx(a.total_mps2 / b.total_mps2, rel=1e-12)
    s = discretize(res.station, "ritz", plane="xz", n=1)
    m, _ = s.dense()
    te = s.point("lab").translation[0]
    ta = s.point("crew").translation[0]
    floor = 0.5 * CREW.f0 * abs(te @ np.linalg.solve(m, ta))
    assert floor > 0.5 * CREW.f0 / s.total_mass  # at least half the translation f0/M
    assert res.objective_optimal >= floor * (1 - 1e-9)  # the old objective fell far below
    assert 1.0 <= res.improvement <= a.total_mps2 / floor
    # the rigid part is a real share of the total (here, with the crew at the site, the
    # elastic part adds to it at the push-off's end: total >= rigid part at both layouts)
    for p in (a, b):
        assert p.total_mps2 >= p.rigid_mps2 > CREW.f0 / s.total_mass
        assert p.total_mps2 <= p.bound_mps2 * (1 + 1e-12)
    # the elastic part is reported beside it and may fall much more
    assert b.elastic_mps2 < a.elastic_mps2


def test_limits_and_progress(small):
    with pytest.raises(InputError) as exc:
        optimize_layout(small, movable={"dock": (-20.0, -4.0)}, maxiter=MAX_GENERATIONS + 1)
    assert exc.value.where == "maxiter"
    with pytest.raises(InputError) as exc:
        optimize_layout(small, movable={"dock": (-20.0, -4.0)}, popsize=0)
    assert exc.value.where == "popsize"
    with pytest.raises(InputError) as exc:
        optimize_layout(small, movable={"dock": (-20.0, -4.0)}, measure="loudest")
    assert exc.value.where == "measure"
    with pytest.raises(InputError) as exc:
        optimize_layout(small, "nowhere", movable={"dock": (-20.0, -4.0)})
    assert exc.value.where == "experiment"
    seen = []
    res = optimize_layout(
        small,
        movable={"dock": (-20.0, -4.0)},
        maxiter=4,
        popsize=5,
        progress=lambda gen, total: seen.append((gen, total)),
    )
    # defaults: the model's experiment and crew points; one call per generation
    assert (res.experiment, res.crew) == ("lab", "crew")
    assert seen and [g for g, _ in seen] == list(range(1, len(seen) + 1))
    assert all(t == 4 for _, t in seen) and len(seen) <= 4


def test_result_to_dict_and_plot(small):
    from matplotlib.figure import Figure

    res = optimize_layout(small, movable={"dock": (-20.0, -4.0)}, maxiter=3, popsize=5)
    d = res.to_dict()
    assert d["objective_initial_g"] == pytest.approx(res.initial_peak.total_mps2 / G0)
    assert d["optimal"]["rigid_g"] == pytest.approx(res.optimal_peak.rigid_mps2 / G0)
    assert d["improvement"] == pytest.approx(res.improvement)
    assert d["masses"][0]["key"] == "core/dock"
    assert isinstance(res.plot(), Figure)
    # to_xarray: the same coordinates and objective as the result (same numbers, same units)
    ds = res.to_xarray()
    assert all("units" in v.attrs for v in ds.data_vars.values())
    np.testing.assert_array_equal(ds.position_m.sel(layout="initial").values, res.initial)
    np.testing.assert_array_equal(ds.position_m.sel(layout="optimal").values, res.optimal)
    assert ds.lower_m.values.tolist() == [-20.0] and ds.upper_m.values.tolist() == [-4.0]
    assert float(ds.objective_g.sel(layout="optimal")) == res.objective_optimal / G0
