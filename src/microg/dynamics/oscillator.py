"""Closed-form responses of one damped modal oscillator, exact for any ``omega tau``.

For ``eta'' + 2 zeta omega eta' + omega^2 eta = p(t)`` (report Eq. 2.15 with modal damping),
``sigma = zeta omega``, ``omega_d = omega sqrt(1 - zeta^2)``:

* ``h``: impulse response  ``exp(-sigma tau) sin(omega_d tau) / omega_d``,
* ``g``: free response to a unit displacement ``exp(-sigma tau)(cos + sigma/omega_d sin)``,
* ``S = int_0^tau h``: unit-step response, ``R = int_0^tau S``: unit-ramp response.

``g`` and ``h`` are written with ``sinc`` so they are exact for ``omega -> 0``; ``S`` and ``R``
lose digits by cancellation when ``omega tau`` is small, so for ``omega tau <``
:data:`SERIES_BELOW` they are summed from their Taylor series (the recursion of the ODE
itself).  A rigid-body mode (``omega = 0``) therefore needs no special case: it is double
integration, ``S = tau^2/2``, ``R = tau^3/6``.

A damped term that has decayed below exp(-:data:`DECAYED`) (1e-261) of its start is set to
exactly 0 (:func:`exp_decayed`, :func:`exp_table`): far below rounding, and it keeps subnormal
numbers (slow arithmetic) out of the kernels.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "DECAYED",
    "SERIES_BELOW",
    "exp_decayed",
    "exp_table",
    "oscillator_functions",
    "sinc",
    "step_ramp_series",
]

#: below this value of omega * tau the step and ramp functions are summed from their series
SERIES_BELOW = 0.5
#: number of series terms: the terms fall roughly like (2 x)^n / n!, 20 terms reach 4e-19 at x = 0.5
_SERIES_TERMS = 20
#: a damped term that has decayed by more than exp(-DECAYED) (1e-261) of its start is set to 0:
#: far below rounding, and it keeps subnormal numbers (100x slower arithmetic) out of the kernel
DECAYED = 600.0


def exp_decayed(z: np.ndarray) -> np.ndarray:
    """``exp(z)``, exactly 0 where ``Re z < -DECAYED`` (no subnormal results).

    Parameters
    ----------
    z : array, real or complex exponents (dimensionless)
    """
    return np.exp(np.where(z.real < -DECAYED, -np.inf, z))


def exp_table(lam: np.ndarray, t0: float, step: float, count: int) -> np.ndarray:
    """``exp(lam (t0 + i step))``, i = 0 .. count - 1, shape (modes, count).

    Each entry is the product of two direct exponentials, a coarse one at ``t0 + i1 q step``
    and a fine one at ``i2 step`` (``i = i1 q + i2``, ``q = ceil(sqrt(count))``): one rounding
    more than a direct exponential, no recurrence, and about ``2 sqrt(count)`` exponentials
    instead of ``count``.  Entries whose exponent's real part is below ``-DECAYED`` are 0.

    Parameters
    ----------
    lam : (modes, 1) complex exponents ``-sigma + i omega_d``, 1/s
    t0 : first time, s
    step : spacing, s
    count : number of times
    """
    q = max(1, int(np.ceil(np.sqrt(count))))
    nc = -(-count // q)
    coarse = exp_decayed(lam * (t0 + np.arange(nc) * (q * step)))  # (modes, nc)
    fine = np.exp(lam * (np.arange(q) * step))  # (modes, q)
    out = (coarse[:, :, None] * fine[:, None, :]).reshape(lam.shape[0], nc * q)[:, :count]
    t_last = t0 + (count - 1) * step
    if np.any(lam.real * max(abs(t0), abs(t_last)) < -DECAYED):  # a product may be subnormal
        out = np.where(lam.real * (t0 + np.arange(count) * step) < -DECAYED, 0.0, out)
    return out


def sinc(theta: np.ndarray) -> np.ndarray:
    """sin(theta)/theta, exact at 0 (numpy's sinc is normalised by pi); theta in rad."""
    return np.sinc(theta / np.pi)


def step_ramp_series(
    x: np.ndarray, two_sigma_tau: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Unit-step and unit-ramp responses S (s^2), R (s^3) from their Taylor series.

    Both obey y'' + 2 sigma y' + omega^2 y = forcing with zero start; writing a_n = c_n tau^n the
    recursion is a_{n+2} = -((n+1) (2 sigma tau) a_{n+1} + x^2 a_n) / ((n+2)(n+1)), x = omega tau,
    started from S: a_2 = tau^2/2 and R: a_3 = tau^3/6.

    Parameters
    ----------
    x : array, ``omega tau`` (dimensionless, below :data:`SERIES_BELOW`)
    two_sigma_tau : array, ``2 zeta omega tau`` (dimensionless)
    tau : array, elapsed times, s
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
    decay = exp_decayed(-st)
    cos_t = np.cos(theta)
    tsinc = tau * sinc(theta)  # sin(omega_d tau) / omega_d
    h = decay * tsinc
    g = decay * (cos_t + sigma * tsinc)
    x = omega * tau
    w2 = omega * omega
    small = x < SERIES_BELOW
    with np.errstate(divide="ignore", invalid="ignore"):
        S = (1.0 - g) / w2
        R = (tau - h - 2.0 * sigma * S) / w2 if need_ramp else None
    if np.any(small):
        s_ser, r_ser = step_ramp_series(x[small], 2.0 * st[small], tau[small])
        S[small] = s_ser
        if R is not None:
            R[small] = r_ser
    return g, h, S, R
