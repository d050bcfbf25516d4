"""Exact rigid-body modes: the part of the rigid-body span that the stiffness annihilates.

Rigid-body modes are never left to an eigensolver's round-off.  A discretisation declares
the exact rigid-body vectors (unit translations and rotations about the centre of mass);
:func:`rigid_basis` keeps the combinations that ``K`` annihilates row by row and returns them
M-orthonormal.  Both solvers (:mod:`microg.dynamics.dense`, :mod:`microg.dynamics.eigsparse`)
use it, and :func:`support_coordinates` picks where to hold a free structure isostatically.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # scipy loads on first use: ``import microg.analysis`` stays light
    import scipy.sparse as sp

__all__ = ["RIGID_TOL", "rigid_basis", "m_orthonormal", "rowwise_small", "support_coordinates"]

#: row-wise relative tolerance for deciding that K annihilates a rigid-body vector:
#: exact rigid vectors of the frame models score ~1e-16; a restraint softer than 1e-12 of a
#: row's stiffness cannot be told from rigid (documented limit)
RIGID_TOL = 1e-12
#: fraction of the largest stiffness times the vector's largest entry below which a row's
#: K r is round-off (double precision, 2.2e-16, times the few hundred terms a row or a
#: condensation may sum); a restraint softer than this cannot be told from rigid
#: (documented limit)
RIGID_FLOOR = 1e-13


def rigid_basis(
    mass: sp.spmatrix, stiffness: sp.spmatrix, candidates: np.ndarray | None, tol: float = 1e-9
) -> np.ndarray:
    """M-orthonormal basis of the part of span(candidates) that ``K`` annihilates.

    ``K`` is applied to the raw candidates only (exact rigid vectors give exact-to-rounding
    products); combinations are formed in coefficient space.  Candidates that pass on their
    own are accepted first, so a rotation restrained by gravity gradient cannot leak into
    the free ones through round-off of a 6x6 eigen-decomposition; combinations of the rest
    (M-orthogonalised against the accepted) are then tested the same way.

    Parameters
    ----------
    mass, stiffness : sparse or ndarray (n, n)
        SI mass and stiffness.
    candidates : ndarray (n, r) or None
        Exact rigid-body coordinate vectors (1 m, 1 rad).
    tol : float
        Largest row-wise relative residual ``|K r|_i / (|K| |r|)_i`` of a rigid vector.

    Returns
    -------
    ndarray (n, r0)
        ``B`` with ``B^T M B = I`` and ``K B = 0`` to round-off, in the order of the
        candidates that pass (Gram-Schmidt in the mass inner product).
    """
    n = mass.shape[0]
    if candidates is None or np.size(candidates) == 0:
        return np.zeros((n, 0))
    c = np.asarray(candidates, float).reshape(n, -1)
    kc = stiffness @ c
    ak = abs(stiffness)
    akc = ak @ np.abs(c)
    # the largest stiffness of the DOFs (condensation spreads its round-off over every row):
    # a row whose |K||r| is itself round-off (a DOF on a rotation's axis, a transverse DOF of
    # a bar whose massless rotations were condensed) is judged against it, not against its
    # own round-off
    kmax = np.full(n, float(ak.max()) if n else 0.0)
    mcc = c.T @ (mass @ c)
    mcc = 0.5 * (mcc + mcc.T)
    kcc = c.T @ kc
    kcc = 0.5 * (kcc + kcc.T)
    eye = np.eye(c.shape[1])
    ok = rowwise_small(kc, akc, tol, floor=_floor(kmax, c))
    accepted = eye[:, ok]
    rest = eye[:, ~ok]
    if rest.shape[1] and accepted.shape[1]:
        ma = accepted.T @ mcc @ accepted
        rest = rest - accepted @ np.linalg.lstsq(ma, accepted.T @ mcc @ rest, rcond=None)[0]
    if rest.shape[1]:
        mr = rest.T @ mcc @ rest
        dr = np.diag(mr).copy()
        rest = rest[:, dr > 0] / np.sqrt(dr[dr > 0])[None, :]  # unit M-norm (units mixed)
        mr = rest.T @ mcc @ rest
        w, v = np.linalg.eigh(0.5 * (mr + mr.T))
        keep = w > 1e-12 * max(w.max(), 1e-300) if w.size else np.zeros(0, bool)
        g = rest @ (v[:, keep] / np.sqrt(w[keep]))
        kr = g.T @ kcc @ g
        _, v = np.linalg.eigh(0.5 * (kr + kr.T))
        g = g @ v
        good = rowwise_small(kc @ g, akc @ np.abs(g), tol, floor=_floor(kmax, c @ g))
        accepted = np.concatenate([accepted, g[:, good]], axis=1)
    if accepted.shape[1] == 0:
        return np.zeros((n, 0))
    return c @ _m_orthonormal_coefficients(accepted.T @ mcc @ accepted, accepted)


def _m_orthonormal_coefficients(gram: np.ndarray, coef: np.ndarray) -> np.ndarray:
    """Coefficients making ``coef`` orthonormal in ``gram``: Gram-Schmidt (Cholesky) in order.

    Keeping the order keeps the rigid modes named (x, y, z translations, then rotations about
    the centre of mass, each orthogonalised against the earlier ones); a dependent or
    massless direction falls back to the eigen-decomposition, dropping it.  The Gram matrix
    is first scaled to a unit diagonal: its entries mix units (kg for translations, kg m^2
    for rotations), so that a station's rotary inertia 2e17 kg m^2 beside its mass 3.6e4 kg
    (fuzz reproduction ``model-5a35beda18``) must not make the translations "dependent".
    """
    import scipy.linalg as sla

    g = 0.5 * (gram + gram.T)
    dg = np.diag(g).copy() if g.size else np.zeros(0)
    live = dg > 0.0
    if not np.all(live):
        # a candidate without mass: no mass-normalised direction of it exists
        return _m_orthonormal_coefficients(g[np.ix_(live, live)], coef[:, live])
    sc = 1.0 / np.sqrt(dg)
    gs = sc[:, None] * g * sc[None, :]
    w = np.linalg.eigvalsh(gs) if gs.size else np.zeros(0)
    if w.size and w.min() > 1e-10 * w.max():
        r = sla.cholesky(gs, lower=False)
        return (coef * sc[None, :]) @ sla.solve_triangular(r, np.eye(g.shape[0]))
    w, v = np.linalg.eigh(gs)
    keep = w > 1e-12 * max(w.max(), 1e-300)
    return (coef * sc[None, :]) @ (v[:, keep] / np.sqrt(w[keep]))


def _floor(kmax: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Row scale ``kmax_i * max |x|`` of each column of ``x``, (n, r)."""
    return kmax[:, None] * np.max(np.abs(x), axis=0)[None, :] if x.size else np.zeros(x.shape)


def rowwise_small(
    kx: np.ndarray, ax: np.ndarray, tol: float, *, floor: np.ndarray | None = None
) -> np.ndarray:
    """Columns whose products ``K x`` vanish row by row relative to ``|K| |x|``.

    Parameters
    ----------
    kx, ax : ndarray (n, r)
        ``K x`` and ``|K| |x|``.
    tol : float
        Largest row-wise ratio.
    floor : ndarray (n, r), optional
        Each row's scale (the largest stiffness times the column's largest entry): a
        ``K x`` below :data:`RIGID_FLOOR` of it is round-off and passes whatever ``|K| |x|``
        is, so that round-off never reads as a restraint (slender bars, a DOF on a rotation's
        axis, where ``|K| |x|`` is itself round-off).
    """
    kx = np.abs(kx)
    if floor is not None:
        kx = np.where(kx <= RIGID_FLOOR * floor, 0.0, kx)
    ratio = np.where(ax > 0, kx / np.where(ax > 0, ax, 1.0), np.where(kx > 0, np.inf, 0.0))
    return np.max(ratio, axis=0) <= tol


def m_orthonormal(M: sp.spmatrix, c: np.ndarray) -> np.ndarray:
    """M-orthonormal basis of span(c), dependent or massless columns dropped (order kept)."""
    c = np.asarray(c, float)
    if c.size == 0:
        return c.reshape(M.shape[0], 0)
    mc = c.T @ (M @ c)
    return c @ _m_orthonormal_coefficients(mc, np.eye(c.shape[1]))


def support_coordinates(basis: np.ndarray) -> np.ndarray:
    """``r`` coordinates that hold a free structure isostatically (its rigid motions fixed).

    The rows of the rigid basis (n, r) best conditioned as an r x r block, by QR with column
    pivoting of its transpose: with these coordinates held at zero no rigid motion is left,
    and the remaining stiffness is definite (Geradin & Rixen, Sec. 4.3).

    Parameters
    ----------
    basis : ndarray (n, r)
        Rigid-body vectors.

    Returns
    -------
    ndarray (r,) of int
        Coordinate indices, sorted.
    """
    import scipy.linalg as sla

    r = basis.shape[1]
    if r == 0:
        return np.zeros(0, int)
    _, _, piv = sla.qr(np.asarray(basis, float).T, mode="economic", pivoting=True)
    return np.sort(piv[:r])
