"""The acceleration map along the structure: its kernel, its result, its quietest sample.

The report's conclusions 6 and 7 (Section 5, Figure 9): the acceleration a crew push-off
causes at a point is, mode by mode (Eq. 2.20b, Eq. 3.1 with the report's crew force Eq. 2.16)::

    a_j(P_e) = |phi_j(P_e)| |phi_j(P_a)| f0 / (M_jj omega_j t1) [A_j]max

so the best place for an experiment is near a node of the fundamental elastic mode
(``phi_1(P_e) = 0``).  :func:`acceleration_map` evaluates that map along the whole sampled
structure and :func:`best_location` picks the quietest sample (definitions: see
:mod:`microg.location.amap`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from microg._vectors import parse_direction
from microg.dynamics.crew import CrewPushoff
from microg.dynamics.modes import Modes
from microg.errors import InputError
from microg.location.peaks import kept_modes, point_peaks
from microg.location.sampling import (
    Node,
    SampleLine,
    element_lines,
    find_nodes,
    sample_lines,
    sample_shapes,
)
from microg.structure.structure import Structure
from microg.units import G0

__all__ = [
    "FUNDAMENTAL_MIN_PARTICIPATION",
    "MEASURES",
    "POINTS_COMPONENT",
    "AccelerationMap",
    "Location",
    "acceleration_map",
    "best_location",
    "resolve_point",
]

#: a mode counts as excited when |phi_j(crew).d| exceeds this fraction of the largest elastic one
FUNDAMENTAL_MIN_PARTICIPATION = 1e-6
#: the carrier of the named points added to a map (imported models: ``on="points"``)
POINTS_COMPONENT = "points"
#: names of the map's measures (see :meth:`AccelerationMap.measure`)
MEASURES = ("total", "elastic", "rigid", "bound", "long_time")


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

    def plot3d(
        self, *, measure: str = "total", title: str | None = None, best: Location | None = None
    ) -> Any:
        """The map coloured along the structure in 3-D (a plotly Figure).

        See :func:`microg.plotting.interactive.maps.acceleration_map_3d`.
        """
        from microg.plotting.interactive.maps import acceleration_map_3d

        return acceleration_map_3d(self, measure=measure, best=best, title=title)


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
    cp = resolve_point(structure, crew_point, "crew_point")
    use, omega, rigid, elastic, zeta_arr = kept_modes(modes, zeta, include_rigid)
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
        maps = [resolve_point(structure, name, "points") for name in points]
        base = labels if labels is not None else np.full(positions.shape[0], "", dtype=object)
        labels = np.concatenate([base, np.array(list(points), dtype=object)])
        positions = np.concatenate([positions, np.array([m.position for m in maps], float)])
        component = np.concatenate([component, np.full(len(maps), POINTS_COMPONENT)])
        extra = np.stack([np.asarray(m.translation, float) @ phi for m in maps])
        shapes = np.concatenate([shapes, extra])
    resp = np.einsum("pam,a->pm", shapes, d)  # displacement along d per unit modal coordinate
    gamma = (np.asarray(cp.translation, float) @ phi).T @ d  # (m,)
    pk = point_peaks(resp, gamma, omega, rigid, elastic, zeta_arr, crew, duration)

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


def resolve_point(structure: Structure, name: str, where: str) -> Any:
    """The point map of ``name``; an unknown name is an InputError naming ``where``.

    Parameters
    ----------
    structure : Structure
    name : str
        A named point (or ``grid:N`` of an imported model).
    where : str
        The parameter's name in the error.
    """
    try:
        return structure.point(name)
    except InputError as exc:
        raise InputError(exc.what, where=where, fix=exc.fix) from None
    except KeyError:
        known = ", ".join(sorted(structure.points)) or "(none)"
        raise InputError(
            f"unknown point {name!r}", where=where, fix=f"known points: {known}"
        ) from None


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
