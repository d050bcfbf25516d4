"""Dense free-free modal solution of small structures (Eq. 2.10), rigid modes exact."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from microg.dynamics.rigid import RIGID_TOL, rigid_basis
from microg.errors import InputError, SolverError

__all__ = ["solve_dense"]


def _check_symmetric(a: np.ndarray, name: str) -> np.ndarray:
    scale = np.max(np.abs(a)) or 1.0
    if np.max(np.abs(a - a.T)) > 1e-10 * scale:
        raise InputError(f"the {name} matrix is not symmetric", fix="check the model assembly")
    return 0.5 * (a + a.T)


def _massless(mass: np.ndarray, labels: tuple[str, ...] | None) -> str:
    """Name the coordinates that dominate the (near-)null space of the mass matrix."""
    w, v = np.linalg.eigh(mass)
    null = v[:, w <= 1e-12 * max(w.max(), 1e-300)]
    if null.size == 0 or labels is None:
        return "a coordinate carries no mass"
    weight = np.max(np.abs(null), axis=1)
    idx = np.flatnonzero(weight > 0.1 * weight.max())
    names = [labels[i] for i in idx[:6]]
    more = f" and {idx.size - 6} more" if idx.size > 6 else ""
    return f"coordinates {', '.join(names)}{more} carry no mass"


def solve_dense(
    mass: np.ndarray,
    stiffness: np.ndarray,
    rigid_candidates: np.ndarray | None = None,
    *,
    tol: float = RIGID_TOL,
    labels: tuple[str, ...] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Solve ``K phi = omega^2 M phi`` (Eq. 2.10) for a free-free structure, densely.

    Parameters
    ----------
    mass, stiffness : ndarray (n, n)
        Generalized mass (SPD) and stiffness (PSD) matrices, SI.
    rigid_candidates : ndarray (n, r), optional
        Exact rigid-body coordinate vectors.  Those K annihilates (row by row, to ``tol``)
        become exact zero modes.  Without them, the eigenvectors of near-zero eigenvalues are
        the candidates, and the same row-wise test decides.
    tol : float
        Row-wise relative tolerance on ``K r`` for rigidity.
    labels : tuple of str, optional
        Coordinate names, to say which coordinates carry no mass when M is singular.

    Returns
    -------
    omega : ndarray (n,)
        rad/s, ascending, exact zeros for rigid-body modes.
    phi : ndarray (n, n)
        Mass-normalised shapes, one per column.
    rigid : ndarray (n,) of bool
    """
    mass = _check_symmetric(np.asarray(mass, dtype=float), "mass")
    stiffness = _check_symmetric(np.asarray(stiffness, dtype=float), "stiffness")
    n = mass.shape[0]
    try:
        sla.cholesky(mass, lower=True)
    except sla.LinAlgError:
        raise InputError(
            "the mass matrix is not positive definite: " + _massless(mass, labels),
            fix="give every part of the model mass (mass_per_length or point masses) "
            "or remove the massless part",
        ) from None
    if rigid_candidates is None:
        # no exact rigid vectors given: screen the near-zero eigenvectors, then accept only
        # those K annihilates row by row (a gravity-gradient or soft mode fails that test)
        lam_all, vec_all = sla.eigh(stiffness, mass)
        scale = max(np.max(np.abs(lam_all)), 1e-300)
        rigid_candidates = vec_all[:, np.abs(lam_all) <= 1e-6 * scale]
    # row-wise test |K r|_i <= tol (|K| |r|)_i: a whole-matrix norm cannot tell an exact
    # rigid vector from a rotation restrained by gravity gradient (stiffness ~1e-7 of K)
    rigid_vecs = rigid_basis(mass, stiffness, np.asarray(rigid_candidates, float), tol)
    r = rigid_vecs.shape[1]
    if r:
        # complement of the rigid span, M-orthogonal to it
        q = sla.null_space((mass @ rigid_vecs).T)
        kq = q.T @ stiffness @ q
        mq = q.T @ mass @ q
        lam, v = sla.eigh(0.5 * (kq + kq.T), 0.5 * (mq + mq.T))
        phi_el = q @ v
    else:
        lam, phi_el = sla.eigh(stiffness, mass)
    scale = max(np.max(np.abs(lam)) if lam.size else 0.0, 1e-300)
    if lam.size and lam.min() < -1e-8 * scale:
        raise SolverError(
            f"negative eigenvalue {lam.min():.3e}"
            ": the stiffness matrix is not positive semi-definite"
        )
    omega_el = np.sqrt(np.clip(lam, 0.0, None))
    omega = np.concatenate([np.zeros(r), omega_el])
    phi = np.concatenate([rigid_vecs, phi_el], axis=1)
    rigid = np.concatenate([np.ones(r, bool), np.zeros(n - r, bool)])
    order = np.argsort(omega, kind="stable")
    return omega[order], phi[:, order], rigid[order]
