"""Librational motion (Eqs. 2.27-2.35) against numerical integration."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microg.dynamics.crew import CrewPushoff
from microg.seed.libration import (
    libration_accel_impulse,
    libration_frequencies,
    libration_response,
    orbital_rate,
)


def test_orbital_rate_and_frequency() -> None:
    # Eq. 2.29-2.30: sqrt(mu/R^3); with I_z << I_x ~ I_y the libration is ~sqrt(3) w0
    w0 = orbital_rate(6.87e6)
    assert w0 == pytest.approx(np.sqrt(3.986004418e14 / 6.87e6**3), rel=1e-15)
    w = libration_frequencies(w0, np.array([1.0, 1.0, 0.0]))
    assert w["x"] == pytest.approx(np.sqrt(3) * w0, rel=1e-15)
    assert w["y"] == pytest.approx(np.sqrt(3) * w0, rel=1e-15)


def test_response_matches_integration() -> None:
    # reference: solve_ivp (DOP853, rtol 1e-12) of I theta'' + I w^2 theta = z_a f(t),
    # integrated between the force's breakpoints; closed form to 1e-8 of the peak
    crew = CrewPushoff(111.2, 1.0, 13.0, 14.0)
    w, inertia, z_a, z_e = 1.9e-3, 3.0e9, 7.1, 7.1
    t = np.linspace(0.0, 30.0, 601)
    res = libration_response(crew, w, inertia, z_e, z_a, t)

    def branch(tt: float, mid: float) -> float:
        if mid <= crew.t1:
            return crew.f0 / crew.t1 * tt
        if crew.t13 < mid <= crew.t14:
            return crew.f0 / (crew.t14 - crew.t13) * (tt - crew.t14)
        return 0.0

    y = np.zeros(2)
    theta = np.empty_like(t)
    edges = [0.0, crew.t1, crew.t13, crew.t14, t[-1]]
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        mid = 0.5 * (a + b)

        def rhs(tt, yy, mid=mid):
            return [yy[1], z_a * branch(tt, mid) / inertia - w**2 * yy[0]]

        sol = solve_ivp(rhs, (a, b), y, rtol=1e-12, atol=1e-20, method="DOP853", dense_output=True)
        sel = (t >= a) & (t <= b)
        theta[sel] = sol.sol(t[sel])[0]
        y = sol.y[:, -1]
    assert np.max(np.abs(res.theta - theta)) <= 1e-8 * np.max(np.abs(theta))


def test_impulse_estimate_is_eq_3_2() -> None:
    # Eq. 3.2: a = Z^2 f0 w t1 / (2 I); the exact history's libration amplitude between the
    # push and the landing equals it to O(w t1) (here 2e-3)
    crew = CrewPushoff(111.2, 1.0, 1.0e4, 1.0e4 + 1.0)  # landing far away
    w, inertia, z = 1.9e-3, 3.0e9, 7.1
    est = libration_accel_impulse(z, z, crew.f0, crew.t1, w, inertia)
    assert est == pytest.approx(z * z * crew.f0 * w * crew.t1 / (2 * inertia), rel=1e-15)
    t = np.linspace(crew.t1 + 1e-6, 0.99e4, 200001)  # after the push: free libration
    res = libration_response(crew, w, inertia, z, z, t)
    assert np.max(np.abs(res.accel)) == pytest.approx(est, rel=2e-3)
