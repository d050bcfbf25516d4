"""Two independent routes to the crew push-off response must agree.

microg.dynamics.crew evaluates the report's closed forms (Eqs. 2.17, 2.19); microg.dynamics.response
propagates an exact piecewise-linear modal solution segment by segment.  They share no code.
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff, accel_amax, acceleration_a, displacement_u
from microg.dynamics.response import modal_pwl_response


@pytest.mark.parametrize(
    "crew", [CrewPushoff(111.2, 1.0, 13.0, 14.0), CrewPushoff(50.0, 0.5, 3.0, 4.5)]
)
def test_closed_form_equals_pwl_kernel(crew: CrewPushoff) -> None:
    # both are exact; agreement to 1e-10 of the peak is rounding (arguments w t <= ~200)
    omega = np.array([0.1, 0.4, 1.021, 2.577])
    t_b, f_b = crew.breakpoints()
    # avoid the jump instants themselves: Eq. 2.16 closes its intervals on the right, the
    # kernel takes the value after a jump; both agree everywhere else
    t = np.linspace(0.0, 60.0, 1500)
    res = modal_pwl_response(omega, np.zeros(4), t_b, np.tile(f_b, (4, 1)), t)
    u = displacement_u(omega[:, None], t, crew) * crew.f0 / (omega[:, None] ** 3 * crew.t1)
    a = acceleration_a(omega[:, None], t, crew) * crew.f0 / (omega[:, None] * crew.t1)
    assert np.max(np.abs(res.eta - u)) <= 1e-10 * np.max(np.abs(u))
    assert np.max(np.abs(res.eta_ddot - a)) <= 1e-10 * np.max(np.abs(a))


@pytest.mark.parametrize("omega", [0.1, 0.4, 1.021, 2.577, 9.3])
def test_exact_peak_equals_closed_form_amax(omega: float) -> None:
    """peak_response (refined between coarse samples) against [A]max of Eq. 3.1 (crest test).

    accel_amax finds the largest |A| on each interval of Eq. 2.16 from the sinusoid's crests;
    peak_response shares no code with it.  The window runs one full period past t14, so the
    free vibration's crest (which accel_amax counts) is inside it.
    """
    from microg.dynamics.forces import crew_pushoff
    from microg.dynamics.response import peak_response

    crew = CrewPushoff(111.2, 1.0, 13.0, 14.0)
    t_end = crew.t14 + 2 * np.pi / omega * 1.01
    grid = np.linspace(0.0, t_end, 41)  # coarse: 0.4-16 s steps, the crests fall between
    force = crew_pushoff(crew.f0, crew.t1, crew.t13, crew.t14)
    unit = {"p": np.eye(3)[:, :1]}  # the point moves along x with the one modal coordinate
    p = peak_response(np.array([omega]), 0.0, np.ones((1, 1)), unit, [(force, np.ones(1))], grid)
    expected = crew.f0 / (omega * crew.t1) * accel_amax(omega, crew)
    # both exact; the refinement stops within rtol = 1e-9, the closed form is exact to rounding
    assert p["p"].peak_accel_mps2 == pytest.approx(expected, rel=2e-9)
    assert p["p"].upper_bound_mps2 >= expected * (1 - 1e-12)
