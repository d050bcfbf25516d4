"""A modal model as a :class:`~microg.structure.Structure` in modal coordinates.

The coordinates are the model's mass-normalised modal coordinates ``eta`` (m sqrt(kg)), so
``M = I`` and ``K = diag(omega^2)`` exactly.  A point riding on grid ``g`` at offset ``d``
moves by ``u = u_g + theta_g x d``: its translation map is ``phi_T[g] - [d]x phi_R[g]``
(3, m) and its rotation map ``phi_R[g]`` (3, m), the same rigid-offset rule as the frame
elements (:func:`microg.structure.elements.rigid_link`).

The exact rigid-body vectors: the rigid modes are exact rigid motions ``phi_r = R0 A``
(``R0`` the unit rigid motions about the basic origin,
:func:`microg.models.rigid_modes.rigid_basis_at`), so a unit rigid motion ``e_d`` is the
coordinate vector with ``A q = e_d`` on the rigid modes and 0 elsewhere; ``K`` annihilates
it exactly (its diagonal is exactly 0 there). The rigid-body mass is ``(A A^T)^-1`` (from
``A^T M_rr A = I``).

Point maps are built only for the points asked for: :class:`GridPointMaps` lists the
named points and the requested grids, and builds the map of any other ``grid:N`` on first
access, so a 20,000-grid model observed at 10 grids never forms maps for all grids.
The samples (:class:`ModalSamples`, the grids) are views of the model; the rigid-body
coefficients are fitted at a few grids and verified at all of them (``O(grids)``).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence

import numpy as np

from microg.errors import InputError, ModelError
from microg.models.modal import ModalModel
from microg.models.rigid_modes import rigid_basis_at
from microg.structure.structure import PointMap, Structure

__all__ = [
    "GRID_COMPONENT",
    "RIGID_FIT_GRIDS",
    "GridPointMaps",
    "ModalSamples",
    "modal_structure",
    "rigid_coefficients",
]

_DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")
#: grids per block of the shape-peak pass (a block of |phi_t| stays in cache)
_PEAK_BLOCK = 512


def _skew(d: np.ndarray) -> np.ndarray:
    s = np.zeros((3, 3))
    s[0, 1], s[0, 2], s[1, 0], s[1, 2], s[2, 0], s[2, 1] = -d[2], d[1], d[2], -d[0], -d[1], d[0]
    return s


class GridPointMaps(Mapping[str, PointMap]):
    """Point maps of a modal model, built on demand.

    Iterates over the named points and the grids asked for; ``maps["grid:N"]`` works for
    every grid of the model (an unknown grid is an :class:`InputError` listing the nearest
    IDs).
    """

    def __init__(self, model: ModalModel, names: Sequence[str]):
        self._model = model
        self._names = list(dict.fromkeys(names))
        self._cache: dict[str, PointMap] = {}

    def __getitem__(self, name: str) -> PointMap:
        if name in self._cache:
            return self._cache[name]
        p = self._model.point(name)
        i = self._model.grid_index(p.grid, where=name)
        phi = self._model.phi[i]
        off = np.asarray(p.offset_m, float)
        rot = phi[3:, :]
        tr = phi[:3, :] - _skew(off) @ rot if np.any(off) else phi[:3, :]
        pm = PointMap(
            name=name,
            position=self._model.xyz_m[i] + off,
            translation=tr,
            rotation=rot,
        )
        self._cache[name] = pm
        return pm

    def __contains__(self, name: object) -> bool:
        if not isinstance(name, str):
            return False
        try:
            self._model.point(name)
        except InputError:
            return False
        return True

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)


#: the carrier of a modal model's grids in acceleration maps (no element connectivity)
GRID_COMPONENT = "grids"
#: at most this many grids determine the rigid-body coefficients (all grids verify them)
RIGID_FIT_GRIDS = 64


class ModalSamples:
    """The grids of a modal model as samples (maps, plots, modal-mass peaks), built lazily.

    Nothing is copied: positions and translations are views of the model's arrays, and
    labels are formed on first use.  :meth:`displacement` multiplies by the coordinates'
    nonzero entries only, so the modes of the diagonal modal structure (a signed
    permutation, mixed only within the rigid block) cost ``O(grids x modes)``, not
    ``O(grids x modes^2)``; :meth:`peak_translation` gives the largest translation of each
    mode without forming the displacements at all.

    Attributes
    ----------
    position : ndarray (g, 3)
        Grid positions, m.
    labels : tuple of str
        ``"grid:N"``.
    component : ndarray (g,) of str
        :data:`GRID_COMPONENT` for every grid (a modal model has no element connectivity).
    phi_t : ndarray (g, 3, m)
        Translational rows of the mode shapes (a view of ``model.phi``).
    """

    def __init__(self, model: ModalModel):
        self._model = model
        self._labels: tuple[str, ...] | None = None
        self._peaks: dict[str, np.ndarray] = {}
        self._last_q: tuple[np.ndarray, dict[str, np.ndarray]] | None = None

    @property
    def position(self) -> np.ndarray:
        """Grid positions, m (g, 3)."""
        return self._model.xyz_m

    @property
    def phi_t(self) -> np.ndarray:
        """Translational rows of the shapes (g, 3, m), a view."""
        return self._model.phi[:, :3, :]

    @property
    def labels(self) -> tuple[str, ...]:
        """``"grid:N"`` of every grid."""
        if self._labels is None:
            self._labels = tuple(f"grid:{g}" for g in self._model.grid_ids.tolist())
        return self._labels

    @property
    def component(self) -> np.ndarray:
        """The carrier of every grid, :data:`GRID_COMPONENT`."""
        return np.full(self._model.n_grids, GRID_COMPONENT)

    def __len__(self) -> int:
        return self._model.n_grids

    def displacement(self, q: np.ndarray) -> np.ndarray:
        """Grid translations, m: (g, 3) for q (m,), (g, 3, k) for q (m, k).

        Columns of ``q`` with one nonzero entry are a scaled shape (bit for bit the dense
        product); the others are multiplied over their nonzero rows only.
        """
        q = np.asarray(q, float)
        pt = self.phi_t
        if q.ndim == 1:
            return np.asarray(pt @ q)
        nz = q != 0
        count = nz.sum(axis=0)
        single = np.flatnonzero(count == 1)
        r = np.argmax(nz[:, single], axis=0)
        if q.shape[0] == q.shape[1] and np.array_equal(r, single):
            # the single entries are on the diagonal (the modal structure's own modes): one
            # streaming product, the other columns zero until set below
            scale = np.zeros(q.shape[1])
            scale[single] = q[single, single]
            out = pt * scale
        else:
            out = np.zeros((pt.shape[0], 3, q.shape[1]))
            if single.size:
                out[:, :, single] = pt[:, :, r] * q[r, single]
        multi = np.flatnonzero(count > 1)
        if multi.size:
            rows = np.flatnonzero(nz[:, multi].any(axis=1))
            out[:, :, multi] = pt[:, :, rows] @ q[np.ix_(rows, multi)]
        return out

    def shape_peaks(self, part: str = "translation") -> np.ndarray:
        """Largest |translation| (or |rotation|, rad) of each shape over grids and axes (m,)."""
        if part not in self._peaks:
            # both parts in one pass over the shapes, in blocks of grids: no (g, 6, m)
            # temporary of |phi| (max commutes with blocks; max |x| = max(max x, -min x))
            phi = self._model.phi
            rows = phi.shape[1]
            hi = np.full((rows, phi.shape[2]), -np.inf)
            lo = np.full((rows, phi.shape[2]), np.inf)
            for i in range(0, phi.shape[0], _PEAK_BLOCK):
                block = phi[i : i + _PEAK_BLOCK]
                np.maximum(hi, block.max(axis=0), out=hi)
                np.minimum(lo, block.min(axis=0), out=lo)
            per_row = np.maximum(hi, -lo) if phi.shape[0] else np.zeros_like(hi)
            self._peaks["translation"] = per_row[:3].max(axis=0)
            rot = per_row[3:6]
            self._peaks["rotation"] = rot.max(axis=0) if rot.shape[0] else np.zeros(phi.shape[2])
        return self._peaks[part]

    def peak_translation(self, q: np.ndarray) -> np.ndarray:
        """``max over grids and axes of |displacement(q)|`` per column of q (k,).

        Exact: for a column with one nonzero entry ``q_rj`` it is ``|q_rj|`` times the
        shape's own peak (rounding is monotone, so the maximum commutes with the scaling);
        other columns are formed over their nonzero rows.
        """
        return self._peak_of(q, "translation")

    def peak_rotation(self, q: np.ndarray) -> np.ndarray:
        """``max over grids and axes of |rotation(q)|`` per column of q, rad (k,).

        As :meth:`peak_translation`; zeros when the model's shapes carry no rotations.
        """
        return self._peak_of(q, "rotation")

    def _peak_of(self, q: np.ndarray, part: str) -> np.ndarray:
        q = np.asarray(q, float).reshape(self._model.n_modes, -1)
        if part == "rotation" and self._model.phi.shape[1] < 6:
            return np.zeros(q.shape[1])
        last = self._last_q
        if last is None or last[0].shape != q.shape or not np.array_equal(last[0], q):
            last = (q.copy(), self._motion_peaks(q))
            self._last_q = last
        return last[1][part]

    def _motion_peaks(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """Translation and rotation peaks of every column of q, both from one pass."""
        nz = q != 0
        count = nz.sum(axis=0)
        out = {part: np.zeros(q.shape[1]) for part in ("translation", "rotation")}
        single = np.flatnonzero(count == 1)
        if single.size:
            r = np.argmax(nz[:, single], axis=0)
            for part, peak in out.items():
                peak[single] = np.abs(q[r, single]) * self.shape_peaks(part)[r]
        multi = np.flatnonzero(count > 1)
        if multi.size:
            rows = np.flatnonzero(nz[:, multi].any(axis=1))
            phi = self._model.phi
            # one gather of all six rows (a slice when the rows are consecutive: a view)
            consecutive = rows.size == rows[-1] - rows[0] + 1
            sub = phi[:, :, rows[0] : rows[-1] + 1] if consecutive else phi[:, :, rows]
            motion = np.abs(sub @ q[np.ix_(rows, multi)])  # (g, 6, k)
            out["translation"][multi] = np.max(motion[:, :3], axis=(0, 1), initial=0.0)
            if phi.shape[1] >= 6:
                out["rotation"][multi] = np.max(motion[:, 3:6], axis=(0, 1), initial=0.0)
        return out


def _fit_grids(xyz: np.ndarray) -> np.ndarray:
    """Up to RIGID_FIT_GRIDS grid rows spread over the model (its extremes included)."""
    g = xyz.shape[0]
    if g <= RIGID_FIT_GRIDS:
        return np.arange(g)
    ext = np.r_[np.argmin(xyz, axis=0), np.argmax(xyz, axis=0)]
    spread = np.linspace(0, g - 1, RIGID_FIT_GRIDS - ext.size).astype(int)
    return np.unique(np.r_[ext, spread])


def rigid_coefficients(model: ModalModel) -> np.ndarray:
    """``A`` (6, k) with ``phi_rigid = R0 A`` exactly (R0 about the basic origin).

    ``A`` is the least-squares fit at up to :data:`RIGID_FIT_GRIDS` grids (one grid
    already determines it: ``R0`` of a grid is invertible); the fit is verified at every
    grid that moves rigidly: the grids the reader left out of its rigid-body fit
    (``replaced_rigid.excluded_grids``: partly connected grids, modal DOFs), where the
    file's motion is kept, are left out here too, and so are DOFs zero in every mode (not
    in the file).  Raises ModelError when the rigid modes are not rigid-body motions of
    the other grids.
    """
    idx = np.flatnonzero(model.rigid)
    if idx.size == 0:
        return np.zeros((6, 0))
    excluded = () if model.replaced_rigid is None else model.replaced_rigid.excluded_grids
    keep = ~np.isin(model.grid_ids, np.asarray(excluded, dtype=np.int64))
    if not keep.any():
        keep[:] = True
    xyz, phi = model.xyz_m[keep], model.phi[keep]
    # DOFs zero in every mode are not in the file (a partly output grid): not fitted
    act = np.any(phi != 0.0, axis=2)  # (g, 6)
    if not act.any():
        act[:] = True
    sub = _fit_grids(xyz)
    r_sub = rigid_basis_at(xyz[sub])[act[sub]]
    a, *_ = np.linalg.lstsq(r_sub, phi[sub][:, :, idx][act[sub]], rcond=None)
    pr = phi[:, :, idx]  # (g, 6, k)
    # R0 a at every grid: translation a_t + a_r x x_g, rotation a_r
    x = xyz[:, :, None]
    ar = a[3:][None, :, :]
    pred_t = a[:3][None] + np.cross(ar, x, axisa=1, axisb=1, axisc=1)
    pred = np.concatenate([pred_t, np.broadcast_to(ar, pred_t.shape)], axis=1)
    err = np.sqrt(np.sum(((pr - pred) * act[:, :, None]) ** 2)) / max(
        float(np.linalg.norm(pr)), 1e-300
    )
    if err > 1e-8:
        raise ModelError(
            f"the modes marked rigid are not rigid-body motions of the grids (residual {err:.2g})",
            where=model.source or "modal model",
            fix="read the model with rigid-mode replacement on",
        )
    return np.asarray(a)


def modal_structure(
    model: ModalModel, points: Sequence[str] | None = None, *, samples: bool = True
) -> Structure:
    """Structure of ``model`` in its modal coordinates (see the module docstring).

    Parameters
    ----------
    model : ModalModel
    points : sequence of str, optional
        Names (named points or ``grid:N``) to list in ``Structure.points``; default the
        model's named points.  Any other ``grid:N`` still resolves on access.
    samples : bool
        Attach :class:`ModalSamples` of all grids (views of the model, nothing copied):
        the acceleration maps, plots and the modal-mass peak of
        :func:`microg.dynamics.modes.solve_modes` over every grid (one pass over the
        shapes, ``O(grids x modes)``).  False: the named points and ``points`` only.

    Returns
    -------
    Structure
        ``method = "modal"``, ``M = I``, ``K = diag(omega^2)``.
    """
    m = model.n_modes
    if m == 0:
        raise ModelError("the model has no modes", where=model.source or "modal model")
    names = [p.name for p in model.points] if points is None else list(points)
    maps = GridPointMaps(model, names)
    for n in names:
        maps[n]  # validate now: an unknown name is one clear error
    a = rigid_coefficients(model)
    idx = np.flatnonzero(model.rigid)
    rigid_body: dict[str, np.ndarray] = {}
    for j, d in enumerate(_DIRECTIONS):
        if idx.size == 0:
            break
        e = np.zeros(6)
        e[j] = 1.0
        q, *_ = np.linalg.lstsq(a, e, rcond=None)
        if np.linalg.norm(a @ q - e) <= 1e-9:
            v = np.zeros(m)
            v[idx] = q
            rigid_body[d] = v
    total, cm, inertia = _mass_properties(model, a)
    return Structure(
        mass=np.eye(m),
        stiffness=np.diag(model.omega**2),
        dof_labels=tuple(f"mode:{j + 1}" for j in range(m)),
        points=maps,
        rigid_body=rigid_body,
        method="modal",
        plane=None,
        total_mass=total,
        center_of_mass=cm,
        inertia_cm=inertia,
        samples=ModalSamples(model) if samples else None,
        meta={
            "model": model.name,
            "source": model.source,
            "n_grids": model.n_grids,
            "units": model.units.to_dict(),
            "replaced_rigid": None
            if model.replaced_rigid is None
            else model.replaced_rigid.to_dict(),
            "warnings": list(model.warnings),
            "node_positions": model.xyz_m,
        },
    )


def _mass_properties(model: ModalModel, a: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass, centre of mass and inertia about it from the rigid-body mass."""
    if a.shape[1] == 6:
        mrr = np.linalg.inv(a @ a.T)
    elif model.rigid_mass is not None:
        mrr = np.asarray(model.rigid_mass, float)
    else:
        return float("nan"), np.full(3, np.nan), np.full((3, 3), np.nan)
    mrr = 0.5 * (mrr + mrr.T)
    total = float(np.trace(mrr[:3, :3]) / 3.0)
    c = -mrr[:3, 3:] / total  # = [cm]x
    cm = np.array([c[2, 1], c[0, 2], c[1, 0]])
    inertia = mrr[3:, 3:] - total * (np.dot(cm, cm) * np.eye(3) - np.outer(cm, cm))
    return total, cm, inertia
