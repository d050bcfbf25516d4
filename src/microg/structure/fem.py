"""Three-dimensional frame finite elements of a free-free station.

Each beam is cut into 12-DOF Euler-Bernoulli frame elements (3 translations and 3 small
rotations per node) with consistent mass; each rigid body is one 6-DOF master node.  The
assembled :class:`~microg.structure.Structure` has sparse (CSR) mass and stiffness matrices
and is always free-free: no degree of freedom is constrained.  (Validation against clamped
textbook beams deletes DOFs afterwards with :func:`constrain`.)

Modelling assumptions, each a documented choice:

* **Element.**  Cubic Hermite bending in both planes (``ei_z`` for bending about local z,
  i.e. deflection along local y; ``ei_y`` for bending about local y), linear axial and
  torsion.  Consistent mass for translation (``rho A``) and for torsion (polar mass moment
  ``rho J`` per length); bending rotary inertia (Rayleigh) and shear (Timoshenko) neglected.
* **Polar mass moment.**  Model files carry no section geometry.  With ``ea`` given,
  ``rho J = m' (EI_y + EI_z) / EA`` (exact for a homogeneous section: ``J_p = I_y + I_z``
  and ``I/A = EI/EA``).  With ``ea`` absent, a polar radius of gyration of 2 % of the beam
  length is assumed (``rho J = m' (0.02 L)^2``; a truss of bay width ``b`` has
  ``r_p = b / sqrt(2)``, so 2 % of a 90 m keel is a 2.5 m bay).  It is needed only to keep
  the mass matrix definite; it sets torsional frequencies, not bending ones.
* **Axially rigid beams** (``ea`` None) get a penalty ``EA = 1e6 max(EI) / L^2``: the first
  axial frequency is then about 450 times the first bending one, so the penalty lowers
  coupled bending frequencies by a relative ~1e-6 while the condition number grows by only
  ``1e6 (L_e / L)^2`` (a constraint elimination would couple every node of a beam through
  its axial DOF and destroy the band structure).
* **Torsionally free input** (``gj`` = 0, allowed by the model format for the planar report
  models) is treated as torsionally rigid, ``GJ = 1e4 max(EI)``: the report's assumed modes
  carry the solar boom round with the keel's rotation, and a free twist would be a mechanism.
  **The rule: a torsional stiffness ``gj <= GJ_ZERO_FRACTION max(EI_y, EI_z)``
  (``GJ_ZERO_FRACTION = 1e-12``) is numerically zero and is treated exactly like ``gj = 0``**
  (so ``gj = "1e-30 lbf*ft^2"`` and ``gj = 0`` give the same structure).  A torsion mode
  1e-6 of a bending frequency (``GJ/EI`` down to 1e-12) is still modelled as given.
* **Rigid bodies.**  A body's master node is at its attach point when it rides on a beam
  (the master *is* that beam node), else at the root of the first beam cantilevered from
  it, else at the centre of mass of its point masses.  Its point masses are lumped into the
  master's 6x6 rigid-body mass (mass, offset coupling, parallel-axis inertia).
* **Joints.**  A beam root on a body is linked rigidly to the master node (the slave DOFs
  are eliminated exactly by the transformation ``u_s = u_m + theta_m x d``,
  ``theta_s = theta_m``; no penalty).  A beam root on a beam, and a body on a beam, share a
  node of the carrier beam (one is placed there).
* **Gravity gradient** (optional): the libration stiffness of Eqs. 2.27-2.28,
  ``3 w0^2 (I_y - I_z)`` on roll (x) and ``3 w0^2 (I_x - I_z)`` on pitch (y), centre-of-mass
  principal moments taken as the diagonal of the inertia tensor, is added on the root body's
  master rotations.  The exact linearised roll-yaw equations (with gyroscopic coupling and
  ``4 w0^2`` on roll) differ; like the report, this keeps pitch exact and roll approximate.
  Elastic modes change by the same tiny relative amount as in the Ritz model (~1e-7).
  When ``I_z`` is not the smallest moment the restoring stiffness is negative: the attitude
  is unstable, and the solver reports that libration as an unstable mode (a growth rate, not
  a frequency) instead of refusing the model.
* **Rigid-body vectors** (:attr:`Structure.rigid_body`) are exact unit translations and unit
  rotations **about the station's centre of mass** (not the origin), so that they, and the
  rigid modes, do not depend on where the model sits in its frame.
* **Exact flexibility** (:class:`FrameTree`).  The model is a tree: every node but the root
  body's master is the far end of exactly one element.  With ``d_e = x_b - x_a`` the
  element's deformation is ``delta_e = q_b - T(d_e) q_a`` (``T`` the rigid link) and
  ``K = C^T D C`` with ``C`` unit lower triangular (nodes are numbered parents first) and
  ``D`` the block diagonal of the elements' cantilever stiffnesses (plus the gravity-gradient
  restraint of the root).  So ``G = C^-1 D^+ C^-T`` is a generalized inverse of ``K``
  (``K G K = K``) computed without cancellation: loads are summed from the tips to the
  root, deformations from the closed-form cantilever flexibilities, displacements summed
  back out.  The assembled ``K`` loses the lowest modes of fine meshes to round-off
  (relative error ~ eps (L/h)^4: 4e-3 at 10,000 elements on a beam); ``G`` keeps them to
  ~ eps L/h.  :func:`microg.dynamics.eigsparse.solve_sparse` uses it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from microg.errors import InputError
from microg.models.station import POLAR_GYRATION_FRACTION, Beam, PointMass, RigidBody, Station
from microg.structure.structure import PointMap, Structure

__all__ = [
    "FrameStructure",
    "FrameTree",
    "NodeSamples",
    "build_fem",
    "constrain",
    "frame_mass_local",
    "frame_rotation",
    "frame_stiffness_local",
    "point_mass_matrix",
    "rigid_link",
    "torsion_is_rigid",
    "cantilever_flexibility_local",
    "DOF_NAMES",
    "AXIAL_PENALTY",
    "TORSION_PENALTY",
    "GJ_ZERO_FRACTION",
    "MAX_STIFFNESS_RATIO",
    "check_stiffness_contrast",
    "POLAR_GYRATION_FRACTION",
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
#: largest accepted ratio of the bending stiffnesses (EI) of two beams of one model.  Real
#: stations span a few decades (a truss 1e10 N m^2, a light antenna 1e3 N m^2); in double
#: precision a soft part 1e-12 of the stiff one keeps only ~4 digits in the rows where they
#: join, and beyond 1e16 it is lost entirely (documented in docs/model-format.md)
MAX_STIFFNESS_RATIO = 1e12
#: default number of elements per beam when neither discretisation option is given
DEFAULT_ELEMENTS_PER_BEAM = 10


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


def constrain(
    mass: sp.spmatrix, stiffness: sp.spmatrix, fixed_dofs: Sequence[int]
) -> tuple[sp.csr_matrix, sp.csr_matrix, np.ndarray]:
    """Delete DOFs (homogeneous boundary conditions) from mass and stiffness matrices.

    Station models are always free-free; this is for validation against clamped beams.

    Parameters
    ----------
    mass, stiffness : sparse (n, n)
    fixed_dofs : sequence of int
        Indices of the DOFs held at zero.

    Returns
    -------
    mass, stiffness : sparse CSR (n_free, n_free)
    free : ndarray of int
        Indices of the kept DOFs.
    """
    keep = np.ones(mass.shape[0], bool)
    keep[np.asarray(fixed_dofs, int)] = False
    free = np.flatnonzero(keep)
    m = sp.csr_matrix(mass)[free][:, free]
    k = sp.csr_matrix(stiffness)[free][:, free]
    return m.tocsr(), k.tocsr(), free


# --------------------------------------------------------------------------- exact flexibility


def cantilever_flexibility_local(
    length: np.ndarray, ea: np.ndarray, ei_y: np.ndarray, ei_z: np.ndarray, gj: np.ndarray
) -> np.ndarray:
    """Tip flexibility of frame elements clamped at their first end, local axes (closed form).

    The inverse of the far-end block ``k[6:, 6:]`` of :func:`frame_stiffness_local`: axial
    ``L/EA``, torsion ``L/GJ``, bending ``L/EI [[L^2/3, L/2], [L/2, 1]]`` for ``(v, theta_z)``
    and with the sign of ``theta_y = -dw/dx`` for ``(w, theta_y)`` (tip deflection and slope
    of a cantilever under a tip force and a tip moment, e.g. Roark, Table 8.1 cases 1a, 3a).

    Parameters
    ----------
    length : ndarray (ne,)
        Element lengths, m.
    ea : ndarray (ne,)
        Axial stiffness, N.
    ei_y, ei_z : ndarray (ne,)
        Bending stiffness about local y and local z, N m^2.
    gj : ndarray (ne,)
        Torsional stiffness, N m^2.

    Returns
    -------
    ndarray (ne, 6, 6)
        m/N, 1/N, rad/(N m) per unit tip load (u, v, w, theta_x, theta_y, theta_z).
    """
    L = np.asarray(length, float)
    f = np.zeros((L.size, 6, 6))
    f[:, 0, 0] = L / np.asarray(ea, float)
    f[:, 3, 3] = L / np.asarray(gj, float)
    for ei, (t, r, sign) in (
        (np.asarray(ei_z, float), (1, 5, 1.0)),
        (np.asarray(ei_y, float), (2, 4, -1.0)),
    ):
        f[:, t, t] = L**3 / (3.0 * ei)
        f[:, t, r] = f[:, r, t] = sign * L**2 / (2.0 * ei)
        f[:, r, r] = L / ei
    return f


@dataclass(frozen=True)
class FrameTree:
    """The tree of a frame model, for its exact generalized inverse ``G = C^-1 D^+ C^-T``.

    ``K = C^T D C``: ``(C q)_b = q_b - T(d_e) q_a`` for the element ``e`` from node ``a`` to
    node ``b`` (``T`` the rigid link, ``d_e = x_b - x_a``), ``(C q)_root = q_root``; ``D`` is
    block diagonal with each element's cantilever stiffness (station axes) and, for the root,
    the gravity-gradient restraint.  The module docstring says why ``G`` is accurate.

    Attributes
    ----------
    n_nodes : int
    root : int
        Node of the root body (the tree's root).
    parent, child : ndarray (ne,) of int
        Nodes ``a`` and ``b`` of each element (``child`` holds every node but the root once).
    offset : ndarray (ne, 3)
        ``x_b - x_a``, m.
    flexibility : ndarray (ne, 6, 6)
        Cantilever flexibility of each element in station axes (``D_e^-1``).
    root_stiffness : ndarray (6,)
        Restraint of the root's six coordinates (N/m, N m/rad): the gravity gradient on roll
        and pitch, zero elsewhere (negative for an unstable attitude).
    free : tuple of str
        The rigid-body directions ``K`` annihilates exactly (keys of ``rigid_body``).
    """

    n_nodes: int
    root: int
    parent: np.ndarray
    child: np.ndarray
    offset: np.ndarray
    flexibility: np.ndarray
    root_stiffness: np.ndarray
    free: tuple[str, ...]

    def kinematics(self) -> sp.csr_matrix:
        """The unit lower-triangular matrix ``C`` (nodes are numbered parents first)."""
        n = 6 * self.n_nodes
        t = rigid_link(self.offset)
        rr = 6 * self.child[:, None, None] + np.arange(6)[None, :, None]
        cc = 6 * self.parent[:, None, None] + np.arange(6)[None, None, :]
        rows = np.concatenate([np.arange(n), np.broadcast_to(rr, t.shape).ravel()])
        cols = np.concatenate([np.arange(n), np.broadcast_to(cc, t.shape).ravel()])
        vals = np.concatenate([np.ones(n), -t.ravel()])
        c = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
        c.eliminate_zeros()
        return c

    def stiffness_blocks(self) -> np.ndarray:
        """``D``'s element blocks (ne, 6, 6): the inverse of :attr:`flexibility`."""
        return np.linalg.inv(self.flexibility)

    def factor(self) -> TreeFlexibility:
        """An operator applying ``G`` (the triangular factor is made once, O(n))."""
        return TreeFlexibility(self)


class TreeFlexibility:
    """Applies the generalized inverse ``G = C^-1 D^+ C^-T`` of a tree frame's stiffness.

    Parameters
    ----------
    tree : FrameTree
    """

    def __init__(self, tree: FrameTree) -> None:
        import scipy.sparse.linalg as spla

        self.tree = tree
        self.n = 6 * tree.n_nodes
        # C is unit lower triangular: no pivoting, no fill (L = C, U = I)
        self._lu = spla.splu(tree.kinematics().tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.0)
        k = np.asarray(tree.root_stiffness, float)
        root_inv = np.divide(1.0, k, out=np.zeros(6), where=k != 0.0)
        # D^+ as one block-diagonal sparse matrix (a single compiled product per application)
        child = 6 * tree.child[:, None] + np.arange(6)
        rows = np.broadcast_to(child[:, :, None], tree.flexibility.shape).ravel()
        cols = np.broadcast_to(child[:, None, :], tree.flexibility.shape).ravel()
        root = 6 * tree.root + np.arange(6)
        self._dplus = sp.csr_matrix(
            (
                np.concatenate([tree.flexibility.ravel(), root_inv]),
                (np.concatenate([rows, root]), np.concatenate([cols, root])),
            ),
            shape=(self.n, self.n),
        )

    def __call__(self, y: np.ndarray) -> np.ndarray:
        """``G y`` for ``y`` (n,) or (n, k): N and N m in, m and rad out."""
        y = np.asarray(y, float)
        one = y.ndim == 1
        yy = y.reshape(self.n, -1)
        z = self._lu.solve(yy, trans="T")  # internal forces carried by each element
        w = self._dplus @ z  # each element's deformation under its own load
        x = self._lu.solve(w)  # deformations summed out from the root
        return x.ravel() if one else x


def _frame_tree(
    P: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    R: np.ndarray,
    length: np.ndarray,
    props: np.ndarray,
    root: int,
    root_k: np.ndarray,
    free: tuple[str, ...],
) -> FrameTree | None:
    """The :class:`FrameTree` of an assembled mesh, or None if it is not a tree rooted there."""
    nn = P.shape[0]
    seen = np.zeros(nn, int)
    np.add.at(seen, b, 1)
    seen[root] += 1
    if np.any(seen != 1) or np.any(a >= b):
        return None  # not a tree numbered parents first: the generic solver handles it
    f_loc = cantilever_flexibility_local(length, props[:, 0], props[:, 1], props[:, 2], props[:, 3])
    r6 = np.zeros((length.size, 6, 6))
    r6[:, :3, :3] = R
    r6[:, 3:, 3:] = R
    flex = np.swapaxes(r6, 1, 2) @ f_loc @ r6
    return FrameTree(
        n_nodes=nn,
        root=int(root),
        parent=np.asarray(a, int),
        child=np.asarray(b, int),
        offset=P[b] - P[a],
        flexibility=0.5 * (flex + np.swapaxes(flex, 1, 2)),
        root_stiffness=np.asarray(root_k, float),
        free=free,
    )


@dataclass(frozen=True)
class FrameStructure(Structure):
    """A :class:`~microg.structure.Structure` of frame elements that knows its tree.

    Attributes
    ----------
    tree : FrameTree or None
        The exact flexibility's data (None for a model without beams).
    """

    tree: FrameTree | None = None


# --------------------------------------------------------------------------- samples


@dataclass(frozen=True)
class NodeSamples:
    """Translation of sample points (nodes and body masses) from coordinates, without dense maps.

    A sample rides rigidly on one node: ``u = u_node + theta_node x offset``.

    Attributes
    ----------
    position : ndarray (p, 3)
        Undeformed station-frame positions, m.
    labels : tuple of str
        One label per sample (``"keel:n3"``, ``"core/orbiter"``).
    dof_index : ndarray (p, 3) of int
        Coordinates of the carrying node's translations (x, y, z).
    rot_index : ndarray (p, 3) of int
        Coordinates of the carrying node's rotations.
    offset : ndarray (p, 3)
        Sample position minus carrying node position, m (zero for beam nodes).
    """

    position: np.ndarray
    labels: tuple[str, ...]
    dof_index: np.ndarray
    rot_index: np.ndarray
    offset: np.ndarray

    def __len__(self) -> int:
        return int(self.position.shape[0])

    def displacement(self, q: np.ndarray) -> np.ndarray:
        """Translations of the samples, m, for coordinates ``q`` (n,) or (n, m).

        Returns an array (p, 3) for a vector and (p, 3, m) for a matrix (one column each).
        """
        q = np.asarray(q)
        u = q[self.dof_index]
        th = q[self.rot_index]
        if q.ndim == 1:
            return u + np.cross(th, self.offset)
        return u + np.cross(th, self.offset[:, :, None], axisa=1, axisb=1, axisc=1)


# --------------------------------------------------------------------------- assembly


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


def check_stiffness_contrast(station: Station) -> None:
    """Refuse bending stiffnesses more than :data:`MAX_STIFFNESS_RATIO` apart.

    Parameters
    ----------
    station : Station

    Raises
    ------
    InputError
        Naming the softest beam, with the ratio.
    """
    if not station.beams:
        return
    ei = np.array([[b.ei_y, b.ei_z] for b in station.beams], float)
    lo, hi = np.unravel_index(np.argmin(ei), ei.shape), np.unravel_index(np.argmax(ei), ei.shape)
    ratio = ei[hi] / ei[lo]
    if ratio > MAX_STIFFNESS_RATIO:
        soft, stiff = station.beams[lo[0]].name, station.beams[hi[0]].name
        raise InputError(
            f"bending stiffness of beam {soft!r} is {ratio:.3g} times smaller than that of "
            f"{stiff!r}, beyond the limit {MAX_STIFFNESS_RATIO:g} that double precision "
            "resolves",
            where=f"beam {soft}",
            fix="check the value and its unit, or model the soft part as a point mass",
        )


def _effective_properties(beam: Beam) -> tuple[float, float, float]:
    """Axial stiffness (N), torsional stiffness (N m^2) and rho J (kg m) used for ``beam``."""
    ei_max = max(beam.ei_y, beam.ei_z)
    ea = beam.ea if beam.ea is not None else AXIAL_PENALTY * ei_max / beam.length**2
    gj = TORSION_PENALTY * ei_max if torsion_is_rigid(beam) else beam.gj
    return float(ea), float(gj), beam.polar_mass_per_length


def build_fem(
    station: Station,
    *,
    elements_per_beam: int | None = None,
    max_element_length: float | None = None,
    gravity_gradient: bool = False,
) -> Structure:
    """Assemble the free-free frame finite-element model of ``station``.

    Parameters
    ----------
    station : Station
    elements_per_beam : int, optional
        Minimum number of elements per beam (more where masses, points and joints cut it).
    max_element_length : float, optional
        Largest element length, m.  With both options the finer wins; with neither, 10
        elements per beam.
    gravity_gradient : bool
        Add the libration stiffness of Eqs. 2.27-2.28 on the root body's rotations.

    Returns
    -------
    Structure
        Sparse CSR mass and stiffness (method ``"fem"``, plane None), a :class:`PointMap`
        per named point, exact rigid-body vectors, and :class:`NodeSamples` as ``samples``.
    """
    if elements_per_beam is not None and (
        int(elements_per_beam) != elements_per_beam or elements_per_beam < 1
    ):
        raise InputError(
            f"elements_per_beam must be a positive integer, got {elements_per_beam!r}",
            where="elements_per_beam",
        )
    if max_element_length is not None and not (max_element_length > 0):
        raise InputError(
            f"max_element_length must be positive, got {max_element_length!r}",
            where="max_element_length",
        )
    if not station.bodies:
        raise InputError("the station has no rigid body", fix="add a root [[body]]")
    check_stiffness_contrast(station)
    for body in station.bodies[1:]:
        if body.parent is None:
            # a second free body is joined to nothing: six free motions (a mechanism)
            raise InputError(
                f"body {body.name!r} is attached to nothing (only the first body is the root): "
                "the structure has a mechanism, six free motions of that body",
                where=f"body {body.name}",
                fix="give it a parent beam and an attach point",
            )

    mesh = _Mesh()
    for body in station.bodies:
        if body.parent is None:
            mesh.body_node[body.name] = mesh.add(_body_reference(body, station), body.name)

    el: dict[str, list[np.ndarray]] = {k: [] for k in ("a", "b", "da", "db", "len", "dir", "ori")}
    props: list[np.ndarray] = []
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
        hs = [beam.length / DEFAULT_ELEMENTS_PER_BEAM]
        if elements_per_beam is not None or max_element_length is not None:
            hs = []
            if elements_per_beam is not None:
                hs.append(beam.length / int(elements_per_beam))
            if max_element_length is not None:
                hs.append(float(max_element_length))
        s = _beam_stations(beam, station, min(hs))
        pos = beam.station_position(s)
        ref = np.empty(s.size, int)
        ref[0] = parent_node
        ref[1:] = [mesh.add(pos[i], f"{beam.name}:n{i}") for i in range(1, s.size)]
        off = np.zeros((s.size, 3))
        off[0] = pos[0] - mesh.positions[parent_node]
        mesh.beam_s[beam.name], mesh.beam_ref[beam.name] = s, ref
        mesh.beam_off[beam.name] = off
        ne = s.size - 1
        el["a"].append(ref[:-1])
        el["b"].append(ref[1:])
        el["da"].append(off[:-1])
        el["db"].append(off[1:])
        el["len"].append(np.diff(s))
        el["dir"].append(np.broadcast_to(beam.direction, (ne, 3)))
        el["ori"].append(np.broadcast_to(beam.orientation, (ne, 3)))
        ea, gj, rho_j = _effective_properties(beam)
        props.append(
            np.broadcast_to([ea, beam.ei_y, beam.ei_z, gj, beam.mass_per_length, rho_j], (ne, 6))
        )
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

    n_nodes = len(mesh.positions)
    n = 6 * n_nodes
    P = np.array(mesh.positions).reshape(n_nodes, 3)
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    kval: list[np.ndarray] = []
    mval: list[np.ndarray] = []

    if station.beams:
        a = np.concatenate(el["a"])
        b = np.concatenate(el["b"])
        pr = np.concatenate(props)
        length = np.concatenate(el["len"])
        kloc = frame_stiffness_local(length, pr[:, 0], pr[:, 1], pr[:, 2], pr[:, 3])
        mloc = frame_mass_local(length, pr[:, 4], pr[:, 5])
        R = frame_rotation(np.concatenate(el["dir"]), np.concatenate(el["ori"]))
        ne = length.size
        A = np.zeros((ne, 12, 12))
        ta = rigid_link(np.concatenate(el["da"]))
        tb = rigid_link(np.concatenate(el["db"]))
        # A = blockdiag(R, R, R, R) @ blockdiag(T_a, T_b): local DOFs from independent DOFs
        for blk, t in ((0, ta), (1, tb)):
            o = 6 * blk
            A[:, o : o + 3, o : o + 6] = R @ t[:, :3, :]
            A[:, o + 3 : o + 6, o : o + 6] = R @ t[:, 3:, :]
        At = np.swapaxes(A, 1, 2)
        ke = At @ kloc @ A
        me = At @ mloc @ A
        dofs = np.concatenate([6 * a[:, None] + np.arange(6), 6 * b[:, None] + np.arange(6)], 1)
        rows.append(np.broadcast_to(dofs[:, :, None], (ne, 12, 12)).ravel())
        cols.append(np.broadcast_to(dofs[:, None, :], (ne, 12, 12)).ravel())
        kval.append(ke.ravel())
        mval.append(me.ravel())

    # point masses: on bodies (offset from the master), on beams (at their node)
    carriers: list[tuple[str, PointMass]] = [
        (bd.name, pm) for bd in station.bodies for pm in bd.masses
    ]
    carriers += [(bm.name, pm) for bm in station.beams for pm in bm.masses]
    if carriers:
        nodes, offs = zip(
            *(mesh.locate(station, c, pm.position) for c, pm in carriers), strict=True
        )
        pms = [pm for _, pm in carriers]
        m6 = point_mass_matrix(
            np.array([pm.mass for pm in pms]),
            np.array([pm.inertia for pm in pms], float).reshape(-1, 3, 3),
            np.array(offs),
        )
        d6 = 6 * np.asarray(nodes)[:, None] + np.arange(6)
        rows.append(np.broadcast_to(d6[:, :, None], m6.shape).ravel())
        cols.append(np.broadcast_to(d6[:, None, :], m6.shape).ravel())
        mval.append(m6.ravel())
        kval.append(np.zeros(m6.size))

    r_all = np.concatenate(rows) if rows else np.zeros(0, int)
    c_all = np.concatenate(cols) if cols else np.zeros(0, int)
    K = sp.coo_matrix((np.concatenate(kval), (r_all, c_all)), shape=(n, n)).tocsr()
    M = sp.coo_matrix((np.concatenate(mval), (r_all, c_all)), shape=(n, n)).tocsr()
    K = 0.5 * (K + K.T)
    M = 0.5 * (M + M.T)
    K.eliminate_zeros()
    M.eliminate_zeros()

    total, cm, inertia = _mass_properties(station)
    root_node = mesh.body_node[station.bodies[0].name]
    root_k = np.zeros(6)
    if gravity_gradient:
        # Eqs. 2.27-2.28 on the root's rotations; negative when I_z is not the smallest
        # moment (an unstable attitude: the solver reports it as an unstable libration)
        w2 = station.orbit.omega0**2
        ix, iy, iz = np.diag(inertia)
        root_k[3:5] = 3.0 * w2 * (iy - iz), 3.0 * w2 * (ix - iz)
        gg = sp.coo_matrix(
            (root_k[3:5], ([6 * root_node + 3, 6 * root_node + 4],) * 2), shape=(n, n)
        )
        K = (K + gg).tocsr()

    labels = tuple(f"{name}:{c}" for name in mesh.names for c in DOF_NAMES)
    rigid = _rigid_vectors(P, cm)
    tree = None
    if station.beams:
        tree = _frame_tree(
            P,
            np.concatenate(el["a"]),
            np.concatenate(el["b"]),
            R,
            length,
            pr,
            root_node,
            root_k,
            tuple(
                c
                for c, k in zip(("x", "y", "z", "rx", "ry", "rz"), root_k, strict=True)
                if k == 0.0
            ),
        )
    points = {}
    for p in station.points:
        node, off = mesh.locate(station, p.on, p.position)
        tr = np.zeros((3, n))
        rot = np.zeros((3, n))
        tr[:, 6 * node : 6 * node + 3] = np.eye(3)
        tr[:, 6 * node + 3 : 6 * node + 6] = -_skew(off)
        rot[:, 6 * node + 3 : 6 * node + 6] = np.eye(3)
        points[p.name] = PointMap(
            name=p.name, position=np.asarray(p.position, float), translation=tr, rotation=rot
        )

    samples = _samples(station, mesh, P)
    return FrameStructure(
        mass=M,
        stiffness=K,
        dof_labels=labels,
        points=points,
        rigid_body=rigid,
        method="fem",
        plane=None,
        total_mass=total,
        center_of_mass=cm,
        inertia_cm=inertia,
        samples=samples,
        meta={
            "model": station.name,
            "source": station.source,
            "n_nodes": n_nodes,
            "n_elements": int(sum(x.size for x in el["len"])),
            "elements_per_beam": elements_per_beam,
            "max_element_length": max_element_length,
            "gravity_gradient": gravity_gradient,
            "node_positions": P,
            "node_names": tuple(mesh.names),
            "assumptions": (
                f"axially rigid beams: EA = {AXIAL_PENALTY:g} max(EI)/L^2; "
                f"gj = 0: GJ = {TORSION_PENALTY:g} max(EI); polar mass rho J = m'(EI_y+EI_z)/EA, "
                f"or m'({POLAR_GYRATION_FRACTION:g} L)^2 without ea; "
                "inertia_cm includes the beams' polar mass moments; "
                f"gj <= {GJ_ZERO_FRACTION:g} max(EI) is treated as gj = 0"
            ),
        },
        tree=tree,
    )


def _mass_properties(station: Station) -> tuple[float, np.ndarray, np.ndarray]:
    """Station.mass_properties() plus the beams' polar (torsional) mass moments."""
    total, cm, inertia = station.mass_properties()
    for bm in station.beams:
        _, _, rho_j = _effective_properties(bm)
        inertia = inertia + rho_j * bm.length * np.outer(bm.direction, bm.direction)
    return total, cm, inertia


def _rigid_vectors(P: np.ndarray, center: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Unit rigid translations and rotations about ``center`` (the centre of mass), per node.

    The lever arms ``P - center`` are formed once, exactly as the model's own offsets, so
    the vectors do not depend on where the model sits in its frame (about the origin, a model
    50 m away carries 50 m lever arms whose rounding is ~1e-14 of the rows of ``K r``).
    """
    out = {}
    nn = P.shape[0]
    arm = P - (np.zeros(3) if center is None else np.asarray(center, float))
    for i, d in enumerate(("x", "y", "z")):
        v = np.zeros((nn, 6))
        v[:, i] = 1.0
        out[d] = v.ravel()
    for i, d in enumerate(("rx", "ry", "rz")):
        axis = np.zeros(3)
        axis[i] = 1.0
        v = np.zeros((nn, 6))
        v[:, :3] = np.cross(axis, arm)
        v[:, 3 + i] = 1.0
        out[d] = v.ravel()
    return out


def _samples(station: Station, mesh: _Mesh, P: np.ndarray) -> NodeSamples:
    nodes = list(range(P.shape[0]))
    offs = [np.zeros(3)] * len(nodes)
    labels = list(mesh.names)
    for body in station.bodies:
        for pm in body.masses:
            node, off = mesh.locate(station, body.name, pm.position)
            nodes.append(node)
            offs.append(off)
            labels.append(f"{body.name}/{pm.name}")
    nodes_arr = np.asarray(nodes)
    offset = np.array(offs).reshape(-1, 3)
    return NodeSamples(
        position=P[nodes_arr] + offset,
        labels=tuple(labels),
        dof_index=6 * nodes_arr[:, None] + np.arange(3),
        rot_index=6 * nodes_arr[:, None] + np.arange(3, 6),
        offset=offset,
    )


# --------------------------------------------------------------------------- helpers


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
