"""The main job: a station's microgravity environment under crew disturbances.

``run_analysis`` loads a model, discretises it, solves the free-free modes, applies the
disturbances (exact piecewise-linear modal response, damped modes, rigid-body modes
included), assesses the acceleration at the observed points against the ISS vibratory
requirement, and recommends isolation where a point does not comply.  It returns one
:class:`Analysis` object; the CLI and the HTML report only read it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.dynamics.forces import ForceHistory
from microg.dynamics.modes import Modes, solve_modes
from microg.dynamics.response import PointResponse, generalized_force_vector, response_at_points
from microg.environment.metrics import Assessment, assess
from microg.environment.requirements import (
    Requirement,
    iss_requirement,
    report_flat_requirement,
)
from microg.errors import InputError
from microg.models.station import Station
from microg.structure.structure import Structure
from microg.units import G0, IN, LB, LBF

if TYPE_CHECKING:
    from microg.isolation.design import MountDesign
    from microg.isolation.mount import MountChoice

__all__ = [
    "Disturbance",
    "AnalysisOptions",
    "IsolationAdvice",
    "Analysis",
    "run_analysis",
    "build_structure",
]

#: the seed report's criterion: peak acceleration below 1e-5 g (Introduction)
REPORT_LIMIT_G = 1e-5

#: largest number of output samples of one analysis (memory: ~100 bytes per sample and mode)
MAX_SAMPLES = 2_000_000


@dataclass(frozen=True)
class Disturbance:
    """A force history applied at a named point in a direction.

    Attributes
    ----------
    force : ForceHistory
        Breakpoints (s, N); its own direction, if any, wins over ``direction``.
    point : str
        Named point of the model where it acts.
    direction : ndarray (3,)
        Unit vector of the force in the station frame.
    """

    force: ForceHistory
    point: str
    direction: np.ndarray

    @property
    def unit_direction(self) -> np.ndarray:
        """The direction used: the force's own (CSV) direction if it has one."""
        d = self.force.direction if self.force.direction is not None else self.direction
        d = np.asarray(d, float)
        return d / np.linalg.norm(d)


@dataclass(frozen=True)
class AnalysisOptions:
    """Everything ``microg analyze`` needs besides the model (SI).

    Attributes
    ----------
    disturbances : sequence of Disturbance
        Applied together (superposed).
    observe : sequence of str
        Named points to assess.
    method : str
        ``"fem"`` (3-D frame elements) or ``"ritz"`` (the report's planar assumed modes).
    plane : str
        ``"3d"`` (default), ``"xz"`` or ``"yz"`` for ``ritz``.
    elements_per_beam : int
        Finite elements per beam (``fem``); assumed functions per beam (``ritz``).
    zeta : float
        Modal damping ratio of the elastic modes.
    max_freq_hz : float
        Elastic modes up to this frequency are kept (the rigid-body modes always).
    duration : float
        Length of the output record, s.
    dt : float
        Output sample interval, s.
    requirement : str
        ``"iss"`` (ISS vibratory requirement) or ``"flat"`` (the report's 1e-5 g).
    package_mass : float
        Experiment package mass for the isolation advice, kg.
    absorber_mu : float or None
        Absorber mass ratio for the isolation advice (None: spring only).
    """

    disturbances: Sequence[Disturbance]
    observe: Sequence[str]
    method: str = "fem"
    plane: str = "3d"
    elements_per_beam: int = 10
    zeta: float = 0.005
    max_freq_hz: float = 10.0
    duration: float = 200.0
    dt: float = 0.01
    requirement: str = "iss"
    package_mass: float = 1000.0 * LB
    absorber_mu: float | None = None


@dataclass(frozen=True)
class IsolationAdvice:
    """Isolation recommendation for one observed point.

    Attributes
    ----------
    point : str
    needed : bool
        False when the point complies without isolation.
    band_hz : tuple of float
        Lowest and highest band edges where the requirement is exceeded, Hz.
    target_ma : float
        Largest acceleration magnification that brings every exceeding band to its limit.
    design : MountDesign or None
        :class:`microg.isolation.design.MountDesign`: the report's rule (M_a over the
        exceeding band), with stiffness, natural frequency and sag.
    note : str
    package_accel : ndarray (3, nt) or None
        What the isolated package feels: the exact response of the designed mount (the same
        mount on each axis) to the point's acceleration history, m/s^2.
    isolated : Assessment or None
        The package's acceleration assessed against the same requirement.
    peak_stroke : float or None
        Largest package motion relative to the mount over the axes (rattle space), m.
    mount : MountChoice or None
        :class:`microg.isolation.mount.MountChoice`: the recommended spring-damper mount
        from the whole-spectrum screen (``found`` False when none complies).
    """

    point: str
    needed: bool
    band_hz: tuple[float, float] | None
    target_ma: float | None
    design: MountDesign | None
    note: str
    package_accel: np.ndarray | None = None
    isolated: Assessment | None = None
    peak_stroke: float | None = None
    mount: MountChoice | None = None


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`run_analysis`.

    Attributes
    ----------
    model : str
        Model name.
    options : AnalysisOptions
    structure : Structure
    modes : Modes
        All computed modes (``used`` marks those in the response).
    used : ndarray of bool
        Modes kept for the response (rigid + elastic up to ``max_freq_hz``).
    responses : dict of str to PointResponse
        Motion of each observed point (3 axes, SI).
    assessments : dict of str to Assessment
    isolation : dict of str to IsolationAdvice
    timepts : ndarray
        Output times, s.
    """

    model: str
    options: AnalysisOptions
    structure: Structure
    modes: Modes
    used: np.ndarray
    responses: dict[str, PointResponse]
    assessments: dict[str, Assessment]
    isolation: dict[str, IsolationAdvice]
    timepts: np.ndarray
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        """The ``microg analyze --json`` contract."""
        modes = self.modes.to_dict()
        for row, used in zip(modes["modes"], self.used, strict=True):
            row["used"] = bool(used)
        obs = {}
        for name, a in self.assessments.items():
            d = a.to_dict()
            d["isolation"] = _advice_dict(self.isolation[name])
            # the seed report's single-number criterion, beside the band-by-band one
            d["report_criterion"] = {
                "limit_g": REPORT_LIMIT_G,
                "peak_within": bool(a.peak_accel_g <= REPORT_LIMIT_G),
            }
            obs[name] = d
        return {
            "model": self.model,
            "method": self.structure.method,
            "plane": self.structure.plane,
            "modes": modes,
            "disturbances": [
                {
                    "name": d.force.name,
                    "at": d.point,
                    "direction": d.unit_direction,
                    "peak_force_N": float(np.max(np.abs(d.force.force))),
                    "impulse_Ns": float(d.force.impulse()),
                }
                for d in self.options.disturbances
            ],
            "damping": self.options.zeta,
            "requirement": self.options.requirement,
            "record": {"duration_s": self.options.duration, "dt_s": self.options.dt},
            "observations": obs,
            "complies": all(a.complies for a in self.assessments.values()),
            "warnings": list(self.warnings),
            "notes": list(self.notes),
        }


def _advice_dict(adv: IsolationAdvice) -> dict[str, Any]:
    out: dict[str, Any] = {
        "needed": adv.needed,
        "band_hz": adv.band_hz,
        "target_Ma": adv.target_ma,
        "note": adv.note,
        "design": None,
    }
    if adv.isolated is not None:
        iso = adv.isolated
        out["isolated"] = {
            "peak_accel_g": iso.peak_accel_g,
            "rms_accel_g": iso.rms_accel_g,
            "complies": bool(iso.complies),
            "peak_stroke_m": adv.peak_stroke,
            "worst_band": None
            if iso.worst_band is None
            else {"center_hz": iso.worst_band.center_hz, "margin": iso.worst_band.margin},
        }
    if adv.mount is not None:
        mc = adv.mount
        out["recommended_mount"] = {
            "found": bool(mc.found),
            "k1_N_per_m": mc.k1,
            "k1_lbf_per_in": mc.k1 * IN / LBF,
            "zeta1": mc.zeta1,
            "c1_N_s_per_m": mc.c1,
            "freq_hz_n": mc.freq_hz_n,
            "screen_min_margin": mc.min_margin,
        }
    d = adv.design
    if d is not None:
        out["design"] = {
            k: getattr(d, k)
            for k in (
                "k1",
                "k1_lbf_per_in",
                "omega_n",
                "freq_hz_n",
                "achieved_Ma",
                "sag_1g",
                "mu",
                "k",
            )
            if hasattr(d, k)
        }
        out["design"]["units"] = "k1 N/m, omega_n rad/s, freq_hz_n Hz, sag_1g m"
        out["design"]["rule"] = "report Section 4.2: M_a <= target over the exceeding band"
    return out


def build_structure(station: Station, method: str, plane: str, n: int) -> Structure:
    """Discretise ``station`` by ``method`` ("fem": n elements per beam; "ritz": n functions)."""
    if method == "fem":
        from microg.structure.fem import build_fem

        return build_fem(station, elements_per_beam=n)
    if method == "ritz":
        from microg.structure.ritz import build_ritz

        return build_ritz(station, None if plane == "3d" else plane, n, gravity_gradient=False)
    raise InputError(f"unknown method {method!r}", where="--method", fix="use fem or ritz")


def _advise(
    name: str,
    a: Assessment,
    opts: AnalysisOptions,
    response: PointResponse,
    requirement: Requirement,
) -> IsolationAdvice:
    from microg.isolation.design import design_mount
    from microg.isolation.mount import search_mount
    from microg.isolation.timedomain import IsolatorModel, package_response

    if a.complies:
        return IsolationAdvice(name, False, None, None, None, "complies without isolation")
    to = a.third_octave
    margin = to.margin.min(axis=0)
    bad = np.isfinite(margin) & (margin < 1.0)
    if not np.any(bad):
        return IsolationAdvice(
            name,
            True,
            None,
            None,
            None,
            "exceeds the peak limit only: a passive mount cannot help a transient's peak "
            "without knowing its spectrum",
        )
    lo = float(to.lower_hz[bad].min())
    hi = float(to.upper_hz[bad].max())
    target = float(max(margin[bad].min(), 1e-6))
    note = (
        f"bands {lo:.3g}-{hi:.3g} Hz exceed the requirement; the mount must attenuate them by "
        f"{1 / target:.3g}x (M_a <= {target:.3g})"
    )
    try:
        design = design_mount(
            opts.package_mass,
            (2 * np.pi * lo, 2 * np.pi * hi),
            min(target, 1.0),
            mu=opts.absorber_mu,
        )
    except InputError as exc:
        return IsolationAdvice(name, True, (lo, hi), target, None, f"{note}; no design: {exc}")
    # the report's rule ignores the mount's own resonance, which a transient excites below
    # the exceeding band: screen spring-damper mounts on the whole spectrum, then verify the
    # choice with the exact time-domain response
    choice = search_mount(a.spectrum, requirement, opts.package_mass, 10.0 * design.k1)
    if choice.found:
        mount = IsolatorModel(m1=opts.package_mass, k1=choice.k1, c1=choice.c1)
    else:
        mount = IsolatorModel(
            m1=opts.package_mass,
            k1=design.k1,
            m2=design.m2 or 0.0,
            k2=design.k2 or 0.0,
            c=design.c or 0.0,
        )
    runs = [package_response(mount, response.timepts, row) for row in response.acceleration]
    pkg = np.array([r.package_accel for r in runs])
    isolated = assess(response.timepts, pkg, requirement)
    stroke = max(r.peak_stroke for r in runs)
    if choice.found:
        note += (
            f"; the report's rule gives k1 = {design.k1:.4g} N/m, but its undamped resonance "
            f"at {design.freq_hz_n:.3g} Hz is excited by the transient. Recommended: k1 = "
            f"{choice.k1:.4g} N/m ({choice.k1 * IN / LBF:.4g} lbf/in) with damping ratio "
            f"{choice.zeta1:g} (c1 = {choice.c1:.4g} N s/m, f_n = {choice.freq_hz_n:.3g} Hz)"
        )
    else:
        note += (
            f"; no spring-damper mount screened ({choice.screened}) makes it comply "
            f"(best margin {choice.min_margin:.3g}): active isolation (ARIS-class) is needed"
        )
    verdict = "complies" if isolated.complies else "does not comply"
    note += (
        f"; verified in the time domain: the package {verdict} "
        f"(peak {isolated.peak_accel_g:.3g} g, stroke {stroke:.3g} m)"
    )
    return IsolationAdvice(
        name, True, (lo, hi), target, design, note, pkg, isolated, stroke, choice
    )


def run_analysis(
    station: Station,
    opts: AnalysisOptions,
    *,
    progress: Callable[[str], None] | None = None,
) -> Analysis:
    """Run the main job on ``station`` (see the module docstring).

    Parameters
    ----------
    station : Station
    opts : AnalysisOptions
    progress : callable, optional
        Called with a stage name as each stage starts (for a progress bar).
    """
    step = progress or (lambda _s: None)
    if not opts.disturbances:
        raise InputError("no disturbance", where="--force", fix="give at least one --force")
    if opts.dt <= 0 or opts.duration <= opts.dt:
        raise InputError("need 0 < dt < duration", where="--dt/--duration")
    if opts.duration / opts.dt > MAX_SAMPLES:
        raise InputError(
            f"{opts.duration / opts.dt:.3g} output samples is more than {MAX_SAMPLES:,}",
            where="--duration/--dt",
            fix="shorten --duration or lengthen --dt",
        )
    step("structure")
    structure = build_structure(station, opts.method, opts.plane, opts.elements_per_beam)
    points = {name: structure.point(name) for name in opts.observe}
    forces_at = {d.point: structure.point(d.point) for d in opts.disturbances}
    step("modes")
    n_req = None
    if structure.is_sparse:
        n_req = min(structure.n_dof - 1, 60)
    modes = solve_modes(structure, n_req)
    used = modes.rigid | (modes.freq_hz <= opts.max_freq_hz)
    warnings = []
    if structure.is_sparse and not modes.rigid[-1] and modes.freq_hz[-1] <= opts.max_freq_hz:
        warnings.append(
            f"only {modes.n_modes} modes computed; the highest ({modes.freq_hz[-1]:.3g} Hz) is "
            f"below --max-freq {opts.max_freq_hz:g} Hz"
        )
    m = modes.subset(np.nonzero(used)[0])
    zeta = np.where(m.rigid, 0.0, opts.zeta)
    step("response")
    timepts = np.arange(0.0, opts.duration + 0.5 * opts.dt, opts.dt)
    maps = {n: p.translation for n, p in points.items()}
    responses: dict[str, PointResponse] = {}
    for d in opts.disturbances:
        b = generalized_force_vector(forces_at[d.point].translation, d.unit_direction)
        r = response_at_points(m.omega, zeta, m.phi, maps, d.force, b, timepts)
        for name, pr in r.items():
            if name in responses:
                old = responses[name]
                responses[name] = PointResponse(
                    name,
                    timepts,
                    old.displacement + pr.displacement,
                    old.velocity + pr.velocity,
                    old.acceleration + pr.acceleration,
                )
            else:
                responses[name] = pr
    step("assessment")
    req = iss_requirement() if opts.requirement == "iss" else report_flat_requirement()
    assessments = {n: assess(timepts, r.acceleration, req) for n, r in responses.items()}
    step("isolation")
    advice = {n: _advise(n, a, opts, responses[n], req) for n, a in assessments.items()}
    fitted = [m.name for m in station.all_masses() if m.fitted]
    notes = []
    if fitted:
        notes.append(
            f"{len(fitted)} mass items of model {station.name!r} carry fitted values (marked "
            f"fitted = true in the model file: {', '.join(sorted(set(fitted)))}); for the "
            "shipped IOC models these were fitted to the seed report's Appendix C because the "
            "OCR lost them, so local results near them (the keel) inherit that uncertainty"
        )
    return Analysis(
        model=station.name,
        options=opts,
        structure=structure,
        modes=modes,
        used=used,
        responses=responses,
        assessments=assessments,
        isolation=advice,
        timepts=timepts,
        warnings=warnings,
        notes=notes,
    )


def peak_g(response: PointResponse) -> float:
    """Peak magnitude of a point's acceleration, g."""
    return float(np.max(np.linalg.norm(response.acceleration, axis=0)) / G0)
