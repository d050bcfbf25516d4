"""``design_active``: design an active isolator to a target and verify it (the one entry point).

The plant (a preset's or the caller's), the controller (:mod:`~microg.isolation.active.
controller`), then every check of :mod:`~microg.isolation.active.verify`: poles of the
continuous and sampled closed loops, margins per loop, transmissibility against the target, the
direct-disturbance response, the sensors' noise floor against the requirement's bands, and,
given the station's acceleration at the mount point, the time-domain response through the
closed loop (stroke and force against their limits, the band verdict with the noise floor
added in quadrature) beside the frequency-domain path of the same record
(``S_out,i = sum_j |T_ij|^2 S_j``, axes taken as uncorrelated), and, given the station's
vibratory sources (:class:`~microg.isolation.active.sourcecheck.MountSources`), their band
table and verdict at the mount point through the closed loop
(:mod:`~microg.isolation.active.sourcecheck`).

A design's **binding limit** is the first exceeded of: ``umbilical`` (the target is not met:
the umbilicals' path, attenuated by all the loop gain the sensors, the delay and the platform
allow, still transmits too much), ``rattlespace`` (the stroke exceeds the rattlespace or the
position sensors' range), ``actuator_force`` (the force or torque exceeds the actuators'),
``sensor_noise`` (the noise floor alone exceeds the requirement in a band).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from microg import defaults
from microg.errors import InputError
from microg.isolation.active import verify
from microg.isolation.active.controller import (
    CONTROLLERS,
    Controller,
    design_feedback,
    no_controller,
)
from microg.isolation.active.plant import ActivePlant
from microg.isolation.active.result import ActiveIsolation, TimeCheck
from microg.isolation.active.sourcecheck import MountSources, sources_check
from microg.isolation.active.target import (
    F_TOP_HZ,
    PASS_LEVEL,
    Target,
    band_target,
    target_by_name,
)
from microg.units import G0

__all__ = ["design_active", "default_freq_hz"]


def default_freq_hz(plant: ActivePlant, target: Target, n: int = 500) -> np.ndarray:
    """Curves' frequencies, Hz: 1e-4 Hz to min(300 Hz, 0.45 fs), with the target's checks."""
    top = min(F_TOP_HZ, 0.45 * plant.sample_rate_hz)
    f = np.geomspace(1e-4, top, n)
    chk = target.check_freq_hz()
    return np.unique(np.concatenate([f, chk[chk <= top]]))


def _target(plant: ActivePlant, target: Any, preset_target: str | None) -> Target:
    if target is None:
        return target_by_name(preset_target or "g-limit")
    if isinstance(target, Target):
        return target
    if isinstance(target, str):
        return target_by_name(target)
    if isinstance(target, Mapping):
        att = {float(c): float(v[0] if isinstance(v, tuple) else v) for c, v in target.items()}
        edges = {
            float(c): (float(v[1]), float(v[2]))
            if isinstance(v, tuple)
            else (float(c) * 2 ** (-1 / 6), float(c) * 2 ** (1 / 6))
            for c, v in target.items()
        }
        return band_target(att, edges)
    raise InputError(
        f"unknown target {target!r}", where="target", fix="use g-limit, aris or a band map"
    )


#: a designed controller whose coupled (6-DOF) loop is unstable is designed again with the
#: acceleration loops' ceiling halved, at most this many times
BACK_OFF = 12


def _controller(plant: ActivePlant, kind: str, target: Target, pade_order: int) -> Controller:
    if kind == "designed":
        # the channels are designed one by one; the coupling (centre of mass off the umbilicals'
        # attachment) can destabilise the whole: back off the loop gain until it is stable
        ctrl = design_feedback(plant, target, pade_order=pade_order)
        for _ in range(BACK_OFF):
            if verify.poles_stable(verify.closed_loop(plant, ctrl, pade_order=pade_order))[0]:
                return ctrl
            assert ctrl.omega_a is not None
            ceiling = float(ctrl.omega_a.min()) / (4 * math.pi)
            trial = design_feedback(plant.with_(max_loop_hz=ceiling), target, pade_order=pade_order)
            ctrl = Controller(
                trial.kind,
                trial.system,
                trial.omega_a,
                trial.omega_p,
                (
                    *trial.notes,
                    f"the coupled loop was unstable: loops backed off to {ceiling:.3g} Hz",
                ),
            )
        return ctrl
    if kind == "off":
        return no_controller()
    if kind == "h2":
        from microg.isolation.active.h2 import design_h2

        return design_h2(plant, target, pade_order=pade_order)
    raise InputError(
        f"unknown controller {kind!r}", where="controller", fix=f"use {', '.join(CONTROLLERS)}"
    )


def design_active(
    plant: ActivePlant | str = "aris",
    *,
    target: Target | str | Mapping[float, Any] | None = None,
    controller: str = "designed",
    timepts: np.ndarray | None = None,
    base_accel: np.ndarray | None = None,
    point: str = "mount",
    requirement: Any = defaults.REQUIREMENT,
    freq_hz: np.ndarray | None = None,
    pade_order: int = 3,
    sources: MountSources | None = None,
) -> ActiveIsolation:
    """Design an active isolator and verify it (module docstring).

    Parameters
    ----------
    plant : an :class:`ActivePlant`, or a preset name (``aris``, ``g-limit``)
    target : ``g-limit``, ``aris``, a :class:`Target`, or a map band centre (Hz) -> factor
        (or -> (factor, lower_hz, upper_hz)); default the preset's (``g-limit`` otherwise)
    controller : ``designed`` (acceleration feedback with centring), ``h2`` or ``off``
    timepts : (nt,) equally spaced times of the station's response at the mount point, s
    base_accel : (3, nt) the mount point's acceleration, m/s^2
    point : the mount point's name (for the output)
    requirement : the band requirement (name or object) of the noise and time checks
    freq_hz : frequencies of the curves, Hz (default :func:`default_freq_hz`)
    pade_order : order of the delay's Pade approximant (continuous model)
    sources : the station's modes and vibratory sources; ``point`` must then be a point of
        its model: the sources' band table and verdict on the platform (``result.sources``)
    """
    from microg.environment.metrics import Spectrum, acceleration_psd, assess, band_rms
    from microg.environment.requirements import requirement as requirement_by_name
    from microg.isolation.active.presets import load_preset

    preset_target = None
    if isinstance(plant, str):
        plant, preset_target = load_preset(plant)
    if not isinstance(plant, ActivePlant):
        raise InputError("must be an ActivePlant or a preset name", where="plant")
    if not (isinstance(pade_order, int) and 0 <= pade_order <= 10):
        raise InputError(f"must be an integer 0-10, got {pade_order!r}", where="pade_order")
    tgt = _target(plant, target, preset_target)
    top = float(tgt.hi_hz.max()) if tgt.name != "g-limit" else 10.0
    if 0.5 * plant.sample_rate_hz <= top:
        raise InputError(
            f"{plant.sample_rate_hz:g} Hz samples below the target band (up to {top:g} Hz needs "
            f"more than {2 * top:g} Hz)",
            where="sample-rate",
        )
    req = requirement_by_name(requirement)
    ctrl = _controller(plant, controller, tgt, pade_order)
    notes = list(ctrl.notes)
    cl = verify.closed_loop(plant, ctrl, pade_order=pade_order)
    cl_d = verify.closed_loop(plant, ctrl, discrete=True)
    ok_c, worst_c = verify.poles_stable(cl)
    ok_d, worst_d = verify.poles_stable(cl_d)
    stable = ok_c and ok_d
    if not ok_c:
        notes.append(f"the continuous closed loop is unstable (a pole at Re = {worst_c:.3g} 1/s)")
    if not ok_d:
        notes.append(f"the sampled closed loop is unstable (a pole at |z| = {1 + worst_d:.6g})")
    f = default_freq_hz(plant, tgt) if freq_hz is None else np.asarray(freq_hz, float)
    if f.ndim != 1 or f.size == 0 or np.any(~np.isfinite(f)) or np.any(f <= 0):
        raise InputError("must be finite frequencies > 0", where="freq_hz")
    if ctrl.kind == "off":
        m_c: list[verify.LoopMargin] = []
        m_d: list[verify.LoopMargin] = []
        loop_resp = np.zeros((6, f.size), complex)
    else:
        m_c, loop_resp = verify.loop_margins(plant, ctrl, pade_order=pade_order, freq_hz=f)
        m_d, _ = verify.loop_margins(plant, ctrl, discrete=True)
    off = verify.closed_loop(plant, no_controller(), pade_order=pade_order)
    # the target on its own check frequencies, and a decade below its quasi-steady corner
    fc = tgt.check_freq_hz()
    fq = np.array([] if tgt.pass_below_hz is None else [0.1 * tgt.pass_below_hz])
    # one frequency response of each closed loop's [a0, d] -> a block at every frequency asked
    n_f, n_c = f.size, fc.size
    resp = verify.base_and_disturbance(cl, np.concatenate([f, fc, fq]))
    resp_off = verify.base_and_disturbance(off, f)
    tr, passive = resp[:3, :3, :n_f], resp_off[:3, :3]
    dist = np.abs(np.array([resp[i, 3 + i, :n_f] for i in range(6)]))
    dist_p = np.abs(np.array([resp_off[i, 3 + i] for i in range(6)]))
    bands = req.bands
    npsd, nb_rms = verify.noise_floor(cl, plant, f, bands.lower_hz, bands.upper_hz)
    nb_rms = nb_rms / G0
    lim = tgt.limit(fc)
    tc = np.abs(np.array([resp[i, i, n_f : n_f + n_c] for i in range(3)]))
    fin = np.isfinite(lim)
    ratio = np.max(tc[:, fin] / lim[fin], axis=1) if fin.any() else np.zeros(3)
    passes_qs = None
    if tgt.pass_below_hz is not None:
        tq = np.abs(np.array([resp[i, i, n_f + n_c] for i in range(3)]))
        passes_qs = bool(np.all(tq >= PASS_LEVEL))
    exceeded: list[str] = []
    if not (np.all(ratio <= 1.0) and passes_qs is not False):
        exceeded.append("umbilical")
        worst = int(np.argmax(ratio))
        notes.append(
            f"target {tgt.name} not met: |T_{'xyz'[worst]}| reaches {ratio[worst]:.3g} times the "
            "allowed level (the umbilicals' path, attenuated by the loop gain available)"
            + ("; the quasi-steady acceleration is not passed" if passes_qs is False else "")
        )
    time = None
    stroke_lim, force_lim = plant.limits()
    if (timepts is None) != (base_accel is None):
        raise InputError("give both timepts and base_accel, or neither", where="base_accel")
    if timepts is not None and base_accel is not None:
        t = np.asarray(timepts, float)
        a0 = np.asarray(base_accel, float)
        plat, q, force = verify.time_response(cl, t, a0)
        base_a = assess(t, a0, req)
        iso = assess(t, plat, req)
        spec = acceleration_psd(t, a0)
        s_out = np.einsum(
            "ijf,jf->if", np.abs(verify.transmissibility_matrix(cl, spec.freq_hz)) ** 2, spec.psd
        )
        spectral = band_rms(
            Spectrum(spec.freq_hz, s_out, spec.df_hz, spec.nyquist_hz, spec.method, spec.record_s),
            bands,
        )
        nb = iso.third_octave.center_hz.size
        noise = nb_rms[:, :nb]
        combined = np.sqrt(iso.third_octave.rms_g**2 + noise**2)
        lim_b = iso.third_octave.limit_g
        cmargin = np.min(lim_b[None, :] / np.maximum(combined, 1e-300), axis=0)
        resolved = np.asarray(iso.third_octave.resolved, bool)
        noise_ok = bool(np.all(combined[:, resolved] <= lim_b[resolved]))
        time = TimeCheck(
            point=point,
            timepts=t,
            base_accel=a0,
            platform_accel=plat,
            stroke=q,
            force=force,
            base=base_a,
            isolated=iso,
            spectral_rms_g=spectral.rms / G0,
            noise_rms_g=noise,
            combined_margin=cmargin,
            complies=bool(iso.complies) and noise_ok,
        )
        if np.any(time.peak_stroke > stroke_lim):
            exceeded.append("rattlespace")
            j = int(np.argmax(time.peak_stroke / stroke_lim))
            notes.append(
                f"stroke {time.peak_stroke[j]:.3g} {'m' if j < 3 else 'rad'} on "
                f"{['x', 'y', 'z', 'rx', 'ry', 'rz'][j]} exceeds the limit {stroke_lim[j]:.3g}"
            )
        if np.any(time.peak_force > force_lim):
            exceeded.append("actuator_force")
            j = int(np.argmax(time.peak_force / force_lim))
            notes.append(
                f"actuator {'force' if j < 3 else 'torque'} {time.peak_force[j]:.3g} on "
                f"{['x', 'y', 'z', 'rx', 'ry', 'rz'][j]} exceeds the limit {force_lim[j]:.3g}"
            )
    src_check = None
    if sources is not None:
        src_check = sources_check(cl, sources, point, req, nb_rms)
        if src_check.cross_axis_ratio > 1e-3:
            notes.append(
                f"sources check: cross-axis transmissibility up to {src_check.cross_axis_ratio:.3g}"
                " of the direct one is left out (each axis is weighted by |T_ii|^2)"
            )
    if np.any(nb_rms > req.limit_g[None, :]):
        exceeded.append("sensor_noise")
        j = int(np.argmax(np.max(nb_rms, axis=0) / req.limit_g))
        notes.append(
            f"the sensors' noise floor ({nb_rms[:, j].max():.3g} g) exceeds the requirement in the "
            f"{bands.center_hz[j]:.3g}-Hz band ({req.limit_g[j]:.3g} g)"
        )
    margins = tuple(m_c + m_d)
    result = ActiveIsolation(
        plant=plant,
        controller=ctrl,
        target=tgt,
        stable=stable,
        pole_margin=(worst_c, worst_d),
        margins=margins,
        loop_response=loop_resp,
        freq_hz=f,
        transmissibility=tr,
        passive=passive,
        disturbance=dist,
        disturbance_passive=dist_p,
        noise_psd=npsd,
        noise_center_hz=np.asarray(bands.center_hz, float),
        noise_limit_g=np.asarray(req.limit_g, float),
        noise_band_rms_g=nb_rms,
        target_ratio=ratio,
        passes_quasi_steady=passes_qs,
        time=time,
        sources=src_check,
        meets_target=False,
        binding_limit=exceeded[0] if exceeded else None,
        limits_exceeded=tuple(exceeded),
        notes=tuple(notes),
    )
    meets = stable and (ctrl.kind == "off" or result.margins_kept) and not exceeded
    from dataclasses import replace

    return replace(result, meets_target=bool(meets))
