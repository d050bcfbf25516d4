"""Tests of microg.dynamics.eigsparse: exact rigid modes plus inverse iteration on G_e M."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from microg.dynamics.eigsparse import solve_sparse
from microg.dynamics.rigid import rigid_basis
from microg.errors import InputError


def chain(n: int, k: float = 1.0e4, m: float = 2.0, cut: int | None = None):
    """Free-free chain of n equal masses and n-1 equal springs (spring ``cut`` removed)."""
    kk = np.full(n - 1, k)
    if cut is not None:
        kk[cut] = 0.0
    main = np.zeros(n)
    main[:-1] += kk
    main[1:] += kk
    K = sp.diags([main, -kk, -kk], [0, -1, 1], format="csr")
    M = sp.diags(np.full(n, m), format="csr")
    return M, K


def chain_exact(n: int, k: float = 1.0e4, m: float = 2.0) -> np.ndarray:
    # free-free chain: omega_j^2 = 4 k / m sin^2(j pi / (2 n)), j = 0..n-1 (e.g. Meirovitch,
    # Fundamentals of Vibrations, Sec. 8.6; the eigenvectors are cos((i + 1/2) j pi / n))
    j = np.arange(n)
    return np.sqrt(4 * k / m) * np.sin(j * np.pi / (2 * n))


@pytest.mark.parametrize("dense_max", [0, 10**6], ids=["shift-invert", "dense"])
def test_free_free_chain_matches_closed_form(dense_max):
    n = 1500 if dense_max == 0 else 300
    M, K = chain(n)
    omega, phi, rigid = solve_sparse(M, K, np.ones((n, 1)), n_modes=12, dense_max=dense_max)
    assert rigid.tolist() == [True] + [False] * 11
    assert omega[0] == 0.0  # exact zero, not round-off
    exact = chain_exact(n)[:12]
    # lowest elastic eigenvalue ~ 4k/m (pi/2n)^2 is 2.2e-6 of the largest (4k/m): the
    # eigenvalue round-off eps * lambda_max / lambda_1 ~ 1e-10 bounds the agreement
    np.testing.assert_allclose(omega[1:], exact[1:], rtol=1e-9)
    np.testing.assert_allclose(phi.T @ (M @ phi), np.eye(12), atol=1e-10)  # mass-normalised
    # rigid mode is the uniform translation, normalised: 1/sqrt(total mass)
    np.testing.assert_allclose(np.abs(phi[:, 0]), 1 / np.sqrt(2.0 * n), rtol=1e-12)
    # residuals of the elastic modes: K phi = omega^2 M phi to the round-off of K phi, the
    # backward error ||r|| / || |K| |phi| || of each mode (its rounding floor is ~eps n)
    res = np.linalg.norm(K @ phi - (M @ phi) * omega**2, axis=0)
    assert np.all(res <= 1e-9 * np.linalg.norm(abs(K) @ np.abs(phi), axis=0))


@pytest.mark.parametrize("dense_max", [0, 10**6], ids=["shift-invert", "dense"])
def test_mechanism_is_refused_naming_the_part(dense_max):
    n = 2200 if dense_max == 0 else 300
    M, K = chain(n, cut=100)  # two free pieces: one zero mode more than the rigid vector
    # a mechanism is a modelling error (an unrestrained part): one line, the moving part named
    with pytest.raises(InputError, match="mechanism.*coordinates"):
        solve_sparse(M, K, np.ones((n, 1)), n_modes=6, dense_max=dense_max)


def test_candidate_not_annihilated_is_not_rigid():
    n = 2500
    M, K = chain(n)
    K = (K + sp.diags(np.r_[1e-3, np.zeros(n - 1)])).tocsr()  # weak ground spring at node 0
    x = np.ones((n, 1))
    assert rigid_basis(M, K, x).shape[1] == 0
    omega, _, rigid = solve_sparse(M, K, x, n_modes=4)
    assert not rigid.any()
    # Rayleigh quotient of the uniform vector, k_g / (n m), to first order in the tiny spring
    np.testing.assert_allclose(omega[0] ** 2, 1e-3 / (2.0 * n), rtol=1e-3)


def test_rigid_basis_detects_only_annihilated_combinations():
    n = 2100
    M, K = chain(n)
    # candidates: a translation (rigid) and a linear ramp (strained); their span has one rigid
    c = np.column_stack([np.ones(n), np.arange(n, dtype=float)])
    b = rigid_basis(M, K, c)
    assert b.shape[1] == 1
    np.testing.assert_allclose(b.T @ (M @ b), [[1.0]], rtol=1e-12)
    np.testing.assert_allclose(b[:, 0] / b[0, 0], 1.0, rtol=1e-10)


def test_bad_input():
    M, K = chain(10)
    with pytest.raises(ValueError, match="not symmetric"):
        solve_sparse(M, sp.triu(K).tocsr(), None)
    with pytest.raises(InputError, match="non-finite"):
        solve_sparse(M, (K * np.nan).tocsr(), None)
    with pytest.raises(InputError, match="n_modes"):
        solve_sparse(M, K, None, n_modes=0)


@pytest.mark.parametrize("dense_max", [0, 10**6], ids=["inverse-iteration", "dense"])
def test_massless_coordinates_are_condensed_not_refused(dense_max):
    # every other mass of a free-free chain is zero: the massless coordinates are condensed
    # statically. Reference: the chain of the massive ones with two springs in series
    # (k/2 each), whose closed form is chain_exact with k -> k/2
    n = 2 * 1200 + 1 if dense_max == 0 else 2 * 150 + 1
    M, K = chain(n)
    M = sp.diags(np.where(np.arange(n) % 2 == 0, 2.0, 0.0), format="csr")
    sol = solve_sparse(M, K, np.ones((n, 1)), n_modes=8, dense_max=dense_max)
    exact = chain_exact((n + 1) // 2, k=0.5e4)[:8]
    assert sol.rigid.sum() == 1 and sol.omega[0] == 0.0
    # eigenvalue round-off eps lambda_max / lambda_1 ~ 1e-10 (as in the chain test above)
    np.testing.assert_allclose(sol.omega[1:], exact[1:], rtol=1e-9)
    phi = sol.phi
    # the massless coordinates hold the static response: the mean of their neighbours
    inner = np.arange(1, n - 1, 2)
    np.testing.assert_allclose(phi[inner], 0.5 * (phi[inner - 1] + phi[inner + 1]), atol=1e-10)
    np.testing.assert_allclose(phi.T @ (M @ phi), np.eye(8), atol=1e-10)


def test_block_fallback_matches_arpack_and_a_dense_solve(monkeypatch):
    # ARPACK stops after ARPACK_RESTARTS; the block subspace iteration then takes over
    # (a degenerate cluster of identical appendages is where ARPACK stalls:
    # tests/validation/test_solver_reproductions.py::test_500_stub_beams_on_one_body).
    # Forced here on the IOC at 100 elements per beam (1,842 DOF, tree flexibility) by an
    # ARPACK that converges nothing.  References: ARPACK's own modes of the same model, and
    # the dense graded solve of the same M, K (independent).  The two solvers agree to
    # 3.3e-8 (measured; both leave residuals at the rounding level eps |K| |phi| of the
    # axial penalties, ~5e-9 of lambda M phi), hence 1e-7 against dense; the fallback and
    # ARPACK share the same final Rayleigh-Ritz step, hence 1e-10 between them
    import scipy.sparse.linalg as spla

    import microg
    from microg.dynamics.dense import solve_dense
    from microg.dynamics.modes import solve_modes
    from microg.structure.discretize import discretize

    s = discretize(microg.load_station("ioc"), "fem", n=100)
    arpack = solve_modes(s, 30)
    calls = []

    def stalled(*args, **kwargs):
        calls.append(kwargs["maxiter"])
        raise spla.ArpackNoConvergence("stalled", np.zeros(0), np.zeros((s.n_dof, 0)))

    monkeypatch.setattr(spla, "eigsh", stalled)
    block = solve_modes(s, 30)
    assert calls  # the fallback was taken
    cand = np.column_stack(list(s.rigid_body.values()))
    dense = solve_dense(s.mass.toarray(), s.stiffness.toarray(), cand)
    assert block.n_rigid == arpack.n_rigid == 6
    np.testing.assert_allclose(block.omega[6:], arpack.omega[6:], rtol=1e-10)
    np.testing.assert_allclose(block.omega[6:], dense.omega[6:30], rtol=1e-7)
    m = s.mass.toarray()
    np.testing.assert_allclose(block.phi.T @ m @ block.phi, np.eye(30), atol=1e-9)


def test_symmetric_lu_is_kept_only_where_diagonal_pivots_are_safe():
    # diagonal pivots of a positive definite matrix (Cholesky's) solve it; an indefinite
    # matrix whose diagonal pivots lose it (a tiny pivot: growth 1e18) is left to partial
    # pivoting (None)
    from microg.dynamics.eigsparse import _symmetric_lu

    rng = np.random.default_rng(3)
    a = rng.standard_normal((40, 40))
    spd = sp.csc_matrix(a @ a.T + 40 * np.eye(40))
    lu = _symmetric_lu(spd)
    assert lu is not None
    b = rng.standard_normal(40)
    np.testing.assert_allclose(spd @ lu.solve(b), b, rtol=0, atol=1e-12 * np.abs(b).max())
    tiny = sp.csc_matrix(np.kron(np.eye(20), [[1e-18, 1.0], [1.0, 1e-18]]))
    assert _symmetric_lu(tiny) is None


def test_singular_mass_pencil_solves_with_exact_rigid_modes_and_unit_modal_masses():
    # a free-free spring chain whose every other coordinate is massless (a lumped model's
    # rotations kept as coordinates): the finite modes are those of the chain with the
    # massless coordinates condensed (springs in series), solved densely as the truth
    n = 801  # > DENSE_MAX: inverse iteration
    k = np.linspace(1.0, 3.0, n - 1)
    K = sp.diags([np.r_[k, 0] + np.r_[0, k], -k, -k], [0, 1, -1], format="csr")
    m = np.where(np.arange(n) % 2 == 0, 1.0 + 0.5 * np.sin(np.arange(n)), 0.0)
    M = sp.diags(m, format="csr")
    sol = solve_sparse(M, K, np.ones((n, 1)), n_modes=12)
    assert sol.rigid.sum() == 1 and sol.omega[0] == 0.0
    mass_idx = np.flatnonzero(m > 0)
    kc = 1.0 / (1.0 / k[0::2] + 1.0 / k[1::2])  # two springs in series between masses
    Kc = np.diag(np.r_[kc, 0] + np.r_[0, kc]) - np.diag(kc, 1) - np.diag(kc, -1)
    w2 = np.linalg.eigvalsh(Kc / np.sqrt(np.outer(m[mass_idx], m[mass_idx])))
    np.testing.assert_allclose(sol.omega[1:12] ** 2, w2[1:12], rtol=1e-9)
    phi = sol.phi
    np.testing.assert_allclose(phi.T @ (M @ phi), np.eye(12), atol=1e-10)
    # the massless coordinates hold their static solution: K_oo x_o = -K_oa x_a
    res = (K @ phi - (M @ phi) * sol.omega**2)[m == 0]
    assert np.abs(res).max() <= 1e-9 * np.abs(K @ np.abs(phi)).max()
