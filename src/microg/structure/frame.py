"""General frame finite elements: a graph model assembled into a free-free Structure.

:func:`build_frame` turns a :class:`~microg.models.graph.GraphModel` (closed loops allowed)
into a :class:`~microg.structure.Structure`.  Coordinates are the 6 DOFs of each node
(translations and small rotations in the basic frame), after the exact elimination of rigid
links and interpolation elements and of the DOFs that carry no mass.

Elements (pure kernels below; the Euler-Bernoulli frame matrices, rotations, rigid links
and point masses are those of :mod:`microg.structure.fem`, imported, not copied):

* **Beams** (NASTRAN CBAR/CBEAM).  Timoshenko stiffness: the cubic element with the shear
  parameter ``phi = 12 EI / (k G A L^2)`` per plane (Przemieniecki, *Theory of Matrix
  Structural Analysis*, Eq. 5.115 with shear, sec. 5.6), exact for a uniform beam under end
  loads; ``phi = 0`` (no shear stiffness given) is the Euler-Bernoulli element.  Mass:

  - ``"lumped"`` (NASTRAN's default): half of ``m' L`` on each end's three translations;
    a ``"beam"`` (CBEAM) also lumps half of the polar moment ``rho J L`` on each end's axial
    rotation, a ``"bar"`` (CBAR) does not.  No rotational inertia otherwise (so the bending
    rotations carry no mass; see condensation below).  This reproduces Simcenter Nastran's
    grid-point weight table and eigenvalues of the ``beam_modes`` fixture to its printed
    digits (``tests/validation/test_nastran_beam_modes.py``).
  - ``"consistent"`` (NASTRAN ``PARAM,COUPMASS``): the consistent mass of the shear-deformable
    element, translational and rotary inertia (Przemieniecki Eq. 11.41; Friedman & Kosmatka,
    *Computers & Structures* 47 (1993) 473, interdependent interpolation), torsion
    ``rho J L / 6 [[2, 1], [1, 2]]``.  At ``phi = 0`` without rotary inertia it is
    :func:`microg.structure.fem.frame_mass_local`.  (NASTRAN's own coupled CBAR mass was not
    available to check against; the difference, if any, is in the shear terms only.)

  Offsets (CBAR WA/WB) are rigid links from the node to the beam end; pin flags release end
  components by static condensation of the element (its mass by the same transformation).
  A section with ``I12 != 0`` is bent about its principal axes.
* **Rods** (CROD/CONROD): axial ``EA/L`` and torsion ``GJ/L``; mass lumped (``m' L/2`` on each
  end's translations) or consistent (linear in all three translations, NASTRAN's coupled
  rod mass).
* **Springs** (CBUSH): a 6x6 stiffness and viscous damping in the spring axes at the spring's
  point, each node carried there rigidly: the element is then free of rigid-body forces
  wherever the point is.  **Scalar springs** (CELAS): ``k (e_b - e_a)(e_b - e_a)^T`` on the
  two components along the nodes' axes.
* **Concentrated masses** (CONM2): :func:`microg.structure.fem.point_mass_matrix` (offset and
  full inertia tensor).
* **Rigid links** (RBE2): the dependent components are eliminated exactly,
  ``u_d = u_i + theta_i x (x_d - x_i)``, ``theta_d = theta_i`` (no penalty).  **Interpolation**
  (RBE3): the reference node's motion is the weighted least-squares rigid-body fit of the
  independent nodes' translations (the sources' components along their axes), eliminated
  exactly the same way; it adds no stiffness and moves rigid-body motion exactly.  Chains
  of links are resolved; a component dependent twice, or a cycle, is an error.

Degrees of freedom:

1. **Unconnected DOFs** (no stiffness and no mass: rotations of rod-only nodes, unused
   grids) are removed, as NASTRAN's ``AUTOSPC`` does; ``meta["removed"]`` counts them.
2. **Massless DOFs** (the lumped-mass rotations) are condensed exactly: with ``M_oo = 0``
   the equations of the massless set are static, ``u_o = -K_oo^-1 K_oa u_a``, so
   ``K_r = K_aa - K_ao K_oo^-1 K_oa`` and ``M_r = M_aa`` have the same finite eigenvalues as
   the full pencil, and forces on the massless set map exactly through the point maps.  The
   condensed stiffness is dense: at most :data:`CONDENSE_MAX` retained DOFs (a documented
   limit: a larger lumped model needs ``mass="consistent"``, or a solver that accepts a
   singular mass matrix).
3. **Rigid-body vectors** are the exact unit translations and rotations about the centre of
   mass (as :mod:`microg.structure.fem`'s), restricted to the retained DOFs (a rigid motion
   satisfies every link exactly).

The structure is free-free; ``constrained=True`` applies the model's single-point
constraints (NASTRAN SPC) instead, for validation against clamped decks.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.errors import InputError
from microg.models.graph_check import validate_graph
from microg.models.graph_model import (
    BeamElement,
    BeamSection,
    ConcentratedMass,
    GraphModel,
    GraphPoint,
    Node,
    Spring,
)
from microg.models.station import Beam, RigidBody, Station
from microg.structure.structure import PointMap, Structure

if TYPE_CHECKING:  # scipy loads on first use (see microg.structure.fem)
    import scipy.sparse as sp

__all__ = [
    "AXIAL_PENALTY",
    "CONDENSE_MAX",
    "DEFAULT_ELEMENTS_PER_BEAM",
    "DOF_NAMES",
    "GJ_ZERO_FRACTION",
    "MAX_FEM_DOF",
    "StationMesh",
    "TORSION_PENALTY",
    "frame_mass_local",
    "frame_rotation",
    "frame_stiffness_local",
    "mass_properties_of",
    "mesh_station",
    "point_mass_matrix",
    "rigid_link",
    "torsion_is_rigid",
    "FrameMatrices",
    "FrameSamples",
    "assemble_frame",
    "beam_mass_consistent_local",
    "beam_mass_lumped_local",
    "beam_stiffness_local",
    "build_frame",
    "bush_matrix",
    "graph_from_station",
    "interpolation_matrix",
    "release_ends",
    "rod_mass_local",
    "rod_stiffness_local",
    "shear_parameter",
]

#: coordinate names of a node, in order
DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")
#: axially rigid beams: EA = AXIAL_PENALTY * max(EI_y, EI_z) / L^2
AXIAL_PENALTY = 1e6
#: torsionally rigid beams (gj = 0): GJ = TORSION_PENALTY * max(EI_y, EI_z)
TORSION_PENALTY = 1e4
#: a torsional stiffness at most this fraction of max(EI_y, EI_z) is numerically zero and is
#: treated as gj = 0 (the rule of docs/model-format.md: 1e-30 lbf*ft^2 behaves like 0)
GJ_ZERO_FRACTION = 1e-12
#: default number of elements per beam when neither discretisation option is given
DEFAULT_ELEMENTS_PER_BEAM = 10
#: largest number of retained DOFs when massless DOFs are condensed (dense K_r)
CONDENSE_MAX = 2500
#: an RBE3 whose normal matrix has a condition number above this is singular
INTERPOLATION_COND_MAX = 1e12


# --------------------------------------------------------------------------- kernels


def frame_stiffness_local(
    length: np.ndarray, ea: np.ndarray, ei_y: np.ndarray, ei_z: np.ndarray, gj: np.ndarray
) -> np.ndarray:
    """Stiffness matrices of 3-D Euler-Bernoulli frame elements in local axes.

    Local DOF order per node ``(u, v, w, theta_x, theta_y, theta_z)``, node a then node b;
    ``theta_z = dv/dx`` and ``theta_y = -dw/dx`` (Przemieniecki, *Theory of Matrix
    Structural Analysis*, Eq. 5.115).

    Parameters
    ----------
    length : ndarray (ne,)
        Element lengths, m.
    ea : ndarray (ne,)
        Axial stiffness, N.
    ei_y, ei_z : ndarray (ne,)
        Bending stiffness about local y (deflection w) and local z (deflection v), N m^2.
    gj : ndarray (ne,)
        Torsional stiffness, N m^2.

    Returns
    -------
    ndarray (ne, 12, 12)
        N/m, N, N m per unit DOF.
    """
    L = np.asarray(length, float)
    k = np.zeros((L.size, 12, 12))
    _put2(k, (0, 6), np.asarray(ea, float) / L)
    _put2(k, (3, 9), np.asarray(gj, float) / L)
    _put4(k, (1, 5, 7, 11), np.asarray(ei_z, float) / L**3, _bend_k(L, +1.0))
    _put4(k, (2, 4, 8, 10), np.asarray(ei_y, float) / L**3, _bend_k(L, -1.0))
    return k


def frame_mass_local(
    length: np.ndarray, mass_per_length: np.ndarray, polar_mass_per_length: np.ndarray
) -> np.ndarray:
    """Consistent mass matrices of 3-D frame elements in local axes.

    Translational mass from the same cubic (bending) and linear (axial) shape functions as
    :func:`frame_stiffness_local`; torsional mass ``rho J L / 6 [[2, 1], [1, 2]]``.

    Parameters
    ----------
    length : ndarray (ne,)
        Element lengths, m.
    mass_per_length : ndarray (ne,)
        ``rho A``, kg/m.
    polar_mass_per_length : ndarray (ne,)
        ``rho J``, polar mass moment per length about the axis, kg m.

    Returns
    -------
    ndarray (ne, 12, 12)
        kg, kg m, kg m^2 per unit DOF.
    """
    L = np.asarray(length, float)
    m = np.zeros((L.size, 12, 12))
    mL = np.asarray(mass_per_length, float) * L
    _put2(m, (0, 6), mL / 6.0, mass=True)
    _put2(m, (3, 9), np.asarray(polar_mass_per_length, float) * L / 6.0, mass=True)
    _put4(m, (1, 5, 7, 11), mL / 420.0, _bend_m(L, +1.0))
    _put4(m, (2, 4, 8, 10), mL / 420.0, _bend_m(L, -1.0))
    return m


def frame_rotation(direction: np.ndarray, orientation: np.ndarray) -> np.ndarray:
    """Rotation matrices from station to element axes (rows: local x, y, z).

    Parameters
    ----------
    direction : ndarray (ne, 3)
        Unit vectors along the elements (local x).
    orientation : ndarray (ne, 3)
        Local y axes (made exactly perpendicular to ``direction`` here).

    Returns
    -------
    ndarray (ne, 3, 3)
        ``R`` with ``v_local = R @ v_station``.
    """
    ex = np.asarray(direction, float)
    ex = ex / np.linalg.norm(ex, axis=-1, keepdims=True)
    ey = np.asarray(orientation, float)
    ey = ey - np.sum(ey * ex, axis=-1, keepdims=True) * ex
    ey = ey / np.linalg.norm(ey, axis=-1, keepdims=True)
    ez = np.cross(ex, ey)
    return np.stack([ex, ey, ez], axis=-2)


def rigid_link(offset: np.ndarray) -> np.ndarray:
    """Rigid-link matrices: slave-node DOFs from master-node DOFs.

    ``u_s = u_m + theta_m x d`` and ``theta_s = theta_m`` with ``d = x_s - x_m``.

    Parameters
    ----------
    offset : ndarray (..., 3)
        Slave position minus master position, m.

    Returns
    -------
    ndarray (..., 6, 6)
    """
    d = np.asarray(offset, float)
    t = np.zeros((*d.shape[:-1], 6, 6))
    t[..., range(6), range(6)] = 1.0
    t[..., :3, 3:] = -_skew(d)
    return t


def point_mass_matrix(mass: np.ndarray, inertia: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """6x6 mass matrices of point masses rigidly attached to a node.

    Parameters
    ----------
    mass : ndarray (p,)
        kg.
    inertia : ndarray (p, 3, 3)
        Rotary inertia about each mass's own centre, station axes, kg m^2.
    offset : ndarray (p, 3)
        Mass centre minus node position, m.

    Returns
    -------
    ndarray (p, 6, 6)
        ``T^T diag(m I, J) T`` with ``T`` the rigid link (mass, m [d]x coupling and the
        parallel-axis inertia ``J + m (|d|^2 I - d d^T)``).
    """
    m = np.asarray(mass, float)
    local = np.zeros((m.size, 6, 6))
    local[:, range(3), range(3)] = m[:, None]
    local[:, 3:, 3:] = np.asarray(inertia, float)
    t = rigid_link(offset)
    return np.swapaxes(t, -1, -2) @ local @ t


def _skew(d: np.ndarray) -> np.ndarray:
    """Cross-product matrices ``[d]x`` with ``[d]x v = d x v``."""
    d = np.asarray(d, float)
    s = np.zeros((*d.shape[:-1], 3, 3))
    s[..., 0, 1], s[..., 0, 2] = -d[..., 2], d[..., 1]
    s[..., 1, 0], s[..., 1, 2] = d[..., 2], -d[..., 0]
    s[..., 2, 0], s[..., 2, 1] = -d[..., 1], d[..., 0]
    return s


def _put2(a: np.ndarray, idx: tuple[int, int], c: np.ndarray, *, mass: bool = False) -> None:
    i, j = idx
    diag, off = (2.0, 1.0) if mass else (1.0, -1.0)
    a[:, i, i] += diag * c
    a[:, j, j] += diag * c
    a[:, i, j] += off * c
    a[:, j, i] += off * c


def _put4(a: np.ndarray, idx: tuple[int, ...], c: np.ndarray, block: np.ndarray) -> None:
    ix = np.asarray(idx)
    a[:, ix[:, None], ix[None, :]] += c[:, None, None] * block


def _bend_k(L: np.ndarray, sign: float) -> np.ndarray:
    """Hermite bending stiffness pattern (times EI/L^3); sign -1 for the x-z plane."""
    s = sign
    one = np.ones_like(L)
    return np.stack(
        [
            np.stack([12 * one, 6 * s * L, -12 * one, 6 * s * L], -1),
            np.stack([6 * s * L, 4 * L**2, -6 * s * L, 2 * L**2], -1),
            np.stack([-12 * one, -6 * s * L, 12 * one, -6 * s * L], -1),
            np.stack([6 * s * L, 2 * L**2, -6 * s * L, 4 * L**2], -1),
        ],
        -2,
    )


def _bend_m(L: np.ndarray, sign: float) -> np.ndarray:
    """Hermite consistent-mass pattern (times rho A L / 420); sign -1 for the x-z plane."""
    s = sign
    one = np.ones_like(L)
    return np.stack(
        [
            np.stack([156 * one, 22 * s * L, 54 * one, -13 * s * L], -1),
            np.stack([22 * s * L, 4 * L**2, 13 * s * L, -3 * L**2], -1),
            np.stack([54 * one, 13 * s * L, 156 * one, -22 * s * L], -1),
            np.stack([-13 * s * L, -3 * L**2, -22 * s * L, 4 * L**2], -1),
        ],
        -2,
    )


def shear_parameter(length: np.ndarray, ei: np.ndarray, shear: np.ndarray | None) -> np.ndarray:
    """Timoshenko shear parameter ``phi = 12 EI / (k G A L^2)`` (0 without shear flexibility).

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    ei : ndarray (ne,)
        Bending stiffness of the plane, N m^2.
    shear : ndarray (ne,) or None
        Shear stiffness ``k G A`` of the same plane, N; ``inf`` or None: rigid in shear.
    """
    L = np.asarray(length, float)
    if shear is None:
        return np.zeros_like(L)
    ks = np.asarray(shear, float)
    with np.errstate(divide="ignore"):
        return np.where(np.isfinite(ks), 12.0 * np.asarray(ei, float) / (ks * L**2), 0.0)


def beam_stiffness_local(
    length: np.ndarray,
    ea: np.ndarray,
    ei_y: np.ndarray,
    ei_z: np.ndarray,
    gj: np.ndarray,
    phi_v: np.ndarray | None = None,
    phi_w: np.ndarray | None = None,
) -> np.ndarray:
    """Stiffness of shear-deformable (Timoshenko) 3-D beam elements in local axes.

    DOF order and signs of :func:`microg.structure.fem.frame_stiffness_local`.  Per bending
    plane, with ``phi`` the shear parameter (:func:`shear_parameter`),
    ``EI/((1+phi) L^3) [[12, 6L, -12, 6L], [6L, (4+phi)L^2, -6L, (2-phi)L^2], ...]``
    (Przemieniecki sec. 5.6): the Euler-Bernoulli element with ``EI/(1+phi)`` plus
    ``EI phi/((1+phi) L) [[1, -1], [-1, 1]]`` on the two rotations.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    ea, gj : ndarray (ne,)
        N, N m^2.
    ei_y, ei_z : ndarray (ne,)
        About local y (deflection w) and local z (deflection v), N m^2.
    phi_v, phi_w : ndarray (ne,), optional
        Shear parameters of the v (x-y) and w (x-z) planes; 0 (Euler-Bernoulli) by default.

    Returns
    -------
    ndarray (ne, 12, 12)
    """
    L = np.asarray(length, float)
    pv = np.zeros_like(L) if phi_v is None else np.asarray(phi_v, float)
    pw = np.zeros_like(L) if phi_w is None else np.asarray(phi_w, float)
    eiy = np.asarray(ei_y, float)
    eiz = np.asarray(ei_z, float)
    k = frame_stiffness_local(L, ea, eiy / (1.0 + pw), eiz / (1.0 + pv), gj)
    for (i, j), c in (
        ((5, 11), eiz * pv / (L * (1.0 + pv))),
        ((4, 10), eiy * pw / (L * (1.0 + pw))),
    ):
        k[:, i, i] += c
        k[:, j, j] += c
        k[:, i, j] -= c
        k[:, j, i] -= c
    return k


def _plane_mass(
    L: np.ndarray, m: np.ndarray, r: np.ndarray, phi: np.ndarray, s: float
) -> np.ndarray:
    """4x4 consistent mass (v, theta, v, theta) of one bending plane; s = -1 for x-z."""
    p = phi
    d = (1.0 + p) ** 2
    t11 = 13 / 35 + 7 * p / 10 + p**2 / 3
    t12 = (11 / 210 + 11 * p / 120 + p**2 / 24) * L
    t13 = 9 / 70 + 3 * p / 10 + p**2 / 6
    t14 = -(13 / 420 + 3 * p / 40 + p**2 / 24) * L
    t22 = (1 / 105 + p / 60 + p**2 / 120) * L**2
    t24 = -(1 / 140 + p / 60 + p**2 / 120) * L**2
    r11 = np.full_like(L, 6 / 5)
    r12 = (1 / 10 - p / 2) * L
    r22 = (2 / 15 + p / 6 + p**2 / 3) * L**2
    r24 = (-1 / 30 - p / 6 + p**2 / 6) * L**2
    trans = np.stack(
        [
            np.stack([t11, t12, t13, t14], -1),
            np.stack([t12, t22, -t14, t24], -1),
            np.stack([t13, -t14, t11, -t12], -1),
            np.stack([t14, t24, -t12, t22], -1),
        ],
        -2,
    )
    rot = np.stack(
        [
            np.stack([r11, r12, -r11, r12], -1),
            np.stack([r12, r22, -r12, r24], -1),
            np.stack([-r11, -r12, r11, -r12], -1),
            np.stack([r12, r24, -r12, r22], -1),
        ],
        -2,
    )
    out = (m * L / d)[:, None, None] * trans + (r / (L * d))[:, None, None] * rot
    sign = np.array([1.0, s, 1.0, s])
    return out * sign[:, None] * sign[None, :]


def beam_mass_consistent_local(
    length: np.ndarray,
    mass_per_length: np.ndarray,
    polar_mass: np.ndarray,
    phi_v: np.ndarray | None = None,
    phi_w: np.ndarray | None = None,
    rotary_y: np.ndarray | None = None,
    rotary_z: np.ndarray | None = None,
) -> np.ndarray:
    """Consistent mass of shear-deformable 3-D beam elements in local axes.

    Per bending plane, the shape functions of the Timoshenko element with shear parameter
    ``phi`` (Friedman & Kosmatka 1993): translational inertia ``m' L/(1+phi)^2 [...]`` and
    rotary inertia ``rho I/((1+phi)^2 L) [...]`` (Przemieniecki Eq. 11.41).  Axial
    ``m' L/6 [[2, 1], [1, 2]]``, torsion ``rho J L/6 [[2, 1], [1, 2]]``.  With ``phi = 0`` and
    no rotary inertia this is :func:`microg.structure.fem.frame_mass_local`.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    mass_per_length : ndarray (ne,)
        ``m' = rho A``, kg/m.
    polar_mass : ndarray (ne,)
        ``rho J`` per length, kg m.
    phi_v, phi_w : ndarray (ne,), optional
        Shear parameters of the v (x-y) and w (x-z) planes.
    rotary_y, rotary_z : ndarray (ne,), optional
        Rotary inertia per length of rotation about local y (w plane) and z (v plane), kg m.

    Returns
    -------
    ndarray (ne, 12, 12)
    """
    L = np.asarray(length, float)
    zero = np.zeros_like(L)
    m = np.asarray(mass_per_length, float) * np.ones_like(L)
    out = frame_mass_local(L, m, polar_mass)
    pv = zero if phi_v is None else np.asarray(phi_v, float)
    pw = zero if phi_w is None else np.asarray(phi_w, float)
    ry = zero if rotary_y is None else np.asarray(rotary_y, float)
    rz = zero if rotary_z is None else np.asarray(rotary_z, float)
    for idx, phi, rot, s in (((1, 5, 7, 11), pv, rz, 1.0), ((2, 4, 8, 10), pw, ry, -1.0)):
        ix = np.asarray(idx)
        e = np.flatnonzero((phi != 0) | (rot != 0))  # the others are the fem kernel's exactly
        if e.size:
            out[e[:, None, None], ix[None, :, None], ix[None, None, :]] = _plane_mass(
                L[e], m[e], rot[e], phi[e], s
            )
    return out


def beam_mass_lumped_local(
    length: np.ndarray, mass_per_length: np.ndarray, polar_mass: np.ndarray, torsion: np.ndarray
) -> np.ndarray:
    """Lumped (diagonal) mass of 3-D beam elements, NASTRAN's default.

    Half the element's mass ``m' L`` on each end's three translations; where ``torsion`` is
    true (CBEAM), half its polar moment ``rho J L`` on each end's axial rotation too.  No
    rotational inertia otherwise.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    mass_per_length : ndarray (ne,)
        kg/m.
    polar_mass : ndarray (ne,)
        kg m.
    torsion : ndarray (ne,) of bool
        Lump the polar moment (CBEAM) or not (CBAR).

    Returns
    -------
    ndarray (ne, 12, 12)
    """
    L = np.asarray(length, float)
    half = 0.5 * np.asarray(mass_per_length, float) * L
    m = np.zeros((L.size, 12, 12))
    for i in (0, 1, 2, 6, 7, 8):
        m[:, i, i] = half
    tor = np.where(np.asarray(torsion, bool), 0.5 * np.asarray(polar_mass, float) * L, 0.0)
    m[:, 3, 3] = tor
    m[:, 9, 9] = tor
    return m


def rod_stiffness_local(length: np.ndarray, ea: np.ndarray, gj: np.ndarray) -> np.ndarray:
    """Rod elements (CROD): ``EA/L`` axially and ``GJ/L`` in torsion, local axes (ne, 12, 12)."""
    L = np.asarray(length, float)
    zero = np.zeros_like(L)
    return frame_stiffness_local(L, ea, zero, zero, gj)


def rod_mass_local(length: np.ndarray, mass_per_length: np.ndarray, lumped: bool) -> np.ndarray:
    """Rod mass: lumped ``m' L/2`` per end translation, or consistent (linear) in x, y and z.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    mass_per_length : ndarray (ne,)
        kg/m.
    lumped : bool

    Returns
    -------
    ndarray (ne, 12, 12)
        The consistent form is ``m' L/6 [[2, 1], [1, 2]]`` on each translation pair.
    """
    L = np.asarray(length, float)
    mL = np.asarray(mass_per_length, float) * L
    m = np.zeros((L.size, 12, 12))
    for i in range(3):
        if lumped:
            m[:, i, i] = m[:, i + 6, i + 6] = mL / 2.0
        else:
            m[:, i, i] = m[:, i + 6, i + 6] = mL / 3.0
            m[:, i, i + 6] = m[:, i + 6, i] = mL / 6.0
    return m


def release_ends(
    stiffness: np.ndarray, mass: np.ndarray, released: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Release element DOFs (pin flags) by static condensation of each element.

    ``u_r = -K_rr^+ K_rk u_k`` (pseudo-inverse: a component released at both ends leaves
    no stiffness there); ``K' = T^T K T`` and ``M' = T^T M T`` with ``T`` that map, and the
    released rows and columns zero.

    Parameters
    ----------
    stiffness, mass : ndarray (ne, 12, 12)
        Local matrices.
    released : ndarray (ne, 12) of bool

    Returns
    -------
    stiffness, mass : ndarray (ne, 12, 12)
    """
    k = np.array(stiffness, float)
    m = np.array(mass, float)
    rel = np.asarray(released, bool)
    for e in np.flatnonzero(rel.any(axis=1)):
        r = np.flatnonzero(rel[e])
        keep = np.flatnonzero(~rel[e])
        t = np.zeros((12, keep.size))
        t[keep, np.arange(keep.size)] = 1.0
        t[r] = -np.linalg.pinv(k[e][np.ix_(r, r)]) @ k[e][np.ix_(r, keep)]
        kk = t.T @ k[e] @ t
        mm = t.T @ m[e] @ t
        k[e] = 0.0
        m[e] = 0.0
        k[e][np.ix_(keep, keep)] = 0.5 * (kk + kk.T)
        m[e][np.ix_(keep, keep)] = 0.5 * (mm + mm.T)
    return k, m


def bush_matrix(
    matrix6: np.ndarray,
    axes: np.ndarray,
    node_a: np.ndarray,
    node_b: np.ndarray | None,
    location: np.ndarray,
) -> np.ndarray:
    """12x12 (6x6 grounded) basic-frame matrix of a CBUSH-like spring at ``location``.

    The relative motion at the spring point is ``d = L_b u_b - L_a u_a`` with ``L`` the
    rigid links from each node to the point (:func:`microg.structure.fem.rigid_link`);
    ``K_e = G^T R6^T k R6 G`` with ``G = [-L_a, L_b]`` and ``R6 = diag(R, R)`` the spring axes.

    Parameters
    ----------
    matrix6 : ndarray (6, 6)
        Stiffness (or damping) in the spring axes.
    axes : ndarray (3, 3)
        Rows: spring x, y, z in the basic frame.
    node_a, node_b : ndarray (3,)
        Node positions, m (node_b None: grounded).
    location : ndarray (3,)
        Spring point, m.
    """
    r6 = np.zeros((6, 6))
    r6[:3, :3] = r6[3:, 3:] = np.asarray(axes, float)
    kb = r6.T @ np.asarray(matrix6, float) @ r6
    la = rigid_link(np.asarray(location, float) - np.asarray(node_a, float))
    if node_b is None:
        g = -la
    else:
        lb = rigid_link(np.asarray(location, float) - np.asarray(node_b, float))
        g = np.concatenate([-la, lb], axis=1)
    out = g.T @ kb @ g
    return 0.5 * (out + out.T)


def interpolation_matrix(
    reference: np.ndarray,
    positions: np.ndarray,
    directions: np.ndarray,
    weights: np.ndarray,
    *,
    where: str = "interpolation",
) -> np.ndarray:
    """RBE3: the reference point's 6 DOFs from independent translation components.

    The reference motion ``q`` (translation and rotation at ``reference``) minimises
    ``sum_k w_k (e_k . (u_k - q_t - q_r x d_k))^2`` with ``d_k`` the source position minus
    the reference, i.e. ``q = (S^T W S)^-1 S^T W s`` where ``s_k = e_k . u_k`` are the source
    components and ``S_k = e_k^T [I, -[d_k]x]``.  A rigid motion of the sources is returned
    exactly.

    Parameters
    ----------
    reference : ndarray (3,)
        Reference node position, m.
    positions : ndarray (k, 3)
        Position of the node of each source component, m.
    directions : ndarray (k, 3)
        Unit direction of each source component (basic frame).
    weights : ndarray (k,)
        > 0.

    Returns
    -------
    ndarray (6, k)
        ``q = W_rbe3 @ s``.
    """
    d = np.asarray(positions, float) - np.asarray(reference, float)
    e = np.asarray(directions, float)
    w = np.asarray(weights, float)
    S = np.concatenate([e, np.cross(d, e)], axis=1)  # e.(q_t + q_r x d) = e.q_t + (d x e).q_r
    N = S.T @ (w[:, None] * S)
    scale = float(np.max(np.abs(np.diag(N)))) or 1.0
    if np.linalg.cond(N / scale) > INTERPOLATION_COND_MAX:
        raise InputError(
            "its independent components do not determine the reference's six motions "
            "(too few nodes, or collinear ones)",
            where=where,
            fix="add independent nodes off the line, or give them more components",
        )
    return np.linalg.solve(N, S.T * w[None, :])


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class FrameMatrices:
    """The assembled graph before DOF elimination: 6 basic-frame DOFs per node (g-set).

    Attributes
    ----------
    stiffness, mass, damping, structural_damping : sparse CSR (6 nn, 6 nn)
        SI; ``damping`` viscous (N s/m), ``structural_damping`` sum of ``GE_e K_e``.
    positions : ndarray (nn, 3)
        Node positions, m.
    names : tuple of str
        Node names.
    transform : sparse CSR (6 nn, n_ind)
        ``u_g = transform @ u_ind``: the rigid links and interpolations eliminated.
    independent : ndarray of int
        The g-set DOFs kept as coordinates of ``transform``.
    beam_rotation : ndarray (nb, 3, 3)
        Station-to-element rotation of each beam element (rows: local x, y, z; the principal
        bending axes of a skewed section), in the order of ``graph.beams``.
    beam_length : ndarray (nb,)
        Length of each beam element between its (offset) ends, m.
    """

    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    damping: sp.csr_matrix
    structural_damping: sp.csr_matrix
    positions: np.ndarray
    names: tuple[str, ...]
    transform: sp.csr_matrix
    independent: np.ndarray
    beam_rotation: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3)))
    beam_length: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True)
class FrameSamples:
    """Translations of sample points (nodes and offset masses) from the coordinates.

    ``u_g = T (E q)`` with ``E`` the recovery of condensed massless DOFs
    (``u_o = X u_a``), then a sample rides rigidly on its node:
    ``u = u_node + theta_node x offset``.

    Attributes
    ----------
    position : ndarray (p, 3)
        m.
    labels : tuple of str
        ``"grid:7"``, ``"grid:11/conm2:21"``.
    component : ndarray (p,) of str
        Carrier of each sample for the acceleration maps: the label's prefix (``"keel"`` of
        ``"keel:n3"``, ``"grid"`` of ``"grid:7"``), as the maps read frame labels.
    offset : ndarray (p, 3)
        Sample position minus node position, m.
    rows : sparse CSR (6 p, n_ind)
        The g-set rows of the samples' nodes (translations then rotations).
    retained, condensed : ndarray of int
        Indices (in the independent set) of the coordinates and of the condensed DOFs.
    recovery : ndarray (n_condensed, n)
        ``X``.
    n_ind : int
        Size of the independent set.
    """

    position: np.ndarray
    labels: tuple[str, ...]
    component: np.ndarray
    offset: np.ndarray
    rows: sp.csr_matrix
    retained: np.ndarray
    condensed: np.ndarray
    recovery: np.ndarray
    n_ind: int

    def __len__(self) -> int:
        return int(self.position.shape[0])

    def expand(self, q: np.ndarray) -> np.ndarray:
        """Independent-set DOFs (n_ind,) or (n_ind, m) from coordinates ``q``."""
        q = np.asarray(q, float)
        u = np.zeros((self.n_ind, *q.shape[1:]))
        u[self.retained] = q
        if self.condensed.size:
            u[self.condensed] = self.recovery @ q
        return u

    def displacement(self, q: np.ndarray) -> np.ndarray:
        """Translations of the samples, m: (p, 3) for a vector ``q``, (p, 3, m) for a matrix."""
        q = np.asarray(q, float)
        u6 = np.asarray(self.rows @ self.expand(q))
        p = self.position.shape[0]
        if q.ndim == 1:
            u6 = u6.reshape(p, 6)
            return u6[:, :3] + np.cross(u6[:, 3:], self.offset)
        u6 = u6.reshape(p, 6, -1)
        return u6[:, :3] + np.cross(u6[:, 3:], self.offset[:, :, None], axisa=1, axisb=1, axisc=1)


class _PointMaps(Mapping[str, PointMap]):
    """Named points, plus every node by name on lookup (maps built on demand and cached).

    Iteration and ``len`` cover the named points only, so code that walks all points
    (modal-mass peaks) does not build a dense map per node of a large model.
    """

    def __init__(self, named: dict[str, PointMap], build_node: Any, node_names: set[str]):
        self._named = named
        self._build = build_node
        self._nodes = node_names
        self._cache: dict[str, PointMap] = {}

    def __getitem__(self, key: str) -> PointMap:
        if key in self._named:
            return self._named[key]
        if key in self._nodes:
            if key not in self._cache:
                self._cache[key] = self._build(key)
            return self._cache[key]
        raise KeyError(key)

    def __contains__(self, key: object) -> bool:
        return key in self._named or key in self._nodes

    def __iter__(self) -> Iterator[str]:
        return iter(self._named)

    def __len__(self) -> int:
        return len(self._named)


# --------------------------------------------------------------------------- assembly


def _coo(
    rows: list[np.ndarray], cols: list[np.ndarray], vals: list[np.ndarray], n: int
) -> sp.csr_matrix:
    import scipy.sparse as sp

    if not rows:
        return sp.csr_matrix((n, n))
    a = sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    ).tocsr()
    a = 0.5 * (a + a.T)
    a.eliminate_zeros()
    return sp.csr_matrix(a)


def _scatter(
    dofs: np.ndarray,
    mats: np.ndarray,
    out_r: list[np.ndarray],
    out_c: list[np.ndarray],
    out_v: list[np.ndarray],
) -> None:
    ne, nd = dofs.shape
    out_r.append(np.broadcast_to(dofs[:, :, None], (ne, nd, nd)).ravel())
    out_c.append(np.broadcast_to(dofs[:, None, :], (ne, nd, nd)).ravel())
    out_v.append(np.asarray(mats).reshape(ne, nd, nd).ravel())


def _element_transform(R: np.ndarray, off_a: np.ndarray, off_b: np.ndarray) -> np.ndarray:
    """Local 12 DOFs from the two nodes' basic DOFs through rigid end offsets (ne, 12, 12)."""
    ne = R.shape[0]
    A = np.zeros((ne, 12, 12))
    for blk, t in ((0, rigid_link(off_a)), (1, rigid_link(off_b))):
        o = 6 * blk
        A[:, o : o + 3, o : o + 6] = R @ t[:, :3, :]
        A[:, o + 3 : o + 6, o : o + 6] = R @ t[:, 3:, :]
    return A


def _principal(
    R: np.ndarray, secs: list[BeamSection]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rotate local y, z to the principal bending axes of the sections where I12 != 0.

    Returns the rotated frames ``R``, the principal ``EI_y``, ``EI_z`` (N m^2) and the indices
    of the skew sections.  Shear is not handled here: the caller drops the shear flexibility
    of the skew sections (NASTRAN ignores the shear factors when I12 != 0).
    """
    ei_y = np.array([s.ei_y_N_m2 for s in secs])
    ei_z = np.array([s.ei_z_N_m2 for s in secs])
    ei_yz = np.array([s.ei_yz_N_m2 for s in secs])
    skew = np.flatnonzero(ei_yz != 0)
    R = R.copy()
    for e in skew:
        # B = [[E int y^2, E int yz], [E int yz, E int z^2]] in (y, z); its eigenvectors are the
        # principal directions; deflection along eigenvector k has stiffness lambda_k
        B = np.array([[ei_z[e], ei_yz[e]], [ei_yz[e], ei_y[e]]])
        lam, Q = np.linalg.eigh(B)
        ey = Q[0, 0] * R[e, 1] + Q[1, 0] * R[e, 2]
        R[e, 1] = ey
        R[e, 2] = np.cross(R[e, 0], ey)
        ei_z[e], ei_y[e] = lam[0], lam[1]
    return R, ei_y, ei_z, skew


def assemble_frame(graph: GraphModel, *, mass: str | None = None) -> FrameMatrices:
    """Element matrices of ``graph`` assembled on 6 basic-frame DOFs per node, links resolved.

    Parameters
    ----------
    graph : GraphModel
    mass : {"lumped", "consistent"}, optional
        Overrides the model's mass formulation.

    Returns
    -------
    FrameMatrices
    """
    validate_graph(graph)
    formulation = graph.mass_formulation if mass is None else mass
    if formulation not in ("lumped", "consistent"):
        raise InputError(
            f"unknown mass formulation {formulation!r}",
            where="mass",
            fix="use lumped or consistent",
        )
    lumped = formulation == "lumped"
    index = graph.node_index()
    P = np.array([n.position for n in graph.nodes], float).reshape(-1, 3)
    n = 6 * P.shape[0]
    if n > MAX_FEM_DOF:
        raise InputError(
            f"the frame model has {n:,} degrees of freedom ({P.shape[0]:,} nodes), beyond the "
            f"limit of {MAX_FEM_DOF:,}",
            where=graph.source or graph.name,
            fix="use a coarser mesh, or a modal model of the structure",
        )
    rk: list[np.ndarray] = []
    ck: list[np.ndarray] = []
    vk: list[np.ndarray] = []
    rm: list[np.ndarray] = []
    cm: list[np.ndarray] = []
    vm: list[np.ndarray] = []
    rc: list[np.ndarray] = []
    cc: list[np.ndarray] = []
    vc: list[np.ndarray] = []
    rg: list[np.ndarray] = []
    cg: list[np.ndarray] = []
    vg: list[np.ndarray] = []

    beam_R = np.zeros((0, 3, 3))
    beam_L = np.zeros(0)
    if graph.beams:
        bm = graph.beams
        a = np.array([index[b.nodes[0]] for b in bm])
        b_ = np.array([index[b.nodes[1]] for b in bm])
        off = np.array([b.offsets for b in bm], float).reshape(-1, 2, 3)
        xa = P[a] + off[:, 0]
        xb = P[b_] + off[:, 1]
        axis = xb - xa
        L = np.linalg.norm(axis, axis=1)
        R = frame_rotation(axis / L[:, None], np.array([b.orientation for b in bm], float))
        secs = [b.section for b in bm]
        R, ei_y, ei_z, skew = _principal(R, secs)
        beam_R, beam_L = R, L
        sy = np.array([np.inf if s.shear_y_N is None else s.shear_y_N for s in secs])
        sz = np.array([np.inf if s.shear_z_N is None else s.shear_z_N for s in secs])
        sy[skew] = np.inf  # NASTRAN: shear factors ignored when I12 != 0
        sz[skew] = np.inf
        phi_v = shear_parameter(L, ei_z, sy)
        phi_w = shear_parameter(L, ei_y, sz)
        ea = np.array([s.ea_N for s in secs])
        gj = np.array([s.gj_N_m2 for s in secs])
        mpl = np.array([s.mass_per_length_kg_per_m for s in secs])
        polar = np.array([s.polar_mass_kg_m for s in secs])
        kl = beam_stiffness_local(L, ea, ei_y, ei_z, gj, phi_v, phi_w)
        if lumped:
            ml = beam_mass_lumped_local(L, mpl, polar, np.array([b.kind == "beam" for b in bm]))
        else:
            ry = np.array([s.rotary_y_kg_m for s in secs])
            rz = np.array([s.rotary_z_kg_m for s in secs])
            if skew.size:
                ry[skew] = rz[skew] = 0.5 * (ry[skew] + rz[skew])
            ml = beam_mass_consistent_local(L, mpl, polar, phi_v, phi_w, ry, rz)
        rel = np.zeros((len(bm), 12), bool)
        for e, b in enumerate(bm):
            for end, comps in enumerate(b.releases):
                for ch in comps:
                    rel[e, 6 * end + int(ch) - 1] = True
        if rel.any():
            kl, ml = release_ends(kl, ml, rel)
        A = _element_transform(R, off[:, 0], off[:, 1])
        At = np.swapaxes(A, 1, 2)
        dofs = np.concatenate([6 * a[:, None] + np.arange(6), 6 * b_[:, None] + np.arange(6)], 1)
        _scatter(dofs, At @ kl @ A, rk, ck, vk)
        _scatter(dofs, At @ ml @ A, rm, cm, vm)

    if graph.rods:
        rd = graph.rods
        a = np.array([index[r.nodes[0]] for r in rd])
        b_ = np.array([index[r.nodes[1]] for r in rd])
        axis = P[b_] - P[a]
        L = np.linalg.norm(axis, axis=1)
        ex = axis / L[:, None]
        ori = np.zeros_like(ex)
        ori[np.arange(ex.shape[0]), np.argmin(np.abs(ex), axis=1)] = 1.0
        R = frame_rotation(ex, ori)
        kl = rod_stiffness_local(
            L, np.array([r.ea_N for r in rd]), np.array([r.gj_N_m2 for r in rd])
        )
        ml = rod_mass_local(L, np.array([r.mass_per_length_kg_per_m for r in rd]), lumped)
        zero = np.zeros((len(rd), 3))
        A = _element_transform(R, zero, zero)
        At = np.swapaxes(A, 1, 2)
        dofs = np.concatenate([6 * a[:, None] + np.arange(6), 6 * b_[:, None] + np.arange(6)], 1)
        _scatter(dofs, At @ kl @ A, rk, ck, vk)
        _scatter(dofs, At @ ml @ A, rm, cm, vm)

    for s in graph.springs:
        ia = index[s.nodes[0]]
        ib = None if s.nodes[1] is None else index[s.nodes[1]]
        pb = None if ib is None else P[ib]
        d = 6 * ia + np.arange(6)
        if ib is not None:
            d = np.concatenate([d, 6 * ib + np.arange(6)])
        kb = bush_matrix(s.stiffness, s.axes, P[ia], pb, s.location)
        cb = bush_matrix(s.damping, s.axes, P[ia], pb, s.location)
        _scatter(d[None], kb[None], rk, ck, vk)
        _scatter(d[None], cb[None], rc, cc, vc)
        if s.structural_damping:
            _scatter(d[None], s.structural_damping * kb[None], rg, cg, vg)

    nodes = graph.nodes
    for cs in graph.scalar_springs:
        dl: list[np.ndarray] = []
        vl: list[np.ndarray] = []
        for end, dof in enumerate(cs.dofs):
            if dof is None:
                continue
            i = index[dof[0]]
            c = dof[1] - 1
            v = np.zeros(6)
            v[3 * (c // 3) : 3 * (c // 3) + 3] = nodes[i].axes[c % 3]
            dl.append(6 * i + np.arange(6))
            vl.append(v if end else -v)
        d = np.concatenate(dl)
        ke = np.outer(np.concatenate(vl), np.concatenate(vl))
        _scatter(d[None], (cs.stiffness * ke)[None], rk, ck, vk)
        if cs.damping:
            _scatter(d[None], (cs.damping * ke)[None], rc, cc, vc)
        if cs.structural_damping:
            _scatter(d[None], (cs.structural_damping * cs.stiffness * ke)[None], rg, cg, vg)

    if graph.masses:
        ms = graph.masses
        m6 = point_mass_matrix(
            np.array([m.mass_kg for m in ms]),
            np.array([m.inertia_kg_m2 for m in ms], float).reshape(-1, 3, 3),
            np.array([m.offset_m for m in ms], float).reshape(-1, 3),
        )
        d6 = 6 * np.array([index[m.node] for m in ms])[:, None] + np.arange(6)
        _scatter(d6, m6, rm, cm, vm)

    K = _coo(rk, ck, vk, n)
    M = _coo(rm, cm, vm, n)
    C = _coo(rc, cc, vc, n)
    G = _coo(rg, cg, vg, n)
    T, ind = _link_transform(graph, P, index)
    return FrameMatrices(K, M, C, G, P, tuple(nd.name for nd in nodes), T, ind, beam_R, beam_L)


def _basic_dofs(node: Node, comps: str, *, where: str) -> list[int]:
    """Basic-frame DOF offsets (0-5) of a node's components: exact for full triples."""
    rotated = not np.allclose(node.axes, np.eye(3), atol=1e-12)
    out: list[int] = []
    for base, triple in ((0, "123"), (3, "456")):
        have = [c for c in triple if c in comps]
        if rotated and 0 < len(have) < 3:
            raise InputError(
                f"components {''.join(have)} of node {node.name!r} are along its rotated axes "
                f"({node.frame}); only all of {triple} or none can be constrained there",
                where=where,
                fix=f"use all of {triple}, or give the node basic axes (CD = 0)",
            )
        out += [base + triple.index(c) for c in have]
    return out


def _link_transform(
    graph: GraphModel, P: np.ndarray, index: dict[str, int]
) -> tuple[sp.csr_matrix, np.ndarray]:
    """``u_g = T u_ind`` from the rigid links and interpolations (chains resolved exactly)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    n = 6 * P.shape[0]
    eq_rows: list[np.ndarray] = []
    eq_cols: list[np.ndarray] = []
    eq_vals: list[np.ndarray] = []
    dep: dict[int, str] = {}
    count = 0

    def add(dof: int, cols: np.ndarray, vals: np.ndarray, owner: str) -> None:
        nonlocal count
        if dof in dep:
            node = graph.nodes[dof // 6].name
            raise InputError(
                f"component {dof % 6 + 1} of node {node!r} is dependent in both "
                f"{dep[dof]} and {owner}",
                where=owner,
                fix="make each component dependent in one rigid element only",
            )
        dep[dof] = owner
        eq_rows.append(np.full(cols.size, count))
        eq_cols.append(cols)
        eq_vals.append(vals)
        count += 1

    for rl in graph.rigid_links:
        ii = index[rl.independent]
        for dn in rl.dependents:
            di = index[dn]
            t = rigid_link(P[di] - P[ii])
            for k in _basic_dofs(graph.nodes[di], rl.components, where=rl.name):
                nz = np.flatnonzero(t[k])
                add(6 * di + k, 6 * ii + nz, t[k, nz], rl.name)
    for ip in graph.interpolations:
        ri = index[ip.reference]
        pos, dirs, wts, cols = [], [], [], []
        for nd, comps, w in ip.sources:
            i = index[nd]
            for ch in comps:
                c = int(ch) - 1
                pos.append(P[i])
                dirs.append(graph.nodes[i].axes[c])
                wts.append(w)
                cols.append(6 * i + np.arange(3))
        W = interpolation_matrix(P[ri], np.array(pos), np.array(dirs), np.array(wts), where=ip.name)
        # source component s_k = e_k . u_k: expand W (6, k) onto the sources' basic DOFs
        full_cols = np.concatenate(cols)
        full_vals = (W[:, :, None] * np.array(dirs)[None, :, :]).reshape(6, -1)
        for k in _basic_dofs(graph.nodes[ri], ip.components, where=ip.name):
            add(6 * ri + k, full_cols, full_vals[k], ip.name)
    if not dep:
        return sp.identity(n, format="csr"), np.arange(n)
    m_dofs = np.array(list(dep))
    is_dep = np.zeros(n, bool)
    is_dep[m_dofs] = True
    ind = np.flatnonzero(~is_dep)
    G = sp.coo_matrix(
        (np.concatenate(eq_vals), (np.concatenate(eq_rows), np.concatenate(eq_cols))),
        shape=(count, n),
    ).tocsc()
    Gmm = G[:, m_dofs]
    Gmn = G[:, ind]
    A = (sp.identity(m_dofs.size, format="csc") - Gmm).tocsc()
    if Gmm.nnz:
        try:
            lu = spla.splu(A)
        except RuntimeError:
            raise InputError(
                "rigid elements form a cycle (a node depends on itself through a chain)",
                where=", ".join(sorted(set(dep.values()))[:5]),
                fix="break the chain: one independent node per rigid assembly",
            ) from None
        X = (
            sp.csr_matrix(lu.solve(Gmn.toarray()))
            if m_dofs.size * ind.size <= 4e7
            else _chain_solve(A, Gmn)
        )
    else:
        X = sp.csr_matrix(Gmn)
    X = X.tocoo()
    t_rows = np.concatenate([ind, m_dofs[X.row]])
    t_cols = np.concatenate([np.arange(ind.size), X.col])
    t_vals = np.concatenate([np.ones(ind.size), X.data])
    T = sp.csr_matrix((t_vals, (t_rows, t_cols)), shape=(n, ind.size))
    T.eliminate_zeros()
    return T, ind


def _chain_solve(A: sp.csc_matrix, B: sp.csc_matrix) -> sp.csr_matrix:
    """Sparse solve of (I - G_mm) X = G_mn by repeated substitution (acyclic chains)."""
    import scipy.sparse as sp

    Gmm = sp.identity(A.shape[0], format="csr") - A
    X = sp.csr_matrix(B)
    term = X
    for _ in range(A.shape[0] + 1):
        term = sp.csr_matrix(Gmm @ term)
        term.eliminate_zeros()
        if term.nnz == 0:
            return X
        X = X + term
    raise InputError("rigid elements form a cycle", fix="break the chain of dependent nodes")


def _mass_props(M: Any, r: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass, centre of mass and inertia about it from M and the rigid vectors (n, 6).

    The rotations of ``r`` are about a reference point; the centre of mass is returned
    relative to it.
    """
    mrr = np.asarray(r.T @ (M @ r))
    mrr = 0.5 * (mrr + mrr.T)
    total = float(np.trace(mrr[:3, :3]) / 3.0)
    if not total > 0:
        raise InputError("the model has no mass", fix="give elements density or add masses")
    first = np.array([mrr[1, 5], mrr[2, 3], mrr[0, 4]])  # sum m p, from the coupling block
    cm = first / total
    inertia = mrr[3:, 3:] - total * (float(cm @ cm) * np.eye(3) - np.outer(cm, cm))
    return total, cm, 0.5 * (inertia + inertia.T)


def mass_properties_of(
    M: Any, positions: np.ndarray, dofs: np.ndarray | None = None
) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass (kg), centre of mass (m) and inertia about it (kg m^2) of a frame model.

    ``r^T M r`` for the exact rigid-body vectors ``r`` about the model's mean node, then
    about the centre of mass so found (lever arms formed once, from each node's offset to
    that point: a model 5 km from the origin loses nothing to the shift).

    Parameters
    ----------
    M : sparse (n, n)
        Mass matrix on the DOFs ``dofs`` of the 6-DOF nodes at ``positions``.
    positions : ndarray (nn, 3)
        Node positions, m.
    dofs : ndarray of int, optional
        The node DOFs (``6 node + k``) the coordinates are (default: all, in order).
    """
    P = np.asarray(positions, float)
    sel = slice(None) if dofs is None else np.asarray(dofs)
    c0 = P.mean(axis=0) if P.size else np.zeros(3)
    total, d, _ = _mass_props(M, rigid_link(P - c0).reshape(-1, 6)[sel])
    cm = c0 + d
    total, d2, inertia = _mass_props(M, rigid_link(P - cm).reshape(-1, 6)[sel])
    return total, cm + d2, inertia


def build_frame(
    graph: GraphModel,
    *,
    mass: str | None = None,
    constrained: bool = False,
    condense_max: int = CONDENSE_MAX,
) -> Structure:
    """Assemble the free-free frame finite-element model of a graph.

    Parameters
    ----------
    graph : GraphModel
    mass : {"lumped", "consistent"}, optional
        Mass formulation; default the model's (a NASTRAN deck's is lumped unless COUPMASS).
    constrained : bool
        Apply the model's single-point constraints (for validation against clamped decks);
        the structure then has no rigid-body vectors.
    condense_max : int
        Largest number of retained DOFs when massless DOFs are condensed (dense).

    Returns
    -------
    Structure
        Method ``"fem"``; sparse CSR matrices, or dense ones when massless DOFs were
        condensed; a :class:`PointMap` per named point (and per node on lookup by name),
        exact rigid-body vectors, :class:`FrameSamples` as ``samples``; ``meta`` carries the
        damping matrices (``damping``, ``structural_damping``, in the coordinates), the
        ``transform`` from the independent set to the 6 DOFs per node (``u_g = transform @
        samples.expand(q)``), the removed and condensed DOF counts and ``warnings``.
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    fm = assemble_frame(graph, mass=mass)
    T = fm.transform
    warnings: list[str] = []
    n_ind = T.shape[1]
    keep = np.ones(n_ind, bool)
    applied: list[str] = []
    if graph.constraints and not constrained:
        nodes = sorted({c.node for c in graph.constraints})
        shown = ", ".join(nodes[:5]) + (", ..." if len(nodes) > 5 else "")
        warnings.append(
            f"the model's single-point constraints (SPC) at {len(nodes)} node(s) ({shown}) are "
            "not applied: this is the free-free structure (constrained=True, or --constrained, "
            "applies them, as a clamped NASTRAN run does)"
        )
    if constrained:
        index = graph.node_index()
        pos_ind = np.full(T.shape[0], -1)
        pos_ind[fm.independent] = np.arange(fm.independent.size)
        for c in graph.constraints:
            i = index[c.node]
            for k in _basic_dofs(graph.nodes[i], c.components, where=f"constraint on {c.node}"):
                j = pos_ind[6 * i + k]
                if j < 0:
                    raise InputError(
                        f"component {k + 1} of node {c.node!r} is constrained and dependent",
                        where=f"constraint on {c.node}",
                        fix="constrain the independent node of the rigid element instead",
                    )
                keep[j] = False
            applied.append(f"{c.node}:{c.components}")
    Kn = sp.csr_matrix(T.T @ fm.stiffness @ T)
    Mn = sp.csr_matrix(T.T @ fm.mass @ T)
    Cn = sp.csr_matrix(T.T @ fm.damping @ T)
    Gn = sp.csr_matrix(T.T @ fm.structural_damping @ T)
    k_abs = np.asarray(abs(Kn).sum(axis=1)).ravel()
    m_abs = np.asarray(abs(Mn).sum(axis=1)).ravel()
    k_scale = float(np.max(Kn.diagonal())) if Kn.nnz else 0.0
    unconnected = keep & (k_abs <= 1e-14 * max(k_scale, 1e-300)) & (m_abs == 0)
    keep &= ~unconnected
    live = np.flatnonzero(keep)
    names = fm.names
    ind_labels = [f"{names[d // 6]}:{DOF_NAMES[d % 6]}" for d in fm.independent]
    # massless directions: zero rows, and null directions of small coupled mass blocks
    # (a node whose lumped torsional inertias span fewer than three axes)
    Q, null, ind_labels = _mass_basis(Mn, live, ind_labels)
    if Q is not None:
        T = sp.csr_matrix(T @ Q)
        Kn, Mn = sp.csr_matrix(Q.T @ Kn @ Q), sp.csr_matrix(Q.T @ Mn @ Q)
        Cn, Gn = sp.csr_matrix(Q.T @ Cn @ Q), sp.csr_matrix(Q.T @ Gn @ Q)
    massless = live[null[live]]
    retained = live[~null[live]]
    if retained.size == 0:
        raise InputError(
            "the model has no mass",
            where=graph.source or graph.name,
            fix="give elements density or add masses",
        )
    if unconnected.any():
        warnings.append(
            f"{int(unconnected.sum())} DOFs with neither stiffness nor mass removed "
            "(as NASTRAN AUTOSPC)"
        )
    Kaa = Kn[retained][:, retained]
    Maa = Mn[retained][:, retained]
    X = np.zeros((0, retained.size))
    if massless.size:
        if retained.size > condense_max:
            raise InputError(
                f"{massless.size} DOFs carry no mass (lumped mass: bending rotations); condensing "
                f"them exactly leaves {retained.size} DOFs, a dense matrix beyond the limit of "
                f"{condense_max}",
                where="mass",
                fix="use mass='consistent' (NASTRAN PARAM,COUPMASS,1) or add rotary inertia",
            )
        Koo = Kn[massless][:, massless].tocsc()
        Koa = Kn[massless][:, retained].toarray()
        try:
            lu = spla.splu(Koo)
            piv = np.abs(lu.U.diagonal())
            singular = piv.min() <= 1e-12 * piv.max()
            X = -lu.solve(Koa)
        except RuntimeError:
            singular = True
        if singular or not np.all(np.isfinite(X)):
            d = _weak_dofs(Koo)
            labs = ", ".join(ind_labels[massless[i]] for i in d[:6])
            raise InputError(
                f"a massless part of the model is a mechanism (DOFs {labs} have neither mass "
                "nor stiffness against it)",
                where=graph.source or graph.name,
                fix="connect it, or give it mass",
            )
        Kd = Kaa.toarray() + np.asarray(Kn[retained][:, massless] @ X)
        K_out: Any = 0.5 * (Kd + Kd.T)
        M_out: Any = Maa.toarray()
        Cd = _condense_full(Cn, retained, massless, X)
        Gd = _condense_full(Gn, retained, massless, X)
        C_out: Any = Cd
        G_out: Any = Gd
    else:
        K_out, M_out = Kaa.tocsr(), Maa.tocsr()
        C_out = Cn[retained][:, retained].tocsr()
        G_out = Gn[retained][:, retained].tocsr()
    labels = tuple(ind_labels[i] for i in retained)

    # mass properties from the unconstrained mass and the exact rigid vectors about a point
    # of the model (its mean node: lever arms of the model's size, not of its distance from
    # the origin, whose rounding would cancel in the shift to the centre of mass)
    P = fm.positions
    total, cm, inertia = mass_properties_of(
        fm.transform.T @ fm.mass @ fm.transform, P, fm.independent
    )
    # rigid-body vectors: exact unit motions about the centre of mass (lever arms formed once,
    # as microg.structure.fem does), restricted to the retained coordinates
    r_ind = rigid_link(P - cm).reshape(-1, 6)[fm.independent]
    r_ret = (r_ind if Q is None else np.asarray(Q.T @ r_ind))[retained]
    rigid = (
        {}
        if constrained and applied
        else {d: r_ret[:, k].copy() for k, d in enumerate(("x", "y", "z", "rx", "ry", "rz"))}
    )

    samples = _samples(graph, fm.positions, fm.names, T, retained, massless, X, n_ind)

    node_map = _NodeMap(graph.node_index(), P, T, retained, massless, X, n_ind)
    named = {p.name: _named_map(node_map, p) for p in graph.points}
    points = _PointMaps(named, node_map, {nd.name for nd in graph.nodes})
    meta = {
        "model": graph.name,
        "source": graph.source,
        "format": "graph",
        "mass_formulation": graph.mass_formulation if mass is None else mass,
        "n_nodes": len(graph.nodes),
        "n_elements": len(graph.beams)
        + len(graph.rods)
        + len(graph.springs)
        + len(graph.scalar_springs),
        "n_masses": len(graph.masses),
        "n_rigid_elements": len(graph.rigid_links) + len(graph.interpolations),
        "removed": int(unconnected.sum()),
        "condensed": int(massless.size),
        "constraints_applied": tuple(applied),
        "transform": T,
        "damping": C_out,
        "structural_damping": G_out,
        "node_positions": P,
        "node_names": names,
        "warnings": tuple(warnings) + tuple(graph.meta.get("warnings", ())),
        "graph_meta": dict(graph.meta),
    }
    return Structure(
        mass=M_out,
        stiffness=K_out,
        dof_labels=labels,
        points=points,
        rigid_body=rigid,
        method="fem",
        plane=None,
        total_mass=total,
        center_of_mass=cm,
        inertia_cm=inertia,
        samples=samples,
        meta=meta,
    )


#: coupled mass blocks up to this many DOFs are checked for massless directions
MASS_BLOCK_MAX = 60


def _mass_basis(
    M: sp.csr_matrix, live: np.ndarray, labels: list[str]
) -> tuple[sp.csr_matrix | None, np.ndarray, list[str]]:
    """Orthonormal change of coordinates exposing the massless directions of ``M``.

    ``M`` splits into blocks (connected components of its sparsity among the live DOFs:
    for lumped mass, one node each).  A zero row is massless as it is.  A small block
    (<= MASS_BLOCK_MAX DOFs) with null directions that are not coordinate axes has its
    affected DOFs replaced by an orthonormal basis: the complement of the null space
    (coordinates kept, labelled ``node:dofs:k``) and the null space (massless).  Blocks
    larger than that (consistent mass) are taken as they are.

    Returns
    -------
    Q : sparse (n, n) or None
        ``u_old = Q u_new``; None when no block needed turning.
    null : ndarray (n,) of bool
        Massless coordinates (new).
    labels : list of str
        Coordinate labels (new).
    """
    import scipy.linalg as sla
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    n = M.shape[0]
    null = np.zeros(n, bool)
    diag = M.diagonal()
    rows_zero = np.asarray(abs(M).sum(axis=1)).ravel() == 0
    null[live] = rows_zero[live]
    sub = M[live][:, live]
    ncomp, comp = connected_components(sub != 0, directed=False)
    order = np.argsort(comp, kind="stable")
    bounds = np.searchsorted(comp[order], np.arange(ncomp + 1))
    q_rows: list[np.ndarray] = []
    q_cols: list[np.ndarray] = []
    q_vals: list[np.ndarray] = []
    turned = np.zeros(n, bool)
    labels = list(labels)
    for c in range(ncomp):
        idx = live[order[bounds[c] : bounds[c + 1]]]
        if idx.size < 2 or idx.size > MASS_BLOCK_MAX or not np.all(diag[idx] > 0):
            continue
        B = M[idx][:, idx].toarray()
        w, V = np.linalg.eigh(0.5 * (B + B.T))
        nul = w <= 1e-12 * max(float(w.max()), 1e-300)
        if not nul.any():
            continue
        N = V[:, nul]
        affected = np.flatnonzero(np.max(np.abs(N), axis=1) > 1e-12)
        Ns = N[affected]
        C = sla.null_space(Ns.T)
        basis = np.concatenate([C, Ns], axis=1)  # (a, a): kept combinations, then massless
        dofs = idx[affected]
        q_rows.append(np.repeat(dofs, dofs.size))
        q_cols.append(np.tile(dofs, dofs.size))
        q_vals.append(basis.ravel())
        turned[dofs] = True
        null[dofs[C.shape[1] :]] = True
        null[dofs[: C.shape[1]]] = False
        head = labels[dofs[0]].rsplit(":", 1)[0]
        names = "/".join(labels[d].rsplit(":", 1)[1] for d in dofs)
        for k, d in enumerate(dofs):
            labels[d] = f"{head}:{names}:{k + 1}"
    if not turned.any():
        return None, null, labels
    keep = np.flatnonzero(~turned)
    Q = sp.csr_matrix(
        (
            np.concatenate([np.ones(keep.size), *q_vals]),
            (np.concatenate([keep, *q_rows]), np.concatenate([keep, *q_cols])),
        ),
        shape=(n, n),
    )
    return Q, null, labels


@dataclass(frozen=True)
class _NodeMap:
    """The point map of a node, or of a position carried rigidly by it.

    A class rather than a closure, so that a frame model's structure pickles (for the
    figure helper of ``microg analyze`` and for process pools).

    Attributes
    ----------
    index : dict of str to int
        Node name -> row of ``positions``.
    positions : ndarray (n, 3)
        Node positions, m.
    transform : sparse matrix (6 n, n_ind)
        Node DOFs from the independent coordinates.
    retained, massless : ndarray of int
        Independent coordinates kept, and those condensed out by ``condensed``.
    condensed : ndarray or None
        The massless coordinates as a function of the retained ones.
    n_ind : int
        Number of independent coordinates.
    """

    index: dict[str, int]
    positions: np.ndarray
    transform: Any
    retained: np.ndarray
    massless: np.ndarray
    condensed: Any
    n_ind: int

    def __call__(self, name: str, position: np.ndarray | None = None) -> PointMap:
        i = self.index[name]
        node = self.positions[i]
        pos = node if position is None else np.asarray(position, float)
        full = np.zeros((6, self.n_ind))
        full[:] = self.transform[6 * i : 6 * i + 6].toarray()
        coords = full[:, self.retained] + (
            full[:, self.massless] @ self.condensed if self.massless.size else 0.0
        )
        tr = rigid_link(pos - node)[:3] @ coords
        return PointMap(name=name, position=pos.copy(), translation=tr, rotation=coords[3:].copy())


def _named_map(node_map: Any, p: GraphPoint) -> PointMap:
    m = node_map(p.node, p.position)
    return PointMap(
        name=p.name, position=m.position, translation=m.translation, rotation=m.rotation
    )


def _condense_full(A: sp.csr_matrix, a: np.ndarray, o: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``E^T A E`` with ``E = [I; X]`` over the retained (a) and condensed (o) sets, dense."""
    Aaa = A[a][:, a].toarray()
    Aao = A[a][:, o]
    Aoo = A[o][:, o]
    out = Aaa + np.asarray(Aao @ X) + np.asarray(Aao @ X).T + X.T @ np.asarray(Aoo @ X)
    return 0.5 * (out + out.T)


def _weak_dofs(Koo: sp.csc_matrix) -> list[int]:
    """Indices of the DOFs that dominate the near-null space of a singular K_oo."""
    if Koo.shape[0] <= 3000:
        w, v = np.linalg.eigh(Koo.toarray())
        null = v[:, np.abs(w) <= 1e-10 * max(float(np.max(np.abs(w))), 1e-300)]
        if null.size:
            weight = np.max(np.abs(null), axis=1)
            return [int(i) for i in np.flatnonzero(weight > 0.1 * weight.max())]
    return [int(i) for i in np.flatnonzero(np.asarray(abs(Koo).sum(axis=1)).ravel() == 0)]


def _samples(
    graph: GraphModel,
    positions: np.ndarray,
    names: tuple[str, ...],
    T: sp.csr_matrix,
    retained: np.ndarray,
    massless: np.ndarray,
    X: np.ndarray,
    n_ind: int,
) -> FrameSamples:
    """Samples at the connected nodes and at the concentrated masses off their nodes."""
    import scipy.sparse as sp

    live = np.zeros(n_ind, bool)
    live[retained] = True
    live[massless] = True
    # a node is a sample if some DOF of it depends on a live coordinate
    reach = np.asarray(abs(T) @ live.astype(float)).reshape(-1, 6).sum(axis=1) > 0
    nodes = [int(i) for i in np.flatnonzero(reach)]
    offs = [np.zeros(3)] * len(nodes)
    labels = [names[i] for i in nodes]
    index = graph.node_index()
    for m in graph.masses:
        if np.any(m.offset_m):
            i = index[m.node]
            nodes.append(i)
            offs.append(np.asarray(m.offset_m, float))
            # a station's body masses are named "body/mass" (graph_from_station): kept as they
            # are, the labels of microg.structure.fem's samples
            labels.append(m.name if "/" in m.name else f"{m.node}/{m.name}")
    # carriers as the acceleration maps read frame labels: "keel:n3" -> "keel" (a station's
    # beam, whose samples form a line), "core/orbiter" -> "core", "grid:7" -> "grid"
    comp = [lab.split("/", 1)[0].split(":", 1)[0] for lab in labels]
    nodes_arr = np.asarray(nodes, int)
    offset = np.array(offs, float).reshape(-1, 3)
    sel = (6 * nodes_arr[:, None] + np.arange(6)).ravel()
    rows = sp.csr_matrix(T[sel])
    # the independent set, with the condensed DOFs recovered and everything else zero
    keep_idx = np.zeros(n_ind, bool)
    keep_idx[retained] = True
    keep_idx[massless] = True
    rows = sp.csr_matrix(rows @ sp.diags(keep_idx.astype(float)))
    return FrameSamples(
        position=positions[nodes_arr] + offset,
        labels=tuple(labels),
        component=np.array(comp, dtype=str),
        offset=offset,
        rows=rows,
        retained=retained,
        condensed=massless,
        recovery=X,
        n_ind=n_ind,
    )


# --------------------------------------------------------------------------- station mesher


@dataclass
class _Mesh:
    """Working state of the mesher (private)."""

    positions: list[np.ndarray] = field(default_factory=list)
    names: list[str] = field(default_factory=list)
    body_node: dict[str, int] = field(default_factory=dict)
    beam_s: dict[str, np.ndarray] = field(default_factory=dict)
    beam_ref: dict[str, np.ndarray] = field(default_factory=dict)
    beam_off: dict[str, np.ndarray] = field(default_factory=dict)

    def add(self, position: np.ndarray, name: str) -> int:
        self.positions.append(np.asarray(position, float))
        self.names.append(name)
        return len(self.positions) - 1

    def locate(
        self, station: Station, component: str, position: np.ndarray
    ) -> tuple[int, np.ndarray]:
        """Independent node carrying ``position`` on ``component``, and the offset to it."""
        position = np.asarray(position, float)
        if component in self.body_node:
            node = self.body_node[component]
        elif component in self.beam_s:
            beam = station.component(component)
            assert isinstance(beam, Beam)  # beam_s holds only beams
            k = int(np.argmin(np.abs(self.beam_s[component] - beam.arc_length(position))))
            node = int(self.beam_ref[component][k])
        else:
            raise InputError(
                f"component {component!r} is not meshed (not in tree order)",
                fix="list every beam after its parent and every body after its carrier beam",
            )
        return node, position - self.positions[node]


def _beam_stations(beam: Beam, station: Station, h: float) -> np.ndarray:
    """Arc lengths of the nodes of ``beam``: breakpoints kept, segments split evenly."""
    L = beam.length
    cuts = [0.0, L]
    cuts += [beam.arc_length(pm.position) for pm in beam.masses]
    cuts += [beam.arc_length(p.position) for p in station.points if p.on == beam.name]
    cuts += [beam.arc_length(b.root) for b in station.beams if b.parent == beam.name]
    cuts += [
        beam.arc_length(b.attach)
        for b in station.bodies
        if b.parent == beam.name and b.attach is not None
    ]
    cuts_arr = np.unique(np.clip(np.asarray(cuts, float), 0.0, L))
    keep = np.concatenate([[True], np.diff(cuts_arr) > 1e-9 * L])
    cuts_arr = cuts_arr[keep]
    cuts_arr[-1] = L
    out = [np.zeros(1)]
    for a, b in zip(cuts_arr[:-1], cuts_arr[1:], strict=True):
        n = max(1, math.ceil((b - a) / h - 1e-9))
        out.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(out)


def _body_reference(body: RigidBody, station: Station) -> np.ndarray:
    for bm in station.beams:
        if bm.parent == body.name:
            return np.asarray(bm.root, float)
    if body.masses:
        m = np.array([pm.mass for pm in body.masses])
        p = np.array([pm.position for pm in body.masses], float)
        return m @ p / m.sum()
    return np.zeros(3)


def torsion_is_rigid(beam: Beam) -> bool:
    """True when ``beam``'s torsional stiffness is zero or numerically zero.

    The rule (docs/model-format.md): ``gj <= GJ_ZERO_FRACTION max(EI_y, EI_z)`` is treated
    exactly like ``gj = 0``, i.e. torsionally rigid.

    Parameters
    ----------
    beam : Beam
    """
    return not beam.gj > GJ_ZERO_FRACTION * max(beam.ei_y, beam.ei_z)


def _effective_properties(beam: Beam) -> tuple[float, float, float]:
    """Axial stiffness (N), torsional stiffness (N m^2) and rho J (kg m) used for ``beam``."""
    ei_max = max(beam.ei_y, beam.ei_z)
    ea = beam.ea if beam.ea is not None else AXIAL_PENALTY * ei_max / beam.length**2
    gj = TORSION_PENALTY * ei_max if torsion_is_rigid(beam) else beam.gj
    return float(ea), float(gj), beam.polar_mass_per_length


def _mass_properties(station: Station) -> tuple[float, np.ndarray, np.ndarray]:
    """Station.mass_properties() plus the beams' polar (torsional) mass moments."""
    total, cm, inertia = station.mass_properties()
    for bm in station.beams:
        _, _, rho_j = _effective_properties(bm)
        inertia = inertia + rho_j * bm.length * np.outer(bm.direction, bm.direction)
    return total, cm, inertia


# --------------------------------------------------------------------------- station -> graph


#: largest frame model (degrees of freedom, 6 per node) a station is meshed into: checked
#: before any node is made.  A 500,000-DOF sparse model takes ~0.5 GB for its matrices and
#: 60 modes (~6 s to solve on this project's machine, 1 thread); the shipped IOC model has
#: ~42,000 nodes (250,000 DOFs) at the CLI's largest --elements 10,000.
MAX_FEM_DOF = 500_000


@dataclass
class StationMesh:
    """The one meshing of a tree-of-beams station (nodes and beam elements), before assembly.

    Attributes
    ----------
    mesh : _Mesh
        Node positions and names, the node of each body, each beam's node arc lengths and
        nodes.
    elements : list of tuple
        ``(beam, e, node_a, node_b, offset_a)`` per element, in tree order (parents first):
        element ``e`` of ``beam`` from node ``a`` to node ``b``; ``offset_a`` is the rigid
        offset from node ``a`` to the element's start (non-zero for a beam's root on a body).
    """

    mesh: _Mesh
    elements: list[tuple[Beam, int, int, int, np.ndarray]]


def _element_size(
    beam: Beam, elements_per_beam: int | None, max_element_length: float | None
) -> float:
    """Target element length of ``beam``, m: the finer of the two options (default 10)."""
    if elements_per_beam is None and max_element_length is None:
        return beam.length / DEFAULT_ELEMENTS_PER_BEAM
    hs = [] if elements_per_beam is None else [beam.length / int(elements_per_beam)]
    if max_element_length is not None:
        hs.append(float(max_element_length))
    return min(hs)


def mesh_station(
    station: Station,
    *,
    elements_per_beam: int | None = None,
    max_element_length: float | None = None,
) -> StationMesh:
    """Mesh a tree station: nodes at bodies, joints, masses and points, beams cut evenly.

    A root body's node is at the root of its first beam (else at its masses' centre of
    mass); a body riding on a beam shares the beam's node at its attach point; a beam on a
    beam starts at the carrier's node nearest its root.  Every beam is cut at its masses,
    points and joints, and each segment evenly into elements no longer than the target
    (:func:`_element_size`).

    Parameters
    ----------
    station : Station
    elements_per_beam : int, optional
        Minimum number of elements per beam.
    max_element_length : float, optional
        Largest element length, m.

    Raises
    ------
    InputError
        A mesh beyond :data:`MAX_FEM_DOF` (checked before any node is made), or a model
        not in tree order.
    """
    if not station.bodies:
        raise InputError("the station has no rigid body", fix="add a root [[body]]")
    for v, what in (
        (elements_per_beam, "elements_per_beam"),
        (max_element_length, "max_element_length"),
    ):
        if v is not None and not (v > 0):
            raise InputError(f"{what} must be positive, got {v!r}", where=what)
    # the size before the mesh: a bound from the options alone, then the exact count
    n_bodies = sum(1 for b in station.bodies if b.parent is None)
    estimate = n_bodies + sum(
        beam.length / _element_size(beam, elements_per_beam, max_element_length)
        for beam in station.beams
    )
    if 6.0 * estimate > 2.0 * MAX_FEM_DOF:
        _too_many(6.0 * estimate, elements_per_beam, max_element_length, station)
    stations = {}
    for beam in station.beams:
        h = _element_size(beam, elements_per_beam, max_element_length)
        stations[beam.name] = _beam_stations(beam, station, h)
    n_dof = 6 * (n_bodies + sum(s.size - 1 for s in stations.values()))
    if n_dof > MAX_FEM_DOF:
        _too_many(n_dof, elements_per_beam, max_element_length, station)

    mesh = _Mesh()
    for body in station.bodies:
        if body.parent is None:
            mesh.body_node[body.name] = mesh.add(_body_reference(body, station), body.name)
    elements: list[tuple[Beam, int, int, int, np.ndarray]] = []
    for beam in station.beams:
        if beam.parent in mesh.body_node:
            parent_node = mesh.body_node[beam.parent]
        elif beam.parent in mesh.beam_s:
            parent_node, _ = mesh.locate(station, beam.parent, beam.root)
        else:
            raise InputError(
                f"beam {beam.name!r}: parent {beam.parent!r} is not defined before it",
                where=f"beam {beam.name}",
                fix="list beams in tree order (parents first)",
            )
        s = stations[beam.name]
        pos = beam.station_position(s)
        ref = np.empty(s.size, int)
        ref[0] = parent_node
        ref[1:] = [mesh.add(pos[i], f"{beam.name}:n{i}") for i in range(1, s.size)]
        mesh.beam_s[beam.name], mesh.beam_ref[beam.name] = s, ref
        mesh.beam_off[beam.name] = np.zeros((s.size, 3))
        root_off = pos[0] - mesh.positions[parent_node]
        for e in range(s.size - 1):
            off_a = root_off if e == 0 else np.zeros(3)
            elements.append((beam, e, int(ref[e]), int(ref[e + 1]), off_a))
        for body in station.bodies:
            if body.parent == beam.name:
                attach = body.attach if body.attach is not None else beam.root
                node, _ = mesh.locate(station, beam.name, attach)
                mesh.body_node[body.name] = node
    for body in station.bodies:
        if body.name not in mesh.body_node:
            raise InputError(
                f"body {body.name!r} rides on {body.parent!r}, which is not a beam of the model",
                where=f"body {body.name}",
            )
    return StationMesh(mesh, elements)


def _too_many(
    n_dof: float,
    elements_per_beam: int | None,
    max_element_length: float | None,
    station: Station,
) -> None:
    """Refuse a mesh beyond :data:`MAX_FEM_DOF`, naming the option and the largest value."""
    where = "elements_per_beam" if elements_per_beam is not None else "max_element_length"
    n_beams = max(len(station.beams), 1)
    most = max(1, int(MAX_FEM_DOF / (6 * 1.05 * n_beams)))
    if elements_per_beam is not None:
        fix = f"use at most ~{most} elements per beam for this model"
    else:
        total = sum(b.length for b in station.beams)
        fix = f"use a max_element_length of at least ~{1.05 * total * 6 / MAX_FEM_DOF:.3g} m"
    raise InputError(
        f"the frame mesh would have ~{n_dof:.3g} degrees of freedom, beyond the limit of "
        f"{MAX_FEM_DOF:,}",
        where=where,
        fix=fix,
    )


def graph_from_station(
    station: Station,
    *,
    elements_per_beam: int | None = None,
    max_element_length: float | None = None,
    gravity_gradient: bool = False,
) -> GraphModel:
    """The tree-of-beams station as a graph model, meshed by :func:`mesh_station`.

    Nodes named ``body`` and ``beam:nK``; Euler-Bernoulli elements with consistent mass and
    the station's effective properties (penalty EA for axially rigid beams, GJ for
    ``gj = 0``, polar mass moment: :func:`_effective_properties`); beam roots on bodies as
    rigid end offsets; point masses as concentrated masses at their nodes (named
    ``carrier/mass``, bodies' first); named points riding on their nodes; and the
    gravity-gradient stiffness (``gravity_gradient=True``) as a grounded spring on the root
    body's rotations.  :func:`microg.structure.fem.build_fem` assembles this graph (its
    tree solver is the same model's exact flexibility), and :func:`build_frame` of it has
    the same matrices.

    Parameters
    ----------
    station : Station
    elements_per_beam, max_element_length : optional
        As for :func:`mesh_station`.
    gravity_gradient : bool
        Add the libration stiffness of Eqs. 2.27-2.28 on the root body's rotations (a
        stable attitude only: a spring cannot be negative; ``build_fem`` reports an
        unstable one as an unstable mode).
    """
    sm = mesh_station(
        station, elements_per_beam=elements_per_beam, max_element_length=max_element_length
    )
    mesh = sm.mesh
    sections: dict[str, BeamSection] = {}
    for beam in station.beams:
        ea, gj, rho_j = _effective_properties(beam)
        sections[beam.name] = BeamSection(
            beam.name, ea, beam.ei_y, beam.ei_z, gj, beam.mass_per_length, rho_j
        )
    beams = [
        BeamElement(
            f"{beam.name}:e{e}",
            (mesh.names[a], mesh.names[b]),
            sections[beam.name],
            np.asarray(beam.orientation, float),
            np.stack([off_a, np.zeros(3)]),
        )
        for beam, e, a, b, off_a in sm.elements
    ]
    masses: list[ConcentratedMass] = []
    carriers = [(bd.name, pm) for bd in station.bodies for pm in bd.masses]
    carriers += [(bm.name, pm) for bm in station.beams for pm in bm.masses]
    for carrier, pm in carriers:
        node, off = mesh.locate(station, carrier, pm.position)
        masses.append(
            ConcentratedMass(
                f"{carrier}/{pm.name}",
                mesh.names[node],
                float(pm.mass),
                off,
                np.asarray(pm.inertia, float),
            )
        )
    points = []
    for p in station.points:
        node, _ = mesh.locate(station, p.on, p.position)
        points.append(
            GraphPoint(
                p.name, mesh.names[node], np.asarray(p.position, float), p.kind, p.description
            )
        )
    springs: list[Spring] = []
    root = mesh.names[mesh.body_node[station.bodies[0].name]]
    if gravity_gradient:
        _, _, inertia = _mass_properties(station)
        w2 = station.orbit.omega0**2
        ix, iy, iz = np.diag(inertia)
        k_roll, k_pitch = 3.0 * w2 * (iy - iz), 3.0 * w2 * (ix - iz)
        if k_roll < 0 or k_pitch < 0:
            raise InputError(
                "gravity gradient makes the attitude unstable (I_z is not the smallest moment)",
                fix="use gravity_gradient=False or a model whose keel lies along z",
            )
        k6 = np.diag([0.0, 0.0, 0.0, k_roll, k_pitch, 0.0])
        pos_root = mesh.positions[mesh.body_node[station.bodies[0].name]]
        springs.append(
            Spring("gravity-gradient", (root, None), k6, np.zeros((6, 6)), np.eye(3), pos_root)
        )
    nodes = tuple(
        Node(nm, np.asarray(p, float)) for nm, p in zip(mesh.names, mesh.positions, strict=True)
    )
    return GraphModel(
        name=station.name,
        nodes=nodes,
        beams=tuple(beams),
        springs=tuple(springs),
        masses=tuple(masses),
        points=tuple(points),
        mass_formulation="consistent",
        description=station.description,
        source=station.source,
        meta={"format": "station", "gravity_gradient": gravity_gradient},
    )
