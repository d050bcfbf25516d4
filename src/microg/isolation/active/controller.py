"""Controllers of an active isolator: acceleration feedback with relative-position centring, H2.

The ARIS / g-LIMIT architecture (Fialho & Thampi, AIAA 2000; Whorton, NASA MSFC): the measured
platform acceleration is fed back through an integrator (absolute-velocity, "sky-hook",
feedback) and the measured relative position through a centring spring, decoupled by the
platform's mass matrix:

    u = -M (g(s) a_m  +  diag(omega_p^2)  q_m),   g_i(s) = omega_a,i s / (s + omega_l,i)^2,

an integrator (``omega_a / s`` above ``omega_l``) behind a second-order high-pass at
``omega_l = LEAK_RATIO * (k + omega_p^2) / omega_a`` a decade below the isolation corner: the
loop takes no static force, so a constant (quasi-steady) acceleration is passed with the
centring spring's stroke ``a0 / (k + omega_p^2)`` only (a pure integrator would integrate it
into an ever-growing force), at the price of a mild peak (about 1.16) below the corner.

Per decoupled channel (``k = (M^-1 K)_ii``, ``c = (M^-1 C)_ii``), with ideal sensors and no
delay, the base-to-platform transmissibility is the closed form

    T(s) = (c s + k + omega_p^2) / (s^2 (1 + g(s)) + c s + k + omega_p^2),

which rolls off at 20 dB/decade between the corner ``(k + omega_p^2) / omega_a`` and
``omega_a``, at 40 dB/decade above, down to the umbilical damping's floor ``c / omega``
(:func:`channel_transmissibility` evaluates it with the sensor filter and the delay).

:func:`design_feedback` designs to a :class:`~microg.isolation.active.target.Target`: the
largest ``omega_a`` whose loop keeps ``PM_MIN`` of phase and ``GM_MIN`` of gain margin (the
accelerometer filter and the delay limit it) and stays within the plant's ``max_loop_hz`` (the
platform's own flexible modes, not modelled, bound it), then the stiffest centring ``omega_p``
that still meets the target with a factor ``DESIGN_MARGIN`` to spare (the least stroke for
the target).
Rotational channels get their own ``omega_a`` and the translational ``omega_p``.

The H2 (LQG) design per decoupled axis is :func:`microg.isolation.active.h2.design_h2`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._kept import Kept
from microg.errors import InputError
from microg.isolation.active.margins import loop_margin_values
from microg.isolation.active.plant import DOF_NAMES, ActivePlant, gain, plant_key

if TYPE_CHECKING:
    from microg.isolation.active.target import Target

__all__ = [
    "Controller",
    "CONTROLLERS",
    "feedback_controller",
    "channel_margins_ok",
    "channel_transmissibility",
    "design_feedback",
    "loop_margin_values",
    "no_controller",
    "PM_MIN_DEG",
    "GM_MIN",
    "DESIGN_MARGIN",
]

#: controller kinds
CONTROLLERS = ("designed", "h2", "off")
#: least phase margin of every loop of a designed controller, degrees
PM_MIN_DEG = 45.0
#: least gain margin of every loop of a designed controller (6 dB)
GM_MIN = 2.0
#: a designed controller meets its target with this factor to spare (the MIMO model adds the
#: coupling and the exact sensor/delay dynamics the channel design approximates)
DESIGN_MARGIN = 0.8
#: the acceleration loop's high-pass sits this fraction of the isolation corner
LEAK_RATIO = 0.1
#: least centring, rad/s (keeps a platform without umbilical stiffness centred)
OMEGA_P_MIN = 2 * math.pi * 1e-4


@dataclass(frozen=True)
class Controller:
    """A controller of the generalized plant: ``u = K y``, ``y = [a_m (6), q_m (6)]``.

    Attributes
    ----------
    kind : ``designed``, ``h2`` or ``off``
    system : ``control.StateSpace`` (12 inputs, 6 outputs), continuous
    omega_a : (6,) acceleration-loop gain per channel, rad/s (None for ``h2``)
    omega_p : (6,) centring frequency per channel, rad/s (None for ``h2``)
    notes : what the design found (which limit set each parameter)
    """

    kind: str
    system: Any = field(repr=False)
    omega_a: np.ndarray | None = None
    omega_p: np.ndarray | None = None
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready parameters (frequencies in Hz beside rad/s)."""
        out: dict[str, Any] = {"kind": self.kind, "n_states": int(self.system.nstates)}
        if self.omega_a is not None and self.omega_p is not None:
            out["accel_loop_rad_per_s"] = dict(
                zip(DOF_NAMES, map(float, self.omega_a), strict=True)
            )
            out["accel_loop_hz"] = {
                n: float(w) / (2 * math.pi) for n, w in zip(DOF_NAMES, self.omega_a, strict=True)
            }
            out["centring_rad_per_s"] = dict(zip(DOF_NAMES, map(float, self.omega_p), strict=True))
            out["centring_hz"] = {
                n: float(w) / (2 * math.pi) for n, w in zip(DOF_NAMES, self.omega_p, strict=True)
            }
        out["notes"] = list(self.notes)
        return out


def leak(plant: ActivePlant, i: int, omega_a: float, omega_p: float) -> float:
    """High-pass corner ``omega_l`` of channel ``i``'s acceleration loop, rad/s (docstring)."""
    k, _ = plant.channel(i)
    return LEAK_RATIO * (max(k, 0.0) + omega_p**2) / omega_a


def feedback_controller(plant: ActivePlant, omega_a: np.ndarray, omega_p: np.ndarray) -> Any:
    """``u = -M (g(s) a_m + diag(omega_p^2) q_m)``, ``control.StateSpace`` (module docstring).

    Parameters
    ----------
    plant : the plant (its mass matrix decouples the loops)
    omega_a : (6,) acceleration-loop gains, rad/s
    omega_p : (6,) centring frequencies, rad/s
    """
    import control as ct

    mm = plant.mass_matrix()
    wa = np.asarray(omega_a, float)
    wp = np.asarray(omega_p, float)
    wl = np.array([leak(plant, i, wa[i], wp[i]) for i in range(6)])
    # per channel g = wa s / (s + wl)^2: states (x1, x2) with x1' = -wl x1 + a, x2' = x1 - wl x2,
    # g a = wa (x1 - wl x2)  (x1 = a / (s + wl), x2 = a / (s + wl)^2)
    a = np.zeros((12, 12))
    b = np.zeros((12, 12))
    c = np.zeros((6, 12))
    for i in range(6):
        a[2 * i, 2 * i] = -wl[i]
        a[2 * i + 1, 2 * i] = 1.0
        a[2 * i + 1, 2 * i + 1] = -wl[i]
        b[2 * i, i] = 1.0
        c[i, 2 * i] = wa[i]
        c[i, 2 * i + 1] = -wa[i] * wl[i]
    d = np.hstack([np.zeros((6, 6)), -mm @ np.diag(wp**2)])
    return ct.ss(a, b, -mm @ c, d)


@functools.cache
def no_controller() -> Controller:
    """The controller off: ``u = 0`` (the platform rides on its umbilicals); one shared object."""
    return Controller("off", gain(np.zeros((6, 12))), None, None, ("controller off",))


def _pade_poly(plant: ActivePlant, order: int) -> tuple[np.ndarray, np.ndarray]:
    import control as ct

    tau = plant.effective_delay_s
    if tau <= 0 or order == 0:
        return np.array([1.0]), np.array([1.0])
    num, den = ct.pade(tau, order)
    return np.asarray(num, float), np.asarray(den, float)


def _accel_filter(plant: ActivePlant, s: np.ndarray) -> np.ndarray:
    if not math.isfinite(plant.accel_bandwidth_hz):
        return np.ones_like(s)
    wb = 2 * math.pi * plant.accel_bandwidth_hz
    return wb**2 / (s**2 + math.sqrt(2.0) * wb * s + wb**2)


def channel_transmissibility(
    plant: ActivePlant,
    i: int,
    omega_a: float,
    omega_p: float,
    freq_hz: np.ndarray,
    *,
    pade_order: int = 3,
) -> np.ndarray:
    """Decoupled channel ``i``'s base-to-platform transmissibility, complex (module docstring).

    ``T = (c s + k + D w_p^2) / (s^2 + c s + k + D (g H s^2 + w_p^2))`` with ``D`` the Pade
    delay, ``H`` the accelerometer filter, ``g = omega_a s / (s + omega_l)^2`` (derived from the
    channel's     ``q'' + c q' + k q = -a0 + v``, ``v = -D (g H a + w_p^2 q)``, ``a = q'' + a0``).

    Parameters
    ----------
    plant : the plant
    i : channel (0-5: x, y, z, rx, ry, rz)
    omega_a : acceleration-loop gain, rad/s
    omega_p : centring frequency, rad/s
    freq_hz : frequencies, Hz
    pade_order : order of the delay's Pade approximant
    """
    k, c = plant.channel(i)
    s = 2j * math.pi * np.asarray(freq_hz, float)
    num, den = _pade_poly(plant, pade_order)
    dly = np.polyval(num, s) / np.polyval(den, s)
    wl = leak(plant, i, omega_a, omega_p)
    g = omega_a * s / (s + wl) ** 2
    h = _accel_filter(plant, s)
    top = c * s + k + dly * omega_p**2
    return top / (s**2 + c * s + k + dly * (g * h * s**2 + omega_p**2))


def _channel_loop(
    plant: ActivePlant, i: int, omega_a: float, omega_p: float, pade_order: int
) -> Any:
    """Loop of decoupled channel ``i`` broken at the actuator, ``control.StateSpace`` (SISO).

    ``L = D (g H s^2 + w_p^2) / (s^2 + c s + k)``; built as a series of small state-space
    blocks (no high-order polynomial is ever formed).
    """
    import control as ct

    k, c = plant.channel(i)
    wl = leak(plant, i, omega_a, omega_p)
    body = ct.ss([[0.0, 1.0], [-k, -c]], [[0.0], [1.0]], np.eye(2), np.zeros((2, 1)))
    # [q, q'] -> a = q'' = v - c q' - k q enters with the feedthrough of v: use
    # g H s^2 q = g H (v - c q' - k q); the loop's output is D (g H a + w_p^2 q)
    acc_out = ct.ss(body.A, body.B, np.array([[-k, -c], [1.0, 0.0]]), np.array([[1.0], [0.0]]))
    g = ct.ss(
        [[-wl, 0.0], [1.0, -wl]], [[1.0], [0.0]], [[omega_a, -omega_a * wl]], [[0.0]]
    )  # omega_a s / (s + wl)^2
    if math.isfinite(plant.accel_bandwidth_hz):
        wb = 2 * math.pi * plant.accel_bandwidth_hz
        h = ct.ss(
            [[0.0, 1.0], [-(wb**2), -math.sqrt(2.0) * wb]], [[0.0], [wb**2]], [[1.0, 0.0]], [[0.0]]
        )
    else:
        h = gain(np.eye(1))
    ctrl = ct.append(g * h, gain(np.array([[omega_p**2]])))
    summed = gain(np.ones((1, 2))) * ctrl * acc_out  # v -> g H a + w_p^2 q
    dly = plant.actuator_delay(pade_order)
    dly1 = gain(np.eye(1, 6)) * dly * gain(np.eye(6, 1))
    return dly1 * summed


#: frequencies of the channel loops' margins, rad/s (read by control.stability_margins)
_DESIGN_OMEGA = 2 * math.pi * np.geomspace(1e-6, 2e4, 1500)


def _margins_ok(loop: Any) -> tuple[bool, float, float]:
    import control as ct

    closed = ct.feedback(loop, gain(np.eye(1)))
    if closed.nstates and np.max(np.linalg.eigvals(closed.A).real) >= 0:
        return False, 0.0, 0.0
    gm, pm, _, _ = loop_margin_values(loop, _DESIGN_OMEGA)
    return abs(math.log(gm)) >= math.log(GM_MIN) and pm >= PM_MIN_DEG, gm, pm


#: channel loops' margin checks already made (by plant, channel, gains and Pade order): the
#: centring search of every design of one plant tries the same loops
_CHANNEL_CACHE: Kept[tuple[Any, ...], bool] = Kept(256)


def channel_margins_ok(
    plant: ActivePlant, i: int, omega_a: float, omega_p: float, pade_order: int = 3
) -> bool:
    """Whether decoupled channel ``i``'s loop is stable with the design margins (GM, PM).

    Parameters
    ----------
    plant : the plant
    i : channel (0-5: x, y, z, rx, ry, rz)
    omega_a : acceleration-loop gain, rad/s
    omega_p : centring frequency, rad/s
    pade_order : order of the delay's Pade approximant
    """
    key = (plant_key(plant), i, float(omega_a), float(omega_p), pade_order)
    hit = _CHANNEL_CACHE.get(key)
    if hit is None:
        hit = _CHANNEL_CACHE.put(
            key, _margins_ok(_channel_loop(plant, i, omega_a, omega_p, pade_order))[0]
        )
    return hit


def _largest(ok: Any, lo: float, hi: float, rel: float = 0.01) -> float | None:
    """Largest x in [lo, hi] with ok(x) (ok assumed monotone: true below, false above)."""
    if ok(hi):
        return hi
    if not ok(lo):
        return None
    while hi / lo > 1 + rel:
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


#: acceleration-loop gains already searched, by plant and Pade order (the search depends on
#: nothing else: ``microg analyze`` designs the same preset for every observed point)
_GAINS_CACHE: Kept[tuple[Any, ...], np.ndarray] = Kept(32)


def accel_loop_gains(plant: ActivePlant, pade_order: int = 3) -> np.ndarray:
    """Each channel's largest acceleration-loop gain keeping the margins, (6,), rad/s.

    The bisection of :func:`design_feedback` (module docstring), cached per plant and Pade
    order (a copy is returned).

    Parameters
    ----------
    plant : the plant
    pade_order : order of the delay's Pade approximant in the design model
    """
    key = (plant_key(plant), pade_order)
    hit = _GAINS_CACHE.get(key)
    if hit is not None:
        return hit.copy()
    top = 2 * math.pi * min(0.5 * plant.sample_rate_hz, plant.max_loop_hz)
    wa = np.zeros(6)
    for i in range(6):
        best = _largest(
            lambda w, i=i: channel_margins_ok(plant, i, w, OMEGA_P_MIN, pade_order),
            2 * math.pi * 1e-3,
            top,
        )
        if best is None:
            raise InputError(
                f"no acceleration loop on channel {DOF_NAMES[i]} keeps {PM_MIN_DEG:g} deg of "
                f"phase and {20 * math.log10(GM_MIN):.0f} dB of gain margin",
                where="sample-rate",
                fix="raise the sampling rate or the accelerometer bandwidth, or shorten the delay",
            )
        wa[i] = best
    _GAINS_CACHE.put(key, wa.copy())
    return wa


def design_feedback(plant: ActivePlant, target: Target, *, pade_order: int = 3) -> Controller:
    """Acceleration feedback with centring designed to ``target`` (module docstring).

    Parameters
    ----------
    plant : the plant
    target : the transmissibility target (translational channels)
    pade_order : order of the delay's Pade approximant in the design model
    """
    notes: list[str] = []
    top = 2 * math.pi * min(0.5 * plant.sample_rate_hz, plant.max_loop_hz)
    wa = accel_loop_gains(plant, pade_order)
    capped = [n for n, w in zip(DOF_NAMES, wa, strict=True) if w >= top * (1 - 1e-9)]
    notes.append(
        f"acceleration loops at the largest gain keeping {PM_MIN_DEG:g} deg / "
        f"{20 * math.log10(GM_MIN):.0f} dB margins"
        + (
            f" (capped at max_loop_hz = {plant.max_loop_hz:g} Hz: {', '.join(capped)})"
            if capped
            else ""
        )
        + ": "
        + ", ".join(f"{n} {w / (2 * math.pi):.3g} Hz" for n, w in zip(DOF_NAMES, wa, strict=True))
    )
    f = target.check_freq_hz()
    lim = target.limit(f)
    pass_f = None if target.pass_below_hz is None else 0.1 * target.pass_below_hz
    from microg.isolation.active.target import PASS_LEVEL

    def meets(i: int, wp: float) -> bool:
        t = np.abs(channel_transmissibility(plant, i, wa[i], wp, f, pade_order=pade_order))
        return bool(np.all(t <= DESIGN_MARGIN * lim))

    wp_t = np.zeros(3)
    for i in range(3):
        best = _largest(lambda w, i=i: meets(i, w), OMEGA_P_MIN, wa[i] / 3.0)
        if best is None:
            notes.append(
                f"channel {DOF_NAMES[i]}: the target is out of reach even with the least "
                f"centring ({OMEGA_P_MIN / (2 * math.pi):.2g} Hz): the umbilical's path binds"
            )
            best = OMEGA_P_MIN
        # the centring loop must keep the margins too (halved until it does)
        while best > OMEGA_P_MIN and not channel_margins_ok(plant, i, wa[i], best, pade_order):
            best = max(0.5 * best, OMEGA_P_MIN)
        wp_t[i] = best
        if pass_f is not None:
            tq = abs(channel_transmissibility(plant, i, wa[i], best, np.array([pass_f]))[0])
            if tq < PASS_LEVEL:
                notes.append(
                    f"channel {DOF_NAMES[i]}: |T| = {tq:.3g} at {pass_f:g} Hz: the quasi-steady "
                    "acceleration is not passed"
                )
    wp = np.concatenate([wp_t, np.full(3, float(wp_t.min()))])
    notes.append(
        "centring at the stiffest value meeting the target with a factor "
        f"{DESIGN_MARGIN:g} to spare: "
        + ", ".join(
            f"{n} {w / (2 * math.pi):.3g} Hz" for n, w in zip(DOF_NAMES[:3], wp_t, strict=True)
        )
    )
    return Controller("designed", feedback_controller(plant, wa, wp), wa, wp, tuple(notes))
