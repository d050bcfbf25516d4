"""A modal model as a :class:`~microg.structure.Structure` in modal coordinates.

The coordinates are the model's mass-normalised modal coordinates ``eta`` (m sqrt(kg)), so
``M = I`` and ``K = diag(omega^2)`` exactly.  A point riding on grid ``g`` at offset ``d``
moves by ``u = u_g + theta_g x d``: its translation map is ``phi_T[g] - [d]x phi_R[g]``
(3, m) and its rotation map ``phi_R[g]`` (3, m), the same rigid-offset rule as the frame
elements (:func:`microg.structure.fem.rigid_link`).

The exact rigid-body vectors: the rigid modes are exact rigid motions ``phi_r = R0 A``
(``R0`` the unit rigid motions about the basic origin, :func:`microg.models.modal.rigid_basis_at`),
so a unit rigid motion ``e_d`` is the coordinate vector with ``A q = e_d`` on the rigid
modes and 0 elsewhere; ``K`` annihilates it exactly (its diagonal is exactly 0 there).
The rigid-body mass is ``(A A^T)^-1`` (from ``A^T M_rr A = I``).

Point maps are built only for the points asked for: :class:`GridPointMaps` lists the
named points and the requested grids, and builds the map of any other ``grid:N`` on first
access, so a 20,000-grid model observed at 10 grids never forms maps for all grids.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from microg.errors import InputError, ModelError
from microg.models.modal import ModalModel, rigid_basis_at
from microg.structure.structure import PointMap, Structure

__all__ = ["GridPointMaps", "ModalSamples", "modal_structure", "rigid_coefficients"]

_DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")


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


@dataclass(frozen=True)
class ModalSamples:
    """Translations of every grid from modal coordinates (maps and plots).

    Attributes
    ----------
    position : ndarray (g, 3)
        Grid positions, m.
    labels : tuple of str
        ``"grid:N"``.
    phi_t : ndarray (g, 3, m)
        Translational rows of the mode shapes.
    """

    position: np.ndarray
    labels: tuple[str, ...]
    phi_t: np.ndarray

    def __len__(self) -> int:
        return int(self.position.shape[0])

    def displacement(self, q: np.ndarray) -> np.ndarray:
        """Grid translations, m: (g, 3) for q (m,), (g, 3, k) for q (m, k)."""
        return np.asarray(self.phi_t @ np.asarray(q, float))


def rigid_coefficients(model: ModalModel) -> np.ndarray:
    """``A`` (6, k) with ``phi_rigid = R0 A`` exactly (R0 about the basic origin).

    Raises ModelError when the rigid modes are not rigid-body motions of the grids.
    """
    idx = np.flatnonzero(model.rigid)
    if idx.size == 0:
        return np.zeros((6, 0))
    R0 = rigid_basis_at(model.xyz_m).reshape(-1, 6)
    pr = model.phi[:, :, idx].reshape(-1, idx.size)
    a, *_ = np.linalg.lstsq(R0, pr, rcond=None)
    err = np.linalg.norm(pr - R0 @ a) / max(np.linalg.norm(pr), 1e-300)
    if err > 1e-8:
        raise ModelError(
            f"the modes marked rigid are not rigid-body motions of the grids (residual {err:.2g})",
            where=model.source or "modal model",
            fix="read the model with rigid-mode replacement on",
        )
    return a


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
        Attach :class:`ModalSamples` of all grids (maps, plots, the modal-mass peak of
        :func:`microg.dynamics.modes.solve_modes`, which then costs O(grids x modes^2));
        False for an analysis at a few points of a large model.

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
        samples=ModalSamples(
            position=model.xyz_m,
            labels=tuple(f"grid:{g}" for g in model.grid_ids),
            phi_t=model.phi[:, :3, :],
        )
        if samples
        else None,
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
