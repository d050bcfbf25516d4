"""A graph model file's validated structure -> the frozen SI :class:`GraphModel`.

Step 3 of reading a graph TOML file, as :mod:`microg.models.build` is for stations: every
quantity of :class:`~microg.models.graph_schema.GraphFileIn` is converted to SI (a bare
number takes the unit of ``[graph] units``, :data:`BARE_UNITS`), frames are made from
their points, nodes take their frame's axes, sections get their homogeneous-section
defaults, and the references between tables (frames, sections) are resolved; then
:func:`~microg.models.graph_check.validate_graph` checks the whole.  Every fault is one
:class:`~microg.errors.ModelError`, ``FILE: table[i].key: what is wrong (how to fix)``.
"""

from __future__ import annotations

import re

import numpy as np

from microg.errors import InputError, ModelError
from microg.models.coords import BASIC, CoordinateFrame, frame_from_points
from microg.models.graph_check import validate_graph
from microg.models.graph_model import (
    BeamElement,
    BeamSection,
    ConcentratedMass,
    Constraint,
    GraphModel,
    GraphPoint,
    Interpolation,
    Node,
    RigidLink,
    RodElement,
    Spring,
    default_orientation,
    spring_axes,
)
from microg.models.graph_schema import (
    INERTIA_KEYS,
    SPRING_KEYS,
    BeamIn,
    GraphFileIn,
    SectionIn,
    SpringIn,
    SpringValuesIn,
)
from microg.models.schema import InertiaIn
from microg.units import parse_quantity

__all__ = ["BARE_UNITS", "build_graph"]

#: unit of a bare number for each quantity kind, by ``[graph] units``
BARE_UNITS: dict[str, dict[str, str]] = {
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


class _Builder:
    """Converts a validated graph file to SI (private)."""

    def __init__(self, doc: GraphFileIn, file: str):
        self.doc = doc
        self.file = file
        self.units = doc.graph.units

    def err(self, path: str, what: str, fix: str | None = None) -> ModelError:
        return ModelError(what, where=f"{self.file}: {path}", fix=fix)

    def q(self, value: str | float, kind: str, path: str) -> float:
        """A quantity in SI: a bare number in the file's unit system, 0 in any."""
        default = BARE_UNITS[self.units][kind] if self.units else None
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
        except InputError:
            if extra:
                raise self.err(
                    path,
                    f"{value!r} is not a {kind.replace('_', ' ')}",
                    f"write e.g. '1e5 {BARE_UNITS['SI'][kind]}'",
                ) from None
            raise

    def vec(self, value: list[str | float], path: str) -> np.ndarray:
        return np.array([self.q(v, "length", f"{path}[{i}]") for i, v in enumerate(value)])

    def build(self) -> GraphModel:
        doc = self.doc
        frames: dict[str, CoordinateFrame] = {"basic": BASIC}
        for i, f in enumerate(doc.frame):
            p = f"frame[{i}]"
            if f.name in frames:
                raise self.err(f"{p}.name", f"duplicate frame {f.name!r}")
            o = self.vec(f.origin, f"{p}.origin")
            frames[f.name] = frame_from_points(
                f.name,
                f.kind,
                o,
                o + np.asarray(f.z_axis, float),
                self.vec(f.xz_point, f"{p}.xz_point"),
                where=f"{self.file}: {p}",
            )
        nodes: list[Node] = []
        for i, n in enumerate(doc.node):
            at = self.vec(n.at, f"node[{i}].at")
            if n.frame not in frames:
                raise self.err(
                    f"node[{i}].frame",
                    f"unknown frame {n.frame!r}",
                    f"known: {', '.join(frames)}",
                )
            nodes.append(Node(n.name, at, frames[n.frame].axes_at(at), n.frame))
        node_pos = {n.name: n.position for n in nodes}
        sections: dict[str, BeamSection] = {}
        for i, s in enumerate(doc.section):
            sec = self.section(s, f"section[{i}]")
            if sec.name in sections:
                raise self.err(f"section[{i}].name", f"duplicate section {sec.name!r}")
            sections[sec.name] = sec
        beams = [self.beam(b, f"beam[{i}]", sections, node_pos) for i, b in enumerate(doc.beam)]
        rods = [
            RodElement(
                r.name,
                r.nodes,
                self.q(r.ea, "axial_stiffness", f"rod[{i}].ea"),
                self.q(r.gj, "torsional_stiffness", f"rod[{i}].gj"),
                self.q(r.mass_per_length, "mass_per_length", f"rod[{i}].mass_per_length"),
            )
            for i, r in enumerate(doc.rod)
        ]
        springs = [
            self.spring(s, f"spring[{i}]", frames, node_pos) for i, s in enumerate(doc.spring)
        ]
        masses = []
        for i, m in enumerate(doc.mass):
            p = f"mass[{i}]"
            at_m = self.vec(m.at, f"{p}.at") if m.at is not None else None
            off = np.zeros(3) if at_m is None or m.node not in node_pos else at_m - node_pos[m.node]
            masses.append(
                ConcentratedMass(
                    m.name,
                    m.node,
                    self.q(m.mass, "mass", f"{p}.mass"),
                    off,
                    self.inertia(m.inertia, f"{p}.inertia"),
                )
            )
        links = [
            RigidLink(r.name, r.independent, tuple(r.dependents), r.components) for r in doc.rigid
        ]
        interps = [
            Interpolation(
                ip.name,
                ip.reference,
                ip.components,
                tuple((s.node, s.components, s.weight) for s in ip.sources),
            )
            for ip in doc.interpolation
        ]
        points = []
        for i, pt in enumerate(doc.point):
            at = (
                self.vec(pt.at, f"point[{i}].at")
                if pt.at is not None
                else node_pos.get(pt.node, np.zeros(3))
            )
            points.append(
                GraphPoint(pt.name, pt.node, np.asarray(at, float), pt.kind, pt.description)
            )
        graph = GraphModel(
            name=doc.graph.name,
            nodes=tuple(nodes),
            beams=tuple(beams),
            rods=tuple(rods),
            springs=tuple(springs),
            masses=tuple(masses),
            rigid_links=tuple(links),
            interpolations=tuple(interps),
            points=tuple(points),
            frames=tuple(f for k, f in frames.items() if k != "basic"),
            mass_formulation=doc.graph.mass,
            constraints=tuple(Constraint(c.node, c.components) for c in doc.constraint),
            description=doc.graph.description,
            source=self.file,
            meta={"format": "graph-toml", "units": self.units},
        )
        validate_graph(graph)
        return graph

    def inertia(self, raw: InertiaIn, path: str) -> np.ndarray:
        v = {k: self.q(getattr(raw, k) or 0, "rotary_inertia", f"{path}.{k}") for k in INERTIA_KEYS}
        return np.array(
            [
                [v["xx"], v["xy"], v["xz"]],
                [v["xy"], v["yy"], v["yz"]],
                [v["xz"], v["yz"], v["zz"]],
            ]
        )

    def section(self, t: SectionIn, p: str) -> BeamSection:
        if (t.ei is not None) == (t.ei_y is not None or t.ei_z is not None) or (
            (t.ei_y is None) != (t.ei_z is None)
        ):
            raise self.err(f"{p}.ei", "give either ei, or both ei_y and ei_z")
        ea = self.q(t.ea, "axial_stiffness", f"{p}.ea")
        if t.ei is not None:
            ei_y = ei_z = self.q(t.ei, "bending_stiffness", f"{p}.ei")
        else:
            assert t.ei_y is not None and t.ei_z is not None  # checked above
            ei_y = self.q(t.ei_y, "bending_stiffness", f"{p}.ei_y")
            ei_z = self.q(t.ei_z, "bending_stiffness", f"{p}.ei_z")
        for v, k in ((ea, "ea"), (ei_y, "ei_y"), (ei_z, "ei_z")):
            if not v > 0:
                raise self.err(f"{p}.{k}", "must be > 0")
        gj = self.q(t.gj, "torsional_stiffness", f"{p}.gj")
        if not gj > 0:
            raise self.err(f"{p}.gj", "must be > 0")
        mpl = self.q(t.mass_per_length, "mass_per_length", f"{p}.mass_per_length")
        if mpl < 0:
            raise self.err(f"{p}.mass_per_length", "must be >= 0")
        # homogeneous section: I/A = EI/EA (the rule of microg.models.station.Beam)
        if t.polar_gyration is not None:
            r = self.q(t.polar_gyration, "length", f"{p}.polar_gyration")
            if r < 0:
                raise self.err(f"{p}.polar_gyration", "must be >= 0")
            polar = mpl * r**2
        else:
            polar = mpl * (ei_y + ei_z) / ea
        shear: list[float | None] = []
        for k, raw in (("shear_y", t.shear_y), ("shear_z", t.shear_z)):
            if raw is None:
                shear.append(None)
                continue
            v = self.q(raw, "axial_stiffness", f"{p}.{k}")
            if not v > 0:
                raise self.err(f"{p}.{k}", "must be > 0 (omit it for no shear flexibility)")
            shear.append(v)
        ei_yz = self.q(t.ei_yz or 0, "bending_stiffness", f"{p}.ei_yz")
        rot = t.rotary_inertia
        return BeamSection(
            t.name,
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
        t: BeamIn,
        p: str,
        sections: dict[str, BeamSection],
        pos: dict[str, np.ndarray],
    ) -> BeamElement:
        a, b = t.nodes
        if t.section not in sections:
            raise self.err(
                f"{p}.section",
                f"unknown section {t.section!r}",
                f"known: {', '.join(sections) or 'none'}",
            )
        off = np.zeros((2, 3))
        if t.offsets is not None:
            off = np.stack([self.vec(t.offsets[k], f"{p}.offsets[{k}]") for k in range(2)])
        if t.orientation is not None:
            ori = np.asarray(t.orientation, float)
        else:
            d = (pos.get(b, np.zeros(3)) + off[1]) - (pos.get(a, np.zeros(3)) + off[0])
            ori = default_orientation(d)
        return BeamElement(t.name, (a, b), sections[t.section], ori, off, t.kind, t.releases)

    def diagonal(self, raw: SpringValuesIn, key: str, kinds: tuple[str, str], p: str) -> np.ndarray:
        mat = np.zeros((6, 6))
        for i, comp in enumerate(SPRING_KEYS):
            value = getattr(raw, comp)
            if value is not None:
                v = self.q(value, kinds[i >= 3], f"{p}.{key}.{comp}")
                if v < 0:
                    raise self.err(f"{p}.{key}.{comp}", "must be >= 0")
                mat[i, i] = v
        return mat

    def spring(
        self,
        t: SpringIn,
        p: str,
        frames: dict[str, CoordinateFrame],
        pos: dict[str, np.ndarray],
    ) -> Spring:
        a, b = t.nodes
        k = self.diagonal(t.stiffness, "stiffness", ("stiffness", "rotational_stiffness"), p)
        c = self.diagonal(t.damping, "damping", ("damping", "rotational_damping"), p)
        if t.axes is not None and t.orientation is not None:
            raise self.err(f"{p}.axes", "give axes or orientation, not both")
        pa = pos.get(a, np.zeros(3))
        pb = pos.get(b, pa) if b is not None else pa
        loc = self.vec(t.at, f"{p}.at") if t.at is not None else 0.5 * (pa + pb)
        if isinstance(t.axes, tuple):
            axes = np.array(t.axes, float)
        elif t.axes is not None:
            if t.axes not in frames:
                raise self.err(
                    f"{p}.axes", f"unknown frame {t.axes!r}", f"known: {', '.join(frames)}"
                )
            axes = frames[t.axes].axes_at(loc)
        else:
            ori = None if t.orientation is None else np.asarray(t.orientation, float)
            axes = spring_axes(pa, pb, ori, k, c, where=f"{self.file}: {p}")
        return Spring(t.name, (a, b), k, c, axes, loc)


def build_graph(doc: GraphFileIn, file: str) -> GraphModel:
    """The graph model of a validated graph file, SI, checked.

    Parameters
    ----------
    doc : GraphFileIn
        The file's structure, validated (:mod:`microg.models.graph_schema`).
    file : str
        The file's name, for messages and :attr:`GraphModel.source`.

    Raises
    ------
    ModelError
        A quantity of the wrong dimension or out of range, an unknown frame or section, a
        duplicate, a non-positive stiffness; and every fault of
        :func:`~microg.models.graph_check.validate_graph` (an :class:`InputError`).
    """
    return _Builder(doc, file).build()
