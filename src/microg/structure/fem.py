"""Three-dimensional frame finite elements of a free-free tree-of-beams station.

The tree station is a convenience that generates a frame graph: :func:`build_fem` meshes it
with :func:`microg.structure.mesh.graph_from_station` (the one mesher) and assembles that
graph with :func:`microg.structure.assembly.assemble_frame` (the one assembler, with the
kernels of :mod:`microg.structure.elements`), then keeps what only a tree has: its exact
flexibility (:class:`FrameTree`), used by the modal solvers. Each beam is cut into 12-DOF
Euler-Bernoulli frame elements (3 translations and 3 small rotations per node) with
consistent mass; each rigid body is one 6-DOF master node. The :class:`FrameStructure` has
sparse (CSR) mass and stiffness matrices and is always free-free: no degree of freedom is
constrained. (Validation against clamped textbook beams deletes DOFs afterwards with
:func:`constrain`.) Massless coordinates are kept (the solvers condense them exactly).

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
* **Rotary inertia.**  A station whose rigid rotations about its centre of mass have an
  inertia tensor with a principal moment at most :data:`INERTIA_ZERO_FRACTION` of its
  trace (zero to rounding: point masses on one line with no rotary inertia, a single point
  mass) is refused, naming the components: that rotation has neither inertia nor
  stiffness, a mechanism (:func:`check_rotary_inertia`).
* **Size.**  Meshes beyond :data:`~microg.structure.assembly.MAX_FEM_DOF` degrees of freedom
  are refused before any node is made.
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

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from microg.errors import InputError
from microg.models.graph_model import ConcentratedMass
from microg.models.station import POLAR_GYRATION_FRACTION, Station
from microg.structure.assembly import MAX_FEM_DOF, assemble_frame
from microg.structure.elements import (
    DOF_NAMES,
    frame_mass_local,
    frame_rotation,
    frame_stiffness_local,
    point_mass_matrix,
    rigid_link,
    skew,
)
from microg.structure.mesh import (
    AXIAL_PENALTY,
    DEFAULT_ELEMENTS_PER_BEAM,
    GJ_ZERO_FRACTION,
    TORSION_PENALTY,
    graph_from_station,
    station_mass_properties,
    torsion_is_rigid,
)
from microg.structure.structure import PointMap, Structure

if TYPE_CHECKING:  # scipy loads on first use: a figure helper unpickles these classes without it
    import scipy.sparse as sp

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
    "check_rotary_inertia",
    "DEFAULT_ELEMENTS_PER_BEAM",
    "DOF_NAMES",
    "AXIAL_PENALTY",
    "TORSION_PENALTY",
    "GJ_ZERO_FRACTION",
    "INERTIA_ZERO_FRACTION",
    "MAX_FEM_DOF",
    "MAX_STIFFNESS_RATIO",
    "check_stiffness_contrast",
    "POLAR_GYRATION_FRACTION",
]

#: largest accepted ratio of the bending stiffnesses (EI) of two beams of one model.  Real
#: stations span a few decades (a truss 1e10 N m^2, a light antenna 1e3 N m^2); in double
#: precision a soft part 1e-12 of the stiff one keeps only ~4 digits in the rows where they
#: join, and beyond 1e16 it is lost entirely (documented in docs/model-format.md)
MAX_STIFFNESS_RATIO = 1e12
#: a principal moment of the station's inertia about its centre of mass at most this
#: fraction of the tensor's trace is zero to rounding (the products r^T M r round at
#: ~eps of the trace; 1e-13 is ~450 eps): the rotation about that axis has no inertia
INERTIA_ZERO_FRACTION = 1e-13


# --------------------------------------------------------------------------- constraints


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
    import scipy.sparse as sp

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
        import scipy.sparse as sp

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
        import scipy.sparse as sp
        import scipy.sparse.linalg as spla

        self.tree = tree
        self.n = 6 * tree.n_nodes
        # C is unit lower triangular: no pivoting, no fill (L = C, U = I)
        self._lu = spla.splu(tree.kinematics().tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.0)
        k = np.asarray(tree.root_stiffness, float)
        root_inv = np.divide(1.0, k, out=np.zeros(6), where=k != 0.0)
        # D^+ as one block-diagonal BSR matrix of 6 x 6 blocks, block row = node (each node
        # but the root is the child of exactly one element; the root's block is its
        # restraint's inverse): no assembly sort, one compiled block product per application
        blocks = np.zeros((tree.n_nodes, 6, 6))
        blocks[tree.child] = tree.flexibility
        blocks[tree.root] = np.diag(root_inv)
        self._dplus = sp.bsr_matrix(
            (blocks, np.arange(tree.n_nodes), np.arange(tree.n_nodes + 1)),
            shape=(self.n, self.n),
        )

    def __call__(self, y: np.ndarray) -> np.ndarray:
        """``G y`` for ``y`` (n,) or (n, k): N and N m in, m and rad out."""
        y = np.asarray(y, float)
        if y.ndim == 1:
            z = self._lu.solve(y, trans="T")  # internal forces carried by each element
            return self._lu.solve(self._dplus @ z)  # element deformations summed from the root
        # several loads: SuperLU solves column by column on Fortran-ordered arrays (a C-ordered
        # block would be copied twice)
        z = self._lu.solve(np.asfortranarray(y.reshape(self.n, -1)), trans="T")
        w = np.asfortranarray(self._dplus @ z)
        return self._lu.solve(w)


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


def check_rotary_inertia(
    mass: sp.spmatrix, rigid_body: dict[str, np.ndarray], carriers: Sequence[str]
) -> None:
    """Refuse a model whose rigid rotation about some axis has no inertia (a mechanism).

    The inertia tensor the solver sees is ``J = R^T M R`` with ``R`` the unit rotations
    about the centre of mass.  A principal moment at most :data:`INERTIA_ZERO_FRACTION` of
    ``trace(J)`` is zero to rounding: the masses lie on one line (or at one point) and carry
    no rotary inertia about it, so that rotation has neither inertia nor stiffness.

    Parameters
    ----------
    mass : sparse (n, n)
        Mass matrix, SI.
    rigid_body : mapping
        The exact rigid vectors (``"rx"``, ``"ry"``, ``"rz"`` about the centre of mass).
    carriers : sequence of str
        The components carrying mass (``"body core"``, ``"beam keel"``), for the message.

    Raises
    ------
    InputError
        Naming the components and the axis.
    """
    rot = np.column_stack([rigid_body[d] for d in ("rx", "ry", "rz")])
    j = np.asarray(rot.T @ (mass @ rot))
    w, v = np.linalg.eigh(0.5 * (j + j.T))
    tr = float(np.trace(j))
    zero = w <= INERTIA_ZERO_FRACTION * tr if tr > 0 else np.ones(3, bool)
    if not zero.any():
        return
    where = ", ".join(carriers[:4]) + (
        f" and {len(carriers) - 4} more" if len(carriers) > 4 else ""
    )
    if zero.all():
        what = (
            "all its mass is at one point and carries no rotary inertia: its three rotations "
            "have neither inertia nor stiffness (a mechanism)"
        )
        fix = "give the point mass its rotary inertia (inertia = {xx = ..., yy = ..., zz = ...})"
    else:
        axis = v[:, int(np.argmin(w))]
        axis = axis * np.sign(axis[np.argmax(np.abs(axis))])
        what = (
            "its masses lie on one line (through the centre of mass, along "
            f"[{axis[0]:.3g}, {axis[1]:.3g}, {axis[2]:.3g}]) and carry no rotary inertia about "
            "it: the rotation about that line has neither inertia nor stiffness (a mechanism)"
        )
        fix = "give the point masses their rotary inertia, or add a mass off that line"
    lead = "" if len(carriers) == 1 else "the station: "
    raise InputError(lead + what, where=where or None, fix=fix)


def build_fem(
    station: Station,
    *,
    elements_per_beam: int | None = None,
    max_element_length: float | None = None,
    gravity_gradient: bool = False,
) -> FrameStructure:
    """Assemble the free-free frame finite-element model of ``station``.

    The station is meshed into a graph (:func:`microg.structure.mesh.graph_from_station`)
    and assembled by :func:`microg.structure.assembly.assemble_frame`; the tree of the mesh
    gives the exact flexibility (:class:`FrameTree`).

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
    FrameStructure
        Sparse CSR mass and stiffness (method ``"fem"``, plane None), a :class:`PointMap`
        per named point, exact rigid-body vectors, :class:`NodeSamples` as ``samples`` and
        the tree.

    Raises
    ------
    InputError
        Bad options, a mesh beyond :data:`MAX_FEM_DOF`, a body attached to nothing, a
        stiffness contrast beyond :data:`MAX_STIFFNESS_RATIO`, or a rotation without
        inertia (:func:`check_rotary_inertia`), each naming the parameter or component.
    """
    import scipy.sparse as sp

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

    graph = graph_from_station(
        station, elements_per_beam=elements_per_beam, max_element_length=max_element_length
    )
    fm = assemble_frame(graph)
    K, M = fm.stiffness, fm.mass
    P = fm.positions
    n_nodes = P.shape[0]
    n = 6 * n_nodes
    index = graph.node_index()

    total, cm, inertia = station_mass_properties(station)
    root_node = index[station.bodies[0].name]  # the root body's node is named after it
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
        K = sp.csr_matrix(K + gg)

    labels = tuple(f"{name}:{c}" for name in fm.names for c in DOF_NAMES)
    rigid = _rigid_vectors(P, cm)
    carriers = [f"body {b.name}" for b in station.bodies if b.masses]
    carriers += [f"beam {b.name}" for b in station.beams if b.masses or b.mass_per_length > 0]
    check_rotary_inertia(M, rigid, carriers)
    tree = None
    if graph.beams:
        a = np.array([index[b.nodes[0]] for b in graph.beams])
        b_ = np.array([index[b.nodes[1]] for b in graph.beams])
        pr = np.array(
            [
                [s.ea_N, s.ei_y_N_m2, s.ei_z_N_m2, s.gj_N_m2]
                for s in (b.section for b in graph.beams)
            ]
        )
        tree = _frame_tree(
            P,
            a,
            b_,
            fm.beam_rotation,
            fm.beam_length,
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
    for p in graph.points:
        node = index[p.node]
        off = np.asarray(p.position, float) - P[node]
        tr = np.zeros((3, n))
        rot = np.zeros((3, n))
        tr[:, 6 * node : 6 * node + 3] = np.eye(3)
        tr[:, 6 * node + 3 : 6 * node + 6] = -skew(off)
        rot[:, 6 * node + 3 : 6 * node + 6] = np.eye(3)
        points[p.name] = PointMap(
            name=p.name, position=np.asarray(p.position, float), translation=tr, rotation=rot
        )

    n_body_masses = sum(len(b.masses) for b in station.bodies)
    samples = _samples(P, fm.names, graph.masses[:n_body_masses], index)
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
            "n_elements": len(graph.beams),
            "elements_per_beam": elements_per_beam,
            "max_element_length": max_element_length,
            "gravity_gradient": gravity_gradient,
            "node_positions": P,
            "node_names": tuple(fm.names),
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


def _samples(
    P: np.ndarray,
    names: Sequence[str],
    body_masses: Sequence[ConcentratedMass],
    index: dict[str, int],
) -> NodeSamples:
    """Every node, then every body mass at its own position (``"body/mass"`` labels)."""
    nodes = list(range(P.shape[0]))
    offs = [np.zeros(3)] * len(nodes)
    labels = list(names)
    for gm in body_masses:
        nodes.append(index[gm.node])
        offs.append(np.asarray(gm.offset_m, float))
        labels.append(gm.name)
    nodes_arr = np.asarray(nodes)
    offset = np.array(offs).reshape(-1, 3)
    return NodeSamples(
        position=P[nodes_arr] + offset,
        labels=tuple(labels),
        dof_index=6 * nodes_arr[:, None] + np.arange(3),
        rot_index=6 * nodes_arr[:, None] + np.arange(3, 6),
        offset=offset,
    )
