"""The one mesher of a tree-of-beams station, and the station as a frame graph.

:func:`mesh_station` places nodes at bodies, joints, masses and points and cuts every beam
evenly (:class:`StationMesh`); :func:`graph_from_station` writes the mesh as a
:class:`~microg.models.graph_model.GraphModel` of Euler-Bernoulli elements with consistent
mass and the station's effective properties (penalty axial and torsional stiffness of
rigid beams, :data:`AXIAL_PENALTY`, :data:`TORSION_PENALTY`, :func:`torsion_is_rigid`).
:func:`microg.structure.fem.build_fem` assembles that graph and keeps its exact tree
flexibility; :func:`microg.structure.frame.build_frame` of it gives the same matrices.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from microg import defaults
from microg.errors import InputError
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
from microg.structure.assembly import MAX_FEM_DOF

__all__ = [
    "AXIAL_PENALTY",
    "DEFAULT_ELEMENTS_PER_BEAM",
    "GJ_ZERO_FRACTION",
    "TORSION_PENALTY",
    "StationMesh",
    "graph_from_station",
    "mesh_station",
    "station_mass_properties",
    "torsion_is_rigid",
]

#: axially rigid beams: EA = AXIAL_PENALTY * max(EI_y, EI_z) / L^2
AXIAL_PENALTY = 1e6
#: torsionally rigid beams (gj = 0): GJ = TORSION_PENALTY * max(EI_y, EI_z)
TORSION_PENALTY = 1e4
#: a torsional stiffness at most this fraction of max(EI_y, EI_z) is numerically zero and is
#: treated as gj = 0 (the rule of docs/model-format.md: 1e-30 lbf*ft^2 behaves like 0)
GJ_ZERO_FRACTION = 1e-12
#: default number of elements per beam when neither discretisation option is given
DEFAULT_ELEMENTS_PER_BEAM = defaults.ELEMENTS


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


def station_mass_properties(station: Station) -> tuple[float, np.ndarray, np.ndarray]:
    """Station.mass_properties() plus the beams' polar (torsional) mass moments.

    Parameters
    ----------
    station : Station

    Returns
    -------
    total : float
        kg.
    center : ndarray (3,)
        Centre of mass, m.
    inertia : ndarray (3, 3)
        About the centre of mass, kg m^2 (with ``rho J L`` along each beam).
    """
    total, cm, inertia = station.mass_properties()
    for bm in station.beams:
        _, _, rho_j = _effective_properties(bm)
        inertia = inertia + rho_j * bm.length * np.outer(bm.direction, bm.direction)
    return total, cm, inertia


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
        _, _, inertia = station_mass_properties(station)
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
