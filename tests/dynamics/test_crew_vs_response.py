"""Two independent routes to the crew push-off response must agree.

microg.dynamics.crew evaluates the report's closed forms (Eqs. 2.17, 2.19); microg.dynamics.response
propagates an exact piecewise-linear modal solution segment by segment.  They share no code.
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff, acceleration_a, displacement_u
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
