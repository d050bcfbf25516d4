"""The structure of a station model file (pydantic), its unit systems and its limits.

Step 2 of reading a model (``docs/model-format.md``): after :mod:`tomllib` has parsed the
text, :class:`FileIn` checks the structure: known keys only, required keys present, the right
kind of value for each key, at most :data:`MAX_COUNTS` entries.  Quantities stay as written
(a string with a unit, or a bare number); :mod:`microg.models.build` converts them to SI and
checks each against :data:`FIELD_LIMITS`.

Directions are read here, by the one direction parser :func:`microg._vectors.parse_direction`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, PlainValidator, StrictBool, StrictStr

from microg._vectors import DIRECTION_FIX, parse_direction
from microg.errors import InputError
from microg.models.messages import fail
from microg.units import DIMENSIONS, LIMITS

__all__ = [
    "EARTH_RADIUS",
    "FIELD_LIMITS",
    "HILL_RADIUS",
    "Limit",
    "MAX_COUNTS",
    "MAX_NAME",
    "MAX_TEXT",
    "MIN_BEAM_LENGTH",
    "MIN_MASS",
    "ON_AXIS_TOL",
    "UNIT_SYSTEMS",
    "BeamIn",
    "BeamMassIn",
    "BodyIn",
    "BodyMassIn",
    "FileIn",
    "InertiaIn",
    "MassIn",
    "OrbitIn",
    "PointIn",
    "StationIn",
    "Direction",
    "Name",
    "Position",
    "Quantity",
    "Range",
    "TableIn",
    "Text",
]

#: Earth's equatorial radius (WGS 84), m: ``[orbit] altitude`` is measured from it, and an
#: orbit radius must exceed it
EARTH_RADIUS = 6_378_137.0
#: radius of the Earth's Hill sphere, m (about 1.5 million km): beyond it the Sun, not the
#: Earth, holds an orbit, so no circular Earth orbit is larger
HILL_RADIUS = 1.5e9
#: shortest beam, m: below a millimetre a beam is not a structural member of a station
MIN_BEAM_LENGTH = 1e-3

#: a point is "on" a beam when its distance from the axis and its overshoot beyond the ends
#: are at most this fraction of the beam's length
ON_AXIS_TOL = 1e-6

#: the most entries of each kind in one model file (documented in docs/model-format.md)
MAX_COUNTS: dict[str, int] = {
    "body": 10_000,
    "beam": 10_000,
    "point": 10_000,
    "mass": 20_000,  # point masses, all carriers together
}
#: longest name, characters
MAX_NAME = 200
#: longest free text (description, source), characters
MAX_TEXT = 10_000

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


@dataclass(frozen=True)
class Limit:
    """The accepted range of one kind of field, SI.

    Attributes
    ----------
    dimension : a key of :data:`microg.units.DIMENSIONS`
    lo, hi : smallest and largest accepted values (SI unit of the dimension)
    lo_open : True when ``lo`` itself is not accepted (a strict lower bound)
    why : the reason for the bounds, for the message
    min_nonzero : smallest accepted non-zero magnitude (zero itself stays accepted)
    """

    dimension: str
    lo: float
    hi: float
    lo_open: bool = False
    why: str = ""
    min_nonzero: float = 0.0


def _lim(dimension: str, lo: float | None, lo_open: bool = False, why: str = "") -> Limit:
    hi = LIMITS[dimension]
    return Limit(dimension, -hi if lo is None else lo, hi, lo_open, why)


_MASS_WHY = "a mass is 1 mg to 1e9 kg; zero only for a pure rotary inertia"
#: smallest non-zero mass, kg, and mass per length, kg/m: below a milligram a mass is
#: round-off, not a part of a station (and subnormal values break the solvers' scaling)
MIN_MASS = 1e-6

#: accepted range of each kind of field (SI); see docs/model-format.md, "Limits"
FIELD_LIMITS: dict[str, Limit] = {
    "position": _lim("length", None),
    "beam_length": Limit(
        "length", MIN_BEAM_LENGTH, LIMITS["length"], why="a beam is 1 mm to 100 km long"
    ),
    "reference_length": Limit("length", MIN_BEAM_LENGTH, LIMITS["length"]),
    "orbit_radius": Limit(
        "length",
        EARTH_RADIUS,
        HILL_RADIUS,
        lo_open=True,
        why="above the Earth's equatorial radius 6378.137 km, within its Hill sphere 1.5e6 km",
    ),
    "altitude": Limit(
        "length",
        0.0,
        HILL_RADIUS - EARTH_RADIUS,
        lo_open=True,
        why="above the Earth's surface, within its Hill sphere 1.5e6 km",
    ),
    "mu": _lim("gravitational_parameter", 0.0, lo_open=True),
    "weight_gravity": Limit(
        "acceleration", 0.1, 100.0, why="the gravity at which weights were measured"
    ),
    "mass": Limit("mass", 0.0, LIMITS["mass"], why=_MASS_WHY, min_nonzero=MIN_MASS),
    "weight": Limit("force", 0.0, LIMITS["mass"] * 100.0, why=_MASS_WHY),
    "mass_per_length": Limit(
        "mass_per_length",
        0.0,
        LIMITS["mass_per_length"],
        why="a mass per length is 0, or 1 mg/m to 1e6 kg/m",
        min_nonzero=MIN_MASS,
    ),
    "weight_per_length": Limit("force_per_length", 0.0, LIMITS["mass_per_length"] * 100.0),
    "bending_stiffness": _lim("bending_stiffness", 0.0, lo_open=True),
    "torsional_stiffness": _lim("torsional_stiffness", 0.0),
    "axial_stiffness": _lim("axial_stiffness", 0.0, lo_open=True),
    "inertia_moment": _lim("rotary_inertia", 0.0),
    "inertia_product": _lim("rotary_inertia", None),
}


# --------------------------------------------------------------------------------- validators

_Q_FIX = 'write a number and a unit in quotes, e.g. "10 m"'


def _quantity_input(value: Any) -> str | float:
    """A quantity as written: a string with a unit, or a number (needs a unit system)."""
    if isinstance(value, str):
        return value
    if isinstance(value, int | float) and not isinstance(value, bool):
        try:
            ok = math.isfinite(value)
        except OverflowError:  # an integer beyond the float range
            ok = False
        if not ok:
            raise fail("not_finite", "expected a finite value", "give a finite number", value)
        return value
    raise fail("quantity", "expected a number with a unit", _Q_FIX, value)


def _direction_input(value: Any) -> tuple[float, float, float]:
    """A unit-less direction: an axis name or three numbers, read by :func:`parse_direction`."""
    if not isinstance(value, str | list):
        raise fail("direction", "expected an axis or a vector [x, y, z]", DIRECTION_FIX, value)
    try:
        d = parse_direction(value, "direction")
    except InputError as exc:
        if "zero vector" in exc.what:
            raise fail(
                "direction", "is the zero vector", "give a non-zero vector, e.g. [0, 0, 1]", value
            ) from None
        raise fail(
            "direction", "expected an axis or a vector [x, y, z]", DIRECTION_FIX, value
        ) from None
    return (float(d[0]), float(d[1]), float(d[2]))


def _vector_input(value: Any) -> list[str | float]:
    if not isinstance(value, list) or len(value) != 3:
        raise fail(
            "vector",
            "expected a position [x, y, z] of three lengths",
            'write e.g. ["0 m", "0 m", "5 m"]',
            value,
        )
    return [_quantity_input(c) for c in value]


def _range_input(value: Any) -> list[str | float]:
    if not isinstance(value, list) or len(value) != 2:
        raise fail(
            "range",
            "expected a range [lo, hi] of two lengths",
            'write e.g. ["10 m", "70 m"]',
            value,
        )
    return [_quantity_input(c) for c in value]


#: a quantity as written (a string with a unit, or a finite number)
Quantity = Annotated[str | float, PlainValidator(_quantity_input)]
#: a position [x, y, z] of three quantities
Position = Annotated[list[str | float], PlainValidator(_vector_input)]
#: a range [lo, hi] of two quantities
Range = Annotated[list[str | float], PlainValidator(_range_input)]
#: a unit direction (an axis name or three numbers)
Direction = Annotated[tuple[float, float, float], PlainValidator(_direction_input)]
#: a name: a non-empty string of at most MAX_NAME characters
Name = Annotated[StrictStr, Field(min_length=1, max_length=MAX_NAME)]
#: free text of at most MAX_TEXT characters
Text = Annotated[StrictStr, Field(max_length=MAX_TEXT)]


# ----------------------------------------------------------------------------------- tables


class TableIn(BaseModel):
    """A table of a model file: unknown keys refused, values frozen."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class StationIn(TableIn):
    """``[station]``."""

    name: Name
    description: Text = ""
    units: Literal["SI", "US"] | None = None
    weight_gravity: Quantity | None = None
    reference_length: Quantity | None = None


class OrbitIn(TableIn):
    """``[orbit]``."""

    radius: Quantity | None = None
    altitude: Quantity | None = None
    mu: Quantity | None = None


class InertiaIn(TableIn):
    """An ``inertia = { xx = ..., ... }`` inline table."""

    xx: Quantity | None = None
    yy: Quantity | None = None
    zz: Quantity | None = None
    xy: Quantity | None = None
    xz: Quantity | None = None
    yz: Quantity | None = None


class MassIn(TableIn):
    """The keys common to body and beam point masses."""

    name: Name
    mass: Quantity | None = None
    weight: Quantity | None = None
    inertia: InertiaIn | None = None
    source: Text = ""
    fitted: StrictBool = False
    movable: Range | None = None


class BodyMassIn(MassIn):
    """``[[body.mass]]``."""

    at: Position


class BeamMassIn(MassIn):
    """``[[beam.mass]]``."""

    s: Quantity | None = None
    at: Position | None = None


class BodyIn(TableIn):
    """``[[body]]``."""

    name: Name
    parent: Name | None = None
    at: Position | None = None
    mass: Annotated[list[BodyMassIn], Field(max_length=MAX_COUNTS["mass"])] = []


class BeamIn(TableIn):
    """``[[beam]]``."""

    name: Name
    parent: Name
    root: Position
    direction: Direction
    length: Quantity
    orientation: Direction | None = None
    ei: Quantity | None = None
    ei_y: Quantity | None = None
    ei_z: Quantity | None = None
    gj: Quantity
    ea: Quantity | None = None
    mass_per_length: Quantity | None = None
    weight_per_length: Quantity | None = None
    mass: Annotated[list[BeamMassIn], Field(max_length=MAX_COUNTS["mass"])] = []


class PointIn(TableIn):
    """``[[point]]``."""

    name: Name
    on: Name
    at: Position | None = None
    s: Quantity | None = None
    kind: Literal["crew", "experiment", "point"] = "point"
    description: Text = ""


class FileIn(TableIn):
    """A whole model file."""

    station: StationIn
    orbit: OrbitIn
    body: Annotated[list[BodyIn], Field(min_length=1, max_length=MAX_COUNTS["body"])]
    beam: Annotated[list[BeamIn], Field(max_length=MAX_COUNTS["beam"])] = []
    point: Annotated[list[PointIn], Field(max_length=MAX_COUNTS["point"])] = []
