"""Verification of the quasi-steady terms against independent references.

* Gravity gradient: the difference of two-body gravity at the point and at the centre of mass,
  computed in 50-digit decimal arithmetic (no cancellation problem there).
* Rotation: the acceleration of a point of a rigid body from its kinematics, by integrating the
  attitude equation R' = [omega(t)]x R (scipy's DOP853) and differentiating the point's
  inertial position twice by finite differences.
* Drag: a hand calculation at a stated density.
* LVLH hold: the static terms of the Clohessy-Wiltshire (Hill) equations, (0, n^2 y, -3 n^2 z)
  in the station frame (x velocity, y orbit normal, z zenith) to first order in rho / R
  (Clohessy & Wiltshire 1960, J. Aerospace Sci. 27(9):653; SMAD Table 8-2 gives the same terms
  for a free particle, with the opposite sign).
"""

from __future__ import annotations

from decimal import Decimal, localcontext

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microg.environment.quasisteady import (
    AtmosphereInputs,
    Attitude,
    Drag,
    OrbitInputs,
    drag_accel,
    exponential_density,
    gravity_gradient_accel,
    orbit_samples,
    quasi_steady,
    rotation_accel,
)
from microg.models.station import NamedPoint, Orbit, PointMass, RigidBody, Station
from microg.units import G0

MU = 3.986004418e14


def _two_body_difference(rho: np.ndarray, rc: np.ndarray) -> np.ndarray:
    """g(R) - g(R + rho), g(r) = -mu r / |r|^3, in 50-digit decimal arithmetic."""
    with localcontext() as ctx:
        ctx.prec = 50
        mu = Decimal(MU)
        R = [Decimal(float(v)) for v in rc]
        S = [Decimal(float(a)) + Decimal(float(b)) for a, b in zip(rc, rho, strict=True)]
        nr = sum(v * v for v in R).sqrt()
        ns = sum(v * v for v in S).sqrt()
        return np.array(
            [float(-mu * r / nr**3 + mu * s / ns**3) for r, s in zip(R, S, strict=True)]
        )


def test_gravity_gradient_equals_two_body_difference_in_extended_precision():
    rng = np.random.default_rng(12)
    for _ in range(40):
        R = rng.uniform(6.6e6, 4.2e7)
        d = rng.normal(size=3)
        rc = R * d / np.linalg.norm(d)
        rho = rng.normal(size=3) * rng.choice([0.01, 1.0, 30.0, 300.0, 3e4])
        ref = _two_body_difference(rho, rc)
        got = gravity_gradient_accel(rho, rc, MU)
        # the cancellation-free form loses no digits: a few roundings, 1e-14 of the result
        assert np.max(np.abs(got - ref)) <= 1e-14 * np.linalg.norm(ref)
    # the naive float difference of the two gravities would not pass that test: at 1 m from
    # the CM it cancels ~7 of 16 digits (g ~ 8 m/s^2, the tidal part ~ 1e-6 m/s^2)
    rc = np.array([6.778e6, 0.0, 0.0])
    rho = np.array([0.3, -0.7, 1.1])
    naive = -MU * rc / np.linalg.norm(rc) ** 3 + MU * (rc + rho) / np.linalg.norm(rc + rho) ** 3
    ref = _two_body_difference(rho, rc)
    assert np.max(np.abs(naive - ref)) > 1e-12 * np.linalg.norm(ref)


def test_gravity_gradient_of_arrays_equals_the_point_by_point_values():
    # the batched shapes (points against one CM; points against every orbit sample) give the
    # one-point values: the same roundings in another order, 1e-14 of the result
    rng = np.random.default_rng(3)
    rho = rng.normal(size=(7, 3)) * 50.0
    rcs = rng.normal(size=(5, 3))
    rcs *= 6.778e6 / np.linalg.norm(rcs, axis=1)[:, None]
    one = np.array([[gravity_gradient_accel(r, c, MU) for c in rcs] for r in rho])
    tol = 1e-14 * np.max(np.abs(one))
    np.testing.assert_allclose(gravity_gradient_accel(rho, rcs[0], MU), one[:, 0], rtol=0, atol=tol)
    np.testing.assert_allclose(
        gravity_gradient_accel(rho[:, None, :], rcs[None], MU), one, rtol=0, atol=tol
    )


def _skew(w: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


@pytest.mark.parametrize(
    ("omega", "alpha"),
    [
        (np.array([0.0, 1.1e-3, 0.0]), np.zeros(3)),
        (np.array([3e-3, -1e-3, 2e-3]), np.array([1e-6, 4e-6, -2e-6])),
        (np.array([0.02, 0.01, -0.015]), np.array([-3e-4, 1e-4, 2e-4])),
    ],
)
def test_rotation_term_equals_rigid_body_kinematics(omega, alpha):
    """alpha x rho + omega x (omega x rho) against d^2/dt^2 of R(t) rho at t = 0.

    R(t) solves R' = [omega + alpha t]x R, R(0) = I (inertial angular velocity changing at the
    rate alpha), integrated forward and backward; a 5-point stencil differentiates.
    """
    rho = np.array([12.0, -7.5, 31.0])

    def rhs(t, y):
        R = y.reshape(3, 3)
        return (_skew(omega + alpha * t) @ R).ravel()

    h = 1.0
    pts = {}
    for sign in (1, -1):
        sol = solve_ivp(
            rhs,
            (0.0, 2.0 * h * sign),
            np.eye(3).ravel(),
            method="DOP853",
            rtol=1e-13,
            atol=1e-15,
            t_eval=[h * sign, 2.0 * h * sign],
        )
        pts[sign * h] = sol.y[:, 0].reshape(3, 3) @ rho
        pts[sign * 2 * h] = sol.y[:, 1].reshape(3, 3) @ rho
    x0 = rho
    acc = (-pts[2 * h] + 16 * pts[h] - 30 * x0 + 16 * pts[-h] - pts[-2 * h]) / (12 * h * h)
    got = rotation_accel(rho, omega, alpha)
    # stencil error ~ h^4 |omega|^6 |rho| / 90 and integration error ~1e-13 |rho| / h^2:
    # with |omega| <= 0.03 rad/s both are below 1e-7 of |omega|^2 |rho|
    scale = (np.dot(omega, omega) + np.linalg.norm(alpha)) * np.linalg.norm(rho)
    assert np.max(np.abs(got - acc)) <= 1e-7 * scale


def test_drag_against_hand_calculation():
    # stated density 3.0e-12 kg/m^3 (about 400 km), ballistic coefficient 100 kg/m^2, relative
    # speed 7668.56 m/s.  By hand: 0.5 * 3.0e-12 * 7668.56^2 / 100
    # = 0.5 * 3.0e-12 * 5.880680e7 / 100 = 8.82102e-7 m/s^2, against the wind
    v = np.array([7668.56, 0.0, 0.0])
    a = drag_accel(3.0e-12, v, 100.0)
    assert a[0] == pytest.approx(-8.82102e-7, rel=2e-6)  # hand rounding to 6 digits
    assert a[1] == 0.0 and a[2] == 0.0


def _point_station(z_offsets: dict[str, np.ndarray], radius_m: float) -> Station:
    """Two equal masses 20 m apart on the z axis (CM at the origin) and named points."""
    masses = (
        PointMass("a", 1000.0, np.array([0.0, 0.0, 10.0])),
        PointMass("b", 1000.0, np.array([0.0, 0.0, -10.0])),
    )
    body = RigidBody("core", masses)
    pts = tuple(NamedPoint(n, "core", p, kind="experiment") for n, p in z_offsets.items())
    return Station("two-mass", (body,), (), pts, Orbit(radius_m))


def test_full_drag_against_hand_calculation_on_an_equatorial_orbit():
    """Exponential atmosphere at exactly 400 km (equatorial, prograde orbit) by hand.

    Density: the table's base value 3.725e-12 kg/m^3 (Vallado 2013, Table 8-4, 400 km).
    Relative wind: orbital speed sqrt(mu / R) less the co-rotating atmosphere w_E R
    (R = 6778.137 km, w_E = 7.2921151e-5 rad/s): 7668.558 - 494.270 = 7174.289 m/s.
    Ballistic coefficient 100 kg/m^2.  By hand: 0.5 * 3.725e-12 * 7174.289^2 / 100
    = 0.5 * 3.725e-12 * 5.147042e7 / 100 = 9.58637e-7 m/s^2 (0.0977537 micro-g).
    """
    R = 6378137.0 + 400e3
    st = _point_station({"p": np.array([0.0, 0.0, 0.0])}, R)
    res = quasi_steady(
        st,
        orbit=OrbitInputs(radius_m=R, inclination_deg=0.0, n_samples=36),
        drag=Drag(ballistic_coefficient_kg_per_m2=100.0),
        atmosphere=AtmosphereInputs(model="exponential"),
        with_map=False,
    )
    assert res.density_kg_per_m3 == pytest.approx(np.full(36, 3.725e-12), rel=1e-9)
    drag = res.points["cm"].drag_mps2
    # hand value to 6 digits; the drag acts against the flight direction (station -x)
    assert drag[0] == pytest.approx(-9.58637e-7, rel=3e-6)
    assert abs(drag[1]) < 1e-20 and abs(drag[2]) < 1e-20
    assert exponential_density(400e3) == pytest.approx(3.725e-12, rel=1e-15)


def test_lvlh_hold_gives_the_hill_static_terms():
    R = 6778e3
    n = np.sqrt(MU / R**3)
    offsets = {
        "up": np.array([0.0, 0.0, 3.0]),
        "side": np.array([0.0, 8.0, 0.0]),
        "ahead": np.array([25.0, 0.0, 0.0]),
        "mixed": np.array([4.0, -6.0, -2.0]),
    }
    st = _point_station(offsets, R)
    res = quasi_steady(st, orbit=OrbitInputs(radius_m=R), with_map=False)
    for name, rho in offsets.items():
        p = res.points[name]
        hill = np.array([0.0, n * n * rho[1], -3.0 * n * n * rho[2]])
        got = p.gravity_gradient_mps2 + p.rotation_mps2
        # exact two-body terms differ from the linear ones by O(rho/R) relative (~1e-5 here)
        assert np.max(np.abs(got - hill)) <= 1e-5 * n * n * np.linalg.norm(rho)
        # LVLH components: X = x, Y = -y, Z = -z in LVLH hold
        np.testing.assert_allclose(
            p.accel_lvlh_mps2, np.diag([1.0, -1.0, -1.0]) @ p.accel_mps2, rtol=1e-12, atol=1e-22
        )
    # the famous size of the 1 micro-g zone: |z| < 1e-6 g / (3 n^2) ~ 2.6 m at 400 km
    assert G0 * 1e-6 / (3 * n * n) == pytest.approx(2.56, abs=0.01)


def test_inertial_attitude_orbit_average_by_hand():
    """Fixed in inertial space, r_hat turns in the x-z plane: <r r^T> = (e_x e_x + e_z e_z)/2,
    so the orbital average of -n^2 (3 r r^T - I) rho is -n^2 (rho_x / 2, -rho_y, rho_z / 2)."""
    R = 7000e3
    n = np.sqrt(MU / R**3)
    rho = np.array([5.0, -3.0, 9.0])
    st = _point_station({"p": rho}, R)
    res = quasi_steady(
        st,
        orbit=OrbitInputs(radius_m=R, n_samples=64),
        attitude=Attitude("inertial"),
        with_map=False,
    )
    p = res.points["p"]
    hand = -n * n * np.array([rho[0] / 2, -rho[1], rho[2] / 2])
    # 64 uniform samples average a 2/rev term exactly; the exact terms differ by O(rho/R)
    assert np.max(np.abs(p.gravity_gradient_mps2 - hand)) <= 1e-5 * n * n * np.linalg.norm(rho)
    assert np.all(p.rotation_mps2 == 0.0)
    # the peak of the magnitude over the orbit, by hand: |(3 r r^T - I) rho| is largest where
    # r_hat is along the in-plane part of rho: 2 |rho_xz| versus |rho_y|, combined
    inplane = np.hypot(rho[0], rho[2])
    peak_hand = n * n * np.hypot(2 * inplane, rho[1])
    # 64 samples resolve the 2/rev peak to (2 pi / 32)^2 / 8 ~ 5e-3 relative
    assert p.peak_magnitude_mps2 == pytest.approx(peak_hand, rel=6e-3)


def test_rate_attitude_equal_to_the_orbit_rate_is_lvlh_hold():
    R = 6900e3
    n = np.sqrt(MU / R**3)
    st = _point_station({"p": np.array([1.0, 2.0, -7.0])}, R)
    orbit = OrbitInputs(radius_m=R, n_samples=48)
    lv = quasi_steady(st, orbit=orbit, with_map=False)
    rt = quasi_steady(
        st, orbit=orbit, attitude=Attitude("rate", omega_rad_s=[0.0, n, 0.0]), with_map=False
    )
    for key in ("gravity_gradient_mps2", "rotation_mps2", "accel_lvlh_mps2"):
        a, b = getattr(lv.points["p"], key), getattr(rt.points["p"], key)
        # the same motion written two ways: rounding of the rotation matrices only
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a))
    geo = orbit_samples(
        orbit,
        Attitude("rate", omega_rad_s=[0.0, n, 0.0]),
        np.datetime64("2024-03-20T12:00:00", "ms"),
    )
    np.testing.assert_allclose(geo.r_hat, np.tile([0.0, 0.0, 1.0], (48, 1)), atol=1e-12)
