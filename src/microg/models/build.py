"""Step 3 of reading a model: the checked structure (pydantic) -> a frozen SI ``Station``.

:func:`build_station` converts every quantity to SI with :func:`microg.units.parse_quantity`
(dimension-checked, within :data:`~microg.models.schema.FIELD_LIMITS`) and checks the physics
and the tree: signs, parents, cycles, points on their carriers, unique names, counts.  Every
error is a :class:`~microg.errors.ModelError` naming ``FILE: field.path``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

import numpy as np

from microg.errors import InputError, ModelError
from microg.models.messages import EXAMPLES
from microg.models.schema import (
    EARTH_RADIUS,
    FIELD_LIMITS,
    MAX_COUNTS,
    ON_AXIS_TOL,
    UNIT_SYSTEMS,
    BeamIn,
    BeamMassIn,
    BodyIn,
    BodyMassIn,
    FileIn,
    InertiaIn,
    Limit,
    MassIn,
    PointIn,
)
from microg.models.station import Beam, NamedPoint, Orbit, PointMass, RigidBody, Station
from microg.units import DIMENSIONS, G0, parse_quantity

__all__ = ["Builder", "build_station"]


def build_station(doc: FileIn, file: str, source: str = "") -> Station:
    """The SI station of a structurally valid model file.

    Parameters
    ----------
    doc : the validated file (:class:`~microg.models.schema.FileIn`)
    file : the file's name for messages
    source : stored as :attr:`Station.source`

    Raises
    ------
    ModelError
        One line: ``FILE: field.path: what is wrong (how to fix)``.
    """
    return Builder(doc, file, source).build()


class Builder:
    """Converts a structurally valid file to a Station, checking as it goes."""

    def __init__(self, doc: FileIn, file: str, source: str):
        self.doc = doc
        self.file = file
        self.source = source
        self.units = UNIT_SYSTEMS[doc.station.units] if doc.station.units else None

    # ----- helpers
    def error(self, path: str, what: str, fix: str | None = None) -> ModelError:
        """A :class:`~microg.errors.ModelError` at ``FILE: path``."""
        return ModelError(what, where=f"{self.file}: {path}" if path else self.file, fix=fix)

    def q(self, value: str | float, kind: str, path: str) -> float:
        """Parse a quantity to SI, checked for its dimension and its limits (FIELD_LIMITS)."""
        lim = FIELD_LIMITS[kind]
        dimension = lim.dimension
        default = self.units[dimension] if self.units else None
        if default is None and not isinstance(value, str) and value == 0.0:
            default = DIMENSIONS[dimension]  # zero is zero in every unit
        try:
            out = parse_quantity(
                value, dimension, where=f"{self.file}: {path}", default_unit=default
            )
        except InputError as exc:
            fix = exc.fix
            if "has no unit" in exc.what:
                fix = (
                    f"write it with a unit, e.g. '{value} {DIMENSIONS[dimension]}', "
                    'or declare units = "SI" or "US" in [station]'
                )
            raise ModelError(exc.what, where=exc.where, fix=fix) from None
        return self.within(out, value, lim, path)

    def within(self, out: float, value: str | float, lim: Limit, path: str) -> float:
        """``out`` (SI) if it is in ``lim``, else a ModelError naming ``path``."""
        si = DIMENSIONS[lim.dimension]
        low = out <= lim.lo if lim.lo_open else out < lim.lo
        if low and out <= 0.0 and lim.lo >= 0.0:
            if lim.lo > 0.0 or lim.lo_open:
                raise self.error(path, f"{value!r} must be positive", lim.why or "give a value > 0")
            raise self.error(
                path, f"{value!r} must not be negative", lim.why or "give a value >= 0"
            )
        if 0.0 < abs(out) < lim.min_nonzero:
            raise self.error(
                path,
                f"{value!r} is {out:.6g} {si}, below the smallest non-zero value "
                f"{lim.min_nonzero:g} {si}",
                lim.why or "give 0 or a value of physical size",
            )
        if low or out > lim.hi:
            side = ("not above" if lim.lo_open else "below") if low else "beyond"
            bound = lim.lo if low else lim.hi
            raise self.error(
                path,
                f"{value!r} is {out:.6g} {si}, {side} the limit of {bound:.6g} {si}",
                lim.why or "check the value and its unit (limits: docs/model-format.md)",
            )
        return out

    def vec(self, value: Sequence[str | float], path: str) -> np.ndarray:
        """A position (3,), m: each component parsed as a length."""
        return np.array([self.q(c, "position", f"{path}[{i}]") for i, c in enumerate(value)])

    # ----- the whole file
    def build(self) -> Station:
        """The checked SI :class:`~microg.models.station.Station` of the whole file."""
        doc = self.doc
        st = doc.station
        gravity = (
            G0
            if st.weight_gravity is None
            else self.q(st.weight_gravity, "weight_gravity", "station.weight_gravity")
        )
        self.gravity = gravity
        ref_length = (
            None
            if st.reference_length is None
            else self.q(st.reference_length, "reference_length", "station.reference_length")
        )
        orbit = self.orbit()

        n_masses = sum(len(b.mass) for b in doc.body) + sum(len(b.mass) for b in doc.beam)
        if n_masses > MAX_COUNTS["mass"]:
            raise self.error(
                "",
                f"{n_masses} point masses, more than the limit of {MAX_COUNTS['mass']:,}",
                "merge point masses (limits: docs/model-format.md)",
            )
        self.check_names()
        # components: name -> ("body" | "beam", index)
        self.kind: dict[str, tuple[str, int]] = {}
        for i, b in enumerate(doc.body):
            self.kind[b.name] = ("body", i)
        for i, bm in enumerate(doc.beam):
            self.kind[bm.name] = ("beam", i)

        # beam scalars and raw geometry, in file order
        geo = [self.beam_geometry(i, b) for i, b in enumerate(doc.beam)]
        self.check_parents()
        order = self.tree_order()

        # place components parent-first, snapping attach points onto parent axes
        beams: dict[str, Beam] = {}
        bodies: dict[str, RigidBody] = {}
        for kind, i in order:
            if kind == "beam":
                raw = doc.beam[i]
                g = geo[i]
                root = g["root"]
                if raw.parent in beams:
                    root = self.on_beam(beams[raw.parent], root, None, f"beam[{i}].root")[1]
                beam = Beam(
                    name=raw.name,
                    parent=raw.parent,
                    root=root,
                    direction=g["direction"],
                    length=g["length"],
                    orientation=g["orientation"],
                    ei_y=g["ei_y"],
                    ei_z=g["ei_z"],
                    gj=g["gj"],
                    ea=g["ea"],
                    mass_per_length=g["mass_per_length"],
                )
                masses = tuple(
                    self.beam_mass(f"beam[{i}].mass[{j}]", m, beam) for j, m in enumerate(raw.mass)
                )
                beams[raw.name] = dataclasses.replace(beam, masses=masses)
            else:
                raw_b = doc.body[i]
                attach = None
                if i > 0:
                    assert raw_b.parent is not None and raw_b.at is not None
                    at = self.vec(raw_b.at, f"body[{i}].at")
                    attach = self.on_beam(beams[raw_b.parent], at, None, f"body[{i}].at")[1]
                masses = tuple(
                    self.body_mass(f"body[{i}].mass[{j}]", m) for j, m in enumerate(raw_b.mass)
                )
                bodies[raw_b.name] = RigidBody(
                    name=raw_b.name, masses=masses, parent=raw_b.parent, attach=attach
                )

        beam_list = tuple(beams[doc.beam[i].name] for k, i in order if k == "beam")
        body_list = tuple(bodies[doc.body[i].name] for k, i in order if k == "body")
        points = tuple(self.point(i, p, beams) for i, p in enumerate(doc.point))

        total = sum(pm.mass for b in body_list for pm in b.masses)
        total += sum(pm.mass for b in beam_list for pm in b.masses)
        total += sum(b.mass_per_length * b.length for b in beam_list)
        if not total > 0.0:
            raise self.error(
                "station",
                "the station has no mass (no point masses and every mass_per_length is 0)",
                "give the bodies point masses or the beams a mass_per_length",
            )
        if ref_length is None:
            ref_length = max((b.length for b in beam_list), default=1.0)

        return Station(
            name=st.name,
            bodies=body_list,
            beams=beam_list,
            points=points,
            orbit=orbit,
            reference_length=ref_length,
            description=st.description,
            source=self.source,
            unit_system=st.units or None,
        )

    def orbit(self) -> Orbit:
        """The orbit from exactly one of radius or altitude (m), with ``mu`` (m^3/s^2) if given."""
        o = self.doc.orbit
        if (o.radius is None) == (o.altitude is None):
            what = (
                "both radius and altitude given"
                if o.radius is not None
                else "no radius or altitude"
            )
            raise self.error(
                "orbit",
                f"{what}",
                'give exactly one of radius = "6878 km" or altitude = "500 km"',
            )
        if o.radius is not None:
            radius = self.q(o.radius, "orbit_radius", "orbit.radius")
        else:
            assert o.altitude is not None
            radius = EARTH_RADIUS + self.q(o.altitude, "altitude", "orbit.altitude")
        if o.mu is None:
            return Orbit(radius=radius)
        mu = self.q(o.mu, "mu", "orbit.mu")
        return Orbit(radius=radius, mu=mu)

    def check_names(self) -> None:
        """Check that component, point and per-component mass names are unique."""
        doc = self.doc
        seen: dict[str, str] = {}
        comps = [(f"body[{i}].name", b.name) for i, b in enumerate(doc.body)]
        comps += [(f"beam[{i}].name", b.name) for i, b in enumerate(doc.beam)]
        for path, name in comps:
            if name in seen:
                raise self.error(
                    path,
                    f"duplicate component name {name!r} (also {seen[name]})",
                    "give every body and beam its own name",
                )
            seen[name] = path
        seen = {}
        for i, p in enumerate(doc.point):
            if p.name in seen:
                raise self.error(
                    f"point[{i}].name",
                    f"duplicate point name {p.name!r} (also {seen[p.name]})",
                    "give every point its own name",
                )
            seen[p.name] = f"point[{i}].name"
        groups: tuple[tuple[str, Sequence[BodyIn | BeamIn]], ...] = (
            ("body", doc.body),
            ("beam", doc.beam),
        )
        for kind, comps_ in groups:
            for i, c in enumerate(comps_):
                seen = {}
                for j, m in enumerate(c.mass):
                    path = f"{kind}[{i}].mass[{j}].name"
                    if m.name in seen:
                        raise self.error(
                            path,
                            f"duplicate mass name {m.name!r} on {kind} {c.name!r} "
                            f"(also {seen[m.name]})",
                            f"give every point mass of {c.name!r} its own name",
                        )
                    seen[m.name] = path

    def beam_geometry(self, i: int, b: BeamIn) -> dict[str, Any]:
        """SI geometry, stiffness (N m^2, N) and mass per length (kg/m) of beam ``i``."""
        p = f"beam[{i}]"
        root = self.vec(b.root, f"{p}.root")
        direction = np.asarray(b.direction, float)
        length = self.q(b.length, "beam_length", f"{p}.length")
        if b.orientation is None:
            axis = int(np.argmin(np.abs(direction)))
            o = np.zeros(3)
            o[axis] = 1.0
        else:
            o = np.asarray(b.orientation, float)
        perp = o - np.dot(o, direction) * direction
        if np.linalg.norm(perp) <= 1e-6:
            raise self.error(
                f"{p}.orientation",
                "is parallel to direction",
                "give a vector of the beam's local y axis, perpendicular to direction",
            )
        perp /= np.linalg.norm(perp)
        perp -= np.dot(perp, direction) * direction  # second pass: perpendicular to rounding
        orientation = perp / np.linalg.norm(perp)

        if b.ei is not None:
            for key in ("ei_y", "ei_z"):
                if getattr(b, key) is not None:
                    raise self.error(
                        f"{p}.{key}",
                        "given together with ei",
                        "give either ei (same about both axes) or ei_y and ei_z",
                    )
            ei_y = ei_z = self.q(b.ei, "bending_stiffness", f"{p}.ei")
        else:
            for key in ("ei_y", "ei_z"):
                if getattr(b, key) is None:
                    raise self.error(
                        f"{p}.{key}" if (b.ei_y, b.ei_z) != (None, None) else f"{p}.ei",
                        "required key is missing",
                        'add ei = "1e9 N*m^2", or both ei_y and ei_z',
                    )
            assert b.ei_y is not None and b.ei_z is not None
            ei_y = self.q(b.ei_y, "bending_stiffness", f"{p}.ei_y")
            ei_z = self.q(b.ei_z, "bending_stiffness", f"{p}.ei_z")
        gj = self.q(b.gj, "torsional_stiffness", f"{p}.gj")
        ea = None if b.ea is None else self.q(b.ea, "axial_stiffness", f"{p}.ea")
        if (b.mass_per_length is None) == (b.weight_per_length is None):
            raise self.error(
                f"{p}.mass_per_length" if b.mass_per_length is not None else p,
                "both mass_per_length and weight_per_length given"
                if b.mass_per_length is not None
                else "no mass_per_length or weight_per_length",
                'give exactly one of mass_per_length = "50 kg/m" or weight_per_length = "9 lbf/ft"',
            )
        if b.mass_per_length is not None:
            mpl = self.q(b.mass_per_length, "mass_per_length", f"{p}.mass_per_length")
        else:
            assert b.weight_per_length is not None
            wpl = self.q(b.weight_per_length, "weight_per_length", f"{p}.weight_per_length")
            mpl = self.within(
                wpl / self.gravity,
                b.weight_per_length,
                FIELD_LIMITS["mass_per_length"],
                f"{p}.weight_per_length",
            )
        return {
            "root": root,
            "direction": direction,
            "length": length,
            "orientation": orientation,
            "ei_y": ei_y,
            "ei_z": ei_z,
            "gj": gj,
            "ea": ea,
            "mass_per_length": mpl,
        }

    def check_parents(self) -> None:
        """Check the attachments: the root first, bodies on beams with ``at``, parents known."""
        doc = self.doc
        known = ", ".join(self.kind)
        b0 = doc.body[0]
        if b0.parent is not None:
            raise self.error(
                "body[0].parent",
                f"the first body ({b0.name!r}) is the root and cannot have a parent",
                "remove parent, or put the root body first",
            )
        if b0.at is not None:
            raise self.error(
                "body[0].at",
                f"the first body ({b0.name!r}) is the root and has no attach point",
                "remove at, or put the root body first",
            )
        for i, b in enumerate(doc.body[1:], start=1):
            if b.parent is None:
                raise self.error(
                    f"body[{i}].parent",
                    f"body {b.name!r} is not the root (the first body) and has no parent",
                    'give the beam it rides on, e.g. parent = "keel", and its attach point at',
                )
            kind = self.kind.get(b.parent)
            if kind is None:
                raise self.error(
                    f"body[{i}].parent",
                    f"no beam named {b.parent!r}",
                    f"name one of the beams ({', '.join(x.name for x in doc.beam) or 'none'})",
                )
            if kind[0] != "beam":
                raise self.error(
                    f"body[{i}].parent",
                    f"{b.parent!r} is a body; a body rides on a beam",
                    "give a beam as parent",
                )
            if b.at is None:
                raise self.error(
                    f"body[{i}].at",
                    "required key is missing",
                    f"add the point where it joins beam {b.parent!r}, e.g. {EXAMPLES['at']}",
                )
        for i, bm in enumerate(doc.beam):
            if bm.parent not in self.kind:
                raise self.error(
                    f"beam[{i}].parent",
                    f"no body or beam named {bm.parent!r}",
                    f"name one of: {known}",
                )

    def tree_order(self) -> list[tuple[str, int]]:
        """Components parent-first (stable in file order); a cycle is an error."""
        doc = self.doc
        parent: dict[str, str | None] = {b.name: b.parent for b in doc.body}
        parent.update({b.name: b.parent for b in doc.beam})
        names = [b.name for b in doc.body] + [b.name for b in doc.beam]
        placed = {doc.body[0].name}
        order = [("body", 0)]
        progress = True
        while progress:
            progress = False
            for name in names:
                if name not in placed and parent[name] in placed:
                    placed.add(name)
                    order.append(self.kind[name])
                    progress = True
        left = [n for n in names if n not in placed]
        if left:
            # follow parents from the first unplaced component until a name repeats
            chain = [left[0]]
            while (nxt := parent[chain[-1]]) not in chain:
                assert nxt is not None
                chain.append(nxt)
            cycle = chain[chain.index(nxt) :] + [nxt]
            kind, i = self.kind[nxt]
            what = (
                f"{kind} {nxt!r} is attached to itself"
                if len(cycle) == 2
                else "cycle of attachments: " + " -> ".join(cycle)
            )
            raise self.error(
                f"{kind}[{i}].parent",
                what,
                "every component must hang, through its parents, from the root body "
                f"{doc.body[0].name!r}",
            )
        return order

    def on_beam(
        self, beam: Beam, at: np.ndarray | None, s: float | None, path: str
    ) -> tuple[float, np.ndarray]:
        """Arc length and snapped position of a point given by ``at`` or ``s`` on ``beam``."""
        tol = ON_AXIS_TOL * beam.length
        if at is not None:
            s = beam.arc_length(at)
            off = float(np.linalg.norm(at - beam.station_position(s)))
            if off > tol:
                raise self.error(
                    path,
                    f"is {off:.6g} m off the axis of beam {beam.name!r}",
                    f"put it on the axis, root {_fmt_vec(beam.root)} m, direction "
                    f"{_fmt_vec(beam.direction)}, or give s (arc length) instead",
                )
        assert s is not None
        if s < -tol or s > beam.length + tol:
            raise self.error(
                path,
                f"lies at s = {s:.6g} m, outside beam {beam.name!r} (0 to {beam.length:.6g} m)",
                "put it between the root and the tip of the beam",
            )
        s = min(max(s, 0.0), beam.length)
        return s, beam.station_position(s)

    def mass_value(self, path: str, m: MassIn, inertia: np.ndarray) -> float:
        """Mass of a point mass, kg: > 0, or 0 for a pure rotary inertia."""
        if (m.mass is None) == (m.weight is None):
            what = "both mass and weight given" if m.mass is not None else "no mass or weight"
            raise self.error(
                f"{path}.mass" if m.mass is not None else path,
                what,
                'give exactly one of mass = "100 kg" or weight = "220 lbf"',
            )
        key = "mass" if m.mass is not None else "weight"
        raw = m.mass if m.mass is not None else m.weight
        assert raw is not None
        value = self.q(raw, key, f"{path}.{key}")
        if value > 0.0 or (value == 0.0 and np.any(inertia != 0.0)):
            if key == "mass":
                return value
            return self.within(value / self.gravity, raw, FIELD_LIMITS["mass"], f"{path}.{key}")
        raise self.error(
            f"{path}.{key}",
            f"{raw!r} must be positive" + ("" if value < 0.0 else " (or carry an inertia)"),
            "give a value > 0; zero only for a pure rotary inertia with an inertia table",
        )

    def inertia(self, path: str, raw: InertiaIn | None) -> np.ndarray:
        """The inertia tensor (3, 3), kg m^2, positive semidefinite (zeros when none is given)."""
        if raw is None:
            return np.zeros((3, 3))
        p = f"{path}.inertia"

        def get(key: str, kind: str) -> float:
            v = getattr(raw, key)
            return 0.0 if v is None else self.q(v, kind, f"{p}.{key}")

        xx, yy, zz = (get(k, "inertia_moment") for k in ("xx", "yy", "zz"))
        xy, xz, yz = (get(k, "inertia_product") for k in ("xy", "xz", "yz"))
        out = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        lam = np.linalg.eigvalsh(out)
        if lam[0] < -1e-9 * max(float(np.trace(out)), np.finfo(float).tiny):
            raise self.error(
                p,
                f"is not positive semidefinite (principal moments {_fmt_vec(lam)})",
                "check the products of inertia: xy, xz, yz are tensor entries (minus the "
                "products of inertia) and must be small beside the moments",
            )
        return out

    def movable(
        self,
        path: str,
        raw: Sequence[str | float] | None,
        coord: float,
        span: tuple[float, float] | None,
    ) -> tuple[float, float] | None:
        """The movable range ``(lo, hi)``, m, holding ``coord`` and within ``span``."""
        if raw is None:
            return None
        p = f"{path}.movable"
        lo = self.q(raw[0], "position", f"{p}[0]")
        hi = self.q(raw[1], "position", f"{p}[1]")
        if lo > hi:
            raise self.error(p, f"lo {lo:.6g} m > hi {hi:.6g} m", "write the range as [lo, hi]")
        if span is not None:
            tol = ON_AXIS_TOL * (span[1] - span[0])
            if lo < span[0] - tol or hi > span[1] + tol:
                raise self.error(
                    p,
                    f"[{lo:.6g}, {hi:.6g}] m leaves the beam (0 to {span[1]:.6g} m)",
                    "keep the range within the beam's length",
                )
            lo, hi = max(lo, span[0]), min(hi, span[1])
        # the position may come from a projection (at = [x, y, z]): allow its round-off
        slack = (
            ON_AXIS_TOL * (span[1] - span[0])
            if span is not None
            else 1e-12 * max(abs(lo), abs(hi), abs(coord))
        )
        if not lo - slack <= coord <= hi + slack:
            raise self.error(
                p,
                f"[{lo:.6g}, {hi:.6g}] m does not contain the mass's position {coord:.6g} m",
                "widen the range or move the mass into it",
            )
        return (lo, hi)

    def body_mass(self, path: str, m: BodyMassIn) -> PointMass:
        """A point mass on a body: mass (kg), position (m), inertia (kg m^2), movable range."""
        inertia = self.inertia(path, m.inertia)
        mass = self.mass_value(path, m, inertia)
        pos = self.vec(m.at, f"{path}.at")
        return PointMass(
            name=m.name,
            mass=mass,
            position=pos,
            inertia=inertia,
            source=m.source,
            fitted=m.fitted,
            movable=self.movable(path, m.movable, float(pos[2]), None),
        )

    def beam_mass(self, path: str, m: BeamMassIn, beam: Beam) -> PointMass:
        """A point mass on ``beam`` at arc length ``s`` or at ``at`` (m), snapped to its axis."""
        if (m.s is None) == (m.at is None):
            raise self.error(
                path,
                "both s and at given" if m.s is not None else "no position (s or at)",
                'give exactly one of s = "10 m" (arc length from the root) or at = [x, y, z]',
            )
        inertia = self.inertia(path, m.inertia)
        mass = self.mass_value(path, m, inertia)
        if m.s is not None:
            s, pos = self.on_beam(beam, None, self.q(m.s, "position", f"{path}.s"), f"{path}.s")
        else:
            assert m.at is not None
            s, pos = self.on_beam(beam, self.vec(m.at, f"{path}.at"), None, f"{path}.at")
        return PointMass(
            name=m.name,
            mass=mass,
            position=pos,
            inertia=inertia,
            source=m.source,
            fitted=m.fitted,
            movable=self.movable(path, m.movable, s, (0.0, beam.length)),
        )

    def point(self, i: int, p: PointIn, beams: dict[str, Beam]) -> NamedPoint:
        """Named point ``i`` at its position (m), on a body or snapped to its beam's axis."""
        path = f"point[{i}]"
        kind = self.kind.get(p.on)
        if kind is None:
            raise self.error(
                f"{path}.on",
                f"no body or beam named {p.on!r}",
                f"name one of: {', '.join(self.kind)}",
            )
        if kind[0] == "body":
            if p.s is not None:
                raise self.error(
                    f"{path}.s",
                    f"s (arc length) is for points on beams; {p.on!r} is a body",
                    "give its station-frame position at = [x, y, z] instead",
                )
            if p.at is None:
                raise self.error(f"{path}.at", "required key is missing", f"add {EXAMPLES['at']}")
            pos = self.vec(p.at, f"{path}.at")
        else:
            beam = beams[p.on]
            if (p.s is None) == (p.at is None):
                raise self.error(
                    path,
                    "both s and at given" if p.s is not None else "no position (s or at)",
                    'give exactly one of s = "10 m" (arc length from the root) or at = [x, y, z]',
                )
            if p.s is not None:
                pos = self.on_beam(beam, None, self.q(p.s, "position", f"{path}.s"), f"{path}.s")[1]
            else:
                assert p.at is not None
                at = self.vec(p.at, f"{path}.at")
                pos = self.on_beam(beam, at, None, f"{path}.at")[1]
        return NamedPoint(
            name=p.name, on=p.on, position=pos, kind=p.kind, description=p.description
        )


def _fmt_vec(v: np.ndarray) -> str:
    return "[" + ", ".join(f"{x:.6g}" for x in v) + "]"
