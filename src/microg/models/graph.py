"""General frame models (graph models): the public names, from the modules that own them.

A graph model is a frame finite-element model of nodes and elements connected in any
pattern (``docs/model-format.md``, "Graph models").  Its parts, one concept per module:

* :mod:`microg.models.coords` -- coordinate frames (:class:`CoordinateFrame`, CORD2R/C/S);
* :mod:`microg.models.graph_model` -- the frozen SI dataclasses (:class:`GraphModel`,
  :class:`Node`, :class:`BeamElement`, ...), component strings, spring axes;
* :mod:`microg.models.graph_check` -- :func:`validate_graph`;
* :mod:`microg.models.graph_schema` -- the graph TOML file's structure (pydantic);
* :mod:`microg.models.graph_build` -- that structure -> :class:`GraphModel` in SI;
* :mod:`microg.models.graph_toml` -- :func:`load_graph`, :func:`loads_graph`,
  :func:`dump_graph`.

This module only gathers their public names (no module of microg imports it: they import
the owners, so that the frame assembly never loads the file reader and pydantic).
"""

from __future__ import annotations

from microg.models.coords import BASIC, FRAME_KINDS, CoordinateFrame, frame_from_points
from microg.models.graph_check import validate_graph
from microg.models.graph_model import (
    COMPONENTS,
    MASS_FORMULATIONS,
    MAX_GRAPH_ITEMS,
    PARALLEL_TOL,
    ZERO_LENGTH_TOL,
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
    ScalarSpring,
    Spring,
    default_orientation,
    parse_components,
    spring_axes,
)
from microg.models.graph_toml import dump_graph, load_graph, loads_graph

__all__ = [
    "BASIC",
    "COMPONENTS",
    "FRAME_KINDS",
    "MASS_FORMULATIONS",
    "MAX_GRAPH_ITEMS",
    "PARALLEL_TOL",
    "ZERO_LENGTH_TOL",
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
    "default_orientation",
    "dump_graph",
    "frame_from_points",
    "load_graph",
    "loads_graph",
    "parse_components",
    "spring_axes",
    "validate_graph",
]
