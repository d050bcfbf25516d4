"""Lowest modes of a large free-free structure: exact rigid modes plus deflated shift-invert.

Method (the rigid span is never left to the eigensolver):

1. **Rigid modes.**  The candidate rigid-body vectors are M-orthonormalised and rotated to
   diagonalise ``K`` in their span.  A combination ``r`` is rigid when ``K`` annihilates it
   to round-off, judged row by row: ``max_i |K r|_i / (|K| |r|)_i <= tol``.  An exactly
   rigid vector gives ~1e-15 (the rounding of each row's sum); the gravity-gradient
   restraint of a station's rotations gives ~1e-6 on the master-node rows, far above,
   although it is ~1e-12 of ``||K|| ||r||`` (a norm-wise test cannot see it).  Rigid modes
   get ``omega = 0`` exactly.
2. **Elastic modes** come from ARPACK (``scipy.sparse.linalg.eigsh``) in shift-invert
   mode on the M-orthogonal complement of the rigid span: the operator is
   ``P (K - sigma M)^-1 M`` with ``P = I - B B^T M`` (``B`` the rigid basis), started in
   the complement.  ``sigma`` is negative, so ``K - sigma M`` is positive definite and is
   factorised once (SuperLU, symmetric ordering).  Deflating avoids asking Lanczos for a
   six-fold eigenvalue, which it can return with missing copies.
3. **Clean-up.**  The elastic vectors are projected once more, then a Rayleigh-Ritz step
   on their span gives M-orthonormal shapes and eigenvalues consistent with the matrices;
   every residual ``||K phi - w^2 M phi|| / || |K| |phi| ||`` is checked.
4. **Mechanisms.**  An elastic mode with zero energy to round-off
   (``w^2 <= 1000 eps phi^T |K| phi``) that is not a rigid-body candidate is a mechanism
   (a modelling error): :class:`~microg.errors.SolverError` names the count.  Nothing is
   returned silently wrong.

Small problems (``n <= dense_max``, or asking for half the modes or more) use
:func:`microg.dynamics.modes.solve_dense` on the rigid basis found in step 1, then the same checks.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from microg.dynamics.dense import solve_dense
from microg.dynamics.rigid import m_orthonormal, rigid_basis
from microg.errors import InputError, SolverError

__all__ = ["solve_sparse", "DENSE_MAX", "RESIDUAL_TOL", "SHIFT_FRACTION"]

#: problems up to this size are solved densely.  Measured on this project's 2-core machine:
#: solve_dense takes ~10 s at n = 1500 where shift-invert takes 0.1 s, and shift-invert
#: resolves the lowest modes of finely meshed beams better (dense eigenvalue error is
#: ~eps * lambda_max), so the dense path is kept for small models and for "all modes".
DENSE_MAX = 500
#: largest accepted componentwise residual of a returned mode
RESIDUAL_TOL = 1e-8
#: default shift: sigma = -SHIFT_FRACTION * max_i(K_ii / M_ii).  Closer to 0 converges
#: faster (the wanted eigenvalues of the inverted operator spread apart); the rigid span,
#: along which K - sigma M is nearly singular, is projected out, and round-off along it is
#: ~eps / SHIFT_FRACTION ~ 2e-4 of each solve before the projection removes it.
SHIFT_FRACTION = 1e-12
_EPS = np.finfo(float).eps


def solve_sparse(
    mass: sp.spmatrix,
    stiffness: sp.spmatrix,
    rigid_candidates: np.ndarray | None,
    n_modes: int = 30,
    tol: float = 1e-9,
    *,
    sigma: float | None = None,
    dense_max: int = DENSE_MAX,
    labels: tuple[str, ...] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lowest ``n_modes`` modes (rigid ones included) of ``K phi = omega^2 M phi`` (Eq. 2.10).

    Parameters
    ----------
    mass, stiffness : sparse (n, n)
        Symmetric mass (positive definite) and stiffness (positive semi-definite), SI.
    rigid_candidates : ndarray (n, r) or None
        Exact rigid-body vectors; those ``K`` annihilates become exact zero modes.  Without
        them no rigid span is deflated and zero-energy modes are reported as rigid.
    n_modes : int
        Number of modes returned, rigid ones included (at least the rigid count).
    tol : float
        Row-wise relative residual below which ``K`` annihilates a candidate.
    sigma : float, optional
        Shift (rad^2/s^2), negative; default ``-1e-12 max_i(K_ii/M_ii)``.
    dense_max : int
        Largest size solved densely.

    labels : tuple of str, optional
        Coordinate names, to say which coordinates carry no mass.

    Returns
    -------
    omega : ndarray (m,)
        rad/s, ascending, exactly 0.0 for rigid modes.
    phi : ndarray (n, m)
        Mass-normalised shapes, one per column.
    rigid : ndarray (m,) of bool
    """
    M = sp.csr_matrix(mass, dtype=float)
    K = sp.csr_matrix(stiffness, dtype=float)
    n = M.shape[0]
    for name, a in (("mass", M), ("stiffness", K)):
        scale = abs(a).max() if a.nnz else 1.0
        if a.nnz and abs(a - a.T).max() > 1e-10 * scale:
            raise InputError(f"the {name} matrix is not symmetric", fix="check the model assembly")
    if n_modes < 1:
        raise InputError(f"n_modes must be at least 1, got {n_modes}", where="n_modes")
    diag_m = M.diagonal()
    if np.any(diag_m <= 0):
        bad = np.flatnonzero(diag_m <= 0)
        what = (
            f"coordinates {', '.join(labels[i] for i in bad[:6])}"
            + (f" and {bad.size - 6} more" if bad.size > 6 else "")
            + " carry no mass"
            if labels is not None
            else "a coordinate carries no mass"
        )
        raise InputError(
            f"the mass matrix is not positive definite: {what}",
            fix="give every part of the model mass (mass_per_length or point masses) "
            "or remove the massless part",
        )
    B = rigid_basis(M, K, rigid_candidates, tol)
    r = B.shape[1]
    k_el = min(max(n_modes - r, 0), n - r)
    if n <= dense_max or 2 * n_modes >= n:
        omega_d, phi_d, rigid_d = solve_dense(M.toarray(), K.toarray(), B, tol=tol, labels=labels)
        if int(np.count_nonzero(rigid_d)) != r:
            raise SolverError(
                f"dense solver found {np.count_nonzero(rigid_d)} rigid modes, expected {r}"
            )
        X = phi_d[:, ~rigid_d][:, :k_el]
    else:
        X = _elastic_shift_invert(M, K, B, k_el, sigma)
    lam, phi_el = _rayleigh_ritz(M, K, B, X)
    _check(M, K, B, rigid_candidates, lam, phi_el)
    omega = np.concatenate([np.zeros(r), np.sqrt(np.clip(lam, 0.0, None))])
    phi = np.concatenate([B, phi_el], axis=1)
    rigid = np.concatenate([np.ones(r, bool), np.zeros(lam.size, bool)])
    m = max(n_modes, r)
    return omega[:m], phi[:, :m], rigid[:m]


def _elastic_shift_invert(
    M: sp.csr_matrix, K: sp.csr_matrix, B: np.ndarray, k: int, sigma: float | None
) -> np.ndarray:
    n = M.shape[0]
    if k == 0:
        return np.zeros((n, 0))
    if sigma is None:
        sigma = -SHIFT_FRACTION * float(np.max(K.diagonal() / M.diagonal()))
    if not sigma < 0:
        raise InputError(f"the shift must be negative, got {sigma}", where="sigma")
    try:
        lu = spla.splu((K - sigma * M).tocsc(), permc_spec="MMD_AT_PLUS_A")
    except RuntimeError as exc:  # exactly singular: not positive definite
        raise SolverError(f"factorising K - sigma M failed: {exc}") from None
    MB = M @ B

    def project(x: np.ndarray) -> np.ndarray:
        return x - B @ (MB.T @ x)

    def op(y: np.ndarray) -> np.ndarray:
        y = np.asarray(y, float)
        return project(lu.solve(y.reshape(n, -1))).reshape(y.shape)

    opinv = spla.LinearOperator((n, n), matvec=op, matmat=op, dtype=float)
    v0 = project(np.random.default_rng(0).standard_normal(n))
    # a generous Lanczos basis: restarts cost more than the n x ncv storage (measured 3x)
    ncv = min(n - B.shape[1] - 1, max(4 * k, k + 40))
    try:
        _, vecs = spla.eigsh(
            K, k=k, M=M, sigma=sigma, which="LM", OPinv=opinv, v0=v0, ncv=ncv, maxiter=50 * n
        )
    except spla.ArpackNoConvergence as exc:
        raise SolverError(f"ARPACK did not converge: {exc}") from None
    return vecs


def _rayleigh_ritz(
    M: sp.csr_matrix, K: sp.csr_matrix, B: np.ndarray, X: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs of (K, M) on span(X) after removing its rigid components."""
    if X.shape[1] == 0:
        return np.zeros(0), X
    X = X - B @ ((M @ B).T @ X)
    kx = X.T @ (K @ X)
    mx = X.T @ (M @ X)
    lam, v = sla.eigh(0.5 * (kx + kx.T), 0.5 * (mx + mx.T))
    return lam, X @ v


def _check(
    M: sp.csr_matrix,
    K: sp.csr_matrix,
    B: np.ndarray,
    candidates: np.ndarray | None,
    lam: np.ndarray,
    phi: np.ndarray,
) -> None:
    if lam.size == 0:
        return
    absK = abs(K)
    Kphi = K @ phi
    scale = np.sum(np.abs(phi) * (absK @ np.abs(phi)), axis=0)  # phi^T |K| |phi|
    if np.any(lam < -1e3 * _EPS * scale):
        raise SolverError(
            f"negative eigenvalue {lam.min():.3e}: "
            "the stiffness matrix is not positive semi-definite"
        )
    res = np.linalg.norm(Kphi - (M @ phi) * lam, axis=0)
    den = np.maximum(np.linalg.norm(absK @ np.abs(phi), axis=0), np.finfo(float).tiny)
    bad = res / den > RESIDUAL_TOL
    if np.any(bad):
        raise SolverError(
            f"{np.count_nonzero(bad)} modes did not converge "
            f"(largest residual {np.max(res / den):.2e})"
        )
    zero = lam <= 1e3 * _EPS * scale
    if candidates is not None and np.any(zero):
        q = m_orthonormal(M, np.asarray(candidates, float).reshape(M.shape[0], -1))
        in_span = np.sum(((M @ q).T @ phi[:, zero]) ** 2, axis=0) > 0.5
        count = int(np.count_nonzero(~in_span))
        if count:
            raise SolverError(
                f"{count} zero-frequency mode(s) beyond the {B.shape[1]} rigid-body modes: "
                "the structure has a mechanism (an unrestrained joint or part)"
            )
