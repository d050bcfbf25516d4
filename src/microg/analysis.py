"""The main job: a station's microgravity environment under crew disturbances.

:func:`analyze` is the public entry (``microg.analyze``); ``microg analyze`` on the command
line parses its options and calls it.  It loads or takes a model, discretises it through
:func:`microg.structure.discretize.discretize`, solves the free-free modes, applies the
disturbances (exact piecewise-linear modal response, damped modes, rigid-body modes
included), assesses the acceleration at the observed points against a requirement, and
advises isolation where a point does not comply.  It returns one :class:`Analysis`; the
CLI and the HTML report only read it.

Every default lives here, once (:data:`DEFAULTS`).  Inputs that would make a verdict
meaningless are refused (:class:`~microg.errors.InputError` naming the parameter); inputs
that make it shaky put a line in :attr:`Analysis.warnings`.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._vectors import axis_name, parse_direction
from microg.dynamics.dense import blas_threads
from microg.dynamics.forces import ForceHistory, parse_force_spec
from microg.dynamics.modes import DEFAULT_N_MODES, Modes, solve_modes
from microg.dynamics.peaks import PeakResponse
from microg.dynamics.response import PointResponse, generalized_force_vector
from microg.dynamics.superposition import ModalLoad, superpose
from microg.environment.metrics import Assessment, assess, band_mean_square
from microg.environment.requirements import (
    BandTable,
    Requirement,
)
from microg.errors import InputError
from microg.isolation.advise import IsolationAdvice, advise_isolation
from microg.structure.discretize import discretize
from microg.structure.structure import Structure
from microg.units import G0, LB, parse_quantity

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "DEFAULTS",
    "REPORT_LIMIT_G",
    "Disturbance",
    "AnalysisOptions",
    "ModeContributions",
    "Observation",
    "Analysis",
    "ModesReady",
    "analyze",
    "run_analysis",
]

#: the seed report's criterion: peak acceleration below 1e-5 g (Introduction)
REPORT_LIMIT_G = 1e-5
#: largest number of output samples of one analysis (memory: ~100 bytes per sample and mode)
MAX_SAMPLES = 2_000_000
#: interval over which the requirement's band RMS is stated (PIMS judges 100-s intervals)
REQUIREMENT_INTERVAL_S = 100.0
#: ... and when vibratory sources are assessed (their bands reach 300 Hz)
DEFAULT_SOURCE_MODES = 300
#: the defaults of :func:`analyze` and ``microg analyze``, SI
DEFAULTS: dict[str, Any] = {
    "force": "crew-pushoff",
    "direction": "x",
    "method": "fem",
    "plane": "3d",
    "damping": 0.005,
    "max_freq_hz": 10.0,
    "duration_s": 200.0,
    "dt_s": 0.01,
    "requirement": "iss",
    "package_mass_kg": 1000.0 * LB,
    "gravity_gradient": False,
}


@dataclass(frozen=True)
class Disturbance:
    """A force history applied at a named point.

    Attributes
    ----------
    force : ForceHistory
        Breakpoints (s, N).
    point : str
        Named point of the model where it acts.
    direction : ndarray (3,)
        Unit vector of the force in the station frame (a CSV force's own direction wins).
    """

    force: ForceHistory
    point: str
    direction: np.ndarray

    @property
    def unit_direction(self) -> np.ndarray:
        """The direction used: the force's own (CSV) direction if it has one, unit length.

        For a vector force (a direction that varies in time) it is the direction at the
        largest force, for display; the response uses every component.
        """
        if self.force.is_vector:
            vec = self.force.components()
            return parse_direction(vec[:, int(np.argmax(np.linalg.norm(vec, axis=0)))], "force")
        d = self.force.direction if self.force.direction is not None else self.direction
        return parse_direction(np.asarray(d, float), "direction")


@dataclass(frozen=True)
class AnalysisOptions:
    """Everything the main job needs besides the model, SI (defaults: :data:`DEFAULTS`).

    Attributes
    ----------
    disturbances : sequence of Disturbance
        Applied together (superposed).
    observe : sequence of str
        Named points to assess.
    method : str
        ``"fem"`` (3-D frame elements) or ``"ritz"`` (assumed modes).
    plane : str
        ``"3d"``, or ``"xz"``/``"yz"`` for the report's planar ``ritz`` model.
    n : int or None
        Elements per beam (fem) or functions per beam (ritz); None: the discretisation's
        default.
    n_modes : int or None
        Modes to solve for sparse models (None: :data:`~microg.dynamics.modes.DEFAULT_N_MODES`).
    zeta : float
        Modal damping ratio of the elastic modes.
    max_freq_hz : float
        Elastic modes up to this frequency enter the response (rigid-body modes always).
    duration_s : float
        Length of the output record, s.
    dt_s : float
        Output sample interval, s.
    requirement : str
        Name of the band requirement (``"iss"`` or ``"flat"``).
    package_mass_kg : float
        Experiment package mass for the isolation advice, kg.
    absorber_mu : float or None
        Absorber mass ratio for the isolation advice (None: spring only).
    isolation : bool
        Advise isolation where a point does not comply.
    gravity_gradient : bool
        Restrain the rigid rotations by the gravity-gradient (libration) stiffness.
    sources : SourceCatalogue or None
        Continuous vibratory sources, assessed in the frequency domain beside (or, with no
        disturbance, instead of) the transient response.
    """

    disturbances: Sequence[Disturbance]
    observe: Sequence[str]
    method: str = DEFAULTS["method"]
    plane: str = DEFAULTS["plane"]
    n: int | None = None
    n_modes: int | None = None
    zeta: float = DEFAULTS["damping"]
    max_freq_hz: float = DEFAULTS["max_freq_hz"]
    duration_s: float = DEFAULTS["duration_s"]
    dt_s: float = DEFAULTS["dt_s"]
    requirement: str = DEFAULTS["requirement"]
    package_mass_kg: float = DEFAULTS["package_mass_kg"]
    absorber_mu: float | None = None
    isolation: bool = True
    gravity_gradient: bool = DEFAULTS["gravity_gradient"]
    sources: Any = None


@dataclass(frozen=True)
class ModeContributions:
    """What each mode contributes at one observed point: which mode to stiffen or detune.

    Attributes
    ----------
    mode : ndarray of int (k,)
        Mode numbers (1-based, as in the modes table) of the modes in the response.
    freq_hz : ndarray (k,)
        Their frequencies, Hz.
    at_peak_g : ndarray (k,)
        Each mode's acceleration at the instant of the peak, projected on the peak's
        direction, g.  They sum to the peak magnitude.
    own_peak_g : ndarray (k,)
        Each mode's own largest acceleration magnitude over the record, g.
    worst_band_rms_g : ndarray (k,) or None
        Each mode's band RMS in the worst band on the worst axis, g (None when no band).
    worst_band_hz : float or None
        Centre of that band, Hz.
    worst_axis : str or None
    """

    mode: np.ndarray
    freq_hz: np.ndarray
    at_peak_g: np.ndarray
    own_peak_g: np.ndarray
    worst_band_rms_g: np.ndarray | None
    worst_band_hz: float | None
    worst_axis: str | None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready table, one row per mode."""
        rows = []
        for i in range(self.mode.size):
            row: dict[str, Any] = {
                "mode": int(self.mode[i]),
                "freq_hz": float(self.freq_hz[i]),
                "at_peak_g": float(self.at_peak_g[i]),
                "own_peak_g": float(self.own_peak_g[i]),
            }
            if self.worst_band_rms_g is not None:
                row["worst_band_rms_g"] = float(self.worst_band_rms_g[i])
            rows.append(row)
        return {"worst_band_hz": self.worst_band_hz, "worst_axis": self.worst_axis, "modes": rows}

    def to_xarray(self) -> Any:
        """The table as an ``xarray.Dataset`` over ``mode`` (g; ``freq_hz`` a coordinate)."""
        import xarray as xr

        data: dict[str, Any] = {
            "at_peak_g": ("mode", self.at_peak_g, {"units": "g"}),
            "own_peak_g": ("mode", self.own_peak_g, {"units": "g"}),
        }
        if self.worst_band_rms_g is not None:
            data["worst_band_rms_g"] = ("mode", self.worst_band_rms_g, {"units": "g"})
        attrs: dict[str, Any] = {"worst_axis": self.worst_axis or ""}
        if self.worst_band_hz is not None:
            attrs["worst_band_hz"] = float(self.worst_band_hz)
        return xr.Dataset(
            data,
            coords={
                "mode": ("mode", self.mode, {"units": "1"}),
                "freq_hz": ("mode", self.freq_hz, {"units": "Hz"}),
            },
            attrs=attrs,
        )


@dataclass(frozen=True)
class Observation:
    """The result at one observed point.

    Attributes
    ----------
    name : str
    response : PointResponse
        Displacement, velocity and acceleration (3 axes, SI) at the output times.
    assessment : Assessment
        Peak, RMS, bands, margins, integrated acceleration against the requirement.
    isolation : IsolationAdvice
    contributions : ModeContributions
    interval : dict
        Band margins over consecutive intervals of :data:`REQUIREMENT_INTERVAL_S`.
    peak : PeakResponse
        The certified true maximum of the exact acceleration over the record (between
        samples and at both sides of every force jump); ``assessment.peak_accel_g`` is it.
    """

    name: str
    response: PointResponse
    assessment: Assessment
    isolation: IsolationAdvice
    contributions: ModeContributions
    interval: Mapping[str, Any]
    peak: PeakResponse | None = None

    @property
    def peak_accel_g(self) -> float:
        """Peak of the acceleration magnitude, g."""
        return float(self.assessment.peak_accel_g)

    @property
    def complies(self) -> bool:
        """The band verdict at this point."""
        return bool(self.assessment.complies)

    def to_dict(self) -> dict[str, Any]:
        """The observation block of ``microg analyze --json``."""
        d = self.assessment.to_dict()
        d["report_criterion"] = {
            "limit_g": REPORT_LIMIT_G,
            "peak_within": bool(self.assessment.peak_accel_g <= REPORT_LIMIT_G),
        }
        d["requirement_interval"] = dict(self.interval)
        if self.peak is not None:
            d["peak"] = self.peak.to_dict()
        d["mode_contributions"] = self.contributions.to_dict()
        d["isolation"] = self.isolation.to_dict()
        return d

    def to_xarray(self) -> Any:
        """The acceleration history as an ``xarray.DataArray`` ``accel_mps2`` (axis, time)."""
        import xarray as xr

        r = self.response
        return xr.DataArray(
            r.acceleration,
            dims=("axis", "time"),
            coords={
                "axis": ["x", "y", "z"],
                "time": ("time", r.timepts, {"units": "s"}),
            },
            name="accel_mps2",
            attrs={"units": "m/s^2", "point": self.name, "long_name": "acceleration"},
        )

    def plot(self) -> Figure:
        """Acceleration history and 1/3-octave bands against the requirement (a Figure)."""
        from microg.plotting.analysis import observation_figure

        return observation_figure(self)


@dataclass(frozen=True)
class ModesReady:
    """The main job part-way: the structure and its modes, before any response.

    What :func:`run_analysis` hands its ``on_modes`` callback as soon as the modes are
    solved; the same values become the :class:`Analysis`'s fields of these names.

    Attributes
    ----------
    model : str
        Model name.
    options : AnalysisOptions
    structure : Structure
    modes : Modes
    used : ndarray of bool
        Modes that enter the response (rigid-body modes and elastic ones up to
        ``options.max_freq_hz``).
    """

    model: str
    options: AnalysisOptions
    structure: Structure
    modes: Modes
    used: np.ndarray


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`analyze`.

    Attributes
    ----------
    model : str
        Model name.
    options : AnalysisOptions
    structure : Structure
    modes : Modes
        All computed modes (``used`` marks those in the response).
    used : ndarray of bool
        Modes kept for the response (rigid + elastic up to ``max_freq_hz``).
    observations : dict of str to Observation
    timepts : ndarray
        Output times, s.
    requirement : Requirement
    warnings : list of str
        What makes the verdict shaky; shown in the JSON, the console and the report.
    notes : list of str
    meta : dict
        Provenance: microg version, UTC time, command, model path and sha256.
    frequency_domain : VibratoryAssessment or None
        The vibratory sources' band table per observed point (frequency domain), when sources
        were given.
    """

    model: str
    options: AnalysisOptions
    structure: Structure
    modes: Modes
    used: np.ndarray
    observations: dict[str, Observation]
    timepts: np.ndarray
    requirement: Requirement
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)
    frequency_domain: Any = None

    @property
    def complies(self) -> bool:
        """Every observed point meets the band requirement (transient and vibratory)."""
        ok = all(o.complies for o in self.observations.values())
        if self.frequency_domain is not None:
            ok = ok and bool(np.all(self.frequency_domain.complies))
        return ok

    @property
    def responses(self) -> dict[str, PointResponse]:
        """Response of each observed point."""
        return {n: o.response for n, o in self.observations.items()}

    @property
    def assessments(self) -> dict[str, Assessment]:
        """Assessment of each observed point."""
        return {n: o.assessment for n, o in self.observations.items()}

    @property
    def isolation(self) -> dict[str, IsolationAdvice]:
        """Isolation advice of each observed point."""
        return {n: o.isolation for n, o in self.observations.items()}

    def to_dict(self) -> dict[str, Any]:
        """The ``microg analyze --json`` contract (documented in docs/assessment.md)."""
        modes = self.modes.to_dict()
        for row, used in zip(modes["modes"], self.used, strict=True):
            row["used"] = bool(used)
        o = self.options
        return {
            "meta": dict(self.meta),
            "model": self.model,
            "method": self.structure.method,
            "plane": self.structure.plane,
            "modes": modes,
            "disturbances": [_disturbance_dict(d) for d in o.disturbances],
            "damping": o.zeta,
            "requirement": self.requirement.name,
            "requirement_source": self.requirement.source,
            "record": {
                "duration_s": o.duration_s,
                "dt_s": o.dt_s,
                "nyquist_hz": 0.5 / o.dt_s,
                "max_freq_hz": o.max_freq_hz,
            },
            "observations": {n: ob.to_dict() for n, ob in self.observations.items()},
            **self._frequency_dict(),
            "complies": self.complies,
            "report_criterion": {
                "limit_g": REPORT_LIMIT_G,
                "peak_within": all(
                    ob.assessment.peak_accel_g <= REPORT_LIMIT_G
                    for ob in self.observations.values()
                ),
            }
            if self.observations
            else None,
            "warnings": list(self.warnings),
            "notes": list(self.notes),
        }

    def _frequency_dict(self) -> dict[str, Any]:
        fd = self.frequency_domain
        if fd is None:
            return {}
        return {"frequency_domain": fd.to_dict(), "frequency_domain_basis": fd.info_dict()}

    def to_xarray(self) -> Any:
        """Every observed point's acceleration history in one ``xarray.Dataset``.

        ``accel_mps2`` over (point, axis, time), m/s^2, and the verdict numbers per point
        (``peak_accel_g``, ``complies``); the model, requirement and warnings in the attributes.
        """
        import xarray as xr

        names = list(self.observations)
        obs = [self.observations[n] for n in names]
        acc = (
            np.stack([o.response.acceleration for o in obs])
            if obs
            else np.zeros((0, 3, self.timepts.size))
        )
        return xr.Dataset(
            {
                "accel_mps2": (("point", "axis", "time"), acc, {"units": "m/s^2"}),
                "peak_accel_g": (
                    "point",
                    np.array([o.assessment.peak_accel_g for o in obs], float),
                    {"units": "g"},
                ),
                "complies": (
                    "point",
                    np.array([bool(o.assessment.complies) for o in obs], bool),
                    {"units": "1"},
                ),
            },
            coords={
                "point": names,
                "axis": ["x", "y", "z"],
                "time": ("time", self.timepts, {"units": "s"}),
            },
            attrs={
                "model": self.model,
                "requirement": str(getattr(self.requirement, "name", "")),
                "warnings": "\n".join(self.warnings),
            },
        )

    def plot(self) -> Figure:
        """The modes used and the peak at each observed point (a Figure)."""
        from microg.plotting.analysis import analysis_figure

        return analysis_figure(self)


def _disturbance_dict(d: Disturbance) -> dict[str, Any]:
    f = d.force
    vec = f.components(d.unit_direction)  # (3, nb), N
    direction = d.unit_direction
    dt = np.diff(f.timepts)
    impulse = np.sum(0.5 * (vec[:, 1:] + vec[:, :-1]) * dt, axis=1)  # trapezoids: exact (N s)
    out: dict[str, Any] = {
        "name": f.name,
        "at": d.point,
        "direction": None if f.is_vector else [float(v) for v in direction],
        "direction_axis": "varies (three components)" if f.is_vector else axis_name(direction),
        "peak_force_N": float(np.max(np.linalg.norm(vec, axis=0))),
        "impulse_Ns": float(np.linalg.norm(impulse)),
        "impulse_Ns_axis": dict(zip("xyz", (float(v) for v in impulse), strict=True)),
        "end_s": float(f.timepts[-1]),
        "final_force_N": float(np.linalg.norm(vec[:, -1])),
    }
    if f.params:
        out["params"] = {k: float(v) for k, v in f.params.items()}
    return out


# ----------------------------------------------------------------------------- inputs


def _si(value: Any, dimension: str, where: str, unit_system: str | None) -> float:
    """A float (SI) or a string (with a unit, or bare in the model's unit system) -> SI."""
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


def _as_list(value: Any) -> list[Any]:
    if value is None:
        return []
    if isinstance(value, str | ForceHistory | np.ndarray):
        return [value]
    if isinstance(value, Sequence):
        return list(value)
    return [value]


def _directions(value: Any) -> list[Any]:
    """Directions as a list; a single 3-vector of numbers is one direction."""
    if value is None:
        return []
    if isinstance(value, str | np.ndarray):
        return [value]
    items = list(value)
    if len(items) == 3 and all(
        isinstance(c, int | float | np.integer | np.floating) for c in items
    ):
        return [items]
    return items


def _forces(force: Any, unit_system: str | None = None) -> list[ForceHistory]:
    """Force histories from specs; bare parameter values take the model's unit system."""
    bare: dict[str, str] | None = None
    if unit_system is not None:
        from microg.models.toml import UNIT_SYSTEMS

        bare = UNIT_SYSTEMS.get(unit_system)
    specs = _as_list(force) or [DEFAULTS["force"]]
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


def _point_names(model: Any) -> list[tuple[str, str]]:
    """(name, kind) of the model's named points."""
    pts = getattr(model, "points", ())
    if isinstance(pts, Mapping):
        return [(n, getattr(p, "kind", "point")) for n, p in pts.items()]
    return [(p.name, getattr(p, "kind", "point")) for p in pts]


def _has_grids(model: Any) -> bool:
    """True for imported models whose grids are points too (``grid:N``)."""
    return hasattr(model, "grid_ids") or type(model).__name__ == "GraphModel"


def _point(structure: Structure, name: str, where: str) -> Any:
    """The structure's map of ``name``; an unknown name is an InputError naming ``where``."""
    try:
        return structure.point(name)
    except InputError as exc:
        raise InputError(exc.what, where=where, fix=exc.fix) from None


def _check_points(names: Sequence[str], known: Sequence[str], where: str) -> None:
    for p in names:
        if p not in known:
            raise InputError(
                f"unknown point {p!r}", where=where, fix=f"known points: {', '.join(known)}"
            )


def _load(model: Any) -> Any:
    if isinstance(model, str | Path):
        from microg.models.load import load_model

        return load_model(model)
    return model


def _sources(sources: Any) -> Any:
    """A source catalogue from a path, ``"example"`` or a catalogue object (None: none)."""
    if sources is None:
        return None
    if isinstance(sources, str | Path):
        from microg.environment.sources import load_sources

        return load_sources(sources)
    return sources


def _requirement(name: str | Requirement) -> Requirement:
    """A requirement object, or the one of that name (``iss``, ``ssp41000``, ``flat``)."""
    if isinstance(name, Requirement):
        return name
    from microg.environment.requirements import requirement as by_name

    return by_name(name)


def analyze(
    model: Any = "ioc",
    force: Any = None,
    at: str | Sequence[str] | None = None,
    direction: Any = None,
    observe: str | Sequence[str] | None = None,
    *,
    method: str = DEFAULTS["method"],
    plane: str = DEFAULTS["plane"],
    n: int | None = None,
    n_modes: int | None = None,
    damping: float = DEFAULTS["damping"],
    max_freq: float | str = DEFAULTS["max_freq_hz"],
    duration: float | str = DEFAULTS["duration_s"],
    dt: float | str = DEFAULTS["dt_s"],
    requirement: str | Requirement = DEFAULTS["requirement"],
    package_mass: float | str | None = None,
    absorber_mu: float | None = None,
    isolation: bool = True,
    gravity_gradient: bool = DEFAULTS["gravity_gradient"],
    sources: Any = None,
    progress: Callable[[str], None] | None = None,
    command: str | None = None,
    on_modes: Callable[[ModesReady], object] | None = None,
) -> Analysis:
    """The main job: modes, response to disturbances, compliance, isolation advice.

    Parameters
    ----------
    model : Station, modal model, str or Path
        A model object, a model file path or a shipped model name (default ``"ioc"``).
    force : str, ForceHistory, or a list of them
        Spec strings as on the command line (``"crew-pushoff"``,
        ``"crew-pushoff:f0=40lbf,t1=0.5s"``, a library activity, a CSV path) or force
        objects.  Default: the report's push-off.
    at : str or list of str
        Named point where each force acts (one for all, or one per force).  Default: the
        model's first point of kind ``crew``.
    direction : str, 3 numbers, or a list of them
        Force direction(s): ``"x"``, ``"-z"``, ``"1 0 0"``, ``[0, 1, 0]``.  Default ``"x"``.
    observe : str or list of str
        Named points to assess.  Default: the model's points of kind ``experiment`` (all
        points when it has none).
    method : {"fem", "ritz"}
    plane : {"3d", "xz", "yz"}
    n : int, optional
        Elements (fem) or functions (ritz) per beam.
    n_modes : int, optional
        Modes solved for sparse models.
    damping : float
        Modal damping ratio of the elastic modes, 0 <= zeta < 1.
    max_freq : float (Hz) or str
        Elastic modes up to this frequency enter the response.
    duration, dt : float (s) or str
        Record length and output sample interval.
    requirement : str or Requirement
        ``"iss"`` (the ISS vibratory requirement as PIMS codes it) or ``"flat"`` (the report's
        1e-5 g); or a Requirement object.
    package_mass : float (kg) or str
        Experiment package mass for the isolation advice (default 1000 lb).
    absorber_mu : float, optional
        Absorber mass ratio for the isolation advice.
    isolation : bool
        Advise isolation where a point does not comply.
    gravity_gradient : bool
        Restrain the rigid rotations by gravity gradient (libration).
    sources : str, Path or SourceCatalogue, optional
        A source catalogue (``[[source]]`` TOML, see :mod:`microg.environment.sources`, or
        ``"example"``): continuous vibratory sources assessed in the frequency domain.  With
        sources and no ``force``, only the frequency-domain analysis runs.
    progress : callable, optional
        Called with a stage name as each stage starts.
    command : str, optional
        The command line, for the provenance record.
    on_modes : callable, optional
        Called with a :class:`ModesReady` as soon as the modes are solved, before the
        response (``microg analyze`` starts drawing the model's figures then).

    Returns
    -------
    Analysis

    Notes
    -----
    A float is SI; a string is parsed, with its unit or, when bare, in the model's unit
    system.  Errors name the parameter (``duration``, ``observe``, ``force[1]``...).
    """
    mdl = _load(model)
    units = getattr(mdl, "unit_system", None)
    catalogue = _sources(sources)
    forces = [] if (catalogue is not None and force is None) else _forces(force, units)
    nf = len(forces)
    points = _point_names(mdl)
    known = [p for p, _ in points]
    at_list = [str(a) for a in _as_list(at)]
    if not at_list and nf:
        crew = [p for p, k in points if k == "crew"]
        if not crew:
            raise InputError(
                "the model has no crew point", where="at", fix=f"name one of: {', '.join(known)}"
            )
        at_list = [crew[0]]
    obs = [str(o) for o in _as_list(observe)]
    if not obs:
        obs = [p for p, k in points if k == "experiment"] or list(known)
    dirs = _directions(direction) or [DEFAULTS["direction"]]
    for name, vals in (("at", at_list), ("direction", dirs)):
        if nf and len(vals) not in (1, nf):
            raise InputError(
                f"{len(vals)} values for {nf} forces", where=name, fix="give one, or one per force"
            )
    if not _has_grids(mdl):  # grid names (grid:N) of imported models resolve on the structure
        _check_points(at_list, known, "at")
        _check_points(obs, known, "observe")
    if len(set(obs)) != len(obs):
        raise InputError("a point is observed twice", where="observe", fix="name each point once")
    dists = []
    for i, f in enumerate(forces):
        w = "direction" if len(dirs) == 1 else f"direction[{i}]"
        d = parse_direction(dirs[i if len(dirs) == nf else 0], w)
        dists.append(Disturbance(f, at_list[i if len(at_list) == nf else 0], d))
    if not (isinstance(damping, int | float) and 0.0 <= float(damping) < 1.0):
        raise InputError(f"must be 0 <= zeta < 1, got {damping!r}", where="damping")
    pm = (
        DEFAULTS["package_mass_kg"]
        if package_mass is None
        else _si(package_mass, "mass", "package_mass", units)
    )
    if not pm > 0:
        raise InputError(f"must be > 0, got {package_mass!r}", where="package_mass")
    if absorber_mu is not None and not (np.isfinite(absorber_mu) and absorber_mu > 0):
        raise InputError(f"must be > 0, got {absorber_mu!r}", where="absorber_mu")
    opts = AnalysisOptions(
        disturbances=dists,
        observe=obs,
        method=method,
        plane=plane,
        n=n,
        n_modes=n_modes,
        zeta=float(damping),
        max_freq_hz=_si(max_freq, "frequency", "max_freq", units),
        duration_s=_si(duration, "time", "duration", units),
        dt_s=_si(dt, "time", "dt", units),
        requirement=requirement.name if isinstance(requirement, Requirement) else requirement,
        package_mass_kg=pm,
        absorber_mu=absorber_mu,
        isolation=isolation,
        gravity_gradient=gravity_gradient,
        sources=catalogue,
    )
    return run_analysis(
        mdl,
        opts,
        progress=progress,
        requirement=requirement if isinstance(requirement, Requirement) else None,
        command=command,
        on_modes=on_modes,
    )


# ------------------------------------------------------------------------------ the job


def _check_record(opts: AnalysisOptions) -> None:
    if not opts.duration_s > 0:
        raise InputError(
            f"must be > 0, got {opts.duration_s:g} s",
            where="duration",
            fix="give the record's length, e.g. 200 s",
        )
    if not (opts.dt_s > 0 and opts.duration_s > opts.dt_s):
        raise InputError(
            f"need 0 < dt < duration, got dt = {opts.dt_s:g} s, duration = {opts.duration_s:g} s",
            where="dt",
        )
    if opts.duration_s / opts.dt_s > MAX_SAMPLES:
        raise InputError(
            f"{opts.duration_s / opts.dt_s:.3g} output samples is more than {MAX_SAMPLES:,}",
            where="duration",
            fix="shorten the duration or lengthen dt",
        )
    if not opts.max_freq_hz > 0:
        raise InputError(f"must be > 0, got {opts.max_freq_hz:g} Hz", where="max_freq")
    if not opts.disturbances and opts.sources is None:
        raise InputError("no disturbance", where="force", fix="give at least one force")
    for d in opts.disturbances:
        end = float(d.force.timepts[-1])
        if end > opts.duration_s:
            raise InputError(
                f"force {d.force.name!r} lasts until {end:g} s, after the {opts.duration_s:g}-s "
                "record ends: the response to the rest of it is not computed",
                where="duration",
                fix=f"use a duration of at least {end:g} s (and time for the response to decay)",
            )


def _structure(model: Any, opts: AnalysisOptions) -> Structure:
    if isinstance(model, Structure):
        return model
    return discretize(
        model, opts.method, plane=opts.plane, n=opts.n, gravity_gradient=opts.gravity_gradient
    )


def _force_warnings(opts: AnalysisOptions) -> list[str]:
    out = []
    for d in opts.disturbances:
        f = d.force
        vec = f.components(d.unit_direction)
        last = float(np.linalg.norm(vec[:, -1]))
        peak = float(np.max(np.linalg.norm(vec, axis=0)))
        if peak > 0 and abs(last) > 1e-9 * peak:
            impulse = f.impulse() + last * (opts.duration_s - f.timepts[-1])
            out.append(
                f"force {f.name!r} does not end at zero: it holds {last:.4g} N from "
                f"{f.timepts[-1]:g} s to the end of the record ({opts.duration_s:g} s); its "
                f"impulse over the record is {impulse:.4g}"
                " N s, and the station keeps accelerating (a quasi-steady load, not a transient)"
            )
    return out


def _scalar_parts(d: Disturbance) -> list[tuple[ForceHistory, np.ndarray]]:
    """A disturbance as scalar histories along fixed unit vectors.

    A scalar force is one history along its direction; a vector force (three components per
    breakpoint, a direction that varies in time) is its x, y and z components along the
    axes -- linear, so the response is their sum.
    """
    if not d.force.is_vector:
        return [(d.force, d.unit_direction)]
    vec = d.force.components()
    parts = []
    for i, axis in enumerate("xyz"):
        if np.any(vec[i]):
            comp = ForceHistory(d.force.timepts, vec[i], f"{d.force.name} ({axis})")
            parts.append((comp, np.eye(3)[i]))
    return parts


def _modal_forces(
    structure: Structure, modes: Modes, opts: AnalysisOptions
) -> tuple[list[ModalLoad], list[str]]:
    """The scalar loads of every disturbance; refuse a force that does no work."""
    loads: list[ModalLoad] = []
    warnings = []
    for i, d in enumerate(opts.disturbances):
        tmap = structure.point(d.point).translation
        where = "direction" if len(opts.disturbances) == 1 else f"direction[{i}]"
        plane = f" of the planar {structure.plane} model" if structure.plane else ""
        worked = False
        for f, u in _scalar_parts(d):
            b = generalized_force_vector(tmap, u)
            # the part of the force the model can carry: its projection on the point's motion
            reach = np.linalg.norm(tmap @ np.linalg.pinv(tmap) @ u) if tmap.size else 0.0
            if not np.any(b) or reach < 1e-9:
                if not d.force.is_vector:
                    raise InputError(
                        f"a force along {axis_name(u) or list(np.round(u, 6))} at {d.point!r} "
                        f"does no work on the model{plane}: the response would be zero",
                        where=where,
                        fix="give a direction the model can move in"
                        + (" (in the model's plane), or use the 3-D model" if plane else ""),
                    )
                warnings.append(f"{f.name} at {d.point!r} does no work on the model{plane}")
                continue
            if reach < 1 - 1e-9:
                inplane = f" (its plane is {structure.plane})" if structure.plane else ""
                warnings.append(
                    f"only {100 * reach:.3g}% of the force {f.name!r} at {d.point!r} acts on "
                    f"the model{inplane}; the rest is dropped"
                )
            loads.append(ModalLoad(f, modes.phi.T @ b))
            worked = True
        if not worked:
            raise InputError(
                f"the force {d.force.name!r} at {d.point!r} does no work on the model{plane}",
                where=where,
                fix="give a force the model can carry",
            )
    return loads, warnings


def _with_exact_peak(a: Assessment, peak: PeakResponse, req: Requirement) -> Assessment:
    """The assessment with its peaks replaced by the certified exact ones.

    The exact peak is at least the sampled one, so a verdict that passed a peak limit on the
    samples is re-judged on the exact value.
    """
    exact = float(peak.peak_accel_g)
    complies = a.complies
    if req.peak_limit_g is not None and exact > req.peak_limit_g:
        complies = False
    return replace(
        a,
        peak_accel_g=exact,
        peak_accel_g_axis=np.asarray(peak.peak_accel_g_axis, float),
        complies=complies,
    )


class _ModalSeries:
    """The modal accelerations (k, nt) of a run, with the per-mode quantities every point shares.

    A point's per-mode series is its map coefficient times the modal acceleration, so its
    peak and band RMS are ``|coefficient|`` times the modal one (the PSD scales with the
    square: demeaning, the periodogram and the band sum are linear in ``|X|^2``); these are
    computed once per run, not once per observed point.
    """

    def __init__(self, t: np.ndarray, acc: np.ndarray):
        self.t = t
        self.acc = acc
        self._peak: np.ndarray | None = None
        self._band: dict[float, np.ndarray] = {}

    def peak_abs(self) -> np.ndarray:
        """``max_t |acc_j(t)|`` per mode, m/s^2 (k,)."""
        if self._peak is None:  # max |x| = max(max x, -min x): no |acc| temporary
            self._peak = np.maximum(self.acc.max(axis=1), -self.acc.min(axis=1))
        return self._peak

    def band_rms(self, center_hz: float, lower_hz: float, upper_hz: float) -> np.ndarray:
        """RMS of each modal acceleration in one band, m/s^2 (k,)."""
        key = float(center_hz)
        if key not in self._band:
            bands = BandTable(np.array([center_hz]), np.array([lower_hz]), np.array([upper_hz]))
            ms = band_mean_square(self.t, self.acc, bands)[:, 0]
            self._band[key] = np.sqrt(np.maximum(ms, 0.0))
        return self._band[key]


def _contributions(
    mode_numbers: np.ndarray,
    m: Modes,
    tphi: np.ndarray,
    modal: _ModalSeries,
    a: Assessment,
    acc_at_peak: np.ndarray,
) -> ModeContributions:
    """Per-mode contributions at a point (``acc_at_peak``: modal accelerations at the peak).

    Mode j's own series at the point is ``tphi[:, j] acc_j(t)``: its peak magnitude is
    ``|tphi[:, j]| max_t |acc_j|`` and its band RMS on an axis ``|tphi[ax, j]|`` times the
    band RMS of ``acc_j`` (:class:`_ModalSeries`).
    """
    total = tphi @ acc_at_peak  # (3,)
    size = float(np.linalg.norm(total))
    u = total / size if size > 0 else np.zeros(3)
    at_peak = (u @ tphi) * acc_at_peak / G0
    own = np.linalg.norm(tphi, axis=0) * modal.peak_abs() / G0
    wb = a.worst_band
    band_rms_g = None
    band_hz = None
    axis = None
    if wb is not None and np.isfinite(wb.margin):
        ax = "xyz".index(wb.axis) if wb.axis in "xyz" else 0
        to = a.third_octave
        i = int(np.argmin(np.abs(to.center_hz - wb.center_hz)))
        rms = modal.band_rms(to.center_hz[i], to.lower_hz[i], to.upper_hz[i])
        band_rms_g = np.abs(tphi[ax]) * rms / G0
        band_hz = float(wb.center_hz)
        axis = wb.axis
    return ModeContributions(
        mode=mode_numbers,
        freq_hz=m.freq_hz,
        at_peak_g=at_peak,
        own_peak_g=own,
        worst_band_rms_g=band_rms_g,
        worst_band_hz=band_hz,
        worst_axis=axis,
    )


def _intervals(t: np.ndarray, accel: np.ndarray, req: Requirement) -> dict[str, Any]:
    """Worst band margin over consecutive intervals of REQUIREMENT_INTERVAL_S (PIMS practice).

    Uses :func:`microg.environment.intervals.interval_band_rms`; only bands one interval
    resolves are judged.
    """
    from microg.environment.intervals import interval_band_rms

    length = REQUIREMENT_INTERVAL_S
    if t.size * (t[1] - t[0]) < length:
        return {"interval_s": length, "count": 0, "min_margin": None, "worst_start_s": None}
    b = interval_band_rms(t, accel, req, interval_s=length)
    lim = b.limit_g[None, None, :]
    with np.errstate(divide="ignore"):
        margin = np.where(b.rms_g > 0, lim / np.where(b.rms_g > 0, b.rms_g, 1.0), np.inf)
    margin = np.where(b.resolved[None, None, :], margin, np.inf)
    per_interval = margin.min(axis=(1, 2))
    i = int(np.argmin(per_interval))
    worst = float(per_interval[i])
    return {
        "interval_s": length,
        "count": int(per_interval.size),
        "min_margin": worst if np.isfinite(worst) else "inf",
        "worst_start_s": float(b.t_start_s[i]),
        "judged_bands_hz": [float(c) for c in b.bands.center_hz[b.resolved]],
    }


class _Provenance:
    """The provenance record of a run, its model file hashed in a background thread.

    A modal model's file can be hundreds of MB (193 MB for 20,000 grids x 200
    modes), a quarter of a second of SHA-256; hashlib and file reads release the GIL, so the
    hash runs beside the computation instead of after it.  :meth:`result` joins the thread
    and re-raises anything it raised.
    """

    def __init__(self, model: Any, command: str | None):
        import threading

        self._out: dict[str, Any] = {}
        self._error: BaseException | None = None

        def work() -> None:
            try:
                self._out = _meta(model, command)
            except BaseException as exc:  # re-raised in the caller's thread by result()
                self._error = exc

        self._thread = threading.Thread(target=work, name="microg-provenance", daemon=True)
        self._thread.start()

    def result(self) -> dict[str, Any]:
        """The record (:func:`_meta`), once the hash is done."""
        self._thread.join()
        if self._error is not None:
            raise self._error
        return self._out


def _sha256_file(path: Path) -> str:
    """SHA-256 of a file (``hashlib.file_digest``: read into one reused buffer)."""
    with path.open("rb") as fh:
        return hashlib.file_digest(fh, "sha256").hexdigest()


def _meta(model: Any, command: str | None) -> dict[str, Any]:
    from microg import __version__

    src = getattr(model, "source", "") or ""
    sha = None
    path = None
    if src:
        p = Path(src)
        if p.is_file():
            path = str(p.resolve())
            sha = _sha256_file(p)
        else:
            path = src
            try:
                from importlib import resources

                name = Path(src).name
                data = resources.files("microg").joinpath("data").joinpath(name).read_bytes()
                sha = hashlib.sha256(data).hexdigest()
            except (OSError, FileNotFoundError, ValueError):
                sha = None
    return {
        "microg_version": __version__,
        "created_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "command": command,
        "model_path": path,
        "model_sha256": sha,
    }


def run_analysis(
    model: Any,
    opts: AnalysisOptions,
    *,
    progress: Callable[[str], None] | None = None,
    requirement: Requirement | None = None,
    command: str | None = None,
    on_modes: Callable[[ModesReady], object] | None = None,
) -> Analysis:
    """Run the main job on a model with validated options (see :func:`analyze`).

    Parameters
    ----------
    model : Station, modal model or Structure
    opts : AnalysisOptions
    progress : callable, optional
        Called with a stage name as each stage starts (for a progress bar).
    requirement : Requirement, optional
        Overrides ``opts.requirement`` (a custom requirement object).
    command : str, optional
        The command line, for the provenance record.
    on_modes : callable, optional
        Called with a :class:`ModesReady` once the modes are solved, before the response.
    """
    step = progress or (lambda _s: None)
    _check_record(opts)
    req = requirement or _requirement(opts.requirement)
    step("structure")
    structure = _structure(model, opts)
    for d in opts.disturbances:
        _point(structure, d.point, "at")
    if opts.sources is not None:
        opts.sources.validate_points(structure.points)
    for name in opts.observe:
        _point(structure, name, "observe")
    step("modes")
    n_req = None
    if structure.is_sparse:
        # the vibratory regime reaches 300 Hz: sources need the modes well above it
        default = DEFAULT_SOURCE_MODES if opts.sources is not None else DEFAULT_N_MODES
        n_req = min(structure.n_dof - 1, opts.n_modes or default)
    # a small structure (a modal model: its modes; the IOC FEM) on one BLAS thread; a large
    # one keeps the threads for its sparse eigensolve (solve_modes limits its own small steps)
    with blas_threads(structure.n_dof):
        modes = solve_modes(structure, n_req)
    # the model file's hash runs beside the response and assessment (compute-bound), not the
    # structure and modes, whose scans of the mode shapes compete with it for memory bandwidth
    provenance = _Provenance(model, command)
    warnings: list[str] = []
    elastic = getattr(modes, "elastic", ~modes.rigid)
    used = modes.rigid | (np.asarray(elastic) & (modes.freq_hz <= opts.max_freq_hz))
    name = str(getattr(model, "name", None) or structure.meta.get("model", "model"))
    if on_modes is not None:
        on_modes(ModesReady(name, opts, structure, modes, used))
    observations: dict[str, Observation] = {}
    t = np.zeros(0)
    if opts.disturbances:
        warnings += _check_modes_used(modes, np.asarray(elastic, bool), used, opts.max_freq_hz)
        # the transient's products contract over the modes (a few hundred): small GEMMs, on
        # one BLAS thread (two contend with each other and with the provenance hash: the
        # modal-model benchmark's point projections take 0.045 s on one, 0.08-0.15 s on two)
        with blas_threads(modes.n_modes):
            observations, t, w = _transient(structure, modes, used, opts, req, step)
        warnings += w
    vib = None
    if opts.sources is not None:
        step("frequency domain")
        from microg.environment.vibratory import assess_sources

        zeta_all = np.where(modes.rigid, 0.0, opts.zeta)
        vib = assess_sources(modes, opts.sources, list(opts.observe), req, zeta_all)
        warnings += [f"frequency domain: {w}" for w in vib.warnings]
    for pname, ob in observations.items():
        warnings += [f"{pname}: {w}" for w in ob.assessment.warnings]
    notes = _notes(model, opts, observations)
    return Analysis(
        model=name,
        options=opts,
        structure=structure,
        modes=modes,
        used=used,
        observations=observations,
        timepts=t,
        requirement=req,
        warnings=warnings,
        notes=notes,
        meta=provenance.result(),
        frequency_domain=vib,
    )


def _check_modes_used(
    modes: Modes, elastic: np.ndarray, used: np.ndarray, max_freq_hz: float
) -> list[str]:
    """Refuse a transient response without any mode; warn when it holds no elastic mode.

    Without rigid modes (a clamped or imported model whose modes all lie above
    ``max_freq_hz``) the response would be identically zero and the verdict a green
    "complies" that no number supports.
    """
    el_freq = modes.freq_hz[elastic]
    lowest = float(el_freq.min()) if el_freq.size else float("nan")
    if not np.any(used):
        raise InputError(
            f"no mode enters the response: the model has no rigid-body mode and its lowest "
            f"mode ({lowest:.4g} Hz) is above max_freq = {max_freq_hz:g} Hz, so the response "
            "would be zero",
            where="max_freq",
            fix=f"raise max_freq above {lowest:.4g} Hz (and dt to resolve it)",
        )
    if el_freq.size and not np.any(used & elastic):
        return [
            f"no elastic mode below max_freq = {max_freq_hz:g} Hz (the lowest is "
            f"{lowest:.4g} Hz): the response is the rigid-body motion alone"
        ]
    return []


def _transient(
    structure: Structure,
    modes: Modes,
    used: np.ndarray,
    opts: AnalysisOptions,
    req: Requirement,
    step: Callable[[str], None],
) -> tuple[dict[str, Observation], np.ndarray, list[str]]:
    """The transient regime: exact response, assessment, exact peaks, isolation advice."""
    warnings: list[str] = []
    if np.any(np.asarray(modes.unstable, bool)):
        unstable = np.asarray(modes.unstable, bool)
        growth = np.asarray(modes.growth_rate, float)
        k = int(np.flatnonzero(unstable)[0])
        note = next((n for n in modes.notes if "unstable" in n), "")
        raise InputError(
            f"mode {k + 1} is unstable (growth rate {growth[k]:.3g} rad/s): the "
            f"transient response grows without bound, so no verdict can be drawn. {note}",
            where="gravity_gradient",
            fix="analyse the free-free structure (no gravity gradient), or correct the inertias",
        )
    maps = {name: structure.point(name).translation for name in opts.observe}
    if structure.is_sparse and not modes.rigid[-1] and modes.freq_hz[-1] <= opts.max_freq_hz:
        warnings.append(
            f"only {modes.n_modes} modes computed; the highest ({modes.freq_hz[-1]:.3g} Hz) is "
            f"below max_freq {opts.max_freq_hz:g} Hz: modes between are missing from the response"
        )
    idx = np.flatnonzero(used)
    m = modes.subset(idx)
    nyquist = 0.5 / opts.dt_s
    f_top = float(np.max(m.freq_hz, initial=0.0))
    if f_top >= nyquist:
        raise InputError(
            f"dt = {opts.dt_s:g} s samples at {1 / opts.dt_s:g} Hz, too coarse for the modes in "
            f"the response (up to {f_top:.3g} Hz, above the {nyquist:.3g}-Hz Nyquist frequency): "
            "the spectrum and the band verdict would be aliased",
            where="dt",
            fix=f"use dt <= {0.25 / f_top:.3g} s, or max_freq below {nyquist:.3g} Hz",
        )
    if f_top > 0.5 * nyquist:
        warnings.append(
            f"the highest mode in the response ({f_top:.3g} Hz) is above half the Nyquist "
            f"frequency ({nyquist:.3g} Hz): fewer than 4 samples per period; bands near Nyquist "
            "are approximate"
        )
    warnings += _force_warnings(opts)
    zeta = np.where(m.rigid, 0.0, opts.zeta)
    loads, w = _modal_forces(structure, m, opts)
    warnings += w
    step("response")
    t = np.arange(0.0, opts.duration_s + 0.5 * opts.dt_s, opts.dt_s)
    names = list(maps)
    # every point's rows in one product per series (one GEMM, not one per point)
    rows = [tmap @ m.phi for tmap in maps.values()]
    tphi_all = np.concatenate(rows) if rows else np.zeros((0, m.n_modes))
    sup = superpose(m.omega, zeta, loads, t, names, tphi_all)
    step("assessment")
    mode_numbers = idx + 1
    modal = _ModalSeries(t, sup.modal_accel)

    def observe(j: int, name: str) -> Observation:
        r = slice(3 * j, 3 * j + 3)
        tphi = tphi_all[r]
        resp = sup.points[name]
        peak = sup.peaks[name]
        a = _with_exact_peak(assess(t, resp.acceleration, req), peak, req)
        return Observation(
            name=name,
            response=resp,
            assessment=a,
            isolation=IsolationAdvice.not_assessed(name),
            contributions=_contributions(
                mode_numbers, m, tphi, modal, a, sup.modal_accel_at_peak[:, j]
            ),
            interval=_intervals(t, resp.acceleration, req),
            peak=peak,
        )

    def isolate(ob: Observation) -> Observation:
        adv = advise_isolation(
            ob.name,
            ob.assessment,
            ob.response,
            req,
            package_mass=opts.package_mass_kg,
            absorber_mu=opts.absorber_mu,
        )
        return replace(ob, isolation=adv)

    obs = [observe(j, name) for j, name in enumerate(names)]
    step("isolation")
    if opts.isolation:
        obs = [isolate(ob) for ob in obs]
    observations = {ob.name: ob for ob in obs}
    return observations, t, warnings


def _notes(model: Any, opts: AnalysisOptions, obs: Mapping[str, Observation]) -> list[str]:
    notes = []
    if obs:
        notes.append(
            f"the band verdict is judged on the band RMS over the whole {opts.duration_s:g}-s "
            f"record: a choice (a transient's band RMS falls as the record grows); the margin "
            f"over the worst {REQUIREMENT_INTERVAL_S:g}-s interval is given beside it"
        )
    masses = getattr(model, "all_masses", None)
    fitted = [pm.name for pm in masses() if pm.fitted] if callable(masses) else []
    if fitted:
        notes.append(
            f"{len(fitted)} mass items of model {getattr(model, 'name', '')!r} carry fitted "
            f"values (marked fitted = true in the model file: {', '.join(sorted(set(fitted)))}); "
            "for the shipped IOC models these were fitted to the seed report's Appendix C "
            "because the OCR lost them, so local results near them (the keel) inherit that "
            "uncertainty"
        )
    return notes
