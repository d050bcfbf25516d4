"""Peak accelerations of modes: Eq. 3.1 per mode, the rigid-body part, the peak over time.

With mass-normalised shapes (``M_jj = 1``) a force ``f(t)`` along ``d`` at the crew point
``a`` drives mode ``j`` as ``eta_j'' + 2 zeta_j omega_j eta_j' + omega_j^2 eta_j =
gamma_j f(t)``, ``gamma_j = phi_j(a).d``, and the acceleration at a point ``s`` along ``d``
is ``sum_j phi_j(s).d eta_j''(t)``.  This module gives

* :func:`mode_peak_factors`: ``max_t |eta_j''| / gamma_j`` per mode, the report's Eq. 3.1
  factor ``f0 [A_j]max / (omega_j t1)`` for the undamped push-off of Eq. 2.16 (exact
  ``[A]max``), ``max |f|`` for a rigid-body mode;
* :func:`rigid_part`: the rigid-body modes' acceleration, ``c f(t)`` with
  ``c = sum over rigid j of phi_j(s).d phi_j(a).d`` -- independent of the basis chosen in
  the degenerate rigid-body subspace, so its peak ``|c| max|f|`` is exact;
* :func:`time_grid`, :func:`peak_over_time`: the peak over a time window of a modal sum on a
  grid of :data:`POINTS_PER_PERIOD` points per period of the fastest mode plus both sides of
  every force jump;
* :func:`elastic_modes`: which modes are elastic -- the one rule, ``Modes.elastic`` where
  the modes define it, else every mode that is not an exact rigid-body mode;
* :func:`point_peaks`: all of these at a set of points at once (the kernel of the map and of
  the peaks at one point), for the modes :func:`kept_modes` keeps.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.dynamics.crew import CrewPushoff, accel_amax
from microg.dynamics.response import modal_pwl_response
from microg.errors import InputError

if TYPE_CHECKING:
    from microg.dynamics.modes import Modes

__all__ = [
    "MAX_TIMEPTS",
    "POINTS_PER_PERIOD",
    "PointPeaks",
    "elastic_mask",
    "elastic_modes",
    "force_breakpoints",
    "kept_modes",
    "max_force",
    "mode_peak_factors",
    "peak_over_time",
    "point_peaks",
    "rigid_part",
    "time_grid",
]

#: grid points per period of the fastest mode for the time-domain peak (under-estimates a
#: sinusoid's crest by at most 1 - cos(pi/32) = 0.48 %)
POINTS_PER_PERIOD = 32
#: largest time grid of a peak over time
MAX_TIMEPTS = 400_000
#: minimum number of grid intervals over the window
MIN_INTERVALS = 2000


def elastic_modes(modes: Any) -> np.ndarray:
    """Boolean mask of the elastic modes: ``modes.elastic`` if defined, else ``~modes.rigid``.

    The one rule of what "elastic" means lives on :class:`~microg.dynamics.modes.Modes`;
    this module never sets a frequency threshold of its own.

    Parameters
    ----------
    modes : Modes
    """
    el = getattr(modes, "elastic", None)
    if callable(el):
        el = el()
    if el is not None:
        return np.array(el, dtype=bool)
    return ~np.asarray(modes.rigid, bool)


def elastic_mask(modes_or_omega: Any, rigid: np.ndarray | None = None) -> np.ndarray:
    """The elastic modes, from a Modes object or from ``(omega, rigid)`` arrays.

    With a Modes object this is :func:`elastic_modes`; with arrays, ``~rigid`` (the
    fallback rule).  Kept for callers of the former ``microg.location.amap.elastic_mask``.

    Parameters
    ----------
    modes_or_omega : Modes or ndarray (m,)
        Modes, or their frequencies in rad/s (not used by the rule).
    rigid : ndarray (m,) of bool, optional
        Required with arrays.
    """
    if hasattr(modes_or_omega, "rigid"):
        return elastic_modes(modes_or_omega)
    if rigid is None:
        raise InputError(
            "elastic_mask needs the rigid flags of the modes",
            where="rigid",
            fix="pass modes.rigid, or the Modes object itself",
        )
    return ~np.asarray(rigid, bool)


def force_breakpoints(force: Any) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoint times (s) and forces (N) of a piecewise-linear force history.

    Parameters
    ----------
    force : CrewPushoff or ForceHistory
        The report's push-off (Eq. 2.16) or any object with ``timepts`` and ``force``.
    """
    if isinstance(force, CrewPushoff):
        return force.breakpoints()
    t = getattr(force, "timepts", None)
    f = getattr(force, "force", None)
    if t is None or f is None:
        raise InputError("must be a CrewPushoff or a ForceHistory", where="force")
    return np.asarray(t, float), np.asarray(f, float)


def max_force(force: Any) -> float:
    """``max_t |f(t)|`` of a piecewise-linear force, N (attained at a breakpoint)."""
    _, fb = force_breakpoints(force)
    return float(np.max(np.abs(fb))) if fb.size else 0.0


def time_grid(
    tb: np.ndarray, omega: np.ndarray, elastic: np.ndarray, duration: float | None
) -> np.ndarray:
    """Output times, s: uniform at POINTS_PER_PERIOD of the fastest mode, plus both jump sides.

    The window runs from the first breakpoint to the last plus three periods of the slowest
    elastic mode (or for ``duration`` s); at least :data:`MIN_INTERVALS` intervals, at most
    :data:`MAX_TIMEPTS` points.

    Parameters
    ----------
    tb : ndarray (nb,)
        Force breakpoints, s (a repeated time is a jump).
    omega : ndarray (m,)
        Modal frequencies, rad/s.
    elastic : ndarray (m,) of bool
        Elastic modes (their slowest sets the tail).
    duration : float, optional
        Window length, s.
    """
    t0, t_last = float(tb[0]), float(tb[-1])
    if duration is None:
        tail = 3.0 * 2.0 * np.pi / omega[elastic].min() if np.any(elastic) else 1.0
        t_end = t_last + tail
    else:
        t_end = t0 + float(duration)
    span = max(t_end - t0, 1e-9)
    w_max = float(omega.max()) if omega.size else 0.0
    dt = 2.0 * np.pi / w_max / POINTS_PER_PERIOD if w_max > 0 else span / MIN_INTERVALS
    dt = min(dt, span / MIN_INTERVALS)
    n = int(min(np.ceil(span / dt) + 1, MAX_TIMEPTS))
    grid = np.linspace(t0, t_end, n)
    extra = np.concatenate([tb, np.nextafter(tb, -np.inf)])
    extra = extra[(extra >= t0) & (extra <= t_end)]
    return np.unique(np.concatenate([grid, extra]))


def mode_peak_factors(
    omega: np.ndarray,
    force: CrewPushoff | Any,
    zeta: np.ndarray | float = 0.0,
    *,
    elastic: np.ndarray | None = None,
) -> tuple[np.ndarray, bool]:
    """Peak modal acceleration per unit modal participation, ``max_t |eta_j''(t)|`` (N/kg).

    For the report's push-off (Eq. 2.16) and undamped modes this is
    ``f0 [A_j]max / (omega_j t1)`` (Eqs. 2.18, 3.1, exact [A]max) and ``|f0|`` for a rigid
    mode (omega = 0: the acceleration follows the force); otherwise the peak over a time
    grid (:func:`time_grid`) of the exact piecewise-linear response
    (:func:`~microg.dynamics.response.modal_pwl_response`).

    Parameters
    ----------
    omega : ndarray (m,)
        rad/s.
    force : CrewPushoff or ForceHistory
        Force history, N.
    zeta : float or ndarray (m,)
        Modal damping ratios.
    elastic : ndarray (m,) of bool, optional
        Elastic modes (set the grid's tail; default: the modes with omega > 0).

    Returns
    -------
    peaks : ndarray (m,)
        m/s^2 per (m/sqrt(kg))^2 of mass-normalised participation, i.e. N/kg.
    exact : bool
        True when the closed form was used.
    """
    omega = np.asarray(omega, float)
    zeta = np.broadcast_to(np.asarray(zeta, float), omega.shape)
    if isinstance(force, CrewPushoff) and np.all(zeta == 0):
        out = np.full(omega.shape, abs(force.f0))
        pos = omega > 0
        if np.any(pos):
            out[pos] = abs(force.f0) * accel_amax(omega[pos], force) / (omega[pos] * force.t1)
        return out, True
    tb, fb = force_breakpoints(force)
    el = omega > 0 if elastic is None else np.asarray(elastic, bool)
    grid = time_grid(tb, omega, el, None)
    res = modal_pwl_response(omega, zeta, tb, np.tile(fb, (omega.size, 1)), grid)
    return np.max(np.abs(res.eta_ddot), axis=1), False


def rigid_part(resp: np.ndarray, gamma: np.ndarray, rigid: np.ndarray, force: Any) -> np.ndarray:
    """Peak of the rigid-body modes' acceleration, ``|sum_rigid resp_j gamma_j| max|f|``.

    The rigid modes follow the force exactly (``eta_j'' = gamma_j f(t)``, with or without
    damping), so their sum at a point is ``c f(t)``; ``c`` (and so the result) does not
    depend on the basis of the rigid-body subspace.

    Parameters
    ----------
    resp : ndarray (p, m)
        Displacement along ``d`` of each point per unit modal coordinate.
    gamma : ndarray (m,)
        Participation ``phi_j(crew).d`` of each mode.
    rigid : ndarray (m,) of bool
    force : CrewPushoff or ForceHistory
        N.

    Returns
    -------
    ndarray (p,)
        m/s^2.
    """
    rigid = np.asarray(rigid, bool)
    c = resp[:, rigid] @ gamma[rigid]
    return np.abs(c) * max_force(force)


def peak_over_time(r: np.ndarray, eta_ddot: np.ndarray) -> np.ndarray:
    """``max over t of |r @ eta_ddot|`` (p,), evaluated in blocks of time to bound memory.

    Parameters
    ----------
    r : ndarray (p, m)
        Point responses per unit modal coordinate.
    eta_ddot : ndarray (m, nt)
        Modal accelerations on the time grid.
    """
    p, nt = r.shape[0], eta_ddot.shape[1]
    out = np.zeros(p)
    if r.shape[1] == 0:
        return out
    block = max(1, int(4_000_000 // max(p, 1)))
    for start in range(0, nt, block):
        a = r @ eta_ddot[:, start : start + block]
        np.maximum(out, np.max(np.abs(a), axis=1), out=out)
    return out


@dataclass(frozen=True)
class PointPeaks:
    """Every peak of the map at a set of points (see :func:`point_peaks`), m/s^2.

    Attributes
    ----------
    per_mode : ndarray (m, p)
        Eq. 3.1 per mode and point.
    total, elastic, rigid, bound : ndarray (p,)
        Peak over time of the modal sum, of its elastic modes, the exact rigid-body part,
        and ``rigid`` plus the per-mode peaks of the other modes (an upper bound).
    long_time : ndarray (p,) or None
        The supremum over all t >= 0 of an undamped response to a force ending at zero.
    grid : ndarray
        The time grid of the peaks over time, s.
    exact : bool
        Whether ``per_mode`` is the closed form (exact [A]max).
    """

    per_mode: np.ndarray
    total: np.ndarray
    elastic: np.ndarray
    rigid: np.ndarray
    bound: np.ndarray
    long_time: np.ndarray | None
    grid: np.ndarray
    exact: bool


def point_peaks(
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
) -> PointPeaks:
    """Every peak of the map at points with responses ``resp`` (p, m) per modal coordinate.

    Parameters
    ----------
    resp : ndarray (p, m)
        Displacement along the force direction per unit modal coordinate, m/sqrt(kg).
    gamma : ndarray (m,)
        The force's participation ``phi_j(crew).d``, 1/sqrt(kg).
    omega : ndarray (m,)
        rad/s.
    rigid, elastic : ndarray (m,) of bool
    zeta : ndarray (m,)
        Damping ratios.
    force : CrewPushoff or ForceHistory
        N.
    duration : float or None
        Time window, s (default: :func:`time_grid`'s).
    with_long_time : bool
        Also the long-time peak (undamped models whose force ends at zero).
    """
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
    return PointPeaks(per_mode, total, el_peak, rig, bound, long_time, grid, exact)


def kept_modes(
    modes: Modes, zeta: float | np.ndarray, include_rigid: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(use, omega, rigid, elastic, zeta) of the modes kept, the damping validated.

    Parameters
    ----------
    modes : Modes
        The solved modes (omega in rad/s).
    zeta : float or ndarray (m,)
        Modal damping ratios, 0 <= zeta < 1.
    include_rigid : bool
        Keep the rigid-body modes.
    """
    omega = np.asarray(modes.omega, float)
    rigid = np.asarray(modes.rigid, bool)
    zeta_arr = np.broadcast_to(np.asarray(zeta, float), omega.shape).astype(float)
    if np.any(~np.isfinite(zeta_arr)) or np.any(zeta_arr < 0) or np.any(zeta_arr >= 1):
        raise InputError("damping ratio must satisfy 0 <= zeta < 1", where="zeta")
    use = np.ones(omega.size, bool) if include_rigid else ~rigid
    elastic = elastic_modes(modes)
    return use, omega[use], rigid[use], elastic[use], zeta_arr[use]
