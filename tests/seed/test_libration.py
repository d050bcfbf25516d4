"""Librational motion (Eqs. 2.29, 2.30, 3.2) against closed forms and the exact history."""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff, acceleration_a
from microg.seed.libration import libration_accel_impulse, libration_frequencies, orbital_rate


def test_orbital_rate_and_frequency() -> None:
    # Eq. 2.29-2.30: sqrt(mu/R^3); with I_z << I_x ~ I_y the libration is ~sqrt(3) w0
    w0 = orbital_rate(6.87e6)
    assert w0 == pytest.approx(np.sqrt(3.986004418e14 / 6.87e6**3), rel=1e-15)
    w = libration_frequencies(w0, np.array([1.0, 1.0, 0.0]))
    assert w["x"] == pytest.approx(np.sqrt(3) * w0, rel=1e-15)
    assert w["y"] == pytest.approx(np.sqrt(3) * w0, rel=1e-15)


def test_impulse_estimate_is_eq_3_2() -> None:
    # Eq. 3.2: a = Z^2 f0 w t1 / (2 I); the exact history's libration amplitude between the
    # push and the landing equals it to O(w t1) (here 2e-3).  The exact history: the torque
    # Z f(t) has Eq. 2.16's shape, so theta'' = Z/I f0/(w t1) A(t) (microg.dynamics.crew)
    crew = CrewPushoff(111.2, 1.0, 1.0e4, 1.0e4 + 1.0)  # landing far away
    w, inertia, z = 1.9e-3, 3.0e9, 7.1
    est = libration_accel_impulse(z, z, crew.f0, crew.t1, w, inertia)
    assert est == pytest.approx(z * z * crew.f0 * w * crew.t1 / (2 * inertia), rel=1e-15)
    t = np.linspace(crew.t1 + 1e-6, 0.99e4, 200001)  # after the push: free libration
    accel = z * z / inertia * crew.f0 / (w * crew.t1) * acceleration_a(w, t, crew)
    assert np.max(np.abs(accel)) == pytest.approx(est, rel=2e-3)
