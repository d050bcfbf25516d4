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
``omega tau`` is small, so for ``omega tau < 1`` they are summed from their Taylor series (the
recursion of the ODE itself).  A rigid-body mode (``omega = 0``) therefore needs no special case:
it is double integration, ``S = tau^2/2``, ``R = tau^3/6``.

The start states of all segments are the prefix composition of the segments' affine state maps,
done by a log-depth (Hillis-Steele) scan vectorised over modes and segments; the output times are
located with ``np.searchsorted`` and evaluated at once, vectorised over modes and times.

Conventions: the force is zero before the first breakpoint; a repeated breakpoint time is a jump
(the last value at that time holds from it on, i.e. the force is right-continuous; times closer than
4 roundings of max(|t|, 1 s) count as repeated); after the last breakpoint the force holds its last
value.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from microg.errors import InputError
from microg.units import G0

if TYPE_CHECKING:
    from microg.dynamics.forces import ForceHistory

__all__ = [
    "ModalResponse",
    "PointResponse",
    "modal_pwl_response",
    "generalized_force_vector",
    "response_at_points",
    "oscillator_functions",
]

#: below this value of omega * tau the step and ramp functions are summed from their series
_SERIES_BELOW = 0.5
#: number of series terms: the terms fall roughly like (2 x)^n / n!, 24 terms reach 1e-24 at x = 0.5
_SERIES_TERMS = 24


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
    # S series
    a_prev = np.zeros_like(tau)  # a_1
    a_cur = 0.5 * tau * tau  # a_2
    s_sum = a_cur.copy()
    # R series
    r_prev = np.zeros_like(tau)  # a_2
    r_cur = tau * tau * tau / 6.0  # a_3
    r_sum = r_cur.copy()
    for n in range(1, _SERIES_TERMS):
        # S: next is a_{n+2} from a_{n+1} (cur) and a_n (prev)
        nxt = -((n + 1) * two_sigma_tau * a_cur + x2 * a_prev) / ((n + 2) * (n + 1))
        a_prev, a_cur = a_cur, nxt
        s_sum += nxt
        k = n + 1  # R: a_{k+2} from a_{k+1}, a_k
        rnxt = -((k + 1) * two_sigma_tau * r_cur + x2 * r_prev) / ((k + 2) * (k + 1))
        r_prev, r_cur = r_cur, rnxt
        r_sum += rnxt
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
    decay = np.exp(-st)
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

    Segment k maps its start state z_k to z_{k+1} = M_k z_k + c_k.  The inclusive prefix
    composition of these affine maps (log-depth scan over segments, vectorised over modes) applied
    to z_0 = 0 gives z_{k+1} = C_k, the accumulated offset.
    """
    m, K = p_right.shape
    eta0 = np.zeros((m, K))
    vel0 = np.zeros((m, K))
    if K == 1:
        return eta0, vel0
    w = omega[:, None]
    z = zeta[:, None]
    tau = lengths[None, :]
    g, h, S, R = oscillator_functions(w, z, tau)
    p = p_right[:, :-1]
    s = slopes[:, :-1]
    # state map of one segment: [eta, v] -> [[g, h], [-w^2 h, g']] [eta, v] + c
    # with g' for velocity: v(tau) = v0 g + a0 h + s S and a0 = p - 2 sigma v0 - w^2 eta0
    two_sigma = 2.0 * z * w
    w2 = w * w
    m00, m01 = g, h
    m10 = -w2 * h
    m11 = g - two_sigma * h
    c0 = p * S + s * R
    c1 = p * h + s * S
    # Hillis-Steele inclusive scan: (M, c)_k <- (M, c)_k o (M, c)_{k-d}
    d = 1
    n = K - 1
    while d < n:
        a00, a01, a10, a11 = m00[:, d:], m01[:, d:], m10[:, d:], m11[:, d:]
        b00, b01, b10, b11 = m00[:, :-d], m01[:, :-d], m10[:, :-d], m11[:, :-d]
        bc0, bc1 = c0[:, :-d], c1[:, :-d]
        new_c0 = a00 * bc0 + a01 * bc1 + c0[:, d:]
        new_c1 = a10 * bc0 + a11 * bc1 + c1[:, d:]
        new00 = a00 * b00 + a01 * b10
        new01 = a00 * b01 + a01 * b11
        new10 = a10 * b00 + a11 * b10
        new11 = a10 * b01 + a11 * b11
        c0 = np.concatenate([c0[:, :d], new_c0], axis=1)
        c1 = np.concatenate([c1[:, :d], new_c1], axis=1)
        m00 = np.concatenate([m00[:, :d], new00], axis=1)
        m01 = np.concatenate([m01[:, :d], new01], axis=1)
        m10 = np.concatenate([m10[:, :d], new10], axis=1)
        m11 = np.concatenate([m11[:, :d], new11], axis=1)
        d *= 2
    eta0[:, 1:] = c0
    vel0[:, 1:] = c1
    return eta0, vel0


def _uniform_split(tau: np.ndarray) -> tuple[float, int, int] | None:
    """(dt, L, nblocks), nblocks * L <= n, if ``tau`` is uniform to a few roundings; else None."""
    n = tau.size
    if n < 64:
        return None
    dt = (tau[-1] - tau[0]) / (n - 1)
    if not dt > 0:
        return None
    dev = np.max(np.abs(tau - (tau[0] + np.arange(n) * dt)))
    if dev > 8.0 * np.spacing(np.max(np.abs(tau)) + abs(tau[0])):
        return None
    L = int(np.ceil(np.sqrt(n)))
    return dt, L, n // L


def _elastic_segment(
    omega: np.ndarray,
    zeta: np.ndarray,
    eta0: np.ndarray,
    vel0: np.ndarray,
    acc0: np.ndarray,
    jerk0: np.ndarray,
    p0: np.ndarray,
    s0: np.ndarray,
    tau: np.ndarray,
    out: np.ndarray,
) -> None:
    """Response of elastic modes (omega > 0) on one segment at elapsed times ``tau`` (sorted).

    Writes eta, eta', eta'' into ``out`` (a view of shape (3, m, n)).  With E = exp(lambda tau),
    lambda = -sigma + i omega_d, each quantity is ``Re E * cc + Im E * cs + q0 + q1 tau`` with
    per-mode coefficients folding in the start state and the force.  On a uniform run of ``tau``
    E_i = exp(lambda tau_b) exp(lambda r dt) (i = b L + r): two small tables of direct
    evaluations, and the whole (3, m, n) block is one batched matrix product with inner
    dimension 4 -- a few roundings per entry, no recurrence.  Otherwise E is evaluated directly.
    Where omega tau < _SERIES_BELOW (a prefix of ``tau`` for each mode) the folded form loses
    digits by cancellation; those entries are recomputed with :func:`oscillator_functions`.
    """
    sigma = zeta * omega
    omega_d = omega * np.sqrt(1.0 - zeta * zeta)
    w2 = omega * omega
    beta = s0 / w2
    g_coef = eta0 - p0 / w2 + 2.0 * sigma * s0 / (w2 * w2)
    h_coef = vel0 - beta
    alpha = p0 / w2 - 2.0 * sigma * s0 / (w2 * w2)
    zero = np.zeros_like(omega)
    cc = np.stack([g_coef, h_coef, acc0])  # (3, m): coefficient of Re E
    cs = (sigma * cc + np.stack([h_coef, acc0, jerk0])) / omega_d  # coefficient of Im E
    q0 = np.stack([alpha, beta, zero])
    q1 = np.stack([beta, zero, zero])
    lam = (-sigma + 1j * omega_d)[:, None]
    n = tau.size
    split = _uniform_split(tau)
    done = 0
    if split is not None:
        dt, L, nblocks = split
        done = nblocks * L
        tau_b = tau[0] + (np.arange(nblocks) * L) * dt
        A = np.exp(lam * tau_b[None, :])  # (m, nblocks)
        W = np.exp(lam * (np.arange(L) * dt)[None, :])  # (m, L)
        Ar, Ai = A.real[None], A.imag[None]
        c_, s_ = cc[:, :, None], cs[:, :, None]
        lhs = np.stack(
            [
                c_ * Ar + s_ * Ai,
                s_ * Ar - c_ * Ai,
                q0[:, :, None] + q1[:, :, None] * tau_b[None, None, :],
                np.broadcast_to(q1[:, :, None], (3, omega.size, nblocks)),
            ],
            axis=-1,
        )  # (3, m, nblocks, 4)
        rhs = np.stack(
            [W.real, W.imag, np.ones_like(W.real), np.broadcast_to(np.arange(L) * dt, W.shape)],
            axis=1,
        )  # (m, 4, L)
        target = out[:, :, :done].reshape(3, omega.size, nblocks, L)
        if np.shares_memory(target, out):
            np.matmul(lhs, rhs, out=target)
        else:  # pragma: no cover - reshape of a last-axis slice is always a view
            out[:, :, :done] = (lhs @ rhs).reshape(3, omega.size, done)
    if done < n:
        rest = tau[done:]
        E = np.exp(lam * rest[None, :])
        c, s = E.real, E.imag
        for q in range(3):
            out[q, :, done:] = (
                c * cc[q, :, None] + s * cs[q, :, None] + q0[q, :, None] + q1[q, :, None] * rest
            )
    # stable recomputation where omega tau < _SERIES_BELOW (a prefix of tau for each mode)
    n_small = np.searchsorted(tau, _SERIES_BELOW / omega, side="left")
    nmax = int(n_small.max(initial=0))
    if nmax:
        rows = np.flatnonzero(n_small)
        tt = tau[None, :nmax]
        w, z = omega[rows, None], zeta[rows, None]
        g, h, S, R = oscillator_functions(w, z, tt)
        mask = np.arange(nmax)[None, :] < n_small[rows, None]
        e0, v0, a0 = eta0[rows, None], vel0[rows, None], acc0[rows, None]
        stable = (
            e0 * g + v0 * h + p0[rows, None] * S + s0[rows, None] * R,
            v0 * g + a0 * h + s0[rows, None] * S,
            a0 * g + jerk0[rows, None] * h,
        )
        sub = np.ix_(rows, np.arange(nmax))
        for q in range(3):
            view = out[q]
            view[sub] = np.where(mask, stable[q], view[sub])


#: above this many segments holding output times, evaluate all outputs at once (gather path)
_MAX_SLICED_SEGMENTS = 64


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
    timepts_out : (nt,) sorted output times, s; any spacing; times before the first breakpoint
        give zero response

    Returns
    -------
    ModalResponse
        ``eta``, ``eta_dot``, ``eta_ddot`` of shape (m, nt); accelerations are right-continuous.
    """
    omega = np.asarray(omega, dtype=float)
    zeta = np.broadcast_to(np.asarray(zeta, dtype=float), omega.shape).astype(float)
    timepts_force = np.asarray(timepts_force, dtype=float)
    modal_force = np.asarray(modal_force, dtype=float)
    if modal_force.ndim == 1 and omega.size == 1:
        modal_force = modal_force[None, :]
    timepts_out = np.asarray(timepts_out, dtype=float)
    _validate(omega, zeta, timepts_force, modal_force, timepts_out)

    starts, p_right, slopes, lengths = _segments(timepts_force, modal_force)
    eta_k, vel_k = _start_states(omega, zeta, p_right, slopes, lengths)
    w = omega[:, None]
    two_sigma = 2.0 * zeta[:, None] * w
    w2 = w * w
    acc_k = p_right - two_sigma * vel_k - w2 * eta_k
    jerk_k = slopes - two_sigma * acc_k - w2 * vel_k
    state = (eta_k, vel_k, acc_k, jerk_k, p_right, slopes)

    bounds = np.r_[np.searchsorted(timepts_out, starts, side="left"), timepts_out.size]
    filled = np.flatnonzero(np.diff(bounds) > 0)
    if filled.size > _MAX_SLICED_SEGMENTS:
        eta, eta_dot, eta_ddot = _evaluate_gathered(omega, zeta, starts, state, timepts_out)
    else:
        m, nt = omega.size, timepts_out.size
        full = np.zeros((3, m, nt))
        rigid = np.flatnonzero(omega == 0)
        elastic = np.flatnonzero(omega != 0)
        contiguous = elastic.size > 0 and elastic[-1] - elastic[0] + 1 == elastic.size
        el_rows = slice(elastic[0], elastic[-1] + 1) if contiguous else elastic
        out_e = full[:, el_rows] if contiguous else np.zeros((3, elastic.size, nt))
        for k in filled:
            i0, i1 = bounds[k], bounds[k + 1]
            tau = timepts_out[i0:i1] - starts[k]
            e0, v0, a0, j0, p0, s0 = (x[:, k] for x in state)
            if rigid.size:  # double integration of a linear force: exact polynomials
                r = rigid
                t1, t2, t3 = tau, tau * tau / 2.0, tau**3 / 6.0
                full[0, r, i0:i1] = (
                    e0[r, None] + np.outer(v0[r], t1) + np.outer(p0[r], t2) + np.outer(s0[r], t3)
                )
                full[1, r, i0:i1] = v0[r, None] + np.outer(p0[r], t1) + np.outer(s0[r], t2)
                full[2, r, i0:i1] = p0[r, None] + np.outer(s0[r], t1)
            if elastic.size:
                el = el_rows
                _elastic_segment(
                    omega[el],
                    zeta[el],
                    e0[el],
                    v0[el],
                    a0[el],
                    j0[el],
                    p0[el],
                    s0[el],
                    tau,
                    out_e[:, :, i0:i1],
                )
        if elastic.size and not contiguous:
            full[:, elastic] = out_e
        eta, eta_dot, eta_ddot = full
    return ModalResponse(timepts=timepts_out, eta=eta, eta_dot=eta_dot, eta_ddot=eta_ddot)


def _evaluate_gathered(
    omega: np.ndarray,
    zeta: np.ndarray,
    starts: np.ndarray,
    state: tuple[np.ndarray, ...],
    timepts_out: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Evaluate every output at once: locate its segment, gather the start state, closed form."""
    eta_k, vel_k, acc_k, jerk_k, p_right, slopes = state
    seg = np.searchsorted(starts, timepts_out, side="right") - 1
    before = seg < 0
    seg_c = np.where(before, 0, seg)
    tau = np.where(before, 0.0, timepts_out - starts[seg_c])[None, :]
    g, h, S, R = oscillator_functions(omega[:, None], zeta[:, None], tau)
    e0, v0, a0 = eta_k[:, seg_c], vel_k[:, seg_c], acc_k[:, seg_c]
    p0, s0, j0 = p_right[:, seg_c], slopes[:, seg_c], jerk_k[:, seg_c]
    eta = e0 * g + v0 * h + p0 * S + s0 * R
    eta_dot = v0 * g + a0 * h + s0 * S
    eta_ddot = a0 * g + j0 * h
    if np.any(before):
        eta[:, before] = 0.0
        eta_dot[:, before] = 0.0
        eta_ddot[:, before] = 0.0
    return eta, eta_dot, eta_ddot


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
    report Eqs. 2.13-2.14), the modal response comes from :func:`modal_pwl_response`, and each point
    moves by ``T_point @ phi @ eta`` (rigid-body rotation at offset points is in ``T_point``).

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
    if phi.ndim != 2 or phi.shape[1] != omega.size:
        raise InputError(f"phi must have shape (n, {omega.size})", where="response_at_points: phi")
    if b.shape != (phi.shape[0],):
        raise InputError(
            f"force_dof_vector must have shape ({phi.shape[0]},)", where="response_at_points"
        )
    timepts_force = np.asarray(force_history.timepts, dtype=float)
    force = np.asarray(force_history.force, dtype=float)
    gamma = phi.T @ b  # (m,) modal participation per newton
    modal = modal_pwl_response(omega, zeta, timepts_force, np.outer(gamma, force), timepts_out)
    out: dict[str, PointResponse] = {}
    for name, tmap in point_maps.items():
        tmap = np.asarray(tmap, dtype=float)
        if tmap.shape != (3, phi.shape[0]):
            raise InputError(
                f"translation map must have shape (3, {phi.shape[0]}), got {tmap.shape}",
                where=f"response_at_points: point {name!r}",
            )
        tphi = tmap @ phi  # (3, m)
        out[name] = PointResponse(
            name=name,
            timepts=modal.timepts,
            displacement=tphi @ modal.eta,
            velocity=tphi @ modal.eta_dot,
            acceleration=tphi @ modal.eta_ddot,
        )
    return out
