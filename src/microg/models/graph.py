"""General frame models: a graph of nodes and elements, in frozen SI dataclasses.

A :class:`GraphModel` is what a NASTRAN bulk-data deck (:mod:`microg.models.bdf`) or a graph
TOML file (this module, format in ``docs/model-format.md``, "Graph models") becomes, and what
:func:`microg.structure.frame.build_frame` assembles into a free-free
:class:`~microg.structure.Structure`.  Unlike the tree-of-beams
:class:`~microg.models.station.Station` it allows closed loops, several load paths, springs
and dampers between any two nodes, rigid links and interpolation elements.
:func:`microg.structure.frame.graph_from_station` writes a station as a graph.

Conventions (all values SI: m, kg, s, N, rad):

* **Nodes** have a position in the basic (station) frame and *displacement axes*: the
  directions of their components 1-3 (translations) and 4-6 (rotations), rows of a 3x3
  rotation (identity for the basic frame; NASTRAN's GRID CD).  Components named on springs,
  links and constraints (``"123456"`` strings) are along these axes.
* **Beams** run from node a (plus offset a) to node b (plus offset b); local x along the
  beam, local y the orientation vector made perpendicular, local z = x cross y.  ``ei_z`` is
  the bending stiffness about local z (deflection along y: NASTRAN's plane 1, ``E I1``),
  ``ei_y`` about local y (deflection along z: plane 2, ``E I2``).
* **Mass formulation** is the model's: ``"lumped"`` (NASTRAN's default) or ``"consistent"``
  (NASTRAN's ``PARAM,COUPMASS``); :mod:`microg.structure.frame` documents both.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from microg._io import loads_toml
from microg.errors import InputError, ModelError
from microg.models.coords import BASIC, FRAME_KINDS, CoordinateFrame, frame_from_points

__all__ = [
    "BASIC",
    "COMPONENTS",
    "FRAME_KINDS",
    "MASS_FORMULATIONS",
    "MAX_GRAPH_ITEMS",
    "BeamElement",
    "BeamSection",
    "ConcentratedMass",
    "Constraint",
    "CoordinateFrame",
    "GraphModel",
    "GraphPoint",
    "Interpolation",
    "Node",
    "RigidLink",
    "RodElement",
    "ScalarSpring",
    "Spring",
    "dump_graph",
    "load_graph",
    "loads_graph",
    "parse_components",
    "validate_graph",
]

#: the six components of a node, NASTRAN's numbering: 1-3 translations, 4-6 rotations
COMPONENTS = "123456"
#: mass formulations of beams and rods
MASS_FORMULATIONS = ("lumped", "consistent")
#: largest number of nodes, elements, masses... of each kind in one model (documented limit)
MAX_GRAPH_ITEMS = 2_000_000
#: a beam whose end points are closer than this fraction of the model size has zero length
ZERO_LENGTH_TOL = 1e-9
#: an orientation within this angle (rad) of the beam axis is parallel to it
PARALLEL_TOL = 1e-6


# --------------------------------------------------------------------------- items


@dataclass(frozen=True)
class Node:
    """A node (NASTRAN GRID): 6 degrees of freedom.

    Attributes
    ----------
    name : str
        ``"grid:101"`` for NASTRAN grid 101.
    position : ndarray (3,)
        Basic frame, m.
    axes : ndarray (3, 3)
        Rows: directions of components 1-3 (and of rotations 4-6) in the basic frame.
    frame : str
        Name of the frame the axes come from (``"basic"``).
    """

    name: str
    position: np.ndarray
    axes: np.ndarray = field(default_factory=lambda: np.eye(3))
    frame: str = "basic"


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
    squares) the motion of the independent nodes' components; it adds no stiffness.

    Attributes
    ----------
    name : str
    reference : str
        The dependent (reference) node.
    components : str
        Its dependent components.
    sources : tuple of (str, str, float)
        (node, translational components among ``"123"``, weight > 0) of each independent.
    """

    name: str
    reference: str
    components: str
    sources: tuple[tuple[str, str, float], ...]


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
    beams, rods, springs, scalar_springs, masses, rigid_links, interpolations : tuples
        The elements.
    points : tuple of GraphPoint
    frames : tuple of CoordinateFrame
        The coordinate systems the model was written in (for reference).
    mass_formulation : {"lumped", "consistent"}
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
    springs: tuple[Spring, ...] = ()
    scalar_springs: tuple[ScalarSpring, ...] = ()
    masses: tuple[ConcentratedMass, ...] = ()
    rigid_links: tuple[RigidLink, ...] = ()
    interpolations: tuple[Interpolation, ...] = ()
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
            raise InputError(f"unknown node {name!r}", fix=_nearest(name, list(idx)))
        return self.nodes[idx[name]]


def _nearest(name: str, known: Sequence[str], n: int = 5) -> str:
    """'nearest names: ...' for an error message (numeric distance for grid:N names)."""
    if not known:
        return "the model has none"
    m = re.fullmatch(r"(\w+):(\d+)", name)
    if m:
        prefix, num = m.group(1), int(m.group(2))
        same = [k for k in known if re.fullmatch(rf"{prefix}:\d+", k)]
        if same:
            same.sort(key=lambda k: abs(int(k.split(":")[1]) - num))
            return "nearest: " + ", ".join(same[:n])
    import difflib

    close = difflib.get_close_matches(name, known, n=n, cutoff=0.0)
    return "known, e.g.: " + ", ".join(close or list(known)[:n])


def parse_components(value: Any, *, where: str, allowed: str = COMPONENTS) -> str:
    """Component digits (``"123456"``; NASTRAN's packed integer 123456 too), sorted, unique."""
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


# --------------------------------------------------------------------------- validation


def validate_graph(graph: GraphModel) -> None:
    """Check names, references, signs and geometry of ``graph`` (InputError on the first fault).

    Checked: unique names per kind; every node an element, mass, link or point names
    exists; finite values; positive section stiffnesses and non-negative masses; a
    symmetric positive semidefinite inertia per mass; symmetric stiffness and damping
    matrices of springs; non-zero beam and rod lengths; an orientation not parallel to its
    beam; a rigid link's independent node not among its dependents; orthonormal axes;
    at most :data:`MAX_GRAPH_ITEMS` items of each kind.
    """
    src = graph.source or graph.name
    if graph.mass_formulation not in MASS_FORMULATIONS:
        raise InputError(
            f"unknown mass formulation {graph.mass_formulation!r}",
            where=f"{src}: mass",
            fix="use lumped or consistent",
        )
    for label, items in (
        ("node", graph.nodes),
        ("beam", graph.beams),
        ("rod", graph.rods),
        ("spring", graph.springs),
        ("scalar spring", graph.scalar_springs),
        ("mass", graph.masses),
        ("rigid link", graph.rigid_links),
        ("interpolation", graph.interpolations),
        ("point", graph.points),
    ):
        if len(items) > MAX_GRAPH_ITEMS:
            raise InputError(
                f"{len(items)} {label}s exceed the limit of {MAX_GRAPH_ITEMS}",
                where=src,
                fix="split or condense the model",
            )
        seen: set[str] = set()
        for it in items:
            name = it.name
            if name in seen:
                raise InputError(f"duplicate {label} name {name!r}", where=f"{src}: {name}")
            seen.add(name)
    if not graph.nodes:
        raise InputError("the model has no node", where=src, fix="add nodes and elements")
    index = graph.node_index()
    pos = np.array([n.position for n in graph.nodes], float).reshape(-1, 3)
    if not np.all(np.isfinite(pos)):
        bad = graph.nodes[int(np.flatnonzero(~np.isfinite(pos).all(axis=1))[0])].name
        raise InputError("position is not finite", where=f"{src}: {bad}")
    scale = max(float(np.ptp(pos, axis=0).max()) if pos.shape[0] > 1 else 0.0, 1e-300)
    try:
        axes = np.array([n.axes for n in graph.nodes], float).reshape(-1, 3, 3)
    except ValueError:
        axes = np.full((len(graph.nodes), 3, 3), np.nan)
    err = np.abs(axes @ np.swapaxes(axes, 1, 2) - np.eye(3)).max(axis=(1, 2))
    if not np.all(err <= 1e-9):
        bad = graph.nodes[int(np.flatnonzero(~(err <= 1e-9))[0])].name
        raise InputError("axes are not orthonormal", where=f"{src}: {bad}")

    def ref(node: str | None, where: str) -> None:
        if node is not None and node not in index:
            raise InputError(
                f"node {node!r} does not exist",
                where=f"{src}: {where}",
                fix=_nearest(node, list(index)),
            )

    checked: set[int] = set()
    for b in graph.beams:
        for nd in b.nodes:
            ref(nd, b.name)
        s = b.section
        if id(s) not in checked:
            _check_section(s, f"{src}: {b.name}")
            checked.add(id(s))
        if b.kind not in ("beam", "bar"):
            raise InputError(f"unknown beam kind {b.kind!r}", where=f"{src}: {b.name}")
        for rel in b.releases:
            if rel:
                parse_components(rel, where=f"{src}: {b.name}: releases")
    if graph.beams:
        ia = np.array([index[b.nodes[0]] for b in graph.beams])
        ib = np.array([index[b.nodes[1]] for b in graph.beams])
        off = np.array([b.offsets for b in graph.beams], float).reshape(-1, 2, 3)
        axis = (pos[ib] + off[:, 1]) - (pos[ia] + off[:, 0])
        length = np.linalg.norm(axis, axis=1)
        short = np.flatnonzero(~(length > ZERO_LENGTH_TOL * scale))
        if short.size:
            raise InputError(
                "has zero length (its ends coincide)",
                where=f"{src}: {graph.beams[int(short[0])].name}",
                fix="connect two distinct points, or use a spring (CBUSH) or rigid link (RBE2)",
            )
        ov = np.array([b.orientation for b in graph.beams], float).reshape(-1, 3)
        nv = np.linalg.norm(ov, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            sine = np.linalg.norm(np.cross(axis / length[:, None], ov / nv[:, None]), axis=1)
        para = np.flatnonzero(~(sine > PARALLEL_TOL))
        if para.size:
            raise InputError(
                "orientation vector is zero or parallel to the beam",
                where=f"{src}: {graph.beams[int(para[0])].name}",
                fix="give a vector in the beam's x-y plane, not along its axis",
            )
    for r in graph.rods:
        for nd in r.nodes:
            ref(nd, r.name)
        if not (math.isfinite(r.ea_N) and r.ea_N > 0 and r.gj_N_m2 >= 0):
            raise InputError("needs EA > 0 and GJ >= 0", where=f"{src}: {r.name}")
        if not r.mass_per_length_kg_per_m >= 0:
            raise InputError("negative mass per length", where=f"{src}: {r.name}")
        d = pos[index[r.nodes[1]]] - pos[index[r.nodes[0]]]
        if float(np.linalg.norm(d)) <= ZERO_LENGTH_TOL * scale:
            raise InputError(
                "has zero length (its nodes coincide)",
                where=f"{src}: {r.name}",
                fix="connect two distinct nodes, or use a spring (CBUSH/CELAS)",
            )
    for sp_ in graph.springs:
        ref(sp_.nodes[0], sp_.name)
        ref(sp_.nodes[1], sp_.name)
        for mat, what in ((sp_.stiffness, "stiffness"), (sp_.damping, "damping")):
            a = np.asarray(mat, float)
            if a.shape != (6, 6) or not np.all(np.isfinite(a)):
                raise InputError(f"{what} must be a finite 6x6 matrix", where=f"{src}: {sp_.name}")
            if np.max(np.abs(a - a.T)) > 1e-12 * max(np.max(np.abs(a)), 1e-300):
                raise InputError(f"{what} matrix is not symmetric", where=f"{src}: {sp_.name}")
            if np.any(np.diag(a) < 0):
                raise InputError(f"negative {what}", where=f"{src}: {sp_.name}")
        ax = np.asarray(sp_.axes, float)
        if ax.shape != (3, 3) or not np.allclose(ax @ ax.T, np.eye(3), atol=1e-9):
            raise InputError("axes are not orthonormal", where=f"{src}: {sp_.name}")
    for cs in graph.scalar_springs:
        for d_ in cs.dofs:
            if d_ is not None:
                ref(d_[0], cs.name)
                if d_[1] not in range(1, 7):
                    raise InputError(f"component {d_[1]} is not 1-6", where=f"{src}: {cs.name}")
        if cs.dofs[0] is None and cs.dofs[1] is None:
            raise InputError("connects nothing (both ends grounded)", where=f"{src}: {cs.name}")
        if not (math.isfinite(cs.stiffness) and math.isfinite(cs.damping)):
            raise InputError("stiffness and damping must be finite", where=f"{src}: {cs.name}")
    for m in graph.masses:
        ref(m.node, m.name)
        j = np.asarray(m.inertia_kg_m2, float)
        if not (math.isfinite(m.mass_kg) and m.mass_kg >= 0) or j.shape != (3, 3):
            raise InputError("needs a mass >= 0 and a 3x3 inertia", where=f"{src}: {m.name}")
        if not np.all(np.isfinite(j)) or np.max(np.abs(j - j.T)) > 1e-12 * max(
            np.max(np.abs(j)), 1e-300
        ):
            raise InputError("inertia is not a symmetric finite tensor", where=f"{src}: {m.name}")
        tr = float(np.trace(j))
        if tr and float(np.linalg.eigvalsh(j).min()) < -1e-9 * tr:
            raise InputError(
                "inertia tensor is not positive semidefinite",
                where=f"{src}: {m.name}",
                fix="check the signs of the products of inertia",
            )
    for rl in graph.rigid_links:
        ref(rl.independent, rl.name)
        for d in rl.dependents:
            ref(d, rl.name)
        if rl.independent in rl.dependents:
            raise InputError(
                f"independent node {rl.independent!r} is also dependent", where=f"{src}: {rl.name}"
            )
        parse_components(rl.components, where=f"{src}: {rl.name}")
    for ip in graph.interpolations:
        ref(ip.reference, ip.name)
        parse_components(ip.components, where=f"{src}: {ip.name}")
        if not ip.sources:
            raise InputError("has no independent node", where=f"{src}: {ip.name}")
        for nd, comps, w in ip.sources:
            ref(nd, ip.name)
            parse_components(comps, where=f"{src}: {ip.name}", allowed="123")
            if not (math.isfinite(w) and w > 0):
                raise InputError(f"weight {w} must be > 0", where=f"{src}: {ip.name}")
    for p in graph.points:
        ref(p.node, p.name)
        if p.kind not in ("crew", "experiment", "point"):
            raise InputError(f"unknown kind {p.kind!r}", where=f"{src}: {p.name}")
    for c in graph.constraints:
        ref(c.node, f"constraint on {c.node}")
        parse_components(c.components, where=f"{src}: constraint on {c.node}")


def _check_section(s: BeamSection, where: str) -> None:
    vals = (s.ea_N, s.ei_y_N_m2, s.ei_z_N_m2, s.gj_N_m2)
    if not all(math.isfinite(v) and v > 0 for v in vals):
        raise InputError(
            f"section {s.name!r} needs EA, EI_y, EI_z, GJ > 0, got {vals}",
            where=where,
            fix="give positive stiffnesses (E, G and the section's A, I1, I2, J)",
        )
    if s.ei_yz_N_m2 and s.ei_y_N_m2 * s.ei_z_N_m2 <= s.ei_yz_N_m2**2:
        raise InputError(f"section {s.name!r}: I1 I2 must exceed I12^2", where=where)
    for v, what in (
        (s.mass_per_length_kg_per_m, "mass per length"),
        (s.polar_mass_kg_m, "polar mass moment"),
        (s.rotary_y_kg_m, "rotary inertia"),
        (s.rotary_z_kg_m, "rotary inertia"),
    ):
        if not (math.isfinite(v) and v >= 0):
            raise InputError(f"section {s.name!r}: negative {what}", where=where)
    for sv in (s.shear_y_N, s.shear_z_N):
        if sv is not None and not (math.isfinite(sv) and sv > 0):
            raise InputError(
                f"section {s.name!r}: shear stiffness must be > 0 (or absent)", where=where
            )


# --------------------------------------------------------------------------- graph TOML

#: unit of a bare number for each quantity kind, by ``[graph] units``
_BARE_UNITS: dict[str, dict[str, str]] = {
    "SI": {
        "length": "m",
        "mass": "kg",
        "force": "N",
        "stiffness": "N/m",
        "damping": "N*s/m",
        "axial_stiffness": "N",
        "bending_stiffness": "N*m^2",
        "torsional_stiffness": "N*m^2",
        "mass_per_length": "kg/m",
        "rotary_inertia": "kg*m^2",
        "rotational_stiffness": "N*m/rad",
        "rotational_damping": "N*m*s/rad",
    },
    "US": {
        "length": "ft",
        "mass": "slug",
        "force": "lbf",
        "stiffness": "lbf/ft",
        "damping": "lbf*s/ft",
        "axial_stiffness": "lbf",
        "bending_stiffness": "lbf*ft^2",
        "torsional_stiffness": "lbf*ft^2",
        "mass_per_length": "slug/ft",
        "rotary_inertia": "slug*ft^2",
        "rotational_stiffness": "lbf*ft/rad",
        "rotational_damping": "lbf*ft*s/rad",
    },
}

#: rotational spring/damper quantities, parsed as a dimension of microg.units times a factor
#: of exactly 1 SI unit appended to the unit text (microg.units has no N m/rad dimension)
_ROTATIONAL = {
    "rotational_stiffness": ("torsional_stiffness", "*m"),  # N m/rad * m = N m^2
    "rotational_damping": ("torsional_stiffness", "*m/s"),  # N m s/rad * m/s = N m^2
}

_KEYS: dict[str, tuple[set[str], set[str]]] = {
    # table: (required keys, optional keys)
    "graph": ({"name"}, {"description", "units", "mass"}),
    "frame": ({"name", "kind", "origin", "z_axis", "xz_point"}, set()),
    "node": ({"name", "at"}, {"frame"}),
    "section": (
        {"name", "ea", "gj", "mass_per_length"},
        {"ei", "ei_y", "ei_z", "ei_yz", "shear_y", "shear_z", "polar_gyration", "rotary_inertia"},
    ),
    "beam": ({"name", "nodes", "section"}, {"orientation", "offsets", "kind", "releases"}),
    "rod": ({"name", "nodes", "ea", "mass_per_length"}, {"gj"}),
    "spring": ({"name", "nodes"}, {"stiffness", "damping", "axes", "orientation", "at"}),
    "mass": ({"name", "node", "mass"}, {"at", "inertia"}),
    "rigid": ({"name", "independent", "dependents"}, {"components"}),
    "interpolation": ({"name", "reference", "sources"}, {"components"}),
    "point": ({"name", "node"}, {"at", "kind", "description"}),
    "constraint": ({"node", "components"}, set()),
}
_SPRING_KEYS = ("x", "y", "z", "rx", "ry", "rz")
_INERTIA_KEYS = ("xx", "yy", "zz", "xy", "xz", "yz")


class _Reader:
    """Builds a GraphModel from a parsed graph TOML document (private)."""

    def __init__(self, doc: dict[str, Any], file: str):
        self.doc = doc
        self.file = file
        self.units: str | None = None

    def err(self, path: str, what: str, fix: str | None = None) -> ModelError:
        return ModelError(what, where=f"{self.file}: {path}", fix=fix)

    def table(self, key: str) -> list[dict[str, Any]]:
        raw = self.doc.get(key, [])
        if key == "graph":
            raw = [raw]
        if not isinstance(raw, list) or not all(isinstance(t, dict) for t in raw):
            raise self.err(key, f"must be an array of tables [[{key}]]")
        req, opt = _KEYS[key]
        for i, t in enumerate(raw):
            path = key if key == "graph" else f"{key}[{i}]"
            for k in t:
                if k not in req | opt:
                    raise self.err(
                        f"{path}.{k}",
                        "unknown key",
                        f"check its spelling; allowed keys here: {', '.join(sorted(req | opt))}",
                    )
            for k in sorted(req):
                if k not in t:
                    raise self.err(f"{path}.{k}", "is required")
        return raw

    def text(self, value: Any, path: str) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.err(path, f"expected a non-empty string, got {value!r}")
        return value.strip()

    def q(self, value: Any, kind: str, path: str) -> float:
        from microg.units import parse_quantity

        if isinstance(value, bool) or not isinstance(value, str | int | float):
            raise self.err(path, f'expected a quantity such as "1 {_BARE_UNITS["SI"][kind]}"')
        default = _BARE_UNITS[self.units][kind] if self.units else None
        if isinstance(value, int | float) and value == 0:
            return 0.0
        dim, extra = _ROTATIONAL.get(kind, (kind, ""))
        text: str | float = value
        if extra:
            bare = isinstance(value, int | float) or re.fullmatch(r"\s*[-+.\deE]+\s*", value)
            if bare:
                default = None if default is None else default + extra
                text = float(value)
            else:
                text = f"{value}{extra}"
        try:
            return parse_quantity(text, dim, where=f"{self.file}: {path}", default_unit=default)
        except InputError as exc:
            if extra:
                raise self.err(
                    path,
                    f"{value!r} is not a {kind.replace('_', ' ')}",
                    f"write e.g. '1e5 {_BARE_UNITS['SI'][kind]}'",
                ) from None
            raise exc

    def vec(self, value: Any, path: str, kind: str = "length") -> np.ndarray:
        if not isinstance(value, list) or len(value) != 3:
            raise self.err(path, "expected an array of three values")
        return np.array([self.q(v, kind, f"{path}[{i}]") for i, v in enumerate(value)])

    def direction(self, value: Any, path: str) -> np.ndarray:
        from microg._vectors import parse_direction

        return parse_direction(value, where=f"{self.file}: {path}")

    def build(self) -> GraphModel:
        head = self.table("graph")[0]
        name = self.text(head["name"], "graph.name")
        units = head.get("units")
        if units is not None and units not in _BARE_UNITS:
            raise self.err("graph.units", f"unknown unit system {units!r}", "use SI or US")
        self.units = units
        mass = head.get("mass", "consistent")
        if mass not in MASS_FORMULATIONS:
            raise self.err(
                "graph.mass", f"unknown mass formulation {mass!r}", "use lumped or consistent"
            )
        for key in self.doc:
            if key not in _KEYS:
                raise self.err(key, "unknown table", f"allowed: {', '.join(_KEYS)}")
        frames: dict[str, CoordinateFrame] = {"basic": BASIC}
        for i, t in enumerate(self.table("frame")):
            p = f"frame[{i}]"
            fname = self.text(t["name"], f"{p}.name")
            kind = t["kind"]
            if kind not in FRAME_KINDS:
                raise self.err(
                    f"{p}.kind", f"unknown kind {kind!r}", f"use {', '.join(FRAME_KINDS)}"
                )
            if fname in frames:
                raise self.err(f"{p}.name", f"duplicate frame {fname!r}")
            o = self.vec(t["origin"], f"{p}.origin")
            frames[fname] = frame_from_points(
                fname,
                kind,
                o,
                o + self.direction(t["z_axis"], f"{p}.z_axis"),
                self.vec(t["xz_point"], f"{p}.xz_point"),
                where=f"{self.file}: {p}",
            )
        nodes: list[Node] = []
        for i, t in enumerate(self.table("node")):
            p = f"node[{i}]"
            at = self.vec(t["at"], f"{p}.at")
            fr = t.get("frame", "basic")
            if fr not in frames:
                raise self.err(f"{p}.frame", f"unknown frame {fr!r}", f"known: {', '.join(frames)}")
            nodes.append(Node(self.text(t["name"], f"{p}.name"), at, frames[fr].axes_at(at), fr))
        node_pos = {n.name: n.position for n in nodes}
        sections: dict[str, BeamSection] = {}
        for i, t in enumerate(self.table("section")):
            s = self.section(t, f"section[{i}]")
            if s.name in sections:
                raise self.err(f"section[{i}].name", f"duplicate section {s.name!r}")
            sections[s.name] = s
        beams = [
            self.beam(t, f"beam[{i}]", sections, node_pos) for i, t in enumerate(self.table("beam"))
        ]
        rods = []
        for i, t in enumerate(self.table("rod")):
            p = f"rod[{i}]"
            rods.append(
                RodElement(
                    self.text(t["name"], f"{p}.name"),
                    self.pair(t["nodes"], f"{p}.nodes"),
                    self.q(t["ea"], "axial_stiffness", f"{p}.ea"),
                    self.q(t.get("gj", 0), "torsional_stiffness", f"{p}.gj"),
                    self.q(t["mass_per_length"], "mass_per_length", f"{p}.mass_per_length"),
                )
            )
        springs = [
            self.spring(t, f"spring[{i}]", frames, node_pos)
            for i, t in enumerate(self.table("spring"))
        ]
        masses = []
        for i, t in enumerate(self.table("mass")):
            p = f"mass[{i}]"
            nd = self.text(t["node"], f"{p}.node")
            at_m = self.vec(t["at"], f"{p}.at") if "at" in t else None
            off = np.zeros(3) if at_m is None or nd not in node_pos else at_m - node_pos[nd]
            masses.append(
                ConcentratedMass(
                    self.text(t["name"], f"{p}.name"),
                    nd,
                    self.q(t["mass"], "mass", f"{p}.mass"),
                    off,
                    self.inertia(t.get("inertia", {}), f"{p}.inertia"),
                )
            )
        links = []
        for i, t in enumerate(self.table("rigid")):
            p = f"rigid[{i}]"
            deps = t["dependents"]
            if not isinstance(deps, list) or not deps:
                raise self.err(f"{p}.dependents", "expected a non-empty array of node names")
            links.append(
                RigidLink(
                    self.text(t["name"], f"{p}.name"),
                    self.text(t["independent"], f"{p}.independent"),
                    tuple(self.text(d, f"{p}.dependents[{k}]") for k, d in enumerate(deps)),
                    self.components(t.get("components", COMPONENTS), f"{p}.components"),
                )
            )
        interps = []
        for i, t in enumerate(self.table("interpolation")):
            p = f"interpolation[{i}]"
            srcs = t["sources"]
            if not isinstance(srcs, list) or not srcs:
                raise self.err(f"{p}.sources", "expected a non-empty array of tables")
            out = []
            for k, s in enumerate(srcs):
                sp_ = f"{p}.sources[{k}]"
                if (
                    not isinstance(s, dict)
                    or set(s) - {"node", "components", "weight"}
                    or "node" not in s
                ):
                    raise self.err(sp_, 'expected { node = ..., components = "123", weight = 1.0 }')
                w = s.get("weight", 1.0)
                if isinstance(w, bool) or not isinstance(w, int | float) or not w > 0:
                    raise self.err(f"{sp_}.weight", f"expected a number > 0, got {w!r}")
                out.append(
                    (
                        self.text(s["node"], f"{sp_}.node"),
                        self.components(s.get("components", "123"), f"{sp_}.components", "123"),
                        float(w),
                    )
                )
            interps.append(
                Interpolation(
                    self.text(t["name"], f"{p}.name"),
                    self.text(t["reference"], f"{p}.reference"),
                    self.components(t.get("components", COMPONENTS), f"{p}.components"),
                    tuple(out),
                )
            )
        points = []
        for i, t in enumerate(self.table("point")):
            p = f"point[{i}]"
            nd = self.text(t["node"], f"{p}.node")
            at = self.vec(t["at"], f"{p}.at") if "at" in t else node_pos.get(nd, np.zeros(3))
            points.append(
                GraphPoint(
                    self.text(t["name"], f"{p}.name"),
                    nd,
                    np.asarray(at, float),
                    str(t.get("kind", "point")),
                    str(t.get("description", "")),
                )
            )
        cons = [
            Constraint(
                self.text(t["node"], f"constraint[{i}].node"),
                self.components(t["components"], f"constraint[{i}].components"),
            )
            for i, t in enumerate(self.table("constraint"))
        ]
        graph = GraphModel(
            name=name,
            nodes=tuple(nodes),
            beams=tuple(beams),
            rods=tuple(rods),
            springs=tuple(springs),
            masses=tuple(masses),
            rigid_links=tuple(links),
            interpolations=tuple(interps),
            points=tuple(points),
            frames=tuple(f for k, f in frames.items() if k != "basic"),
            mass_formulation=mass,
            constraints=tuple(cons),
            description=str(head.get("description", "")),
            source=self.file,
            meta={"format": "graph-toml", "units": units},
        )
        validate_graph(graph)
        return graph

    def components(self, value: Any, path: str, allowed: str = COMPONENTS) -> str:
        try:
            return parse_components(value, where=f"{self.file}: {path}", allowed=allowed)
        except InputError as exc:
            raise ModelError(exc.what, where=exc.where, fix=exc.fix) from None

    def pair(self, value: Any, path: str) -> tuple[str, str]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.err(path, "expected two node names")
        return self.text(value[0], f"{path}[0]"), self.text(value[1], f"{path}[1]")

    def inertia(self, raw: Any, path: str) -> np.ndarray:
        if not isinstance(raw, dict) or set(raw) - set(_INERTIA_KEYS):
            raise self.err(
                path, "expected an inline table with keys among " + ", ".join(_INERTIA_KEYS)
            )
        v = {k: self.q(raw.get(k, 0), "rotary_inertia", f"{path}.{k}") for k in _INERTIA_KEYS}
        return np.array(
            [
                [v["xx"], v["xy"], v["xz"]],
                [v["xy"], v["yy"], v["yz"]],
                [v["xz"], v["yz"], v["zz"]],
            ]
        )

    def rows(self, value: Any, path: str) -> np.ndarray:
        """Three unit rows (x, y, z axes in the basic frame), right-handed and orthonormal."""
        ok = isinstance(value, list) and len(value) == 3
        ok = ok and all(
            isinstance(r, list)
            and len(r) == 3
            and all(isinstance(v, int | float) and not isinstance(v, bool) for v in r)
            for r in value
        )
        if not ok:
            raise self.err(path, "expected a frame name or three rows [[x...], [y...], [z...]]")
        ax = np.array(value, float)
        if not np.allclose(ax @ ax.T, np.eye(3), atol=1e-9) or np.linalg.det(ax) < 0:
            raise self.err(path, "the rows are not orthonormal and right-handed")
        return ax

    def section(self, t: dict[str, Any], p: str) -> BeamSection:
        if ("ei" in t) == ("ei_y" in t or "ei_z" in t) or (("ei_y" in t) != ("ei_z" in t)):
            raise self.err(f"{p}.ei", "give either ei, or both ei_y and ei_z")
        ea = self.q(t["ea"], "axial_stiffness", f"{p}.ea")
        if "ei" in t:
            ei_y = ei_z = self.q(t["ei"], "bending_stiffness", f"{p}.ei")
        else:
            ei_y = self.q(t["ei_y"], "bending_stiffness", f"{p}.ei_y")
            ei_z = self.q(t["ei_z"], "bending_stiffness", f"{p}.ei_z")
        for v, k in ((ea, "ea"), (ei_y, "ei_y"), (ei_z, "ei_z")):
            if not v > 0:
                raise self.err(f"{p}.{k}", "must be > 0")
        gj = self.q(t["gj"], "torsional_stiffness", f"{p}.gj")
        if not gj > 0:
            raise self.err(f"{p}.gj", "must be > 0")
        mpl = self.q(t["mass_per_length"], "mass_per_length", f"{p}.mass_per_length")
        if mpl < 0:
            raise self.err(f"{p}.mass_per_length", "must be >= 0")
        # homogeneous section: I/A = EI/EA (the rule of microg.models.station.Beam)
        if "polar_gyration" in t:
            r = self.q(t["polar_gyration"], "length", f"{p}.polar_gyration")
            if r < 0:
                raise self.err(f"{p}.polar_gyration", "must be >= 0")
            polar = mpl * r**2
        else:
            polar = mpl * (ei_y + ei_z) / ea
        shear: list[float | None] = []
        for k in ("shear_y", "shear_z"):
            if k in t:
                v = self.q(t[k], "axial_stiffness", f"{p}.{k}")
                if not v > 0:
                    raise self.err(f"{p}.{k}", "must be > 0 (omit it for no shear flexibility)")
                shear.append(v)
            else:
                shear.append(None)
        rot = t.get("rotary_inertia", False)
        if not isinstance(rot, bool):
            raise self.err(f"{p}.rotary_inertia", "expected true or false")
        ei_yz = self.q(t.get("ei_yz", 0), "bending_stiffness", f"{p}.ei_yz")
        return BeamSection(
            self.text(t["name"], f"{p}.name"),
            ea,
            ei_y,
            ei_z,
            gj,
            mpl,
            polar,
            shear[0],
            shear[1],
            mpl * ei_y / ea if rot else 0.0,
            mpl * ei_z / ea if rot else 0.0,
            ei_yz,
        )

    def beam(
        self,
        t: dict[str, Any],
        p: str,
        sections: dict[str, BeamSection],
        pos: dict[str, np.ndarray],
    ) -> BeamElement:
        a, b = self.pair(t["nodes"], f"{p}.nodes")
        sec = self.text(t["section"], f"{p}.section")
        if sec not in sections:
            raise self.err(
                f"{p}.section",
                f"unknown section {sec!r}",
                f"known: {', '.join(sections) or 'none'}",
            )
        off = np.zeros((2, 3))
        if "offsets" in t:
            raw = t["offsets"]
            if not isinstance(raw, list) or len(raw) != 2:
                raise self.err(f"{p}.offsets", "expected two positions [[...], [...]]")
            off = np.stack([self.vec(raw[k], f"{p}.offsets[{k}]") for k in range(2)])
        if "orientation" in t:
            ori = self.direction(t["orientation"], f"{p}.orientation")
        else:
            d = (pos.get(b, np.zeros(3)) + off[1]) - (pos.get(a, np.zeros(3)) + off[0])
            ori = _default_orientation(d)
        kind = t.get("kind", "beam")
        if kind not in ("beam", "bar"):
            raise self.err(f"{p}.kind", f"unknown kind {kind!r}", "use beam or bar")
        rel = t.get("releases", ["", ""])
        if not isinstance(rel, list) or len(rel) != 2 or not all(isinstance(r, str) for r in rel):
            raise self.err(f"{p}.releases", 'expected two component strings, e.g. ["", "456"]')
        rels = tuple(
            self.components(r, f"{p}.releases[{k}]") if r else "" for k, r in enumerate(rel)
        )
        return BeamElement(
            self.text(t["name"], f"{p}.name"),
            (a, b),
            sections[sec],
            ori,
            off,
            kind,
            (rels[0], rels[1]),
        )

    def spring(
        self,
        t: dict[str, Any],
        p: str,
        frames: dict[str, CoordinateFrame],
        pos: dict[str, np.ndarray],
    ) -> Spring:
        nodes = t["nodes"]
        if not isinstance(nodes, list) or len(nodes) not in (1, 2):
            raise self.err(f"{p}.nodes", "expected one node (grounded) or two")
        a = self.text(nodes[0], f"{p}.nodes[0]")
        b = self.text(nodes[1], f"{p}.nodes[1]") if len(nodes) == 2 else None
        k = np.zeros((6, 6))
        c = np.zeros((6, 6))
        for key, mat, kinds in (
            ("stiffness", k, ("stiffness", "rotational_stiffness")),
            ("damping", c, ("damping", "rotational_damping")),
        ):
            raw = t.get(key, {})
            if not isinstance(raw, dict) or set(raw) - set(_SPRING_KEYS):
                raise self.err(
                    f"{p}.{key}", "expected an inline table with keys among x, y, z, rx, ry, rz"
                )
            for i, comp in enumerate(_SPRING_KEYS):
                if comp in raw:
                    v = self.q(raw[comp], kinds[i >= 3], f"{p}.{key}.{comp}")
                    if v < 0:
                        raise self.err(f"{p}.{key}.{comp}", "must be >= 0")
                    mat[i, i] = v
        if "axes" in t and "orientation" in t:
            raise self.err(f"{p}.axes", "give axes or orientation, not both")
        pa = pos.get(a, np.zeros(3))
        pb = pos.get(b, pa) if b is not None else pa
        loc = self.vec(t["at"], f"{p}.at") if "at" in t else 0.5 * (pa + pb)
        if "axes" in t and isinstance(t["axes"], list):
            axes = self.rows(t["axes"], f"{p}.axes")
        elif "axes" in t:
            fr = t["axes"]
            if fr not in frames:
                raise self.err(f"{p}.axes", f"unknown frame {fr!r}", f"known: {', '.join(frames)}")
            axes = frames[fr].axes_at(loc)
        else:
            ori = (
                self.direction(t["orientation"], f"{p}.orientation") if "orientation" in t else None
            )
            axes = spring_axes(pa, pb, ori, k, c, where=f"{self.file}: {p}")
        return Spring(self.text(t["name"], f"{p}.name"), (a, b), k, c, axes, loc)


def _default_orientation(direction: np.ndarray) -> np.ndarray:
    """The basic axis least aligned with ``direction`` (the station format's rule)."""
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
        orientation = _default_orientation(ex)
    v = np.asarray(orientation, float)
    ey = v - float(np.dot(v, ex)) * ex
    if float(np.linalg.norm(ey)) <= PARALLEL_TOL * max(float(np.linalg.norm(v)), 1e-300):
        raise InputError(
            "orientation vector is parallel to the spring's axis", where=where, fix="give another"
        )
    ey = ey / np.linalg.norm(ey)
    return np.stack([ex, ey, np.cross(ex, ey)])


def loads_graph(text: str, *, filename: str = "<string>") -> GraphModel:
    """Read a graph model from TOML text (format: ``docs/model-format.md``, "Graph models")."""
    doc = loads_toml(text, filename, ModelError)
    if "graph" not in doc or not isinstance(doc["graph"], dict):
        raise ModelError(
            "missing [graph] table", where=filename, fix="start the file with [graph] and a name"
        )
    return _Reader(doc, filename).build()


def load_graph(path: str | Path) -> GraphModel:
    """Read a graph model TOML file (UTF-8)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the file: {exc}", where=str(path)) from None
    return loads_graph(text, filename=str(path))


# --------------------------------------------------------------------------- writer


def _tq(value: float, unit: str) -> str:
    return f'"{float(value):.17g} {unit}"'


def _tv(v: np.ndarray, unit: str = "m") -> str:
    return "[" + ", ".join(_tq(x, unit) for x in np.asarray(v, float)) + "]"


def _ts(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def dump_graph(graph: GraphModel) -> str:
    """A graph model as graph TOML, SI with a unit on every value.

    Loading the text reproduces the model to round-off, with two exceptions that raise an
    :class:`InputError` here rather than write something else: a node whose axes are not
    those of one of the model's frames at its position, and a spring whose axes are not
    representable (written as an orientation, which needs non-coincident nodes).
    """
    lines = [
        "[graph]",
        f"name = {_ts(graph.name)}",
        f"description = {_ts(graph.description)}",
        f'mass = "{graph.mass_formulation}"',
        "",
    ]
    frames = {f.name: f for f in graph.frames}
    for f in graph.frames:
        z = f.rotation[2]
        lines += [
            "[[frame]]",
            f"name = {_ts(f.name)}",
            f'kind = "{f.kind}"',
            f"origin = {_tv(f.origin)}",
            f"z_axis = [{', '.join(f'{x:.17g}' for x in z)}]",
            f"xz_point = {_tv(f.origin + f.rotation[0])}",
            "",
        ]
    for n in graph.nodes:
        lines += ["[[node]]", f"name = {_ts(n.name)}", f"at = {_tv(n.position)}"]
        if n.frame != "basic":
            fr = frames.get(n.frame)
            if fr is None or not np.allclose(fr.axes_at(n.position), n.axes, atol=1e-12):
                raise InputError(f"node {n.name!r}: its axes are not those of a model frame")
            lines.append(f"frame = {_ts(n.frame)}")
        elif not np.allclose(n.axes, np.eye(3), atol=1e-12):
            raise InputError(f"node {n.name!r}: rotated axes without a frame cannot be written")
        lines.append("")
    secs: dict[str, BeamSection] = {}
    for b in graph.beams:
        secs.setdefault(b.section.name, b.section)
    for s in secs.values():
        lines += [
            "[[section]]",
            f"name = {_ts(s.name)}",
            f"ea = {_tq(s.ea_N, 'N')}",
            f"ei_y = {_tq(s.ei_y_N_m2, 'N*m^2')}",
            f"ei_z = {_tq(s.ei_z_N_m2, 'N*m^2')}",
            f"gj = {_tq(s.gj_N_m2, 'N*m^2')}",
            f"mass_per_length = {_tq(s.mass_per_length_kg_per_m, 'kg/m')}",
        ]
        if s.ei_yz_N_m2:
            lines.append(f"ei_yz = {_tq(s.ei_yz_N_m2, 'N*m^2')}")
        if s.mass_per_length_kg_per_m > 0:
            r_p = math.sqrt(s.polar_mass_kg_m / s.mass_per_length_kg_per_m)
            lines.append(f"polar_gyration = {_tq(r_p, 'm')}")
        for k, v in (("shear_y", s.shear_y_N), ("shear_z", s.shear_z_N)):
            if v is not None:
                lines.append(f"{k} = {_tq(v, 'N')}")
        if s.rotary_y_kg_m or s.rotary_z_kg_m:
            lines.append("rotary_inertia = true")
        lines.append("")
    for b in graph.beams:
        lines += [
            "[[beam]]",
            f"name = {_ts(b.name)}",
            f"nodes = [{_ts(b.nodes[0])}, {_ts(b.nodes[1])}]",
            f"section = {_ts(b.section.name)}",
            f"orientation = [{', '.join(f'{x:.17g}' for x in b.orientation)}]",
            f'kind = "{b.kind}"',
        ]
        if np.any(b.offsets):
            lines.append(f"offsets = [{_tv(b.offsets[0])}, {_tv(b.offsets[1])}]")
        if any(b.releases):
            lines.append(f"releases = [{_ts(b.releases[0])}, {_ts(b.releases[1])}]")
        lines.append("")
    for r in graph.rods:
        lines += [
            "[[rod]]",
            f"name = {_ts(r.name)}",
            f"nodes = [{_ts(r.nodes[0])}, {_ts(r.nodes[1])}]",
            f"ea = {_tq(r.ea_N, 'N')}",
            f"gj = {_tq(r.gj_N_m2, 'N*m^2')}",
            f"mass_per_length = {_tq(r.mass_per_length_kg_per_m, 'kg/m')}",
            "",
        ]
    for spr in graph.springs:
        for mat in (spr.stiffness, spr.damping):
            if np.count_nonzero(mat - np.diag(np.diag(mat))):
                raise InputError(f"spring {spr.name!r}: coupled 6x6 terms cannot be written")
        nodes = [spr.nodes[0]] if spr.nodes[1] is None else list(spr.nodes)
        units_k = ("N/m",) * 3 + ("N*m/rad",) * 3
        units_c = ("N*s/m",) * 3 + ("N*m*s/rad",) * 3
        kk = ", ".join(
            f"{c} = {_tq(spr.stiffness[i, i], units_k[i])}" for i, c in enumerate(_SPRING_KEYS)
        )
        cc = ", ".join(
            f"{c} = {_tq(spr.damping[i, i], units_c[i])}" for i, c in enumerate(_SPRING_KEYS)
        )
        lines += [
            "[[spring]]",
            f"name = {_ts(spr.name)}",
            "nodes = [" + ", ".join(_ts(str(n)) for n in nodes) + "]",
            f"stiffness = {{ {kk} }}",
            f"damping = {{ {cc} }}",
            f"at = {_tv(spr.location)}",
            "axes = ["
            + ", ".join("[" + ", ".join(f"{x:.17g}" for x in row) + "]" for row in spr.axes)
            + "]",
            "",
        ]
    if graph.scalar_springs:
        raise InputError("scalar springs (CELAS) have no graph TOML form; keep the deck")
    for m in graph.masses:
        j = m.inertia_kg_m2
        inertia = ", ".join(
            f"{k} = {_tq(j[a, b], 'kg*m^2')}"
            for k, (a, b) in zip(
                _INERTIA_KEYS, ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)), strict=True
            )
        )
        at = graph.node(m.node).position + m.offset_m
        lines += [
            "[[mass]]",
            f"name = {_ts(m.name)}",
            f"node = {_ts(m.node)}",
            f"mass = {_tq(m.mass_kg, 'kg')}",
            f"at = {_tv(at)}",
            f"inertia = {{ {inertia} }}",
            "",
        ]
    for rl in graph.rigid_links:
        lines += [
            "[[rigid]]",
            f"name = {_ts(rl.name)}",
            f"independent = {_ts(rl.independent)}",
            "dependents = [" + ", ".join(_ts(d) for d in rl.dependents) + "]",
            f'components = "{rl.components}"',
            "",
        ]
    for ip in graph.interpolations:
        srcs = ", ".join(
            f'{{ node = {_ts(n)}, components = "{c}", weight = {w:.17g} }}'
            for n, c, w in ip.sources
        )
        lines += [
            "[[interpolation]]",
            f"name = {_ts(ip.name)}",
            f"reference = {_ts(ip.reference)}",
            f'components = "{ip.components}"',
            f"sources = [{srcs}]",
            "",
        ]
    for p in graph.points:
        lines += [
            "[[point]]",
            f"name = {_ts(p.name)}",
            f"node = {_ts(p.node)}",
            f"at = {_tv(p.position)}",
            f'kind = "{p.kind}"',
            f"description = {_ts(p.description)}",
            "",
        ]
    for c in graph.constraints:
        lines += ["[[constraint]]", f"node = {_ts(c.node)}", f'components = "{c.components}"', ""]
    return "\n".join(lines)
