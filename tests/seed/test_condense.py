"""The report's condensed 2x2 path (Eqs. 2.23-2.26) against the full eigenproblem (Eq. 2.9)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from microg.dynamics.dense import solve_dense
from microg.seed.condense import condensed_modes


@given(seed=st.integers(0, 2**31 - 1), k33=st.floats(1.0, 1e3), k44=st.floats(1.0, 1e3))
@settings(max_examples=80, deadline=None)
def test_condensed_equals_full(seed: int, k33: float, k44: float) -> None:
    # reference: the full 4x4 generalized eigenproblem with q1, q2 free (k11 = k22 = 0):
    # eliminating the two zero-stiffness coordinates is exact, so the elastic w^2 agree to
    # rounding (1e-9 relative for well-conditioned random SPD matrices)
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(4, 4))
    m = a @ a.T + 4 * np.eye(4)
    k = np.diag([0.0, 0.0, k33, k44])
    cm = condensed_modes(m, k33, k44)
    omega, phi, rigid = solve_dense(m, k, np.eye(4)[:, :2])
    assert rigid.sum() == 2
    assert np.allclose(cm.omega2, omega[2:] ** 2, rtol=1e-9)
    # Eq. 2.26 vectors satisfy (K - w^2 M) phi = 0 and are M-orthogonal to each other and
    # to the rigid modes
    for j in range(2):
        r = (k - cm.omega2[j] * m) @ cm.phi[:, j]
        assert np.linalg.norm(r) <= 1e-9 * np.linalg.norm(k) * np.linalg.norm(cm.phi[:, j])
    g = cm.phi.T @ m @ cm.phi
    assert abs(g[0, 1]) <= 1e-9 * np.sqrt(g[0, 0] * g[1, 1])
    assert np.allclose(phi[:, :2].T @ m @ cm.phi, 0.0, atol=1e-9 * np.sqrt(g.max()))
    assert np.allclose(cm.modal_mass, np.diag(g), rtol=1e-12)
