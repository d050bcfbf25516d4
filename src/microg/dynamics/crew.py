"""The report's crew push-off/landing force (Eq. 2.16) and its exact modal response.

The force ramps from 0 to ``f0`` over ``(0, t1]``, is zero until ``t13``, jumps to ``-f0``
and ramps back to zero at ``t14`` (the seed review's reading of Eq. 2.16; the printed slope
``f0/t1`` of the landing ramp is the same when ``t14 - t13 = t1``, the report's case).
For an undamped mode ``eta'' + w^2 eta = f(t)`` from rest (Eq. 2.15) the response is written
``eta = f0/(w^3 t1) U(t)`` (Eq. 2.17) and ``eta'' = f0/(w t1) A(t)`` (Eq. 2.18).

By superposition of ramps and steps (Duhamel), with ``H_a = H(t - a)``::

    f(t) = f0 [r(t)/t1 - r(t-t1)/t1 - H_t1 - H_t13 + r(t-t13)/d - r(t-t14)/d],  d = t14 - t13

and the unit-ramp and unit-step responses ``(w s - sin w s)/w^3`` and ``(1 - cos w s)/w^2``
give, on all four intervals (2.17c and 2.19d are missing from the OCR; derived here)::

    U = [w t - sin w t] - [w s1 - sin w s1 + w t1 (1 - cos w s1)] H_t1
        + [(t1/d)(w s13 - sin w s13) - w t1 (1 - cos w s13)] H_t13
        - (t1/d) [w s14 - sin w s14] H_t14
    A = sin w t - [sin w s1 + w t1 cos w s1] H_t1
        + [(t1/d) sin w s13 - w t1 cos w s13] H_t13 - (t1/d) sin w s14 H_t14

with ``s_a = t - a``.  They satisfy ``A = w t1 f/f0 - U`` (the equation of motion).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from microg import defaults
from microg.errors import InputError
from microg.units import check_limit

__all__ = [
    "CrewPushoff",
    "MIN_RAMP_S",
    "displacement_u",
    "acceleration_a",
    "accel_amax",
    "force",
]


#: shortest push-off ramp and landing, s: a shorter pulse is an impulse, and f0 / t1 would
#: leave the floating-point range in the closed forms
MIN_RAMP_S = 1e-6

#: the one message for the sign convention of f0
_F0_FIX = "give the magnitude (e.g. 25 lbf); the direction carries the sign"


@dataclass(frozen=True)
class CrewPushoff:
    """The crew force of Eq. 2.16: the one crew-force type (validated on construction).

    :func:`microg.dynamics.forces.crew_pushoff` turns it into a
    :class:`~microg.dynamics.forces.ForceHistory`; the closed forms below take it directly.

    Attributes
    ----------
    f0 : float
        Peak force, N (the report: 25 lbf = 111.2 N); ``0 < f0 <= LIMITS["force"]`` (1e7 N).
    t1 : float
        Push-off ramp duration, s (1 s); at least :data:`MIN_RAMP_S`.
    t13 : float
        Landing start, s (13 s); ``t13 >= t1``.
    t14 : float
        Landing end, s (14 s); ``t14 - t13 >= MIN_RAMP_S`` and ``t14 <= LIMITS["time"]`` (1e7 s).

    Raises
    ------
    InputError
        Naming the parameter (``f0``, ``t1``, ``t13``, ``t14``) that breaks a rule.
    """

    f0: float = defaults.CREW_F0_N
    t1: float = defaults.CREW_T1_S
    t13: float = defaults.CREW_T13_S
    t14: float = defaults.CREW_T14_S

    def __post_init__(self) -> None:
        vals = {"f0": self.f0, "t1": self.t1, "t13": self.t13, "t14": self.t14}
        for name, v in vals.items():
            if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
                raise InputError(f"must be a number, got {v!r}", where=name)
            if not np.isfinite(v):
                raise InputError(f"must be finite, got {v}", where=name)
            object.__setattr__(self, name, float(v))
        f0, t1, t13, t14 = self.f0, self.t1, self.t13, self.t14
        if not f0 > 0:
            raise InputError(f"must be > 0, got {f0:g} N", where="f0", fix=_F0_FIX)
        check_limit(f0, "force", where="f0")
        if not t1 >= MIN_RAMP_S:
            raise InputError(f"must be >= {MIN_RAMP_S:g} s, got {t1:g} s", where="t1")
        if not t13 >= t1:
            raise InputError(f"must be >= t1 ({t1:g} s), got {t13:g} s", where="t13")
        if not t14 - t13 >= MIN_RAMP_S:
            raise InputError(
                f"must be > t13 ({t13:g} s) by at least {MIN_RAMP_S:g} s, got {t14:g} s",
                where="t14",
            )
        check_limit(t14, "time", where="t14")

    @classmethod
    def checked(cls, f0: float, t1: float, t13: float, t14: float) -> CrewPushoff:
        """The CLI's constructor: as ``CrewPushoff(...)``, with errors naming ``--f0``, ...

        The validation is the constructor's (one rule); only the names differ, until the
        CLI maps parameter names to its flags itself.
        """
        try:
            return cls(f0, t1, t13, t14)
        except InputError as exc:
            where = f"--{exc.where}" if exc.where in ("f0", "t1", "t13", "t14") else exc.where
            raise InputError(
                exc.what.replace(" t1 (", " --t1 ("), where=where, fix=exc.fix
            ) from None

    def breakpoints(self) -> tuple[np.ndarray, np.ndarray]:
        """Piecewise-linear breakpoints (times s, force N); a repeated time is a jump."""
        t = np.array([0.0, self.t1, self.t1, self.t13, self.t13, self.t14])
        f = np.array([0.0, self.f0, 0.0, 0.0, -self.f0, 0.0])
        return t, f


def force(p: CrewPushoff, t: np.ndarray) -> np.ndarray:
    """Crew force f(t) of Eq. 2.16, N; as printed, each interval is closed on the right."""
    t = np.asarray(t, float)
    out = np.where((t > 0) & (t <= p.t1), p.f0 / p.t1 * t, 0.0)
    out = np.where((t > p.t13) & (t <= p.t14), p.f0 / (p.t14 - p.t13) * (t - p.t14), out)
    return out


def _h(x: np.ndarray) -> np.ndarray:
    return (x > 0).astype(float)


def displacement_u(omega: np.ndarray | float, t: np.ndarray, p: CrewPushoff) -> np.ndarray:
    """Dimensionless displacement U(t) (Eqs. 2.17a-d), broadcast over ``omega`` and ``t``.

    Parameters
    ----------
    omega : float or ndarray
        Modal frequency, rad/s (> 0).
    t : ndarray
        Times, s.
    p : CrewPushoff
    """
    w = np.asarray(omega, float)
    t = np.asarray(t, float)
    s1, s13, s14 = t - p.t1, t - p.t13, t - p.t14
    r = p.t1 / (p.t14 - p.t13)
    u = (w * t - np.sin(w * t)) * _h(t)
    u = u - (w * s1 - np.sin(w * s1) + w * p.t1 * (1 - np.cos(w * s1))) * _h(s1)
    u = u + (r * (w * s13 - np.sin(w * s13)) - w * p.t1 * (1 - np.cos(w * s13))) * _h(s13)
    u = u - r * (w * s14 - np.sin(w * s14)) * _h(s14)
    return u


def acceleration_a(omega: np.ndarray | float, t: np.ndarray, p: CrewPushoff) -> np.ndarray:
    """Dimensionless acceleration A(t) (Eqs. 2.19a-d), broadcast over ``omega`` and ``t``.

    Parameters
    ----------
    omega : float or ndarray
        Modal frequency, rad/s.
    t : ndarray
        Times, s.
    p : CrewPushoff
    """
    w = np.asarray(omega, float)
    t = np.asarray(t, float)
    s1, s13, s14 = t - p.t1, t - p.t13, t - p.t14
    r = p.t1 / (p.t14 - p.t13)
    a = np.sin(w * t) * _h(t)
    a = a - (np.sin(w * s1) + w * p.t1 * np.cos(w * s1)) * _h(s1)
    a = a + (r * np.sin(w * s13) - w * p.t1 * np.cos(w * s13)) * _h(s13)
    a = a - r * np.sin(w * s14) * _h(s14)
    return a


def _interval_coeffs(
    w: np.ndarray, p: CrewPushoff
) -> list[tuple[float, float, np.ndarray, np.ndarray]]:
    """A(t) = alpha sin wt + beta cos wt on each interval: (start, stop, alpha, beta)."""
    r = p.t1 / (p.t14 - p.t13)
    zero = np.zeros_like(w)
    one = np.ones_like(w)

    def shifted(a: float, c_sin: np.ndarray, c_cos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # c_sin sin w(t-a) + c_cos cos w(t-a) in terms of sin wt, cos wt
        ca, sa = np.cos(w * a), np.sin(w * a)
        return c_sin * ca + c_cos * sa, -c_sin * sa + c_cos * ca

    a1, b1 = one, zero
    x, y = shifted(p.t1, -one, -w * p.t1)
    a2, b2 = a1 + x, b1 + y
    x, y = shifted(p.t13, r * one, -w * p.t1)
    a3, b3 = a2 + x, b2 + y
    x, y = shifted(p.t14, -r * one, zero)
    a4, b4 = a3 + x, b3 + y
    return [
        (0.0, p.t1, a1, b1),
        (p.t1, p.t13, a2, b2),
        (p.t13, p.t14, a3, b3),
        (p.t14, np.inf, a4, b4),
    ]


def accel_amax(omega: np.ndarray | float, p: CrewPushoff) -> np.ndarray:
    """Exact max over t >= 0 of |A(t)|, [A]max of Eq. 3.1, vectorised over ``omega``.

    On each interval A is a sinusoid ``R sin(w t + phi)``: its maximum is ``R`` when a crest
    falls inside the interval, else the larger endpoint value.  After ``t14`` the free
    vibration's amplitude counts (the mode is undamped).

    Parameters
    ----------
    omega : float or ndarray
        Modal frequency, rad/s (> 0).
    p : CrewPushoff
    """
    w = np.atleast_1d(np.asarray(omega, float))
    best = np.zeros_like(w)
    for start, stop, alpha, beta in _interval_coeffs(w, p):
        amp = np.hypot(alpha, beta)
        if np.isinf(stop):
            best = np.maximum(best, amp)
            continue
        phase = np.arctan2(beta, alpha)  # A = amp sin(w t + phase)
        # crests at w t + phase = pi/2 + k pi; is there one with t in [start, stop]?
        k_lo = np.ceil((w * start + phase - np.pi / 2) / np.pi)
        t_crest = (np.pi / 2 + k_lo * np.pi - phase) / w
        inside = t_crest <= stop
        ends = np.maximum(
            np.abs(alpha * np.sin(w * start) + beta * np.cos(w * start)),
            np.abs(alpha * np.sin(w * stop) + beta * np.cos(w * stop)),
        )
        best = np.maximum(best, np.where(inside, amp, ends))
    return best if np.ndim(omega) else best[0]
