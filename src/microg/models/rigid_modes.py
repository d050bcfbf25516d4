"""Exact rigid-body modes for a free-free run's noisy ones.

Rigid-body modes come out of a free-free eigensolution at small noisy frequencies, possibly
mixed.  :func:`replace_rigid_modes` recognises them (the rigid-body content of each shape
and the frequency gap to the first elastic mode) and replaces them by exact rigid-body
modes built from the grid geometry and the mass, with ``omega = 0`` exactly
(:class:`ReplacedRigid` says what it did).  Shapes are mass-normalised, SI, basic frame
(:mod:`microg.models.modal`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = [
    "RIGID_GAP",
    "RIGID_TOL",
    "ReplacedRigid",
    "replace_rigid_modes",
    "rigid_basis_at",
    "shift_rigid_mass",
]

#: a mode is taken as rigid when its largest rigid frequency is this factor below the first
#: elastic one (documented limit: a "rigid" mode closer than 10x to the first elastic mode
#: is not replaced, and a warning says so)
RIGID_GAP = 10.0
#: largest relative residual of a least-squares rigid-body fit of a shape for it to count as
#: a rigid-body mode (translations and rotations scaled by the model's size)
RIGID_TOL = 0.05


@dataclass(frozen=True)
class ReplacedRigid:
    """What :func:`replace_rigid_modes` replaced (the ``replaced_rigid`` contract).

    Attributes
    ----------
    count : int
        How many of the file's modes were replaced by exact rigid-body modes.
    max_file_freq_hz : float
        The largest |frequency| the file gave them, Hz.
    file_freq_hz : tuple of float
        Each replaced mode's file frequency (negative for a negative eigenvalue), Hz.
    max_rigid_residual : float
        Largest relative residual of the rigid-body fit of the replaced shapes.
    first_elastic_hz : float or None
        The first elastic frequency kept, Hz.
    mass_source : str
        Where the rigid-body mass came from (``"OGPWG"``, ``"mass matrix"``, ``"given"``,
        ``"file modes"``).
    """

    count: int
    max_file_freq_hz: float
    file_freq_hz: tuple[float, ...] = ()
    max_rigid_residual: float = 0.0
    first_elastic_hz: float | None = None
    mass_source: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form: ``count`` and ``max_file_freq_hz`` are the contract."""
        return {
            "count": self.count,
            "max_file_freq_hz": self.max_file_freq_hz,
            "file_freq_hz": list(self.file_freq_hz),
            "max_rigid_residual": self.max_rigid_residual,
            "first_elastic_hz": self.first_elastic_hz,
            "mass_source": self.mass_source,
        }


def _skew(d: np.ndarray) -> np.ndarray:
    d = np.asarray(d, float)
    s = np.zeros((*d.shape[:-1], 3, 3))
    s[..., 0, 1], s[..., 0, 2] = -d[..., 2], d[..., 1]
    s[..., 1, 0], s[..., 1, 2] = d[..., 2], -d[..., 0]
    s[..., 2, 0], s[..., 2, 1] = -d[..., 1], d[..., 0]
    return s


def rigid_basis_at(xyz: np.ndarray, ref: np.ndarray | None = None) -> np.ndarray:
    """Unit rigid-body motions at grids: ``R[g, :, k]``, (g, 6, 6).

    Columns x, y, z are 1 (length unit) translations; rx, ry, rz are 1 rad rotations about
    ``ref`` (default the origin): ``u = theta x (x_g - ref)``, rotation ``theta``.
    """
    xyz = np.asarray(xyz, float)
    d = xyz - (np.zeros(3) if ref is None else np.asarray(ref, float))
    R = np.zeros((xyz.shape[0], 6, 6))
    R[:, range(3), range(3)] = 1.0
    R[:, :3, 3:] = -_skew(d)  # theta x d = -[d]x theta
    R[:, range(3, 6), range(3, 6)] = 1.0
    return R


def shift_rigid_mass(mass6: np.ndarray, from_point: np.ndarray, to_point: np.ndarray) -> np.ndarray:
    """A 6x6 rigid-body mass about ``from_point`` expressed about ``to_point``.

    ``R(to) = R(from) S`` with ``S = [[I, -[from - to]x], [0, I]]``, so ``M_to = S^T M S``.
    """
    s = np.eye(6)
    s[:3, 3:] = -_skew(np.asarray(from_point, float) - np.asarray(to_point, float))
    return s.T @ np.asarray(mass6, float) @ s


def _sym_inv_sqrt(g: np.ndarray) -> np.ndarray:
    w, v = np.linalg.eigh(0.5 * (g + g.T))
    if w.min() <= 1e-12 * max(w.max(), 1e-300):
        raise InputError(
            "the rigid-body mass is singular on the rigid modes",
            where="rigid_mass",
            fix="give a positive-definite 6x6 rigid-body mass or the mass matrix",
        )
    return (v / np.sqrt(w)) @ v.T


def replace_rigid_modes(
    freq_hz_signed: np.ndarray,
    phi: np.ndarray,
    xyz_m: np.ndarray,
    *,
    rigid_mass: np.ndarray | None = None,
    rigid_mass_ref_m: np.ndarray | None = None,
    mass_matrix: Any = None,
    mass_source: str = "",
    gap: float = RIGID_GAP,
    tol: float = RIGID_TOL,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, ReplacedRigid | None, list[str]]:
    """Recognise a free-free run's rigid-body modes and replace them by exact ones.

    A mode is rigid when its shape is a rigid-body motion (relative residual of the
    least-squares fit ``phi_j ~ R c_j`` below ``tol``, rotations weighted by the model's
    RMS radius) and the leading run of such modes (at most 6, ascending |f|) lies ``gap``
    times below the next mode.  They are replaced by ``R C (C^T M_rr C)^(-1/2)``: exact
    rigid motions of the same span, M-orthonormal with the 6x6 rigid-body mass ``M_rr``
    (from ``rigid_mass`` or ``R^T M R`` of ``mass_matrix``); elastic modes are
    M-orthogonalised against them when ``mass_matrix`` is given.  Without a mass, the
    file's own normalisation of the rigid modes stands (they were M-orthonormal): the exact
    modes are ``R C`` and a warning says so.

    Parameters
    ----------
    freq_hz_signed : ndarray (m,)
        File frequencies, Hz, negative for a negative eigenvalue.
    phi : ndarray (g, 6, m)
        Mass-normalised shapes, SI, basic frame.
    xyz_m : ndarray (g, 3)
        Grid positions, m.
    rigid_mass : ndarray (6, 6), optional
        Rigid-body mass about ``rigid_mass_ref_m`` (default origin), SI (kg, kg m, kg m^2).
    mass_matrix : ndarray or sparse (6g, 6g), optional
        Mass on the grids' DOFs (grid-major, 6 per grid), SI.
    mass_source : str
        Label of the mass for the report.
    gap : float
        Required ratio of the first elastic to the largest rigid frequency.
    tol : float
        Largest relative residual of a rigid shape.

    Returns
    -------
    omega : ndarray (m,)
        rad/s, exact zeros for the replaced modes, rigid modes first.
    phi : ndarray (g, 6, m)
    rigid : ndarray (m,) bool
    replaced : ReplacedRigid or None
    warnings : list of str
    """
    f = np.asarray(freq_hz_signed, float)
    phi = np.asarray(phi, float)
    xyz = np.asarray(xyz_m, float)
    g, _, m = phi.shape
    warnings: list[str] = []
    order = np.argsort(np.abs(f), kind="stable")
    f, phi = f[order], phi[:, :, order]
    omega = 2.0 * np.pi * np.abs(f)
    rigid = np.zeros(m, bool)
    if g == 0 or m == 0:
        return omega, phi, rigid, None, warnings
    x0 = xyz.mean(axis=0)
    lc = float(np.sqrt(np.mean(np.sum((xyz - x0) ** 2, axis=1)))) or 1.0
    R = rigid_basis_at(xyz, x0)  # (g, 6, 6), about the centroid
    w = np.array([1.0, 1.0, 1.0, lc, lc, lc])
    Rw = (R * w[None, :, None]).reshape(6 * g, 6)
    scale = np.array([1.0, 1.0, 1.0, 1.0 / lc, 1.0 / lc, 1.0 / lc])  # well-conditioned
    q, _ = np.linalg.qr(Rw * scale[None, :])
    pw = (phi * w[None, :, None]).reshape(6 * g, m)
    norm = np.linalg.norm(pw, axis=0)
    resid = np.linalg.norm(pw - q @ (q.T @ pw), axis=0) / np.where(norm > 0, norm, 1.0)
    resid = np.where(norm > 0, resid, 1.0)
    run = 0
    while run < min(6, m) and resid[run] < tol:
        run += 1
    if run == 0:
        return omega, phi, rigid, None, warnings
    f_max = float(np.max(np.abs(f[:run])))
    f_next = float(abs(f[run])) if run < m else None
    if f_next is not None and not f_max * gap <= f_next:
        warnings.append(
            f"modes 1-{run} have rigid-body shapes but their largest frequency "
            f"({f_max:.4g} Hz) is not {gap:g}x below the next mode ({f_next:.4g} Hz): "
            "kept as they are, not replaced by exact rigid-body modes"
        )
        return omega, phi, rigid, None, warnings
    # coefficients of the rigid fit in R(x0) (unweighted: m, rad)
    coef, *_ = np.linalg.lstsq(Rw, pw[:, :run], rcond=None)
    u, s, _ = np.linalg.svd(coef, full_matrices=False)
    k = int(np.count_nonzero(s > 1e-6 * s[0]))
    if k < run:
        warnings.append(
            f"{run} rigid-looking modes span only {k} rigid-body motions; {run - k} kept"
        )
    c = coef if k == run else u[:, :k] * s[:k]
    mrr = None
    src = mass_source
    if mass_matrix is not None:
        rf = R.reshape(6 * g, 6)
        mrr = rf.T @ np.asarray(mass_matrix @ rf)
        src = src or "mass matrix"
    elif rigid_mass is not None:
        ref = np.zeros(3) if rigid_mass_ref_m is None else np.asarray(rigid_mass_ref_m, float)
        mrr = shift_rigid_mass(np.asarray(rigid_mass, float), ref, x0)
        src = src or "given"
    if mrr is not None:
        c = c @ _sym_inv_sqrt(c.T @ mrr @ c)
    else:
        src = "file modes"
    if mrr is None and float(resid[:k].max()) > 1e-8:
        warnings.append(
            f"no mass given: the {k} exact rigid-body modes keep the file's normalisation "
            f"(rigid-body fit residual {float(resid[:k].max()):.2g}); give the mass matrix or "
            "a 6x6 rigid-body mass for an exact normalisation"
        )
    new_rigid = np.einsum("gab,bk->gak", R, c)
    elastic = phi[:, :, run:]
    if mass_matrix is not None and elastic.shape[2]:
        rf = new_rigid.reshape(6 * g, k)
        ef = elastic.reshape(6 * g, -1)
        ef = ef - rf @ (rf.T @ np.asarray(mass_matrix @ ef))
        elastic = ef.reshape(g, 6, -1)
    kept = phi[:, :, k:run]
    phi_out = np.concatenate([new_rigid, kept, elastic], axis=2)
    omega_out = np.concatenate([np.zeros(k), omega[k:]])
    rigid = np.zeros(phi_out.shape[2], bool)
    rigid[:k] = True
    first_el = float(abs(f[run])) if run < m else None
    report = ReplacedRigid(
        count=k,
        max_file_freq_hz=float(np.max(np.abs(f[:k]))),
        file_freq_hz=tuple(float(v) for v in f[:k]),
        max_rigid_residual=float(resid[:k].max()),
        first_elastic_hz=first_el,
        mass_source=src,
    )
    return omega_out, phi_out, rigid, report, warnings
