"""Rearranging massive elements to quieten an experiment site (report conclusion 9).

"By rearranging some massive elements, a minimum value of (phi_11 + phi_21 z_e/l_k)/M_11
can be reached.  However, this has to be done by trial and error."  This module does the
trial and error: it moves the point masses a model (or the caller) marks as movable
(:func:`movable_masses`, :func:`move_masses`) and minimises the peak acceleration that a crew
force causes at the experiment site (:func:`optimize_layout`).

The objective is the peak at the site of :func:`microg.location.site.point_peak` -- the same
kernel as the acceleration map -- on the model discretised by the one entry
:func:`microg.structure.discretize.discretize` (free-free) and solved by
:func:`microg.dynamics.modes.solve_modes`.  By default it is the **total** peak (rigid-body
modes included): the rigid translation ``f0/M`` cannot be moved away, so a layout can only
reduce the elastic part and the rigid rotation; the elastic and rigid parts are reported
beside it.

For assumed modes the optimiser re-assembles only what a moved mass changes (its mass
matrix terms and the named points' maps; the coordinates, the stiffness and the rigid-body
vectors do not depend on where a mass sits); :func:`layout_objective` is the reference route
through ``discretize``, and the two agree to rounding (tested to 1e-9).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from microg import defaults
from microg.dynamics.crew import CrewPushoff
from microg.errors import InputError
from microg.location.pipeline import (
    check_point,
    default_point,
    force_to_dict,
    location_structure,
    spec_units,
)
from microg.location.site import SitePeak, point_peak
from microg.models.station import Beam, NamedPoint, PointMass, RigidBody, Station
from microg.structure.structure import Structure
from microg.units import G0

__all__ = [
    "DEFAULTS",
    "LAYOUT_MEASURES",
    "MAX_GENERATIONS",
    "MAX_MOVABLE",
    "MAX_POPSIZE",
    "LayoutResult",
    "MovableMass",
    "layout_objective",
    "movable_masses",
    "move_masses",
    "optimize_layout",
    "parse_movable",
    "resolve_mass",
]

#: largest number of differential-evolution generations (``maxiter``)
MAX_GENERATIONS = 1000
#: largest population multiplier (``popsize``)
MAX_POPSIZE = 100
#: largest number of movable masses
MAX_MOVABLE = 20
#: objectives the optimiser accepts (see :class:`~microg.location.site.SitePeak`)
LAYOUT_MEASURES = ("total", "elastic", "bound")
#: defaults of :func:`optimize_layout` (and of ``microg optimize``), from :mod:`microg.defaults`
DEFAULTS: dict[str, Any] = {
    "method": defaults.LAYOUT_METHOD,
    "plane": defaults.PLANE,
    "zeta": defaults.DAMPING,
    "measure": "total",
    "seed": 0,
    "maxiter": 60,
    "popsize": 12,
    "polish": True,
}


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class MovableMass:
    """A point mass the layout optimiser may move.

    Attributes
    ----------
    key : str
        ``"carrier/name"``.
    carrier : str
        Body or beam name.
    name : str
    kind : str
        ``"body"`` (coordinate z, m) or ``"beam"`` (arc length s from the root, m).
    value : float
        Current coordinate, m.
    bounds : tuple of float
        (lo, hi), m.
    """

    key: str
    carrier: str
    name: str
    kind: str
    value: float
    bounds: tuple[float, float]


@dataclass(frozen=True)
class LayoutResult:
    """Outcome of :func:`optimize_layout`.

    Attributes
    ----------
    model : str
        Station name.
    experiment, crew : str
        Named points: the site and where the force acts.
    method, plane : str
        Discretisation (see :func:`~microg.location.pipeline.location_structure`).
    n : int or None
        Functions or elements per beam asked for.
    direction : ndarray (3,)
        Unit force direction.
    force : CrewPushoff or ForceHistory
    measure : str
        The objective: ``total``, ``elastic`` or ``bound`` of the site's peak.
    masses : tuple of MovableMass
        The movable masses (``value`` = initial coordinate).
    initial, optimal : ndarray (k,)
        Coordinates, m.
    objective_initial, objective_optimal : float
        The objective at both layouts, m/s^2.
    initial_peak, optimal_peak : SitePeak
        Every peak at the site at both layouts (total, elastic, rigid, bound, per mode).
    n_evaluations : int
        Objective evaluations.
    success : bool
    message : str
    station : Station
        The station with the masses at their optimal positions.
    zeta : float
        Modal damping ratio of the elastic modes.
    """

    model: str
    experiment: str
    crew: str
    method: str
    plane: str
    n: int | None
    direction: np.ndarray
    force: Any
    measure: str
    masses: tuple[MovableMass, ...]
    initial: np.ndarray
    optimal: np.ndarray
    objective_initial: float
    objective_optimal: float
    initial_peak: SitePeak
    optimal_peak: SitePeak
    n_evaluations: int
    success: bool
    message: str
    station: Station = dataclasses.field(repr=False)
    zeta: float = DEFAULTS["zeta"]

    @property
    def improvement(self) -> float:
        """objective_initial / objective_optimal (inf if the optimum is zero)."""
        if self.objective_optimal == 0:
            return float("inf")
        return self.objective_initial / self.objective_optimal

    def to_dict(self) -> dict:
        """The ``microg optimize --json`` document (peaks in g, lengths in m)."""
        g = 1.0 / G0
        gain = self.improvement
        return {
            "model": self.model,
            "method": self.method,
            "plane": self.plane,
            "n": self.n,
            "zeta": self.zeta,
            "experiment_point": self.experiment,
            "crew_point": self.crew,
            "direction": [float(v) for v in self.direction],
            "force": force_to_dict(self.force),
            "measure": self.measure,
            "masses": [
                {
                    "key": mm.key,
                    "kind": mm.kind,
                    "bounds_m": [float(b) for b in mm.bounds],
                    "initial_m": float(x0),
                    "optimal_m": float(x1),
                }
                for mm, x0, x1 in zip(self.masses, self.initial, self.optimal, strict=True)
            ],
            "objective_initial_g": self.objective_initial * g,
            "objective_optimal_g": self.objective_optimal * g,
            "improvement": gain if np.isfinite(gain) else None,
            "initial": self.initial_peak.to_dict(),
            "optimal": self.optimal_peak.to_dict(),
            "n_evaluations": self.n_evaluations,
            "success": self.success,
            "message": self.message,
        }

    def to_xarray(self) -> Any:
        """The movable masses' coordinates at both layouts as an ``xarray.Dataset``.

        Dims ``mass`` (the masses' keys) and ``layout`` (``initial``, ``optimal``):
        ``position_m`` (m), ``lower_m``/``upper_m`` bounds; the objective (g) per layout.
        """
        import xarray as xr

        keys = [mm.key for mm in self.masses]
        pos = np.column_stack([self.initial, self.optimal]).reshape(len(keys), 2)
        bounds = np.array([mm.bounds for mm in self.masses], float).reshape(len(keys), 2)
        obj = np.array([self.objective_initial, self.objective_optimal]) / G0
        return xr.Dataset(
            {
                "position_m": (("mass", "layout"), pos, {"units": "m"}),
                "lower_m": ("mass", bounds[:, 0], {"units": "m"}),
                "upper_m": ("mass", bounds[:, 1], {"units": "m"}),
                "objective_g": ("layout", obj, {"units": "g", "measure": self.measure}),
            },
            coords={"mass": keys, "layout": ["initial", "optimal"]},
            attrs={
                "model": self.model,
                "experiment_point": self.experiment,
                "crew_point": self.crew,
                "measure": self.measure,
                "n_evaluations": self.n_evaluations,
                "success": int(self.success),
            },
        )

    def plot(self, ax: Any = None) -> Any:
        """Peaks at the site before and after (:func:`microg.plotting.location.plot_layout`).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.location import plot_layout

        return plot_layout(self, ax=ax)


# --------------------------------------------------------------------------- the masses


def _carriers(station: Station) -> list[RigidBody | Beam]:
    return [*station.bodies, *station.beams]


def resolve_mass(station: Station, key: str) -> tuple[RigidBody | Beam, PointMass]:
    """The carrier and point mass named ``key`` (``"name"`` if unique, else ``"carrier/name"``).

    Raises InputError (``where="movable"``) for an unknown or ambiguous name, listing the
    choices.
    """
    hits = []
    for comp in _carriers(station):
        for pm in comp.masses:
            if key in (pm.name, f"{comp.name}/{pm.name}"):
                hits.append((comp, pm))
    if len(hits) == 1:
        return hits[0]
    if not hits:
        names = sorted({pm.name for c in _carriers(station) for pm in c.masses})
        raise InputError(
            f"no point mass named {key!r}",
            where="movable",
            fix=f"known masses: {', '.join(names)}",
        )
    opts = ", ".join(f"{c.name}/{pm.name}" for c, pm in hits)
    raise InputError(f"mass name {key!r} is ambiguous", where="movable", fix=f"write one of {opts}")


def _body_extent(station: Station, body: RigidBody) -> tuple[float, float]:
    z = [float(pm.position[2]) for pm in body.masses]
    z += [float(b.root[2]) for b in station.beams if b.parent == body.name]
    if body.attach is not None:
        z.append(float(body.attach[2]))
    return (min(z), max(z)) if z else (0.0, 0.0)


def parse_movable(spec: str) -> tuple[str, str, str]:
    """Split ``"NAME=LO:HI"`` into ``(name, lo, hi)`` texts (lengths parsed later).

    Parameters
    ----------
    spec : str
        ``"Horizontal lab=-91ft:-5ft"``; ``NAME`` may be ``CARRIER/NAME``.
    """
    text = str(spec)
    name, sep, rng = text.rpartition("=")
    parts = rng.split(":")
    if not sep or not name.strip() or len(parts) != 2 or not all(p.strip() for p in parts):
        raise InputError(
            f"expected NAME=LO:HI, got {text!r}",
            where="movable",
            fix="e.g. 'Horizontal lab=-91ft:-5ft'",
        )
    return name.strip(), parts[0].strip(), parts[1].strip()


def _length(value: float | str, unit_system: str | None, where: str) -> float:
    """A length: a float is SI (m); a string has a unit, or is bare in the model's system."""
    from microg.units import parse_quantity

    if not isinstance(value, str):
        v = float(value)
        if not np.isfinite(v):
            raise InputError(f"{value!r} is not a finite length", where=where)
        return v
    default = None
    if unit_system is not None:
        from microg.models.toml import UNIT_SYSTEMS

        default = UNIT_SYSTEMS.get(unit_system, {}).get("length")
    try:
        return parse_quantity(value, "length", where=where, default_unit=default)
    except InputError as exc:
        if default is None and "has no unit" in exc.what:
            raise InputError(
                f"bare number {value!r} has no unit and the model declares no unit system",
                where=where,
                fix=f"write it with a unit, e.g. '{value} m' or '{value} ft', or declare "
                'units = "SI" or "US" in the model\'s [station]',
            ) from None
        raise


def movable_masses(
    station: Station,
    overrides: Mapping[str, tuple[float | str, float | str]] | None = None,
    *,
    unit_system: str | None = None,
) -> tuple[MovableMass, ...]:
    """The movable masses of ``station``: those marked in the file, plus/over ``overrides``.

    A beam mass moves along its beam (arc length s, within 0..length); a body mass moves
    along z within the body's extent (from the lowest to the highest of its masses, beam
    roots and attachment).  The range must contain the current position and have lo < hi.

    Parameters
    ----------
    station : Station
    overrides : mapping of mass key to (lo, hi)
        Keys as for :func:`resolve_mass`; they replace the file's ranges.  A float is m; a
        string is a length with a unit (``"-91 ft"``), or a bare number in the model's unit
        system (an error when the model declares none).
    unit_system : {"SI", "US"}, optional
        Unit system of bare numbers (default: the station's ``unit_system``, if it has one).
    """
    system = unit_system or getattr(station, "unit_system", None)
    chosen: dict[str, tuple[RigidBody | Beam, PointMass, tuple[float, float]]] = {}
    for comp in _carriers(station):
        for pm in comp.masses:
            if pm.movable is not None:
                chosen[f"{comp.name}/{pm.name}"] = (comp, pm, pm.movable)
    for key, rng in (overrides or {}).items():
        comp, pm = resolve_mass(station, key)
        full = f"{comp.name}/{pm.name}"
        if len(rng) != 2:
            raise InputError(f"expected (lo, hi), got {rng!r}", where=f"movable {full}")
        lo = _length(rng[0], system, f"movable {full}")
        hi = _length(rng[1], system, f"movable {full}")
        chosen[full] = (comp, pm, (lo, hi))
    if len(chosen) > MAX_MOVABLE:
        raise InputError(
            f"{len(chosen)} movable masses, at most {MAX_MOVABLE}",
            where="movable",
            fix="move fewer masses at once",
        )
    out = []
    for key, (comp, pm, (lo, hi)) in chosen.items():
        where = f"movable {key}"
        if isinstance(comp, Beam):
            kind, value, span = "beam", comp.arc_length(pm.position), (0.0, comp.length)
            what = f"beam {comp.name!r} (s from 0 to {comp.length:.6g} m)"
        else:
            kind, value, span = "body", float(pm.position[2]), _body_extent(station, comp)
            what = f"body {comp.name!r} (z from {span[0]:.6g} to {span[1]:.6g} m)"
        tol = 1e-9 * max(abs(span[0]), abs(span[1]), 1.0)
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise InputError(f"need LO < HI, got {lo:.6g}:{hi:.6g} m", where=where)
        if lo < span[0] - tol or hi > span[1] + tol:
            raise InputError(
                f"range {lo:.6g}:{hi:.6g} m leaves the {what}", where=where, fix="narrow the range"
            )
        if not lo - tol <= value <= hi + tol:
            raise InputError(
                f"range {lo:.6g}:{hi:.6g} m does not contain the mass's position {value:.6g} m",
                where=where,
                fix="widen the range",
            )
        lo, hi = max(lo, span[0]), min(hi, span[1])
        out.append(MovableMass(key, comp.name, pm.name, kind, value, (lo, hi)))
    return tuple(out)


def _new_position(comp: RigidBody | Beam, pm: PointMass, v: float) -> np.ndarray:
    if isinstance(comp, Beam):
        return np.asarray(comp.station_position(float(v)), float)
    return np.array([pm.position[0], pm.position[1], float(v)])


def move_masses(
    station: Station,
    masses: Sequence[MovableMass],
    values: np.ndarray,
    *,
    carry: Mapping[str, str] | None = None,
) -> Station:
    """A copy of ``station`` with each movable mass at its new coordinate (m).

    Parameters
    ----------
    station : Station
    masses : sequence of MovableMass
    values : ndarray (k,)
        New coordinates, m (z for body masses, s for beam masses).
    carry : mapping of point name to mass key, optional
        Named points that move with a mass (an experiment inside a module).
    """
    values = np.asarray(values, float)
    new_pos: dict[tuple[str, str], np.ndarray] = {}
    shift: dict[str, np.ndarray] = {}
    for mm, v in zip(masses, values, strict=True):
        comp = station.component(mm.carrier)
        pm = next(p for p in comp.masses if p.name == mm.name)
        pos = _new_position(comp, pm, v)
        new_pos[(mm.carrier, mm.name)] = pos
        shift[mm.key] = pos - pm.position

    def moved(comp: RigidBody | Beam) -> tuple[PointMass, ...]:
        return tuple(
            dataclasses.replace(pm, position=new_pos[(comp.name, pm.name)])
            if (comp.name, pm.name) in new_pos
            else pm
            for pm in comp.masses
        )

    bodies = tuple(dataclasses.replace(b, masses=moved(b)) for b in station.bodies)
    beams = tuple(dataclasses.replace(b, masses=moved(b)) for b in station.beams)
    points: tuple[NamedPoint, ...] = station.points
    if carry:
        keyed = {mm.key: mm for mm in masses}
        pts = []
        for p in station.points:
            key = carry.get(p.name)
            if key is not None and key in keyed:
                p = dataclasses.replace(p, position=p.position + shift[key])
            pts.append(p)
        points = tuple(pts)
    return dataclasses.replace(station, bodies=bodies, beams=beams, points=points)


# --------------------------------------------------------------------------- objective


def _default_force(force: Any, station: Station | None = None) -> Any:
    """The force of a spec, an object or None (the report's push-off)."""
    from microg.dynamics.forces import crew_force

    return crew_force(force, bare_units=spec_units(station))


def layout_objective(
    station: Station,
    experiment: str,
    crew: str,
    force: CrewPushoff | Any | None = None,
    *,
    method: str = DEFAULTS["method"],
    plane: str = DEFAULTS["plane"],
    n: int | None = None,
    direction: str | np.ndarray | None = None,
    zeta: float = DEFAULTS["zeta"],
) -> SitePeak:
    """The peaks at the experiment site for the layout of ``station`` (the reference route).

    ``discretize(station, method, plane=..., n=n, gravity_gradient=False)``, then
    ``solve_modes``, then :func:`~microg.location.site.point_peak`: the total peak over time
    (rigid + elastic), its elastic and rigid parts, and the bound (rigid + Eq. 3.1 summed
    over the elastic modes, exact [A]max).

    Parameters
    ----------
    station : Station
    experiment, crew : str
        Named points (experiment site, crew force).
    force : str, CrewPushoff or ForceHistory, optional
        N, or a spec of :func:`~microg.dynamics.forces.crew_force` (default: the report's
        push-off).
    method : {"ritz", "fem"}
    plane : {"xz", "yz", "3d"}
    n : int, optional
        Functions or elements per beam.
    direction : str or ndarray (3,), optional
        Force direction (default: the plane's lateral axis).
    zeta : float
        Modal damping ratio of the elastic modes (0: the exact undamped [A]max per mode).
    """
    from microg.dynamics.modes import solve_modes

    structure, d = location_structure(station, method, plane, n, direction)
    for name, where in ((experiment, "experiment"), (crew, "crew")):
        if name not in structure.points:
            known = ", ".join(sorted(structure.points))
            raise InputError(f"unknown point {name!r}", where=where, fix=f"known points: {known}")
    modes = solve_modes(structure)
    force = _default_force(force, station)
    return point_peak(structure, modes, experiment, crew, d, force, zeta=zeta)


class _RitzLayout:
    """Assumed-modes structures of trial layouts, re-assembling only what moved masses change.

    ``M(x) = M_0 + sum_k (m_k T_k(x)^T T_k(x) + R_k(x)^T I_k R_k(x))``: ``M_0`` is assembled
    once without the movable masses, and each moved mass adds its point-mass terms (Eq. 2.5)
    with the translation and rotation maps ``T_k``, ``R_k`` of its new position.  The
    coordinates, the stiffness (free-free: no gravity gradient) and the rigid-body vectors do
    not depend on where a mass sits.  On a rigid body the maps are affine in the position
    (``T(p) = t + theta x (p - p_root)``, ``R`` constant), so they are built once from four
    positions; on a beam they are recomputed by :func:`~microg.structure.ritz.point_maps`.
    """

    def __init__(
        self,
        station: Station,
        masses: Sequence[MovableMass],
        carry: Mapping[str, str],
        points: Sequence[str],
        plane: str,
        n: int | None,
        direction: np.ndarray,
    ):
        from microg.structure.ritz import assemble

        base, _ = location_structure(station, "ritz", plane, n, direction)
        self.base = base
        self.coords = list(base.meta["coordinates"])
        self.station = station
        self.masses = tuple(masses)
        self.carry = dict(carry)
        self.points = tuple(points)
        moving = {(mm.carrier, mm.name) for mm in masses}

        def strip(comp: Any) -> Any:
            keep = tuple(pm for pm in comp.masses if (comp.name, pm.name) not in moving)
            return dataclasses.replace(comp, masses=keep)

        stripped = dataclasses.replace(
            station,
            bodies=tuple(strip(b) for b in station.bodies),
            beams=tuple(strip(b) for b in station.beams),
        )
        self.mass0, self.stiff = assemble(stripped, self.coords, gravity_gradient=False)
        self.pms = [
            next(p for p in station.component(mm.carrier).masses if p.name == mm.name)
            for mm in masses
        ]
        # what moves: the masses (by index) and the wanted named points, each on a carrier
        self.tracked = [(f"\0mass{k}", mm.carrier) for k, mm in enumerate(masses)]
        self.tracked += [(p, station.point(p).on) for p in self.points]
        self.affine: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}
        probes = []
        eye = np.eye(3)
        for name, on in self.tracked:
            if isinstance(station.component(on), RigidBody):
                probes += [
                    NamedPoint(f"{name}\0{i}", on, eye[i - 1] if i else np.zeros(3))
                    for i in range(4)
                ]
        if probes:
            maps = self._maps(station, probes)
            for name, on in self.tracked:
                if isinstance(station.component(on), RigidBody):
                    m = [maps[f"{name}\0{i}"] for i in range(4)]
                    dt = np.stack([m[i].translation - m[0].translation for i in (1, 2, 3)])
                    self.affine[name] = (np.zeros(3), m[0].translation, dt, m[0].rotation)

    def _maps(self, station: Station, points: Sequence[NamedPoint]) -> dict[str, Any]:
        from microg.structure.ritz import point_maps

        return point_maps(dataclasses.replace(station, points=tuple(points)), self.coords)

    def structure(self, x: np.ndarray) -> Structure:
        """The structure of the layout with coordinates ``x`` (m), named points only."""
        from microg.structure.structure import PointMap

        st = move_masses(self.station, self.masses, x, carry=self.carry)
        where: dict[str, tuple[str, np.ndarray]] = {}
        for k, (mm, pm, v) in enumerate(zip(self.masses, self.pms, x, strict=True)):
            where[f"\0mass{k}"] = (mm.carrier, _new_position(st.component(mm.carrier), pm, v))
        for p in self.points:
            pt = st.point(p)
            where[p] = (pt.on, np.asarray(pt.position, float))
        maps: dict[str, PointMap] = {}
        beam_probes = [
            NamedPoint(name, on, pos)
            for name, (on, pos) in where.items()
            if name not in self.affine
        ]
        if beam_probes:
            maps.update(self._maps(st, beam_probes))
        for name, (p0, t0, dt, rot) in self.affine.items():
            pos = where[name][1]
            maps[name] = PointMap(name, pos, t0 + np.einsum("i,ian->an", pos - p0, dt), rot)
        mass = self.mass0.copy()
        for k, pm in enumerate(self.pms):
            pmap = maps[f"\0mass{k}"]
            mass += pm.mass * pmap.translation.T @ pmap.translation
            mass += pmap.rotation.T @ pm.inertia @ pmap.rotation
        total, cm, inertia = st.mass_properties()
        return Structure(
            mass=0.5 * (mass + mass.T),
            stiffness=self.stiff,
            dof_labels=self.base.dof_labels,
            points={
                p: PointMap(p, maps[p].position, maps[p].translation, maps[p].rotation)
                for p in self.points
            },
            rigid_body=self.base.rigid_body,
            method=self.base.method,
            plane=self.base.plane,
            total_mass=total,
            center_of_mass=cm,
            inertia_cm=inertia,
            samples=None,
            meta=self.base.meta,
        )


# --------------------------------------------------------------------------- optimiser


def _check_int(value: Any, lo: int, hi: int, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InputError(f"must be an integer, got {value!r}", where=where)
    if not lo <= int(value) <= hi:
        raise InputError(f"must be in {lo}..{hi}, got {value}", where=where)
    return int(value)


def optimize_layout(
    station: Station,
    experiment: str | None = None,
    crew: str | None = None,
    force: CrewPushoff | Any | None = None,
    *,
    movable: Mapping[str, tuple[float | str, float | str]] | None = None,
    carry: Mapping[str, str] | None = None,
    method: str = DEFAULTS["method"],
    plane: str = DEFAULTS["plane"],
    n: int | None = None,
    direction: str | np.ndarray | None = None,
    zeta: float = DEFAULTS["zeta"],
    measure: str = DEFAULTS["measure"],
    seed: int = DEFAULTS["seed"],
    maxiter: int = DEFAULTS["maxiter"],
    popsize: int = DEFAULTS["popsize"],
    polish: bool = DEFAULTS["polish"],
    unit_system: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> LayoutResult:
    """Move the movable masses to minimise the crew-induced peak at an experiment site.

    The objective is the site's ``measure`` (default ``total``: the peak over time of the
    modal sum, rigid-body modes included) from :func:`~microg.location.site.point_peak`, on
    the layout's model (report conclusion 9).  A seeded
    ``scipy.optimize.differential_evolution`` over the bounds finds the basin (the elastic
    part is multimodal: it is near zero wherever a node of a mode crosses the site), then
    L-BFGS-B polishes it inside the same bounds; the better point is kept, and never one
    worse than the start.

    Parameters
    ----------
    station : Station
    experiment : str, optional
        Named experiment site (default: the model's first point of kind experiment).
    crew : str, optional
        Named point of the crew force (default: the model's first point of kind crew).
    force : str, CrewPushoff or ForceHistory, optional
        N, or a spec of :func:`~microg.dynamics.forces.crew_force` (``microg analyze
        --force``'s grammar; bare values take the station's unit system); default: the
        report's push-off, 25 lbf.
    movable : mapping of mass key to (lo, hi), optional
        Ranges overriding/adding to the file's ``movable`` ranges (see
        :func:`movable_masses`; floats are m, strings lengths with units).
    carry : mapping of point name to mass key, optional
        Named points that move with a mass.
    method : {"ritz", "fem"}
        Discretisation (default :data:`microg.defaults.LAYOUT_METHOD`, ``ritz``: assumed
        modes, re-assembled incrementally; ``fem`` re-meshes and re-solves every trial).
    plane : {"xz", "yz", "3d"}
        Default :data:`microg.defaults.PLANE`.
    n : int, optional
        Functions or elements per beam (default: the discretisation's; 1 function is the
        report's model).
    direction : str or ndarray (3,), optional
        Force direction (default: the plane's lateral axis).
    zeta : float
        Modal damping ratio of the elastic modes, 0 <= zeta < 1 (default
        :data:`microg.defaults.DAMPING`; 0: the exact undamped [A]max per mode).
    measure : {"total", "elastic", "bound"}
        The objective.
    seed : int
        Seed of the differential evolution (results are reproducible).
    maxiter : int
        Differential-evolution generations, 1 to :data:`MAX_GENERATIONS`.
    popsize : int
        Population multiplier, 1 to :data:`MAX_POPSIZE`.
    polish : bool
        Run the L-BFGS-B polish.
    unit_system : {"SI", "US"}, optional
        Unit system of bare numbers in ``movable`` (default: the station's).
    progress : callable (generation, maxiter) -> None, optional
        Called after each generation.
    """
    from scipy.optimize import differential_evolution, minimize

    from microg.dynamics.modes import solve_modes

    if measure not in LAYOUT_MEASURES:
        raise InputError(
            f"unknown measure {measure!r}", where="measure", fix="use total, elastic or bound"
        )
    maxiter = _check_int(maxiter, 1, MAX_GENERATIONS, "maxiter")
    popsize = _check_int(popsize, 1, MAX_POPSIZE, "popsize")
    seed = _check_int(seed, 0, 2**32 - 1, "seed")
    if method not in ("ritz", "fem"):
        raise InputError(f"unknown method {method!r}", where="method", fix="use ritz or fem")
    experiment = experiment or default_point(station, "experiment", "experiment")
    crew = crew or default_point(station, "crew", "crew")
    force = _default_force(force, station)
    masses = movable_masses(station, movable, unit_system=unit_system)
    if not masses:
        raise InputError(
            "no movable masses",
            where="movable",
            fix='mark masses movable in the model file or give movable ranges "NAME=LO:HI"',
        )
    keys = {mm.key for mm in masses}
    carry_full = {}
    for point, key in (carry or {}).items():
        check_point(station, point, "carry")
        try:
            comp, pm = resolve_mass(station, key)
        except InputError as exc:
            raise InputError(exc.what, where=f"carry {point}", fix=exc.fix) from None
        carry_full[point] = f"{comp.name}/{pm.name}"
        if carry_full[point] not in keys:
            raise InputError(
                f"mass {key!r} is not movable",
                where=f"carry {point}",
                fix="give it a movable range",
            )
    check_point(station, experiment, "experiment")
    check_point(station, crew, "crew")
    _, d = location_structure(station, method, plane, n, direction)
    x0 = np.array([mm.value for mm in masses])
    lo = np.array([mm.bounds[0] for mm in masses])
    hi = np.array([mm.bounds[1] for mm in masses])
    fast = (
        _RitzLayout(station, masses, carry_full, (experiment, crew), plane, n, d)
        if method == "ritz"
        else None
    )
    count = [0]

    def evaluate(x: np.ndarray) -> SitePeak:
        count[0] += 1
        x = np.clip(np.asarray(x, float), lo, hi)
        if fast is not None:
            s = fast.structure(x)
            return point_peak(s, solve_modes(s), experiment, crew, d, force, zeta=zeta)
        st = move_masses(station, masses, x, carry=carry_full)
        return layout_objective(
            st, experiment, crew, force, method=method, plane=plane, n=n, direction=d, zeta=zeta
        )

    def fun(x: np.ndarray) -> float:
        return evaluate(x).measure(measure)

    generation = [0]

    def callback(intermediate_result: Any) -> None:
        generation[0] += 1
        if progress is not None:
            progress(generation[0], maxiter)

    bounds = list(zip(lo, hi, strict=True))
    j0 = fun(x0)
    de = differential_evolution(
        fun,
        bounds,
        seed=seed,
        maxiter=maxiter,
        popsize=popsize,
        tol=1e-8,
        polish=False,
        init="sobol",
        callback=callback,
    )
    best_x, best_f = np.asarray(de.x, float), float(de.fun)
    message, success = str(de.message), bool(de.success)
    if polish:
        loc = minimize(fun, best_x, method="L-BFGS-B", bounds=bounds)
        if loc.fun < best_f:
            best_x, best_f = np.asarray(loc.x, float), float(loc.fun)
            message += f"; L-BFGS-B: {loc.message}"
    if j0 <= best_f:  # never report a layout worse than the start
        best_x, best_f = x0.copy(), j0
    best_x = np.clip(best_x, lo, hi)
    st_opt = move_masses(station, masses, best_x, carry=carry_full)
    peak1 = layout_objective(
        st_opt, experiment, crew, force, method=method, plane=plane, n=n, direction=d, zeta=zeta
    )
    peak0_ref = layout_objective(
        move_masses(station, masses, x0, carry=carry_full),
        experiment,
        crew,
        force,
        method=method,
        plane=plane,
        n=n,
        direction=d,
        zeta=zeta,
    )
    return LayoutResult(
        model=station.name,
        experiment=experiment,
        crew=crew,
        method=method,
        plane=plane,
        n=n,
        direction=d,
        force=force,
        measure=measure,
        masses=masses,
        initial=x0,
        optimal=best_x,
        objective_initial=peak0_ref.measure(measure),
        objective_optimal=peak1.measure(measure),
        initial_peak=peak0_ref,
        optimal_peak=peak1,
        n_evaluations=count[0],
        success=success,
        message=message,
        station=st_opt,
    )
