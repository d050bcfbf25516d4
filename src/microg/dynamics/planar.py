"""Which modes of a 3-D model are in a plane: the share of kinetic energy in it."""

from __future__ import annotations

import numpy as np

from microg.dynamics.modes import Modes
from microg.errors import InputError
from microg.structure.structure import Structure

__all__ = ["PLANE_DOFS", "in_plane_fraction", "in_plane_modes"]

#: coordinates of a frame node that move in each plane: translations in it, rotation about
#: its normal
PLANE_DOFS = {"xz": ("ux", "uz", "ry"), "yz": ("uy", "uz", "rx")}


def in_plane_fraction(structure: Structure, modes: Modes, plane: str) -> np.ndarray:
    """Share of each mode's kinetic energy carried by motion in ``plane``.

    ``sum over in-plane coordinates i of phi_i (M phi)_i`` (the whole sum is
    ``phi^T M phi = 1``).  For a frame model the in-plane coordinates are the node
    translations in the plane and rotations about its normal (:data:`PLANE_DOFS`); an
    assumed-modes planar model is all in its own plane.  (Modal effective masses cannot do
    this job: an elastic mode of a free-free structure is M-orthogonal to the rigid-body
    vectors, so its effective masses are zero.)

    Parameters
    ----------
    structure : Structure
    modes : Modes
        Mass-normalised modes of ``structure``.
    plane : {"xz", "yz"}

    Returns
    -------
    ndarray (m,)
        Fractions in [0, 1].
    """
    if plane not in PLANE_DOFS:
        raise InputError(f"unknown plane {plane!r}", where="plane", fix="use xz or yz")
    m = modes.n_modes
    if structure.plane is not None:
        return np.full(m, 1.0 if structure.plane == plane else 0.0)
    suffix = np.array([lab.rsplit(":", 1)[-1] for lab in structure.dof_labels])
    inplane = np.isin(suffix, PLANE_DOFS[plane])
    if not inplane.any():
        raise InputError(
            "the model's coordinates are not node translations and rotations",
            where="plane",
            fix="a plane filter applies to frame models",
        )
    energy = np.asarray(modes.phi * (structure.mass @ modes.phi))
    return np.clip(energy[inplane].sum(axis=0), 0.0, 1.0)


def in_plane_modes(structure: Structure, modes: Modes, plane: str, count: int) -> Modes:
    """The first ``count`` modes with more than half their kinetic energy in ``plane``."""
    keep = np.flatnonzero(in_plane_fraction(structure, modes, plane) > 0.5)[:count]
    return modes.subset(keep)
