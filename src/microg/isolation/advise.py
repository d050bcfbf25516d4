"""Isolation advice for a point that does not comply: the policy, as structured data.

The policy, in order:

Each status follows from the assessment's criteria (:attr:`Assessment.criteria
<microg.environment.assessment.Assessment.criteria>`):

1. A point that complies needs nothing (``status = "not-needed"``); the note names any
   reported-only criterion exceeded (it does not enter the verdict).
2. No resolved band exceeds, but the record cannot decide: no band resolved, or unresolved
   bands whose estimates exceed their limits (``"undecided"``): the note says what record
   would decide; no mount is sized from bands the record does not resolve.
3. No resolved band exceeds and the requirement's own peak limit is exceeded
   (``"peak-only"``): a passive mount cannot help a transient's peak without its spectrum.
   A verified transient criterion exceeded, no band and no peak limit exceeded
   (``"transient-only"``): likewise.
4. Otherwise the exceeding bands give the attenuation needed, band by band (1 / margin).  The
   report's rule (Section 4.2, :func:`~microg.isolation.design.design_mount`) sizes a mount for
   ``M_a <= target`` over the exceeding band; its undamped resonance is excited by a transient
   below that band, so spring-damper mounts are also screened on the whole spectrum
   (:func:`~microg.isolation.mount.search_mount`).  The screened choice (or, when none
   complies, the report-rule design) is verified with the exact time-domain response of the
   package (:func:`~microg.isolation.timedomain.package_response`).
5. A mount is **recommended** only when that time-domain check complies and the record can
   see the mount's resonance (its natural frequency lies in a band the record resolves;
   otherwise the advice names the record length needed) (``"passive-mount"``).  Otherwise no
   passive mount in the screen complies (``"no-passive-mount"``): the advice says so, gives
   the attenuation needed per band, and that active isolation is needed.  A design that
   fails its own check is never recommended.
6. When no passive mount is recommended, the default active isolator (the ``aris`` preset,
   :func:`~microg.isolation.active.design.design_active`) is designed for the attenuation
   asked per band and verified on the same response: stable, margins kept, the platform's
   band verdict (sensor noise included) compliant, stroke and force within their limits.  Only
   then is the status ``"active-recommended"``; otherwise it stays ``"no-passive-mount"`` (or
   ``"no-design"``) and the note says which limit binds.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._json import json_number
from microg.errors import InputError
from microg.units import IN, LBF

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from microg.dynamics.response import PointResponse
    from microg.environment.metrics import Assessment
    from microg.environment.requirements import Requirement
    from microg.isolation.active.result import ActiveIsolation
    from microg.isolation.design import MountDesign
    from microg.isolation.mount import MountChoice

__all__ = ["IsolationAdvice", "advise_isolation", "STATUSES"]

#: the advice's possible outcomes
STATUSES = (
    "not-assessed",
    "not-needed",
    "undecided",
    "peak-only",
    "transient-only",
    "passive-mount",
    "no-passive-mount",
    "no-design",
    "active-recommended",
)

#: the active isolator the advice designs when no passive mount is recommended
ACTIVE_PRESET = "aris"


@dataclass(frozen=True)
class IsolationAdvice:
    """Isolation advice for one observed point.

    Attributes
    ----------
    point : str
    status : str
        One of :data:`STATUSES`.
    attenuation_needed : dict of float to float
        Exceeding band centre (Hz) -> factor by which that band must be attenuated
        (1 / margin, > 1).
    band_hz : tuple of float or None
        Lowest and highest edges of the exceeding bands, Hz.
    target_ma : float or None
        Largest acceleration magnification that brings every exceeding band to its limit.
    design : MountDesign or None
        The report's rule (Sec. 4.2) over the exceeding band.
    mount : MountChoice or None
        The whole-spectrum screen of spring-damper mounts.
    verified : str or None
        Which mount the time-domain check ran on: ``"screened"`` or ``"report-rule"``.
    isolated : Assessment or None
        The package's acceleration on the verified mount, against the same requirement.
    package_accel : ndarray (3, nt) or None
        What the isolated package feels, m/s^2.
    peak_stroke_m : float or None
        Largest package motion relative to the mount (rattle space), m.
    verifiable : bool
        The verified mount's natural frequency lies in the bands the record resolves, so the
        time-domain check can see its resonance.
    recommended : bool
        True only when the verified (passive) mount complies in the time domain and is
        verifiable.
    active : ActiveIsolation or None
        The default active isolator designed and verified when no passive mount is
        recommended (None otherwise, or when its design was refused: see the note).
    note : str
        One-paragraph summary of the above.
    """

    point: str
    status: str
    attenuation_needed: dict[float, float] = field(default_factory=dict)
    band_hz: tuple[float, float] | None = None
    target_ma: float | None = None
    design: MountDesign | None = None
    mount: MountChoice | None = None
    verified: str | None = None
    isolated: Assessment | None = None
    package_accel: np.ndarray | None = None
    peak_stroke_m: float | None = None
    verifiable: bool = False
    recommended: bool = False
    active: ActiveIsolation | None = None
    note: str = ""

    @property
    def needed(self) -> bool:
        """True when the point does not comply."""
        return self.status not in ("not-needed", "not-assessed")

    @classmethod
    def not_assessed(cls, point: str) -> IsolationAdvice:
        """Advice placeholder when isolation is not asked for."""
        return cls(point, "not-assessed", note="isolation not assessed")

    def freq_hz(self) -> np.ndarray:
        """Frequencies for the mounts' curves, Hz.

        The design's and the screened mount's grids joined (empty when neither exists).
        """
        grids = [m.default_freq_hz() for m in (self.design, self.mount) if m is not None]
        return np.unique(np.concatenate(grids)) if grids else np.zeros(0)

    def to_xarray(self) -> Any:
        """Attenuation needed per exceeding band and the mounts' curves, ``xarray.Dataset``.

        Dims ``center_hz`` (exceeding bands: ``attenuation_needed``, and ``required_Ma`` =
        1 / attenuation) and ``freq_hz`` (``design_Ma``: the report-rule design's ``M_a``;
        ``mount_transmissibility``: the screened mount's ``|U1/U0|``), all dimensionless.
        """
        import xarray as xr

        centers = np.array(sorted(self.attenuation_needed), float)
        factor = np.array([self.attenuation_needed[c] for c in sorted(self.attenuation_needed)])
        f = self.freq_hz()
        data: dict[str, Any] = {
            "attenuation_needed": ("center_hz", factor, {"units": "1"}),
            "required_Ma": ("center_hz", 1.0 / factor if factor.size else factor, {"units": "1"}),
        }
        if self.design is not None:
            data["design_Ma"] = ("freq_hz", self.design.magnification(f), {"units": "1"})
        if self.mount is not None:
            t = self.mount.transmissibility(f)
            data["mount_transmissibility"] = ("freq_hz", t, {"units": "1"})
        return xr.Dataset(
            data,
            coords={
                "center_hz": ("center_hz", centers, {"units": "Hz"}),
                "freq_hz": ("freq_hz", f, {"units": "Hz"}),
            },
            attrs={
                "point": self.point,
                "status": self.status,
                "recommended": int(self.recommended),
                "verified": self.verified or "",
            },
        )

    def plot(self, ax: Any = None) -> Figure:
        """Attenuation needed per band against the mounts' curves (``plotting.isolation``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.isolation import plot_isolation_advice

        return plot_isolation_advice(self, ax=ax)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready advice (keys documented in docs/assessment.md)."""
        out: dict[str, Any] = {
            "status": self.status,
            "needed": self.needed,
            "recommended": self.recommended,
            "verifiable_by_record": self.verifiable,
            "note": self.note,
            "band_hz": self.band_hz,
            "target_Ma": self.target_ma,
            "attenuation_needed": [
                {"center_hz": c, "factor": f} for c, f in sorted(self.attenuation_needed.items())
            ],
            "design": None,
            "recommended_mount": None,
            "screened_mount": None,
            "isolated": None,
        }
        if self.active is not None:
            out["active"] = _active_dict(self.active)
        d = self.design
        if d is not None:
            out["design"] = {
                "rule": "report Section 4.2: M_a <= target over the exceeding band",
                "k1_N_per_m": d.k1,
                "k1_lbf_per_in": d.k1_lbf_per_in,
                "omega_n": d.omega_n,
                "natural_freq_hz": d.freq_hz_n,
                "achieved_Ma": d.achieved_Ma,
                "sag_1g_m": d.sag_1g,
                "mu": d.mu,
                "absorber_k": d.k,
            }
        mc = self.mount
        if mc is not None:
            screened = mc.to_dict()
            out["screened_mount"] = screened
            if self.recommended and self.verified == "screened":
                out["recommended_mount"] = screened
        if self.recommended and self.verified == "report-rule" and out["design"] is not None:
            out["recommended_mount"] = {"found": True, **out["design"]}
        if self.isolated is not None:
            iso = self.isolated
            wb = iso.worst_band
            out["isolated"] = {
                "verified_mount": self.verified,
                "peak_accel_g": iso.peak_accel_g,
                "rms_accel_g": iso.rms_accel_g,
                "complies": bool(iso.complies),
                "peak_stroke_m": self.peak_stroke_m,
                "worst_band": None
                if wb is None
                else {"center_hz": wb.center_hz, "margin": json_number(wb.margin)},
            }
        return out


def _active_dict(act: ActiveIsolation) -> dict[str, Any]:
    """The ``isolation.active`` block: the verdict, margins, stroke and force of the check."""
    full = act.to_dict()
    cont = [m for m in act.margins if m.model == "continuous"]
    disc = [m for m in act.margins if m.model == "discrete"]

    def least(ms: list[Any]) -> dict[str, Any]:
        if not ms:
            return {"phase_margin_deg": None, "gain_margin_db": None}
        pm = min(m.phase_margin_deg for m in ms)
        gm = min(m.gain_margin_factor for m in ms)
        return {
            "phase_margin_deg": json_number(pm),
            "gain_margin_db": json_number(20 * np.log10(gm)),
        }

    tc = full["time_check"] or {}
    return {
        "complies": bool(act.complies),
        "preset": act.plant.name,
        "controller": act.controller.kind,
        "target": act.target.name,
        "stable": bool(act.stable),
        "margins_kept": bool(act.margins_kept),
        "least_margins": {"continuous": least(cont), "discrete": least(disc)},
        "margins": full["margins"],
        "meets_target": bool(act.meets_target),
        "binding_limit": act.binding_limit,
        "limits_exceeded": list(act.limits_exceeded),
        "stroke_m": full["stroke_m"],
        "stroke_limit_m": full["stroke_limit_m"],
        "force_N": full["force_N"],
        "force_limit_N": full["force_limit_N"],
        "attenuation_at_0_1_hz": full["attenuation_at_0_1_hz"],
        "worst_band": tc.get("worst_band"),
        "sources": full["sources"],
        "notes": list(act.notes),
    }


def _active_check(
    point: str,
    response: PointResponse,
    requirement: Requirement,
    need: dict[float, float],
    edges: dict[float, tuple[float, float]],
    sources: Any = None,
) -> tuple[ActiveIsolation | None, str]:
    """The default active isolator for ``need``, verified on ``response``: (result, sentence)."""
    from microg.isolation.active.design import design_active

    target = {c: (need[c], *edges[c]) for c in need}
    try:
        act = design_active(
            ACTIVE_PRESET,
            target=target,
            timepts=response.timepts,
            base_accel=response.acceleration,
            point=point,
            requirement=requirement,
            sources=sources,
        )
    except InputError as exc:
        return (
            None,
            f"the {ACTIVE_PRESET.upper()}-class active isolator could not be designed ({exc})",
        )  # noqa: E501
    tm = act.time
    stroke = float(tm.peak_stroke[:3].max()) if tm is not None else float("nan")
    force = float(tm.peak_force[:3].max()) if tm is not None else float("nan")
    cont = [m for m in act.margins if m.model == "continuous"]
    pm = min((m.phase_margin_deg for m in cont), default=float("inf"))
    gm = min((m.gain_margin_factor for m in cont), default=float("inf"))
    facts = (
        f"stroke {stroke:.3g} m of {act.plant.limits()[0][0]:.3g} m, force {force:.3g} N of "
        f"{act.plant.limits()[1][0]:.3g} N, phase margin {pm:.3g} deg, gain margin "
        f"{20 * np.log10(gm):.3g} dB"
    )
    if act.complies:
        return act, (
            f"Active isolation recommended: the {ACTIVE_PRESET.upper()}-class isolator "
            f"(acceleration feedback with centring, designed for the attenuation per band) "
            f"complies in the time domain with the sensor noise included ({facts})"
        )
    why = act.binding_limit or (
        "stability"
        if not act.stable
        else "the loop margins"
        if not act.margins_kept
        else "the platform's band verdict"
    )
    return act, (
        f"the {ACTIVE_PRESET.upper()}-class active isolator designed for it does not comply "
        f"either ({why} binds; {facts}): not recommended"
    )


def _without_bands(point: str, assessment: Assessment) -> IsolationAdvice:
    """The advice when no resolved band exceeds: which criterion decides (module doc, 1-3)."""
    crit = assessment.criteria
    reported = [c for c in crit if c.status == "reported" and not c.complies]
    tail = (
        "; reported only (not in the verdict): "
        + ", ".join(f"{c.name} exceeded (margin {c.margin:.3g})" for c in reported)
        if reported
        else ""
    )
    if assessment.complies:
        return IsolationAdvice(
            point, "not-needed", note=f"every judged criterion complies without isolation{tail}"
        )
    undecided = [c for c in crit if c.status == "undecided"]
    failed = [c for c in crit if c.status == "judged" and c.complies is False]
    peak = [c for c in failed if c.name == f"{assessment.requirement} peak"]
    if peak:
        return IsolationAdvice(
            point,
            "peak-only",
            note=f"no resolved band exceeds; the requirement's peak limit is exceeded (margin "
            f"{peak[0].margin:.3g}): a passive mount cannot help a transient's peak without "
            f"knowing its spectrum{tail}",
        )
    if failed:
        names = ", ".join(f"{c.name} (margin {c.margin:.3g})" for c in failed)
        return IsolationAdvice(
            point,
            "transient-only",
            note=f"no resolved band exceeds; the transient criteria {names} are exceeded: a "
            f"passive mount is not sized from a transient criterion{tail}",
        )
    why = "; ".join(c.why for c in undecided)
    return IsolationAdvice(
        point,
        "undecided",
        note=f"no resolved band exceeds, but the record cannot decide ({why}); isolation is "
        f"not sized from bands the record does not resolve{tail}",
    )


def advise_isolation(
    point: str,
    assessment: Assessment,
    response: PointResponse,
    requirement: Requirement,
    *,
    package_mass: float,
    absorber_mu: float | None = None,
    sources: Any = None,
) -> IsolationAdvice:
    """Isolation advice for one point (the policy of the module docstring).

    Parameters
    ----------
    point : str
        Point name.
    assessment : Assessment
        The point's assessment against ``requirement``.
    response : PointResponse
        The point's motion (the mount's base motion), SI.
    requirement : Requirement
    package_mass : float
        Experiment package mass, kg.
    absorber_mu : float, optional
        Absorber mass ratio for the report-rule design.
    sources : MountSources, optional
        The station's modes and vibratory sources: the active isolator's check then includes
        their band verdict on the platform (:mod:`microg.isolation.active.sourcecheck`).
    """
    from microg.environment.metrics import assess
    from microg.isolation.design import design_mount
    from microg.isolation.mount import search_mount
    from microg.isolation.timedomain import IsolatorModel, package_responses

    to = assessment.third_octave
    margin = to.margin.min(axis=0)
    resolved = np.asarray(getattr(to, "resolved", np.ones(margin.shape, bool)), bool)
    bad = np.isfinite(margin) & (margin < 1.0) & resolved
    if assessment.complies or not np.any(bad):
        return _without_bands(point, assessment)
    need = {float(c): float(1.0 / mm) for c, mm in zip(to.center_hz[bad], margin[bad], strict=True)}
    edges = {
        float(c): (float(a), float(b))
        for c, a, b in zip(to.center_hz[bad], to.lower_hz[bad], to.upper_hz[bad], strict=True)
    }
    lo = float(to.lower_hz[bad].min())
    hi = float(to.upper_hz[bad].max())
    target = float(max(margin[bad].min(), 1e-6))
    worst_c = max(need, key=lambda c: need[c])
    base = (
        f"bands {lo:.3g}-{hi:.3g} Hz exceed the requirement; the worst ({worst_c:.3g} Hz) must "
        f"be attenuated {need[worst_c]:.3g}x (M_a <= {target:.3g})"
    )
    try:
        design = design_mount(
            package_mass, (2 * np.pi * lo, 2 * np.pi * hi), min(target, 1.0), mu=absorber_mu
        )
    except InputError as exc:
        act, sentence = _active_check(point, response, requirement, need, edges, sources)
        ok_act = act is not None and act.complies
        return IsolationAdvice(
            point,
            "active-recommended" if ok_act else "no-design",
            attenuation_needed=need,
            band_hz=(lo, hi),
            target_ma=target,
            active=act,
            note=f"{base}; the report's rule gives no passive design ({exc}); {sentence}",
        )
    # a mount resonating below the record's resolved bands cannot be verified by this record:
    # screen only mounts whose natural frequency the verdict can see
    f_floor = float(np.min(to.lower_hz[resolved])) if resolved.any() else float(lo)
    k_floor = package_mass * (2 * np.pi * f_floor) ** 2
    k_max = 10.0 * design.k1
    decades = float(np.clip(np.log10(k_max / k_floor), 0.5, 4.0)) if k_max > k_floor else 0.5
    choice = search_mount(assessment.spectrum, requirement, package_mass, k_max, decades=decades)
    if choice.found:
        mount = IsolatorModel(m1=package_mass, k1=choice.k1, c1=choice.c1)
        verified = "screened"
    else:
        mount = IsolatorModel(
            m1=package_mass,
            k1=design.k1,
            m2=design.m2 or 0.0,
            k2=design.k2 or 0.0,
            c=design.c or 0.0,
        )
        verified = "report-rule"
    runs = package_responses(mount, response.timepts, response.acceleration)
    pkg = np.array([r.package_accel for r in runs])
    isolated = assess(response.timepts, pkg, requirement)
    stroke = float(max(r.peak_stroke for r in runs))
    f_n = choice.freq_hz_n if verified == "screened" else design.freq_hz_n
    visible = f_n >= f_floor
    ok = bool(isolated.complies) and visible
    rule = (
        f"the report's rule gives k1 = {design.k1:.4g} N/m ({design.k1_lbf_per_in:.4g} lbf/in, "
        f"f_n = {design.freq_hz_n:.3g} Hz)"
    )
    check = (
        f"verified in the time domain: the package {'complies' if ok else 'does not comply'} "
        f"(peak {isolated.peak_accel_g:.3g} g, stroke {stroke:.3g} m)"
    )
    if ok and verified == "screened":
        status = "passive-mount"
        note = (
            f"{base}; {rule}, but its undamped resonance is excited by the transient. "
            f"Recommended: k1 = {choice.k1:.4g} N/m ({choice.k1 * IN / LBF:.4g} lbf/in) with "
            f"damping ratio {choice.zeta1:g} (c1 = {choice.c1:.4g} N s/m, "
            f"f_n = {choice.freq_hz_n:.3g} Hz); {check}"
        )
    elif ok:
        status = "passive-mount"
        note = f"{base}; Recommended: {rule}; {check}"
    elif isolated.complies and not visible:
        status = "no-passive-mount"
        need_s = 5.0 / (f_n * (2 ** (1 / 6) - 2 ** (-1 / 6)))
        note = (
            f"{base}; the only mount that passes (k1 = {mount.k1:.4g} N/m, f_n = "
            f"{f_n:.3g} Hz) resonates below the lowest band this record resolves "
            f"({f_floor:.3g} Hz), so the record cannot verify it: not recommended. Lengthen the "
            f"record to about {need_s:.3g} s to judge it, or use active isolation"
        )
    else:
        status = "no-passive-mount"
        screen = (
            f"the screened spring-damper mount (k1 = {choice.k1:.4g} N/m, zeta {choice.zeta1:g}) "
            "passes the spectral screen but"
            if choice.found
            else f"no spring-damper mount of the {choice.screened} screened complies (best "
            f"margin {choice.min_margin:.3g}); {rule}, and it"
        )
        note = (
            f"{base}; {screen} fails the time-domain check ({check}). No passive mount is "
            "recommended: active isolation (ARIS-class) is needed for the attenuation listed "
            "per band"
        )
    act = None
    if status == "no-passive-mount":
        act, sentence = _active_check(point, response, requirement, need, edges, sources)
        if act is not None and act.complies:
            status = "active-recommended"
        note = f"{note}; {sentence}"
    return IsolationAdvice(
        point=point,
        status=status,
        attenuation_needed=need,
        band_hz=(lo, hi),
        target_ma=target,
        design=design,
        mount=choice,
        verified=verified,
        isolated=isolated,
        package_accel=pkg,
        peak_stroke_m=stroke,
        verifiable=visible,
        recommended=ok,
        active=act,
        note=note,
    )
