"""Dense free-free modal solution of small structures (Eq. 2.10), rigid modes exact.

Method (:func:`solve_dense`), each step a documented choice:

1. **Rigid modes.**  The rigid-body vectors ``K`` annihilates (:func:`~microg.dynamics.rigid.
   rigid_basis`, row by row) are the exact zero modes: ``omega = 0``, ``B^T M B = I``.
2. **Isostatic support instead of a dense complement.**  ``r`` coordinates where the rigid
   motions are best determined (pivoted QR of ``B^T``) are held; with ``E`` the injection of
   the others, every elastic shape is ``x = (I - B B^T M) E y``, and the elastic pencil is
   ``(K_s, M_s) = (E^T K E, E^T M E - W W^T)``, ``W = E^T M B`` (Geradin & Rixen,
   *Mechanical Vibrations*, 3rd ed., Sec. 4.3: the pseudo-inverse of a free structure).  No
   coordinates are mixed in ``K_s``: a gravity-gradient restraint 1e-12 of the elastic
   stiffness, or a stiffness contrast, is not swamped by the rounding of a rotation.
3. **Graded inverse iteration, bottom up** (:func:`graded_eigh`).  ``eigh(K, M)`` has an
   absolute eigenvalue error ``eps lambda_max``: it loses a libration mode 1e-18 of the
   largest eigenvalue (1-5 % on a 16-function Ritz model whose mass matrix has
   condition 1e16).  The inverse form ``M_s y = mu (K_s + s M_s) y`` has error
   ``eps mu_max`` in ``mu = 1 / (lambda + s)``, i.e. a relative error
   ``eps (lambda + s)^2 / ((lambda_min + s) lambda)``: exact for the lowest modes.  Modes
   resolved to :data:`ACCEPT_REL` are kept, the rest are solved again in their complement
   with a shift at the bottom of what is left, until every mode with mass is found.  A
   singular ``M`` (massless coordinates) needs nothing special: its directions have
   ``mu = 0`` (infinite frequency) and are never kept, and the modes that are kept are
   exactly the statically condensed ones, defined on all coordinates.
4. **Classification.**  With ``e_j = eps |phi_j|^T |K| |phi_j|`` the rounding bound of a
   mode's own energy: ``lambda_j < -e_j`` is an unstable mode (a negative stiffness, e.g. an
   unstable gravity-gradient attitude: reported with its growth rate, not an error);
   ``|lambda_j| <= e_j`` is a zero-energy motion that is not a rigid-body vector: a
   mechanism, refused (:class:`~microg.errors.InputError`) naming the components it moves.
   A massless part without stiffness (which has no finite frequency at all) is refused the
   same way.
5. **Checks.**  Every backward error ``||K phi - lambda M phi|| / (|| |K| |phi| || +
   |lambda| || |M| |phi| ||)`` is at most :data:`RESIDUAL_TOL`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg.dynamics.rigid import RIGID_TOL, m_orthonormal, rigid_basis, support_coordinates
from microg.errors import InputError, SolverError

__all__ = [
    "ACCEPT_REL",
    "Eigensolution",
    "MASSLESS_TOL",
    "RESIDUAL_TOL",
    "graded_eigh",
    "m_orthonormal_ascending",
    "moving_components",
    "solve_dense",
]

_EPS = float(np.finfo(float).eps)
#: largest accepted relative error bound of an eigenvalue in :func:`graded_eigh` (1e4 eps)
ACCEPT_REL = 1e4 * _EPS
#: a direction of the diagonally scaled mass matrix with less than this fraction of its
#: largest eigenvalue carries no mass (an infinite frequency; frequencies change by <= 1e-12)
MASSLESS_TOL = 1e-12
#: largest accepted componentwise residual of a returned mode
RESIDUAL_TOL = 1e-8
#: largest spread of the coordinates' K_ii / M_ii that double precision resolves to
#: RESIDUAL_TOL (:func:`_refuse_spread`)
MAX_SPREAD = 1e12
#: a support choice leaving a mass diagonal ``M_ii - W_i^2`` below this fraction of ``M_ii``
#: (six digits lost to cancellation) is replaced by the mass-weighted one (:func:`_supports`)
SUPPORT_CANCEL = 1e-6
#: most levels of the graded solve (each resolves at least four decades of the spectrum)
MAX_LEVELS = 24


@dataclass(frozen=True)
class Eigensolution:
    """Modes of a free-free pencil ``K phi = lambda M phi``, rigid ones first.

    Attributes
    ----------
    omega : ndarray (m,)
        Circular frequencies, rad/s: exactly 0.0 for rigid-body modes, 0.0 for unstable ones.
    phi : ndarray (n, m)
        Shapes, one per column, mass-normalised (``phi.T @ M @ phi = I``).
    rigid : ndarray (m,) of bool
        The exact rigid-body modes.
    unstable : ndarray (m,) of bool
        Modes with a negative eigenvalue (a negative stiffness: an unstable attitude).
    growth_rate : ndarray (m,)
        ``sqrt(-lambda)`` of the unstable modes (the imaginary frequency), rad/s; else 0.
    notes : tuple of str
        What a reader of the result must know (unstable modes, massless coordinates).

    Iterating gives ``(omega, phi, rigid)`` for the callers that unpack three arrays; it is
    refused when a mode is unstable, since the three arrays cannot say so.
    """

    omega: np.ndarray
    phi: np.ndarray
    rigid: np.ndarray
    unstable: np.ndarray
    growth_rate: np.ndarray
    notes: tuple[str, ...] = field(default=())

    @property
    def eigenvalue(self) -> np.ndarray:
        """``lambda = omega^2`` (negative ``-growth_rate^2`` for unstable modes), rad^2/s^2."""
        return self.omega**2 - self.growth_rate**2

    def truncate(self, m: int) -> Eigensolution:
        """The first ``m`` modes."""
        return Eigensolution(
            self.omega[:m],
            self.phi[:, :m],
            self.rigid[:m],
            self.unstable[:m],
            self.growth_rate[:m],
            self.notes,
        )

    def __iter__(self) -> Iterator[np.ndarray]:
        if np.any(self.unstable):
            raise InputError(
                "the structure has an unstable mode (negative stiffness): " + "; ".join(self.notes),
                fix="use the modal solution's unstable and growth_rate (solve_modes)",
            )
        return iter((self.omega, self.phi, self.rigid))


def _check_symmetric(a: np.ndarray, name: str) -> np.ndarray:
    if not np.all(np.isfinite(a)):
        raise InputError(f"the {name} matrix has non-finite entries", where=name)
    scale = np.max(np.abs(a)) if a.size else 0.0
    if a.size and np.max(np.abs(a - a.T)) > 1e-10 * (scale or 1.0):
        raise InputError(f"the {name} matrix is not symmetric", fix="check the model assembly")
    return 0.5 * (a + a.T)


def moving_components(vectors: np.ndarray, labels: tuple[str, ...] | None) -> str:
    """Name what ``vectors`` (n, k) move most: components of ``"comp:..."`` labels.

    Parameters
    ----------
    vectors : ndarray (n, k)
    labels : tuple of str, optional
        Coordinate names (``"keel:n3:ux"``, ``"boom:y2"``); the part before the first ``:``
        is the component.
    """
    v = np.abs(np.asarray(vectors, float)).reshape(vectors.shape[0], -1)
    weight = np.max(v, axis=1)
    if not weight.size or weight.max() == 0:
        return "no coordinate"
    idx = np.flatnonzero(weight > 0.1 * weight.max())
    if labels is None:
        more = f" and {idx.size - 3} more" if idx.size > 3 else ""
        return "coordinates " + ", ".join(str(i) for i in idx[:3]) + more
    comps: list[str] = []
    for i in idx[np.argsort(-weight[idx])]:
        c = labels[i].split(":")[0]
        if c not in comps:
            comps.append(c)
    more = f" and {len(comps) - 4} more" if len(comps) > 4 else ""
    return ", ".join(repr(c) for c in comps[:4]) + more


def _shifted_cholesky(
    k: np.ndarray, m: np.ndarray, s0: float, scale: float
) -> tuple[float, np.ndarray | None]:
    """The smallest tried shift ``s >= s0`` with ``k + s m`` positive definite, and its factor.

    Tries ``s0`` (0 first), then ``scale * 10^(-16 + 2 j)``; None when no shift up to
    ``1e6 scale`` works (a zero-mass, zero-stiffness direction).
    """
    import scipy.linalg as sla

    trials = [s0] + [scale * 10.0 ** (-16 + 2 * j) for j in range(12)]
    for s in trials:
        if s < s0:
            continue
        try:
            return s, sla.cholesky(k + s * m, lower=False, check_finite=False)
        except np.linalg.LinAlgError:
            continue
    return s0, None


def graded_eigh(
    stiffness: np.ndarray,
    mass: np.ndarray,
    n_finite: int | None = None,
    *,
    deflate: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """All finite eigenpairs of ``K y = lambda M y``, each to about :data:`ACCEPT_REL`.

    ``K`` symmetric and definite up to a few negative eigenvalues (unstable modes), ``M``
    positive semi-definite (massless directions have no finite eigenvalue and are left out).
    Method in the module docstring, step 3.

    Coordinates whose mass row is exactly zero are condensed statically first, exactly:
    ``K_c = K_aa - K_ao K_oo^-1 K_oa`` and ``y_o = -K_oo^-1 K_oa y_a`` (Guyan's reduction,
    exact for massless coordinates).  The levels then work on a mass matrix without
    massless coordinates, so that their complement bases never mix a massless coordinate
    (whose mass would be rounding noise ``eps |M|`` times a large static displacement) into
    the mass products: the shapes are M-orthonormal in the caller's exact ``M``.

    Parameters
    ----------
    stiffness, mass : ndarray (n, n)
        Diagonally scaled by the caller for best results.
    n_finite : int, optional
        Number of eigenpairs wanted: the directions with mass (default: counted from
        ``mass``), less the deflated ones.
    deflate : ndarray (n, j), optional
        M-orthonormal vectors already found (rigid or lower modes): the eigenpairs are
        sought in their M-orthogonal complement.

    Returns
    -------
    lam : ndarray (f,)
        Eigenvalues, ascending (rad^2/s^2 for SI matrices).
    y : ndarray (n, f)
        ``M``-orthonormal eigenvectors.

    Raises
    ------
    InputError
        When ``K + s M`` is singular for every shift (a massless, unrestrained direction);
        ``err.vector`` holds that direction.
    """
    import scipy.linalg as sla

    k = 0.5 * (stiffness + stiffness.T)
    m = 0.5 * (mass + mass.T)
    n = k.shape[0]
    if n == 0:
        return np.zeros(0), np.zeros((0, 0))
    zero = np.sum(np.abs(m), axis=1) == 0.0
    a = np.flatnonzero(~zero)
    o = np.flatnonzero(zero)
    if n_finite is None:
        w = np.linalg.eigvalsh(m[np.ix_(a, a)]) if a.size else np.zeros(0)
        n_finite = int(np.count_nonzero(w > MASSLESS_TOL * max(w.max(), 0.0))) if w.size else 0
        if deflate is not None:
            n_finite -= deflate.shape[1]
    if n_finite <= 0 or a.size == 0:
        return np.zeros(0), np.zeros((n, 0))
    if o.size == 0:
        q0 = None if deflate is None else _m_complement(m, deflate)
        return _graded_levels(k, m, n_finite, q0)
    koo = k[np.ix_(o, o)]
    koa = k[np.ix_(o, a)]
    try:
        fac = sla.cho_factor(koo, lower=False, check_finite=False)
        piv = np.abs(np.diag(fac[0]))
        if piv.min() <= 1e-7 * piv.max():  # K_oo's condition beyond ~1e14
            raise np.linalg.LinAlgError("near-singular")
        xo = -sla.cho_solve(fac, koa, check_finite=False)
    except np.linalg.LinAlgError:
        w, v = np.linalg.eigh(koo)
        if w.min() > 1e-14 * max(abs(w).max(), 1e-300):
            # indefinite but regular (a negative stiffness on a massless part): a symmetric
            # solve condenses it the same way
            xo = -np.linalg.solve(koo, koa)
        else:
            err = InputError("a part without mass has no stiffness either")
            vec = np.zeros((n, 1))
            vec[o, 0] = v[:, 0]
            err.vector = vec  # type: ignore[attr-defined]
            raise err from None
    kc = k[np.ix_(a, a)] + koa.T @ xo
    ma = m[np.ix_(a, a)]
    q0 = None if deflate is None else _m_complement(ma, deflate[a])
    lam, ya = _graded_levels(0.5 * (kc + kc.T), ma, n_finite, q0)
    y = np.zeros((n, lam.size))
    y[a] = ya
    y[o] = xo @ ya
    return lam, y


def _m_complement(m: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Orthonormal basis (Euclidean) of the M-orthogonal complement of span(d)."""
    import scipy.linalg as sla

    return np.asarray(sla.null_space(np.asarray(m @ d).T))


def _graded_levels(
    k: np.ndarray, m: np.ndarray, n_finite: int, q0: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """The levels of :func:`graded_eigh` (starting in span(q0), default everything)."""
    import scipy.linalg as sla

    n = k.shape[0]
    dm = np.diag(m)
    pos = dm > MASSLESS_TOL * dm.max()
    scale = float(np.max(np.abs(np.diag(k))[pos] / dm[pos])) if pos.any() else 1.0
    scale = scale if scale > 0 else 1.0
    q = np.eye(n) if q0 is None else q0
    lam_out: list[np.ndarray] = []
    y_out: list[np.ndarray] = []
    found = 0
    s = 0.0
    for level in range(MAX_LEVELS):
        whole = level == 0 and q0 is None
        kc = k if whole else q.T @ k @ q
        mc = m if whole else q.T @ m @ q
        kc = 0.5 * (kc + kc.T)
        mc = 0.5 * (mc + mc.T)
        s, r = _shifted_cholesky(kc, mc, s, scale)
        if r is None:
            w, v = np.linalg.eigh(kc + scale * mc)
            err = InputError("a part without mass has no stiffness either")
            err.vector = q @ v[:, :1]  # type: ignore[attr-defined]
            raise err
        c = sla.solve_triangular(r, sla.solve_triangular(r, mc, trans="T").T, trans="T")
        mu, v = np.linalg.eigh(0.5 * (c + c.T))
        mu, v = mu[::-1], v[:, ::-1]  # descending: lowest lambda first
        x = sla.solve_triangular(r, v)  # (K + s M)-orthonormal
        mu_max = float(mu[0])
        if not mu_max > 0:
            break
        good = mu > 1e3 * _EPS * mu_max
        lam = np.full(mu.size, np.inf)
        lam[good] = 1.0 / mu[good] - s
        # relative error bound eps mu_max / (mu^2 |lambda|); modes below a forced shift
        # (level 0) keep the absolute error ~ eps s, nothing can do better there
        err_abs = np.full(mu.size, np.inf)
        err_abs[good] = _EPS * mu_max / mu[good] ** 2
        ok = good & (err_abs <= ACCEPT_REL * np.abs(lam))
        if level == 0 and s > 0:
            ok |= good & (np.abs(lam) <= s)
        take = min(int(np.count_nonzero(ok)), n_finite - found)
        ok_idx = np.flatnonzero(ok)[:take]
        if take:
            y = q @ (x[:, ok_idx] / np.sqrt(mu[ok_idx]))
            lam_lv = lam[ok_idx]
            if level > 0:
                y, lam_lv = _level_rayleigh_ritz(k, m, y, lam_lv)
            y_out.append(y)
            lam_out.append(lam_lv)
            found += take
        if found >= n_finite:
            break
        rest = np.setdiff1d(np.arange(mu.size), ok_idx)
        if rest.size == 0:
            break
        # the rest's span, made exactly M-orthogonal to every kept mode (twice: the rounding
        # of R^-1 leaves ~eps cond(R) of them in it, which would leak into the residuals)
        qn = q @ x[:, rest]
        acc = np.concatenate(y_out, axis=1) if y_out else np.zeros((n, 0))
        for _ in range(2):
            qn = qn - acc @ (acc.T @ (m @ qn))
            if q0 is not None:
                qn = q0 @ (q0.T @ qn)
            qn, _ = np.linalg.qr(qn)
        q = qn
        est = lam[rest][good[rest] & (mu[rest] > 1e6 * _EPS * mu_max)]
        s_next = 0.5 * float(est.min()) if est.size else 1e3 * (s + 1.0 / mu_max)
        s = max(s_next, s, 0.0)
    if found < n_finite:
        raise SolverError(
            f"graded eigensolver resolved {found} of {n_finite} modes in {MAX_LEVELS} levels"
        )
    lam_all = np.concatenate(lam_out)
    y_all = np.concatenate(y_out, axis=1)
    order = np.argsort(lam_all, kind="stable")
    return lam_all[order], y_all[:, order]


def _level_rayleigh_ritz(
    k: np.ndarray, m: np.ndarray, y: np.ndarray, lam: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Rayleigh-Ritz of one shifted level's modes in the stiffness form, where it is exact.

    A level above the first is solved through ``R^-1`` of ``K + s M``, whose condition (the
    massless directions' stiffness beside ``s M``) leaves its shapes mixed with each other by
    ``eps cond(R)``: 1e-7 for the penalty modes of fuzz reproduction ``model-5f5d8f9777``.
    The shapes ``Y`` are taken in the pencil's own coordinates (not the level's basis,
    whose products cancel).  ``Y^T K Y`` is accurate where its rounding bound
    ``eps |y_j|^T |K| |y_j|`` is at most :data:`ACCEPT_REL` of the level's smallest
    eigenvalue (no cancellation: stiff modes);
    then the pencil ``(Y^T K Y, Y^T M Y)`` is solved and the shapes rotated within the
    level's span (Parlett, *The Symmetric Eigenvalue Problem*, Sec. 11.4).  Otherwise the
    inverse form's shapes are kept.
    """
    import scipy.linalg as sla

    ay = np.abs(y)
    bound = _EPS * np.sum(ay * (np.abs(k) @ ay), axis=0)
    lo = float(np.min(np.abs(lam))) if lam.size else 0.0
    if lam.size < 2 or not np.all(bound <= ACCEPT_REL * lo):
        return y, lam
    ky = y.T @ k @ y
    my = y.T @ m @ y
    try:
        lam_r, v = sla.eigh(0.5 * (ky + ky.T), 0.5 * (my + my.T), check_finite=False)
    except (np.linalg.LinAlgError, ValueError):
        return y, lam
    return y @ v, lam_r


def _scaling(k: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Diagonal scaling making the pencil's diagonal O(1): 1/sqrt(M_ii), else 1/sqrt(K_ii)."""
    dm = np.diag(m).copy()
    dk = np.abs(np.diag(k))
    d = np.ones(dm.size)
    pos = dm > MASSLESS_TOL * (dm.max() if dm.size else 0.0)
    d[pos] = 1.0 / np.sqrt(dm[pos])
    stiff = ~pos & (dk > 0)
    if stiff.any() and pos.any():
        # massless coordinates: scale to the same stiffness-per-mass as the massive ones
        ref = float(np.median(dk[pos] / dm[pos])) if np.any(dk[pos] > 0) else 1.0
        d[stiff] = np.sqrt(max(ref, 1e-300) / dk[stiff])
    return d


def solve_dense(
    mass: np.ndarray,
    stiffness: np.ndarray,
    rigid_candidates: np.ndarray | None = None,
    *,
    tol: float = RIGID_TOL,
    labels: tuple[str, ...] | None = None,
    rigid_vectors: np.ndarray | None = None,
) -> Eigensolution:
    """Solve ``K phi = omega^2 M phi`` (Eq. 2.10) for a free-free structure, densely.

    Parameters
    ----------
    mass, stiffness : ndarray (n, n)
        Generalized mass (positive semi-definite: massless coordinates are condensed) and
        stiffness (symmetric), SI.
    rigid_candidates : ndarray (n, r), optional
        Exact rigid-body coordinate vectors.  Those K annihilates (row by row, to ``tol``)
        become exact zero modes.  Without them, the zero-energy modes of a first solve are
        the candidates, and the same row-wise test decides.
    tol : float
        Row-wise relative tolerance on ``K r`` for rigidity.
    labels : tuple of str, optional
        Coordinate names, to name the components of a mechanism.
    rigid_vectors : ndarray (n, r), optional
        Rigid-body vectors known to be annihilated by ``K`` (no test); overrides
        ``rigid_candidates``.

    Returns
    -------
    Eigensolution
        Rigid modes first, then the others by eigenvalue (unstable ones before elastic).

    Raises
    ------
    InputError
        Bad matrices, or a mechanism (a zero-energy motion that is not rigid, or a massless
        part without stiffness) naming the components it moves.
    """
    mass = _check_symmetric(np.asarray(mass, dtype=float), "mass")
    stiffness = _check_symmetric(np.asarray(stiffness, dtype=float), "stiffness")
    return _solve_dense(mass, stiffness, rigid_candidates, tol, labels, rigid_vectors)


def _solve_dense(
    mass: np.ndarray,
    stiffness: np.ndarray,
    rigid_candidates: np.ndarray | None,
    tol: float,
    labels: tuple[str, ...] | None,
    rigid_vectors: np.ndarray | None,
) -> Eigensolution:
    n = mass.shape[0]
    if rigid_vectors is not None:
        b = m_orthonormal(mass, np.asarray(rigid_vectors, float).reshape(n, -1))
    else:
        if rigid_candidates is None:
            rigid_candidates = _zero_energy_candidates(mass, stiffness, labels)
        b = rigid_basis(mass, stiffness, np.asarray(rigid_candidates, float).reshape(n, -1), tol)
    sup = _supports(mass, b)
    # reversed: a tree numbered parents first is then eliminated leaves first, without fill
    # (the sparse recursion of the tree; measured 3x smaller eigenvalue errors on the IOC)
    keep = np.setdiff1d(np.arange(n), sup)[::-1]
    mb = mass @ b
    ks = stiffness[np.ix_(keep, keep)]
    wk = mb[keep]
    ms = mass[np.ix_(keep, keep)] - wk @ wk.T
    d = _scaling(ks, ms)
    ksd = d[:, None] * ks * d[None, :]
    msd = d[:, None] * ms * d[None, :]
    w = np.linalg.eigvalsh(0.5 * (msd + msd.T)) if keep.size else np.zeros(0)
    n_finite = int(np.count_nonzero(w > MASSLESS_TOL * max(w.max(), 0.0))) if w.size else 0
    notes: list[str] = []
    try:
        lam, y = graded_eigh(ksd, msd, n_finite)
    except InputError as exc:
        vec = np.zeros((n, 1))
        vec[keep] = d[:, None] * getattr(exc, "vector", np.zeros((keep.size, 1)))
        raise InputError(
            "the structure has a mechanism: a part without mass is free to move (no "
            f"stiffness), mostly {moving_components(vec, labels)}",
            fix="connect that part elastically, or give it mass",
        ) from None
    x = np.zeros((n, lam.size))
    x[keep] = d[:, None] * y
    x -= b @ (mb.T @ x)
    if n_finite < keep.size:
        notes.append(
            f"{keep.size - n_finite} coordinate direction(s) carry no mass: condensed "
            "statically (their modes have no finite frequency)"
        )
    return _finish(mass, stiffness, b, lam, x, labels, notes, check_zero=True)


def _supports(mass: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The isostatic support coordinates of :func:`solve_dense` (step 2).

    The rows of ``B`` best conditioned as a block (:func:`support_coordinates`), unless
    holding them leaves a heavy coordinate to cancel in ``M_s = E^T M E - W W^T``: a raw
    row of ``B`` is small where the mass is large (a rotation coordinate carrying
    2e17 kg m^2 moves 2e-9 rad per unit modal amplitude: fuzz reproduction
    ``model-5a35beda18``), and its diagonal ``M_ii - W_i^2`` would keep only
    ``eps M_ii / (M_ii - W_i^2)`` of its digits.  Beyond :data:`SUPPORT_CANCEL` the rows are
    weighted by ``sqrt(M_ii)`` first (the mass's own scale), which holds the heavy ones.
    """
    sup = support_coordinates(b)
    dm = np.diag(mass)
    w2 = np.sum((mass @ b) ** 2, axis=1)
    free = np.setdiff1d(np.flatnonzero(dm > 0), sup)
    if free.size and np.min((dm[free] - w2[free]) / dm[free]) < SUPPORT_CANCEL:
        sup = support_coordinates(b * np.sqrt(np.clip(dm, 0.0, None))[:, None])
    return sup


def _finish(
    mass: Any,
    stiffness: Any,
    b: np.ndarray,
    lam: np.ndarray,
    x: np.ndarray,
    labels: tuple[str, ...] | None,
    notes: list[str],
    *,
    check_zero: bool,
    orthonormalize: bool = True,
) -> Eigensolution:
    """Classify (unstable, mechanism), check residuals, and assemble the solution.

    With ``orthonormalize`` the elastic shapes (ascending ``lam``) are first made exactly
    M-orthonormal by :func:`m_orthonormal_ascending`.
    """
    r = b.shape[1]
    if orthonormalize:
        x = m_orthonormal_ascending(mass, x)
        if r:
            # the combinations carry each shape's rigid-span rounding to the others: project
            # again (B is M-orthonormal), so that every participation factor stays at its
            # own rounding level (effective masses exactly 0: modes.EFFECTIVE_MASS_ZERO)
            x = x - b @ np.asarray((mass @ b).T @ x)
    k_abs: Any = abs(stiffness)
    ax = np.abs(x)
    kax = np.asarray(k_abs @ ax)  # |K| |x|, for the energy bound and the backward error
    energy_bound = _EPS * np.sum(ax * kax, axis=0)  # eps |x|^T |K| |x|
    zero = np.abs(lam) <= energy_bound
    if check_zero and np.any(zero):
        raise InputError(
            f"the structure has a mechanism: {int(np.count_nonzero(zero))} zero-frequency "
            f"mode(s) beyond the {r} rigid-body modes, mostly "
            f"{moving_components(x[:, zero], labels)} (an unrestrained joint or part)",
            fix="connect that part elastically",
        )
    unstable = lam < -energy_bound
    kx = np.asarray(stiffness @ x)
    res = np.linalg.norm(kx - np.asarray(mass @ x) * lam, axis=0)
    # componentwise backward error of the pair (Higham & Higham 1998, SIAM J. Matrix Anal.
    # Appl. 20: ||r|| / (|| |K||x| || + |lambda| || |M||x| ||)): the mass term matters for the
    # highest modes, which live where the mass is small
    m_abs: Any = abs(mass)
    den = np.linalg.norm(kax, axis=0) + np.abs(lam) * np.linalg.norm(np.asarray(m_abs @ ax), axis=0)
    den = np.maximum(den, np.finfo(float).tiny)
    if lam.size and np.any(res / den > RESIDUAL_TOL):
        _refuse_spread(mass, stiffness, labels, int(np.count_nonzero(res / den > RESIDUAL_TOL)))
        raise SolverError(
            f"{int(np.count_nonzero(res / den > RESIDUAL_TOL))} modes did not converge "
            f"(largest residual {np.max(res / den):.2e})"
        )
    if np.any(unstable):
        notes.append(
            f"{int(np.count_nonzero(unstable))} unstable mode(s): a negative stiffness "
            f"(growth rate {np.sqrt(-lam[unstable].min()):.4g} rad/s); the structure diverges "
            "from its equilibrium instead of vibrating about it"
        )
    omega = np.concatenate([np.zeros(r), np.sqrt(np.clip(lam, 0.0, None))])
    growth = np.concatenate([np.zeros(r), np.sqrt(np.clip(-lam, 0.0, None))])
    omega[r:][unstable] = 0.0
    growth[r:][~unstable] = 0.0
    return Eigensolution(
        omega=omega,
        phi=np.concatenate([b, x], axis=1),
        rigid=np.concatenate([np.ones(r, bool), np.zeros(lam.size, bool)]),
        unstable=np.concatenate([np.zeros(r, bool), unstable]),
        growth_rate=growth,
        notes=tuple(notes),
    )


def _refuse_spread(mass: Any, stiffness: Any, labels: tuple[str, ...] | None, bad: int) -> None:
    """InputError when the coordinates' own squared frequencies span beyond double precision.

    ``K_ii / M_ii`` is the squared frequency of coordinate i held alone.  When these span more
    than :data:`MAX_SPREAD` (12 decades), the rounding of the stiffest rows, ``eps K_max``, is
    ``eps * spread`` > 1e-4 of the softest modes' own stiffness, and their backward error
    cannot reach :data:`RESIDUAL_TOL`: a modelling limit (a near-rigid part beside soft ones),
    not a solver defect.  Measured on the IOC model: a keel EI of 1e12 N m^2 (spread 6e11)
    solves, 2e12 (spread 1.3e12) does not.
    """
    dm = np.asarray(mass.diagonal() if hasattr(mass, "diagonal") else np.diag(mass), float)
    dk = np.asarray(
        stiffness.diagonal() if hasattr(stiffness, "diagonal") else np.diag(stiffness), float
    )
    pos = (dm > MASSLESS_TOL * max(float(dm.max(initial=0.0)), 0.0)) & (dk > 0)
    if not np.any(pos):
        return
    ratio = dk[pos] / dm[pos]
    spread = float(ratio.max() / ratio.min())
    if spread <= MAX_SPREAD:
        return
    stiff = int(np.flatnonzero(pos)[np.argmax(ratio)])
    name = labels[stiff] if labels and stiff < len(labels) else f"coordinate {stiff}"
    raise InputError(
        f"{bad} modes cannot be resolved in double precision: the coordinates' stiffness-to-"
        f"mass ratios span {spread:.2g} (more than {MAX_SPREAD:g}), stiffest at {name}",
        where="model",
        fix="check the stiffness values and their units; model a near-rigid part as part of "
        "a rigid body, or use the assumed-modes method, ritz",
    )


def m_orthonormal_ascending(mass: Any, x: np.ndarray) -> np.ndarray:
    """``x R^-1`` with ``R^T R = x^T M x`` (Cholesky): Gram-Schmidt in the mass inner product.

    Shapes in ascending order of eigenvalue: the lowest shape is only rescaled, and each
    higher one loses the components along the lower ones (the direction in which an inverse
    iteration's rounding leaves its error: ``eps cond(R)`` along the stiffness's softest
    directions).  A shape ``x_j`` mixed with a lower mode ``x_i`` by ``c`` changes its
    backward error by at most ``|c|`` (the residual term is ``c (lambda_i - lambda_j) M x_i``
    with ``lambda_i < lambda_j``).  Without it the shapes of a pencil with eigenvalues over
    23 decades (fuzz reproduction ``model-5f5d8f9777``: EI 2 N m^2 beside an axial penalty
    1e12 N) are M-orthonormal to only ~1e-7.

    Parameters
    ----------
    mass : ndarray or sparse (n, n)
    x : ndarray (n, m)
        Linearly independent shapes.
    """
    import scipy.linalg as sla

    if x.shape[1] == 0:
        return x
    g = np.asarray(x.T @ (mass @ x))
    g = 0.5 * (g + g.T)
    try:
        r = sla.cholesky(g, lower=False, check_finite=False)
    except np.linalg.LinAlgError:
        raise SolverError("the computed mode shapes are linearly dependent") from None
    return np.asarray(sla.solve_triangular(r, x.T, trans="T", check_finite=False)).T


def _zero_energy_candidates(
    mass: np.ndarray, stiffness: np.ndarray, labels: tuple[str, ...] | None
) -> np.ndarray:
    """Shapes of the zero-energy modes of the whole pencil (rigid candidates, not yet tested)."""
    d = _scaling(stiffness, mass)
    try:
        lam, y = graded_eigh(d[:, None] * stiffness * d, d[:, None] * mass * d)
    except InputError:
        raise InputError(
            "the structure has a mechanism: a part without mass is free to move (no stiffness)",
            fix="connect that part elastically, or give it mass",
        ) from None
    x = d[:, None] * y
    bound = _EPS * np.sum(np.abs(x) * (np.abs(stiffness) @ np.abs(x)), axis=0)
    return x[:, np.abs(lam) <= 1e3 * bound]
