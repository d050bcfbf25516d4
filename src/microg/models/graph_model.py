"""General frame models in memory: a graph of nodes and elements, frozen SI dataclasses.

A :class:`GraphModel` is what a NASTRAN bulk-data deck (:mod:`microg.models.bdf`) or a graph
TOML file (:mod:`microg.models.graph_toml`; format in ``docs/model-format.md``, "Graph
models") becomes, and what :func:`microg.structure.frame.build_frame` assembles into a
free-free :class:`~microg.structure.Structure`.  Unlike the tree-of-beams
:class:`~microg.models.station.Station` it allows closed loops, several load paths, springs
and dampers between any two nodes, rigid links and interpolation elements.
:func:`microg.structure.mesh.graph_from_station` writes a station as a graph;
:func:`microg.models.graph_check.validate_graph` checks one.

Conventions (all values SI: m, kg, s, N, rad):

* **Nodes** have a position in the basic (station) frame and *displacement axes*: the
  directions of their components 1-3 (translations) and 4-6 (rotations), rows of a 3x3
  rotation (identity for the basic frame; NASTRAN's GRID CD).  Components named on springs,
  links and constraints (``"123456"`` strings) are along these axes.
* **Beams** run from node a (plus offset a) to node b (plus offset b); local x along the
  beam, local y the orientation vector made perpendicular, local z = x cross y.  ``ei_z`` is
  the bending stiffness about local z (deflection along y: NASTRAN's plane 1, ``E I1``),
  ``ei_y`` about local y (deflection along z: plane 2, ``E I2``).  Without an orientation
  a beam takes the basic axis least aligned with it (:func:`default_orientation`).
* **Springs** (CBUSH) take their axes from a coordinate system, or from their nodes and an
  orientation vector (:func:`spring_axes`).
* **Mass formulation** is the model's: ``"lumped"`` (NASTRAN's default), ``"consistent"``
  (microg's), or NASTRAN's ``PARAM,COUPMASS`` mass of CBARs, ``"coupled"`` (Simcenter Nastran
  2020.2) and ``"coupled-nx9"`` (NX Nastran 9.1); :mod:`microg.structure.elements` documents
  them.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg.errors import InputError
from microg.models.coords import CoordinateFrame

__all__ = [
    "COMPONENTS",
    "MASS_FORMULATIONS",
    "MASS_NOTES",
    "NASTRAN_COUPLED_FORMS",
    "MAX_GRAPH_ITEMS",
    "PARALLEL_TOL",
    "ZERO_LENGTH_TOL",
    "BeamElement",
    "BeamSection",
    "ConcentratedMass",
    "Constraint",
    "GraphModel",
    "GraphPoint",
    "Interpolation",
    "MultiPointConstraint",
    "Node",
    "RigidLink",
    "RodElement",
    "ScalarMass",
    "ScalarSpring",
    "ShellElement",
    "ShellSection",
    "Spring",
    "default_orientation",
    "nearest_names",
    "parse_components",
    "spring_axes",
]

#: the six components of a node, NASTRAN's numbering: 1-3 translations, 4-6 rotations
COMPONENTS = "123456"
#: mass formulations of beams and rods: "lumped" (NASTRAN's default), "consistent" (microg's),
#: and NASTRAN's PARAM,COUPMASS mass of CBARs as Simcenter Nastran 2020.2 ("coupled") and NX
#: Nastran 9.1 ("coupled-nx9") form it
MASS_FORMULATIONS = ("lumped", "consistent", "coupled", "coupled-nx9")
#: the mass a deck with PARAM,COUPMASS > 0 may be read with: NASTRAN's coupled CBAR mass as
#: Simcenter 2020.2 or NX 9.1 form it, or microg's consistent mass (torsional inertia too)
NASTRAN_COUPLED_FORMS = ("coupled", "coupled-nx9", "consistent")
#: what each mass formulation is, one line for the output
MASS_NOTES = {
    "lumped": "half of each element's mass on each end's translations, a CBEAM's polar "
    "moment on its axial rotations too",
    "consistent": "microg's consistent mass: cubic (Timoshenko) translation, rotary and "
    "torsional inertia",
    "coupled": "NASTRAN's coupled CBAR mass as Simcenter Nastran 2020.2 forms it: consistent "
    "translation, no torsional inertia, the two ends' rotations uncoupled",
    "coupled-nx9": "NASTRAN's coupled CBAR mass as NX Nastran 9.1 forms it: consistent "
    "translation, no torsional inertia",
}
#: largest number of nodes, elements, masses... of each kind in one model (documented limit)
MAX_GRAPH_ITEMS = 2_000_000
#: a beam whose end points are closer than this fraction of the model size has zero length
ZERO_LENGTH_TOL = 1e-9
#: an orientation within this angle (rad) of the beam axis is parallel to it
PARALLEL_TOL = 1e-6


# --------------------------------------------------------------------------- items


@dataclass(frozen=True)
class Node:
    """A node (NASTRAN GRID): 6 degrees of freedom; or a scalar point (SPOINT): one.

    Attributes
    ----------
    name : str
        ``"grid:101"`` for NASTRAN grid 101, ``"spoint:7"`` for scalar point 7.
    position : ndarray (3,)
        Basic frame, m.  A scalar point is not a point in space: its position (zero) is
        never used, and it is neither a sample nor an observable point.
    axes : ndarray (3, 3)
        Rows: directions of components 1-3 (and of rotations 4-6) in the basic frame.
    frame : str
        Name of the frame the axes come from (``"basic"``).
    scalar : bool
        A scalar point: its one DOF is component 1 (NASTRAN's component 0 or blank), which
        moves with no rigid-body motion.
    """

    name: str
    position: np.ndarray
    axes: np.ndarray = field(default_factory=lambda: np.eye(3))
    frame: str = "basic"
    scalar: bool = False


@dataclass(frozen=True)
class BeamSection:
    """Stiffness and inertia of a uniform beam cross-section (a NASTRAN PBAR/PBEAM with MAT1).

    Attributes
    ----------
    name : str
    ea_N : float
        Axial stiffness E A, N (> 0).
    ei_y_N_m2, ei_z_N_m2 : float
        Bending stiffness about local y (``E I2``) and local z (``E I1``), N m^2 (> 0).
    gj_N_m2 : float
        Torsional stiffness G J, N m^2 (> 0).
    mass_per_length_kg_per_m : float
        Translational mass per length (rho A + non-structural), kg/m (>= 0).
    polar_mass_kg_m : float
        Torsional (polar) mass moment per length, rho (I_y + I_z), kg m (>= 0).
    shear_y_N, shear_z_N : float or None
        Transverse shear stiffness for deflection along local y (``K1 G A``) and local z
        (``K2 G A``), N; None: rigid in shear (Euler-Bernoulli).
    rotary_y_kg_m, rotary_z_kg_m : float
        Rotary inertia per length of bending about local y (rho I2) and z (rho I1), kg m;
        used by the consistent mass only (0: neglected).
    ei_yz_N_m2 : float
        Product ``E I12`` (``I12 = int y z dA``, element axes), N m^2; non-zero turns the
        bending axes to the principal axes (and, as in NASTRAN, drops shear flexibility).
    """

    name: str
    ea_N: float  # noqa: N815 - SI unit suffix
    ei_y_N_m2: float  # noqa: N815 - SI unit suffix
    ei_z_N_m2: float  # noqa: N815 - SI unit suffix
    gj_N_m2: float  # noqa: N815 - SI unit suffix
    mass_per_length_kg_per_m: float
    polar_mass_kg_m: float
    shear_y_N: float | None = None  # noqa: N815 - SI unit suffix
    shear_z_N: float | None = None  # noqa: N815 - SI unit suffix
    rotary_y_kg_m: float = 0.0
    rotary_z_kg_m: float = 0.0
    ei_yz_N_m2: float = 0.0  # noqa: N815 - SI unit suffix


@dataclass(frozen=True)
class BeamElement:
    """A two-node beam (NASTRAN CBAR or CBEAM).

    Attributes
    ----------
    name : str
        ``"cbar:12"``.
    nodes : (str, str)
        End nodes a and b.
    section : BeamSection
    orientation : ndarray (3,)
        Vector in the local x-y plane (basic frame); made perpendicular to the axis.
    offsets : ndarray (2, 3)
        From node a to end a and node b to end b, basic frame, m (rigid offsets).
    kind : {"beam", "bar"}
        ``"bar"`` follows NASTRAN's CBAR lumped mass (no torsional inertia); ``"beam"``
        (CBEAM) lumps the polar mass moment at the ends as well.
    releases : (str, str)
        Pin flags: components (element axes) released at end a and end b.
    """

    name: str
    nodes: tuple[str, str]
    section: BeamSection
    orientation: np.ndarray
    offsets: np.ndarray = field(default_factory=lambda: np.zeros((2, 3)))
    kind: str = "beam"
    releases: tuple[str, str] = ("", "")


@dataclass(frozen=True)
class RodElement:
    """A two-node rod (NASTRAN CROD/CONROD): axial and torsional stiffness only.

    Attributes
    ----------
    name : str
    nodes : (str, str)
    ea_N : float
        E A, N (> 0).
    gj_N_m2 : float
        G J, N m^2 (>= 0).
    mass_per_length_kg_per_m : float
        kg/m (>= 0); lumped or consistent in all three translations.
    """

    name: str
    nodes: tuple[str, str]
    ea_N: float  # noqa: N815 - SI unit suffix
    gj_N_m2: float  # noqa: N815 - SI unit suffix
    mass_per_length_kg_per_m: float


@dataclass(frozen=True)
class ShellSection:
    """Stiffness and mass of a uniform shell (a NASTRAN PSHELL with MAT1), per unit area.

    Resultants in the element axes (x, y in the mid-plane, z the normal):
    ``[Nx, Ny, Nxy] = A [ex, ey, gxy]``, ``[Mx, My, Mxy] = D [kx, ky, kxy]``,
    ``[Qx, Qy] = S [gxz, gyz]``; isotropic matrices (any in-plane axes give the same).

    Attributes
    ----------
    name : str
    membrane_N_per_m : ndarray (3, 3)
        ``A`` (MID1 times T), N/m; zeros: no membrane stiffness.
    bending_N_m : ndarray (3, 3)
        ``D`` (MID2 times 12I/T^3 T^3 / 12), N m; zeros: no bending stiffness.
    shear_N_per_m : ndarray (2, 2)
        ``S`` (MID3's G times TS/T T), N/m.
    mass_per_area_kg_per_m2 : float
        ``rho T + NSM``, kg/m^2 (>= 0); translational only.
    drilling_N_per_m : float
        Penalty ``alpha`` on the drilling rotation, ``alpha (theta_z - omega)^2 / 2`` per
        area, ``omega`` the membrane's rotation (NASTRAN ``1e-6 K6ROT G T``), N/m.
    """

    name: str
    membrane_N_per_m: np.ndarray  # noqa: N815 - SI unit suffix
    bending_N_m: np.ndarray  # noqa: N815 - SI unit suffix
    shear_N_per_m: np.ndarray  # noqa: N815 - SI unit suffix
    mass_per_area_kg_per_m2: float
    drilling_N_per_m: float = 0.0  # noqa: N815 - SI unit suffix


@dataclass(frozen=True)
class ShellElement:
    """A flat three- or four-node shell (NASTRAN CTRIA3 or CQUAD4).

    Attributes
    ----------
    name : str
        ``"cquad4:7"``.
    nodes : tuple of str
        Three (triangle) or four (quadrilateral) corner nodes, in order around the element.
    section : ShellSection
    """

    name: str
    nodes: tuple[str, ...]
    section: ShellSection


@dataclass(frozen=True)
class Spring:
    """A 6x6 spring-damper between two nodes or a node and ground (NASTRAN CBUSH).

    The spring sits at ``location``; each node is carried there rigidly, so the element
    transmits no force under rigid-body motion whatever its location.

    Attributes
    ----------
    name : str
    nodes : (str, str or None)
        Node a and node b (None: grounded).
    stiffness : ndarray (6, 6)
        In the spring axes: N/m (translations), N m/rad (rotations), N/rad and N m/m coupling.
    damping : ndarray (6, 6)
        Viscous damping in the spring axes, N s/m and N m s/rad.
    axes : ndarray (3, 3)
        Rows: the spring's x, y, z axes in the basic frame.
    location : ndarray (3,)
        The spring's point, basic frame, m.
    structural_damping : float
        Loss factor (NASTRAN GE), dimensionless.
    """

    name: str
    nodes: tuple[str, str | None]
    stiffness: np.ndarray
    damping: np.ndarray
    axes: np.ndarray
    location: np.ndarray
    structural_damping: float = 0.0


@dataclass(frozen=True)
class ScalarSpring:
    """A scalar spring between two node components (NASTRAN CELAS1/CELAS2).

    Attributes
    ----------
    name : str
    dofs : ((str, int) or None, (str, int) or None)
        (node, component 1-6 along the node's axes); None: grounded.
    stiffness : float
        N/m, N m/rad (or N/rad between a translation and a rotation).
    damping : float
        Viscous, N s/m (or rotational).
    structural_damping : float
        Loss factor (GE), dimensionless.
    """

    name: str
    dofs: tuple[tuple[str, int] | None, tuple[str, int] | None]
    stiffness: float
    damping: float = 0.0
    structural_damping: float = 0.0


@dataclass(frozen=True)
class ScalarMass:
    """A scalar mass between two node components (NASTRAN CMASS1/CMASS2).

    Its mass matrix is ``m (e_b - e_a)(e_b - e_a)^T`` on the two components (NASTRAN's scalar
    element form, the same as a scalar spring's); one end grounded leaves ``m`` on the
    other.

    Attributes
    ----------
    name : str
    dofs : ((str, int) or None, (str, int) or None)
        (node, component 1-6 along the node's axes; 1 for a scalar point); None: grounded.
    mass : float
        kg (translations, scalar points), kg m^2 (rotations), kg m between a translation and
        a rotation.
    """

    name: str
    dofs: tuple[tuple[str, int] | None, tuple[str, int] | None]
    mass: float


@dataclass(frozen=True)
class MultiPointConstraint:
    """A linear constraint among node components (NASTRAN MPC): ``sum_j a_j u_j = 0``.

    The first term's component is dependent and eliminated exactly,
    ``u_1 = -sum_{j>1} (a_j / a_1) u_j`` (NASTRAN's rule).

    Attributes
    ----------
    name : str
        ``"mpc:3#1"``: set 3, its first equation.
    terms : tuple of (str, int, float)
        (node, component 1-6 along the node's axes (1 for a scalar point), coefficient); the
        coefficients are in the model's units (SI: a rotation's per rad, a translation's per
        m), so that the equation is homogeneous.
    """

    name: str
    terms: tuple[tuple[str, int, float], ...]


@dataclass(frozen=True)
class ConcentratedMass:
    """A rigid mass attached to a node (NASTRAN CONM2).

    Attributes
    ----------
    name : str
    node : str
    mass_kg : float
        (>= 0).
    offset_m : ndarray (3,)
        From the node to the mass centre, basic frame.
    inertia_kg_m2 : ndarray (3, 3)
        Inertia tensor about the mass centre, basic axes (symmetric positive semidefinite).
    """

    name: str
    node: str
    mass_kg: float
    offset_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia_kg_m2: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))


@dataclass(frozen=True)
class RigidLink:
    """A rigid element (NASTRAN RBE2): dependent nodes move rigidly with the independent one.

    Attributes
    ----------
    name : str
    independent : str
    dependents : tuple of str
    components : str
        Dependent components (``"123456"``), along each dependent node's axes.
    """

    name: str
    independent: str
    dependents: tuple[str, ...]
    components: str = COMPONENTS


@dataclass(frozen=True)
class Interpolation:
    """An interpolation element (NASTRAN RBE3): a reference node follows a weighted average.

    The reference node's motion is the rigid-body motion that best fits (weighted least
    squares, :func:`microg.structure.elements.interpolation_matrix`) the motion of the
    independent nodes' components; it adds no stiffness.

    Attributes
    ----------
    name : str
    reference : str
        The reference node.
    components : str
        Its components the fit sets (NASTRAN REFC).
    sources : tuple of (str, str, float)
        (node, components among ``"123456"``, weight > 0) of each independent.
    moved : tuple of (str, str)
        NASTRAN UM: (node, components) that are dependent instead of the reference's
        components (as many in all); empty: the reference's components are dependent.
    """

    name: str
    reference: str
    components: str
    sources: tuple[tuple[str, str, float], ...]
    moved: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Constraint:
    """Components held at zero (NASTRAN SPC): noted, applied only when asked for validation."""

    node: str
    components: str


@dataclass(frozen=True)
class GraphPoint:
    """A named point of interest riding rigidly on a node.

    Attributes
    ----------
    name : str
    node : str
    position : ndarray (3,)
        Basic frame, m.
    kind : {"crew", "experiment", "point"}
    description : str
    """

    name: str
    node: str
    position: np.ndarray
    kind: str = "point"
    description: str = ""


@dataclass(frozen=True)
class GraphModel:
    """A general frame model: a graph of nodes and elements, SI.

    Attributes
    ----------
    name : str
    nodes : tuple of Node
    beams, rods, shells, springs, scalar_springs, masses, rigid_links, interpolations : tuples
        The elements.
    scalar_masses : tuple of ScalarMass
    mpcs : tuple of MultiPointConstraint
        Multipoint constraints (NASTRAN MPC), eliminated exactly.
    points : tuple of GraphPoint
    frames : tuple of CoordinateFrame
        The coordinate systems the model was written in (for reference).
    mass_formulation : {"lumped", "consistent", "coupled", "coupled-nx9"}
    constraints : tuple of Constraint
        Single-point constraints of the source (NASTRAN SPC): not applied by default, microg
        models being free-free.
    description, source : str
    meta : mapping
        Provenance: units declared, WTMASS, cards ignored, notes.
    """

    name: str
    nodes: tuple[Node, ...]
    beams: tuple[BeamElement, ...] = ()
    rods: tuple[RodElement, ...] = ()
    shells: tuple[ShellElement, ...] = ()
    springs: tuple[Spring, ...] = ()
    scalar_springs: tuple[ScalarSpring, ...] = ()
    masses: tuple[ConcentratedMass, ...] = ()
    rigid_links: tuple[RigidLink, ...] = ()
    interpolations: tuple[Interpolation, ...] = ()
    scalar_masses: tuple[ScalarMass, ...] = ()
    mpcs: tuple[MultiPointConstraint, ...] = ()
    points: tuple[GraphPoint, ...] = ()
    frames: tuple[CoordinateFrame, ...] = ()
    mass_formulation: str = "consistent"
    constraints: tuple[Constraint, ...] = ()
    description: str = ""
    source: str = ""
    meta: Mapping[str, Any] = field(default_factory=dict)

    def node_index(self) -> dict[str, int]:
        """Node name -> index in :attr:`nodes`."""
        return {n.name: i for i, n in enumerate(self.nodes)}

    def node(self, name: str) -> Node:
        """The node called ``name``; an unknown name is an InputError listing nearby ones."""
        idx = self.node_index()
        if name not in idx:
            raise InputError(f"unknown node {name!r}", fix=nearest_names(name, list(idx)))
        return self.nodes[idx[name]]


def nearest_names(name: str, known: Sequence[str], n: int = 5) -> str:
    """'nearest: ...' names for an error message (numeric distance for ``grid:N`` names).

    Parameters
    ----------
    name : str
        The unknown name.
    known : sequence of str
        The names that exist.
    n : int
        How many to list.
    """
    if not known:
        return "the model has none"
    m = re.fullmatch(r"(\w+):(\d+)", name)
    if m:
        prefix, num = m.group(1), int(m.group(2))
        same = [k for k in known if re.fullmatch(rf"{prefix}:\d+", k)]
        if same:
            same.sort(key=lambda k: abs(int(k.split(":")[1]) - num))
            return "nearest: " + ", ".join(same[:n])
    close = difflib.get_close_matches(name, known, n=n, cutoff=0.0)
    return "known, e.g.: " + ", ".join(close or list(known)[:n])


def parse_components(value: Any, *, where: str, allowed: str = COMPONENTS) -> str:
    """Component digits (``"123456"``; NASTRAN's packed integer 123456 too), sorted, unique.

    Parameters
    ----------
    value : str or int
        The components as written.
    where : str
        Where they were read, for the error.
    allowed : str
        The digits allowed (``"123"``: translations only).
    """
    text = (
        str(value).strip() if isinstance(value, str | int) and not isinstance(value, bool) else ""
    )
    if not text or any(ch not in allowed for ch in text) or len(set(text)) != len(text):
        raise InputError(
            f"components {value!r} are not distinct digits among {allowed}",
            where=where,
            fix=f"write e.g. '{allowed}'",
        )
    return "".join(sorted(text))


# --------------------------------------------------------------------------- orientation


def default_orientation(direction: np.ndarray) -> np.ndarray:
    """The basic axis least aligned with ``direction`` (the station format's rule).

    Parameters
    ----------
    direction : ndarray (3,)
        A beam's or spring's axis (any length; zero gives x).
    """
    d = np.asarray(direction, float)
    n = float(np.linalg.norm(d))
    if not n > 0:
        return np.array([1.0, 0.0, 0.0])
    e = np.zeros(3)
    e[int(np.argmin(np.abs(d / n)))] = 1.0
    return e


def spring_axes(
    pa: np.ndarray,
    pb: np.ndarray,
    orientation: np.ndarray | None,
    stiffness: np.ndarray,
    damping: np.ndarray,
    *,
    where: str,
) -> np.ndarray:
    """Axes (rows) of a spring from its nodes and an orientation vector (NASTRAN CBUSH rule).

    x from node a to node b, y the orientation made perpendicular, z = x cross y.  Coincident
    nodes (or a grounded spring) give no x axis: the spring then needs a coordinate system,
    unless its stiffness and damping are the same along x, y, z and about them (any axes
    do).  Without an orientation, non-coincident nodes need equal y and z values (any
    perpendicular y does).  Otherwise the missing orientation is an :class:`InputError`.

    Parameters
    ----------
    pa, pb : ndarray (3,)
        Positions of node a and node b (b = a when grounded), m.
    orientation : ndarray (3,) or None
        The y direction (made perpendicular to x), basic frame.
    stiffness, damping : ndarray (6, 6)
        In the spring axes (N/m, N m/rad; N s/m, N m s/rad).
    where : str
        The spring, for errors.

    Returns
    -------
    ndarray (3, 3)
        Rows: the spring's x, y, z axes in the basic frame.
    """
    d = np.asarray(pb, float) - np.asarray(pa, float)
    scale = max(float(np.max(np.abs(np.concatenate([pa, pb])))), 1.0)
    coincident = float(np.linalg.norm(d)) <= 1e-9 * scale
    iso = all(
        np.allclose(np.diag(m)[:3], np.diag(m)[0]) and np.allclose(np.diag(m)[3:], np.diag(m)[3])
        for m in (stiffness, damping)
    ) and all(np.count_nonzero(m - np.diag(np.diag(m))) == 0 for m in (stiffness, damping))
    axisym = all(
        np.isclose(m[1, 1], m[2, 2]) and np.isclose(m[4, 4], m[5, 5]) for m in (stiffness, damping)
    ) and all(np.count_nonzero(m - np.diag(np.diag(m))) == 0 for m in (stiffness, damping))
    if coincident:
        if orientation is None:
            if iso:
                return np.eye(3)
            raise InputError(
                "spring between coincident points has no orientation and direction-dependent "
                "stiffness",
                where=where,
                fix="give its axes (a coordinate system, NASTRAN CID) or equal values in x, y, z",
            )
        raise InputError(
            "spring between coincident points: an orientation vector cannot define its axes",
            where=where,
            fix="give its axes as a coordinate system (NASTRAN CID)",
        )
    ex = d / np.linalg.norm(d)
    if orientation is None:
        if not axisym:
            raise InputError(
                "spring has no orientation and different stiffness about its y and z axes",
                where=where,
                fix="give an orientation vector (NASTRAN X1-X3 or G0) or a coordinate system (CID)",
            )
        orientation = default_orientation(ex)
    v = np.asarray(orientation, float)
    ey = v - float(np.dot(v, ex)) * ex
    if float(np.linalg.norm(ey)) <= PARALLEL_TOL * max(float(np.linalg.norm(v)), 1e-300):
        raise InputError(
            "orientation vector is parallel to the spring's axis", where=where, fix="give another"
        )
    ey = ey / np.linalg.norm(ey)
    return np.stack([ex, ey, np.cross(ex, ey)])
