"""Verification of an active isolator: stability, margins, transmissibility, noise, time response.

Everything is computed with python-control on the closed loop of the generalized plant
(:meth:`~microg.isolation.active.plant.ActivePlant.generalized`) and the controller,
``control.StateSpace.lft`` (``u = K y``):

* **stability**: the poles of the continuous closed loop (delay as a Pade approximant) and of
  the sampled one (ZOH plant at the sampling rate, the controller by Tustin's rule, the delay in
  whole samples), all in the open left half-plane / the unit disc;
* **margins per loop**: each of the six actuator channels broken with the other five closed
  (loop-at-a-time), ``L_i = -[(I - H E_i)^-1 H]_ii`` with ``H = K P_yu``, through
  :func:`control.stability_margins`, for both models;
* **transmissibility**: base acceleration (x, y, z) to platform acceleration, complex (3, 3, nf);
  the **direct-disturbance** response, force on the platform to its acceleration, beside the
  controller-off one;
* **noise floor**: the platform acceleration PSD that the sensors' noises put there,
  ``S_a(f) = sum_j |H_aj(f)|^2 S_j``, and its band RMS over a requirement's bands (Gauss-Legendre
  in log f, :data:`NOISE_NODES` nodes per band);
* **time response**: the station's acceleration at the mount point through the continuous
  closed loop (:func:`foh_response`: the first-order hold of :func:`control.forced_response`,
  exact for input linear between samples, by the blocked scan): the platform acceleration, the
  stroke and the actuator force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from microg._kept import Kept
from microg.errors import InputError
from microg.isolation.active.controller import Controller
from microg.isolation.active.fresp import freq_response, system_key
from microg.isolation.active.margins import margins_from_response
from microg.isolation.active.plant import DOF_NAMES, ActivePlant, gain, plant_key

__all__ = [
    "LoopMargin",
    "closed_loop",
    "loop_margins",
    "poles_stable",
    "transmissibility_matrix",
    "disturbance_response",
    "noise_psd",
    "noise_band_rms",
    "noise_floor",
    "base_and_disturbance",
    "time_response",
    "loops_at_a_time",
    "foh_response",
    "plant_yu_response",
    "NOISE_NODES",
]

#: the loops' frequency responses for the margins: points, lowest frequency (Hz); the margins
#: are read from them by :func:`control.stability_margins` (interpolated between points)
MARGIN_POINTS = 1500
MARGIN_F_LO_HZ = 1e-6
#: Gauss-Legendre nodes per band for the noise floor's band RMS (in log f)
NOISE_NODES = 24


@dataclass(frozen=True)
class LoopMargin:
    """Margins of one loop broken at its actuator with the others closed.

    Attributes
    ----------
    loop : ``x``, ``y``, ``z``, ``rx``, ``ry`` or ``rz``
    model : ``continuous`` (Pade delay) or ``discrete`` (sampled)
    gain_margin : factor (inf: no phase crossover; below 1: a gain *reduction* by it destabilises)
    gain_margin_db : dB
    phase_margin_deg : degrees (inf: no gain crossover)
    gain_crossover_hz : where |L| = 1, Hz (None: none)
    phase_crossover_hz : where the phase crosses -180 deg, Hz (None: none)
    """

    loop: str
    model: str
    gain_margin: float
    phase_margin_deg: float
    gain_crossover_hz: float | None
    phase_crossover_hz: float | None

    @property
    def gain_margin_db(self) -> float:
        """Gain margin, dB."""
        return 20 * math.log10(self.gain_margin) if self.gain_margin > 0 else -math.inf

    @property
    def gain_margin_factor(self) -> float:
        """Distance of the gain margin from 1, ``max(gm, 1/gm)`` (>= 1)."""
        g = self.gain_margin
        return max(g, 1.0 / g) if g > 0 else 1.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready margins (an infinite margin is ``"inf"``)."""

        def num(v: float | None) -> float | str | None:
            if v is None:
                return None
            return float(v) if math.isfinite(v) else ("inf" if v > 0 else "-inf")

        return {
            "gain_margin": num(self.gain_margin),
            "gain_margin_db": num(self.gain_margin_db),
            "phase_margin_deg": num(self.phase_margin_deg),
            "gain_crossover_hz": num(self.gain_crossover_hz),
            "phase_crossover_hz": num(self.phase_crossover_hz),
        }


def _select(n_out: int, rows: list[int] | range, dt: float | None = None) -> Any:
    m = np.zeros((len(rows), n_out))
    m[np.arange(len(rows)), list(rows)] = 1.0
    return gain(m, dt)


def _inputs(n_in: int, cols: list[int] | range, dt: float | None = None) -> Any:
    m = np.zeros((n_in, len(cols)))
    m[list(cols), np.arange(len(cols))] = 1.0
    return gain(m, dt)


def _sub(system: Any, rows: list[int] | range, cols: list[int] | range) -> Any:
    """The part of ``system`` from inputs ``cols`` to outputs ``rows``, ``control.StateSpace``.

    The same matrices as ``_select(rows) * system * _inputs(cols)`` (a 0/1 selection is
    exact), formed directly: one state space instead of two gains and two products.
    """
    import control as ct

    r, c = list(rows), list(cols)
    b, cc, d = (np.asarray(x, float) for x in (system.B, system.C, system.D))
    return ct.ss(np.asarray(system.A, float), b[:, c], cc[r], d[np.ix_(r, c)], system.dt)


def _controller(plant: ActivePlant, controller: Controller, discrete: bool) -> Any:
    import control as ct

    k = controller.system
    if not discrete:
        return k
    dt = 1.0 / plant.sample_rate_hz
    if k.nstates == 0:
        return gain(np.asarray(k.D, float), dt)
    return ct.c2d(k, dt, "tustin")


def closed_loop(
    plant: ActivePlant, controller: Controller, *, discrete: bool = False, pade_order: int = 3
) -> Any:
    """Closed loop ``[a0 (3), d (6), n_a (6), n_p (6)] -> [a (6), q (6), f (6)]``.

    Parameters
    ----------
    plant, controller : the isolator
    discrete : the sampled model instead of the continuous one
    pade_order : order of the delay's Pade approximant (continuous model)

    With the controller off (``u = 0``) the continuous loop is the platform on its umbilicals
    alone (12 states): the sensors and the delay carry nothing to the platform.  Formed once
    per plant, controller, model and Pade order, and shared: callers must not modify it.
    """
    key = (plant_key(plant), controller.kind, system_key(controller.system), discrete, pade_order)
    hit = _CL_CACHE.get(key)
    if hit is not None:
        return hit
    if controller.kind == "off" and not discrete:
        # u = 0: the platform on its umbilicals alone (the sensors and the delay carry nothing)
        feed = np.zeros((15, 21))
        feed[:9, :9] = np.eye(9)
        hit = plant.physical() * gain(feed)
    else:
        gen = plant.generalized(pade_order, discrete=discrete)
        hit = gen.lft(_controller(plant, controller, discrete), nu=6, ny=12)
    return _CL_CACHE.put(key, hit)


#: closed loops already formed (by plant, controller, model and Pade order)
_CL_CACHE: Kept[tuple[Any, ...], Any] = Kept(16)


def poles_stable(system: Any) -> tuple[bool, float]:
    """(all poles stable, the least stability margin): max Re(p) or max |p| - 1.

    Kept per system (by its matrices and sampling time): every observed point of one
    analysis checks the same closed loops.
    """
    key = system_key(system)
    hit = _POLES_CACHE.get(key)
    if hit is not None:
        return hit
    p = np.asarray(system.poles())
    if p.size == 0:
        hit = (True, -math.inf)
    else:
        dtime = system.isdtime(strict=True)
        worst = float(np.max(np.abs(p)) - 1.0) if dtime else float(np.max(p.real))
        hit = (worst < 0.0, worst)
    return _POLES_CACHE.put(key, hit)


#: pole checks already made (by the system's digest)
_POLES_CACHE: Kept[bytes, tuple[bool, float]] = Kept(64)


def loop_margins(
    plant: ActivePlant,
    controller: Controller,
    *,
    discrete: bool = False,
    pade_order: int = 3,
    freq_hz: np.ndarray | None = None,
) -> tuple[list[LoopMargin], np.ndarray]:
    """Margins of each loop broken at its actuator, the other five closed (module docstring).

    Returns the margins and each loop's response ``L_i`` at ``freq_hz`` (6, nf), complex
    (read-only: both are kept per plant, controller, model and frequencies).
    """
    k = _controller(plant, controller, discrete)
    model = "discrete" if discrete else "continuous"
    f_top = 0.499 * plant.sample_rate_hz if discrete else 20.0 * plant.sample_rate_hz
    omega = 2 * math.pi * np.geomspace(MARGIN_F_LO_HZ, f_top, MARGIN_POINTS)
    fr = np.asarray(freq_hz if freq_hz is not None else [], float)
    # the margins are kept per plant and controller; H = K P_yu on the margins' grid (unless
    # they are kept) and the curves' frequencies, from the responses of K and of the plant's
    # P_yu (kept per plant); every loop follows from H by the algebra of the docstring
    key = (plant_key(plant), system_key(k), pade_order, discrete)
    out = _MARGINS_CACHE.get(key)
    fr_key = (*key, fr.tobytes())
    kept = _LOOPS_CACHE.get(fr_key)
    if out is not None and kept is not None:
        return list(out), kept
    grid = omega[:0] if out is not None else omega
    parts = [f for f in (grid / (2 * math.pi), fr) if f.size]  # Hz; each P_yu kept on its own
    f_all = np.concatenate(parts) if parts else fr
    p_all = np.concatenate(
        [plant_yu_response(plant, f, pade_order, discrete) for f in parts]
        or [plant_yu_response(plant, fr, pade_order, discrete)],
        axis=2,
    )
    h = np.einsum("ijf,jkf->ikf", _fresp(k, f_all), p_all)
    loops = loops_at_a_time(h)
    if out is None:
        out = tuple(
            LoopMargin(
                loop=name,
                model=model,
                gain_margin=_num(gm),
                phase_margin_deg=_num(pm),
                gain_crossover_hz=_freq(wgc),
                phase_crossover_hz=_freq(wpc),
            )
            for i, name in enumerate(DOF_NAMES)
            for gm, pm, wgc, wpc in [margins_from_response(loops[i, : grid.size], grid)]
        )
        _MARGINS_CACHE.put(key, out)
    at_fr = loops[:, grid.size :].copy()
    at_fr.setflags(write=False)
    _LOOPS_CACHE.put(fr_key, at_fr)
    return list(out), at_fr


#: loop margins already read (by plant, controller, Pade order and model): every observed
#: point of one analysis checks the same designed controller
_MARGINS_CACHE: Kept[tuple[Any, ...], tuple[LoopMargin, ...]] = Kept(16)
#: and the loops' responses at the curves' frequencies (by the same and the frequencies)
_LOOPS_CACHE: Kept[tuple[Any, ...], np.ndarray] = Kept(16)


#: P_yu responses on the margins' grids already computed (by plant, grid, Pade order, model)
_PYU_CACHE: Kept[tuple[Any, ...], np.ndarray] = Kept(16)


def plant_yu_response(
    plant: ActivePlant, freq_hz: np.ndarray, pade_order: int = 3, discrete: bool = False
) -> np.ndarray:
    """Frequency response of the plant from the actuator commands to the measurements.

    ``P_yu``: (12, 6, nf) complex, ``u`` (6) to ``y = [a_m, q_m]`` (12), kept per plant,
    frequencies, Pade order and model (a copy is not made: do not modify it).

    Parameters
    ----------
    plant : the plant
    freq_hz : (nf,) frequencies, Hz
    pade_order : order of the delay's Pade approximant (continuous model)
    discrete : the sampled model
    """
    f = np.asarray(freq_hz, float).reshape(-1)
    key = (plant_key(plant), f.tobytes(), pade_order, discrete)
    hit = _PYU_CACHE.get(key)
    if hit is None:
        dt = 1.0 / plant.sample_rate_hz if discrete else None
        gen = plant.generalized(pade_order, discrete=discrete)
        p_yu = _select(30, range(18, 30), dt) * gen * _inputs(27, range(21, 27), dt)
        hit = _PYU_CACHE.put(key, _fresp(p_yu, f))
    return hit


def loops_at_a_time(h: np.ndarray) -> np.ndarray:
    """Each loop ``L_i = -[(I - H E_i)^-1 H]_ii`` from ``H = K P_yu``, (n, nf) complex.

    Parameters
    ----------
    h : (n, n, nf) the frequency response of ``H`` (controller times plant, actuator to
        actuator), complex; ``E_i`` is the identity with its ``i``-th diagonal entry zero
        (every loop closed but the ``i``-th, positive feedback as ``u = K y``)
    """
    n = h.shape[0]
    hf = np.moveaxis(np.asarray(h, complex), -1, 0)  # (nf, n, n)
    out = np.empty((n, hf.shape[0]), complex)
    for i in range(n):
        e = np.eye(n)
        e[i, i] = 0.0
        closed = np.linalg.solve(np.eye(n)[None] - hf @ e[None], hf)
        out[i] = -closed[:, i, i]
    return out


def _num(v: Any) -> float:
    if v is None:
        return math.inf
    v = float(v)
    return math.inf if math.isnan(v) else v


def _freq(w: Any) -> float | None:
    if w is None:
        return None
    w = float(w)
    return None if not math.isfinite(w) else w / (2 * math.pi)


def _fresp(system: Any, freq_hz: np.ndarray) -> np.ndarray:
    """Complex frequency response (nout, nin, nf) at ``freq_hz`` (:func:`.fresp.freq_response`)."""
    return freq_response(system, freq_hz)


def transmissibility_matrix(cl: Any, freq_hz: np.ndarray) -> np.ndarray:
    """Base (x, y, z) to platform linear acceleration, complex (3, 3, nf)."""
    sub = _sub(cl, range(3), range(3))
    return _fresp(sub, freq_hz)


def disturbance_response(cl: Any, freq_hz: np.ndarray) -> np.ndarray:
    """Force/torque on the platform to its acceleration, complex (6, 6, nf), SI per N or N m."""
    sub = _sub(cl, range(6), range(3, 9))
    return _fresp(sub, freq_hz)


def base_and_disturbance(cl: Any, freq_hz: np.ndarray) -> np.ndarray:
    """Base (x, y, z) and force/torque (6) to platform acceleration, complex (6, 9, nf).

    ``[:3, :3]`` is :func:`transmissibility_matrix`, ``[:, 3:]`` :func:`disturbance_response`,
    from one frequency response.
    """
    sub = _sub(cl, range(6), range(9))
    return _fresp(sub, freq_hz)


def noise_floor(
    cl: Any, plant: ActivePlant, freq_hz: np.ndarray, lower_hz: np.ndarray, upper_hz: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`noise_psd` at ``freq_hz`` and :func:`noise_band_rms` over the bands, at once.

    Returns the PSD (3, nf), (m/s^2)^2/Hz, and the band RMS (3, nb), m/s^2, from one frequency
    response at the curves' frequencies and the bands' quadrature nodes.
    """
    f = np.asarray(freq_hz, float).reshape(-1)
    nodes, jac = _band_nodes(lower_hz, upper_hz)
    psd = noise_psd(cl, plant, np.concatenate([f, nodes.ravel()]))
    band = psd[:, f.size :].reshape(3, *nodes.shape)
    return psd[:, : f.size], np.sqrt(np.sum(band * jac[None], axis=2))


def _band_nodes(lower_hz: np.ndarray, upper_hz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes in log f per band (nb, NOISE_NODES), Hz, and their weights in f."""
    lo = np.asarray(lower_hz, float)
    hi = np.asarray(upper_hz, float)
    x, wq = np.polynomial.legendre.leggauss(NOISE_NODES)
    u = 0.5 * (x + 1.0)  # on [0, 1]
    lf = np.log(lo)[:, None] + (np.log(hi) - np.log(lo))[:, None] * u[None, :]
    f = np.exp(lf)  # (nb, nodes)
    jac = (np.log(hi) - np.log(lo))[:, None] * 0.5 * wq[None, :] * f  # df = f dlnf
    return f, jac


def noise_psd(cl: Any, plant: ActivePlant, freq_hz: np.ndarray) -> np.ndarray:
    """Platform linear-acceleration PSD from the sensors' noises, (3, nf), (m/s^2)^2/Hz."""
    sub = _sub(cl, range(3), range(9, 21))
    h = _fresp(sub, freq_hz)
    s = np.concatenate([np.full(6, plant.accel_noise_psd), np.full(6, plant.position_noise_psd)])
    return np.einsum("ijf,j->if", np.abs(h) ** 2, s)


def noise_band_rms(
    cl: Any, plant: ActivePlant, lower_hz: np.ndarray, upper_hz: np.ndarray
) -> np.ndarray:
    """Band RMS of the noise floor per axis, (3, nb), m/s^2 (Gauss-Legendre in log f)."""
    f, jac = _band_nodes(lower_hz, upper_hz)
    psd = noise_psd(cl, plant, f.ravel()).reshape(3, *f.shape)
    return np.sqrt(np.sum(psd * jac[None], axis=2))


def time_response(
    cl: Any, timepts: np.ndarray, base_accel: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Platform linear acceleration (3, nt), relative motion q (6, nt), force f (6, nt).

    Parameters
    ----------
    cl : the continuous closed loop (:func:`closed_loop`)
    timepts : (nt,) equally spaced times, s
    base_accel : (3, nt) the mount point's acceleration, m/s^2 (linear between samples)
    """
    t = np.asarray(timepts, float)
    u = np.asarray(base_accel, float)
    if u.shape != (3, t.size):
        raise InputError(f"needs shape (3, {t.size}), got {u.shape}", where="base_accel")
    if t.size < 2:
        raise InputError("needs at least 2 samples", where="timepts")
    steps = np.diff(t)
    if np.any(steps <= 0) or np.ptp(steps) > 1e-9 * max(float(np.mean(steps)), 1e-300) * t.size:
        raise InputError("times must be equally spaced and increasing", where="timepts")
    rows = list(range(3)) + list(range(6, 12)) + list(range(12, 18))
    sub = _sub(cl, rows, range(3))
    y = foh_response(sub, t, u)
    return y[:3], y[3:9], y[9:15]


def foh_response(system: Any, timepts: np.ndarray, inputs: np.ndarray) -> np.ndarray:
    """Outputs (q, nt) of a continuous state-space system from rest, input linear between samples.

    The first-order hold of :func:`control.forced_response`, with its discretisation (one
    matrix exponential of ``[[A dt, B dt, 0], [0, 0, I], [0, 0, 0]]`` gives ``A_d``,
    ``B_d0``, ``B_d1``, ``x_{k+1} = A_d x_k + B_d0 u_k + B_d1 u_{k+1}``), exact for an input
    linear between samples; the recurrence is run by the blocked scan
    :func:`microg._scan.lti_scan` instead of one Python step per sample (equal to the
    sequential loop to a few roundings per block), ``y = C x + D u``.

    Parameters
    ----------
    system : a continuous ``control.StateSpace`` with p inputs and q outputs
    timepts : (nt,) equally spaced times, s (checked by the caller)
    inputs : (p, nt) the inputs at the times (their units per the system)
    """
    from scipy.linalg import expm

    from microg._scan import lti_scan

    A, B = np.asarray(system.A, float), np.asarray(system.B, float)
    C, D = np.asarray(system.C, float), np.asarray(system.D, float)
    t = np.asarray(timepts, float)
    u = np.asarray(inputs, float).reshape(B.shape[1], t.size)
    n, p = B.shape
    if not np.any(u):
        return np.zeros((C.shape[0], t.size))
    dt = (t[-1] - t[0]) / (t.size - 1)
    big = np.zeros((n + 2 * p, n + 2 * p))
    big[:n, :n] = A * dt
    big[:n, n : n + p] = B * dt
    big[n : n + p, n + p :] = np.eye(p)
    e = expm(big)
    ad, bd1 = e[:n, :n], e[:n, n + p :]
    bd0 = e[:n, n : n + p] - bd1
    if n and np.max(np.abs(np.linalg.eigvals(ad))) >= 1.0:
        # not asymptotically stable: the sequential recurrence (the scan's composed block maps
        # would overflow before the states do)
        x = np.zeros((n, t.size))
        for k in range(1, t.size):
            x[:, k] = ad @ x[:, k - 1] + bd0 @ u[:, k - 1] + bd1 @ u[:, k]
        return C @ x + D @ u
    steps = np.concatenate([u[:, :-1], u[:, 1:]]).T  # (nt - 1, 2 p): u_k and u_{k+1}
    y = lti_scan(ad, np.concatenate([bd0.T, bd1.T]), steps, C).T
    return y + D @ u
