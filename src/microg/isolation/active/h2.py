"""H2 (LQG) design of an active isolator per decoupled axis, by :func:`control.h2syn` (slycot).

Each channel ``i`` (``k = (M^-1 K)_ii``, ``c = (M^-1 C)_ii``, per unit mass: ``v = f / M_ii``)
is the platform on its umbilical, ``q'' + c q' + k q = -a0 + D(v)`` with ``a = q'' + a0``
and ``D`` the actuator delay (Pade approximant of ``delay_s`` plus half a ZOH sample).  The
generalized plant of the synthesis has

* exogenous inputs ``w = [w0, wa, wp]``: the base acceleration ``a0 = SIGMA_BASE * w0``, the
  accelerometer noise ``sigma_a * wa`` (added after its filter) and the position sensor's
  ``sigma_p * wp`` (white, the plant's noise levels with floors that keep ``D21`` of full rank);
* performance outputs ``z = [rho * W(s) a, q / stroke, v M_ii / force]``: the platform
  acceleration through ``W``, a band-pass (first order each side) over the target's span, the
  stroke over the rattlespace and the force over the actuator limit (Bryson's rule);
* measurements ``y = [H(s) a + sigma_a wa, q + sigma_p wp]`` (``H`` the accelerometer's
  2nd-order Butterworth) and the control ``u = v``.

``D11 = 0`` (``a`` does not feed through from ``a0``), ``D22 = 0`` (``H`` strictly proper),
``D12`` and ``D21`` of full rank: the standard H2 problem, whose unique optimal controller is the
LQG one, ``u = F x_hat`` with the filter ``x_hat' = A x_hat + B2 u + L (C2 x_hat - y)``, ``F``
and ``L`` from the control and filter Riccati equations (Zhou, Doyle & Glover, *Robust and
Optimal Control*, 1996, Thm 14.7; the test suite solves them with
:func:`scipy.linalg.solve_continuous_are` and compares the controllers).

The weight ``rho`` on the acceleration is the design's one knob: for the translational
channels the smallest ``rho`` (bisection in log) whose channel meets the target with
:data:`~microg.isolation.active.controller.DESIGN_MARGIN` to spare, capped by the largest
``rho`` whose loop (broken at the actuator) keeps the margins
(:data:`~microg.isolation.active.controller.PM_MIN_DEG`, ``GM_MIN``) and by the plant's
``max_loop_hz`` (the loop's gain crossover); rotational channels take the translational
channels' least ``rho`` within their own margin cap.  The channels are assembled with the mass
matrix, ``u = M [K_0 y_0, ..., K_5 y_5]``; when the coupled (6-DOF) closed loop is unstable, every
cap is divided by 4 and the channels are designed again.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.errors import InputError
from microg.isolation.active.controller import (
    DESIGN_MARGIN,
    GM_MIN,
    PM_MIN_DEG,
    Controller,
)
from microg.isolation.active.margins import loop_margin_values
from microg.isolation.active.plant import DOF_NAMES, ActivePlant, gain
from microg.units import G0

if TYPE_CHECKING:
    from microg.isolation.active.target import Target

__all__ = ["design_h2", "channel_plant", "h2_channel", "SIGMA_BASE", "RHO_RANGE"]

#: base-acceleration level of the synthesis (white), m/s^2/sqrt(Hz): a design weight (an
#: illustrative ISS vibratory level, 1e-5 g/sqrt(Hz)); only its ratio to the noises matters
SIGMA_BASE = 1e-5 * G0
#: least accelerometer and position noise of the synthesis relative to their scales (keeps the
#: filter Riccati equation well conditioned when a sensor is given as noiseless)
#: (found by a sweep on the ARIS preset: lower floors give LQG loops without margins, the
#: controller then leaning on the exact position signal to cancel the umbilical)
NOISE_FLOOR_ACCEL = 0.03 * SIGMA_BASE
NOISE_FLOOR_POSITION_M = 1e-3
#: the acceleration weights scanned (log grid, 4 per decade)
RHO_RANGE = (1e2, 1e7)
RHO_PER_DECADE = 4
#: further choices of weight tried when the coupled loop falls short of the margins
COUPLED_TRIES = 4
#: frequencies of the channel loops' margins, rad/s
_OMEGA = 2 * math.pi * np.geomspace(1e-6, 2e4, 1500)


def _slycot() -> None:
    try:
        import slycot  # noqa: F401
    except ImportError:
        raise InputError(
            "the H2 design needs slycot: install the 'h2' extra (pip install 'microg[h2]')",
            where="controller",
            fix="install microg[h2], or use --controller designed",
        ) from None


def _weight(target: Target, plant: ActivePlant) -> Any:
    """``W(s)``: unit band-pass over the target's constrained span (first order each side)."""
    import control as ct

    lo = float(np.min(target.lo_hz))
    hi = float(min(np.max(target.hi_hz), 0.2 * plant.sample_rate_hz))
    wl, wh = 2 * math.pi * lo, 2 * math.pi * max(hi, lo)
    # s wh / ((s + wl)(s + wh)): ~1 between wl and wh
    return ct.ss(ct.tf([wh, 0.0], [1.0, wl + wh, wl * wh]))


def channel_plant(
    plant: ActivePlant, i: int, rho: float, weight: Any, pade_order: int = 3
) -> tuple[Any, Any]:
    """(synthesis plant, analysis plant) of channel ``i`` (module docstring).

    Synthesis: inputs ``[w0, wa, wp, v]``, outputs ``[z1, z2, z3, y1, y2]``.  Analysis: the
    same inputs, outputs ``[a, q, v, y1, y2]`` in SI per unit mass (``a`` and ``v`` m/s^2 or
    rad/s^2, ``q`` m or rad) with ``w0`` scaled to the base acceleration itself (``a0 = w0``).

    Parameters
    ----------
    plant : the plant
    i : channel (0-5: x, y, z, rx, ry, rz)
    rho : weight of the platform acceleration
    weight : ``W(s)``, SISO ``control.StateSpace`` (strictly proper)
    pade_order : order of the delay's Pade approximant
    """
    import control as ct

    if not math.isfinite(plant.accel_bandwidth_hz):
        raise InputError(
            "the H2 design needs a finite accelerometer bandwidth", where="accel-bandwidth"
        )
    k, c = plant.channel(i)
    mii = float(plant.mass_matrix()[i, i])
    stroke, force = (v[i] for v in plant.limits())
    # body: [a0, v_applied] -> [a, q]
    body = ct.ss([[0.0, 1.0], [-k, -c]], [[0.0, 0.0], [-1.0, 1.0]], [[-k, -c], [1.0, 0.0]],
                 [[0.0, 1.0], [0.0, 0.0]])  # fmt: skip
    tau = plant.effective_delay_s
    if tau > 0 and pade_order > 0:
        dly1 = ct.ss(ct.tf(*ct.pade(tau, pade_order)))
    else:
        dly1 = gain(np.eye(1))
    wb = 2 * math.pi * plant.accel_bandwidth_hz
    filt = ct.ss(
        [[0.0, 1.0], [-(wb**2), -math.sqrt(2.0) * wb]], [[0.0], [wb**2]], [[1.0, 0.0]], [[0.0]]
    )
    sa = max(math.sqrt(plant.accel_noise_psd), NOISE_FLOOR_ACCEL)
    sp = max(math.sqrt(plant.position_noise_psd), NOISE_FLOOR_POSITION_M)
    fan = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 0.0], [0.0, 1.0]])  # [a, q] -> [a, q, a, q]

    def build(a0_scale: float, z_blocks: Any, v_scale: float, sa: float, sp: float) -> Any:
        core = (
            ct.append(z_blocks, filt, gain(np.eye(1)))
            * gain(fan)
            * body
            * ct.append(gain(np.array([[a0_scale]])), dly1)
            * gain(np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]))
        )  # [w0, wa, wp, v] -> [z(a), z(q), H a, q] (the noises and v's own row added below)
        place = np.zeros((5, 4))
        place[[0, 1, 3, 4], [0, 1, 2, 3]] = 1.0
        direct = np.zeros((5, 4))
        direct[2, 3] = v_scale
        direct[3, 1] = sa
        direct[4, 2] = sp
        return gain(place) * core + gain(direct)

    synth = _balanced(
        # z divided by rho and w by SIGMA_BASE: the same optimal controller (the H2 norm scales
        # by a constant), with the Riccati equations' data near unity
        build(
            1.0,
            ct.append(weight, gain(np.array([[1.0 / (rho * stroke)]]))),
            mii / (rho * force),
            sa / SIGMA_BASE,
            sp / SIGMA_BASE,
        )
    )
    analysis = _balanced(build(1.0, gain(np.eye(2)), 1.0, sa, sp))
    return synth, analysis


def _balanced(system: Any) -> Any:
    """``system`` under the diagonal similarity that balances its ``A`` (same transfer).

    The Pade approximant's and the filter's companion forms put entries of ~1e8 beside ~1e-2
    (cond(A) ~ 1e15); :func:`scipy.linalg.matrix_balance` (powers of 2, exact) brings the
    rows and columns to comparable norms, which the Riccati solvers of the synthesis need.
    """
    import control as ct
    from scipy.linalg import matrix_balance

    if system.nstates == 0:
        return system
    _, (scale, _) = matrix_balance(system.A, permute=False, separate=True)
    t = np.diag(scale)
    tinv = np.diag(1.0 / scale)
    return ct.ss(tinv @ system.A @ t, tinv @ system.B, system.C @ t, system.D)


def h2_channel(plant: ActivePlant, i: int, rho: float, weight: Any, pade_order: int = 3) -> Any:
    """Channel ``i``'s H2 controller ``[y1, y2] -> v`` (``control.h2syn``), ``control.StateSpace``.

    Parameters: as :func:`channel_plant`.
    """
    import control as ct

    synth, _ = channel_plant(plant, i, rho, weight, pade_order)
    try:
        return ct.h2syn(synth, 2, 1)
    except Exception as exc:  # slycot reports a failed Riccati solution as an error
        raise InputError(
            f"the H2 synthesis of channel {DOF_NAMES[i]} failed ({type(exc).__name__}: {exc})",
            where="controller",
            fix="use --controller designed",
        ) from None


def _channel_checks(
    plant: ActivePlant, i: int, k: Any, pade_order: int, target: Target | None
) -> tuple[bool, float, float]:
    """(margins kept with the crossover within max_loop_hz, worst target ratio, phase margin)."""
    import control as ct

    from microg.isolation.active.fresp import freq_response

    _, an = channel_plant(plant, i, 1.0, gain(np.eye(1)), pade_order)
    cl = an.lft(k, nu=1, ny=2)  # [w0, wa, wp] -> [a, q, v]
    if cl.nstates and np.max(np.linalg.eigvals(cl.A).real) >= 0:
        return False, math.inf, 0.0
    p_yu = gain(np.eye(5)[3:]) * an * gain(np.eye(4)[:, 3:])
    loop = -(k * p_yu)
    gm, pm, wgc, _ = loop_margin_values(loop, _OMEGA)
    ok = abs(math.log(gm)) >= math.log(GM_MIN) and pm >= PM_MIN_DEG
    if wgc is not None and wgc > 2 * math.pi * plant.max_loop_hz:
        ok = False
    ratio = 0.0
    if target is not None:
        f = target.check_freq_hz()
        lim = target.limit(f)
        fin = np.isfinite(lim)
        t = np.abs(freq_response(ct.ss(cl.A, cl.B[:, :1], cl.C[:1], cl.D[:1, :1]), f)[0, 0])
        ratio = float(np.max(t[fin] / lim[fin])) if fin.any() else 0.0
    return ok, ratio, pm


def design_h2(plant: ActivePlant, target: Target, *, pade_order: int = 3) -> Controller:
    """H2 controller per decoupled axis designed to ``target`` (module docstring).

    Parameters
    ----------
    plant : the plant
    target : the transmissibility target (translational channels)
    pade_order : order of the delay's Pade approximant in the design model
    """
    _slycot()
    from microg.isolation.active import verify

    weight = _weight(target, plant)
    lo, hi = RHO_RANGE
    grid = np.geomspace(lo, hi, int(round(RHO_PER_DECADE * math.log10(hi / lo))) + 1)
    # every channel's scan: (rho, margins kept, target ratio) for the weights synthesised
    scans: list[list[tuple[float, bool, float, float]]] = []
    done: dict[tuple[float, ...], list[tuple[float, bool, float, float]]] = {}
    for i in range(6):
        # channels alike (same k, c, mass, limits: the axes of a symmetric umbilical) share a scan
        sig = (
            *plant.channel(i),
            plant.mass_matrix()[i, i],
            *(v[i] for v in plant.limits()),
            i // 3,
        )
        if sig in done:
            scans.append(done[sig])
            continue
        rows = []
        for r in grid:
            try:
                k = h2_channel(plant, i, float(r), weight, pade_order)
            except InputError:
                continue
            ok, ratio, pm = _channel_checks(plant, i, k, pade_order, target if i < 3 else None)
            rows.append((float(r), ok, ratio, pm))
        done[sig] = rows
        if not any(row[1] for row in rows):
            raise InputError(
                f"no H2 design of channel {DOF_NAMES[i]} keeps {PM_MIN_DEG:g} deg of phase and "
                f"{20 * math.log10(GM_MIN):.0f} dB of gain margin within max_loop_hz = "
                f"{plant.max_loop_hz:g} Hz",
                where="controller",
                fix="raise the sampling rate or the accelerometer bandwidth, shorten the delay, "
                "or use --controller designed",
            )
        scans.append(rows)
    notes: list[str] = []
    rhos = np.zeros(6)
    for i in range(3):
        good = [(r, ratio) for r, ok, ratio, _ in scans[i] if ok]
        meets = [r for r, ratio in good if ratio <= DESIGN_MARGIN]
        if meets:
            rhos[i] = min(meets)  # the least weight meeting the target: least force and stroke
        else:
            rhos[i], worst = min(good, key=lambda g: g[1])
            notes.append(
                f"channel {DOF_NAMES[i]}: the target is out of reach with the margins kept "
                f"(best |T| / allowed = {worst:.3g}): the umbilical's path binds"
            )
    # candidates per channel, best first: translations by the weight chosen above then the
    # larger weights that also meet the target; rotations by phase margin
    cands: list[list[float]] = []
    for i in range(6):
        good_rows = [row for row in scans[i] if row[1]]
        if i < 3:
            rest = [row[0] for row in good_rows if row[0] > rhos[i] and row[2] <= DESIGN_MARGIN]
            cands.append([float(rhos[i]), *rest])
        else:
            cands.append([row[0] for row in sorted(good_rows, key=lambda row: -row[3])])

    pick = [0] * 6
    best: tuple[float, np.ndarray, Any] | None = None  # (least phase margin, rhos, system)
    for attempt in range(COUPLED_TRIES + 1):
        rhos = np.array([cands[i][min(pick[i], len(cands[i]) - 1)] for i in range(6)])
        ks = [h2_channel(plant, i, float(rhos[i]), weight, pade_order) for i in range(6)]
        trial = Controller("h2", assemble(plant, ks))
        stable = verify.poles_stable(verify.closed_loop(plant, trial, pade_order=pade_order))[0]
        short = list(range(6))
        if stable:
            ms, _ = verify.loop_margins(plant, trial, pade_order=pade_order)
            short = [
                j
                for j, m in enumerate(ms)
                if m.phase_margin_deg < PM_MIN_DEG or m.gain_margin_factor < GM_MIN
            ]
            least = min(m.phase_margin_deg for m in ms)
            if best is None or least > best[0]:
                best = (least, rhos, trial.system)
        if not short:
            if attempt:
                notes.append(
                    f"the coupled (6-DOF) loop needed {attempt} other choice(s) of weight to keep "
                    "the margins"
                )
            break
        # the next candidate for every loop that falls short in the coupled loop
        for j in short:
            pick[j] += 1
    else:
        if best is not None:
            rhos, trial = best[1], Controller("h2", best[2])
        notes.append(
            "the coupled (6-DOF) loop falls short of the margins for every weight tried (kept: "
            "the choice with the largest least phase margin)"
        )
    ctrl = Controller(
        "h2",
        trial.system,
        None,
        None,
        (
            "H2 per decoupled axis (control.h2syn), the least acceleration weight rho meeting "
            f"the target with {DESIGN_MARGIN:g} to spare and the margins kept: "
            + ", ".join(f"{n} {r:.3g}" for n, r in zip(DOF_NAMES, rhos, strict=True)),
            *notes,
        ),
    )
    return ctrl


def assemble(plant: ActivePlant, channels: list[Any]) -> Any:
    """``u = M [K_0 (a_m0, q_m0), ..., K_5 (a_m5, q_m5)]``: (12 -> 6) ``control.StateSpace``.

    Parameters
    ----------
    plant : the plant (its mass matrix)
    channels : six SISO-output controllers ``[a_m_i, q_m_i] -> v_i``
    """
    import control as ct

    perm = np.zeros((12, 12))
    for i in range(6):
        perm[2 * i, i] = 1.0
        perm[2 * i + 1, 6 + i] = 1.0
    return gain(plant.mass_matrix()) * ct.append(*channels) * gain(perm)
