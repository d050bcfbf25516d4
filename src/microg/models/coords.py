"""Coordinate systems: the one frame class and the one CORD2R/C/S chaining.

A :class:`CoordinateFrame` is a rectangular, cylindrical or spherical system given by its
origin and axes in the basic (station) frame.  Graph models keep the frames their nodes
were written in (:mod:`microg.models.graph_model`); a NASTRAN deck's CORD2R/C/S cards
(:mod:`microg.models.bdf`) and an OP2's GEOM1 coordinate records (:mod:`microg.models.op2`)
become frames through :func:`chain_cord2`, which resolves each system's reference system
(RID) first, as NASTRAN does (MSC Nastran Quick Reference Guide, CORD2R/CORD2C/CORD2S:
point A the origin, B on the z axis, C in the x-z plane, all three in system RID).

Coordinates inside a frame are lengths and radians: rectangular ``(x, y, z)``, cylindrical
``(r, theta, z)``, spherical ``(r, theta, phi)`` with theta from the z axis and phi about z
from x.  NASTRAN writes angles in degrees: :func:`nastran_coordinates` converts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from microg.errors import InputError

__all__ = [
    "BASIC",
    "FRAME_KINDS",
    "NASTRAN_KINDS",
    "Cord2",
    "CoordinateFrame",
    "chain_cord2",
    "frame_from_points",
    "nastran_coordinates",
]

#: kinds of coordinate frame
FRAME_KINDS = ("rectangular", "cylindrical", "spherical")
#: the kind of each NASTRAN system letter (CORD2R, CORD2C, CORD2S)
NASTRAN_KINDS = {"R": "rectangular", "C": "cylindrical", "S": "spherical"}


@dataclass(frozen=True)
class CoordinateFrame:
    """A coordinate system: rectangular, cylindrical or spherical (NASTRAN CORD2R/C/S).

    Attributes
    ----------
    name : str
        ``"cs:3"`` for NASTRAN coordinate system 3.
    kind : {"rectangular", "cylindrical", "spherical"}
    origin : ndarray (3,)
        Origin in the basic frame, m (or the length unit of the file it was read from).
    rotation : ndarray (3, 3)
        Rows: the unit x, y, z axes of the system in the basic frame.
    """

    name: str
    kind: str
    origin: np.ndarray
    rotation: np.ndarray

    def to_basic(self, coords: np.ndarray) -> np.ndarray:
        """Basic-frame positions of points given in this system, (..., 3).

        Parameters
        ----------
        coords : ndarray (..., 3)
            Rectangular ``(x, y, z)``; cylindrical ``(r, theta, z)``; spherical
            ``(r, theta, phi)`` (NASTRAN's: theta from the z axis, phi about z from x);
            lengths in the unit of :attr:`origin` (m), angles in rad.
        """
        c = np.asarray(coords, float)
        if self.kind == "cylindrical":
            r, th, z = c[..., 0], c[..., 1], c[..., 2]
            local = np.stack([r * np.cos(th), r * np.sin(th), z], axis=-1)
        elif self.kind == "spherical":
            r, th, ph = c[..., 0], c[..., 1], c[..., 2]
            local = np.stack(
                [r * np.sin(th) * np.cos(ph), r * np.sin(th) * np.sin(ph), r * np.cos(th)], -1
            )
        else:
            local = c
        return self.origin + local @ self.rotation

    def axes_at(self, position: np.ndarray) -> np.ndarray:
        """Unit axes (rows) of the system's components 1, 2, 3 at basic ``position``, (…, 3, 3).

        Rectangular: the fixed axes.  Cylindrical: radial, tangential, axial.  Spherical:
        radial, meridional (theta), azimuthal (phi).  On the axis (r = 0) the angles are
        taken as 0, NASTRAN's convention.

        Parameters
        ----------
        position : ndarray (..., 3)
            Basic-frame points, in the unit of :attr:`origin` (m).
        """
        p = np.asarray(position, float)
        local = (p - self.origin) @ self.rotation.T
        shape = (*local.shape[:-1], 3, 3)
        if self.kind == "rectangular":
            return np.broadcast_to(self.rotation, shape).copy()
        x, y, z = local[..., 0], local[..., 1], local[..., 2]
        ph = np.arctan2(y, x)
        zero = np.zeros_like(ph)
        one = np.ones_like(ph)
        if self.kind == "cylindrical":
            rows = [
                np.stack([np.cos(ph), np.sin(ph), zero], -1),
                np.stack([-np.sin(ph), np.cos(ph), zero], -1),
                np.stack([zero, zero, one], -1),
            ]
        else:
            th = np.arctan2(np.hypot(x, y), z)
            rows = [
                np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1),
                np.stack([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), -np.sin(th)], -1),
                np.stack([-np.sin(ph), np.cos(ph), zero], -1),
            ]
        return np.stack(rows, axis=-2) @ self.rotation

    def vector_to_basic(self, vector: np.ndarray, at: np.ndarray) -> np.ndarray:
        """Basic components of a vector given by its components along the axes at ``at``.

        Parameters
        ----------
        vector : ndarray (3,)
            Components along the system's axes 1, 2, 3 at ``at`` (any unit, kept).
        at : ndarray (3,)
            Basic-frame point, in the unit of :attr:`origin` (m).
        """
        return np.asarray(vector, float) @ self.axes_at(at)


#: the basic (station) frame
BASIC = CoordinateFrame("basic", "rectangular", np.zeros(3), np.eye(3))


def frame_from_points(
    name: str, kind: str, a: np.ndarray, b: np.ndarray, c: np.ndarray, *, where: str
) -> CoordinateFrame:
    """The frame with origin ``a``, z axis towards ``b`` and ``c`` in the x-z plane (CORD2x).

    ``e_z = (b - a)/|b - a|``; ``e_x`` is ``c - a`` made perpendicular to ``e_z``;
    ``e_y = e_z x e_x`` (the CORD2R/C/S construction of the NASTRAN Quick Reference Guide).

    Parameters
    ----------
    name : str
    kind : {"rectangular", "cylindrical", "spherical"}
    a, b, c : ndarray (3,)
        Points A, B, C in the basic frame, m (or a file's length unit).
    where : str
        Where the points were read, for errors.

    Raises
    ------
    InputError
        Coincident A and B, or C on the line A-B (relative tolerances 1e-12 of the points'
        size and 1e-9 of ``|c - a|``).
    """
    a, b, c = (np.asarray(v, float) for v in (a, b, c))
    ez = b - a
    nz = float(np.linalg.norm(ez))
    scale = max(float(np.max(np.abs(np.concatenate([a, b, c])))), nz, 1e-300)
    if nz <= 1e-12 * scale:
        raise InputError("points A and B coincide", where=where, fix="give B off the origin A")
    ez = ez / nz
    ex = (c - a) - float(np.dot(c - a, ez)) * ez
    nx = float(np.linalg.norm(ex))
    if nx <= 1e-9 * max(float(np.linalg.norm(c - a)), 1e-300) or nx <= 1e-12 * scale:
        raise InputError(
            "point C lies on the z axis A-B", where=where, fix="give C off the line through A, B"
        )
    ex = ex / nx
    ey = np.cross(ez, ex)
    return CoordinateFrame(name, kind, a, np.stack([ex, ey, ez]))


def nastran_coordinates(kind: str, values: np.ndarray, length: float = 1.0) -> np.ndarray:
    """NASTRAN coordinates (angles in degrees) as a frame's coordinates (angles in rad).

    Parameters
    ----------
    kind : {"rectangular", "cylindrical", "spherical"}
        The kind of the system the values are given in.
    values : ndarray (..., 3)
        Rectangular ``(x, y, z)``, cylindrical ``(r, theta deg, z)`` or spherical
        ``(r, theta deg, phi deg)``, lengths in the file's unit.
    length : float
        SI value of the file's length unit, m (1: keep the file's unit).

    Returns
    -------
    ndarray (..., 3)
        Lengths times ``length``, angles in rad.
    """
    v = np.array(values, float)
    if kind == "rectangular":
        return v * length
    out = v.copy()
    out[..., 0] *= length
    out[..., 1] = np.radians(v[..., 1])
    if kind == "cylindrical":
        out[..., 2] *= length
    else:
        out[..., 2] = np.radians(v[..., 2])
    return out


@dataclass(frozen=True)
class Cord2:
    """One CORD2R/C/S definition as written: points A, B, C in its reference system.

    Attributes
    ----------
    cid : int
        The system's id (> 0).
    kind : {"rectangular", "cylindrical", "spherical"}
    rid : int
        The reference system the points are given in (0: basic).
    points : ndarray (3, 3)
        Rows A, B, C in the coordinates of system ``rid`` (file length unit, degrees).
    where : str
        Where it was read (``deck.bdf:12: CORD2R 3``), for errors.
    """

    cid: int
    kind: str
    rid: int
    points: np.ndarray
    where: str


def chain_cord2(defs: Sequence[Cord2], *, length: float = 1.0) -> dict[int, CoordinateFrame]:
    """Frames of CORD2R/C/S definitions, each resolved after its reference system (RID).

    Parameters
    ----------
    defs : sequence of Cord2
        Unique ids; any order (references are followed, as NASTRAN does).
    length : float
        SI value of the file's length unit, m (1: frames in the file's unit).

    Returns
    -------
    dict of int to CoordinateFrame
        Every system by id, and 0, the basic frame; frame names ``"cs:ID"``.

    Raises
    ------
    InputError
        At a definition (its ``where``): id 0, a reference system not defined, references
        in a cycle, or points A, B, C that define no axes.
    """
    frames: dict[int, CoordinateFrame] = {0: BASIC}
    pending = {d.cid: d for d in defs}
    known = set(pending)
    for d in defs:
        if d.cid == 0:
            raise InputError(
                "coordinate system 0 is the basic system", where=d.where, fix="use another id"
            )
        if d.rid != 0 and d.rid not in known:
            raise InputError(
                f"reference system {d.rid} is not defined",
                where=d.where,
                fix="define it or use RID 0",
            )
    while pending:
        ready = [d for d in pending.values() if d.rid in frames]
        if not ready:
            first = next(iter(pending.values()))
            raise InputError(
                "coordinate systems reference each other in a cycle",
                where=first.where,
                fix="break the RID chain",
            )
        for d in ready:
            ref = frames[d.rid]
            pts = ref.to_basic(nastran_coordinates(ref.kind, d.points, length))
            frames[d.cid] = frame_from_points(f"cs:{d.cid}", d.kind, *pts, where=d.where)
            del pending[d.cid]
    return frames
