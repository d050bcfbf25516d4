"""The main job's arguments as given by a user, turned into SI values and objects.

A float is SI; a string is parsed, with its unit or, when bare, in the model's unit system
(:func:`si_value`).  Forces are spec strings or force objects, directions strings or
3-vectors, one or a list; models, source catalogues and requirements are objects or names.
Each helper raises :class:`~microg.errors.InputError` naming the parameter.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from microg.analysis.options import DEFAULTS
from microg.dynamics.forces import ForceHistory, parse_force_spec
from microg.environment.requirements import Requirement
from microg.errors import InputError
from microg.units import parse_quantity

__all__ = [
    "as_list",
    "check_points",
    "direction_list",
    "force_histories",
    "has_grids",
    "model_object",
    "point_names",
    "requirement_object",
    "si_value",
    "source_catalogue",
]


def si_value(value: Any, dimension: str, where: str, unit_system: str | None) -> float:
    """A float (SI) or a string (with a unit, or bare in the model's unit system) -> SI.

    Parameters
    ----------
    value : float (SI) or str (``"0.02 s"``, or a bare number in ``unit_system``)
    dimension : the quantity's dimension (``"time"``, ``"mass"``, ``"frequency"``, ...)
    where : the parameter's name, for the error
    unit_system : the model's unit system (None: SI)
    """
    from microg.units import DIMENSIONS

    if isinstance(value, bool):
        raise InputError(f"expected a {dimension}, got {value!r}", where=where)
    if isinstance(value, int | float | np.integer | np.floating):
        v = float(value)
        if not np.isfinite(v):
            raise InputError(f"{value!r} is not a finite number", where=where)
        return v
    default = _bare_unit(dimension, unit_system) or DIMENSIONS[dimension] or None
    return parse_quantity(str(value), dimension, where=where, default_unit=default)


def _bare_unit(dimension: str, unit_system: str | None) -> str | None:
    """Unit of a bare number of ``dimension`` in a model's unit system (None: SI)."""
    if unit_system is None:
        return None
    from microg.models.toml import UNIT_SYSTEMS

    table = UNIT_SYSTEMS.get(unit_system, {})
    return table.get(dimension)


def as_list(value: Any) -> list[Any]:
    """One value or a sequence of them as a list (None: empty; a string, force or array: one)."""
    if value is None:
        return []
    if isinstance(value, str | ForceHistory | np.ndarray):
        return [value]
    if isinstance(value, Sequence):
        return list(value)
    return [value]


def direction_list(value: Any) -> list[Any]:
    """Directions as a list; a single 3-vector of numbers is one direction."""
    if value is None:
        return []
    if isinstance(value, str | np.ndarray):
        return [value]
    if not isinstance(value, list | tuple):
        raise InputError(
            f"must be a direction ('x', '-z', '1 0 0' or 3 numbers) or a list of them, "
            f"got {type(value).__name__}",
            where="direction",
        )
    items = list(value)
    if len(items) == 3 and all(
        isinstance(c, int | float | np.integer | np.floating) for c in items
    ):
        return [items]
    return items


def force_histories(force: Any, unit_system: str | None = None) -> list[ForceHistory]:
    """Force histories from specs; bare parameter values take the model's unit system."""
    bare: dict[str, str] | None = None
    if unit_system is not None:
        from microg.models.toml import UNIT_SYSTEMS

        bare = UNIT_SYSTEMS.get(unit_system)
    specs = as_list(force) or [DEFAULTS["force"]]
    out = []
    for i, spec in enumerate(specs):
        where = "force" if len(specs) == 1 else f"force[{i}]"
        if isinstance(spec, ForceHistory):
            out.append(spec)
        elif isinstance(spec, str | Path):
            out.append(parse_force_spec(str(spec), where=where, bare_units=bare))
        else:
            raise InputError(
                f"cannot use {spec!r} as a force",
                where=where,
                fix="give a spec string (crew-pushoff, a library name, a CSV path) or a "
                "ForceHistory",
            )
    return out


def point_names(model: Any) -> list[tuple[str, str]]:
    """(name, kind) of the model's named points."""
    pts = getattr(model, "points", ())
    if isinstance(pts, Mapping):
        return [(n, getattr(p, "kind", "point")) for n, p in pts.items()]
    return [(p.name, getattr(p, "kind", "point")) for p in pts]


def has_grids(model: Any) -> bool:
    """True for imported models whose grids are points too (``grid:N``)."""
    return hasattr(model, "grid_ids") or type(model).__name__ == "GraphModel"


def check_points(names: Sequence[str], known: Sequence[str], where: str) -> None:
    """Refuse a point name that is not in ``known`` (``where``: the parameter)."""
    for p in names:
        if p not in known:
            raise InputError(
                f"unknown point {p!r}", where=where, fix=f"known points: {', '.join(known)}"
            )


def model_object(model: Any) -> Any:
    """A model object, or the model a path or shipped name loads."""
    if isinstance(model, str | os.PathLike):
        from microg.models.load import load_model

        return load_model(os.fspath(model))
    kind = type(model).__name__
    if kind not in ("Station", "GraphModel", "ModalModel"):
        raise InputError(
            f"must be a Station, a modal model, a model file path or a shipped model name, "
            f"got {kind}",
            where="model",
        )
    return model


def source_catalogue(sources: Any) -> Any:
    """A source catalogue from a path, ``"example"`` or a catalogue object (None: none)."""
    if sources is None:
        return None
    from microg.environment.sources import SourceCatalogue, load_sources

    if isinstance(sources, str | os.PathLike):
        return load_sources(os.fspath(sources))
    if not isinstance(sources, SourceCatalogue):
        raise InputError(
            f"must be a source catalogue file, 'example' or a SourceCatalogue, "
            f"got {type(sources).__name__}",
            where="sources",
        )
    return sources


def requirement_object(name: str | Requirement) -> Requirement:
    """A requirement object, or the one of that name (``iss``, ``ssp41000``, ``flat``)."""
    if isinstance(name, Requirement):
        return name
    from microg.environment.requirements import requirement as by_name

    return by_name(name)
