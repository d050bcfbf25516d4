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
   ``r`` isostatic support coordinates held (one sparse LU with a symmetric ordering and
   diagonal pivots where they are safe, :func:`_symmetric_lu`; partial pivoting otherwise).
   ARPACK (``scipy.sparse.linalg.eigsh``, mode 3) runs on it in the M inner product; ``M``
   may be singular (massless coordinates: their directions have ``mu = 0``).  An unstable
   mode (a negative stiffness) is a negative ``mu``, found like the others.
3. **Clean-up.**  The eigenvalues are Ritz values *in the inverse form* (ARPACK's, of
   ``G_e M``; not ``X^T K X``, whose rounding ``eps |x|^T |K| |x|`` grows like ``(L/h)^4``
   on fine meshes) and the shapes are made M-orthonormal (Gram-Schmidt, ascending); after
   the block fallback, or with massless coordinates, an inverse-form Rayleigh-Ritz step
   (``X^T M G_e M X``) gives the pairs.  Every residual
   ``||K phi - w^2 M phi|| / || |K| |phi| ||`` is checked.
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
    graded_eigh,
    m_orthonormal_ascending,
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
        if flexibility is not None and _restrained(flexibility):
            # a restrained rigid direction (gravity gradient) puts 1/k ~ 1e7 times the
            # elastic flexibility into G: the elastic modes are then resolved better by the
            # generic graded solve (measured on the IOC: 1.5e-9 against first-order
            # perturbation of the free-free modes, 4e-7 through G)
            flexibility = None
        if flexibility is not None:
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
    lam, X = _elastic_inverse_iteration(M, B, flexibility, k_el)
    return _finish(M, K, B, lam, X, labels, [], check_zero=generic, orthonormalize=False)


def _restrained(g: Operator) -> bool:
    """True when ``g`` is a tree flexibility whose root carries a restraint (``D^+ = 1/k``)."""
    tree = getattr(g, "tree", None)
    k = getattr(tree, "root_stiffness", None)
    return k is not None and bool(np.any(np.asarray(k) != 0.0))


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
    others are solved by :func:`~microg.dynamics.dense.graded_eigh` on the assembled K in the
    M-orthogonal complement of the rigid modes, the modes above the kept ones taken (then made
    M-orthogonal to the kept ones).

    Everything is done in diagonally scaled coordinates ``x = D y``
    (:func:`~microg.dynamics.dense._scaling`: unit mass diagonal), so that the split of the
    mass matrix into massive and massless directions, and the orthogonal complements, do
    not depend on the units of the coordinates: a rotation coordinate carrying a 5 km lever
    arm (``m d^2`` ~ 5e11 kg m^2) beside a beam node's torsional inertia (1e-2 kg m^2) is one
    mass matrix of condition ~10 after scaling, 1e13 before (fuzz reproductions
    ``model-5ccb502b8c``, ``model-5a35beda18``).
    """
    n = M.shape[0]
    d = _scaling(K, M)
    Ms = d[:, None] * M * d[None, :]
    Ms = 0.5 * (Ms + Ms.T)
    Bs = B / d[:, None]
    MB = Ms @ Bs
    P = np.eye(n) - MB @ Bs.T  # P y = y - M B B^T y
    # D^-1 G D^-1 applied to P: the flexibility in the scaled coordinates
    ge = P.T @ (np.asarray(g(P / d[:, None]), float).reshape(n, n) / d[:, None])
    ge = 0.5 * (ge + ge.T)
    w, v = np.linalg.eigh(Ms)
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
        # the higher modes: graded inverse iteration on the assembled K in the M-complement of
        # the rigid modes only (massless coordinates condensed exactly there), keeping those
        # above the modes already kept.  Not in the complement of the kept modes too: those
        # are the exact flexibility's, not the assembled K's, and a complement of vectors that
        # are not K's own leaves the search space off K's invariant subspace by their
        # difference (measured 1.1e-5 on a frequency 100x the first, against a 40-digit
        # solve of the same K; 3e-10 this way: tests/validation/test_solver_invariance.py)
        Ks = d[:, None] * K * d[None, :]
        lam_all, y_all = graded_eigh(0.5 * (Ks + Ks.T), Ms, n_finite, deflate=m_orthonormal(Ms, Bs))
        top = np.argsort(np.abs(lam_all), kind="stable")[ok.size :]
        lam1, y = lam_all[top], y_all[:, top]
        # M-orthogonal to the kept modes (they differ from K's own by the rounding of K)
        y = y - X @ (X.T @ (Ms @ y))
        y = y / np.sqrt(np.einsum("ij,ij->j", y, Ms @ y))
        X = np.concatenate([X, y], axis=1)
        lam0 = np.concatenate([lam0, lam1])
    X = X - Bs @ (MB.T @ X)
    srt = np.argsort(lam0, kind="stable")
    return lam0[srt], d[:, None] * X[:, srt]


def _isostatic_inverse(K: sp.csr_matrix, B: np.ndarray, labels: tuple[str, ...] | None) -> Operator:
    """``y -> G y`` with ``G`` the inverse of ``K`` on all but ``r`` isostatic coordinates."""
    n = K.shape[0]
    sup = support_coordinates(B)
    keep = np.setdiff1d(np.arange(n), sup)
    kk = K[keep][:, keep].tocsc()
    # factored with unit diagonal (D K D, D = diag(K)^-1/2): the pivots, and the test of a
    # mechanism on them, do not depend on the units of the coordinates (a rotation in rad
    # beside a translation in m or in mm: a slender bar's K_rr / K_tt is r^2, 1 m^2 or 1e-6)
    dg = np.asarray(kk.diagonal(), float)
    sc = np.where(dg > 0, 1.0 / np.sqrt(np.where(dg > 0, dg, 1.0)), 1.0)
    S = sp.diags(sc)
    kk = sp.csc_matrix(S @ kk @ S)
    lu = _symmetric_lu(kk)
    if lu is None:
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
        full[keep, 0] = sc * v  # back to the coordinates
        raise InputError(
            "the structure has a mechanism: a motion beyond the rigid-body modes has no "
            f"stiffness, mostly {moving_components(full, labels)} (an unrestrained joint or part)",
            fix="connect that part elastically",
        )

    def apply(y: np.ndarray) -> np.ndarray:
        yy = np.asarray(y, float).reshape(n, -1)
        x = np.zeros_like(yy)
        x[keep] = sc[:, None] * lu.solve(sc[:, None] * yy[keep])
        return x.reshape(np.shape(y))

    return apply


#: backward error of one solve below which the LU of :func:`_symmetric_lu` is kept
SYMMETRIC_LU_TOL = 1e-10


def _symmetric_lu(a: sp.csc_matrix) -> spla.SuperLU | None:
    """SuperLU with the diagonal as pivots (SymmetricMode), or None where it is not safe.

    The stiffness with the isostatic supports held is symmetric and, for a free-free
    structure without negative stiffness, positive definite: the diagonal pivots of its
    minimum-degree ordering are stable (Cholesky's), while SuperLU's default partial
    pivoting leaves that ordering for off-diagonal pivots wherever a row's largest entry is
    not on the diagonal (a shell's massless rotations beside its drilling penalty): on a
    lumped 45 x 45 CQUAD4 plate (12,696 DOFs) 59 million factor entries and 30 s, against
    1.9 million and 0.14 s with diagonal pivots (measured).  Kept only when every pivot is
    well away from zero and one solve has a backward error below :data:`SYMMETRIC_LU_TOL`;
    otherwise (a pivot lost to an indefinite or singular matrix) the caller's partial
    pivoting decides.
    """
    try:
        lu = spla.splu(
            a, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
        )
    except RuntimeError:
        return None
    d = np.abs(lu.U.diagonal())
    if not d.size or not np.all(np.isfinite(d)) or d.min() <= 1e3 * _EPS * d.max():
        return None
    b = np.random.default_rng(2).standard_normal(a.shape[0])
    x = lu.solve(b)
    den = np.linalg.norm(abs(a) @ np.abs(x)) + np.linalg.norm(b)
    if not np.all(np.isfinite(x)) or np.linalg.norm(a @ x - b) > SYMMETRIC_LU_TOL * den:
        return None
    return lu


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


#: ARPACK restarts before the block fallback (:func:`_subspace_iteration`); the models of
#: the test suite and the benchmarks converge in at most 5 (measured)
ARPACK_RESTARTS = 30
#: ARPACK's convergence tolerance on ``|G_e M x - mu x| / |mu|`` (its default is machine
#: epsilon).  An eigenvalue's error is second order in the residual (~1e-24 relative), a
#: shape's first order (1e-12 over its relative gap), and the backward error that
#: :func:`~microg.dynamics.dense._finish` checks against RESIDUAL_TOL = 1e-8 is of the
#: residual's order; it saves about one restart in ten applications of ``G`` (measured on
#: benchmarks/bench_modes.py: 102 -> 89 for 24 modes)
ARPACK_TOL = 1e-12
#: most block iterations of the fallback
SUBSPACE_ITERATIONS = 500
#: relative inverse-form residual at which a block iterate is converged (the caller's
#: Rayleigh-Ritz step and residual check follow).  The floor is the rounding of ``G_e``:
#: 2e-10 on the IOC at 100 elements per beam (measured)
SUBSPACE_TOL = 1e-9


def _subspace_iteration(
    g_e: Callable[[np.ndarray], np.ndarray],
    M: sp.csr_matrix,
    B: np.ndarray,
    MB: np.ndarray,
    k: int,
    p: int,
    start: np.ndarray,
    v0: np.ndarray,
) -> np.ndarray:
    """The ``k`` lowest elastic modes by block inverse (subspace) iteration of ``G_e M``.

    Orthogonal iteration with a Rayleigh-Ritz step in the inverse form (Saad, *Numerical
    Methods for Large Eigenvalue Problems*, Sec. 5.2; Bathe, *Finite Element Procedures*,
    Sec. 11.6): ``Q`` an orthonormal basis, ``Y = G_e M Q``, the pencil
    ``(Q^T M Y, Q^T M Q)`` gives Ritz values ``mu = 1 / lambda`` and vectors ``Q v``, and the
    next basis is the QR factor of ``Y v``.  A block of ``p > k`` vectors converges at the
    rate ``lambda_i / lambda_{p+1}`` whatever the multiplicity of an eigenvalue (which
    single-vector Lanczos resolves only from rounding).  The start is ARPACK's converged
    vectors, ``v0`` and random loads.  Converged when every wanted pair has
    ``|G_e M x - mu x|`` below :data:`SUBSPACE_TOL` of ``|G_e M x|``; the caller's
    Rayleigh-Ritz step and residual check follow.

    Returns
    -------
    ndarray (n, k)
        The wanted Ritz vectors, lowest mode first.
    """
    n = M.shape[0]
    p = int(min(max(p, k + 8), n - B.shape[1]))
    rng = np.random.default_rng(1)
    x = np.concatenate([start, v0.reshape(n, 1), rng.standard_normal((n, p))], axis=1)[:, :p]
    q, _ = np.linalg.qr(g_e(M @ x).reshape(n, -1))
    for _ in range(SUBSPACE_ITERATIONS):
        mq = M @ q
        y = g_e(mq).reshape(n, -1)
        h = mq.T @ y
        mr = q.T @ mq
        try:
            mu, v = sla.eigh(0.5 * (h + h.T), 0.5 * (mr + mr.T), check_finite=False)
        except (sla.LinAlgError, ValueError):
            raise SolverError("block iteration: the iterates lost their mass") from None
        mu, v = mu[::-1], v[:, ::-1]  # largest mu (lowest lambda) first
        yv = y @ v
        res = yv[:, :k] - (q @ v[:, :k]) * mu[None, :k]
        rel = np.linalg.norm(res, axis=0) / np.maximum(np.linalg.norm(yv[:, :k], axis=0), 1e-300)
        if np.all(rel < SUBSPACE_TOL):
            x = q @ v[:, :k]
            return x - B @ (MB.T @ x)
        q, _ = np.linalg.qr(yv)
    raise SolverError(f"neither ARPACK nor block iteration converged for {k} modes")


def _elastic_inverse_iteration(
    M: sp.csr_matrix, B: np.ndarray, g: Operator, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` largest ``mu`` of ``G_e M`` (lowest elastic modes), Rayleigh-Ritz cleaned."""
    n = M.shape[0]
    if k <= 0:
        return np.zeros(0), np.zeros((n, 0))
    MB = M @ B
    # (r, n) C-contiguous copies: each projection is two gemv over contiguous rows (half the
    # time of the (n, r) strided products, measured)
    Bt = np.ascontiguousarray(B.T)
    MBt = np.ascontiguousarray(MB.T)

    def g_e(y: np.ndarray) -> np.ndarray:
        # G_e = P^T G P exactly, input projected too: ARPACK's Lanczos vectors are
        # M-orthogonal to the rigid span only to rounding, and G (the root-clamped tree
        # flexibility, or the isostatic inverse) turns a rounding-sized net force into a
        # large deflection: without it OP is not M-symmetric and the upper Ritz pairs of a
        # fine mesh are lost (IOC at 100 elements per beam, 60 modes: ARPACK's residuals up
        # to 2e4 of the Ritz values, frequencies 4e-4 off)
        yy = np.asarray(y, float)
        x = np.asarray(g(yy - MBt.T @ (Bt @ yy)), float).reshape(yy.shape)
        x -= Bt.T @ (MBt @ x)
        return x

    opinv = spla.LinearOperator((n, n), matvec=g_e, matmat=g_e, dtype=float)
    v0 = g_e(M @ np.random.default_rng(0).standard_normal(n))
    ncv = lanczos_basis_size(k, n)
    massless = bool(np.any(M.diagonal() == 0.0))
    try:
        # mode 3 with sigma = 0: ARPACK iterates OPinv M and returns 1/mu; A is not used
        mu, vecs = spla.eigsh(
            sp.identity(n, format="csr"),
            k=k,
            M=M,
            sigma=0.0,
            which="LM",
            OPinv=opinv,
            v0=v0,
            ncv=ncv,
            maxiter=ARPACK_RESTARTS,
            tol=ARPACK_TOL,
        )
        mu = 1.0 / mu  # eigsh returns sigma + 1/mu = 1/mu
    except spla.ArpackNoConvergence as exc:
        # a degenerate cluster (hundreds of identical appendages: Lanczos finds one vector
        # of a multiple eigenvalue per restart, from rounding alone): a block method
        done = np.asarray(exc.eigenvectors, float).reshape(n, -1)
        vecs = _subspace_iteration(g_e, M, B, MB, k, ncv, done, v0)
        mu = None
    X = vecs - Bt.T @ (MBt @ vecs)
    if mu is None or massless:
        # Rayleigh-Ritz in the inverse form on span(vecs): the block iterates' pairs, and the
        # massless coordinates' purified shapes x = G_e M X v / mu (their static
        # condensation, exact in exact arithmetic already; this removes ARPACK's rounding
        # there), made M-orthonormal again (Gram-Schmidt in ascending order)
        mx_ = M @ X
        mx = X.T @ mx_
        gm = g_e(mx_)
        hx = mx_.T @ gm
        mu, v = sla.eigh(0.5 * (hx + hx.T), 0.5 * (mx + mx.T))
        keep = np.abs(mu) > 1e3 * _EPS * np.max(np.abs(mu))
        mu, v = mu[keep], v[:, keep]
        phi = m_orthonormal_ascending(M, (gm @ v) / mu) if massless else X @ v
    else:
        # ARPACK's Ritz pairs are already the Rayleigh-Ritz pairs of G_e M on its Krylov
        # space (which contains span(vecs)), converged to its tolerance: a second
        # Rayleigh-Ritz step on span(vecs) would cost k more G applications and return the
        # same values; the shapes only need M-orthonormalising (Gram-Schmidt, ascending)
        keep = np.abs(mu) > 1e3 * _EPS * np.max(np.abs(mu))
        order = np.argsort(1.0 / mu[keep], kind="stable")
        mu = mu[keep][order]
        phi = m_orthonormal_ascending(M, X[:, keep][:, order])
    lam = 1.0 / mu
    order = np.argsort(lam, kind="stable")
    return lam[order], phi[:, order]
