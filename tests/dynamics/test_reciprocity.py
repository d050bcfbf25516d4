"""Maxwell-Betti reciprocity of the whole chain: model -> structure -> modes -> response.

The acceleration at point B in direction d_B due to a force history at point A in direction
d_A equals the acceleration at A along d_A due to the same force at B along d_B (symmetric
M and K, classical modal damping). Checked on the IOC model with both discretisations.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from microg.dynamics.forces import crew_pushoff
from microg.dynamics.modes import solve_modes
from microg.dynamics.response import generalized_force_vector, response_at_points
from microg.models.toml import load_station
from microg.structure.fem import build_fem
from microg.structure.ritz import build_ritz

T_OUT = np.linspace(0.0, 30.0, 301)


@pytest.fixture(scope="module", params=["ritz3d", "fem"])
def setup(request):
    st_ = load_station("ioc")
    if request.param == "fem":
        s = build_fem(st_, elements_per_beam=6)
        m = solve_modes(s, 40)
    else:
        s = build_ritz(st_, None, 3, gravity_gradient=False)
        m = solve_modes(s)
    return s, m


def _accel(s, m, src: str, d_src: np.ndarray, dst: str, d_dst: np.ndarray, zeta: float):
    b = generalized_force_vector(s.point(src).translation, d_src)
    r = response_at_points(
        m.omega,
        np.where(m.rigid, 0.0, zeta),
        m.phi,
        {dst: s.point(dst).translation},
        crew_pushoff(),
        b,
        T_OUT,
    )
    return d_dst @ r[dst].acceleration


_unit = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
    lambda v: np.linalg.norm(v) > 0.1
)


@given(
    a=st.sampled_from(["lab", "crew", "vertical-lab", "keel-tip", "boom-tip"]),
    b=st.sampled_from(["lab", "vertical-lab", "keel-tip", "boom-tip"]),
    da=_unit,
    db=_unit,
    zeta=st.sampled_from([0.0, 0.01, 0.05]),
)
@settings(max_examples=25, deadline=None)
def test_reciprocity(setup, a, b, da, db, zeta) -> None:
    # both sides are sums of the same modal terms phi_j(B).d_B phi_j(A).d_A eta_j(t);
    # agreement to 1e-10 of the peak is rounding
    s, m = setup
    da = np.asarray(da) / np.linalg.norm(da)
    db = np.asarray(db) / np.linalg.norm(db)
    ab = _accel(s, m, a, da, b, db, zeta)
    ba = _accel(s, m, b, db, a, da, zeta)
    scale = max(np.max(np.abs(ab)), 1e-300)
    assert np.max(np.abs(ab - ba)) <= 1e-10 * scale
