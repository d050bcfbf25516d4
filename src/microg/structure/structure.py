"""The structural model: generalized mass and stiffness, and maps from coordinates to points.

A :class:`Structure` is what both discretisations (assumed modes in :mod:`microg.structure.ritz`,
frame finite elements in :mod:`microg.structure.fem`) produce, and what
:mod:`microg.dynamics.modes` and
:mod:`microg.dynamics.response` consume.  All values are SI.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = ["PointMap", "Structure"]

Matrix = Any  # numpy.ndarray or scipy.sparse matrix


def _issparse(a: Any) -> bool:
    """``scipy.sparse.issparse(a)``, without importing scipy for a dense structure.

    A scipy sparse matrix cannot exist before :mod:`scipy.sparse` is imported, so when it is
    not loaded the answer is False (the Ritz and modal structures never load it).
    """
    sp = sys.modules.get("scipy.sparse")
    return sp is not None and bool(sp.issparse(a))


@dataclass(frozen=True)
class PointMap:
    """Linear map from generalized coordinates q to the motion of one material point.

    Attributes
    ----------
    name : str
        Point name (a named point of the model, or a sample label).
    position : ndarray, shape (3,)
        Undeformed position in the station frame, m.
    translation : ndarray, shape (3, n)
        Displacement (x, y, z) in m per unit of each coordinate.
    rotation : ndarray, shape (3, n)
        Small rotation (about x, y, z) in rad per unit of each coordinate.
    """

    name: str
    position: np.ndarray
    translation: np.ndarray
    rotation: np.ndarray


@dataclass(frozen=True)
class Structure:
    """Generalized mass and stiffness of a station, with maps to its points.

    Attributes
    ----------
    mass : ndarray or sparse, shape (n, n)
        Generalized mass matrix (symmetric positive definite; positive semi-definite for
        a sparse frame model that keeps its massless DOFs as coordinates), SI.
    stiffness : ndarray or sparse, shape (n, n)
        Generalized stiffness matrix (symmetric positive semi-definite), SI.
    dof_labels : tuple of str
        One label per coordinate.
    points : mapping of str to PointMap
        The model's named points of interest.
    rigid_body : mapping of str to ndarray (n,)
        Exact coordinate vectors of unit rigid-body motions of the whole station, rotations
        about its centre of mass (frame and modal models; the report's assumed modes turn
        about the origin): ``"x"``, ``"y"``, ``"z"`` (1 m translation) and ``"rx"``, ``"ry"``,
        ``"rz"`` (1 rad rotation), those the discretisation can represent.  Those that ``K``
        annihilates are the exact zero-frequency modes; a rotation restrained by gravity
        gradient is not.
    method : str
        ``"ritz"`` or ``"fem"``.
    plane : str or None
        ``"xz"``/``"yz"`` for the report's planar analyses, None for 3-D.
    total_mass : float
        Station mass, kg.
    center_of_mass : ndarray, shape (3,)
        m, in the station frame.
    inertia_cm : ndarray, shape (3, 3)
        Inertia tensor about the centre of mass, kg m^2.
    samples : PointMap or None
        Optional dense sampling of the structure for maps and plots: a PointMap-like object
        whose ``translation`` has shape (p, 3, n) and ``position`` shape (p, 3).
    meta : mapping
        Free-form provenance (model name, source file, discretisation parameters).
    """

    mass: Matrix
    stiffness: Matrix
    dof_labels: tuple[str, ...]
    points: Mapping[str, PointMap]
    rigid_body: Mapping[str, np.ndarray]
    method: str
    plane: str | None
    total_mass: float
    center_of_mass: np.ndarray
    inertia_cm: np.ndarray
    samples: Any = None
    meta: Mapping[str, Any] = field(default_factory=dict)

    @property
    def n_dof(self) -> int:
        """Number of generalized coordinates."""
        return int(self.mass.shape[0])

    @property
    def is_sparse(self) -> bool:
        """True when the matrices are scipy sparse."""
        return _issparse(self.mass)

    def point(self, name: str) -> PointMap:
        """The named point's map; an unknown name is an :class:`InputError` listing the known."""
        try:
            return self.points[name]
        except KeyError:
            known = ", ".join(sorted(self.points)) or "(none)"
            raise InputError(f"unknown point {name!r}", fix=f"known points: {known}") from None

    def dense(self) -> tuple[np.ndarray, np.ndarray]:
        """Mass and stiffness as dense arrays."""
        m = self.mass.toarray() if _issparse(self.mass) else np.asarray(self.mass)
        k = self.stiffness.toarray() if _issparse(self.stiffness) else np.asarray(self.stiffness)
        return m, k
