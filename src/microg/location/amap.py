"""Where to put the laboratory: acceleration maps, nodes of the fundamental mode, layout optimiser.

The report's conclusions 6, 7 and 9 (Section 5, Figure 9): the acceleration a crew push-off
causes at a point is, mode by mode (Eq. 2.20b, Eq. 3.1 with the report's crew force Eq. 2.16)::

    a_j(P_e) = |phi_j(P_e)| |phi_j(P_a)| f0 / (M_jj omega_j t1) [A_j]max

so the best place for an experiment is near a node of the fundamental elastic mode
(``phi_1(P_e) = 0``), and moving masses around can move that node (conclusion 9).

This module evaluates that map along the whole sampled structure (assumed modes or frame
finite elements), locates the nodes of the fundamental, picks the quietest location, and
moves the masses a model marks as movable to minimise the acceleration at an experiment site.
Kernels take SI floats and numpy arrays; shapes are mass-normalised (``M_jj = 1``).

Definitions used throughout:

* the force acts at the crew point along a unit ``direction``; accelerations are the
  component along the same direction (the report's Eq. 3.1 is the lateral component);
* an *elastic* mode has ``omega >= ELASTIC_MIN_OMEGA`` (0.01 Hz, the lower edge of the
  vibratory regime); non-rigid modes below it are gravity-gradient libration modes;
* the *fundamental* is the lowest elastic mode the force excites; its *nodes* are the points
  of each straight line of the structure (a beam, or a rigid body whose samples are
  collinear) where its displacement along ``direction`` changes sign, located by linear
  interpolation between samples (exact on rigid bodies, where the displacement is affine).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from microg._vectors import parse_direction
from microg.dynamics.crew import CrewPushoff, accel_amax
from microg.dynamics.dense import solve_dense
from microg.dynamics.modes import Modes
from microg.dynamics.response import modal_pwl_response
from microg.errors import InputError
from microg.models.station import Beam, NamedPoint, PointMass, RigidBody, Station
from microg.structure.structure import Structure
from microg.units import G0

__all__ = [
    "ELASTIC_MIN_OMEGA",
    "PLANE_DOFS",
    "SampleLine",
    "Node",
    "AccelerationMap",
    "Location",
    "MovableMass",
    "LayoutResult",
    "Conclusion7Case",
    "Conclusion7",
    "elastic_mask",
    "in_plane_fraction",
    "sample_shapes",
    "mode_peak_factors",
    "acceleration_map",
    "best_location",
    "resolve_mass",
    "movable_masses",
    "move_masses",
    "layout_objective",
    "optimize_layout",
    "conclusion7",
    "map_figure",
]

#: lowest elastic frequency, rad/s (0.01 Hz: below it the motion is quasi-steady libration)
ELASTIC_MIN_OMEGA = 2.0 * np.pi * 0.01
#: frame DOF suffixes whose motion lies in each plane of the report (translation in the plane,
#: rotation about its normal)
PLANE_DOFS: dict[str, tuple[str, ...]] = {"xz": ("ux", "uz", "ry"), "yz": ("uy", "uz", "rx")}
#: grid points per period of the fastest mode for the time-domain peak (under-estimates a
#: sinusoid's crest by at most 1 - cos(pi/32) = 0.48 %)
POINTS_PER_PERIOD = 32
#: largest time grid of the total peak
MAX_TIMEPTS = 400_000
#: a mode counts as excited when |phi_j(crew).d| exceeds this fraction of the largest elastic one
FUNDAMENTAL_MIN_PARTICIPATION = 1e-6
#: rigid-body lines are densified to at least this many samples
BODY_LINE_SAMPLES = 121


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class SampleLine:
    """A straight line of samples (a beam, or a rigid body whose samples are collinear).

    Attributes
    ----------
    component : str
        Beam or body name.
    index : ndarray (k,) of int
        Sample indices, ordered along the line.
    origin : ndarray (3,)
        Position of the first sample, m.
    axis : ndarray (3,)
        Unit vector along the line.
    rigid : bool
        True when every mode shape is affine along the line (a rigid body).
    """

    component: str
    index: np.ndarray
    origin: np.ndarray
    axis: np.ndarray
    rigid: bool


@dataclass(frozen=True)
class Node:
    """A node of the fundamental elastic mode.

    Attributes
    ----------
    component : str
        Beam or body it lies on.
    position : ndarray (3,)
        Station-frame position, m.
    distance : float
        Distance along the line from its first sample, m.
    """

    component: str
    position: np.ndarray
    distance: float


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
        ``omega >= ELASTIC_MIN_OMEGA``.
    per_mode : ndarray (m, p)
        Peak acceleration of each mode at each sample, m/s^2 (Eq. 3.1 per mode).
    total_peak : ndarray (p,)
        Peak over the time window of the modal sum, m/s^2 (time grid, see ``timepts``).
    elastic_peak : ndarray (p,)
        The same for the elastic modes alone, m/s^2.
    peak_bound : ndarray (p,)
        Sum of the per-mode peaks: an upper bound of the peak at any time, m/s^2.
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
    exact_per_mode : bool
        True when ``per_mode`` comes from the closed form (undamped crew push-off,
        exact [A]max); False when from the time grid.
    zeta : ndarray (m,)
    include_rigid : bool
    method : str
    plane : str or None
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

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.positions.shape[0])

    def measure(self, name: str = "total") -> np.ndarray:
        """The map's values (m/s^2) by name: total, elastic, bound or long_time."""
        table = {
            "total": self.total_peak,
            "elastic": self.elastic_peak,
            "bound": self.peak_bound,
            "long_time": self.long_time_peak,
        }
        if name not in table:
            raise InputError(
                f"unknown measure {name!r}", fix="use total, elastic, bound or long_time"
            )
        value = table[name]
        if value is None:
            raise InputError(
                "long_time peak is defined only for undamped models whose force ends at zero",
                fix="use total or bound",
            )
        return value


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
    """

    index: int
    component: str
    position: np.ndarray
    peak: float
    measure: str

    @property
    def peak_g(self) -> float:
        """``peak`` in units of standard gravity."""
        return self.peak / G0


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
    masses : tuple of MovableMass
        The movable masses (``value`` = initial coordinate).
    initial : ndarray (k,)
        Initial coordinates, m.
    optimal : ndarray (k,)
        Optimal coordinates, m.
    objective_initial, objective_optimal : float
        Summed elastic Eq. 3.1 peak at the experiment site, m/s^2.
    per_mode_initial, per_mode_optimal : ndarray
        Its terms, m/s^2, one per elastic mode.
    omega_initial, omega_optimal : ndarray
        Elastic frequencies, rad/s.
    n_evaluations : int
        Objective evaluations (each rebuilds the assumed-modes model).
    success : bool
    message : str
    station : Station
        The station with the masses at their optimal positions.
    """

    masses: tuple[MovableMass, ...]
    initial: np.ndarray
    optimal: np.ndarray
    objective_initial: float
    objective_optimal: float
    per_mode_initial: np.ndarray
    per_mode_optimal: np.ndarray
    omega_initial: np.ndarray
    omega_optimal: np.ndarray
    n_evaluations: int
    success: bool
    message: str
    station: Station = dataclasses.field(repr=False)

    @property
    def improvement(self) -> float:
        """objective_initial / objective_optimal (inf if the optimum is zero)."""
        if self.objective_optimal == 0:
            return float("inf")
        return self.objective_initial / self.objective_optimal


# --------------------------------------------------------------------------- helpers


def elastic_mask(omega: np.ndarray, rigid: np.ndarray | None = None) -> np.ndarray:
    """True for elastic modes: not rigid and ``omega >= ELASTIC_MIN_OMEGA`` (rad/s)."""
    omega = np.asarray(omega, float)
    el = omega >= ELASTIC_MIN_OMEGA
    if rigid is not None:
        el &= ~np.asarray(rigid, bool)
    return el


def in_plane_fraction(structure: Structure, modes: Modes, plane: str) -> np.ndarray:
    """Share of each mode's kinetic energy carried by motion in ``plane``.

    ``sum over in-plane coordinates i of phi_i (M phi)_i`` (the whole sum is
    ``phi^T M phi = 1``).  For a frame model the in-plane coordinates are the node
    translations in the plane and rotations about its normal (:data:`PLANE_DOFS`); an
    assumed-modes model is planar, so its modes are all in its own plane.  (The modal
    effective masses cannot do this job: an elastic mode of a free-free structure is
    M-orthogonal to the rigid-body vectors, so its effective masses are zero.)

    Parameters
    ----------
    structure : Structure
    modes : Modes
        Modes of ``structure``.
    plane : {"xz", "yz"}
    """
    if plane not in PLANE_DOFS:
        raise InputError(f"unknown plane {plane!r}", fix="use xz or yz")
    m = modes.n_modes
    if structure.plane is not None:
        return np.full(m, 1.0 if structure.plane == plane else 0.0)
    suffix = np.array([lab.rsplit(":", 1)[-1] for lab in structure.dof_labels])
    inplane = np.isin(suffix, PLANE_DOFS[plane])
    mphi = structure.mass @ modes.phi
    energy = np.asarray(modes.phi * mphi)
    return np.clip(energy[inplane].sum(axis=0), 0.0, 1.0)


def _sample_components(structure: Structure) -> np.ndarray:
    samples = structure.samples
    comp = getattr(samples, "component", None)
    if comp is not None:
        return np.asarray(comp).astype(str)
    labels = getattr(samples, "labels", None)
    if labels is None:
        raise InputError(
            "the structure has no samples", fix="build it with microg.structure.ritz or fem"
        )
    # frame samples: "beam:nK" nodes, "body/mass" masses, "body" master nodes
    return np.array([lab.split("/", 1)[0].split(":", 1)[0] for lab in labels])


def sample_shapes(
    structure: Structure, phi: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions (p, 3, m), carriers (p,) and modal translations (p, 3, m) of the samples.

    Parameters
    ----------
    structure : Structure
        With ``samples`` (assumed modes: :class:`~microg.structure.ritz.RitzSamples`;
        frame elements:
        :class:`~microg.structure.fem.NodeSamples`).
    phi : ndarray (n, m)
        Mode shapes, one per column.
    """
    samples = structure.samples
    if samples is None:
        raise InputError(
            "the structure has no samples", fix="build it with microg.structure.ritz or fem"
        )
    phi = np.asarray(phi, float)
    if hasattr(samples, "displacement"):
        shapes = np.asarray(samples.displacement(phi))
        if shapes.ndim == 2:
            shapes = shapes[:, :, None]
    else:
        shapes = np.einsum("pan,nm->pam", samples.translation, phi)
    return np.asarray(samples.position, float), _sample_components(structure), shapes


def _collinear(pos: np.ndarray, tol: float = 1e-9) -> tuple[np.ndarray, np.ndarray] | None:
    """(origin, unit axis) if the points lie on one line (at least two distinct), else None."""
    if pos.shape[0] < 2:
        return None
    c = pos.mean(axis=0)
    _, s, vt = np.linalg.svd(pos - c, full_matrices=False)
    if s[0] <= 0:
        return None
    if s.size > 1 and s[1] > tol * s[0]:
        return None
    axis = vt[0]
    axis = axis * (1.0 if axis[np.argmax(np.abs(axis))] > 0 else -1.0)
    return c, axis


def _affine_fit(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, bool]:
    """Least-squares affine fit of rows ``y`` (k, q) in ``t`` (k,); True if exact to rounding."""
    design = np.column_stack([np.ones_like(t), t])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    resid = float(np.max(np.abs(design @ coef - y))) if y.size else 0.0
    return coef, resid <= 1e-9 * max(float(np.max(np.abs(y))) if y.size else 0.0, 1e-300)


def _build_lines(
    positions: np.ndarray, component: np.ndarray, shapes: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[SampleLine]]:
    """Group samples into straight lines; densify rigid lines (exact: shapes are affine there).

    A carrier's samples form a line when they are collinear.  The line is *rigid* when every
    mode shape is affine along it (checked to rounding).  Beyond each end, the nearest sample
    of another carrier lying on the line within one sample spacing joins it (a beam's root
    node owned by its parent, a beam root on a body), if on a rigid line it obeys the same
    affine law; so sign changes at joints are not missed.  Rigid lines are then filled to
    BODY_LINE_SAMPLES evenly spaced samples by the affine law, which is exact.
    """
    lines: list[SampleLine] = []
    pos_out, comp_out, shp_out = [positions], [component], [shapes]
    n_total = positions.shape[0]
    scale = float(np.ptp(positions, axis=0).max()) or 1.0
    flat = shapes.reshape(shapes.shape[0], -1)
    for name in dict.fromkeys(component.tolist()):
        own = np.flatnonzero(component == name)
        geo = _collinear(positions[own])
        if geo is None:
            continue
        c, axis = geo
        rel = positions - c
        t_all = rel @ axis
        on_line = np.linalg.norm(rel - np.outer(t_all, axis), axis=1) <= 1e-9 * scale
        t_own = t_all[own]
        order = np.argsort(t_own, kind="stable")
        idx, t_idx = own[order], t_own[order]
        keep = np.r_[True, np.diff(t_idx) > 1e-9 * scale]
        idx, t_idx = idx[keep], t_idx[keep]
        if idx.size < 2:
            continue
        coef, rigid = _affine_fit(t_idx, flat[idx])
        rigid = rigid and idx.size >= 2
        step = float(np.max(np.diff(t_idx)))
        foreign = on_line & (component != name)
        for side in (-1.0, 1.0):
            end = t_idx[0] if side < 0 else t_idx[-1]
            gap = side * (t_all - end)
            cand = np.flatnonzero(foreign & (gap > 1e-9 * scale) & (gap <= 1.01 * step))
            if cand.size == 0:
                continue
            k = int(cand[np.argmin(gap[cand])])
            if rigid:
                pred = coef[0] + coef[1] * t_all[k]
                if np.max(np.abs(pred - flat[k])) > 1e-9 * max(np.max(np.abs(flat[idx])), 1e-300):
                    continue
            idx = np.r_[k, idx] if side < 0 else np.r_[idx, k]
            t_idx = np.r_[t_all[k], t_idx] if side < 0 else np.r_[t_idx, t_all[k]]
        if rigid and idx.size < BODY_LINE_SAMPLES:
            t_new = np.linspace(t_idx[0], t_idx[-1], BODY_LINE_SAMPLES)
            t_new = t_new[np.min(np.abs(t_new[:, None] - t_idx[None, :]), axis=1) > 1e-6 * scale]
            if t_new.size:
                new_flat = np.column_stack([np.ones_like(t_new), t_new]) @ coef
                pos_out.append(c + np.outer(t_new, axis))
                comp_out.append(np.full(t_new.size, name))
                shp_out.append(new_flat.reshape(t_new.size, *shapes.shape[1:]))
                new_idx = n_total + np.arange(t_new.size)
                n_total += t_new.size
                all_t = np.r_[t_idx, t_new]
                all_i = np.r_[idx, new_idx]
                order = np.argsort(all_t, kind="stable")
                idx, t_idx = all_i[order], all_t[order]
        lines.append(SampleLine(name, idx, c + t_idx[0] * axis, axis, rigid))
    return (
        np.concatenate(pos_out),
        np.concatenate(comp_out),
        np.concatenate(shp_out),
        lines,
    )


def _nodes(
    lines: Sequence[SampleLine], positions: np.ndarray, lateral: np.ndarray
) -> tuple[Node, ...]:
    """Sign changes of ``lateral`` (p,) along each line, by linear interpolation."""
    out: list[Node] = []
    seen: list[np.ndarray] = []
    scale = float(np.ptp(positions, axis=0).max()) or 1.0
    for line in lines:
        y = lateral[line.index]
        p = positions[line.index]
        a, b = y[:-1], y[1:]
        cross = (a * b < 0) | ((a == 0) & (b != 0))
        for k in np.flatnonzero(cross):
            frac = a[k] / (a[k] - b[k])
            pos = p[k] + frac * (p[k + 1] - p[k])
            if any(np.linalg.norm(pos - q) <= 1e-6 * scale for q in seen):
                continue
            seen.append(pos)
            out.append(Node(line.component, pos, float((pos - line.origin) @ line.axis)))
        if (
            y.size
            and y[-1] == 0
            and not any(np.linalg.norm(p[-1] - q) <= 1e-6 * scale for q in seen)
        ):
            seen.append(p[-1])
            out.append(Node(line.component, p[-1], float((p[-1] - line.origin) @ line.axis)))
    return tuple(out)


def _force_breakpoints(crew: Any) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(crew, CrewPushoff):
        return crew.breakpoints()
    t = getattr(crew, "timepts", None)
    f = getattr(crew, "force", None)
    if t is None or f is None:
        raise InputError(
            "the force must be a CrewPushoff or a ForceHistory", where="acceleration_map"
        )
    return np.asarray(t, float), np.asarray(f, float)


def _time_grid(
    tb: np.ndarray, omega: np.ndarray, elastic: np.ndarray, duration: float | None
) -> np.ndarray:
    """Output times: uniform at POINTS_PER_PERIOD of the fastest mode, plus both sides of jumps."""
    t0, t_last = float(tb[0]), float(tb[-1])
    if duration is None:
        tail = 3.0 * 2.0 * np.pi / omega[elastic].min() if np.any(elastic) else 1.0
        t_end = t_last + tail
    else:
        t_end = t0 + float(duration)
    span = max(t_end - t0, 1e-9)
    w_max = float(omega.max()) if omega.size else 0.0
    dt = 2.0 * np.pi / w_max / POINTS_PER_PERIOD if w_max > 0 else span / 2000.0
    dt = min(dt, span / 2000.0)
    n = int(min(np.ceil(span / dt) + 1, MAX_TIMEPTS))
    grid = np.linspace(t0, t_end, n)
    extra = np.concatenate([tb, np.nextafter(tb, -np.inf)])
    extra = extra[(extra >= t0) & (extra <= t_end)]
    return np.unique(np.concatenate([grid, extra]))


def mode_peak_factors(
    omega: np.ndarray, crew: CrewPushoff | Any, zeta: np.ndarray | float = 0.0
) -> tuple[np.ndarray, bool]:
    """Peak modal acceleration per unit modal participation, ``max_t |eta_j''(t)|`` (m/s^2 / N).

    For the report's push-off (Eq. 2.16) and undamped modes this is
    ``f0 [A_j]max / (omega_j t1)`` (Eqs. 2.18, 3.1, exact [A]max) and ``|f0|`` for a rigid
    mode (omega = 0: the acceleration follows the force); otherwise the peak over a time
    grid of the exact piecewise-linear response
    (:func:`~microg.dynamics.response.modal_pwl_response`).

    Parameters
    ----------
    omega : ndarray (m,)
        rad/s.
    crew : CrewPushoff or ForceHistory
        Force history, N.
    zeta : float or ndarray (m,)
        Modal damping ratios.

    Returns
    -------
    peaks : ndarray (m,)
        m/s^2 per (m/sqrt(kg))^2 of mass-normalised participation, i.e. N/kg.
    exact : bool
        True when the closed form was used.
    """
    omega = np.asarray(omega, float)
    zeta = np.broadcast_to(np.asarray(zeta, float), omega.shape)
    if isinstance(crew, CrewPushoff) and np.all(zeta == 0):
        out = np.full(omega.shape, abs(crew.f0))
        pos = omega > 0
        if np.any(pos):
            out[pos] = abs(crew.f0) * accel_amax(omega[pos], crew) / (omega[pos] * crew.t1)
        return out, True
    tb, fb = _force_breakpoints(crew)
    grid = _time_grid(tb, omega, elastic_mask(omega), None)
    res = modal_pwl_response(omega, zeta, tb, np.tile(fb, (omega.size, 1)), grid)
    return np.max(np.abs(res.eta_ddot), axis=1), False


def _block_peak(r: np.ndarray, eta_ddot: np.ndarray) -> np.ndarray:
    """max over t of |r @ eta_ddot| (p,), in blocks of time to bound memory."""
    p, nt = r.shape[0], eta_ddot.shape[1]
    out = np.zeros(p)
    if r.shape[1] == 0:
        return out
    block = max(1, int(4_000_000 // max(p, 1)))
    for start in range(0, nt, block):
        a = r @ eta_ddot[:, start : start + block]
        np.maximum(out, np.max(np.abs(a), axis=1), out=out)
    return out


def _max_or_zero(x: np.ndarray, mask: np.ndarray) -> float:
    return float(np.max(np.abs(x[mask]))) if np.any(mask) else 0.0


# --------------------------------------------------------------------------- the map


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
) -> AccelerationMap:
    """Peak acceleration at every sample of the structure from a force at ``crew_point``.

    Per mode (Eq. 2.20b, Eq. 3.1 with mass-normalised shapes, ``M_jj = 1``)::

        a_j(s) = |phi_j(s).d| |phi_j(crew).d| f0 [A_j]max / (omega_j t1)

    (``f0 |phi_j(s).d| |phi_j(crew).d|`` for a rigid-body mode), vectorised over samples and
    modes.  The total is the peak over a time window of the modal sum
    ``a(s, t) = sum_j phi_j(s).d phi_j(crew).d eta_j''(t)`` with the exact piecewise-linear
    modal response evaluated on a grid of at least ``POINTS_PER_PERIOD`` points per period
    of the fastest mode (and both sides of every force jump); ``peak_bound`` is the sum of
    the per-mode peaks.

    Parameters
    ----------
    structure : Structure
        With samples (:func:`~microg.structure.ritz.build_ritz` or
        :func:`~microg.structure.fem.build_fem`).
    modes : Modes
        Modes of ``structure`` (mass-normalised).
    crew_point : str
        Named point where the force acts (unknown: InputError listing the known points).
    direction : ndarray (3,) or {"x", "y", "z"}
        Force direction; accelerations are taken along it.
    crew : CrewPushoff or ForceHistory
        The force history, N (the report's Eq. 2.16 push-off, or any piecewise-linear one).
    zeta : float or ndarray (m,)
        Modal damping ratios (0 <= zeta < 1).
    include_rigid : bool
        Include the rigid-body modes (their acceleration is the same everywhere for a
        translation, grows with the distance from the centre of mass for a rotation).
    duration : float, optional
        Length of the time window from the first breakpoint, s (default: to the last
        breakpoint plus three periods of the fundamental elastic mode).
    """
    d = parse_direction(direction, "direction")
    cp = structure.point(crew_point)
    omega = np.asarray(modes.omega, float)
    rigid = np.asarray(modes.rigid, bool)
    zeta_arr = np.broadcast_to(np.asarray(zeta, float), omega.shape).astype(float)
    if np.any(~np.isfinite(zeta_arr)) or np.any(zeta_arr < 0) or np.any(zeta_arr >= 1):
        raise InputError("damping ratio must satisfy 0 <= zeta < 1", where="zeta")
    use = np.ones(omega.size, bool) if include_rigid else ~rigid
    omega, rigid, zeta_arr = omega[use], rigid[use], zeta_arr[use]
    phi = np.asarray(modes.phi, float)[:, use]
    elastic = elastic_mask(omega, rigid)

    positions, component, shapes = sample_shapes(structure, phi)
    positions, component, shapes, lines = _build_lines(positions, component, shapes)
    resp = np.einsum("pam,a->pm", shapes, d)  # displacement along d per unit modal coordinate
    gamma = (np.asarray(cp.translation, float) @ phi).T @ d  # (m,)

    peaks, exact = mode_peak_factors(omega, crew, zeta_arr)
    per_mode = np.abs(resp.T) * np.abs(gamma)[:, None] * peaks[:, None]

    tb, fb = _force_breakpoints(crew)
    grid = _time_grid(tb, omega, elastic, duration)
    modal = modal_pwl_response(omega, zeta_arr, tb, np.outer(gamma, fb), grid)
    total = _block_peak(resp, modal.eta_ddot)
    el_peak = _block_peak(resp[:, elastic], modal.eta_ddot[elastic])
    bound = per_mode.sum(axis=0)

    long_time = None
    if np.all(zeta_arr == 0) and fb[-1] == 0 and omega.size:
        end = modal_pwl_response(omega, zeta_arr, tb, np.outer(gamma, fb), tb[-1:])
        amp = omega * np.hypot(omega * end.eta[:, 0], end.eta_dot[:, 0])
        long_time = np.maximum(total, np.abs(resp) @ np.abs(amp))

    fund = None
    fshape = None
    nodes: tuple[Node, ...] = ()
    # the fundamental: the lowest elastic mode the force excites (a 3-D model has modes the
    # force cannot reach, e.g. out-of-plane bending for an in-plane push)
    excited = elastic & (
        np.abs(gamma) > FUNDAMENTAL_MIN_PARTICIPATION * _max_or_zero(gamma, elastic)
    )
    if np.any(excited):
        fund = int(np.flatnonzero(excited)[np.argmin(omega[excited])])
        fshape = resp[:, fund]
        nodes = _nodes(lines, positions, fshape)
    return AccelerationMap(
        positions=positions,
        component=component,
        direction=d,
        crew_point=crew_point,
        crew_position=np.asarray(cp.position, float),
        omega=omega,
        rigid=rigid,
        elastic=elastic,
        per_mode=per_mode,
        total_peak=total,
        elastic_peak=el_peak,
        peak_bound=bound,
        long_time_peak=long_time,
        window=(float(grid[0]), float(grid[-1])),
        n_timepts=int(grid.size),
        fundamental=fund,
        fundamental_shape=fshape,
        lines=tuple(lines),
        nodes=nodes,
        exact_per_mode=exact,
        zeta=zeta_arr,
        include_rigid=include_rigid,
        method=structure.method,
        plane=structure.plane,
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
    measure : {"total", "elastic", "bound", "long_time"}
        Which peak to minimise (see :class:`AccelerationMap`).
    """
    values = amap.measure(measure)
    mask = np.ones(values.size, bool)
    if component is not None:
        mask = amap.component == component
        if not np.any(mask):
            known = ", ".join(sorted(set(amap.component.tolist())))
            raise InputError(f"no samples on {component!r}", fix=f"known components: {known}")
    idx = np.flatnonzero(mask)
    i = int(idx[np.argmin(values[idx])])
    return Location(i, str(amap.component[i]), amap.positions[i], float(values[i]), measure)


# --------------------------------------------------------------------------- layout


def _carriers(station: Station) -> list[RigidBody | Beam]:
    return [*station.bodies, *station.beams]


def resolve_mass(station: Station, key: str) -> tuple[RigidBody | Beam, PointMass]:
    """The carrier and point mass named ``key`` (``"name"`` if unique, else ``"carrier/name"``).

    Raises InputError for an unknown or ambiguous name, listing the choices.
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
            where="--movable",
            fix=f"known masses: {', '.join(names)}",
        )
    opts = ", ".join(f"{c.name}/{pm.name}" for c, pm in hits)
    raise InputError(
        f"mass name {key!r} is ambiguous", where="--movable", fix=f"write one of {opts}"
    )


def _body_extent(station: Station, body: RigidBody) -> tuple[float, float]:
    z = [float(pm.position[2]) for pm in body.masses]
    z += [float(b.root[2]) for b in station.beams if b.parent == body.name]
    if body.attach is not None:
        z.append(float(body.attach[2]))
    return (min(z), max(z)) if z else (0.0, 0.0)


def movable_masses(
    station: Station, overrides: Mapping[str, tuple[float, float]] | None = None
) -> tuple[MovableMass, ...]:
    """The movable masses of ``station``: those marked in the file, plus/over ``overrides``.

    A beam mass moves along its beam (arc length s, within 0..length); a body mass moves
    along z within the body's extent (from the lowest to the highest of its masses, beam
    roots and attachment).  The range must contain the current position and have lo < hi.

    Parameters
    ----------
    station : Station
    overrides : mapping of mass key to (lo, hi), m
        Keys as for :func:`resolve_mass`; they replace the file's ranges.
    """
    chosen: dict[str, tuple[RigidBody | Beam, PointMass, tuple[float, float]]] = {}
    for comp in _carriers(station):
        for pm in comp.masses:
            if pm.movable is not None:
                chosen[f"{comp.name}/{pm.name}"] = (comp, pm, pm.movable)
    for key, rng in (overrides or {}).items():
        comp, pm = resolve_mass(station, key)
        chosen[f"{comp.name}/{pm.name}"] = (comp, pm, (float(rng[0]), float(rng[1])))
    out = []
    for key, (comp, pm, (lo, hi)) in chosen.items():
        where = f"--movable {key}"
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
        if isinstance(comp, Beam):
            pos = comp.station_position(float(v))
        else:
            pos = np.array([pm.position[0], pm.position[1], float(v)])
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


def layout_objective(
    station: Station,
    experiment_point: str,
    crew_point: str,
    crew: CrewPushoff,
    *,
    plane: str = "xz",
    n_functions: int = 1,
    direction: np.ndarray | None = None,
) -> tuple[float, np.ndarray, np.ndarray]:
    """Summed elastic Eq. 3.1 peak at the experiment site, m/s^2, with its terms and omegas.

    ``J = sum over elastic j of |phi_j(e).d| |phi_j(a).d| f0 [A_j]max / (omega_j t1)``
    (mass-normalised shapes), on the assumed-modes model of ``station`` in ``plane``.

    Parameters
    ----------
    station : Station
    experiment_point, crew_point : str
        Named points (experiment site e, crew force a).
    crew : CrewPushoff
        Force of Eq. 2.16, N.
    plane : {"xz", "yz"}
    n_functions : int
        Admissible functions per beam.
    direction : ndarray (3,), optional
        Force direction (default: the plane's lateral axis, the only one the planar model has).
    """
    from microg.structure.ritz import PLANES, assemble, planar_coordinates, point_maps

    coords = planar_coordinates(station, plane, n_functions)
    mass, stiff = assemble(station, coords, gravity_gradient=True)
    cand = np.zeros((len(coords), 1))
    cand[0, 0] = 1.0  # the translation coordinate: the only exact rigid-body vector
    omega, phi, rigid = solve_dense(mass, stiff, cand)
    maps = point_maps(station, coords)
    for name in (experiment_point, crew_point):
        if name not in maps:
            known = ", ".join(sorted(maps))
            raise InputError(f"unknown point {name!r}", fix=f"known points: {known}")
    d = PLANES[plane]["lateral"] if direction is None else parse_direction(direction, "direction")
    el = elastic_mask(omega, rigid)
    pe = (maps[experiment_point].translation @ phi[:, el]).T @ d
    pa = (maps[crew_point].translation @ phi[:, el]).T @ d
    peaks, _ = mode_peak_factors(omega[el], crew)
    terms = np.abs(pe * pa) * peaks
    return float(terms.sum()), terms, omega[el]


def optimize_layout(
    station: Station,
    experiment_point: str,
    crew_point: str,
    crew: CrewPushoff,
    *,
    movable: Mapping[str, tuple[float, float]] | None = None,
    carry: Mapping[str, str] | None = None,
    plane: str = "xz",
    n_functions: int = 1,
    seed: int = 0,
    maxiter: int = 60,
    popsize: int = 12,
    polish: bool = True,
) -> LayoutResult:
    """Move the movable masses to minimise the crew-induced peak at an experiment site.

    The objective is :func:`layout_objective` (report conclusion 9: Eq. 3.1 summed over the
    elastic modes, exact [A]max), the assumed-modes model rebuilt for every trial layout.
    A seeded ``scipy.optimize.differential_evolution`` over the bounds finds the basin
    (the objective is multimodal: it is near zero wherever a node of a mode crosses the
    site), then L-BFGS-B polishes it inside the same bounds; the better point is kept.

    Parameters
    ----------
    station : Station
    experiment_point, crew_point : str
        Named points.
    crew : CrewPushoff
    movable : mapping of mass key to (lo, hi) m, optional
        Ranges overriding/adding to the file's ``movable`` ranges (see :func:`movable_masses`).
    carry : mapping of point name to mass key, optional
        Named points that move with a mass.
    plane : {"xz", "yz"}
    n_functions : int
        Admissible functions per beam (1 = the report's model).
    seed : int
        Seed of the differential evolution (results are reproducible).
    maxiter, popsize : int
        Differential-evolution generations and population multiplier.
    polish : bool
        Run the L-BFGS-B polish.
    """
    from scipy.optimize import differential_evolution, minimize

    masses = movable_masses(station, movable)
    if not masses:
        raise InputError(
            "no movable masses",
            where="--movable",
            fix='mark masses movable in the model file or pass --movable "NAME=LO:HI"',
        )
    keys = {mm.key for mm in masses}
    carry_full = {}
    for point, key in (carry or {}).items():
        comp, pm = resolve_mass(station, key)
        carry_full[point] = f"{comp.name}/{pm.name}"
        if carry_full[point] not in keys:
            raise InputError(f"mass {key!r} is not movable", where=f"--carry {point}")
    known_points = [p.name for p in station.points]
    for name in (experiment_point, crew_point, *carry_full):
        if name not in known_points:
            raise InputError(
                f"unknown point {name!r}", fix=f"known points: {', '.join(sorted(known_points))}"
            )
    x0 = np.array([mm.value for mm in masses])
    bounds = [mm.bounds for mm in masses]
    count = [0]

    def evaluate(x: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        count[0] += 1
        st = move_masses(
            station,
            masses,
            np.clip(x, [b[0] for b in bounds], [b[1] for b in bounds]),
            carry=carry_full,
        )
        return layout_objective(
            st, experiment_point, crew_point, crew, plane=plane, n_functions=n_functions
        )

    def fun(x: np.ndarray) -> float:
        return evaluate(x)[0]

    j0, terms0, w0 = evaluate(x0)
    de = differential_evolution(
        fun,
        bounds,
        seed=seed,
        maxiter=maxiter,
        popsize=popsize,
        tol=1e-8,
        polish=False,
        init="sobol",
    )
    best_x, best_f, message, success = (
        np.asarray(de.x, float),
        float(de.fun),
        str(de.message),
        bool(de.success),
    )
    if polish:
        loc = minimize(fun, best_x, method="L-BFGS-B", bounds=bounds)
        if loc.fun < best_f:
            best_x, best_f = np.asarray(loc.x, float), float(loc.fun)
            message += f"; L-BFGS-B: {loc.message}"
    if j0 <= best_f:  # never report a layout worse than the start
        best_x, best_f = x0.copy(), j0
    st_opt = move_masses(station, masses, best_x, carry=carry_full)
    j1, terms1, w1 = layout_objective(
        st_opt, experiment_point, crew_point, crew, plane=plane, n_functions=n_functions
    )
    return LayoutResult(
        masses=masses,
        initial=x0,
        optimal=best_x,
        objective_initial=j0,
        objective_optimal=j1,
        per_mode_initial=terms0,
        per_mode_optimal=terms1,
        omega_initial=w0,
        omega_optimal=w1,
        n_evaluations=count[0],
        success=success,
        message=message,
        station=st_opt,
    )


# --------------------------------------------------------------------------- conclusion 7


@dataclass(frozen=True)
class Conclusion7Case:
    """One orbiter case of the report's conclusion 7 recomputed (X-Z plane, Ritz).

    Attributes
    ----------
    model : str
    total_mass : float
        kg.
    cm_z : float
        Centre of mass z, m.
    lab_z : float
        Laboratory (experiment and crew) z, m.
    lab_to_cm : float
        |lab_z - cm_z|, m.
    omega : ndarray (k,)
        Elastic frequencies, rad/s.
    lab_per_mode : ndarray (k,)
        Eq. 3.1 at the lab per elastic mode, m/s^2.
    lab_elastic_peak : float
        Peak of the elastic modal sum at the lab over the window, m/s^2.
    lab_total_peak : float
        The same with the rigid-body modes (translation), m/s^2.
    rigid_translation : float
        f0 / total mass, m/s^2 (the same everywhere).
    body_nodes_z : ndarray
        z of the fundamental's nodes on the main body, m.
    best_z : float
        z of the quietest main-body sample (elastic measure), m.
    best_elastic_peak : float
        Its elastic peak, m/s^2.
    amap : AccelerationMap
    """

    model: str
    total_mass: float
    cm_z: float
    lab_z: float
    lab_to_cm: float
    omega: np.ndarray
    lab_per_mode: np.ndarray
    lab_elastic_peak: float
    lab_total_peak: float
    rigid_translation: float
    body_nodes_z: np.ndarray
    best_z: float
    best_elastic_peak: float
    amap: AccelerationMap = dataclasses.field(repr=False)


@dataclass(frozen=True)
class Conclusion7:
    """Conclusion 7 / Figure 9 recomputed for the IOC with and without the orbiter.

    Attributes
    ----------
    orbiter, no_orbiter : Conclusion7Case
    ratio_mode1 : float
        Fundamental's Eq. 3.1 at the lab, orbiter / no orbiter (the report: 1.14e-5/1.44e-8).
    ratio_elastic : float
        Elastic peak at the lab, orbiter / no orbiter.
    ratio_total : float
        Total peak (rigid translation included) at the lab, orbiter / no orbiter.
    printed_ratio_mode1 : float
        The report's Table 4 ratio for the first bending mode.
    moved : float
        Increase of the lab's distance from the centre of mass without the orbiter, m
        (the report: 59.9 ft).
    """

    orbiter: Conclusion7Case
    no_orbiter: Conclusion7Case
    ratio_mode1: float
    ratio_elastic: float
    ratio_total: float
    printed_ratio_mode1: float
    moved: float


def _conclusion7_case(
    station: Station, crew: CrewPushoff, point: str, body: str
) -> Conclusion7Case:
    from microg.dynamics.modes import solve_modes
    from microg.structure.ritz import build_ritz

    structure = build_ritz(station, "xz", 1)
    modes = solve_modes(structure)
    amap = acceleration_map(structure, modes, point, "x", crew)
    total, cm, _ = station.mass_properties()
    lab = structure.point(point)
    lab_z = float(lab.position[2])
    phi = modes.phi
    el = elastic_mask(modes.omega, modes.rigid)
    g = (lab.translation @ phi)[0]
    peaks, _ = mode_peak_factors(modes.omega, crew)
    per_mode = (g * g * peaks)[el]
    # peaks at the lab itself: the lab is a named point; evaluate through a one-point map
    i_lab = int(np.argmin(np.linalg.norm(amap.positions - lab.position, axis=1)))
    if np.linalg.norm(amap.positions[i_lab] - lab.position) > 1e-6:
        raise InputError(f"point {point!r} is not on a sample line", where="conclusion7")
    best = best_location(amap, component=body, measure="elastic")
    nodes = np.array([n.position[2] for n in amap.nodes if n.component == body])
    return Conclusion7Case(
        model=station.name,
        total_mass=total,
        cm_z=float(cm[2]),
        lab_z=lab_z,
        lab_to_cm=abs(lab_z - float(cm[2])),
        omega=modes.omega[el],
        lab_per_mode=per_mode,
        lab_elastic_peak=float(amap.elastic_peak[i_lab]),
        lab_total_peak=float(amap.total_peak[i_lab]),
        rigid_translation=abs(crew.f0) / total,
        body_nodes_z=nodes,
        best_z=float(best.position[2]),
        best_elastic_peak=best.peak,
        amap=amap,
    )


def conclusion7(
    crew: CrewPushoff | None = None,
    stations: tuple[Station, Station] | None = None,
    *,
    point: str = "crew",
    body: str = "main",
) -> Conclusion7:
    """Recompute the report's conclusion 7 and Figure 9 (X-Z plane, one function per beam).

    The crew force and the experiment are both at ``point`` (the shipped models' ``crew``,
    z = -55 ft); the push-off is along x.

    Parameters
    ----------
    crew : CrewPushoff, optional
        Default: the report's 25 lbf, 1 s, 13 s, 14 s.
    stations : (with orbiter, without), optional
        Default: the shipped ``ioc`` and ``ioc-no-orbiter``.
    point : str
        Named point of crew and experiment.
    body : str
        The body where laboratories go (for nodes and the best location).
    """
    from microg.dynamics.forces import REPORT_F0_N
    from microg.models.toml import load_station
    from microg.seed.ioc import printed

    crew = crew or CrewPushoff(REPORT_F0_N)
    if stations is None:
        stations = (load_station("ioc"), load_station("ioc-no-orbiter"))
    a = _conclusion7_case(stations[0], crew, point, body)
    b = _conclusion7_case(stations[1], crew, point, body)
    t4 = printed()["table4"]
    pr = t4["xz_orbiter"]["bending_accel_g"][0] / t4["xz_no_orbiter"]["bending_accel_g"][0]
    return Conclusion7(
        orbiter=a,
        no_orbiter=b,
        ratio_mode1=float(a.lab_per_mode[0] / b.lab_per_mode[0]),
        ratio_elastic=a.lab_elastic_peak / b.lab_elastic_peak,
        ratio_total=a.lab_total_peak / b.lab_total_peak,
        printed_ratio_mode1=float(pr),
        moved=b.lab_to_cm - a.lab_to_cm,
    )


# --------------------------------------------------------------------------- figure


def map_figure(
    amap: AccelerationMap,
    *,
    measure: str = "total",
    title: str | None = None,
    best: Location | None = None,
) -> Any:
    """The map drawn on the structure: lines in the view plane, colour = log10 peak (g).

    The view plane is spanned by the two axes along which the samples extend most (the
    IOC: y-z, keel vertical and boom horizontal).  Nodes of the fundamental are black
    crosses, the crew point a red star, ``best`` (if given) a magenta circle.  Returns a
    matplotlib Figure (Agg backend).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    values = amap.measure(measure) / G0
    ext = np.ptp(amap.positions, axis=0)
    ax_idx = np.sort(np.argsort(ext)[-2:])
    names = "xyz"
    logv = np.log10(np.maximum(values, 1e-30))
    finite = values > 0
    vmin = float(logv[finite].min()) if np.any(finite) else -12.0
    vmax = float(logv[finite].max()) if np.any(finite) else -6.0
    fig, ax = plt.subplots(figsize=(7.5, 6.0), layout="constrained")
    norm = plt.Normalize(vmin, vmax)
    for line in amap.lines:
        xy = amap.positions[line.index][:, ax_idx]
        segs = np.stack([xy[:-1], xy[1:]], axis=1)
        seg_val = 0.5 * (logv[line.index][:-1] + logv[line.index][1:])
        # matplotlib's stub wants a Sequence; an (nseg, 2, 2) ndarray is accepted at run time
        lc = LineCollection(segs, cmap="viridis", norm=norm, linewidths=5)  # type: ignore[arg-type]
        lc.set_array(seg_val)
        ax.add_collection(lc)
    sc = ax.scatter(
        amap.positions[:, ax_idx[0]],
        amap.positions[:, ax_idx[1]],
        c=logv,
        cmap="viridis",
        norm=norm,
        s=12,
        zorder=3,
    )
    fig.colorbar(sc, ax=ax, label=f"log10 peak acceleration ({measure}), g")
    if amap.nodes:
        npos = np.array([n.position for n in amap.nodes])
        ax.scatter(
            npos[:, ax_idx[0]],
            npos[:, ax_idx[1]],
            marker="x",
            c="k",
            s=80,
            zorder=4,
            label="nodes of the fundamental",
        )
    ax.scatter(
        [amap.crew_position[ax_idx[0]]],
        [amap.crew_position[ax_idx[1]]],
        marker="*",
        c="r",
        s=160,
        zorder=5,
        label=f"crew point {amap.crew_point!r}",
    )
    if best is not None:
        ax.scatter(
            [best.position[ax_idx[0]]],
            [best.position[ax_idx[1]]],
            marker="o",
            facecolors="none",
            edgecolors="m",
            s=160,
            linewidths=2,
            zorder=5,
            label=f"best location ({best.measure})",
        )
    ax.set_xlabel(f"{names[ax_idx[0]]} (m)")
    ax.set_ylabel(f"{names[ax_idx[1]]} (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(title or f"Peak acceleration from a push-off at {amap.crew_point!r}")
    return fig
