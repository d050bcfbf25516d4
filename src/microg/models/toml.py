"""Station model files: a TOML file (or a shipped model name) -> ``Station``.

The format is specified in ``docs/model-format.md``.  Reading goes in three steps:

1. :mod:`tomllib` parses the text (a syntax error names the file and line);
2. pydantic models check the structure: known keys only, required keys present, the
   right kind of value for each key;
3. a builder converts every quantity to SI with :func:`microg.units.parse_quantity`
   (dimension-checked) and checks the physics and the tree: signs, parents, cycles,
   points on their carriers, unique names.

Every error is a :class:`~microg.errors.ModelError` whose text is one line,
``FILE: field.path: what is wrong (how to fix)``.

:func:`dump_station` writes a station back as TOML in SI units, such that
``loads_station(dump_station(st))`` reproduces ``st``.
"""

from __future__ import annotations

import dataclasses
import math
import re
import tomllib
import types
import typing
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PlainValidator,
    StrictBool,
    StrictStr,
    ValidationError,
)
from pydantic_core import PydanticCustomError

from microg.errors import InputError, ModelError
from microg.models.station import Beam, NamedPoint, Orbit, PointMass, RigidBody, Station
from microg.units import DIMENSIONS, G0, parse_quantity

__all__ = [
    "EARTH_RADIUS",
    "ON_AXIS_TOL",
    "UNIT_SYSTEMS",
    "dump_station",
    "load_station",
    "loads_station",
    "shipped_models",
]

#: Earth's equatorial radius (WGS 84), m: ``[orbit] altitude`` is measured from it
EARTH_RADIUS = 6_378_137.0

#: a point is "on" a beam when its distance from the axis and its overshoot beyond the ends
#: are at most this fraction of the beam's length
ON_AXIS_TOL = 1e-6

#: unit of a bare number for each dimension, by ``[station] units``
UNIT_SYSTEMS: dict[str, dict[str, str]] = {
    "SI": dict(DIMENSIONS),
    "US": {
        "length": "ft",
        "mass": "slug",
        "force": "lbf",
        "time": "s",
        "frequency": "Hz",
        "angular_frequency": "rad/s",
        "stiffness": "lbf/ft",
        "bending_stiffness": "lbf*ft^2",
        "torsional_stiffness": "lbf*ft^2",
        "axial_stiffness": "lbf",
        "mass_per_length": "slug/ft",
        "rotary_inertia": "slug*ft^2",
        "acceleration": "ft/s^2",
        "dimensionless": "",
        "damping": "lbf*s/ft",
        "gravitational_parameter": "ft^3/s^2",
        "force_per_length": "lbf/ft",
    },
}

_DATA_PACKAGE = "microg"
_DATA_DIR = "data"


# --------------------------------------------------------------------------------------
# Step 2: structure (pydantic).  Values stay raw; units are converted in step 3.
# --------------------------------------------------------------------------------------


def _fail(kind: str, what: str, fix: str, value: Any) -> PydanticCustomError:
    """A structure error whose message is ``what`` and whose ``ctx["fix"]`` says how to fix."""
    return PydanticCustomError(kind, what + ", got {v}", {"v": _short(value), "fix": fix})


_Q_FIX = 'write a number and a unit in quotes, e.g. "10 m"'


def _quantity_input(value: Any) -> str | float:
    """A quantity as written: a string with a unit, or a number (needs a unit system)."""
    if isinstance(value, str):
        return value
    if isinstance(value, int | float) and not isinstance(value, bool):
        if not math.isfinite(value):
            raise _fail("not_finite", "expected a finite value", "give a finite number", value)
        return value
    raise _fail("quantity", "expected a number with a unit", _Q_FIX, value)


_AXES = {"x": 0, "y": 1, "z": 2}
_DIR_FIX = 'write an axis such as "+z" or "-x", or three numbers such as [0, 0, 1]'


def _direction_input(value: Any) -> tuple[float, float, float]:
    """A unit-less vector ``[x, y, z]`` or an axis name ``"x"``, ``"+y"``, ``"-z"``."""
    if isinstance(value, str):
        text = value.strip().lower()
        sign = -1.0 if text.startswith("-") else 1.0
        axis = text.lstrip("+-")
        if axis in _AXES and len(text) - len(axis) <= 1:
            out = [0.0, 0.0, 0.0]
            out[_AXES[axis]] = sign
            return (out[0], out[1], out[2])
        raise _fail("direction", "expected an axis or a vector [x, y, z]", _DIR_FIX, value)
    if isinstance(value, list) and len(value) == 3:
        for c in value:
            if isinstance(c, bool) or not isinstance(c, int | float) or not math.isfinite(c):
                raise _fail(
                    "direction", "expected three plain finite numbers [x, y, z]", _DIR_FIX, value
                )
        return (float(value[0]), float(value[1]), float(value[2]))
    raise _fail("direction", "expected an axis or a vector [x, y, z]", _DIR_FIX, value)


def _vector_input(value: Any) -> list[str | float]:
    if not isinstance(value, list) or len(value) != 3:
        raise _fail(
            "vector",
            "expected a position [x, y, z] of three lengths",
            'write e.g. ["0 m", "0 m", "5 m"]',
            value,
        )
    return [_quantity_input(c) for c in value]


def _range_input(value: Any) -> list[str | float]:
    if not isinstance(value, list) or len(value) != 2:
        raise _fail(
            "range",
            "expected a range [lo, hi] of two lengths",
            'write e.g. ["10 m", "70 m"]',
            value,
        )
    return [_quantity_input(c) for c in value]


_Q = Annotated[str | float, PlainValidator(_quantity_input)]
_Vec = Annotated[list[str | float], PlainValidator(_vector_input)]
_Range = Annotated[list[str | float], PlainValidator(_range_input)]
_Dir = Annotated[tuple[float, float, float], PlainValidator(_direction_input)]
_Name = Annotated[StrictStr, Field(min_length=1)]


class _In(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _StationIn(_In):
    name: _Name
    description: StrictStr = ""
    units: Literal["SI", "US"] | None = None
    weight_gravity: _Q | None = None
    reference_length: _Q | None = None


class _OrbitIn(_In):
    radius: _Q | None = None
    altitude: _Q | None = None
    mu: _Q | None = None


class _InertiaIn(_In):
    xx: _Q | None = None
    yy: _Q | None = None
    zz: _Q | None = None
    xy: _Q | None = None
    xz: _Q | None = None
    yz: _Q | None = None


class _MassIn(_In):
    name: _Name
    mass: _Q | None = None
    weight: _Q | None = None
    inertia: _InertiaIn | None = None
    source: StrictStr = ""
    fitted: StrictBool = False
    movable: _Range | None = None


class _BodyMassIn(_MassIn):
    at: _Vec


class _BeamMassIn(_MassIn):
    s: _Q | None = None
    at: _Vec | None = None


class _BodyIn(_In):
    name: _Name
    parent: _Name | None = None
    at: _Vec | None = None
    mass: list[_BodyMassIn] = []


class _BeamIn(_In):
    name: _Name
    parent: _Name
    root: _Vec
    direction: _Dir
    length: _Q
    orientation: _Dir | None = None
    ei: _Q | None = None
    ei_y: _Q | None = None
    ei_z: _Q | None = None
    gj: _Q
    ea: _Q | None = None
    mass_per_length: _Q | None = None
    weight_per_length: _Q | None = None
    mass: list[_BeamMassIn] = []


class _PointIn(_In):
    name: _Name
    on: _Name
    at: _Vec | None = None
    s: _Q | None = None
    kind: Literal["crew", "experiment", "point"] = "point"
    description: StrictStr = ""


class _FileIn(_In):
    station: _StationIn
    orbit: _OrbitIn
    body: Annotated[list[_BodyIn], Field(min_length=1)]
    beam: list[_BeamIn] = []
    point: list[_PointIn] = []


#: example values for "add it" hints, by key
_EXAMPLES: dict[str, str] = {
    "station": '[station] with name = "my station"',
    "orbit": '[orbit] with altitude = "500 km"',
    "body": '[[body]] with name = "core" (the root body)',
    "name": 'name = "keel"',
    "parent": 'parent = "core"',
    "root": 'root = ["0 m", "0 m", "0 m"]',
    "direction": 'direction = "+z" or [0, 0, 1]',
    "length": 'length = "90 m"',
    "gj": 'gj = "1e9 N*m^2"',
    "mass_per_length": 'mass_per_length = "50 kg/m"',
    "at": 'at = ["0 m", "0 m", "-5 m"]',
    "on": 'on = "core"',
}


def _toml_repr(value: Any) -> str:
    """``value`` written as in a TOML file (for messages)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return _tstr(value)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_repr(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_repr(v)}" for k, v in value.items()) + " }"
    return str(value)


def _short(value: Any, limit: int = 60) -> str:
    text = _toml_repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _loc_path(loc: Sequence[str | int]) -> str:
    out = ""
    for el in loc:
        if isinstance(el, int):
            out += f"[{el}]"
        else:
            out += f".{el}" if out else str(el)
    return out


def _model_of(annotation: Any) -> type[BaseModel] | None:
    """The pydantic model inside ``annotation`` (through Annotated, Optional, list)."""
    for _ in range(8):
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            return annotation
        origin = typing.get_origin(annotation)
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if origin is None or not args:
            return None
        if origin in (typing.Union, types.UnionType):
            models = [m for m in (_model_of(a) for a in args) if m is not None]
            return models[0] if models else None
        annotation = args[0]
    return None


def _model_at(loc: Sequence[str | int]) -> type[BaseModel] | None:
    model: type[BaseModel] | None = _FileIn
    for el in loc:
        if isinstance(el, int):
            continue
        if model is None or el not in model.model_fields:
            return None
        model = _model_of(model.model_fields[el].annotation)
    return model


def _structure_error(exc: ValidationError, file: str) -> ModelError:
    """The first error of a pydantic ValidationError as a one-line ModelError."""
    errors = exc.errors(include_url=False)
    # a misspelt key also makes the right one "missing": report the misspelling
    err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = tuple(err["loc"])
    path = _loc_path(loc)
    where = f"{file}: {path}" if path else file
    kind = err["type"]
    key = loc[-1] if loc else ""
    if kind == "missing":
        example = _EXAMPLES.get(str(key))
        fix = f"add it, e.g. {example}" if example else "add it"
        what = (
            "required table is missing"
            if key in ("station", "orbit")
            else "required key is missing"
        )
        if key == "body":
            what = "the model has no [[body]]: it needs at least the root body"
        return ModelError(what, where=where, fix=fix)
    if kind == "extra_forbidden":
        parent = _model_at(loc[:-1])
        allowed = ", ".join(parent.model_fields) if parent is not None else ""
        fix = f"allowed keys here: {allowed}" if allowed else "remove it"
        return ModelError("unknown key", where=where, fix=f"check its spelling; {fix}")
    if kind == "too_short" and key == "body":
        return ModelError(
            "the model has no [[body]]: it needs at least the root body",
            where=where,
            fix=f"add {_EXAMPLES['body']}",
        )
    header = ".".join(str(x) for x in loc if isinstance(x, str))  # beam.mass for beam[0].mass
    if kind in ("model_type", "dict_type"):
        if loc and isinstance(loc[-1], int):
            fix = f"write each item as a [[{header}]] table"
        elif len(loc) == 1:
            fix = f"write it as a [{header}] table"
        else:
            fix = f'write it as an inline table, e.g. {key} = {{ xx = "1 kg*m^2", ... }}'
        return ModelError(f"expected a table, got {_short(err.get('input'))}", where=where, fix=fix)
    if kind == "list_type":
        return ModelError(
            f"expected an array of tables, got {_short(err.get('input'))}",
            where=where,
            fix=f"write each item as a [[{header}]] table",
        )
    simple = {
        "string_type": ("expected a string", f'write it in double quotes, e.g. {key} = "text"'),
        "bool_type": ("expected true or false", "write true or false, without quotes"),
        "literal_error": (
            err["msg"].replace("Input should be", "expected"),
            "use one of the listed values; case matters",
        ),
        "string_too_short": ("expected a non-empty string", "give a name"),
    }
    if kind in simple:
        what, fix = simple[kind]
        return ModelError(f"{what}, got {_short(err.get('input'))}", where=where, fix=fix)
    # our own validators (quantity, vector, direction, range) carry a message and a fix
    ctx = err.get("ctx") or {}
    return ModelError(" ".join(str(err["msg"]).split()), where=where, fix=ctx.get("fix"))


# --------------------------------------------------------------------------------------
# Step 3: units, physics and the tree.
# --------------------------------------------------------------------------------------


class _Builder:
    """Converts a structurally valid file to a Station, checking as it goes."""

    def __init__(self, doc: _FileIn, file: str, source: str):
        self.doc = doc
        self.file = file
        self.source = source
        self.units = UNIT_SYSTEMS[doc.station.units] if doc.station.units else None

    # ----- helpers
    def error(self, path: str, what: str, fix: str | None = None) -> ModelError:
        return ModelError(what, where=f"{self.file}: {path}" if path else self.file, fix=fix)

    def q(
        self,
        value: str | float,
        dimension: str,
        path: str,
        *,
        sign: Literal["any", "positive", "nonnegative"] = "any",
    ) -> float:
        """Parse a quantity to SI, dimension- and sign-checked."""
        default = self.units[dimension] if self.units else None
        if default is None and not isinstance(value, str) and value == 0.0:
            default = DIMENSIONS[dimension]  # zero is zero in every unit
        try:
            out = parse_quantity(
                value, dimension, where=f"{self.file}: {path}", default_unit=default
            )
        except InputError as exc:
            nice = dimension.replace("_", " ")
            article = "an" if nice[0] in "aeiou" else "a"
            what = exc.what.replace(f"a {dimension}", f"{article} {nice}")
            fix = exc.fix.replace(f"of {dimension}", f"of {nice}") if exc.fix else None
            if "has no unit" in what:
                fix = (
                    f"write it with a unit, e.g. '{value} {DIMENSIONS[dimension]}', "
                    'or declare units = "SI" or "US" in [station]'
                )
            raise ModelError(what, where=exc.where, fix=fix) from None
        if not math.isfinite(out):
            raise self.error(path, f"{value!r} is not finite", "give a finite value")
        if sign == "positive" and not out > 0.0:
            raise self.error(path, f"{value!r} must be positive", "give a value > 0")
        if sign == "nonnegative" and not out >= 0.0:
            raise self.error(path, f"{value!r} must not be negative", "give a value >= 0")
        return out

    def vec(self, value: Sequence[str | float], path: str) -> np.ndarray:
        return np.array([self.q(c, "length", f"{path}[{i}]") for i, c in enumerate(value)])

    def unit_vector(self, value: tuple[float, float, float], path: str) -> np.ndarray:
        v = np.asarray(value, float)
        n = float(np.linalg.norm(v))
        if not n > 0.0:
            raise self.error(path, "is the zero vector", "give a non-zero vector, e.g. [0, 0, 1]")
        return v / n

    # ----- the whole file
    def build(self) -> Station:
        doc = self.doc
        st = doc.station
        gravity = (
            G0
            if st.weight_gravity is None
            else self.q(
                st.weight_gravity, "acceleration", "station.weight_gravity", sign="positive"
            )
        )
        self.gravity = gravity
        ref_length = (
            None
            if st.reference_length is None
            else self.q(st.reference_length, "length", "station.reference_length", sign="positive")
        )
        orbit = self.orbit()

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
        )

    def orbit(self) -> Orbit:
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
            radius = self.q(o.radius, "length", "orbit.radius", sign="positive")
        else:
            assert o.altitude is not None
            radius = EARTH_RADIUS + self.q(o.altitude, "length", "orbit.altitude", sign="positive")
        if o.mu is None:
            return Orbit(radius=radius)
        mu = self.q(o.mu, "gravitational_parameter", "orbit.mu", sign="positive")
        return Orbit(radius=radius, mu=mu)

    def check_names(self) -> None:
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
        groups: tuple[tuple[str, Sequence[_BodyIn | _BeamIn]], ...] = (
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

    def beam_geometry(self, i: int, b: _BeamIn) -> dict[str, Any]:
        p = f"beam[{i}]"
        root = self.vec(b.root, f"{p}.root")
        direction = self.unit_vector(b.direction, f"{p}.direction")
        length = self.q(b.length, "length", f"{p}.length", sign="positive")
        if b.orientation is None:
            axis = int(np.argmin(np.abs(direction)))
            o = np.zeros(3)
            o[axis] = 1.0
        else:
            o = self.unit_vector(b.orientation, f"{p}.orientation")
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
            ei_y = ei_z = self.q(b.ei, "bending_stiffness", f"{p}.ei", sign="positive")
        else:
            for key in ("ei_y", "ei_z"):
                if getattr(b, key) is None:
                    raise self.error(
                        f"{p}.{key}" if (b.ei_y, b.ei_z) != (None, None) else f"{p}.ei",
                        "required key is missing",
                        'add ei = "1e9 N*m^2", or both ei_y and ei_z',
                    )
            assert b.ei_y is not None and b.ei_z is not None
            ei_y = self.q(b.ei_y, "bending_stiffness", f"{p}.ei_y", sign="positive")
            ei_z = self.q(b.ei_z, "bending_stiffness", f"{p}.ei_z", sign="positive")
        gj = self.q(b.gj, "torsional_stiffness", f"{p}.gj", sign="nonnegative")
        ea = None if b.ea is None else self.q(b.ea, "axial_stiffness", f"{p}.ea", sign="positive")
        if (b.mass_per_length is None) == (b.weight_per_length is None):
            raise self.error(
                f"{p}.mass_per_length" if b.mass_per_length is not None else p,
                "both mass_per_length and weight_per_length given"
                if b.mass_per_length is not None
                else "no mass_per_length or weight_per_length",
                'give exactly one of mass_per_length = "50 kg/m" or weight_per_length = "9 lbf/ft"',
            )
        if b.mass_per_length is not None:
            mpl = self.q(
                b.mass_per_length, "mass_per_length", f"{p}.mass_per_length", sign="nonnegative"
            )
        else:
            assert b.weight_per_length is not None
            wpl = self.q(
                b.weight_per_length,
                "force_per_length",
                f"{p}.weight_per_length",
                sign="nonnegative",
            )
            mpl = wpl / self.gravity
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
                    f"add the point where it joins beam {b.parent!r}, e.g. {_EXAMPLES['at']}",
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

    def mass_value(self, path: str, m: _MassIn, inertia: np.ndarray) -> float:
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
        value = self.q(raw, "mass" if key == "mass" else "force", f"{path}.{key}")
        if value > 0.0 or (value == 0.0 and np.any(inertia != 0.0)):
            return value if key == "mass" else value / self.gravity
        raise self.error(
            f"{path}.{key}",
            f"{raw!r} must be positive" + ("" if value < 0.0 else " (or carry an inertia)"),
            "give a value > 0; zero only for a pure rotary inertia with an inertia table",
        )

    def inertia(self, path: str, raw: _InertiaIn | None) -> np.ndarray:
        if raw is None:
            return np.zeros((3, 3))
        p = f"{path}.inertia"

        def get(key: str, sign: Literal["any", "nonnegative"]) -> float:
            v = getattr(raw, key)
            return 0.0 if v is None else self.q(v, "rotary_inertia", f"{p}.{key}", sign=sign)

        xx, yy, zz = (get(k, "nonnegative") for k in ("xx", "yy", "zz"))
        xy, xz, yz = (get(k, "any") for k in ("xy", "xz", "yz"))
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
        if raw is None:
            return None
        p = f"{path}.movable"
        lo = self.q(raw[0], "length", f"{p}[0]")
        hi = self.q(raw[1], "length", f"{p}[1]")
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

    def body_mass(self, path: str, m: _BodyMassIn) -> PointMass:
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

    def beam_mass(self, path: str, m: _BeamMassIn, beam: Beam) -> PointMass:
        if (m.s is None) == (m.at is None):
            raise self.error(
                path,
                "both s and at given" if m.s is not None else "no position (s or at)",
                'give exactly one of s = "10 m" (arc length from the root) or at = [x, y, z]',
            )
        inertia = self.inertia(path, m.inertia)
        mass = self.mass_value(path, m, inertia)
        if m.s is not None:
            s, pos = self.on_beam(beam, None, self.q(m.s, "length", f"{path}.s"), f"{path}.s")
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

    def point(self, i: int, p: _PointIn, beams: dict[str, Beam]) -> NamedPoint:
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
                raise self.error(f"{path}.at", "required key is missing", f"add {_EXAMPLES['at']}")
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
                pos = self.on_beam(beam, None, self.q(p.s, "length", f"{path}.s"), f"{path}.s")[1]
            else:
                assert p.at is not None
                at = self.vec(p.at, f"{path}.at")
                pos = self.on_beam(beam, at, None, f"{path}.at")[1]
        return NamedPoint(
            name=p.name, on=p.on, position=pos, kind=p.kind, description=p.description
        )


def _fmt_vec(v: np.ndarray) -> str:
    return "[" + ", ".join(f"{x:.6g}" for x in v) + "]"


# --------------------------------------------------------------------------------------
# Public API
# --------------------------------------------------------------------------------------

_TOML_POS = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")


def loads_station(text: str, *, filename: str = "<string>", source: str = "") -> Station:
    """Build a station from the text of a model file.

    Parameters
    ----------
    text : str
        TOML text in the format of ``docs/model-format.md``.
    filename : str
        Name used for the file in error messages.
    source : str
        Stored as :attr:`Station.source` (the file it was read from).

    Returns
    -------
    Station
        SI units; beams parent-first, the root body first.

    Raises
    ------
    ModelError
        One line: ``FILE: field.path: what is wrong (how to fix)``.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = _TOML_POS.search(msg)
        where = f"{filename}: line {m.group(1)}, column {m.group(2)}" if m else filename
        msg = _TOML_POS.sub("", msg)
        raise ModelError(
            f"invalid TOML: {' '.join(msg.split())}", where=where, fix="fix the TOML syntax there"
        ) from None
    try:
        doc = _FileIn.model_validate(data)
    except ValidationError as exc:
        raise _structure_error(exc, filename) from None
    return _Builder(doc, filename, source).build()


_STATION_TABLE = re.compile(r"^[ \t]*\[[ \t]*station[ \t]*\][ \t]*(#.*)?$", re.MULTILINE)


def shipped_models() -> list[str]:
    """Names of the station models shipped in ``microg/data``.

    A shipped model is a file ``microg/data/NAME.toml`` whose name does not start with
    ``_`` and which has a ``[station]`` table (other TOML data files live there too).
    """
    root = resources.files(_DATA_PACKAGE).joinpath(_DATA_DIR)
    if not root.is_dir():
        return []
    names = []
    for entry in root.iterdir():
        if entry.is_file() and entry.name.endswith(".toml") and not entry.name.startswith("_"):
            try:
                text = entry.read_text(encoding="utf-8")
            except (OSError, UnicodeDecodeError):
                continue
            if _STATION_TABLE.search(text):
                names.append(entry.name[: -len(".toml")])
    return sorted(names)


def load_station(path_or_name: str | Path) -> Station:
    """Read a station model from a TOML file or by the name of a shipped model.

    Parameters
    ----------
    path_or_name : str or Path
        A shipped model name (see :func:`shipped_models`, e.g. ``"ioc"``), or the path of a
        ``.toml`` file.  A string that is a shipped name means the shipped model even if a
        file of that name exists in the working directory (write ``./ioc`` for the file);
        a :class:`~pathlib.Path` is always a file.

    Returns
    -------
    Station
        In SI units, with :attr:`Station.source` set to the file read.

    Raises
    ------
    ModelError
        Unknown name or unreadable file, or an invalid model (one line naming file and field).
    """
    if isinstance(path_or_name, str) and path_or_name in shipped_models():
        fname = f"{path_or_name}.toml"
        res = resources.files(_DATA_PACKAGE).joinpath(_DATA_DIR).joinpath(fname)
        text = res.read_text(encoding="utf-8")
        return loads_station(text, filename=fname, source=f"microg/data/{fname}")
    path = Path(path_or_name)
    label = str(path_or_name)
    if not path.is_file():
        names = ", ".join(shipped_models()) or "none"
        what = "is a directory, not a model file" if path.is_dir() else "no such file"
        raise ModelError(
            f"{what}, and not the name of a shipped model",
            where=label,
            fix=f"give the path of a .toml model file or a shipped model: {names}",
        )
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError(
            f"not UTF-8 text (byte {exc.start})", where=label, fix="save the file as UTF-8"
        ) from None
    except OSError as exc:
        raise ModelError(
            f"cannot read: {exc.strerror or exc}", where=label, fix="check the path and permissions"
        ) from None
    return loads_station(text, filename=label, source=str(path))


# --------------------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------------------

_TOML_ESCAPES = {
    '"': '\\"',
    "\\": "\\\\",
    "\b": "\\b",
    "\t": "\\t",
    "\n": "\\n",
    "\f": "\\f",
    "\r": "\\r",
}


def _tstr(text: str) -> str:
    """A TOML basic string."""
    out = []
    for ch in text:
        if ch in _TOML_ESCAPES:
            out.append(_TOML_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _tq(value: float, unit: str) -> str:
    return _tstr(f"{float(value)!r} {unit}")


def _tvec(v: np.ndarray, unit: str | None = "m") -> str:
    if unit is None:
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"
    return "[" + ", ".join(_tq(x, unit) for x in v) + "]"


def _dump_mass(lines: list[str], table: str, pm: PointMass, beam: Beam | None) -> None:
    lines.append(f"[[{table}.mass]]")
    lines.append(f"name = {_tstr(pm.name)}")
    lines.append(f"mass = {_tq(pm.mass, 'kg')}")
    if beam is None:
        lines.append(f"at = {_tvec(pm.position)}")
    else:
        lines.append(f"s = {_tq(beam.arc_length(pm.position), 'm')}")
    if pm.source:
        lines.append(f"source = {_tstr(pm.source)}")
    if pm.fitted:
        lines.append("fitted = true")
    if pm.movable is not None:
        lines.append(f"movable = [{_tq(pm.movable[0], 'm')}, {_tq(pm.movable[1], 'm')}]")
    inertia = np.asarray(pm.inertia, float)
    if np.any(inertia != 0.0):
        keys = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
        body = ", ".join(f"{k} = {_tq(inertia[ij], 'kg*m^2')}" for k, ij in keys.items())
        lines.append(f"inertia = {{ {body} }}")


def dump_station(station: Station) -> str:
    """The TOML text of a station model, in SI units with a unit on every value.

    Parameters
    ----------
    station : Station
        Any station (beam masses are written by their arc length along the beam).

    Returns
    -------
    str
        A model file such that ``loads_station(dump_station(station))`` equals ``station``
        to rounding (about 1e-15 relative).
    """
    lines = ["# station model written by microg.models.toml.dump_station (SI units)", ""]
    lines.append("[station]")
    lines.append(f"name = {_tstr(station.name)}")
    if station.description:
        lines.append(f"description = {_tstr(station.description)}")
    lines.append(f"reference_length = {_tq(station.reference_length, 'm')}")
    lines += ["", "[orbit]"]
    lines.append(f"radius = {_tq(station.orbit.radius, 'm')}")
    lines.append(f"mu = {_tq(station.orbit.mu, 'm^3/s^2')}")
    for body in station.bodies:
        lines += ["", "[[body]]", f"name = {_tstr(body.name)}"]
        if body.parent is not None:
            lines.append(f"parent = {_tstr(body.parent)}")
        if body.attach is not None:
            lines.append(f"at = {_tvec(body.attach)}")
        for pm in body.masses:
            _dump_mass(lines, "body", pm, None)
    for beam in station.beams:
        lines += ["", "[[beam]]", f"name = {_tstr(beam.name)}", f"parent = {_tstr(beam.parent)}"]
        lines.append(f"root = {_tvec(beam.root)}")
        lines.append(f"direction = {_tvec(beam.direction, None)}")
        lines.append(f"length = {_tq(beam.length, 'm')}")
        lines.append(f"orientation = {_tvec(beam.orientation, None)}")
        lines.append(f"ei_y = {_tq(beam.ei_y, 'N*m^2')}")
        lines.append(f"ei_z = {_tq(beam.ei_z, 'N*m^2')}")
        lines.append(f"gj = {_tq(beam.gj, 'N*m^2')}")
        if beam.ea is not None:
            lines.append(f"ea = {_tq(beam.ea, 'N')}")
        lines.append(f"mass_per_length = {_tq(beam.mass_per_length, 'kg/m')}")
        for pm in beam.masses:
            _dump_mass(lines, "beam", pm, beam)
    for pt in station.points:
        lines += ["", "[[point]]", f"name = {_tstr(pt.name)}", f"on = {_tstr(pt.on)}"]
        lines.append(f"at = {_tvec(pt.position)}")
        lines.append(f"kind = {_tstr(pt.kind)}")
        if pt.description:
            lines.append(f"description = {_tstr(pt.description)}")
    return "\n".join(lines) + "\n"
