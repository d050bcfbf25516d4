"""Exact rigid-body modes for a free-free run's noisy ones.

Rigid-body modes come out of a free-free eigensolution at small noisy frequencies, possibly
mixed.  :func:`replace_rigid_modes` decides which modes are rigid and replaces them by exact
rigid-body modes built from the grid geometry and the mass, with ``omega = 0`` exactly
(:class:`ReplacedRigid` says what it did and on what evidence).  The rule:

1. the file's frequencies are the primary evidence: only the leading modes (at most 6) at or
   below :data:`RIGID_MAX_HZ` and :data:`RIGID_GAP` times below the next mode are candidates
   (a mode above :data:`RIGID_MAX_HZ` is never replaced; one with a rigid-body shape is kept
   with a warning);
2. a least-squares rigid-body fit of their shapes confirms them: it is trusted on at least
   :data:`MIN_RIGID_GRIDS` grids at distinct positions, or, on fewer, when the fitted rigid
   motions are M-orthonormal with the rigid-body mass (OGPWG, a mass matrix);
3. DOFs that are zero in every candidate mode (constrained or absent: a partly connected
   grid) are left out of the fit, and grids that still do not move rigidly (modal DOFs of a
   superelement, a DOF tied by an MPC) are dropped one by one, at most half of them; the
   exact modes keep the file's motion there (the same combination of the file's modes).

Shapes are mass-normalised, SI, basic frame (:mod:`microg.models.modal`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = [
    "MIN_RIGID_GRIDS",
    "RIGID_GAP",
    "RIGID_MAX_HZ",
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
#: highest file frequency of a mode that may be replaced by an exact rigid-body mode, Hz (a
#: tenth of the lowest elastic modes of large space structures, about 0.1 Hz; NASTRAN's
#: free-free rigid modes come out below 1e-3 Hz)
RIGID_MAX_HZ = 0.01
#: fewest grids at distinct positions on which a rigid-body fit is trusted without a mass:
#: on 1 or 2 grids (12 numbers for 6 unknowns) an elastic mode fits a rigid motion
MIN_RIGID_GRIDS = 3
#: tolerance of the mass check of a fit on fewer grids: |C^T M_rr C - I| of the fitted
#: rigid motions of mass-normalised modes
RIGID_MASS_TOL = 0.05


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
    rule : str
        The evidence, in words (frequency limit and gap, the grids of the fit).
    fit_grids : int
        Grids the rigid-body fit used.
    excluded_grids : tuple of int
        Grids left out of the fit (they do not move rigidly); the exact modes keep the
        file's motion there.
    """

    count: int
    max_file_freq_hz: float
    file_freq_hz: tuple[float, ...] = ()
    max_rigid_residual: float = 0.0
    first_elastic_hz: float | None = None
    mass_source: str = ""
    rule: str = ""
    fit_grids: int = 0
    excluded_grids: tuple[int, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form: ``count`` and ``max_file_freq_hz`` are the contract."""
        return {
            "count": self.count,
            "max_file_freq_hz": self.max_file_freq_hz,
            "file_freq_hz": list(self.file_freq_hz),
            "max_rigid_residual": self.max_rigid_residual,
            "first_elastic_hz": self.first_elastic_hz,
            "mass_source": self.mass_source,
            "rule": self.rule,
            "fit_grids": self.fit_grids,
            "excluded_grids": list(self.excluded_grids),
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


def _to_local(v: np.ndarray, axes: np.ndarray | None) -> np.ndarray:
    """(g, 6, n) basic components to each grid's output system (``basic = T local``)."""
    if axes is None:
        return v
    t = np.swapaxes(axes, -1, -2)
    return np.concatenate(
        [np.einsum("gab,gbn->gan", t, v[:, :3]), np.einsum("gab,gbn->gan", t, v[:, 3:])], axis=1
    )


def _to_basic(v: np.ndarray, axes: np.ndarray | None) -> np.ndarray:
    if axes is None:
        return v
    return np.concatenate(
        [np.einsum("gab,gbn->gan", axes, v[:, :3]), np.einsum("gab,gbn->gan", axes, v[:, 3:])],
        axis=1,
    )


@dataclass(frozen=True)
class _Fit:
    coef: np.ndarray  # (6, n): phi ~ R coef on the fitted DOFs
    resid: np.ndarray  # (n,) relative residual of each mode
    grids: np.ndarray  # (g,) bool, grids kept in the fit
    rows: np.ndarray  # (g, 6) bool, DOFs fitted (output systems)
    ok: bool


def _rigid_fit(rl: np.ndarray, pl: np.ndarray, w: np.ndarray, tol: float) -> _Fit:
    """Fit ``pl`` (g, 6, n) by rigid motions ``rl`` (g, 6, 6), dropping non-rigid grids.

    DOFs zero in every mode are left out; while a mode's residual exceeds ``tol``, the grid
    with the largest share of the residual is dropped, as long as at least half the grids
    with active DOFs remain.
    """
    g = pl.shape[0]
    act = np.any(pl != 0.0, axis=2)
    grids = act.any(axis=1)
    n_active = int(grids.sum())
    a_all = rl * w[None, :, None]
    b_all = pl * w[None, :, None]
    while True:
        rows = act & grids[:, None]
        a, b = a_all[rows], b_all[rows]
        coef, *_ = np.linalg.lstsq(a, b, rcond=None)
        res = b - a @ coef
        nb = np.linalg.norm(b, axis=0)
        resid = np.where(nb > 0, np.linalg.norm(res, axis=0) / np.where(nb > 0, nb, 1.0), 1.0)
        if resid.size == 0 or float(resid.max()) < tol:
            return _Fit(coef, resid, grids, rows, True)
        if 2 * (int(grids.sum()) - 1) < n_active:
            return _Fit(coef, resid, grids, rows, False)
        share = np.zeros(g)
        owner = np.nonzero(rows)[0]
        np.add.at(share, owner, np.sum((res / np.where(nb > 0, nb, 1.0)) ** 2, axis=1))
        grids = grids.copy()
        grids[int(np.argmax(share))] = False


def _distinct(xyz: np.ndarray, scale: float) -> int:
    if xyz.shape[0] == 0:
        return 0
    return int(np.unique(np.round(xyz / (1e-9 * scale)), axis=0).shape[0])


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
    max_hz: float = RIGID_MAX_HZ,
    grid_ids: np.ndarray | None = None,
    dof_axes: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, ReplacedRigid | None, list[str]]:
    """Decide which of a free-free run's modes are rigid and replace them by exact ones.

    The rule is the module docstring's: candidates by the file's frequencies (the leading
    modes, at most 6, at or below ``max_hz`` and ``gap`` times below the next mode), confirmed
    by a least-squares rigid-body fit ``phi_j ~ R c_j`` (relative residual below ``tol``,
    rotations weighted by the model's RMS radius) on enough grids, or by the rigid-body mass.
    They are replaced by ``R C (C^T M_rr C)^(-1/2)``: exact rigid motions of the same span,
    M-orthonormal with the 6x6 rigid-body mass ``M_rr`` (from ``rigid_mass`` or ``R^T M R``
    of ``mass_matrix``); elastic modes are M-orthogonalised against them when
    ``mass_matrix`` is given.  Without a mass, the file's own normalisation of the rigid
    modes stands (they were M-orthonormal): the exact modes are ``R C`` and a warning says
    so.  At DOFs left out of the fit the exact modes are the same combination of the file's
    modes.

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
        Required ratio of the next mode's frequency to the largest rigid one.
    tol : float
        Largest relative residual of a rigid shape.
    max_hz : float
        Highest file frequency of a mode that may be replaced, Hz.
    grid_ids : ndarray (g,), optional
        Grid IDs, to name the grids left out of the fit.
    dof_axes : ndarray (g, 3, 3), optional
        Each grid's output system (columns: its axes in basic), in which a DOF the file
        leaves at zero (constrained or absent) is recognised.

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
    ids = np.arange(1, g + 1) if grid_ids is None else np.asarray(grid_ids)
    axes = None if dof_axes is None else np.asarray(dof_axes, float)
    warnings: list[str] = []
    order = np.argsort(np.abs(f), kind="stable")
    f, phi = f[order], phi[:, :, order]
    af = np.abs(f)
    omega = 2.0 * np.pi * af
    rigid = np.zeros(m, bool)
    if g == 0 or m == 0:
        return omega, phi, rigid, None, warnings
    x0 = xyz.mean(axis=0)
    lc = float(np.sqrt(np.mean(np.sum((xyz - x0) ** 2, axis=1)))) or 1.0
    R = rigid_basis_at(xyz, x0)  # (g, 6, 6), about the centroid
    rl = _to_local(R, axes)
    w = np.array([1.0, 1.0, 1.0, lc, lc, lc])
    run = 0
    while run < min(6, m) and af[run] <= max_hz:
        run += 1
    if run == 0:
        # frequencies say elastic: say so when the shapes look rigid on enough grids
        n_t = min(6, m)
        fit = _rigid_fit(rl, _to_local(phi[:, :, :n_t], axes), w, tol)
        k = 0
        while k < n_t and fit.resid[k] < tol:
            k += 1
        if k and _distinct(xyz[fit.grids], lc) >= MIN_RIGID_GRIDS:
            warnings.append(
                f"modes 1-{k} have rigid-body shapes but frequencies of "
                f"{af[0]:.4g}-{af[k - 1]:.4g} Hz, above the {max_hz:g} Hz limit for rigid-body "
                "modes: kept as elastic modes"
            )
        return omega, phi, rigid, None, warnings
    f_max = float(af[run - 1])
    f_next = float(af[run]) if run < m else None
    if f_next is not None and not f_max * gap <= f_next:
        warnings.append(
            f"modes 1-{run} are at or below {max_hz:g} Hz but their largest frequency "
            f"({f_max:.4g} Hz) is not {gap:g}x below the next mode ({f_next:.4g} Hz): "
            "kept as they are, not replaced by exact rigid-body modes"
        )
        return omega, phi, rigid, None, warnings
    pl = _to_local(phi[:, :, :run], axes)
    fit = _rigid_fit(rl, pl, w, tol)
    n_fit = int(fit.grids.sum())
    if not fit.ok:
        warnings.append(
            f"modes 1-{run} are at or below {max_hz:g} Hz but their shapes are not rigid-body "
            f"motions (fit residual {float(fit.resid.max()):.2g} on {n_fit} grids): kept as "
            "the file gives them"
        )
        return omega, phi, rigid, None, warnings
    coef = fit.coef
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
    n_pos = _distinct(xyz[fit.grids], lc)
    by_mass = False
    if n_pos < MIN_RIGID_GRIDS:
        gm = coef.T @ mrr @ coef if mrr is not None else None
        if gm is None or float(np.max(np.abs(gm - np.eye(run)))) > RIGID_MASS_TOL:
            why = (
                "no rigid-body mass to check it"
                if gm is None
                else f"the fitted motions are not M-orthonormal with the rigid-body mass "
                f"({float(np.max(np.abs(gm - np.eye(run)))):.2g})"
            )
            warnings.append(
                f"modes 1-{run} (at or below {max_hz:g} Hz) look rigid, but a rigid-body fit on "
                f"{n_pos} grid position(s) cannot confirm it (at least {MIN_RIGID_GRIDS} needed) "
                f"and {why}: kept as the file gives them"
            )
            return omega, phi, rigid, None, warnings
        by_mass = True
    u, s, vt = np.linalg.svd(coef, full_matrices=False)
    k = int(np.count_nonzero(s > 1e-6 * s[0]))
    if k < run:
        warnings.append(
            f"{run} rigid-looking modes span only {k} rigid-body motions; {run - k} kept"
        )
    p_map = np.eye(run) if k == run else vt[:k].T
    c = coef @ p_map
    s_norm = np.eye(k)
    if mrr is not None:
        s_norm = _sym_inv_sqrt(c.T @ mrr @ c)
    else:
        src = "file modes"
    c = c @ s_norm
    resid_max = float(fit.resid[:k].max())
    if mrr is None and resid_max > 1e-8:
        warnings.append(
            f"no mass given: the {k} exact rigid-body modes keep the file's normalisation "
            f"(rigid-body fit residual {resid_max:.2g}); give the mass matrix or "
            "a 6x6 rigid-body mass for an exact normalisation"
        )
    new_rigid = np.einsum("gab,bk->gak", R, c)
    if not fit.rows.all():
        # where the fit did not reach, the same combination of the file's modes
        file_comb = np.einsum("gak,kl->gal", phi[:, :, :run], p_map @ s_norm)
        nl = _to_local(new_rigid, axes)
        nl[~fit.rows] = _to_local(file_comb, axes)[~fit.rows]
        new_rigid = _to_basic(nl, axes)
    excluded = tuple(int(v) for v in ids[np.any(pl != 0.0, axis=(1, 2)) & ~fit.grids])
    if excluded:
        shown = ", ".join(str(v) for v in excluded[:10]) + (" ..." if len(excluded) > 10 else "")
        warnings.append(
            f"grid(s) {shown} do not move rigidly in the rigid-body modes (partly connected, "
            "or modal DOFs): left out of the rigid-body fit, the file's motion kept there"
        )
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
    first_el = float(af[run]) if run < m else None
    rule = (
        f"file frequencies at or below {max_hz:g} Hz"
        + (f" and {gap:g}x below the next mode" if first_el is not None else "")
        + f"; rigid-body fit on {n_fit} of {g} grids"
        + (", confirmed by the rigid-body mass" if by_mass else "")
    )
    report = ReplacedRigid(
        count=k,
        max_file_freq_hz=float(np.max(af[:k])),
        file_freq_hz=tuple(float(v) for v in f[:k]),
        max_rigid_residual=resid_max,
        first_elastic_hz=first_el,
        mass_source=src,
        rule=rule,
        fit_grids=n_fit,
        excluded_grids=excluded,
    )
    return omega_out, phi_out, rigid, report, warnings
