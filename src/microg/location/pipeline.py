"""The location stage's job, from a model to the map and its best point: :func:`locate`.

``discretize`` (free-free, the one discretisation entry
:func:`microg.structure.discretize.discretize`) -> :func:`microg.dynamics.modes.solve_modes`
-> :func:`~microg.location.mapping.acceleration_map` ->
:func:`~microg.location.mapping.best_location`, for stations and imported models alike, with
the defaults of ``microg locate`` and the checks of its points and direction.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from microg import defaults
from microg._vectors import AXES, parse_direction
from microg.dynamics.crew import CrewPushoff
from microg.errors import InputError
from microg.location.mapping import (
    MEASURES,
    AccelerationMap,
    Location,
    acceleration_map,
    best_location,
    resolve_point,
)
from microg.location.peaks import force_breakpoints
from microg.models.station import Station
from microg.structure.structure import Structure

__all__ = [
    "DEFAULTS",
    "LATERAL",
    "LocateResult",
    "check_point",
    "default_direction",
    "default_point",
    "force_to_dict",
    "is_imported",
    "locate",
    "spec_units",
    "location_structure",
]

#: the force direction by default: the lateral axis of the report's plane
LATERAL: dict[str, str] = {"xz": "x", "yz": "y", "3d": "x"}
#: defaults of :func:`locate` (and of ``microg locate``), from :mod:`microg.defaults`
DEFAULTS: dict[str, Any] = {
    "method": defaults.METHOD,
    "plane": defaults.PLANE,
    "measure": "total",
    "zeta": defaults.DAMPING,
    "include_rigid": True,
}


def force_to_dict(force: Any) -> dict:
    """JSON-ready parameters of a force: the push-off's f0, t1, t13, t14 or the breakpoints."""
    if isinstance(force, CrewPushoff):
        return {"f0_N": force.f0, "t1_s": force.t1, "t13_s": force.t13, "t14_s": force.t14}
    tb, fb = force_breakpoints(force)
    return {
        "name": str(getattr(force, "name", "force")),
        "timepts_s": [float(t) for t in tb],
        "force_N": [float(f) for f in fb],
    }


@dataclass(frozen=True)
class LocateResult:
    """Outcome of :func:`locate`: the map, its quietest sample, and what produced them.

    Attributes
    ----------
    model : str
        Station name.
    force : CrewPushoff or ForceHistory
        N.
    amap : AccelerationMap
    best : Location
    n : int or None
        Functions (ritz) or elements (fem) per beam asked for (None: the default).
    warnings : tuple of str
    mass_formulation : str or None
        A frame (deck) model's element mass and what chose it (as ``microg analyze``'s
        provenance ``mass_formulation_note``); None for stations and modal models.
    """

    model: str
    force: Any
    amap: AccelerationMap = field(repr=False)
    best: Location
    n: int | None = None
    warnings: tuple[str, ...] = ()
    mass_formulation: str | None = None

    def to_dict(self) -> dict:
        """The ``microg locate --json`` document."""
        d = self.amap.to_dict()
        out = {"model": self.model, "method": d.pop("method"), "plane": d.pop("plane")}
        out.update(
            {
                "crew_point": d.pop("crew_point"),
                "crew_position_m": d.pop("crew_position_m"),
                "direction": d.pop("direction"),
                "force": force_to_dict(self.force),
            }
        )
        out.update(d)
        samples = out.pop("samples")
        out["best_location"] = self.best.to_dict()
        if self.mass_formulation is not None:
            out["mass_formulation"] = self.mass_formulation
        out["warnings"] = list(self.warnings)
        out["samples"] = samples
        return out

    def to_xarray(self) -> Any:
        """The map as an ``xarray.Dataset`` (see :meth:`AccelerationMap.to_xarray`)."""
        ds = self.amap.to_xarray()
        ds.attrs["model"] = self.model
        return ds

    def plot(self, *, title: str | None = None, ax: Any = None) -> Any:
        """The map with the best location circled (a matplotlib Figure).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.location import plot_map

        return plot_map(
            self.amap,
            measure=self.best.measure,
            title=title or f"{self.model}: {self.amap.method}",
            best=self.best,
            ax=ax,
        )

    def plot3d(self, *, title: str | None = None) -> Any:
        """The map coloured along the structure in 3-D, the best location ringed (plotly)."""
        return self.amap.plot3d(
            measure=self.best.measure,
            title=title or f"{self.model}: peak acceleration ({self.best.measure}) in 3-D",
            best=self.best,
        )


def default_point(station: Station, kind: str, where: str) -> str:
    """The model's first named point of ``kind`` (``"crew"``, ``"experiment"``).

    Raises InputError naming ``where`` when there is none, listing the points.
    """
    for p in station.points:
        if getattr(p, "kind", "point") == kind:
            return p.name
    known = ", ".join(p.name for p in station.points) or "(none)"
    raise InputError(
        f"the model has no {kind} point and none was given",
        where=where,
        fix=f"name one of: {known}",
    )


def check_point(station: Station, name: str, where: str) -> None:
    """InputError naming ``where`` unless ``name`` is a named point of ``station``."""
    names = [p.name for p in station.points]
    if name not in names:
        raise InputError(
            f"unknown point {name!r}", where=where, fix=f"known points: {', '.join(sorted(names))}"
        )


def default_direction(plane: str) -> str:
    """The force direction by default: the lateral axis of ``plane`` (x for ``3d``)."""
    return LATERAL.get(plane, "x")


def location_structure(
    station: Station, method: str, plane: str, n: int | None, direction: Any
) -> tuple[Structure, np.ndarray]:
    """The one discretisation entry for the location stage, and the checked direction.

    ``discretize(station, method, plane=..., n=n, gravity_gradient=False)``: for ``ritz``
    ``plane`` is the report's planar model (``xz``, ``yz``) or ``3d``; a frame model is
    always 3-D and ``plane`` only sets the default direction.  A planar model moves along
    its lateral axis only.

    Parameters
    ----------
    station : Station
    method : {"ritz", "fem"}
    plane : {"xz", "yz", "3d"}
    n : int, optional
        Functions (ritz) or elements (fem) per beam.
    direction : str or ndarray (3,), optional
        Force direction (default :func:`default_direction`).
    """
    from microg.structure.discretize import discretize

    if plane not in LATERAL:
        raise InputError(f"unknown plane {plane!r}", where="plane", fix="use xz, yz or 3d")
    d = parse_direction(
        direction if direction is not None else default_direction(plane), "direction"
    )
    planar = method == "ritz" and plane != "3d"
    if planar and abs(float(d @ AXES[LATERAL[plane]])) < 1 - 1e-12:
        lat = LATERAL[plane]
        raise InputError(
            f"the {plane} assumed-modes model moves along {lat} only",
            where="direction",
            fix=f"use direction {lat}, another plane, plane 3d, or method fem",
        )
    structure = discretize(
        station,
        method,
        plane=plane if method == "ritz" else "3d",
        n=n,
        gravity_gradient=False,
    )
    return structure, d


def _load(model: Any, **reader: Any) -> Any:
    """A model object as it is, or a path / shipped name read by the one model loader.

    ``reader``: the loader's options (units, wtmass, points, subcase, superelement,
    coupled_mass).
    """
    given = {k: v for k, v in reader.items() if v is not None}
    if not isinstance(model, str | Path):
        if given:
            raise InputError(
                f"{', '.join(reader)} apply when the model is read from a file",
                where=next(iter(given)),
                fix="pass the file's path, or give them to microg.load_model",
            )
        return model
    from microg.models.load import load_model

    return load_model(model, **given)


def is_imported(model: Any) -> bool:
    """True for the models located over their own grids: modal models and frame graphs."""
    return type(model).__name__ in ("ModalModel", "GraphModel")


def _imported_structure(model: Any, crew: str) -> tuple[Structure, np.ndarray | None]:
    """The structure of a modal model or frame graph, and its elements' sample segments.

    A modal model becomes the modal-coordinate structure with its grids as samples
    (:func:`microg.structure.modal.modal_structure`); it has no elements, hence no
    segments.  A frame graph is assembled by the one discretisation entry; its beams and
    rods between sampled nodes are the segments (the beam lines of the map).
    """
    from microg.structure.discretize import discretize

    if type(model).__name__ == "ModalModel":
        from microg.structure.modal import modal_structure

        # the named points are listed; any grid:N (the crew point) resolves on access
        return modal_structure(model, [p.name for p in model.points]), None
    structure = discretize(model)
    labels = getattr(structure.samples, "labels", None) or ()
    index = {lab: i for i, lab in enumerate(labels)}
    ends = [el.nodes for el in (*model.beams, *model.rods)]
    seg = np.array(
        [(index[a], index[b]) for a, b in ends if a in index and b in index], dtype=np.int64
    ).reshape(-1, 2)
    return structure, seg


def spec_units(model: Any) -> dict[str, str] | None:
    """Units of bare values in a force spec: the station's unit system (None otherwise)."""
    from microg.models.toml import UNIT_SYSTEMS

    system = getattr(model, "unit_system", None)
    return UNIT_SYSTEMS.get(system) if isinstance(system, str) else None


def locate(
    model: Station | Any | str | Path,
    crew: str | None = None,
    *,
    force: CrewPushoff | Any | None = None,
    direction: str | np.ndarray | None = None,
    method: str = DEFAULTS["method"],
    plane: str = DEFAULTS["plane"],
    n: int | None = None,
    n_modes: int | None = None,
    zeta: float = DEFAULTS["zeta"],
    include_rigid: bool = DEFAULTS["include_rigid"],
    on: str | None = None,
    measure: str = DEFAULTS["measure"],
    units: str | None = None,
    wtmass: float | None = None,
    points: str | Path | None = None,
    subcase: int | None = None,
    superelement: int | None = None,
    coupled_mass: str | None = None,
) -> LocateResult:
    """Where to put the laboratory: the acceleration map of a crew force and its best point.

    ``discretize`` (free-free) -> ``solve_modes`` -> :func:`acceleration_map` ->
    :func:`best_location`.

    A station (tree of beams) is discretised by ``method``.  An imported model is mapped
    over its own grids: a modal model (:class:`~microg.models.modal.ModalModel`, read from
    ``.op2``/``.op4``/``.unv``/``.npz``) over every grid, its named points added as
    carrier ``"points"``; it has no elements, so the nodes of the fundamental are located
    only where its grids are collinear (a warning says so otherwise).  A frame graph
    (:class:`~microg.models.graph.GraphModel`, a ``.bdf`` deck) over its nodes and
    concentrated masses, its named points added likewise, the nodes of the fundamental
    along the straight chains of its beams and rods.  ``method``, ``plane`` (but for the
    default direction) and ``n`` do not apply to imported models.

    Parameters
    ----------
    model : Station, ModalModel, GraphModel, or a model file path or shipped name
    crew : str, optional
        Named point (or ``grid:N`` of an imported model) where the force acts (default: the
        model's first point of kind crew).
    force : str, CrewPushoff or ForceHistory, optional
        N, or a spec of :func:`~microg.dynamics.forces.crew_force` (``microg analyze
        --force``'s grammar; bare values take the model's unit system); default: the
        report's push-off, 25 lbf, 1 s, 13 s, 14 s.
    direction : str or ndarray (3,), optional
        Force direction (default: the plane's lateral axis, x for xz, y for yz).
    method : {"ritz", "fem"}
        Assumed modes (the report's method) or 3-D frame elements (stations only); default
        :data:`microg.defaults.METHOD`, as every default here (``plane``, ``zeta``).
    plane : {"xz", "yz", "3d"}
        Ritz: the planar model or the 3-D one; fem and imported models: sets the default
        direction only.
    n : int, optional
        Functions (ritz) or elements (fem) per beam (default: the discretisation's).
    n_modes : int, optional
        Lowest modes used (default: :func:`~microg.dynamics.modes.solve_modes`'s).
    zeta : float
        Modal damping ratio, 0 <= zeta < 1 (0: exact [A]max per mode).
    include_rigid : bool
        Include the rigid-body modes.
    on : str, optional
        Restrict the best location to this body or beam; for imported models ``"points"``
        (the named points), ``"grids"`` (a modal model's grids) or ``"grid"`` (a deck's
        nodes).
    measure : {"total", "elastic", "rigid", "bound", "long_time"}
        Peak minimised for the best location.
    units : str, optional
        ``"LENGTH, FORCE, TIME"`` of a NASTRAN (or UFF without dataset 164) model file.
    wtmass : float, optional
        NASTRAN PARAM,WTMASS of the run.
    points : str or Path, optional
        Points/options TOML file naming grids of an imported model.
    subcase : int, optional
        The subcase of an OP2 with modes of several.
    superelement : int, optional
        The superelement of an OP4 holding the matrices of several.
    coupled_mass : {"coupled", "coupled-nx9", "consistent"}, optional
        A NASTRAN deck with ``PARAM,COUPMASS`` > 0: which coupled CBAR mass
        (:func:`microg.load_model`'s).
    """
    from microg.dynamics.forces import crew_force
    from microg.dynamics.modes import solve_modes

    mdl = _load(
        model,
        units=units,
        wtmass=wtmass,
        points=points,
        subcase=subcase,
        superelement=superelement,
        coupled_mass=coupled_mass,
    )
    if method not in ("ritz", "fem"):
        raise InputError(f"unknown method {method!r}", where="method", fix="use ritz or fem")
    if measure not in MEASURES:
        raise InputError(
            f"unknown measure {measure!r}", where="measure", fix=f"use {', '.join(MEASURES)}"
        )
    force = crew_force(force, bare_units=spec_units(mdl))
    if is_imported(mdl):
        return _locate_imported(
            mdl, crew, force, direction, plane, n_modes, zeta, include_rigid, on, measure
        )
    station = mdl
    crew = crew or default_point(station, "crew", "crew")
    check_point(station, crew, "crew")
    structure, d = location_structure(station, method, plane, n, direction)
    modes = solve_modes(structure, n_modes)
    amap = acceleration_map(
        structure, modes, crew, d, force, zeta=zeta, include_rigid=include_rigid
    )
    best = best_location(amap, component=on, measure=measure)
    warnings: list[str] = []
    if amap.fundamental is None:
        warnings.append("the force excites no elastic mode: no nodes of a fundamental")
    return LocateResult(
        model=station.name, force=force, amap=amap, best=best, n=n, warnings=tuple(warnings)
    )


def _locate_imported(
    model: Any,
    crew: str | None,
    force: Any,
    direction: Any,
    plane: str,
    n_modes: int | None,
    zeta: float,
    include_rigid: bool,
    on: str | None,
    measure: str,
) -> LocateResult:
    """:func:`locate` on a modal model or a frame graph (see its docstring)."""
    from microg.dynamics.modes import solve_modes

    if plane not in LATERAL:
        raise InputError(f"unknown plane {plane!r}", where="plane", fix="use xz, yz or 3d")
    crew = crew or default_point(model, "crew", "crew")
    d = parse_direction(
        direction if direction is not None else default_direction(plane), "direction"
    )
    structure, segments = _imported_structure(model, crew)
    resolve_point(structure, crew, "crew")
    modes = solve_modes(structure, n_modes)
    names = [p.name for p in model.points]
    amap = acceleration_map(
        structure,
        modes,
        crew,
        d,
        force,
        zeta=zeta,
        include_rigid=include_rigid,
        points=names,
        segments=segments,
    )
    best = best_location(amap, component=on, measure=measure)
    warnings = [f"model: {w}" for w in structure.meta.get("warnings", ())]
    if amap.fundamental is None:
        warnings.append("the force excites no elastic mode: no nodes of a fundamental")
    elif not amap.lines:
        what = (
            "a modal model has no elements and its grids do not lie on one straight line"
            if segments is None
            else "the model has no straight chain of beams or rods between its nodes"
        )
        warnings.append(
            f"{what}: there is no beam line to locate the nodes of the fundamental on "
            "(the map over every sample and the quietest one are given)"
        )
    form = getattr(model, "mass_formulation", None)
    note = (getattr(model, "meta", None) or {}).get("mass_formulation_note", form)
    return LocateResult(
        model=str(model.name),
        force=force,
        amap=amap,
        best=best,
        n=None,
        warnings=tuple(warnings),
        mass_formulation=note if isinstance(form, str) else None,
    )
