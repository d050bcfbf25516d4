"""Where to put the laboratory: the acceleration map along the structure and its quietest point.

The report's conclusions 6 and 7 (Section 5, Figure 9): the acceleration a crew push-off
causes at a point is, mode by mode (Eq. 2.20b, Eq. 3.1 with the report's crew force Eq. 2.16)::

    a_j(P_e) = |phi_j(P_e)| |phi_j(P_a)| f0 / (M_jj omega_j t1) [A_j]max

so the best place for an experiment is near a node of the fundamental elastic mode
(``phi_1(P_e) = 0``).  This module evaluates that map along the whole sampled structure
(:func:`acceleration_map`), and the same quantities at one named point
(:func:`point_peak`, what the layout optimiser minimises), picks the quietest sample
(:func:`best_location`), and runs the whole job from a model (:func:`locate`: the one
discretisation entry :func:`microg.structure.discretize.discretize`, then
:func:`microg.dynamics.modes.solve_modes`).

Definitions used throughout:

* the force acts at the crew point along a unit ``direction``; accelerations are the
  component along the same direction (the report's Eq. 3.1 is the lateral component);
* *elastic* modes are those of :func:`microg.location.peaks.elastic_modes` (the one rule on
  ``Modes``);
* the *rigid* part is the rigid-body modes' acceleration ``c f(t)``, exact and independent
  of the basis of the rigid-body subspace (:func:`microg.location.peaks.rigid_part`);
* the *fundamental* is the lowest elastic mode the force excites; its *nodes* are the points
  of each straight line of the structure where its displacement along ``direction``
  changes sign (:func:`microg.location.sampling.find_nodes`).

The map is computed on the free-free structure (``gravity_gradient=False``): the libration
mode (period about an hour) is then the rigid rotation, which it equals over a push-off to
``(omega_lib t)^2 ~ 1e-3``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from microg._vectors import AXES, parse_direction
from microg.dynamics.crew import CrewPushoff
from microg.dynamics.modes import Modes
from microg.dynamics.planar import in_plane_fraction
from microg.dynamics.response import modal_pwl_response
from microg.errors import InputError
from microg.location.peaks import (
    elastic_mask,
    elastic_modes,
    force_breakpoints,
    mode_peak_factors,
    peak_over_time,
    rigid_part,
    time_grid,
)
from microg.location.sampling import (
    Node,
    SampleLine,
    element_lines,
    find_nodes,
    sample_lines,
    sample_shapes,
)
from microg.models.station import Station
from microg.structure.structure import Structure
from microg.units import G0

__all__ = [
    "DEFAULTS",
    "FUNDAMENTAL_MIN_PARTICIPATION",
    "LATERAL",
    "MEASURES",
    "POINTS_COMPONENT",
    "AccelerationMap",
    "Location",
    "LocateResult",
    "SitePeak",
    "acceleration_map",
    "best_location",
    "check_point",
    "default_direction",
    "default_point",
    "force_to_dict",
    "is_imported",
    "locate",
    "location_structure",
    "point_peak",
    # re-exported (dynamics.planar, location.sampling, .peaks) for the former module's callers
    "elastic_mask",
    "in_plane_fraction",
    "sample_shapes",
]

#: a mode counts as excited when |phi_j(crew).d| exceeds this fraction of the largest elastic one
FUNDAMENTAL_MIN_PARTICIPATION = 1e-6
#: the force direction by default: the lateral axis of the report's plane
LATERAL: dict[str, str] = {"xz": "x", "yz": "y", "3d": "x"}
#: the carrier of the named points added to a map (imported models: ``on="points"``)
POINTS_COMPONENT = "points"
#: names of the map's measures (see :meth:`AccelerationMap.measure`)
MEASURES = ("total", "elastic", "rigid", "bound", "long_time")
#: defaults of :func:`locate` (and of ``microg locate``): the report's planar model
DEFAULTS: dict[str, Any] = {
    "method": "ritz",
    "plane": "xz",
    "measure": "total",
    "zeta": 0.0,
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


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class AccelerationMap:
    """Peak acceleration along the structure from a force at one point (Eq. 2.20b / 3.1).

    Attributes
    ----------
    positions : ndarray (p, 3)
        Sample positions, m.
    component : ndarray (p,) of str
        Body or beam of each sample.
    direction : ndarray (3,)
        Unit force direction; accelerations are components along it.
    crew_point : str
    crew_position : ndarray (3,)
        m.
    omega : ndarray (m,)
        Frequencies of the modes used, rad/s.
    rigid : ndarray (m,) of bool
    elastic : ndarray (m,) of bool
        The elastic modes (:func:`microg.location.peaks.elastic_modes`).
    per_mode : ndarray (m, p)
        Peak acceleration of each mode at each sample, m/s^2 (Eq. 3.1 per mode).  The
        rigid-body rows depend on the basis of the rigid subspace; ``rigid_peak`` does not.
    total_peak : ndarray (p,)
        Peak over the time window of the modal sum, m/s^2 (time grid, see ``n_timepts``).
    elastic_peak : ndarray (p,)
        The same for the elastic modes alone, m/s^2.
    rigid_peak : ndarray (p,)
        Peak of the rigid-body modes' sum, ``|c| max|f|``, exact, m/s^2.
    peak_bound : ndarray (p,)
        ``rigid_peak`` plus the per-mode peaks of the other modes: an upper bound of the
        peak at any time, m/s^2.
    long_time_peak : ndarray (p,) or None
        Undamped models whose force ends at zero: ``max(total_peak, sum of the free-vibration
        amplitudes)``, the supremum over all t >= 0 when the frequencies are rationally
        independent (the free vibrations then come arbitrarily close to all crests at once),
        else None.
    window : tuple of float
        Time window of ``total_peak``, s.
    n_timepts : int
        Size of its time grid.
    fundamental : int or None
        Index (into ``omega``) of the fundamental: the lowest elastic mode the force excites
        (``|phi_j(crew).d|`` above FUNDAMENTAL_MIN_PARTICIPATION of the largest elastic one).
    fundamental_shape : ndarray (p,) or None
        Its mass-normalised displacement along ``direction`` at the samples, m/sqrt(kg).
    lines : tuple of SampleLine
    nodes : tuple of Node
        Nodes of the fundamental.
    exact_per_mode : bool
        True when ``per_mode`` comes from the closed form (undamped crew push-off,
        exact [A]max); False when from the time grid.
    zeta : ndarray (m,)
    include_rigid : bool
    method : str
    plane : str or None
    labels : ndarray (p,) of str or None
        Name of each sample (``"grid:7"``, a named point's name; ``""`` for the samples a
        rigid line was densified with), when the structure's samples carry labels.
    """

    positions: np.ndarray
    component: np.ndarray
    direction: np.ndarray
    crew_point: str
    crew_position: np.ndarray
    omega: np.ndarray
    rigid: np.ndarray
    elastic: np.ndarray
    per_mode: np.ndarray
    total_peak: np.ndarray
    elastic_peak: np.ndarray
    rigid_peak: np.ndarray
    peak_bound: np.ndarray
    long_time_peak: np.ndarray | None
    window: tuple[float, float]
    n_timepts: int
    fundamental: int | None
    fundamental_shape: np.ndarray | None
    lines: tuple[SampleLine, ...]
    nodes: tuple[Node, ...]
    exact_per_mode: bool
    zeta: np.ndarray
    include_rigid: bool
    method: str
    plane: str | None
    labels: np.ndarray | None = None

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.positions.shape[0])

    def measure(self, name: str = "total") -> np.ndarray:
        """The map's values (m/s^2) by name: total, elastic, rigid, bound or long_time."""
        table = {
            "total": self.total_peak,
            "elastic": self.elastic_peak,
            "rigid": self.rigid_peak,
            "bound": self.peak_bound,
            "long_time": self.long_time_peak,
        }
        if name not in table:
            raise InputError(
                f"unknown measure {name!r}", where="measure", fix=f"use {', '.join(MEASURES)}"
            )
        value = table[name]
        if value is None:
            raise InputError(
                "long_time peak is defined only for undamped models whose force ends at zero",
                where="measure",
                fix="use total or bound",
            )
        return value

    def to_dict(self) -> dict:
        """JSON-ready map: modes, fundamental, nodes, and every sample's peaks in g."""
        g = 1.0 / G0
        lt = self.long_time_peak
        return {
            "method": self.method,
            "plane": self.plane,
            "crew_point": self.crew_point,
            "crew_position_m": [float(v) for v in self.crew_position],
            "direction": [float(v) for v in self.direction],
            "zeta": [float(v) for v in self.zeta],
            "include_rigid": self.include_rigid,
            "window_s": list(self.window),
            "n_timepts": self.n_timepts,
            "per_mode_exact": self.exact_per_mode,
            "modes": [
                {
                    "omega": float(w),
                    "freq_hz": float(w / (2 * np.pi)),
                    "rigid": bool(r),
                    "elastic": bool(e),
                }
                for w, r, e in zip(self.omega, self.rigid, self.elastic, strict=True)
            ],
            "fundamental": (
                None
                if self.fundamental is None
                else {"index": self.fundamental, "omega": float(self.omega[self.fundamental])}
            ),
            "nodes": [n.to_dict() for n in self.nodes],
            "samples": [
                {
                    "component": str(self.component[i]),
                    "label": None if self.labels is None else str(self.labels[i]),
                    "position_m": [float(v) for v in self.positions[i]],
                    "total_peak_g": float(self.total_peak[i] * g),
                    "elastic_peak_g": float(self.elastic_peak[i] * g),
                    "rigid_peak_g": float(self.rigid_peak[i] * g),
                    "peak_bound_g": float(self.peak_bound[i] * g),
                    "long_time_peak_g": None if lt is None else float(lt[i] * g),
                    "per_mode_g": [float(v) for v in self.per_mode[:, i] * g],
                }
                for i in range(self.n_samples)
            ],
        }

    def to_xarray(self) -> Any:
        """An ``xarray.Dataset``: dims ``sample``, ``axis`` and ``mode``, units in attrs."""
        import xarray as xr

        acc = {"units": "m/s^2"}
        data: dict[str, Any] = {
            "position": (("sample", "axis"), self.positions, {"units": "m"}),
            "total_peak": ("sample", self.total_peak, {**acc, "long_name": "peak of the sum"}),
            "elastic_peak": ("sample", self.elastic_peak, {**acc, "long_name": "elastic modes"}),
            "rigid_peak": ("sample", self.rigid_peak, {**acc, "long_name": "rigid-body modes"}),
            "peak_bound": ("sample", self.peak_bound, {**acc, "long_name": "upper bound"}),
            "per_mode": (("mode", "sample"), self.per_mode, {**acc, "long_name": "Eq. 3.1"}),
        }
        if self.long_time_peak is not None:
            data["long_time_peak"] = ("sample", self.long_time_peak, acc)
        if self.fundamental_shape is not None:
            data["fundamental_shape"] = (
                "sample",
                self.fundamental_shape,
                {"units": "m/kg^0.5", "long_name": "mass-normalised shape along direction"},
            )
        coords = {
            "sample": np.arange(self.n_samples),
            "axis": ["x", "y", "z"],
            "mode": np.arange(self.omega.size),
            "component": ("sample", self.component.astype(str)),
            **({} if self.labels is None else {"label": ("sample", self.labels.astype(str))}),
            "omega": ("mode", self.omega, {"units": "rad/s"}),
            "rigid": ("mode", self.rigid),
            "elastic": ("mode", self.elastic),
        }
        attrs = {
            "crew_point": self.crew_point,
            "crew_position_m": [float(v) for v in self.crew_position],
            "direction": [float(v) for v in self.direction],
            "method": self.method,
            "plane": self.plane or "3d",
            "window_s": list(self.window),
            "n_timepts": self.n_timepts,
            "include_rigid": int(self.include_rigid),
        }
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def plot(
        self,
        *,
        measure: str = "total",
        title: str | None = None,
        best: Location | None = None,
        ax: Any = None,
    ) -> Any:
        """The map drawn on the structure (:func:`microg.plotting.location.plot_map`).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.location import plot_map

        return plot_map(self, measure=measure, title=title, best=best, ax=ax)


@dataclass(frozen=True)
class Location:
    """The quietest sample of a map.

    Attributes
    ----------
    index : int
        Sample index.
    component : str
    position : ndarray (3,)
        m.
    peak : float
        Value of the chosen measure there, m/s^2.
    measure : str
    label : str or None
        The sample's name (``"grid:7"``, a named point), when the map has labels.
    """

    index: int
    component: str
    position: np.ndarray
    peak: float
    measure: str
    label: str | None = None

    @property
    def peak_g(self) -> float:
        """``peak`` in units of standard gravity."""
        return self.peak / G0

    def to_dict(self) -> dict:
        """``{"component", "label", "position_m", "measure", "peak_g"}``."""
        return {
            "component": self.component,
            "label": self.label,
            "position_m": [float(v) for v in self.position],
            "measure": self.measure,
            "peak_g": self.peak_g,
        }


@dataclass(frozen=True)
class SitePeak:
    """The peak acceleration at one named point from a force at another (the map at a point).

    Attributes
    ----------
    point, crew_point : str
        Where the acceleration is taken and where the force acts.
    total_mps2 : float
        Peak over the time window of the modal sum (rigid + elastic), m/s^2.
    elastic_mps2 : float
        The same for the elastic modes alone, m/s^2.
    rigid_mps2 : float
        Peak of the rigid-body modes' sum, exact, m/s^2.
    bound_mps2 : float
        ``rigid_mps2`` plus Eq. 3.1 summed over the other modes: an upper bound, m/s^2.
    per_mode_mps2 : ndarray (m,)
        Eq. 3.1 per mode, m/s^2.
    omega : ndarray (m,)
        rad/s.
    rigid, elastic : ndarray (m,) of bool
    window_s : tuple of float
        Time window of the peaks over time, s.
    """

    point: str
    crew_point: str
    total_mps2: float
    elastic_mps2: float
    rigid_mps2: float
    bound_mps2: float
    per_mode_mps2: np.ndarray
    omega: np.ndarray
    rigid: np.ndarray
    elastic: np.ndarray
    window_s: tuple[float, float]

    def measure(self, name: str = "total") -> float:
        """The peak by name (m/s^2): total, elastic, rigid or bound."""
        table = {
            "total": self.total_mps2,
            "elastic": self.elastic_mps2,
            "rigid": self.rigid_mps2,
            "bound": self.bound_mps2,
        }
        if name not in table:
            raise InputError(
                f"unknown measure {name!r}", where="measure", fix="use total, elastic or bound"
            )
        return table[name]

    def to_dict(self) -> dict:
        """Peaks in g, the elastic modes' Eq. 3.1 terms and frequencies."""
        g = 1.0 / G0
        el = self.elastic
        return {
            "point": self.point,
            "crew_point": self.crew_point,
            "total_g": self.total_mps2 * g,
            "elastic_g": self.elastic_mps2 * g,
            "rigid_g": self.rigid_mps2 * g,
            "bound_g": self.bound_mps2 * g,
            "per_mode_g": [float(v) for v in self.per_mode_mps2[el] * g],
            "omega": [float(v) for v in self.omega[el]],
            "window_s": list(self.window_s),
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
    """

    model: str
    force: Any
    amap: AccelerationMap = field(repr=False)
    best: Location
    n: int | None = None
    warnings: tuple[str, ...] = ()

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


# --------------------------------------------------------------------------- kernels


@dataclass(frozen=True)
class _Peaks:
    per_mode: np.ndarray
    total: np.ndarray
    elastic: np.ndarray
    rigid: np.ndarray
    bound: np.ndarray
    long_time: np.ndarray | None
    grid: np.ndarray
    exact: bool


def _peaks(
    resp: np.ndarray,
    gamma: np.ndarray,
    omega: np.ndarray,
    rigid: np.ndarray,
    elastic: np.ndarray,
    zeta: np.ndarray,
    force: Any,
    duration: float | None,
    *,
    with_long_time: bool = True,
) -> _Peaks:
    """Every peak of the map at points with responses ``resp`` (p, m) per modal coordinate."""
    peaks, exact = mode_peak_factors(omega, force, zeta, elastic=elastic)
    per_mode = np.abs(resp.T) * np.abs(gamma)[:, None] * peaks[:, None]
    tb, fb = force_breakpoints(force)
    grid = time_grid(tb, omega, elastic, duration)
    modal = modal_pwl_response(omega, zeta, tb, np.outer(gamma, fb), grid)
    total = peak_over_time(resp, modal.eta_ddot)
    el_peak = peak_over_time(resp[:, elastic], modal.eta_ddot[elastic])
    rig = rigid_part(resp, gamma, rigid, force)
    bound = rig + per_mode[~rigid].sum(axis=0)
    long_time = None
    if with_long_time and np.all(zeta == 0) and fb[-1] == 0 and omega.size:
        end = modal_pwl_response(omega, zeta, tb, np.outer(gamma, fb), tb[-1:])
        amp = omega * np.hypot(omega * end.eta[:, 0], end.eta_dot[:, 0])
        long_time = np.maximum(total, np.abs(resp) @ np.abs(amp))
    return _Peaks(per_mode, total, el_peak, rig, bound, long_time, grid, exact)


def _modal_arrays(
    modes: Modes, zeta: float | np.ndarray, include_rigid: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(use, omega, rigid, elastic, zeta) of the modes kept, validated."""
    omega = np.asarray(modes.omega, float)
    rigid = np.asarray(modes.rigid, bool)
    zeta_arr = np.broadcast_to(np.asarray(zeta, float), omega.shape).astype(float)
    if np.any(~np.isfinite(zeta_arr)) or np.any(zeta_arr < 0) or np.any(zeta_arr >= 1):
        raise InputError("damping ratio must satisfy 0 <= zeta < 1", where="zeta")
    use = np.ones(omega.size, bool) if include_rigid else ~rigid
    elastic = elastic_modes(modes)
    return use, omega[use], rigid[use], elastic[use], zeta_arr[use]


def acceleration_map(
    structure: Structure,
    modes: Modes,
    crew_point: str,
    direction: np.ndarray | str,
    crew: CrewPushoff | Any,
    *,
    zeta: float | np.ndarray = 0.0,
    include_rigid: bool = True,
    duration: float | None = None,
    points: Sequence[str] = (),
    segments: np.ndarray | None = None,
) -> AccelerationMap:
    """Peak acceleration at every sample of the structure from a force at ``crew_point``.

    Per mode (Eq. 2.20b, Eq. 3.1 with mass-normalised shapes, ``M_jj = 1``)::

        a_j(s) = |phi_j(s).d| |phi_j(crew).d| f0 [A_j]max / (omega_j t1)

    (``f0 |phi_j(s).d| |phi_j(crew).d|`` for a rigid-body mode), vectorised over samples and
    modes.  The total is the peak over a time window of the modal sum
    ``a(s, t) = sum_j phi_j(s).d phi_j(crew).d eta_j''(t)`` with the exact piecewise-linear
    modal response evaluated on a grid of at least ``POINTS_PER_PERIOD`` points per period
    of the fastest mode (and both sides of every force jump).

    Parameters
    ----------
    structure : Structure
        With samples (:func:`microg.structure.discretize.discretize`).
    modes : Modes
        Modes of ``structure`` (mass-normalised).
    crew_point : str
        Named point where the force acts (unknown: InputError listing the known points).
    direction : ndarray (3,) or str
        Force direction (``"x"``, ``"-y"``, ``"1 0 0"``...); accelerations are taken along it.
    crew : CrewPushoff or ForceHistory
        The force history, N (the report's Eq. 2.16 push-off, or any piecewise-linear one).
    zeta : float or ndarray (m,)
        Modal damping ratios (0 <= zeta < 1).
    include_rigid : bool
        Include the rigid-body modes (their acceleration is the same everywhere for a
        translation, grows with the distance from the centre of mass for a rotation).
    duration : float, optional
        Length of the time window from the first breakpoint, s (default: to the last
        breakpoint plus three periods of the slowest elastic mode).
    points : sequence of str
        Named points (or ``grid:N``) added to the map after the samples, carrier
        :data:`POINTS_COMPONENT`, each with its own translation map (rigid offsets
        included): ``best_location(amap, component="points")`` is the quietest of them.
    segments : ndarray (s, 2) of int, optional
        Sample indices of two-node elements (a frame model's beams and rods): their
        straight chains (:func:`microg.location.sampling.element_lines`) are lines of the
        map besides the carriers' own lines, so the nodes of the fundamental are found on
        a model whose nodes carry no beam names (a NASTRAN deck).  Elements with both ends
        on a carrier's line are left out.
    """
    d = parse_direction(direction, "direction")
    cp = _resolve(structure, crew_point, "crew_point")
    use, omega, rigid, elastic, zeta_arr = _modal_arrays(modes, zeta, include_rigid)
    phi = np.asarray(modes.phi, float)[:, use]

    positions, component, shapes = sample_shapes(structure, phi)
    n0 = positions.shape[0]
    own = getattr(structure.samples, "labels", None)
    positions, component, shapes, lines = sample_lines(positions, component, shapes)
    labels = None
    if own is not None and len(own) == n0:
        labels = np.array(list(own) + [""] * (positions.shape[0] - n0), dtype=object)
    if segments is not None:
        covered = np.zeros(positions.shape[0], bool)
        for line in lines:
            covered[line.index] = True
        seg = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
        if seg.size and (seg.min() < 0 or seg.max() >= n0):
            raise InputError(f"segment sample indices must be in 0..{n0 - 1}", where="segments")
        names = None if labels is None else [str(v) for v in labels]
        lines = [*lines, *element_lines(positions, seg, labels=names, covered=covered)]
    if points:
        maps = [_resolve(structure, name, "points") for name in points]
        base = labels if labels is not None else np.full(positions.shape[0], "", dtype=object)
        labels = np.concatenate([base, np.array(list(points), dtype=object)])
        positions = np.concatenate([positions, np.array([m.position for m in maps], float)])
        component = np.concatenate([component, np.full(len(maps), POINTS_COMPONENT)])
        extra = np.stack([np.asarray(m.translation, float) @ phi for m in maps])
        shapes = np.concatenate([shapes, extra])
    resp = np.einsum("pam,a->pm", shapes, d)  # displacement along d per unit modal coordinate
    gamma = (np.asarray(cp.translation, float) @ phi).T @ d  # (m,)
    pk = _peaks(resp, gamma, omega, rigid, elastic, zeta_arr, crew, duration)

    fund = None
    fshape = None
    nodes: tuple[Node, ...] = ()
    # the fundamental: the lowest elastic mode the force excites (a 3-D model has modes the
    # force cannot reach, e.g. out-of-plane bending for an in-plane push)
    g_el = np.abs(gamma[elastic])
    excited = elastic & (
        np.abs(gamma) > FUNDAMENTAL_MIN_PARTICIPATION * (float(g_el.max()) if g_el.size else 0.0)
    )
    if np.any(excited):
        fund = int(np.flatnonzero(excited)[np.argmin(omega[excited])])
        fshape = resp[:, fund]
        nodes = find_nodes(lines, positions, fshape)
    return AccelerationMap(
        positions=positions,
        component=component,
        direction=d,
        crew_point=crew_point,
        crew_position=np.asarray(cp.position, float),
        omega=omega,
        rigid=rigid,
        elastic=elastic,
        per_mode=pk.per_mode,
        total_peak=pk.total,
        elastic_peak=pk.elastic,
        rigid_peak=pk.rigid,
        peak_bound=pk.bound,
        long_time_peak=pk.long_time,
        window=(float(pk.grid[0]), float(pk.grid[-1])),
        n_timepts=int(pk.grid.size),
        fundamental=fund,
        fundamental_shape=fshape,
        lines=tuple(lines),
        nodes=nodes,
        exact_per_mode=pk.exact,
        zeta=zeta_arr,
        include_rigid=include_rigid,
        method=structure.method,
        plane=structure.plane,
        labels=None if labels is None else labels.astype(str),
    )


def _resolve(structure: Structure, name: str, where: str) -> Any:
    """The point map of ``name``; an unknown name is an InputError naming ``where``."""
    try:
        return structure.point(name)
    except InputError as exc:
        raise InputError(exc.what, where=where, fix=exc.fix) from None
    except KeyError:
        known = ", ".join(sorted(structure.points)) or "(none)"
        raise InputError(
            f"unknown point {name!r}", where=where, fix=f"known points: {known}"
        ) from None


def point_peak(
    structure: Structure,
    modes: Modes,
    point: str,
    crew_point: str,
    direction: np.ndarray | str,
    crew: CrewPushoff | Any,
    *,
    zeta: float | np.ndarray = 0.0,
    include_rigid: bool = True,
    duration: float | None = None,
) -> SitePeak:
    """The peaks of :func:`acceleration_map` at one named point (same kernel, same grid).

    Parameters
    ----------
    structure : Structure
        Samples are not needed.
    modes : Modes
        Modes of ``structure``.
    point : str
        Named point where the acceleration is taken (the experiment site).
    crew_point : str
        Named point where the force acts.
    direction : ndarray (3,) or str
        Force direction; accelerations along it.
    crew : CrewPushoff or ForceHistory
        N.
    zeta : float or ndarray (m,)
        Modal damping ratios.
    include_rigid : bool
        Include the rigid-body modes.
    duration : float, optional
        Time window, s (default as for the map).
    """
    d = parse_direction(direction, "direction")
    ep = structure.point(point)
    cp = structure.point(crew_point)
    use, omega, rigid, elastic, zeta_arr = _modal_arrays(modes, zeta, include_rigid)
    phi = np.asarray(modes.phi, float)[:, use]
    resp = ((np.asarray(ep.translation, float) @ phi).T @ d)[None, :]
    gamma = (np.asarray(cp.translation, float) @ phi).T @ d
    pk = _peaks(resp, gamma, omega, rigid, elastic, zeta_arr, crew, duration, with_long_time=False)
    return SitePeak(
        point=point,
        crew_point=crew_point,
        total_mps2=float(pk.total[0]),
        elastic_mps2=float(pk.elastic[0]),
        rigid_mps2=float(pk.rigid[0]),
        bound_mps2=float(pk.bound[0]),
        per_mode_mps2=pk.per_mode[:, 0],
        omega=omega,
        rigid=rigid,
        elastic=elastic,
        window_s=(float(pk.grid[0]), float(pk.grid[-1])),
    )


def best_location(
    amap: AccelerationMap, *, component: str | None = None, measure: str = "total"
) -> Location:
    """The sample with the smallest peak acceleration (Figure 9, conclusion 7).

    Parameters
    ----------
    amap : AccelerationMap
    component : str, optional
        Restrict to one body or beam (e.g. the main body, where laboratories go).
    measure : {"total", "elastic", "rigid", "bound", "long_time"}
        Which peak to minimise (see :class:`AccelerationMap`).
    """
    values = amap.measure(measure)
    mask = np.ones(values.size, bool)
    if component is not None:
        mask = amap.component == component
        if not np.any(mask):
            known = ", ".join(sorted(set(amap.component.tolist())))
            raise InputError(
                f"no samples on {component!r}", where="on", fix=f"known components: {known}"
            )
    idx = np.flatnonzero(mask)
    i = int(idx[np.argmin(values[idx])])
    label = None if amap.labels is None else str(amap.labels[i])
    return Location(i, str(amap.component[i]), amap.positions[i], float(values[i]), measure, label)


# --------------------------------------------------------------------------- the pipeline


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


def _load(model: Any, units: str | None, wtmass: float | None, points: str | Path | None) -> Any:
    """A model object as it is, or a path / shipped name read by the one model loader."""
    if not isinstance(model, str | Path):
        if units is not None or wtmass is not None or points is not None:
            raise InputError(
                "units, wtmass and points apply when the model is read from a file",
                where="units"
                if units is not None
                else ("wtmass" if wtmass is not None else "points"),
                fix="pass the file's path, or give them to microg.load_model",
            )
        return model
    from microg.models.load import load_model

    return load_model(model, units=units, wtmass=wtmass, points=points)


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
    force : CrewPushoff or ForceHistory, optional
        N (default: the report's push-off, 25 lbf, 1 s, 13 s, 14 s).
    direction : str or ndarray (3,), optional
        Force direction (default: the plane's lateral axis, x for xz, y for yz).
    method : {"ritz", "fem"}
        Assumed modes (the report's method) or 3-D frame elements (stations only).
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
    """
    from microg.dynamics.forces import REPORT_F0_N
    from microg.dynamics.modes import solve_modes

    mdl = _load(model, units, wtmass, points)
    if method not in ("ritz", "fem"):
        raise InputError(f"unknown method {method!r}", where="method", fix="use ritz or fem")
    if measure not in MEASURES:
        raise InputError(
            f"unknown measure {measure!r}", where="measure", fix=f"use {', '.join(MEASURES)}"
        )
    force = force if force is not None else CrewPushoff(REPORT_F0_N)
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
    _resolve(structure, crew, "crew")
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
    return LocateResult(
        model=str(model.name), force=force, amap=amap, best=best, n=None, warnings=tuple(warnings)
    )
