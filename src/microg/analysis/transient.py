"""The main job's transient regime: disturbances to modal loads, exact response, assessment.

The disturbances become scalar modal loads (:func:`modal_loads`, refusing a force that does no
work on the model); the modes in the response, the record and the damping are checked once
here; then one call of :func:`microg.dynamics.superposition.superpose` gives the exact
response, the certified peaks and the modal accelerations at them, and each observed point is
assessed against the requirement (the peak replaced by the certified one, the worst
:data:`~microg.analysis.options.REQUIREMENT_INTERVAL_S` interval, the modes' contributions)
and, where it does not comply, given isolation advice (:func:`transient`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from microg._vectors import axis_name
from microg.analysis.contributions import ModalSeries, mode_contributions
from microg.analysis.options import REQUIREMENT_INTERVAL_S, AnalysisOptions, Disturbance
from microg.analysis.result import Observation
from microg.dynamics.forces import ForceHistory
from microg.dynamics.modes import Modes
from microg.dynamics.peaks import PeakResponse
from microg.dynamics.response import generalized_force_vector
from microg.dynamics.superposition import ModalLoad, superpose
from microg.environment.metrics import Assessment, assess
from microg.environment.requirements import Requirement
from microg.errors import InputError
from microg.isolation.advise import IsolationAdvice, advise_isolation
from microg.structure.structure import Structure

__all__ = ["check_modes_used", "modal_loads", "transient"]


def check_modes_used(
    modes: Modes, elastic: np.ndarray, used: np.ndarray, max_freq_hz: float
) -> list[str]:
    """Refuse a transient response without any mode; warn when it holds no elastic mode.

    Without rigid modes (a clamped or imported model whose modes all lie above
    ``max_freq_hz``) the response would be identically zero and the verdict a green
    "complies" that no number supports.
    """
    el_freq = modes.freq_hz[elastic]
    lowest = float(el_freq.min()) if el_freq.size else float("nan")
    if not np.any(used):
        raise InputError(
            f"no mode enters the response: the model has no rigid-body mode and its lowest "
            f"mode ({lowest:.4g} Hz) is above max_freq = {max_freq_hz:g} Hz, so the response "
            "would be zero",
            where="max_freq",
            fix=f"raise max_freq above {lowest:.4g} Hz (and dt to resolve it)",
        )
    if el_freq.size and not np.any(used & elastic):
        return [
            f"no elastic mode below max_freq = {max_freq_hz:g} Hz (the lowest is "
            f"{lowest:.4g} Hz): the response is the rigid-body motion alone"
        ]
    return []


def transient(
    structure: Structure,
    modes: Modes,
    used: np.ndarray,
    opts: AnalysisOptions,
    req: Requirement,
    step: Callable[[str], None],
) -> tuple[dict[str, Observation], np.ndarray, list[str]]:
    """The transient regime: exact response, assessment, exact peaks, isolation advice."""
    warnings: list[str] = []
    if np.any(np.asarray(modes.unstable, bool)):
        unstable = np.asarray(modes.unstable, bool)
        growth = np.asarray(modes.growth_rate, float)
        k = int(np.flatnonzero(unstable)[0])
        note = next((n for n in modes.notes if "unstable" in n), "")
        raise InputError(
            f"mode {k + 1} is unstable (growth rate {growth[k]:.3g} rad/s): the "
            f"transient response grows without bound, so no verdict can be drawn. {note}",
            where="gravity_gradient",
            fix="analyse the free-free structure (no gravity gradient), or correct the inertias",
        )
    maps = {name: structure.point(name).translation for name in opts.observe}
    if structure.is_sparse and not modes.rigid[-1] and modes.freq_hz[-1] <= opts.max_freq_hz:
        warnings.append(
            f"only {modes.n_modes} modes computed; the highest ({modes.freq_hz[-1]:.3g} Hz) is "
            f"below max_freq {opts.max_freq_hz:g} Hz: modes between are missing from the response"
        )
    idx = np.flatnonzero(used)
    m = modes.subset(idx)
    nyquist = 0.5 / opts.dt_s
    f_top = float(np.max(m.freq_hz, initial=0.0))
    if f_top >= nyquist:
        raise InputError(
            f"dt = {opts.dt_s:g} s samples at {1 / opts.dt_s:g} Hz, too coarse for the modes in "
            f"the response (up to {f_top:.3g} Hz, above the {nyquist:.3g}-Hz Nyquist frequency): "
            "the spectrum and the band verdict would be aliased",
            where="dt",
            fix=f"use dt <= {0.25 / f_top:.3g} s, or max_freq below {nyquist:.3g} Hz",
        )
    if f_top > 0.5 * nyquist:
        warnings.append(
            f"the highest mode in the response ({f_top:.3g} Hz) is above half the Nyquist "
            f"frequency ({nyquist:.3g} Hz): fewer than 4 samples per period; bands near Nyquist "
            "are approximate"
        )
    warnings += _force_warnings(opts)
    zeta = np.where(m.rigid, 0.0, opts.zeta)
    loads, w = modal_loads(structure, m, opts)
    warnings += w
    step("response")
    t = np.arange(0.0, opts.duration_s + 0.5 * opts.dt_s, opts.dt_s)
    names = list(maps)
    # every point's rows in one product per series (one GEMM, not one per point)
    rows = [tmap @ m.phi for tmap in maps.values()]
    tphi_all = np.concatenate(rows) if rows else np.zeros((0, m.n_modes))
    sup = superpose(m.omega, zeta, loads, t, names, tphi_all)
    step("assessment")
    mode_numbers = idx + 1
    modal = ModalSeries(t, sup.modal_accel)

    def observe(j: int, name: str) -> Observation:
        r = slice(3 * j, 3 * j + 3)
        tphi = tphi_all[r]
        resp = sup.points[name]
        peak = sup.peaks[name]
        a = _with_exact_peak(assess(t, resp.acceleration, req), peak, req)
        return Observation(
            name=name,
            response=resp,
            assessment=a,
            isolation=IsolationAdvice.not_assessed(name),
            contributions=mode_contributions(
                mode_numbers, m, tphi, modal, a, sup.modal_accel_at_peak[:, j]
            ),
            interval=_intervals(t, resp.acceleration, req),
            peak=peak,
        )

    def isolate(ob: Observation) -> Observation:
        adv = advise_isolation(
            ob.name,
            ob.assessment,
            ob.response,
            req,
            package_mass=opts.package_mass_kg,
            absorber_mu=opts.absorber_mu,
            sources=mount_sources,
        )
        return replace(ob, isolation=adv)

    obs = [observe(j, name) for j, name in enumerate(names)]
    step("isolation")
    mount_sources = None
    if opts.sources is not None:
        from microg.isolation.active.sourcecheck import MountSources

        # the active check (when one is made) verifies the platform on the sources too, with
        # every mode, as the frequency-domain block does
        mount_sources = MountSources(modes, opts.sources, np.where(modes.rigid, 0.0, opts.zeta))
    if opts.isolation:
        obs = [isolate(ob) for ob in obs]
    observations = {ob.name: ob for ob in obs}
    return observations, t, warnings


def _force_warnings(opts: AnalysisOptions) -> list[str]:
    out = []
    for d in opts.disturbances:
        f = d.force
        vec = f.components(d.unit_direction)
        last = float(np.linalg.norm(vec[:, -1]))
        peak = float(np.max(np.linalg.norm(vec, axis=0)))
        if peak > 0 and abs(last) > 1e-9 * peak:
            impulse = f.impulse() + last * (opts.duration_s - f.timepts[-1])
            out.append(
                f"force {f.name!r} does not end at zero: it holds {last:.4g} N from "
                f"{f.timepts[-1]:g} s to the end of the record ({opts.duration_s:g} s); its "
                f"impulse over the record is {impulse:.4g}"
                " N s, and the station keeps accelerating (a quasi-steady load, not a transient)"
            )
    return out


def _scalar_parts(d: Disturbance) -> list[tuple[ForceHistory, np.ndarray]]:
    """A disturbance as scalar histories along fixed unit vectors.

    A scalar force is one history along its direction; a vector force (three components per
    breakpoint, a direction that varies in time) is its x, y and z components along the
    axes -- linear, so the response is their sum.
    """
    if not d.force.is_vector:
        return [(d.force, d.unit_direction)]
    vec = d.force.components()
    parts = []
    for i, axis in enumerate("xyz"):
        if np.any(vec[i]):
            comp = ForceHistory(d.force.timepts, vec[i], f"{d.force.name} ({axis})")
            parts.append((comp, np.eye(3)[i]))
    return parts


def modal_loads(
    structure: Structure, modes: Modes, opts: AnalysisOptions
) -> tuple[list[ModalLoad], list[str]]:
    """The scalar loads of every disturbance; refuse a force that does no work."""
    loads: list[ModalLoad] = []
    warnings = []
    for i, d in enumerate(opts.disturbances):
        tmap = structure.point(d.point).translation
        where = "direction" if len(opts.disturbances) == 1 else f"direction[{i}]"
        plane = f" of the planar {structure.plane} model" if structure.plane else ""
        worked = False
        for f, u in _scalar_parts(d):
            b = generalized_force_vector(tmap, u)
            # the part of the force the model can carry: its projection on the point's motion
            reach = np.linalg.norm(tmap @ np.linalg.pinv(tmap) @ u) if tmap.size else 0.0
            if not np.any(b) or reach < 1e-9:
                if not d.force.is_vector:
                    raise InputError(
                        f"a force along {axis_name(u) or list(np.round(u, 6))} at {d.point!r} "
                        f"does no work on the model{plane}: the response would be zero",
                        where=where,
                        fix="give a direction the model can move in"
                        + (" (in the model's plane), or use the 3-D model" if plane else ""),
                    )
                warnings.append(f"{f.name} at {d.point!r} does no work on the model{plane}")
                continue
            if reach < 1 - 1e-9:
                inplane = f" (its plane is {structure.plane})" if structure.plane else ""
                warnings.append(
                    f"only {100 * reach:.3g}% of the force {f.name!r} at {d.point!r} acts on "
                    f"the model{inplane}; the rest is dropped"
                )
            loads.append(ModalLoad(f, modes.phi.T @ b))
            worked = True
        if not worked:
            raise InputError(
                f"the force {d.force.name!r} at {d.point!r} does no work on the model{plane}",
                where=where,
                fix="give a force the model can carry",
            )
    return loads, warnings


def _with_exact_peak(a: Assessment, peak: PeakResponse, req: Requirement) -> Assessment:
    """The assessment with its peaks replaced by the certified exact ones.

    The exact peak is at least the sampled one, so a verdict that passed a peak limit on the
    samples is re-judged on the exact value.
    """
    exact = float(peak.peak_accel_g)
    complies = a.complies
    if req.peak_limit_g is not None and exact > req.peak_limit_g:
        complies = False
    return replace(
        a,
        peak_accel_g=exact,
        peak_accel_g_axis=np.asarray(peak.peak_accel_g_axis, float),
        complies=complies,
    )


def _intervals(t: np.ndarray, accel: np.ndarray, req: Requirement) -> dict[str, Any]:
    """Worst band margin over consecutive intervals of REQUIREMENT_INTERVAL_S (PIMS practice).

    Uses :func:`microg.environment.intervals.interval_band_rms`; only bands one interval
    resolves are judged.
    """
    from microg.environment.intervals import interval_band_rms

    length = REQUIREMENT_INTERVAL_S
    if t.size * (t[1] - t[0]) < length:
        return {"interval_s": length, "count": 0, "min_margin": None, "worst_start_s": None}
    b = interval_band_rms(t, accel, req, interval_s=length)
    lim = b.limit_g[None, None, :]
    with np.errstate(divide="ignore"):
        margin = np.where(b.rms_g > 0, lim / np.where(b.rms_g > 0, b.rms_g, 1.0), np.inf)
    margin = np.where(b.resolved[None, None, :], margin, np.inf)
    per_interval = margin.min(axis=(1, 2))
    i = int(np.argmin(per_interval))
    worst = float(per_interval[i])
    return {
        "interval_s": length,
        "count": int(per_interval.size),
        "min_margin": worst if np.isfinite(worst) else "inf",
        "worst_start_s": float(b.t_start_s[i]),
        "judged_bands_hz": [float(c) for c in b.bands.center_hz[b.resolved]],
    }
