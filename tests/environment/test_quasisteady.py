"""Unit tests of microg.environment.quasisteady: kernels, inputs, orbit geometry, results.

References are stated per test: closed forms (geodetic from its forward formula, the
exponential table), pymsis called directly, brute-force maxima, and the model's own mass
properties.  The verification against two-body gravity, rigid-body kinematics and hand drag is
in tests/validation/test_quasisteady_verification.py.
"""

from __future__ import annotations

import builtins
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.figure import Figure

from microg.environment import quasisteady as qs
from microg.environment.quasisteady import (
    EXPONENTIAL_ATMOSPHERE,
    AtmosphereInputs,
    Attitude,
    Drag,
    OrbitInputs,
    exponential_density,
    geodetic,
    gravity_gradient_accel,
    peak_magnitude,
    quasi_steady,
    quasi_steady_requirement,
)
from microg.errors import InputError
from microg.models.toml import load_station
from microg.units import G0


@pytest.fixture(scope="module")
def ioc():
    return load_station("ioc")


def test_requirement_is_one_micro_g_with_its_source():
    req = quasi_steady_requirement()
    # the data file's "1 ug" (NASA-CR-205357), read through the unit parser
    assert req.limit_g == pytest.approx(1e-6, rel=1e-15)
    assert "NASA-CR-205357" in req.source and req.verified
    assert "internal payload" in req.applies_to


def test_exponential_density_matches_vallado_table():
    tab = EXPONENTIAL_ATMOSPHERE
    # at every base altitude the density is the tabulated nominal value
    np.testing.assert_allclose(exponential_density(tab[:, 0] * 1e3), tab[:, 1], rtol=1e-14)
    # between bases: rho_0 exp(-(h - h_0)/H) by hand at 425 km (band 400 km, H = 58.515 km)
    assert exponential_density(425e3) == pytest.approx(3.725e-12 * math.exp(-25 / 58.515))


def test_geodetic_inverts_the_forward_formula():
    # forward: X = (N + h) cos(lat) cos(lon), Y = (N + h) cos(lat) sin(lon),
    # Z = (N (1 - e^2) + h) sin(lat), N = a / sqrt(1 - e^2 sin^2 lat)  (WGS84)
    a, f = qs.EARTH_EQUATORIAL_RADIUS_M, qs.EARTH_FLATTENING
    e2 = f * (2 - f)
    rng = np.random.default_rng(4)
    lat = rng.uniform(-90, 90, 200)
    lon = rng.uniform(-180, 180, 200)
    h = rng.uniform(1e5, 2e6, 200)
    phi, lam = np.radians(lat), np.radians(lon)
    N = a / np.sqrt(1 - e2 * np.sin(phi) ** 2)
    xyz = np.column_stack(
        [
            (N + h) * np.cos(phi) * np.cos(lam),
            (N + h) * np.cos(phi) * np.sin(lam),
            (N * (1 - e2) + h) * np.sin(phi),
        ]
    )
    glat, glon, galt = geodetic(xyz)
    # Bowring with refinements: sub-millimetre and 1e-9 degree at these altitudes
    np.testing.assert_allclose(glat, lat, atol=1e-9)
    np.testing.assert_allclose(glon, lon, atol=1e-9)
    np.testing.assert_allclose(galt, h, atol=1e-3)


def test_linear_gradient_is_the_first_order_of_the_exact_one():
    rc = np.array([1.0, 2.0, -0.5])
    rc = 6.9e6 * rc / np.linalg.norm(rc)
    n = math.sqrt(3.986004418e14 / 6.9e6**3)
    for size in (1.0, 50.0, 500.0):
        rho = size * np.array([0.3, -0.8, 0.52])
        exact = gravity_gradient_accel(rho, rc, 3.986004418e14)
        r_hat = rc / 6.9e6
        lin = -(n**2) * (3.0 * r_hat * (r_hat @ rho) - rho)  # -n^2 (3 r (r . rho) - rho)
        # the second-order term is bounded by (15/2) (rho/R) of the first-order magnitude scale
        assert np.linalg.norm(exact - lin) <= 7.5 * size / 6.9e6 * 3 * n * n * size


def test_msis_density_equals_pymsis_called_directly():
    from pymsis import msis

    from microg.environment.drag import density

    orbit = OrbitInputs(radius_m=6778e3, n_samples=12)
    atm = AtmosphereInputs(date_utc="2015-06-01T03:00:00", f107_sfu=110.0, f107a_sfu=120.0, ap=8)
    samples = qs.orbit_samples(orbit, Attitude(), atm.date64())
    rho, model, reason = density(samples, atm)
    assert model.startswith("NRLMSIS") and reason is None
    k = 5
    ref = msis.calculate(
        samples.date[k : k + 1].astype("datetime64[s]"),
        samples.longitude_deg[k : k + 1],
        samples.latitude_deg[k : k + 1],
        samples.altitude_m[k : k + 1] / 1e3,
        f107s=[110.0],
        f107as=[120.0],
        aps=[[8.0] * 7],
        version=2.1,
    )
    # the same call, one sample: identical to rounding of the inputs
    assert rho[k] == pytest.approx(float(np.ravel(ref)[0]), rel=1e-12)


def test_missing_pymsis_falls_back_to_the_exponential_model(monkeypatch, ioc):
    real_import = builtins.__import__

    def no_pymsis(name, *args, **kwargs):
        if name == "pymsis" or name.startswith("pymsis."):
            raise ImportError("no pymsis here")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pymsis)
    res = quasi_steady(ioc, drag=Drag(ballistic_coefficient_kg_per_m2=100.0), with_map=False)
    assert res.atmosphere_model.startswith("exponential")
    assert any("exponential model is used because pymsis" in w for w in res.warnings)
    d = res.to_dict()["atmosphere"]
    assert d["requested"] == "msis" and "pymsis" in d["fallback_reason"]
    # the densities are the table's at the sampled altitudes
    np.testing.assert_allclose(
        res.density_kg_per_m3, exponential_density(res.samples.altitude_m), rtol=1e-14
    )


def test_no_drag_input_fails_where_no_drag_can_bring_the_peak_under_the_limit(ioc):
    # the lab's gravity gradient and rotation alone give 1.41 micro-g (LVLH hold, the lab off
    # the CM across the flight direction): drag along the flight direction only adds in
    # quadrature there, so the verdict is a fail without a drag input
    res = quasi_steady(ioc, with_map=False)
    lab = res.points["lab"]
    assert np.all(lab.drag_mps2 == 0.0)
    assert lab.peak_lower_bound_mps2 == pytest.approx(1.4103e-6 * G0, rel=1e-4)
    assert lab.complies is False and res.complies is False
    assert any("whatever the drag" in w and "lab" in w for w in res.warnings)
    assert res.to_dict()["points"]["lab"]["peak_lower_bound_g"] == pytest.approx(1.4103e-6, 1e-4)
    # the bound holds for every drag (each peak with drag is at least the bound; 1e-12:
    # rounding) and is reached in the limit of no drag
    for b in (30.0, 300.0, 3e4):
        with_drag = quasi_steady(
            ioc, drag=Drag(ballistic_coefficient_kg_per_m2=b), with_map=False
        ).points
        for name, p in res.points.items():
            assert with_drag[name].peak_magnitude_mps2 >= p.peak_lower_bound_mps2 * (1 - 1e-12)
            assert with_drag[name].complies is not True or p.complies is not False


def test_no_drag_input_withholds_the_verdict_where_drag_could_decide(ioc):
    # at the CM the drag-free terms vanish: the bound is 0 and the verdict stays open
    res = quasi_steady(ioc, points=[], with_map=False)
    assert res.points["cm"].peak_lower_bound_mps2 == 0.0
    assert res.complies is None and res.points["cm"].complies is None
    assert any("verdict is withheld" in w for w in res.warnings)


def test_peak_lower_bound_against_a_search_over_the_drag_size():
    # reference: for each sample, min over a fine grid of drag sizes k >= 0 of |q + k u|,
    # then the largest over the samples; the grid's step (1e-4 of |q|) bounds the error to
    # ~1e-8 relative (a quadratic minimum)
    rng = np.random.default_rng(3)
    q = rng.standard_normal((4, 7, 3))
    u = rng.standard_normal((7, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    k = np.linspace(0.0, 10.0, 100_001)
    ref = np.array(
        [
            max(np.min(np.linalg.norm(q[p, s] + k[:, None] * u[s], axis=1)) for s in range(7))
            for p in range(4)
        ]
    )
    np.testing.assert_allclose(qs.peak_lower_bound(q, u), ref, rtol=1e-7)


def test_center_of_mass_and_parts(ioc):
    res = quasi_steady(ioc, drag=Drag(area_m2=900.0, cd=2.2), with_map=False)
    mass, cm, _ = ioc.mass_properties()
    # the model's own mass properties (sum of masses and beams)
    np.testing.assert_allclose(res.center_of_mass_m, cm, rtol=0, atol=1e-12)
    assert res.mass_kg == pytest.approx(mass)
    for p in res.points.values():
        # the total is the sum of its parts (orbital averages are linear)
        parts = p.gravity_gradient_mps2 + p.rotation_mps2 + p.drag_mps2
        np.testing.assert_allclose(p.accel_mps2, parts, rtol=1e-12, atol=1e-22)
        assert p.magnitude_mps2 == pytest.approx(np.linalg.norm(p.accel_mps2))
        assert p.peak_magnitude_mps2 >= p.magnitude_mps2 * (1 - 1e-12)
        assert p.complies == (p.peak_magnitude_mps2 <= 1e-6 * G0)
    # at the CM the tidal and rotational terms vanish: only drag remains
    cmp = res.points["cm"]
    assert np.linalg.norm(cmp.gravity_gradient_mps2 + cmp.rotation_mps2) < 1e-20
    # the beta from the area: m / (Cd A)
    assert res.drag.beta(mass) == pytest.approx(mass / (2.2 * 900.0))
    # the verdict covers the payload (experiment) points: the lab at 3.8 m below the CM
    # sees 3 n^2 |z| ~ 1.4 micro-g, so the station does not comply
    assert res.complies is False and res.points["lab"].complies is False


def test_structure_input_uses_its_center_of_mass(ioc):
    from microg.structure.discretize import discretize

    s = discretize(ioc)
    res = quasi_steady(s, orbit=OrbitInputs(radius_m=ioc.orbit.radius), with_map=True)
    # the frame model's own centre of mass and mass (the same model, another bookkeeping)
    np.testing.assert_allclose(res.center_of_mass_m, s.center_of_mass, atol=1e-12)
    assert set(s.points) <= set(res.points)
    assert res.map is not None and res.map.positions_m.shape[0] == len(s.samples)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    n_points=st.integers(1, 50),
    n_samples=st.integers(1, 40),
    planar=st.booleans(),
)
def test_peak_magnitude_equals_brute_force(seed, n_points, n_samples, planar):
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n_points, 3)) * 1e-6
    d = rng.normal(size=(n_samples, 3)) * 1e-7
    if planar:
        d[:, 2] = 0.0  # drag in LVLH hold lies in a plane: the degenerate hull path
    ref = np.sqrt(np.max(np.sum((q[:, None, :] + d[None]) ** 2, axis=-1), axis=1))
    # the hull keeps every candidate maximiser; rounding of |q|^2 + 2 q.d + |d|^2 only
    np.testing.assert_allclose(peak_magnitude(q, d), ref, rtol=1e-10, atol=1e-22)


def test_peak_magnitude_over_many_blocks_equals_brute_force():
    # 5,003 points against 200 samples on a sphere (every one a hull vertex, so blocks of 655
    # points): eight blocks, the last one ragged
    rng = np.random.default_rng(7)
    q = rng.normal(size=(5003, 3)) * 1e-6
    d = rng.normal(size=(200, 3))
    d *= 1e-7 / np.linalg.norm(d, axis=1)[:, None]
    ref = np.sqrt(np.max(np.sum((q[:, None, :] + d[None]) ** 2, axis=-1), axis=1))
    # as above: rounding of |q|^2 + 2 q.d + |d|^2 only
    np.testing.assert_allclose(peak_magnitude(q, d), ref, rtol=1e-10, atol=1e-22)


@pytest.mark.parametrize(
    "bad", [np.zeros(4), np.zeros((2, 2)), [[0.0, 0.0, np.nan]], "x", [[1.0, 2.0, "a"]]]
)
def test_peak_at_refuses_bad_positions_naming_them(ioc, bad):
    res = quasi_steady(ioc, drag=Drag(ballistic_coefficient_kg_per_m2=100.0), with_map=False)
    with pytest.raises(InputError) as err:
        res.peak_at(bad)
    assert "positions_m" in str(err.value) and "p x 3" in str(err.value)
    # one point as (3,) is a row
    assert res.peak_at(res.center_of_mass_m).shape == (1,)


def test_map_and_zone(ioc):
    res = quasi_steady(ioc, drag=Drag(ballistic_coefficient_kg_per_m2=100.0))
    m = res.map
    assert m is not None and m.positions_m.shape[1] == 3
    # the map's peaks at the named points' positions equal the points' own (exact) peaks
    pk = res.peak_at(np.array([p.position_m for p in res.points.values()]))
    ref = np.array([p.peak_magnitude_mps2 for p in res.points.values()])
    np.testing.assert_allclose(pk, ref, rtol=1e-12)
    # the ideal zone half-widths L/n^2 and L/(3 n^2), reduced by the largest drag d
    n = res.mean_motion_rad_s
    d = np.max(np.linalg.norm(res.drag_samples_mps2, axis=1))
    L = 1e-6 * G0
    assert m.zone_half_width_m["z"] == pytest.approx(math.sqrt(L * L - d * d) / (3 * n * n))
    # points along z within that half-width of the CM comply, just outside do not
    cm = res.center_of_mass_m
    hz = m.zone_half_width_m["z"]
    inside = res.peak_at(cm + np.array([[0, 0, 0.98 * hz], [0, 0, -0.98 * hz]]))
    outside = res.peak_at(cm + np.array([[0, 0, 1.05 * hz], [0, 0, -1.05 * hz]]))
    assert np.all(inside <= L) and np.all(outside > L)
    text = m.to_csv()
    assert text.splitlines()[0].startswith("label,x [m]") and len(text.splitlines()) == 1 + len(
        m.labels
    )


def test_plot_and_xarray(ioc):
    res = quasi_steady(ioc, drag=Drag(ballistic_coefficient_kg_per_m2=100.0))
    fig = res.plot()
    assert isinstance(fig, Figure) and len(fig.axes) >= 2
    ds = res.to_xarray()
    assert ds["accel"].dims == ("point", "axis") and ds["accel"].attrs["units"] == "m/s^2"
    np.testing.assert_allclose(ds["accel"].sel(point="lab").values, res.points["lab"].accel_mps2)


@pytest.mark.parametrize(
    ("make", "where"),
    [
        (lambda: OrbitInputs(radius_m=1e6), "radius"),
        (lambda: OrbitInputs(radius_m=6378137.0 + 50e3), "radius"),
        (lambda: OrbitInputs(radius_m=float("nan")), "radius"),
        (lambda: OrbitInputs(radius_m=7e6, inclination_deg=200.0), "inclination"),
        (lambda: OrbitInputs(radius_m=7e6, n_samples=2), "samples"),
        (lambda: Drag(area_m2=-3.0), "area"),
        (lambda: Drag(area_m2=3.0, cd=-2.2), "cd"),
        (lambda: Drag(cd=2.2), "cd"),
        (lambda: Drag(ballistic_coefficient_kg_per_m2=0.0), "ballistic_coefficient"),
        (lambda: Drag(ballistic_coefficient_kg_per_m2=10.0, area_m2=1.0), "ballistic_coefficient"),
        (lambda: Attitude("tumbling"), "attitude"),
        (lambda: Attitude("rate"), "omega"),
        (lambda: Attitude("lvlh", omega_rad_s=[0, 1, 0]), "omega"),
        (
            lambda: Attitude("lvlh", lvlh_from_station=np.diag([1.0, 1.0, -1.0])),
            "lvlh_from_station",
        ),
        (lambda: AtmosphereInputs(model="jacchia"), "atmosphere"),
        (lambda: AtmosphereInputs(date_utc="yesterday"), "date"),
        (lambda: AtmosphereInputs(f107_sfu=-1.0), "f107"),
        (lambda: AtmosphereInputs(ap=1e4), "ap"),
    ],
)
def test_bad_input_names_the_parameter(make, where):
    with pytest.raises(InputError) as info:
        make()
    assert info.value.where == where


def test_unknown_point(ioc):
    with pytest.raises(InputError) as info:
        quasi_steady(ioc, points=["galley"], with_map=False)
    assert info.value.where == "points" and "lab" in str(info.value)


@pytest.mark.parametrize(
    "attitude",
    [
        Attitude("inertial"),
        Attitude("rate", omega_rad_s=[1e-4, 2e-3, -5e-4], alpha_rad_per_s2=[0, 1e-8, 0]),
    ],
    ids=["inertial", "rate"],
)
def test_map_with_varying_gradient_equals_the_points(ioc, attitude):
    # the map's scalar-field form of |a|^2 against the points' (P, S, 3) evaluation
    res = quasi_steady(ioc, drag=Drag(ballistic_coefficient_kg_per_m2=80.0), attitude=attitude)
    pk = res.peak_at(np.array([p.position_m for p in res.points.values()]))
    ref = np.array([p.peak_magnitude_mps2 for p in res.points.values()])
    # two exact forms of the same sum: rounding only (terms ~ n^2 |rho| add without cancelling)
    np.testing.assert_allclose(pk, ref, rtol=1e-11)


def test_map_csv_quotes_labels_with_commas():
    # a label with a comma ("main/Horizontal lab, SAA0207 and SAA0201") gave its row an extra
    # column; reference: the csv module's reader gives back the six fields and the label
    labels = ("main/Horizontal lab, SAA0207 and SAA0201", 'say "x"', "plain")
    pos = np.array([[1.0, 2.0, 3.0], [0.0, 0.0, 0.0], [-1.5, 0.25, 1e-3]])
    peak = np.array([1.2, 0.5, 2.0]) * 1e-6 * G0
    m = qs.QuasiSteadyMap(pos, labels, peak, 1e-6 * G0, peak <= 1e-6 * G0, None)
    import csv
    import io

    rows = list(csv.reader(io.StringIO(m.to_csv())))
    assert rows[0] == ["label", "x [m]", "y [m]", "z [m]", "peak [ug]", "within_limit"]
    assert [r[0] for r in rows[1:]] == list(labels)
    assert all(len(r) == 6 for r in rows)
    assert rows[1][1:] == ["1", "2", "3", "1.2", "false"]
