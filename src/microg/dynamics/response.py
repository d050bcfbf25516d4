"""Exact modal response to piecewise-linear forces (closed form per segment).

Each modal coordinate obeys (report Eq. 2.15, with modal damping added)::

    eta'' + 2 zeta omega eta' + omega^2 eta = p(t),      eta(t0) = eta'(t0) = 0,

where ``p = phi^T f / modal_mass`` is piecewise linear between breakpoints.  On a segment
starting at ``t_k`` with state ``(eta_k, v_k)`` and force ``p = p_k + s_k tau``
(``tau = t - t_k``) the solution is, exactly::

    eta(tau) = eta_k g(tau) + v_k h(tau) + p_k S(tau) + s_k R(tau)
    v(tau)   = v_k g(tau) + a_k h(tau) + s_k S(tau)            (v obeys the ODE with p = s_k)
    a(tau)   = a_k g(tau) + j_k h(tau)                          (a obeys the free ODE)

with ``a_k = p_k - 2 zeta omega v_k - omega^2 eta_k`` (the equation of motion, right-continuous at
a jump of p), ``j_k = s_k - 2 zeta omega a_k - omega^2 v_k``, and the four functions of the mode

* ``h``: impulse response  ``exp(-sigma tau) sin(omega_d tau) / omega_d``,
* ``g``: free response to a unit displacement ``exp(-sigma tau)(cos + sigma/omega_d sin)``,
* ``S = int_0^tau h``: unit-step response, ``R = int_0^tau S``: unit-ramp response,

``sigma = zeta omega``, ``omega_d = omega sqrt(1 - zeta^2)``.  ``g`` and ``h`` are written with
``sinc`` so they are exact for ``omega -> 0``; ``S`` and ``R`` lose digits by cancellation when
``omega tau`` is small, so for ``omega tau < 0.5`` they are summed from their Taylor series (the
recursion of the ODE itself).  A rigid-body mode (``omega = 0``) therefore needs no special case:
it is double integration, ``S = tau^2/2``, ``R = tau^3/6``.

The start states of all segments are the chain of the segments' affine state maps, computed by
the one blocked O(K) scan :func:`microg._scan.affine_scan`, vectorised over modes.  The output
times are then split into uniformly spaced runs inside one segment, each evaluated by two small
tables of exact exponentials and one batched matrix product (:func:`_table_run`), and the rest,
evaluated directly by the closed form.  :func:`response_at_points` contracts the modes with
``T phi`` block by block, never building the (3, modes, times) array.

A damped term that has decayed below exp(-600) (1e-261) of its start is set to exactly 0: far
below rounding, and it keeps subnormal numbers (slow arithmetic) out of the kernels.

Exact peaks (:func:`peak_response`): the supremum of |a(t)| and of each axis over a window,
including both one-sided limits at the force's jumps and the stationary points between samples,
with a certified upper bound (see the function).

Conventions: the force is zero before the first breakpoint; a repeated breakpoint time is a jump
(the last value at that time holds from it on, i.e. the force is right-continuous; times closer than
4 roundings of max(|t|, 1 s) count as repeated); after the last breakpoint the force holds its last
value.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._scan import affine_scan
from microg.errors import InputError
from microg.units import G0

if TYPE_CHECKING:
    from microg.dynamics.forces import ForceHistory

__all__ = [
    "ModalResponse",
    "PeakResponse",
    "PointResponse",
    "combined_modal_force",
    "generalized_force_vector",
    "modal_pwl_evaluate",
    "modal_pwl_response",
    "oscillator_functions",
    "peak_response",
    "response_at_points",
]

#: below this value of omega * tau the step and ramp functions are summed from their series
_SERIES_BELOW = 0.5
#: number of series terms: the terms fall roughly like (2 x)^n / n!, 20 terms reach 4e-19 at x = 0.5
_SERIES_TERMS = 20
#: a damped term that has decayed by more than exp(-_DECAYED) (1e-261) of its start is set to 0:
#: far below rounding, and it keeps subnormal numbers (100x slower arithmetic) out of the kernel
_DECAYED = 600.0


def _exp_decayed(z: np.ndarray) -> np.ndarray:
    """``exp(z)``, exactly 0 where ``Re z < -_DECAYED`` (no subnormal results)."""
    out = np.exp(np.where(z.real < -_DECAYED, -np.inf, z))
    return out


def _exp_table(lam: np.ndarray, t0: float, step: float, count: int) -> np.ndarray:
    """``exp(lam (t0 + i step))``, i = 0 .. count - 1, shape (modes, count); lam (modes, 1).

    Each entry is the product of two direct exponentials, a coarse one at ``t0 + i1 q step``
    and a fine one at ``i2 step`` (``i = i1 q + i2``, ``q = ceil(sqrt(count))``): one rounding
    more than a direct exponential, no recurrence, and about ``2 sqrt(count)`` exponentials
    instead of ``count``.  Entries whose exponent's real part is below ``-_DECAYED`` are 0.
    """
    q = max(1, int(np.ceil(np.sqrt(count))))
    nc = -(-count // q)
    coarse = _exp_decayed(lam * (t0 + np.arange(nc) * (q * step)))  # (modes, nc)
    fine = np.exp(lam * (np.arange(q) * step))  # (modes, q)
    out = (coarse[:, :, None] * fine[:, None, :]).reshape(lam.shape[0], nc * q)[:, :count]
    t_last = t0 + (count - 1) * step
    if np.any(lam.real * max(abs(t0), abs(t_last)) < -_DECAYED):  # a product may be subnormal
        out = np.where(lam.real * (t0 + np.arange(count) * step) < -_DECAYED, 0.0, out)
    return out


@dataclass(frozen=True)
class ModalResponse:
    """Modal coordinates and their rates at the output times.

    Attributes
    ----------
    timepts : (nt,) output times, s
    eta : (m, nt) modal displacements (units of p / omega^2, e.g. m * sqrt(kg) for
        mass-normalised modes)
    eta_dot : (m, nt) modal velocities
    eta_ddot : (m, nt) modal accelerations, right-continuous at jumps of the force
    """

    timepts: np.ndarray
    eta: np.ndarray
    eta_dot: np.ndarray
    eta_ddot: np.ndarray

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary: the record and each mode's largest sampled |value|.

        The histories themselves are in :meth:`to_xarray` (a record of 200 modes x 20,001
        samples is 32 MB a series, too much for JSON).
        """
        t = np.asarray(self.timepts, float)
        return {
            "n_modes": int(self.eta.shape[0]),
            "n_samples": int(t.size),
            "t_start_s": float(t[0]) if t.size else None,
            "t_end_s": float(t[-1]) if t.size else None,
            "peak_eta": _row_peaks(self.eta),
            "peak_eta_dot": _row_peaks(self.eta_dot),
            "peak_eta_ddot": _row_peaks(self.eta_ddot),
        }

    def to_xarray(self) -> Any:
        """``eta``, ``eta_dot``, ``eta_ddot`` as an ``xarray.Dataset`` over (mode, time).

        Modal units: for mass-normalised modes ``eta`` is m sqrt(kg), its rates per s and
        per s^2 (attribute ``units``); ``mode`` counts from 1.
        """
        import xarray as xr

        dims = ("mode", "time")
        return xr.Dataset(
            {
                "eta": (dims, self.eta, {"units": "m kg^0.5"}),
                "eta_dot": (dims, self.eta_dot, {"units": "m kg^0.5 / s"}),
                "eta_ddot": (dims, self.eta_ddot, {"units": "m kg^0.5 / s^2"}),
            },
            coords={
                "mode": ("mode", np.arange(1, self.eta.shape[0] + 1), {"units": "1"}),
                "time": ("time", np.asarray(self.timepts, float), {"units": "s"}),
            },
        )

    def plot(self, n_show: int = 6) -> Any:
        """The modal accelerations of the ``n_show`` modes with the largest peak (a Figure)."""
        from microg.plotting.modes import plot_modal_response

        return plot_modal_response(self, n_show=n_show)


def _row_peaks(a: np.ndarray) -> list[float]:
    """Largest |value| of each row (an empty row: 0)."""
    a = np.atleast_2d(np.asarray(a, float))
    return np.max(np.abs(a), axis=1, initial=0.0).tolist()


@dataclass(frozen=True)
class PointResponse:
    """Translational response of one named point (three axes of the model frame).

    Attributes
    ----------
    name : point name
    timepts : (nt,) output times, s
    displacement : (3, nt) m
    velocity : (3, nt) m/s
    acceleration : (3, nt) m/s^2
    """

    name: str
    timepts: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray

    def acceleration_g(self) -> np.ndarray:
        """Acceleration in units of standard gravity (G0 = 9.80665 m/s^2), shape (3, nt)."""
        return self.acceleration / G0

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary: the record and the largest sampled values per axis (SI).

        ``peak_accel_g`` is the largest sampled |a| (vector magnitude); the certified
        maximum between samples is :class:`PeakResponse`'s.  The histories are in
        :meth:`to_xarray`.
        """
        t = np.asarray(self.timepts, float)
        mag = np.linalg.norm(np.asarray(self.acceleration, float), axis=0)
        return {
            "name": self.name,
            "n_samples": int(t.size),
            "t_start_s": float(t[0]) if t.size else None,
            "t_end_s": float(t[-1]) if t.size else None,
            "peak_displacement_m_axis": _row_peaks(self.displacement),
            "peak_velocity_mps_axis": _row_peaks(self.velocity),
            "peak_accel_mps2_axis": _row_peaks(self.acceleration),
            "sampled_peak_accel_g": float(np.max(mag, initial=0.0)) / G0,
        }

    def to_xarray(self) -> Any:
        """Displacement, velocity and acceleration as an ``xarray.Dataset`` over (axis, time)."""
        import xarray as xr

        dims = ("axis", "time")
        return xr.Dataset(
            {
                "displacement_m": (dims, self.displacement, {"units": "m"}),
                "velocity_mps": (dims, self.velocity, {"units": "m/s"}),
                "accel_mps2": (dims, self.acceleration, {"units": "m/s^2"}),
            },
            coords={
                "axis": ("axis", ["x", "y", "z"][: np.shape(self.acceleration)[0]]),
                "time": ("time", np.asarray(self.timepts, float), {"units": "s"}),
            },
            attrs={"point": self.name},
        )

    def plot(self) -> Any:
        """The acceleration history, micro-g against s (a Figure)."""
        from microg.plotting.environment import plot_time_history

        return plot_time_history(
            self.timepts, self.acceleration, title=f"Acceleration at {self.name}"
        )


def _sinc(theta: np.ndarray) -> np.ndarray:
    """sin(theta)/theta, exact at 0 (numpy's sinc is normalised by pi)."""
    return np.sinc(theta / np.pi)


def _step_ramp_series(
    x: np.ndarray, two_sigma_tau: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Unit-step and unit-ramp responses S, R from their Taylor series (small omega tau).

    Both obey y'' + 2 sigma y' + omega^2 y = forcing with zero start; writing a_n = c_n tau^n the
    recursion is a_{n+2} = -((n+1) (2 sigma tau) a_{n+1} + x^2 a_n) / ((n+2)(n+1)), x = omega tau,
    started from S: a_2 = tau^2/2 and R: a_3 = tau^3/6.
    """
    x2 = x * x
    # S: a_1 = 0, a_2 = tau^2/2; R: a_2 = 0, a_3 = tau^3/6.  In place, two rotating buffers each
    s_prev, s_cur = np.zeros_like(tau), 0.5 * tau * tau
    r_prev, r_cur = np.zeros_like(tau), tau * tau * tau / 6.0
    s_sum, r_sum = s_cur.copy(), r_cur.copy()
    tmp = np.empty_like(tau)
    for n in range(1, _SERIES_TERMS):
        # S: a_{n+2} = -((n+1) 2 sigma tau a_{n+1} + x^2 a_n) / ((n+2)(n+1)); R: the same, n+1
        for k, prev, cur, total in ((n, s_prev, s_cur, s_sum), (n + 1, r_prev, r_cur, r_sum)):
            np.multiply(cur, two_sigma_tau, out=tmp)
            tmp *= k + 1
            prev *= x2  # becomes the next coefficient (a_n is not needed again)
            prev += tmp
            prev /= -((k + 2) * (k + 1))
            total += prev
        s_prev, s_cur = s_cur, s_prev
        r_prev, r_cur = r_cur, r_prev
    return s_sum, r_sum


def oscillator_functions(
    omega: np.ndarray, zeta: np.ndarray, tau: np.ndarray, *, need_ramp: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Free, impulse, step and ramp responses g, h, S, R of unit modes at elapsed times tau.

    Parameters
    ----------
    omega : array, natural frequencies, rad/s (>= 0), broadcastable with ``tau``
    zeta : array, damping ratios (0 <= zeta < 1), broadcastable with ``tau``
    tau : array, elapsed times >= 0, s
    need_ramp : compute R (skip it when only velocities/accelerations are wanted)

    Returns
    -------
    g, h, S, R : arrays of the broadcast shape; ``R`` is None when ``need_ramp`` is False.
    Units: g dimensionless, h s, S s^2, R s^3.
    """
    omega, zeta, tau = np.broadcast_arrays(
        np.atleast_1d(np.asarray(omega, float)),
        np.atleast_1d(np.asarray(zeta, float)),
        np.atleast_1d(np.asarray(tau, float)),
    )
    sigma = zeta * omega
    omega_d = omega * np.sqrt(1.0 - zeta * zeta)
    st = sigma * tau
    theta = omega_d * tau
    decay = _exp_decayed(-st)
    cos_t = np.cos(theta)
    tsinc = tau * _sinc(theta)  # sin(omega_d tau) / omega_d
    h = decay * tsinc
    g = decay * (cos_t + sigma * tsinc)
    x = omega * tau
    w2 = omega * omega
    small = x < _SERIES_BELOW
    with np.errstate(divide="ignore", invalid="ignore"):
        S = (1.0 - g) / w2
        R = (tau - h - 2.0 * sigma * S) / w2 if need_ramp else None
    if np.any(small):
        s_ser, r_ser = _step_ramp_series(x[small], 2.0 * st[small], tau[small])
        S[small] = s_ser
        if R is not None:
            R[small] = r_ser
    return g, h, S, R


def _validate(
    omega: np.ndarray,
    zeta: np.ndarray,
    timepts_force: np.ndarray,
    modal_force: np.ndarray,
    timepts_out: np.ndarray,
) -> None:
    if omega.ndim != 1:
        raise InputError("omega must be a 1-D array of rad/s", where="modal_pwl_response: omega")
    m = omega.size
    if zeta.shape != (m,):
        raise InputError(f"zeta must have shape ({m},)", where="modal_pwl_response: zeta")
    if timepts_force.ndim != 1 or timepts_force.size < 1:
        raise InputError("need at least one force breakpoint", where="modal_pwl_response")
    if modal_force.shape != (m, timepts_force.size):
        raise InputError(
            f"modal_force must have shape ({m}, {timepts_force.size}), got {modal_force.shape}",
            where="modal_pwl_response: modal_force",
        )
    if timepts_out.ndim != 1:
        raise InputError("timepts_out must be 1-D", where="modal_pwl_response: timepts_out")
    checks = [
        (np.all(np.isfinite(omega)) and np.all(omega >= 0), "omega must be finite and >= 0"),
        (
            np.all(np.isfinite(zeta)) and np.all(zeta >= 0) and np.all(zeta < 1),
            "zeta must satisfy 0 <= zeta < 1 (critical and over-damped modes are not supported)",
        ),
        (np.all(np.isfinite(timepts_force)), "force breakpoint times must be finite"),
        (np.all(np.diff(timepts_force) >= 0), "force breakpoint times must be non-decreasing"),
        (np.all(np.isfinite(modal_force)), "modal forces must be finite"),
        (np.all(np.isfinite(timepts_out)), "output times must be finite"),
        (np.all(np.diff(timepts_out) >= 0), "output times must be sorted"),
    ]
    for ok, msg in checks:
        if not ok:
            raise InputError(msg, where="modal_pwl_response")


def _segments(
    timepts_force: np.ndarray, modal_force: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Unique breakpoint times, right values p_k, slopes s_k and lengths of the finite segments."""
    t = timepts_force
    # times equal to within a few roundings are one time (a jump), not a vanishing ramp
    new_time = np.diff(t) > 4.0 * np.spacing(max(float(np.max(np.abs(t))), 1.0))
    last = np.r_[new_time, True]  # last occurrence of each time: right value
    first = np.r_[True, new_time]  # first occurrence: left value (end of previous segment)
    starts = t[last]
    p_right = modal_force[:, last]  # (m, K)
    p_left = modal_force[:, first]  # (m, K)
    lengths = np.diff(starts)  # (K-1,)
    slopes = np.zeros_like(p_right)
    if lengths.size:
        slopes[:, :-1] = (p_left[:, 1:] - p_right[:, :-1]) / lengths
    return starts, p_right, slopes, lengths


def _start_states(
    omega: np.ndarray,
    zeta: np.ndarray,
    p_right: np.ndarray,
    slopes: np.ndarray,
    lengths: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """States (eta, eta') at the start of every segment, zero at the first breakpoint.

    Segment k maps its start state z_k to z_{k+1} = M_k z_k + c_k; the chain of these affine
    maps is :func:`microg._scan.affine_scan` (vectorised over modes).
    """
    m, K = p_right.shape
    if K == 1:
        return np.zeros((m, 1)), np.zeros((m, 1))
    w = omega[:, None]
    z = zeta[:, None]
    tau = lengths[None, :]
    g, h, S, R = oscillator_functions(w, z, tau)
    assert R is not None
    p = p_right[:, :-1]
    s = slopes[:, :-1]
    # state map of one segment: [eta, v] -> [[g, h], [-w^2 h, g - 2 sigma h]] [eta, v] + c
    # (v(tau) = v0 g + a0 h + s S with a0 = p - 2 sigma v0 - w^2 eta0)
    maps = np.empty((m, K - 1, 2, 2))
    maps[..., 0, 0] = g
    maps[..., 0, 1] = h
    maps[..., 1, 0] = -(w * w) * h
    maps[..., 1, 1] = g - 2.0 * z * w * h
    offsets = np.stack([p * S + s * R, p * h + s * S], axis=-1)
    states = affine_scan(maps, offsets)  # (m, K, 2)
    return states[..., 0], states[..., 1]


@dataclass(frozen=True)
class _State:
    """Modal state at the start of every force segment (private).

    ``starts`` (K,) s; the others (m, K): eta, eta', eta'' (right-continuous), eta''' and the
    force value p and slope s on the segment.
    """

    omega: np.ndarray
    zeta: np.ndarray
    starts: np.ndarray
    eta: np.ndarray
    vel: np.ndarray
    acc: np.ndarray
    jerk: np.ndarray
    p: np.ndarray
    s: np.ndarray

    @property
    def rigid(self) -> np.ndarray:
        return np.flatnonzero(self.omega == 0)

    @property
    def elastic(self) -> np.ndarray:
        return np.flatnonzero(self.omega != 0)


def _prepare(
    omega: np.ndarray, zeta: np.ndarray, timepts_force: np.ndarray, modal_force: np.ndarray
) -> _State:
    starts, p_right, slopes, lengths = _segments(timepts_force, modal_force)
    eta_k, vel_k = _start_states(omega, zeta, p_right, slopes, lengths)
    w = omega[:, None]
    two_sigma = 2.0 * zeta[:, None] * w
    w2 = w * w
    acc_k = p_right - two_sigma * vel_k - w2 * eta_k
    jerk_k = slopes - two_sigma * acc_k - w2 * vel_k
    return _State(omega, zeta, starts, eta_k, vel_k, acc_k, jerk_k, p_right, slopes)


def _as_arrays(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    timepts_force: np.ndarray,
    modal_force: np.ndarray,
    timepts_out: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    omega = np.asarray(omega, dtype=float)
    zeta = np.broadcast_to(np.asarray(zeta, dtype=float), omega.shape).astype(float)
    timepts_force = np.asarray(timepts_force, dtype=float)
    modal_force = np.asarray(modal_force, dtype=float)
    if modal_force.ndim == 1 and omega.size == 1:
        modal_force = modal_force[None, :]
    timepts_out = np.asarray(timepts_out, dtype=float)
    _validate(omega, zeta, timepts_force, modal_force, timepts_out)
    return omega, zeta, timepts_force, modal_force, timepts_out


# --------------------------------------------------------------------------- evaluation

#: uniform runs of at least this many output times (inside one segment) use the table path
_MIN_RUN = 64
#: output times per evaluation block when projecting onto points (bounds the scratch memory)
_CHUNK = 4096


def _runs(t: np.ndarray, starts: np.ndarray) -> tuple[list[tuple[int, int, int]], np.ndarray]:
    """Uniform runs ``(segment, i0, i1)`` of the output times and the indices of the others.

    A run is a maximal set of consecutive output times inside one force segment with equal
    spacing (to a few roundings of the largest time, and within that of ``t0 + i dt``); runs
    shorter than :data:`_MIN_RUN` and irregular times are returned as indices for the direct
    (gathered) evaluation.  Times before the first breakpoint are in neither (zero response).
    """
    nt = t.size
    seg = np.searchsorted(starts, t, side="right") - 1
    tol = 8.0 * np.spacing(max(float(np.max(np.abs(t))) if nt else 0.0, 1.0))
    runs: list[tuple[int, int, int]] = []
    covered = np.zeros(nt + 1, dtype=np.int64)
    if nt >= 2:
        d = np.diff(t)
        valid = (seg[1:] == seg[:-1]) & (seg[1:] >= 0)  # diff j joins points j, j+1
        same = np.r_[False, np.abs(np.diff(d)) <= tol] & np.r_[False, valid[:-1]]
        first = valid & ~same  # a diff that starts a new run
        j0 = np.flatnonzero(first)
        if j0.size:
            run_id = np.cumsum(first) - 1
            j_last = np.flatnonzero(valid)
            # last valid diff of each run
            ends = np.zeros(j0.size, dtype=np.intp)
            np.maximum.at(ends, run_id[j_last], j_last)
            p1 = ends + 1  # last point of each run (inclusive)
            p0 = np.maximum(j0, np.r_[-1, p1[:-1]] + 1)  # a shared point goes to the earlier run
            long = np.flatnonzero(p1 - p0 + 1 >= _MIN_RUN)
            for r in long:
                i0, i1 = int(p0[r]), int(p1[r]) + 1
                tt = t[i0:i1]
                n = i1 - i0
                dt = (tt[-1] - tt[0]) / (n - 1)
                if np.max(np.abs(tt - (tt[0] + np.arange(n) * dt))) > tol:
                    continue  # a slowly drifting spacing: not uniform, evaluate directly
                runs.append((int(seg[i0]), i0, i1))
                covered[i0] += 1
                covered[i1] -= 1
    mask = (np.cumsum(covered[:nt]) == 0) & (seg >= 0)
    return runs, np.flatnonzero(mask)


def _table_run(
    st: _State,
    k: int,
    tau: np.ndarray,
    qs: tuple[int, ...],
    dest: np.ndarray,
    defer: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]] | None = None,
    offset: int = 0,
) -> None:
    """Quantities ``qs`` (0 eta, 1 eta', 2 eta'') of all modes on a uniform run of segment k.

    Writes ``dest`` (len(qs), m, n).  Elastic modes: with E = exp(lambda tau), lambda =
    -sigma + i omega_d, each quantity is ``Re E * cc + Im E * cs + q0 + q1 tau`` with per-mode
    coefficients folding in the start state and the force.  On the run tau_i = tau_0 + i dt,
    with i = b L + r, E_i = exp(lambda (tau_0 + b L dt)) exp(lambda r dt): two small tables of
    direct evaluations, and the whole block is one batched matrix product with inner dimension 4
    (a few roundings per entry, no recurrence).  Where omega tau < _SERIES_BELOW (a prefix of the
    run for each mode) the folded eta and eta' lose digits by cancellation; those entries are
    recomputed with :func:`oscillator_functions` (eta'' has no cancellation).  Rigid modes are
    the exact polynomials of a double integration.
    """
    n = tau.size
    nq = len(qs)
    e0, v0, a0, j0, p0, s0 = (x[:, k] for x in (st.eta, st.vel, st.acc, st.jerk, st.p, st.s))
    rigid, el = st.rigid, st.elastic
    if rigid.size:
        polys = {
            0: (e0[rigid], v0[rigid], p0[rigid] / 2.0, s0[rigid] / 6.0),
            1: (v0[rigid], p0[rigid], s0[rigid] / 2.0, np.zeros(rigid.size)),
            2: (p0[rigid], s0[rigid], np.zeros(rigid.size), np.zeros(rigid.size)),
        }
        powers = np.empty((4, n))
        powers[0] = 1.0
        powers[1] = tau
        np.multiply(tau, tau, out=powers[2])
        np.multiply(powers[2], tau, out=powers[3])
        coef = np.stack([np.stack(polys[q], axis=1) for q in qs])  # (nq, r, 4)
        if rigid[-1] - rigid[0] + 1 == rigid.size:  # a slice: the product written in place
            np.matmul(coef, powers, out=dest[:, int(rigid[0]) : int(rigid[-1]) + 1])
        else:
            dest[:, rigid] = coef @ powers
    if not el.size:
        return
    omega, zeta = st.omega[el], st.zeta[el]
    e0, v0, a0, j0, p0, s0 = e0[el], v0[el], a0[el], j0[el], p0[el], s0[el]
    sigma = zeta * omega
    omega_d = omega * np.sqrt(1.0 - zeta * zeta)
    w2 = omega * omega
    beta = s0 / w2
    alpha = p0 / w2 - 2.0 * sigma * s0 / (w2 * w2)
    zero = np.zeros_like(omega)
    cc_all = (e0 - alpha, v0 - beta, a0)  # coefficient of Re E
    nxt = (v0 - beta, a0, j0)
    cc = np.stack([cc_all[q] for q in qs])  # (nq, me)
    cs = (sigma * cc + np.stack([nxt[q] for q in qs])) / omega_d  # coefficient of Im E
    q0 = np.stack([(alpha, beta, zero)[q] for q in qs])
    q1 = np.stack([(beta, zero, zero)[q] for q in qs])
    lam = (-sigma + 1j * omega_d)[:, None]
    me = el.size
    dt = (tau[-1] - tau[0]) / (n - 1) if n > 1 else 0.0
    L = max(1, int(np.ceil(np.sqrt(n))))
    nb = -(-n // L)
    tau_b = tau[0] + (np.arange(nb) * L) * dt
    A = _exp_table(lam, float(tau[0]), L * dt, nb)  # (me, nb)
    rdt = np.arange(L) * dt
    W = _exp_table(lam, 0.0, dt, L)  # (me, L)
    # Re E cc + Im E cs = Re(Z), Z = (cc - i cs) E, and the other column -Im(Z)
    lhs = np.empty((nq, me, nb, 4))
    Z = (cc - 1j * cs)[:, :, None] * A
    lhs[..., 0] = Z.real
    np.negative(Z.imag, out=lhs[..., 1])
    poly = [iq for iq, q in enumerate(qs) if q < 2]
    if poly:
        ps = slice(poly[0], poly[-1] + 1)
        np.multiply(q1[ps, :, None], tau_b, out=lhs[ps, :, :, 2])
        lhs[ps, :, :, 2] += q0[ps, :, None]
        lhs[ps, :, :, 3] = q1[ps, :, None]
    rhs = np.empty((me, 4, L))
    rhs[:, 0] = W.real
    rhs[:, 1] = W.imag
    rhs[:, 2] = 1.0
    rhs[:, 3] = rdt
    full_blocks = n // L
    rem = n - full_blocks * L
    contiguous = el[-1] - el[0] + 1 == me
    rows = slice(int(el[0]), int(el[-1]) + 1) if contiguous else el
    target = dest[:, rows] if contiguous else np.empty((nq, me, n))
    # eta'' has no polynomial part: its rows need only the inner dimension 2
    groups = [[iq for iq, q in enumerate(qs) if q < 2], [iq for iq, q in enumerate(qs) if q == 2]]
    for grp, width in zip(groups, (4, 2), strict=True):
        if not grp:
            continue
        sl = slice(grp[0], grp[-1] + 1)  # qs is ordered, so each group is a contiguous slice
        lh, rh = lhs[sl, :, :, :width], rhs[:, :width]
        tg = target[sl]
        if full_blocks:
            body = tg[:, :, : full_blocks * L].reshape(len(grp), me, full_blocks, L)
            if np.may_share_memory(body, tg):  # a view (a copy would be new memory)
                np.matmul(lh[:, :, :full_blocks], rh, out=body)
            else:  # pragma: no cover - a reshape of a last-axis slice is a view
                tg[:, :, : full_blocks * L] = (lh[:, :, :full_blocks] @ rh).reshape(
                    len(grp), me, -1
                )
        if rem:
            tg[:, :, full_blocks * L :] = (lh[:, :, -1, None, :] @ rh[:, :, :rem])[:, :, 0]
    # stable recomputation of eta, eta' where omega tau < _SERIES_BELOW: only those entries (a
    # prefix of the run for each mode), gathered flat, so a run starting at a breakpoint costs
    # about sum_j 0.5 / (omega_j dt) evaluations instead of a (modes x longest prefix) block;
    # with ``defer`` they are handed back (segment, mode, column offset + i, tau) and written by
    # the caller, all runs in one call of :func:`_small_tau_values`
    fix = [iq for iq, q in enumerate(qs) if q < 2]
    if fix:
        n_small = np.searchsorted(tau, _SERIES_BELOW / omega, side="left")
        total = int(n_small.sum())
        if total:
            sel = np.flatnonzero(n_small)
            cnt = n_small[sel]
            rows_f = np.repeat(sel, cnt)  # elastic-mode index of each entry
            starts_f = np.cumsum(cnt) - cnt
            cols_f = np.arange(total) - np.repeat(starts_f, cnt)  # position in the run
            if defer is not None:
                defer.append((k, el[rows_f], cols_f + offset, tau[cols_f]))
            else:
                small = _small_tau_values(st, np.full(total, k), el[rows_f], tau[cols_f], qs)
                for iq in fix:
                    target[iq][rows_f, cols_f] = small[iq]
    if not contiguous:
        dest[:, el] = target


def _small_tau_values(
    st: _State, seg: np.ndarray, mode: np.ndarray, tau: np.ndarray, qs: tuple[int, ...]
) -> list[np.ndarray | None]:
    """eta, eta' (those of ``qs`` below 2) of single entries (segment, mode, elapsed time).

    The closed form ``e g + v h + p S + s R`` and ``v g + a h + s S`` with S, R from their
    series (every entry has ``omega tau < _SERIES_BELOW``); None for the other quantities.
    """
    omega, zeta = st.omega[mode], st.zeta[mode]
    sigma_tau = zeta * omega * tau
    theta = omega * np.sqrt(1.0 - zeta * zeta) * tau
    tsinc = tau * _sinc(theta)  # sin(omega_d tau) / omega_d
    decay = np.exp(-sigma_tau)  # sigma tau < 0.5 here: no underflow
    h = decay * tsinc
    g = decay * (np.cos(theta) + (zeta * omega) * tsinc)
    S, R = _step_ramp_series(omega * tau, 2.0 * sigma_tau, tau)
    vv = st.vel[mode, seg]
    out: list[np.ndarray | None] = []
    for q in qs:
        if q == 0:
            out.append(st.eta[mode, seg] * g + vv * h + st.p[mode, seg] * S + st.s[mode, seg] * R)
        elif q == 1:
            out.append(vv * g + st.acc[mode, seg] * h + st.s[mode, seg] * S)
        else:
            out.append(None)
    return out


def _direct(st: _State, seg: np.ndarray, tau: np.ndarray, qs: tuple[int, ...]) -> np.ndarray:
    """Quantities ``qs`` of all modes at elapsed times ``tau`` into segments ``seg`` (>= 0).

    The closed form of the module docstring evaluated directly, shape (len(qs), m, n).
    """
    w, z = st.omega[:, None], st.zeta[:, None]
    g, h, S, R = oscillator_functions(w, z, tau[None, :], need_ramp=0 in qs)
    out = np.empty((len(qs), st.omega.size, tau.size))
    for iq, q in enumerate(qs):
        if q == 0:
            assert R is not None
            out[iq] = st.eta[:, seg] * g + st.vel[:, seg] * h + st.p[:, seg] * S + st.s[:, seg] * R
        elif q == 1:
            out[iq] = st.vel[:, seg] * g + st.acc[:, seg] * h + st.s[:, seg] * S
        else:
            out[iq] = st.acc[:, seg] * g + st.jerk[:, seg] * h
    return out


def _evaluate(
    st: _State, t: np.ndarray, qs: tuple[int, ...], project: np.ndarray | None = None
) -> np.ndarray:
    """Quantities ``qs`` at the output times ``t``: (len(qs), m, nt), or projected (len(qs), r, nt).

    ``project`` (r, m) contracts the modes block by block (at most :data:`_CHUNK` times at a
    time), so the (len(qs), m, nt) modal array is never built.  Uniform runs take the table path
    (:func:`_table_run`), everything else the direct closed form; zero before the first
    breakpoint.
    """
    m, nt, nq = st.omega.size, t.size, len(qs)
    rows = m if project is None else project.shape[0]
    # every entry is written below (np.empty: no zero-filled pages to fault in first)
    out = np.empty((nq, rows, nt))
    out[:, :, : int(np.searchsorted(t, st.starts[0], side="left"))] = 0.0  # before the force
    runs, rest = _runs(t, st.starts)
    scratch = None if project is None else np.empty((nq, m, min(_CHUNK, max(nt, 1))))
    defer: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]] = []
    for k, i0, i1 in runs:
        if project is None:
            _table_run(st, k, t[i0:i1] - st.starts[k], qs, out[:, :, i0:i1], defer, i0)
            continue
        assert scratch is not None
        for c0 in range(i0, i1, _CHUNK):
            c1 = min(c0 + _CHUNK, i1)
            buf = scratch[:, :, : c1 - c0]
            _table_run(st, k, t[c0:c1] - st.starts[k], qs, buf)
            for iq in range(nq):  # 2-D products (BLAS), then one copy into the strided output
                out[iq, :, c0:c1] = project @ buf[iq]
    if defer:  # the small-omega-tau entries of every run, in one evaluation
        seg_f, mode_f, col_f, tau_f = (
            np.concatenate(x)
            for x in zip(
                *[(np.full(m_.size, k), m_, c_, t_) for k, m_, c_, t_ in defer], strict=True
            )
        )
        vals_f = _small_tau_values(st, seg_f, mode_f, tau_f, qs)
        for iq, v in enumerate(vals_f):
            if v is not None:
                out[iq][mode_f, col_f] = v
    seg_all = np.searchsorted(st.starts, t, side="right") - 1
    for c0 in range(0, rest.size, _CHUNK):
        idx = rest[c0 : c0 + _CHUNK]
        seg = seg_all[idx]
        vals = _direct(st, seg, t[idx] - st.starts[seg], qs)
        if project is None:
            out[:, :, idx] = vals
        else:
            for iq in range(nq):
                out[iq][:, idx] = project @ vals[iq]
    return out


def modal_pwl_response(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    timepts_force: np.ndarray,
    modal_force: np.ndarray,
    timepts_out: np.ndarray,
) -> ModalResponse:
    """Exact response of damped/undamped/rigid modal equations to a piecewise-linear force.

    Solves eta'' + 2 zeta omega eta' + omega^2 eta = p(t) (report Eq. 2.15 with modal damping)
    with zero initial state at ``timepts_force[0]``, exactly to rounding, by the closed form of each
    linear segment of ``p`` (see the module docstring).  The force is zero before the first
    breakpoint and holds its last value after the last one; a repeated time is a jump.

    Parameters
    ----------
    omega : (m,) natural frequencies, rad/s; 0 for rigid-body modes
    zeta : (m,) or scalar modal damping ratios, 0 <= zeta < 1
    timepts_force : (nb,) breakpoint times, s, non-decreasing (a repeated time is a jump)
    modal_force : (m, nb) modal force p at each breakpoint, already divided by the modal mass
        (N/kg-like units, m/s^2 per unit modal coordinate); at a repeated time the first column is
        the value just before the jump, the last the value from the jump on
    timepts_out : (nt,) sorted output times, s; any spacing (each uniformly spaced run inside a
        force segment takes the fast table path); times before the first breakpoint give zero
        response

    Returns
    -------
    ModalResponse
        ``eta``, ``eta_dot``, ``eta_ddot`` of shape (m, nt); accelerations are right-continuous.
    """
    omega, zeta, timepts_force, modal_force, timepts_out = _as_arrays(
        omega, zeta, timepts_force, modal_force, timepts_out
    )
    st = _prepare(omega, zeta, timepts_force, modal_force)
    eta, eta_dot, eta_ddot = _evaluate(st, timepts_out, (0, 1, 2))
    return ModalResponse(timepts=timepts_out, eta=eta, eta_dot=eta_dot, eta_ddot=eta_ddot)


def modal_pwl_evaluate(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    timepts_force: np.ndarray,
    modal_force: np.ndarray,
    timepts_out: np.ndarray,
    *,
    derivatives: Sequence[int] = (0, 1, 2),
    project: np.ndarray | None = None,
) -> np.ndarray:
    """Selected derivatives of :func:`modal_pwl_response`'s exact response, optionally projected.

    ``project @ eta^(d)`` is contracted block by block, so the modal array is never built.

    Parameters
    ----------
    omega, zeta, timepts_force, modal_force, timepts_out
        As :func:`modal_pwl_response` (rad/s, -, s, modal force, s).
    derivatives : sequence of int
        Time derivatives wanted, each 0 (eta), 1 (eta') or 2 (eta'').
    project : ndarray (r, m), optional
        Rows to contract the modes with (e.g. points' ``T phi``, m per modal unit).

    Returns
    -------
    ndarray (len(derivatives), m or r, nt)
        In the modal unit times the projection's unit, per s^d.
    """
    qs = tuple(int(d) for d in derivatives)
    if not qs or any(d not in (0, 1, 2) for d in qs):
        raise InputError(f"derivatives must be among 0, 1, 2, got {qs}", where="derivatives")
    omega, zeta, timepts_force, modal_force, timepts_out = _as_arrays(
        omega, zeta, timepts_force, modal_force, timepts_out
    )
    if project is not None:
        project = np.asarray(project, float)
        if project.ndim != 2 or project.shape[1] != omega.size:
            raise InputError(
                f"project must have shape (r, {omega.size}), got {project.shape}", where="project"
            )
    st = _prepare(omega, zeta, timepts_force, modal_force)
    return _evaluate(st, timepts_out, qs, project)


def generalized_force_vector(translation_map: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Generalized force per newton applied at a point in a direction: ``T^T d``.

    Parameters
    ----------
    translation_map : (3, n) map from the n generalized coordinates to the point's translation, m
        per unit coordinate
    direction : (3,) direction of the force (normalised here)

    Returns
    -------
    (n,) generalized force per newton of applied force.
    """
    d = np.asarray(direction, dtype=float)
    norm = np.linalg.norm(d)
    if d.shape != (3,) or not np.isfinite(norm) or norm == 0:
        raise InputError("a force direction must be a non-zero 3-vector", where="direction")
    return np.asarray(translation_map, dtype=float).T @ (d / norm)


def _point_projection(
    phi: np.ndarray, point_maps: Mapping[str, np.ndarray], where: str
) -> tuple[list[str], np.ndarray]:
    """Names and the stacked (3 P, m) projection ``T_point phi`` of every point."""
    names = list(point_maps)
    blocks = []
    for name in names:
        tmap = np.asarray(point_maps[name], dtype=float)
        if tmap.shape != (3, phi.shape[0]):
            raise InputError(
                f"translation map must have shape (3, {phi.shape[0]}), got {tmap.shape}",
                where=f"{where}: point {name!r}",
            )
        blocks.append(tmap @ phi)
    proj = np.concatenate(blocks) if blocks else np.zeros((0, phi.shape[1]))
    return names, proj


def _check_phi(phi: np.ndarray, omega: np.ndarray, b: np.ndarray, where: str) -> None:
    if phi.ndim != 2 or phi.shape[1] != omega.size:
        raise InputError(f"phi must have shape (n, {omega.size})", where=f"{where}: phi")
    if b.shape != (phi.shape[0],):
        raise InputError(f"force_dof_vector must have shape ({phi.shape[0]},)", where=where)


def response_at_points(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    phi: np.ndarray,
    point_maps: Mapping[str, np.ndarray],
    force_history: ForceHistory,
    force_dof_vector: np.ndarray,
    timepts_out: np.ndarray,
) -> dict[str, PointResponse]:
    """Translational response at named points to one force history applied through a dof vector.

    The modal force is ``p_j(t) = phi[:, j] . force_dof_vector * f(t)`` (mass-normalised modes,
    report Eqs. 2.13-2.14), the modal response is that of :func:`modal_pwl_response`, and each
    point moves by ``T_point @ phi @ eta`` (rigid-body rotation at offset points is in
    ``T_point``).  ``T_point phi`` is formed first and contracted with the modal response block
    by block, so the (3, modes, times) modal array is never built.

    Parameters
    ----------
    omega : (m,) natural frequencies, rad/s (0 for rigid-body modes)
    zeta : (m,) or scalar modal damping ratios
    phi : (n, m) mass-normalised mode shapes, one per column (phi^T M phi = I)
    point_maps : name -> (3, n) translation map of the point, m per unit generalized coordinate
    force_history : a :class:`~microg.dynamics.forces.ForceHistory` (``timepts`` s, ``force`` N)
    force_dof_vector : (n,) generalized force per newton of applied force (see
        :func:`generalized_force_vector`)
    timepts_out : (nt,) sorted output times, s

    Returns
    -------
    dict name -> PointResponse (displacement m, velocity m/s, acceleration m/s^2, shape (3, nt)).
    """
    phi = np.asarray(phi, dtype=float)
    omega = np.asarray(omega, dtype=float)
    b = np.asarray(force_dof_vector, dtype=float)
    _check_phi(phi, omega, b, "response_at_points")
    timepts_force = np.asarray(force_history.timepts, dtype=float)
    force = np.asarray(force_history.force, dtype=float)
    gamma = phi.T @ b  # (m,) modal participation per newton
    omega, zeta_a, timepts_force, modal_force, timepts_out = _as_arrays(
        omega, zeta, timepts_force, np.outer(gamma, force), timepts_out
    )
    names, proj = _point_projection(phi, point_maps, "response_at_points")
    st = _prepare(omega, zeta_a, timepts_force, modal_force)
    vals = _evaluate(st, timepts_out, (0, 1, 2), proj)  # (3, 3 P, nt)
    out: dict[str, PointResponse] = {}
    for i, name in enumerate(names):
        rows = slice(3 * i, 3 * i + 3)
        out[name] = PointResponse(
            name=name,
            timepts=timepts_out,
            displacement=vals[0, rows],
            velocity=vals[1, rows],
            acceleration=vals[2, rows],
        )
    return out


# --------------------------------------------------------------------------- exact peaks


def _accel_coefficients(st: _State, seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``a = Re(X exp(lambda tau))`` on segments ``seg``: X (m, n) complex; rigid rows separate.

    For an elastic mode a(tau) = a_k g + j_k h = Re E a_k + Im E (sigma a_k + j_k)/omega_d with
    E = exp(lambda tau), lambda = -sigma + i omega_d; so X = a_k - i (sigma a_k + j_k)/omega_d.
    Rigid rows (omega = 0) get X = 0 here; their a = a_k + j_k tau is added by the callers.
    """
    sigma = (st.zeta * st.omega)[:, None]
    omega_d = (st.omega * np.sqrt(1.0 - st.zeta * st.zeta))[:, None]
    acc, jerk = st.acc[:, seg], st.jerk[:, seg]
    with np.errstate(divide="ignore", invalid="ignore"):
        cs = np.where(omega_d > 0, (sigma * acc + jerk) / omega_d, 0.0)
    cc = np.where(omega_d > 0, acc, 0.0)
    return cc - 1j * cs, np.flatnonzero(st.omega == 0)


def _lam(st: _State) -> np.ndarray:
    return (-st.zeta * st.omega + 1j * st.omega * np.sqrt(1.0 - st.zeta * st.zeta))[:, None]


def _accel_direct(st: _State, seg: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Modal accelerations (m, n) at elapsed times ``tau`` into segments ``seg`` (>= 0)."""
    X, rigid = _accel_coefficients(st, seg)
    out = (X * _exp_decayed(_lam(st) * tau[None, :])).real
    if rigid.size:
        out[rigid] = st.acc[rigid][:, seg] + st.jerk[rigid][:, seg] * tau[None, :]
    return out


def _accel_sub(
    st: _State, seg: np.ndarray, tau_a: np.ndarray, delta: float, nsub: int
) -> np.ndarray:
    """Modal accelerations (m, n, nsub - 1) at ``tau_a + r delta``, r = 1 .. nsub - 1.

    One exponential per interval and one small table ``exp(lambda r delta)`` shared by all
    intervals of this length: a complex product per value.
    """
    X, rigid = _accel_coefficients(st, seg)
    lam = _lam(st)
    XA = X * _exp_decayed(lam * tau_a[None, :])  # (m, n)
    rd = np.arange(1, nsub) * delta
    W = np.exp(lam * rd[None, :])  # (m, nsub - 1)
    out = XA.real[:, :, None] * W.real[:, None, :] - XA.imag[:, :, None] * W.imag[:, None, :]
    if rigid.size:
        tt = tau_a[None, :, None] + rd[None, None, :]
        out[rigid] = (st.acc[rigid][:, seg])[:, :, None] + (st.jerk[rigid][:, seg])[:, :, None] * tt
    return out


#: each refinement round cuts every interval that may still hold a higher value into this many
_SUBDIVIDE = 16
#: new evaluation times per vectorised batch in the refinement (bounds the scratch memory)
_PEAK_BATCH = 8192
#: consecutive sample intervals sharing one derivative bound (taken at the first one's start)
_BOUND_BLOCK = 32


@dataclass(frozen=True)
class PeakResponse:
    """The true maximum of a point's exact acceleration over a time window (certified).

    Attributes
    ----------
    name : point name
    window_s : (2,) the closed window [t_start, t_end] searched, s (the output grid's span)
    peak_accel_mps2 : supremum of the vector magnitude |a(t)| over the window, m/s^2: the largest
        exact value found (an attained value or a one-sided limit at a force jump)
    peak_time_s : where it occurs, s
    peak_side : ``"left"`` when the supremum is the limit from the left at a force jump (the
        value just before the jump), else ``"right"`` (the right-continuous value at that time)
    upper_bound_mps2 : certified upper bound of the supremum: the true maximum lies in
        [peak_accel_mps2, upper_bound_mps2]
    peak_accel_mps2_axis : (3,) supremum of |a_x|, |a_y|, |a_z|, m/s^2
    peak_time_s_axis : (3,) where each occurs, s
    upper_bound_mps2_axis : (3,) certified upper bounds per axis, m/s^2
    sampled_peak_accel_mps2 : largest |a| at the output times alone (what sampling shows), m/s^2
    rounds : refinement rounds used
    """

    name: str
    window_s: tuple[float, float]
    peak_accel_mps2: float
    peak_time_s: float
    peak_side: str
    upper_bound_mps2: float
    peak_accel_mps2_axis: np.ndarray
    peak_time_s_axis: np.ndarray
    upper_bound_mps2_axis: np.ndarray
    sampled_peak_accel_mps2: float
    rounds: int

    @property
    def peak_accel_g(self) -> float:
        """Peak magnitude in standard gravity (G0 = 9.80665 m/s^2)."""
        return self.peak_accel_mps2 / G0

    @property
    def peak_accel_g_axis(self) -> np.ndarray:
        """Peak per axis in standard gravity, shape (3,)."""
        return self.peak_accel_mps2_axis / G0

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary (SI, names carry units)."""
        return {
            "name": self.name,
            "window_s": list(self.window_s),
            "peak_accel_mps2": self.peak_accel_mps2,
            "peak_accel_g": self.peak_accel_g,
            "peak_time_s": self.peak_time_s,
            "peak_side": self.peak_side,
            "upper_bound_mps2": self.upper_bound_mps2,
            "peak_accel_mps2_axis": self.peak_accel_mps2_axis.tolist(),
            "peak_accel_g_axis": self.peak_accel_g_axis.tolist(),
            "peak_time_s_axis": self.peak_time_s_axis.tolist(),
            "upper_bound_mps2_axis": self.upper_bound_mps2_axis.tolist(),
            "sampled_peak_accel_mps2": self.sampled_peak_accel_mps2,
            "rounds": self.rounds,
        }

    def to_xarray(self) -> Any:
        """The per-axis peaks, times and bounds as an ``xarray.Dataset`` over ``axis``.

        The magnitude's peak, time, side, bound and sampled peak are attributes.
        """
        import xarray as xr

        return xr.Dataset(
            {
                "peak_accel_mps2": ("axis", self.peak_accel_mps2_axis, {"units": "m/s^2"}),
                "peak_time_s": ("axis", self.peak_time_s_axis, {"units": "s"}),
                "upper_bound_mps2": ("axis", self.upper_bound_mps2_axis, {"units": "m/s^2"}),
            },
            coords={"axis": ("axis", ["x", "y", "z"])},
            attrs={
                "point": self.name,
                "window_s": list(self.window_s),
                "magnitude_peak_accel_mps2": self.peak_accel_mps2,
                "magnitude_peak_time_s": self.peak_time_s,
                "magnitude_peak_side": self.peak_side,
                "magnitude_upper_bound_mps2": self.upper_bound_mps2,
                "sampled_peak_accel_mps2": self.sampled_peak_accel_mps2,
                "rounds": self.rounds,
            },
        )


def _one_sided(force: ForceHistory, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Limits from the left and values (right-continuous) of a force history at times ``u``."""
    tp, fp = np.asarray(force.timepts, float), np.asarray(force.force, float)
    right = force.at(u)
    i = np.searchsorted(tp, u, side="left") - 1  # last breakpoint strictly before u
    last = tp.size - 1
    i_c = np.clip(i, 0, max(last - 1, 0))
    if last == 0:
        left = np.full(u.shape, fp[0])
    else:
        t0, t1 = tp[i_c], tp[i_c + 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where(t1 > t0, (u - t0) / (t1 - t0), 1.0)
        left = fp[i_c] + (fp[i_c + 1] - fp[i_c]) * frac
    left = np.where(i >= last, fp[-1], left)
    return np.where(i < 0, 0.0, left), right


def combined_modal_force(
    phi: np.ndarray, loads: Sequence[tuple[ForceHistory, np.ndarray]]
) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoints and modal force of the sum of several loads, for :func:`modal_pwl_response`.

    The sum of piecewise-linear forces is piecewise linear on the union of their breakpoints.
    Every union time appears twice: first with the limit from the left, then with the value from
    that time on (a jump where they differ; the kernel merges equal times).

    Parameters
    ----------
    phi : (n, m) mass-normalised mode shapes
    loads : sequence of (force history, (n,) generalized force per newton); force in N

    Returns
    -------
    timepts_force : (2 U,) s
    modal_force : (m, 2 U) modal force p_j per unit modal mass, m/s^2 per unit coordinate
    """
    phi = np.asarray(phi, dtype=float)
    if not loads:
        raise InputError("need at least one load", where="loads")
    u = np.unique(np.concatenate([np.asarray(f.timepts, float) for f, _ in loads]))
    pf = np.zeros((phi.shape[1], 2 * u.size))
    for force, b in loads:
        b = np.asarray(b, dtype=float)
        if b.shape != (phi.shape[0],):
            raise InputError(
                f"a generalized force vector must have shape ({phi.shape[0]},)", where="loads"
            )
        left, right = _one_sided(force, u)
        gamma = phi.T @ b
        pf[:, 0::2] += np.outer(gamma, left)
        pf[:, 1::2] += np.outer(gamma, right)
    return np.repeat(u, 2), pf


def _derivative_bounds(
    st: _State, proj: np.ndarray, seg: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of |a'| and |a''| of every projected row from ``tau`` on in segment ``seg``, (R, n).

    Within a segment every elastic modal acceleration is a free damped sinusoid
    ``a = Re(X exp(lambda tau))`` (:func:`_accel_coefficients`; |lambda| = omega), so from
    elapsed time ``tau`` to the segment's end ``|a'| <= omega A`` and ``|a''| <= omega^2 A`` with
    the amplitude ``A = |X| exp(-sigma tau)``, which does not increase.  A rigid mode's
    acceleration is the line ``a_k + j_k tau``: ``|a'| = |j_k|``, ``a'' = 0``.  A row's bound is the
    sum over modes of ``|T phi|`` times the modal bound.
    """
    el, rigid = st.elastic, st.rigid
    ap = np.abs(proj)
    w = st.omega[el]
    sig = (st.zeta * st.omega)[el][:, None]
    wd = (w * np.sqrt(1.0 - st.zeta[el] ** 2))[:, None]
    acc, jerk = st.acc[el][:, seg], st.jerk[el][:, seg]
    amp = np.hypot(acc, (sig * acc + jerk) / wd) * _exp_decayed(-sig * tau[None, :])
    b1 = (ap[:, el] * w) @ amp
    b2 = (ap[:, el] * (w * w)) @ amp
    if rigid.size:
        b1 += ap[:, rigid] @ np.abs(st.jerk[rigid][:, seg])
    return b1, b2


#: times at which a caller's grid accelerations are checked against the closed form
_GRID_CHECKS = 16


def _checked_grid(st: _State, t: np.ndarray, proj: np.ndarray, vals: np.ndarray) -> np.ndarray:
    """The caller's accelerations at the grid, spot-checked against the closed form."""
    if vals.shape != (proj.shape[0], t.size):
        raise ValueError(f"grid_accel has shape {vals.shape}, expected {(proj.shape[0], t.size)}")
    idx = np.unique(np.linspace(0, t.size - 1, min(_GRID_CHECKS, t.size)).astype(int))
    idx = np.union1d(idx, np.argmax(np.abs(vals), axis=1))  # each row's largest sample too
    ref = _evaluate(st, t[idx], (2,), proj)[0]
    scale = float(np.max(np.abs(vals), initial=0.0))
    if not np.all(np.abs(ref - vals[:, idx]) <= 1e-9 * scale + 1e-300):
        raise ValueError("grid_accel is not the closed-form acceleration at timepts_out")
    return vals


def peak_response(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    phi: np.ndarray,
    point_maps: Mapping[str, np.ndarray],
    loads: Sequence[tuple[ForceHistory, np.ndarray]],
    timepts_out: np.ndarray,
    *,
    rtol: float = 1e-9,
    max_rounds: int = 30,
    grid_accel: np.ndarray | None = None,
) -> dict[str, PeakResponse]:
    """True maximum of the exact acceleration at named points, with a certified bound.

    The acceleration is that of :func:`response_at_points` summed over ``loads``.  It is
    evaluated exactly (closed form) at the output times, at every force breakpoint inside the
    window with both one-sided limits at a jump (the limit from the left is the end of the
    previous segment), then refined between samples: within a force segment each modal
    acceleration is a damped sinusoid (rigid: a line), and :func:`_derivative_bounds` bounds the
    first and second derivatives ``M1, M2`` of each axis from the start of every block of
    :data:`_BOUND_BLOCK` intervals on (the modal amplitudes only decay).  An interval of length
    ``h`` whose end values are ``f_a, f_b`` cannot exceed ``max(f_a, f_b) + M2 h^2 / 8`` (the
    linear interpolant's error); |a|^2 is bounded by the sum of its axes' bounds squared, and
    on the intervals that leaves open by the same rule with ``|(|a|^2)''| <= 2 sum (M1^2 + |f|
    M2)``, ``M1`` tightened to ``|f_b - f_a| / h + M2 h``.  One vectorised pass over all intervals
    with these bounds leaves only those that might exceed the best sample; they are cut into
    :data:`_SUBDIVIDE` and evaluated exactly again, until none might exceed the best value by
    more than ``rtol``.

    Guarantee: the true supremum over the window [timepts_out[0], timepts_out[-1]] lies in
    ``[peak, upper_bound]``, and ``upper_bound <= peak (1 + rtol)`` unless ``max_rounds`` ran out
    (then ``upper_bound`` still holds and says how far off the peak may be).

    Parameters
    ----------
    omega : (m,) natural frequencies, rad/s (0 for rigid-body modes)
    zeta : (m,) or scalar modal damping ratios, 0 <= zeta < 1
    phi : (n, m) mass-normalised mode shapes (phi^T M phi = I)
    point_maps : name -> (3, n) translation map of the point, m per unit generalized coordinate
    loads : sequence of (ForceHistory, (n,) generalized force per newton), forces in N; the
        responses add (see :func:`combined_modal_force`)
    timepts_out : (nt,) sorted output times, s; their span is the window searched
    rtol : relative tolerance of the certified bound (> 0)
    max_rounds : largest number of refinement rounds (>= 0)
    grid_accel : (3 P, nt) optional, m/s^2: the caller's exact accelerations of the points at
        ``timepts_out`` (rows x, y, z of each point, in ``point_maps`` order), so that they
        are not evaluated twice; checked at a few times against the closed form (a mismatch
        beyond 1e-9 of the largest is a defect: ``ValueError``)

    Returns
    -------
    dict name -> PeakResponse (m/s^2, s)
    """
    phi = np.asarray(phi, dtype=float)
    omega = np.asarray(omega, dtype=float)
    if not (np.isfinite(rtol) and rtol > 0):
        raise InputError(f"must be a number > 0, got {rtol!r}", where="rtol")
    if not (isinstance(max_rounds, int | np.integer) and max_rounds >= 0):
        raise InputError(f"must be an integer >= 0, got {max_rounds!r}", where="max_rounds")
    if phi.ndim != 2 or phi.shape[1] != omega.size:
        raise InputError(f"phi must have shape (n, {omega.size})", where="peak_response: phi")
    tb, pf = combined_modal_force(phi, loads)
    omega, zeta_a, tb, pf, t = _as_arrays(omega, zeta, tb, pf, timepts_out)
    if t.size == 0:
        raise InputError("need at least one output time", where="timepts_out")
    names, proj = _point_projection(phi, point_maps, "peak_response")
    st = _prepare(omega, zeta_a, tb, pf)
    n_pts = len(names)
    t_lo, t_hi = float(t[0]), float(t[-1])
    starts = st.starts

    def accel(seg: np.ndarray, tt: np.ndarray) -> np.ndarray:
        """Projected acceleration (R, n) at times tt evaluated on segments seg (-1: zero)."""
        res = np.zeros((proj.shape[0], tt.size))
        ok = np.flatnonzero(seg >= 0)
        for c0 in range(0, ok.size, _PEAK_BATCH):
            idx = ok[c0 : c0 + _PEAK_BATCH]
            sg = seg[idx]
            res[:, idx] = proj @ _accel_direct(st, sg, tt[idx] - starts[sg])
        return res

    def accel_sub(sg: np.ndarray, ta: np.ndarray, tb_: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Times (na, S-1) cutting each interval into S equal parts, and the values there."""
        h = tb_ - ta
        scale = 1e-12 * max(abs(t_lo), abs(t_hi), 1.0)
        keys = np.rint(h / scale)
        tn = np.empty((ta.size, _SUBDIVIDE - 1))
        vn = np.empty((proj.shape[0], ta.size, _SUBDIVIDE - 1))
        _, inv = np.unique(keys, return_inverse=True)
        inv = inv.reshape(-1)
        for g in range(int(inv.max(initial=-1)) + 1):
            grp = np.flatnonzero(inv == g)
            delta = float(h[grp].mean()) / _SUBDIVIDE
            rd = np.arange(1, _SUBDIVIDE) * delta
            step = max(1, _PEAK_BATCH // (_SUBDIVIDE - 1))
            for c0 in range(0, grp.size, step):
                idx = grp[c0 : c0 + step]
                tau_a = ta[idx] - starts[sg[idx]]
                modal = _accel_sub(st, sg[idx], tau_a, delta, _SUBDIVIDE)
                vn[:, idx] = (proj @ modal.reshape(modal.shape[0], -1)).reshape(
                    proj.shape[0], idx.size, -1
                )
                tn[idx] = ta[idx, None] + rd
        return tn, vn

    # 1. samples: the output grid (right-continuous values) and the one-sided limits at jumps
    if grid_accel is None:
        grid_vals = _evaluate(st, t, (2,), proj)[0]  # (R, nt)
    else:
        grid_vals = _checked_grid(st, t, proj, np.asarray(grid_accel, float))
    grid_seg = np.searchsorted(starts, t, side="right") - 1
    k_right = np.flatnonzero((starts >= t_lo) & (starts <= t_hi))
    k_left = np.flatnonzero((starts > t_lo) & (starts <= t_hi))
    seg_left = k_left - 1
    times = np.concatenate([t, starts[k_right], starts[k_left]])
    segs = np.concatenate([grid_seg, k_right, seg_left])
    side = np.concatenate([np.ones(t.size + k_right.size), np.zeros(k_left.size)])  # 0: left
    extra = accel(
        np.concatenate([k_right, seg_left]), np.concatenate([starts[k_right], starts[k_left]])
    )
    vals = np.concatenate([grid_vals, extra], axis=1)

    def mag2(v: np.ndarray) -> np.ndarray:
        return (v * v).reshape(n_pts, 3, *v.shape[1:]).sum(axis=1)

    F = np.concatenate([mag2(grid_vals), mag2(extra)], axis=1)  # |a|^2 (P, samples)
    sampled = np.sqrt(F[:, : t.size].max(axis=1, initial=0.0))
    order = np.lexsort((side, times))
    if np.any(order != np.arange(order.size)):
        times, segs, side, vals, F = (
            times[order],
            segs[order],
            side[order],
            vals[:, order],
            F[:, order],
        )
    absv = np.abs(vals)
    rows = np.arange(proj.shape[0])
    arg_ax = absv.argmax(axis=1) if times.size else np.zeros(proj.shape[0], int)
    best_ax = absv[rows, arg_ax] if times.size else np.zeros(proj.shape[0])  # (R,)
    t_ax, side_ax = times[arg_ax], side[arg_ax]
    arg_F = F.argmax(axis=1)
    best_F = F[np.arange(n_pts), arg_F]  # (P,)
    t_F, side_F = times[arg_F], side[arg_F]

    # 2. intervals inside one segment (a jump separates its two limits: no interval across it)
    link = np.flatnonzero((segs[1:] == segs[:-1]) & (segs[:-1] >= 0) & (np.diff(times) > 0))
    ta, tb_, sg = times[link], times[link + 1], segs[link]
    # derivative bounds from the start of blocks of up to _BOUND_BLOCK consecutive intervals
    # of one segment (the bounds only decay within a segment: the block's first start holds)
    n_int = link.size
    new_blk = np.ones(n_int, dtype=bool)
    new_blk[1:] = (sg[1:] != sg[:-1]) | (np.arange(1, n_int) % _BOUND_BLOCK == 0)
    blk = np.cumsum(new_blk) - 1
    first = np.flatnonzero(new_blk)
    d1_blk, d2_blk = _derivative_bounds(st, proj, sg[first], ta[first] - starts[sg[first]])
    # first pass over all intervals, the cheap bounds: f <= max(|f_a|, |f_b|) + M2 h^2 / 8 per
    # axis and |a|^2 <= the sum of its axes' bounds squared; the finer bound of |a|^2
    # (``bounds``) only on the intervals these do not settle
    h = tb_ - ta
    u_ax = np.maximum(absv[:, link], absv[:, link + 1])
    u_ax += d2_blk[:, blk] * (h * h / 8.0)
    m2 = mag2(u_ax)
    grow = 1.0 + rtol
    cand = np.any(u_ax > best_ax[:, None] * grow, axis=0) | np.any(
        m2 > best_F[:, None] * grow * grow, axis=0
    )
    # largest bound of every interval set aside: the certified bound of the supremum
    drop_ax = np.max(u_ax * ~cand, axis=1, initial=0.0)
    drop_F = np.max(m2 * ~cand, axis=1, initial=0.0)
    cand_i = np.flatnonzero(cand)
    ta, tb_, sg, li = ta[cand_i], tb_[cand_i], sg[cand_i], link[cand_i]
    va, vb = vals[:, li], vals[:, li + 1]
    d1, d2 = d1_blk[:, blk[cand_i]], d2_blk[:, blk[cand_i]]  # (R, n): bounds of |a'|, |a''|
    rounds = 0

    def bounds(
        h: np.ndarray, va: np.ndarray, vb: np.ndarray, d1: np.ndarray, d2: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Upper bounds of |a_axis| (R, n) and |a|^2 (P, n) on intervals of lengths h.

        With |f''| <= M2 on an interval of length h, f <= max(f_a, f_b) + M2 h^2 / 8 (the
        linear interpolant's error); |f'| <= |f_b - f_a| / h + M2 h (mean value theorem).  For
        F = |a|^2: F'' = 2 sum (f'^2 + f f''), or directly F <= sum of the axes' bounds squared.
        """
        h2 = h * h / 8.0
        u_ax = np.maximum(np.abs(va), np.abs(vb)) + d2 * h2
        b1 = np.minimum(d1, np.abs(vb - va) / h + d2 * h)
        bF = 2.0 * mag2(b1) + 2.0 * (u_ax * d2).reshape(n_pts, 3, -1).sum(axis=1)
        u_F = np.minimum(np.maximum(mag2(va), mag2(vb)) + bF * h2, mag2(u_ax))
        return u_ax, u_F

    u_ax, u_F = bounds(tb_ - ta, va, vb, d1, d2)
    while True:
        active = np.any(u_ax > best_ax[:, None] * grow, axis=0) | np.any(
            u_F > best_F[:, None] * grow * grow, axis=0
        )
        gone = ~active
        drop_ax = np.maximum(drop_ax, u_ax[:, gone].max(axis=1, initial=0.0))
        drop_F = np.maximum(drop_F, u_F[:, gone].max(axis=1, initial=0.0))
        keep = np.flatnonzero(active)
        ta, tb_, sg, va, vb = ta[keep], tb_[keep], sg[keep], va[:, keep], vb[:, keep]
        d1, d2 = d1[:, keep], d2[:, keep]
        u_ax, u_F = u_ax[:, keep], u_F[:, keep]
        if keep.size == 0 or rounds >= max_rounds:
            break
        rounds += 1
        tn, vn = accel_sub(sg, ta, tb_)  # (na, S-1), (R, na, S-1)
        # new best values
        an = np.abs(vn).reshape(proj.shape[0], -1)
        i_ax = an.argmax(axis=1)
        better = an[np.arange(an.shape[0]), i_ax] > best_ax
        best_ax = np.where(better, an[np.arange(an.shape[0]), i_ax], best_ax)
        t_ax = np.where(better, tn.ravel()[i_ax], t_ax)
        side_ax = np.where(better, 1.0, side_ax)
        Fn = mag2(vn.reshape(proj.shape[0], -1))
        i_F = Fn.argmax(axis=1)
        betterF = Fn[np.arange(n_pts), i_F] > best_F
        best_F = np.where(betterF, Fn[np.arange(n_pts), i_F], best_F)
        t_F = np.where(betterF, tn.ravel()[i_F], t_F)
        side_F = np.where(betterF, 1.0, side_F)
        # the sub-intervals
        pts_t = np.concatenate([ta[:, None], tn, tb_[:, None]], axis=1)  # (na, S+1)
        pts_v = np.concatenate([va[:, :, None], vn, vb[:, :, None]], axis=2)  # (R, na, S+1)
        ta = pts_t[:, :-1].ravel()
        tb_ = pts_t[:, 1:].ravel()
        sg = np.repeat(sg, _SUBDIVIDE)
        d1, d2 = np.repeat(d1, _SUBDIVIDE, axis=1), np.repeat(d2, _SUBDIVIDE, axis=1)
        va = pts_v[:, :, :-1].reshape(proj.shape[0], -1)
        vb = pts_v[:, :, 1:].reshape(proj.shape[0], -1)
        u_ax, u_F = bounds(tb_ - ta, va, vb, d1, d2)

    up_ax = np.maximum(np.maximum(best_ax, drop_ax), u_ax.max(axis=1, initial=0.0))
    up_F = np.maximum(np.maximum(best_F, drop_F), u_F.max(axis=1, initial=0.0))
    out: dict[str, PeakResponse] = {}
    for i, name in enumerate(names):
        r = slice(3 * i, 3 * i + 3)
        out[name] = PeakResponse(
            name=name,
            window_s=(t_lo, t_hi),
            peak_accel_mps2=float(np.sqrt(best_F[i])),
            peak_time_s=float(t_F[i]),
            peak_side="left" if side_F[i] == 0 else "right",
            upper_bound_mps2=float(np.sqrt(up_F[i])),
            peak_accel_mps2_axis=best_ax[r].copy(),
            peak_time_s_axis=np.asarray(t_ax[r], float).copy(),
            upper_bound_mps2_axis=up_ax[r].copy(),
            sampled_peak_accel_mps2=float(sampled[i]),
            rounds=rounds,
        )
    return out
