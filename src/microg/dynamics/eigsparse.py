"""Lowest modes of a large free-free structure: exact rigid modes plus inverse iteration.

Method (the rigid span is never left to the eigensolver):

1. **Rigid modes.**  Given exactly (a frame tree knows which rigid motions its stiffness
   annihilates), or the candidate vectors ``K`` annihilates row by row
   (:func:`~microg.dynamics.rigid.rigid_basis`: an exactly rigid vector scores ~1e-15, the
   gravity-gradient restraint of a station's rotations ~1e-6 on the master-node rows).  Rigid
   modes get ``omega = 0`` exactly.
2. **A generalized inverse, no shift.**  The elastic modes are the largest eigenvalues
   ``mu = 1/lambda`` of ``G_e M`` with ``G_e = P^T G P``, ``P = I - M B B^T`` (``B`` the
   M-orthonormal rigid basis) and ``G`` any generalized inverse of ``K`` (``K G K = K``):
   Geradin & Rixen, *Mechanical Vibrations*, Sec. 4.3.  ``G`` is the exact tree flexibility
   of a frame model (:class:`~microg.structure.fem.FrameTree`: O(n), no factorisation, no
   round-off growth with the mesh) or, for any other structure, the inverse of ``K`` with
   ``r`` isostatic support coordinates held (one sparse LU with a symmetric ordering).
   ARPACK (``scipy.sparse.linalg.eigsh``, mode 3) runs on it in the M inner product; ``M``
   may be singular (massless coordinates: their directions have ``mu = 0``).  An unstable
   mode (a negative stiffness) is a negative ``mu``, found like the others.
3. **Clean-up.**  A Rayleigh-Ritz step *in the inverse form* (``X^T M G_e M X``, not
   ``X^T K X``, whose rounding ``eps |x|^T |K| |x|`` grows like ``(L/h)^4`` on fine meshes)
   gives M-orthonormal shapes; every residual ``||K phi - w^2 M phi|| / || |K| |phi| ||`` is
   checked.
4. **Mechanisms.**  With the generic inverse, a mode whose eigenvalue is within the rounding
   bound ``eps |phi|^T |K| |phi|`` of its own energy is a zero-energy motion: a mechanism,
   refused naming the components it moves.  A frame tree has none by construction (every
   element has positive stiffnesses; loose bodies are refused when the model is built).

Small problems (``n <= dense_max``, or asking for half the modes or more) use
:func:`microg.dynamics.dense.solve_dense` on the rigid basis found in step 1.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from microg.dynamics.dense import (
    ACCEPT_REL,
    MASSLESS_TOL,
    RESIDUAL_TOL,
    Eigensolution,
    _finish,
    _scaling,
    blas_threads,
    graded_eigh,
    moving_components,
    solve_dense,
)
from microg.dynamics.rigid import m_orthonormal, rigid_basis, support_coordinates
from microg.errors import InputError, SolverError

__all__ = ["solve_sparse", "DENSE_MAX", "RESIDUAL_TOL", "lanczos_basis_size"]

#: problems up to this size are solved densely.  Measured on this project's 2-core machine:
#: solve_dense takes ~10 s at n = 1500 where inverse iteration takes 0.1 s, so the dense
#: path is kept for small models and for "all modes".
DENSE_MAX = 500
_EPS = float(np.finfo(float).eps)

Operator = Callable[[np.ndarray], np.ndarray]


def lanczos_basis_size(k: int, n: int) -> int:
    """ARPACK's Lanczos basis for ``k`` wanted modes of an order-``n`` operator.

    ``2k + 1`` (ARPACK's advice, and scipy's default) with at least ``k + 24``: the
    orthogonalisation costs ``n ncv^2`` per restart, so the former ``4k`` rule cost 3.4x at
    300 modes (benchmarks/bench_modes.py measures it), while a basis below ``k + 20`` restarts
    often for clustered frequencies.
    """
    return int(min(n - 1, max(2 * k + 1, k + 24)))


def solve_sparse(
    mass: sp.spmatrix,
    stiffness: sp.spmatrix,
    rigid_candidates: np.ndarray | None,
    n_modes: int = 30,
    tol: float = 1e-9,
    *,
    dense_max: int = DENSE_MAX,
    labels: tuple[str, ...] | None = None,
    flexibility: Operator | None = None,
    rigid_vectors: np.ndarray | None = None,
) -> Eigensolution:
    """Lowest ``n_modes`` modes (rigid ones included) of ``K phi = omega^2 M phi`` (Eq. 2.10).

    Parameters
    ----------
    mass, stiffness : sparse (n, n)
        Symmetric mass (positive semi-definite) and stiffness, SI.
    rigid_candidates : ndarray (n, r) or None
        Exact rigid-body vectors; those ``K`` annihilates become exact zero modes.
    n_modes : int
        Number of modes returned, rigid ones included (at least the rigid count).
    tol : float
        Row-wise relative residual below which ``K`` annihilates a candidate.
    dense_max : int
        Largest size solved densely.
    labels : tuple of str, optional
        Coordinate names, to name the components of a mechanism.
    flexibility : callable, optional
        ``y -> G y`` for a generalized inverse ``G`` of ``K`` (``K G K = K``) whose null
        space is that of ``rigid_vectors`` (the exact tree flexibility of a frame model).
    rigid_vectors : ndarray (n, r), optional
        The exact null space of ``K`` (overrides ``rigid_candidates``; no test).

    Returns
    -------
    Eigensolution
    """
    M = sp.csr_matrix(mass, dtype=float)
    K = sp.csr_matrix(stiffness, dtype=float)
    n = M.shape[0]
    for name, a in (("mass", M), ("stiffness", K)):
        if a.nnz and not np.all(np.isfinite(a.data)):
            raise InputError(f"the {name} matrix has non-finite entries", where=name)
        scale = abs(a).max() if a.nnz else 1.0
        if a.nnz and abs(a - a.T).max() > 1e-10 * scale:
            raise InputError(f"the {name} matrix is not symmetric", fix="check the model assembly")
    if n_modes < 1:
        raise InputError(f"n_modes must be at least 1, got {n_modes}", where="n_modes")
    dense = n <= dense_max or 2 * n_modes >= n
    if rigid_vectors is not None:
        B = m_orthonormal(M, np.asarray(rigid_vectors, float).reshape(n, -1))
    else:
        B = rigid_basis(M, K, rigid_candidates, tol)
    r = B.shape[1]
    if flexibility is not None and not _consistent(M, K, B, flexibility):
        flexibility = None  # stale (matrices replaced after the model was built)
    if dense:
        if flexibility is not None:
            with blas_threads(n):
                lam, X = _dense_with_flexibility(M.toarray(), K.toarray(), B, flexibility)
            sol = _finish(M, K, B, lam, X, labels, [], check_zero=False)
        else:
            sol = solve_dense(M.toarray(), K.toarray(), labels=labels, rigid_vectors=B)
        return sol.truncate(max(n_modes, r))
    k_el = min(max(n_modes - r, 0), n - r - 1)
    generic = flexibility is None
    if generic:
        flexibility = _isostatic_inverse(K, B, labels)
    assert flexibility is not None
    with blas_threads(lanczos_basis_size(k_el, n)):
        lam, X = _elastic_inverse_iteration(M, B, flexibility, k_el)
    return _finish(M, K, B, lam, X, labels, [], check_zero=generic)


def _consistent(M: sp.csr_matrix, K: sp.csr_matrix, B: np.ndarray, g: Operator) -> bool:
    """``K G_e K y = K y`` on one random vector: ``G`` belongs to this ``K``."""
    y = np.random.default_rng(1).standard_normal(M.shape[0])
    ky = K @ y
    x = g(ky - M @ (B @ (B.T @ ky)))
    x = x - B @ (B.T @ (M @ x))
    return bool(np.linalg.norm(K @ x - ky) <= 1e-6 * np.linalg.norm(abs(K) @ np.abs(y)))


def _dense_with_flexibility(
    M: np.ndarray, K: np.ndarray, B: np.ndarray, g: Operator
) -> tuple[np.ndarray, np.ndarray]:
    """All elastic modes of a small model whose exact flexibility ``G`` is known.

    The lowest modes come from ``G_e M`` (no assembled ``K``: exact whatever the stiffness
    spread, e.g. an axially rigid beam's penalty 1e6 times its bending stiffness), densely:
    with ``M = F F^T``, ``S = F^T G_e F`` and ``x = G_e F v / mu``; those resolved to
    :data:`~microg.dynamics.dense.ACCEPT_REL` (``lambda <= 1e4 lambda_min``) are kept.  The
    others are solved by :func:`~microg.dynamics.dense.graded_eigh` in the M-orthogonal
    complement of everything kept.
    """
    n = M.shape[0]
    MB = M @ B
    P = np.eye(n) - MB @ B.T  # P y = y - M B B^T y
    ge = P.T @ np.asarray(g(P), float).reshape(n, n)
    ge = 0.5 * (ge + ge.T)
    w, v = np.linalg.eigh(0.5 * (M + M.T))
    pos = w > MASSLESS_TOL * max(w.max(), 0.0)
    F = v[:, pos] * np.sqrt(w[pos])
    n_finite = int(np.count_nonzero(pos)) - B.shape[1]
    S = F.T @ ge @ F
    mu, V = np.linalg.eigh(0.5 * (S + S.T))
    order = np.argsort(-np.abs(mu))
    mu, V = mu[order], V[:, order]
    mu_max = float(np.abs(mu[0])) if mu.size else 0.0
    good = np.abs(mu) > 1e6 * _EPS * mu_max
    lam = np.where(good, 1.0 / np.where(good, mu, 1.0), np.inf)
    bound = np.where(good, _EPS * mu_max / np.where(good, mu, 1.0) ** 2, np.inf)
    ok = np.flatnonzero(good & (bound <= ACCEPT_REL * np.abs(lam)))[: max(n_finite, 0)]
    X = (ge @ (F @ V[:, ok])) / mu[ok]
    lam0 = lam[ok]
    if ok.size < n_finite:
        # the higher modes: graded inverse iteration on the assembled K, in the complement
        Q = sla.null_space(np.concatenate([MB, M @ X], axis=1).T)
        quad = getattr(g, "quadratic", None)  # the tree's strain form: no cancellation
        kc = quad(Q) if callable(quad) else Q.T @ K @ Q
        mc = Q.T @ M @ Q
        d = _scaling(kc, mc)
        lam1, y = graded_eigh(d[:, None] * kc * d, d[:, None] * mc * d, n_finite - ok.size)
        X = np.concatenate([X, Q @ (d[:, None] * y)], axis=1)
        lam0 = np.concatenate([lam0, lam1])
    X = X - B @ (MB.T @ X)
    srt = np.argsort(lam0, kind="stable")
    return lam0[srt], X[:, srt]


def _isostatic_inverse(K: sp.csr_matrix, B: np.ndarray, labels: tuple[str, ...] | None) -> Operator:
    """``y -> G y`` with ``G`` the inverse of ``K`` on all but ``r`` isostatic coordinates."""
    n = K.shape[0]
    sup = support_coordinates(B)
    keep = np.setdiff1d(np.arange(n), sup)
    kk = K[keep][:, keep].tocsc()
    try:
        lu = spla.splu(kk, permc_spec="MMD_AT_PLUS_A")
    except RuntimeError:  # exactly singular
        lu = None
    if lu is not None:
        d = np.abs(lu.U.diagonal())
        if d.size and d.min() <= 1e3 * _EPS * d.max():
            lu = None
    if lu is None:
        # a zero-stiffness motion beyond the rigid ones: find and name it (small pivots)
        v = _near_null(kk)
        full = np.zeros((n, 1))
        full[keep, 0] = v
        raise InputError(
            "the structure has a mechanism: a motion beyond the rigid-body modes has no "
            f"stiffness, mostly {moving_components(full, labels)} (an unrestrained joint or part)",
            fix="connect that part elastically",
        )

    def apply(y: np.ndarray) -> np.ndarray:
        yy = np.asarray(y, float).reshape(n, -1)
        x = np.zeros_like(yy)
        x[keep] = lu.solve(yy[keep])
        return x.reshape(np.shape(y))

    return apply


def _near_null(a: sp.csc_matrix) -> np.ndarray:
    """A vector ``a`` nearly annihilates (a few inverse iterations with a tiny shift)."""
    n = a.shape[0]
    scale = float(abs(a).max()) or 1.0
    lu = spla.splu((a + 1e-10 * scale * sp.identity(n, format="csc")).tocsc())
    v = np.random.default_rng(0).standard_normal(n)
    for _ in range(4):
        v = lu.solve(v)
        v /= np.linalg.norm(v)
    return v


def _elastic_inverse_iteration(
    M: sp.csr_matrix, B: np.ndarray, g: Operator, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` largest ``mu`` of ``G_e M`` (lowest elastic modes), Rayleigh-Ritz cleaned."""
    n = M.shape[0]
    if k <= 0:
        return np.zeros(0), np.zeros((n, 0))
    MB = M @ B

    def g_e(y: np.ndarray) -> np.ndarray:
        yy = np.asarray(y, float).reshape(n, -1)
        x = g(yy - MB @ (B.T @ yy))
        x = x.reshape(n, -1)
        return x - B @ (MB.T @ x)

    MBt = np.ascontiguousarray(MB.T)

    def op(y: np.ndarray) -> np.ndarray:
        # ARPACK applies OPinv to M x with x M-orthogonal to the rigid span: the load is
        # self-equilibrated already (B^T M x = 0), so only the output is projected
        x = np.asarray(g(np.asarray(y, float).reshape(n, -1)), float).reshape(n, -1)
        x -= B @ (MBt @ x)
        return x.reshape(np.shape(y))

    opinv = spla.LinearOperator((n, n), matvec=op, matmat=op, dtype=float)
    v0 = g_e(M @ np.random.default_rng(0).standard_normal(n)).ravel()
    ncv = lanczos_basis_size(k, n)
    try:
        # mode 3 with sigma = 0: ARPACK iterates OPinv M and returns 1/mu; A is not used
        _, vecs = spla.eigsh(
            sp.identity(n, format="csr"),
            k=k,
            M=M,
            sigma=0.0,
            which="LM",
            OPinv=opinv,
            v0=v0,
            ncv=ncv,
            maxiter=max(300, 20 * n // max(ncv, 1)),
        )
    except spla.ArpackNoConvergence as exc:
        raise SolverError(f"ARPACK did not converge: {exc}") from None
    # Rayleigh-Ritz in the inverse form on span(vecs): accurate for the lowest modes
    X = vecs - B @ (MB.T @ vecs)
    mx = X.T @ (M @ X)
    gm = g_e(M @ X)
    hx = (M @ X).T @ gm
    mu, v = sla.eigh(0.5 * (hx + hx.T), 0.5 * (mx + mx.T))
    keep = np.abs(mu) > 1e3 * _EPS * np.max(np.abs(mu))
    mu, v = mu[keep], v[:, keep]
    # purified shapes x = G_e M X v / mu: the static condensation of massless coordinates
    phi = (gm @ v) / mu
    norm = np.sqrt(np.einsum("ij,ij->j", phi, M @ phi))
    phi = phi / norm
    lam = 1.0 / mu
    order = np.argsort(lam, kind="stable")
    return lam[order], phi[:, order]
