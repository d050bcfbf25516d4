"""The structure of a graph model file (pydantic): tables, keys and the kind of each value.

Step 2 of reading a graph TOML file (``docs/model-format.md``, "Graph models"), as for
station files (:mod:`microg.models.schema`): after :mod:`tomllib` has parsed the text,
:class:`GraphFileIn` checks known keys only, required keys present, and the kind of each
value -- quantities, positions and directions with the station format's own validators,
component strings (``"123456"``), node pairs, spring axes.  Quantities stay as written;
:mod:`microg.models.graph_build` converts them to SI and checks the references between
tables.  :func:`microg.models.messages.structure_error` words the first error as one line,
``FILE: table[i].key: what is wrong (how to fix)``.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, PlainValidator, StrictBool

from microg.errors import InputError
from microg.models.graph_model import COMPONENTS, parse_components
from microg.models.messages import EXAMPLES, fail
from microg.models.schema import Direction, InertiaIn, Position, Quantity, TableIn, Text

__all__ = [
    "GRAPH_EXAMPLES",
    "INERTIA_KEYS",
    "SPRING_KEYS",
    "BeamIn",
    "ConstraintIn",
    "FrameIn",
    "GraphFileIn",
    "GraphIn",
    "InterpolationIn",
    "MassIn",
    "NodeIn",
    "PointIn",
    "RigidIn",
    "RodIn",
    "SectionIn",
    "SourceIn",
    "SpringIn",
    "SpringValuesIn",
]

#: the keys of a spring's stiffness and damping tables, in the order of the 6x6 diagonal
SPRING_KEYS = ("x", "y", "z", "rx", "ry", "rz")
#: the keys of an inertia table: diagonal, then products
INERTIA_KEYS = ("xx", "yy", "zz", "xy", "xz", "yz")

#: example values for "add it" hints, by key
GRAPH_EXAMPLES: dict[str, str] = {
    **EXAMPLES,
    "graph": '[graph] with name = "my frame"',
    "name": 'name = "n1"',
    "at": 'at = ["0 m", "0 m", "0 m"]',
    "kind": 'kind = "rectangular"',
    "origin": 'origin = ["0 m", "0 m", "0 m"]',
    "z_axis": 'z_axis = "+z"',
    "xz_point": 'xz_point = ["1 m", "0 m", "0 m"]',
    "nodes": 'nodes = ["n1", "n2"]',
    "section": 'section = "tube"',
    "ea": 'ea = "2e8 N"',
    "gj": 'gj = "1e6 N*m^2"',
    "mass_per_length": 'mass_per_length = "5 kg/m"',
    "node": 'node = "n1"',
    "mass": 'mass = "100 kg"',
    "independent": 'independent = "n1"',
    "dependents": 'dependents = ["n2"]',
    "reference": 'reference = "n1"',
    "sources": 'sources = [{ node = "n2", components = "123", weight = 1.0 }]',
    "components": 'components = "123456"',
}


# --------------------------------------------------------------------------------- validators


def _name_input(value: Any) -> str:
    """A name: a string, not blank; surrounding blanks dropped."""
    if not isinstance(value, str) or not value.strip():
        raise fail("name", "expected a non-empty string", 'write e.g. "n1"', value)
    return value.strip()


def _components_input(allowed: str) -> Any:
    def check(value: Any) -> str:
        try:
            return parse_components(value, where="", allowed=allowed)
        except InputError:  # reworded for the file: the path is the schema's
            raise fail(
                "components",
                f"expected distinct digits among {allowed}",
                f'write e.g. components = "{allowed}"',
                value,
            ) from None

    return check


def _pair_input(value: Any) -> tuple[str, str]:
    if not isinstance(value, list) or len(value) != 2:
        raise fail("nodes", "expected two node names", 'write e.g. nodes = ["n1", "n2"]', value)
    a, b = (_name_input(v) for v in value)
    return a, b


def _spring_nodes_input(value: Any) -> tuple[str, str | None]:
    if not isinstance(value, list) or len(value) not in (1, 2):
        raise fail(
            "nodes",
            "expected one node (grounded) or two",
            'write e.g. nodes = ["n1", "n2"] or nodes = ["n1"]',
            value,
        )
    names = [_name_input(v) for v in value]
    return names[0], (names[1] if len(names) == 2 else None)


def _offsets_input(value: Any) -> list[Any]:
    if not isinstance(value, list) or len(value) != 2:
        raise fail(
            "offsets",
            "expected two positions [[...], [...]]",
            'write e.g. offsets = [["0 m", "0 m", "0.1 m"], ["0 m", "0 m", "0.1 m"]]',
            value,
        )
    return value


def _releases_input(value: Any) -> tuple[str, str]:
    if not isinstance(value, list) or len(value) != 2 or not all(isinstance(r, str) for r in value):
        raise fail(
            "releases",
            "expected two component strings",
            'write e.g. releases = ["", "456"]',
            value,
        )
    check = _components_input(COMPONENTS)
    a, b = (check(r) if r else "" for r in value)
    return a, b


def _axes_input(value: Any) -> str | tuple[tuple[float, ...], ...]:
    """A frame name, or three unit rows (x, y, z axes in basic), right-handed, orthonormal."""
    if isinstance(value, str):
        return _name_input(value)
    ok = isinstance(value, list) and len(value) == 3
    ok = ok and all(
        isinstance(r, list)
        and len(r) == 3
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in r)
        for r in value
    )
    if not ok:
        raise fail(
            "axes",
            "expected a frame name or three rows [[x...], [y...], [z...]]",
            'write e.g. axes = "basic" or [[1, 0, 0], [0, 1, 0], [0, 0, 1]]',
            value,
        )
    ax = np.array(value, float)
    # orthonormal to 1e-9: rows written with about 10 significant digits still pass
    if not np.allclose(ax @ ax.T, np.eye(3), atol=1e-9) or np.linalg.det(ax) < 0:
        raise fail(
            "axes",
            "the rows are not orthonormal and right-handed",
            "give unit, mutually perpendicular rows with z = x cross y",
            value,
        )
    return tuple(tuple(float(v) for v in r) for r in value)


def _weight_input(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        raise fail("weight", "expected a number > 0", "write e.g. weight = 1.0", value)
    return float(value)


_GName = Annotated[str, PlainValidator(_name_input)]
_Components = Annotated[str, PlainValidator(_components_input(COMPONENTS))]
_Translations = Annotated[str, PlainValidator(_components_input("123"))]
_Pair = Annotated[tuple[str, str], PlainValidator(_pair_input)]


# ----------------------------------------------------------------------------------- tables


class GraphIn(TableIn):
    """``[graph]``."""

    name: _GName
    description: Text = ""
    units: Literal["SI", "US"] | None = None
    mass: Literal["lumped", "consistent", "coupled", "coupled-nx9"] = "consistent"


class FrameIn(TableIn):
    """``[[frame]]``: a coordinate system from points A (origin), B (on z), C (in x-z)."""

    name: _GName
    kind: Literal["rectangular", "cylindrical", "spherical"]
    origin: Position
    z_axis: Direction
    xz_point: Position


class NodeIn(TableIn):
    """``[[node]]``."""

    name: _GName
    at: Position
    frame: _GName = "basic"


class SectionIn(TableIn):
    """``[[section]]``: a uniform beam cross-section."""

    name: _GName
    ea: Quantity
    ei: Quantity | None = None
    ei_y: Quantity | None = None
    ei_z: Quantity | None = None
    ei_yz: Quantity | None = None
    gj: Quantity
    mass_per_length: Quantity
    shear_y: Quantity | None = None
    shear_z: Quantity | None = None
    polar_gyration: Quantity | None = None
    rotary_inertia: StrictBool = False


class BeamIn(TableIn):
    """``[[beam]]``."""

    name: _GName
    nodes: _Pair
    section: _GName
    orientation: Direction | None = None
    offsets: Annotated[list[Position], PlainValidator(_offsets_input)] | None = None
    kind: Literal["beam", "bar"] = "beam"
    releases: Annotated[tuple[str, str], PlainValidator(_releases_input)] = ("", "")


class RodIn(TableIn):
    """``[[rod]]``."""

    name: _GName
    nodes: _Pair
    ea: Quantity
    gj: Quantity = 0
    mass_per_length: Quantity


class SpringValuesIn(TableIn):
    """A spring's ``stiffness`` or ``damping`` inline table: the diagonal in its axes."""

    x: Quantity | None = None
    y: Quantity | None = None
    z: Quantity | None = None
    rx: Quantity | None = None
    ry: Quantity | None = None
    rz: Quantity | None = None


class SpringIn(TableIn):
    """``[[spring]]``: a 6x6 spring-damper (NASTRAN CBUSH)."""

    name: _GName
    nodes: Annotated[tuple[str, str | None], PlainValidator(_spring_nodes_input)]
    stiffness: SpringValuesIn = SpringValuesIn()
    damping: SpringValuesIn = SpringValuesIn()
    axes: Annotated[str | tuple[tuple[float, ...], ...], PlainValidator(_axes_input)] | None = None
    orientation: Direction | None = None
    at: Position | None = None


class MassIn(TableIn):
    """``[[mass]]``: a concentrated mass (NASTRAN CONM2)."""

    name: _GName
    node: _GName
    mass: Quantity
    at: Position | None = None
    inertia: InertiaIn = InertiaIn()


class RigidIn(TableIn):
    """``[[rigid]]``: a rigid element (NASTRAN RBE2)."""

    name: _GName
    independent: _GName
    dependents: Annotated[list[_GName], Field(min_length=1)]
    components: _Components = COMPONENTS


class SourceIn(TableIn):
    """One independent node of an interpolation element."""

    node: _GName
    components: _Translations = "123"
    weight: Annotated[float, PlainValidator(_weight_input)] = 1.0


class InterpolationIn(TableIn):
    """``[[interpolation]]``: an interpolation element (NASTRAN RBE3)."""

    name: _GName
    reference: _GName
    sources: Annotated[list[SourceIn], Field(min_length=1)]
    components: _Components = COMPONENTS


class PointIn(TableIn):
    """``[[point]]``."""

    name: _GName
    node: _GName
    at: Position | None = None
    kind: Literal["crew", "experiment", "point"] = "point"
    description: Text = ""


class ConstraintIn(TableIn):
    """``[[constraint]]``."""

    node: _GName
    components: _Components


class GraphFileIn(TableIn):
    """A whole graph model file."""

    graph: GraphIn
    frame: list[FrameIn] = []
    node: list[NodeIn] = []
    section: list[SectionIn] = []
    beam: list[BeamIn] = []
    rod: list[RodIn] = []
    spring: list[SpringIn] = []
    mass: list[MassIn] = []
    rigid: list[RigidIn] = []
    interpolation: list[InterpolationIn] = []
    point: list[PointIn] = []
    constraint: list[ConstraintIn] = []
