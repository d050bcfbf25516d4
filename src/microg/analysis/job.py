"""The main job's orchestration: model, modes, transient and vibratory regimes, one result.

:func:`analyze` takes a user's arguments (parsed once, :mod:`microg.analysis.inputs`) and calls
:func:`run_analysis`, which discretises the model, solves the free-free modes, runs the
transient regime (:mod:`microg.analysis.transient`) and the frequency-domain assessment of
vibratory sources, and returns one :class:`~microg.analysis.result.Analysis`.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from microg import _args
from microg._vectors import parse_direction
from microg.analysis.inputs import (
    as_list,
    check_points,
    direction_list,
    force_histories,
    has_grids,
    model_object,
    point_names,
    requirement_object,
    si_value,
    source_catalogue,
)
from microg.analysis.options import (
    DEFAULT_SOURCE_MODES,
    DEFAULTS,
    MAX_SAMPLES,
    REQUIREMENT_INTERVAL_S,
    AnalysisOptions,
    Disturbance,
)
from microg.analysis.provenance import Provenance
from microg.analysis.result import Analysis, Observation
from microg.analysis.transient import check_modes_used, transient
from microg.dynamics.modes import DEFAULT_N_MODES, solve_modes
from microg.environment.requirements import Requirement
from microg.errors import InputError
from microg.structure.discretize import discretize
from microg.structure.structure import Structure

__all__ = ["analyze", "run_analysis"]


def analyze(
    model: Any = "ioc",
    force: Any = None,
    at: str | Sequence[str] | None = None,
    direction: Any = None,
    observe: str | Sequence[str] | None = None,
    *,
    method: str = DEFAULTS["method"],
    plane: str = DEFAULTS["plane"],
    n: int | None = None,
    n_modes: int | None = None,
    damping: float = DEFAULTS["damping"],
    max_freq: float | str = DEFAULTS["max_freq_hz"],
    duration: float | str = DEFAULTS["duration_s"],
    dt: float | str = DEFAULTS["dt_s"],
    requirement: str | Requirement = DEFAULTS["requirement"],
    package_mass: float | str | None = None,
    absorber_mu: float | None = None,
    isolation: bool = True,
    gravity_gradient: bool = DEFAULTS["gravity_gradient"],
    sources: Any = None,
    progress: Callable[[str], None] | None = None,
    command: str | None = None,
) -> Analysis:
    """The main job: modes, response to disturbances, compliance, isolation advice.

    Parameters
    ----------
    model : Station, modal model, str or Path
        A model object, a model file path or a shipped model name (default ``"ioc"``).
    force : str, ForceHistory, or a list of them
        Spec strings as on the command line (``"crew-pushoff"``,
        ``"crew-pushoff:f0=40lbf,t1=0.5s"``, a library activity, a CSV path) or force
        objects.  Default: the report's push-off.
    at : str or list of str
        Named point where each force acts (one for all, or one per force).  Default: the
        model's first point of kind ``crew``.
    direction : str, 3 numbers, or a list of them
        Force direction(s): ``"x"``, ``"-z"``, ``"1 0 0"``, ``[0, 1, 0]``.  Default ``"x"``.
    observe : str or list of str
        Named points to assess.  Default: the model's points of kind ``experiment`` (all
        points when it has none).
    method : {"fem", "ritz"}
    plane : {"3d", "xz", "yz"}
    n : int, optional
        Elements (fem) or functions (ritz) per beam.
    n_modes : int, optional
        Modes solved for sparse models.
    damping : float
        Modal damping ratio of the elastic modes, 0 <= zeta < 1.
    max_freq : float (Hz) or str
        Elastic modes up to this frequency enter the response.
    duration, dt : float (s) or str
        Record length and output sample interval.
    requirement : str or Requirement
        ``"iss"`` (the ISS vibratory requirement as PIMS codes it) or ``"flat"`` (the report's
        1e-5 g); or a Requirement object.
    package_mass : float (kg) or str
        Experiment package mass for the isolation advice (default 1000 lb).
    absorber_mu : float, optional
        Absorber mass ratio for the isolation advice.
    isolation : bool
        Advise isolation where a point does not comply.
    gravity_gradient : bool
        Restrain the rigid rotations by gravity gradient (libration).
    sources : str, Path or SourceCatalogue, optional
        A source catalogue (``[[source]]`` TOML, see :mod:`microg.environment.sources`, or
        ``"example"``): continuous vibratory sources assessed in the frequency domain.  With
        sources and no ``force``, only the frequency-domain analysis runs.
    progress : callable, optional
        Called with a stage name as each stage starts.
    command : str, optional
        The command line, for the provenance record.

    Returns
    -------
    Analysis

    Notes
    -----
    A float is SI; a string is parsed, with its unit or, when bare, in the model's unit
    system.  Errors name the parameter (``duration``, ``observe``, ``force[1]``...).
    """
    mdl = model_object(model)
    for name, flag in (("isolation", isolation), ("gravity_gradient", gravity_gradient)):
        _args.boolean(flag, name)
    n = None if n is None else _args.integer(n, "n", lo=1)
    n_modes = None if n_modes is None else _args.integer(n_modes, "n_modes", lo=1)
    damping = _args.number(damping, "damping", lo=0.0, hi=1.0)  # < 1: _check_options
    if absorber_mu is not None:
        from microg.isolation.absorber import MU_RANGE

        absorber_mu = _args.number(absorber_mu, "absorber_mu", lo=MU_RANGE[0], hi=MU_RANGE[1])
    if progress is not None:
        _args.function(progress, "progress")
    if command is not None:
        _args.text(command, "command")
    _args.text(method, "method")
    _args.text(plane, "plane")
    units = getattr(mdl, "unit_system", None)
    catalogue = source_catalogue(sources)
    forces = [] if (catalogue is not None and force is None) else force_histories(force, units)
    nf = len(forces)
    points = point_names(mdl)
    known = [p for p, _ in points]
    at_list = [str(a) for a in as_list(at)]
    if not at_list and nf:
        crew = [p for p, k in points if k == "crew"]
        if not crew:
            raise InputError(
                "the model has no crew point", where="at", fix=f"name one of: {', '.join(known)}"
            )
        at_list = [crew[0]]
    obs = [str(o) for o in as_list(observe)]
    if not obs:
        obs = [p for p, k in points if k == "experiment"] or list(known)
    dirs = direction_list(direction) or [DEFAULTS["direction"]]
    for name, vals in (("at", at_list), ("direction", dirs)):
        if nf and len(vals) not in (1, nf):
            raise InputError(
                f"{len(vals)} values for {nf} forces", where=name, fix="give one, or one per force"
            )
    if not has_grids(mdl):  # grid names (grid:N) of imported models resolve on the structure
        check_points(at_list, known, "at")
        check_points(obs, known, "observe")
    if len(set(obs)) != len(obs):
        raise InputError("a point is observed twice", where="observe", fix="name each point once")
    dists = []
    for i, f in enumerate(forces):
        w = "direction" if len(dirs) == 1 else f"direction[{i}]"
        d = parse_direction(dirs[i if len(dirs) == nf else 0], w)
        dists.append(Disturbance(f, at_list[i if len(at_list) == nf else 0], d))
    pm = (
        DEFAULTS["package_mass_kg"]
        if package_mass is None
        else si_value(package_mass, "mass", "package_mass", units)
    )
    if not pm > 0:
        raise InputError(f"must be > 0, got {package_mass!r}", where="package_mass")
    opts = AnalysisOptions(
        disturbances=dists,
        observe=obs,
        method=method,
        plane=plane,
        n=n,
        n_modes=n_modes,
        zeta=float(damping),
        max_freq_hz=si_value(max_freq, "frequency", "max_freq", units),
        duration_s=si_value(duration, "time", "duration", units),
        dt_s=si_value(dt, "time", "dt", units),
        requirement=requirement.name if isinstance(requirement, Requirement) else requirement,
        package_mass_kg=pm,
        absorber_mu=absorber_mu,
        isolation=isolation,
        gravity_gradient=gravity_gradient,
        sources=catalogue,
    )
    return run_analysis(
        mdl,
        opts,
        progress=progress,
        requirement=requirement if isinstance(requirement, Requirement) else None,
        command=command,
    )


def _check_options(opts: AnalysisOptions) -> None:
    """Refuse options that make no verdict: the one check of the damping, record and bands.

    The damping ratio is checked here once; the response kernels below trust it.
    """
    if not 0.0 <= opts.zeta < 1.0:
        raise InputError(f"must be 0 <= zeta < 1, got {opts.zeta!r}", where="damping")
    if not opts.duration_s > 0:
        raise InputError(
            f"must be > 0, got {opts.duration_s:g} s",
            where="duration",
            fix="give the record's length, e.g. 200 s",
        )
    if not (opts.dt_s > 0 and opts.duration_s > opts.dt_s):
        raise InputError(
            f"need 0 < dt < duration, got dt = {opts.dt_s:g} s, duration = {opts.duration_s:g} s",
            where="dt",
        )
    if opts.duration_s / opts.dt_s > MAX_SAMPLES:
        raise InputError(
            f"{opts.duration_s / opts.dt_s:.3g} output samples is more than {MAX_SAMPLES:,}",
            where="duration",
            fix="shorten the duration or lengthen dt",
        )
    if not opts.max_freq_hz > 0:
        raise InputError(f"must be > 0, got {opts.max_freq_hz:g} Hz", where="max_freq")
    if not opts.disturbances and opts.sources is None:
        raise InputError("no disturbance", where="force", fix="give at least one force")
    for d in opts.disturbances:
        end = float(d.force.timepts[-1])
        if end > opts.duration_s:
            raise InputError(
                f"force {d.force.name!r} lasts until {end:g} s, after the {opts.duration_s:g}-s "
                "record ends: the response to the rest of it is not computed",
                where="duration",
                fix=f"use a duration of at least {end:g} s (and time for the response to decay)",
            )


def _structure(model: Any, opts: AnalysisOptions) -> Structure:
    if isinstance(model, Structure):
        return model
    return discretize(
        model, opts.method, plane=opts.plane, n=opts.n, gravity_gradient=opts.gravity_gradient
    )


def _point(structure: Structure, name: str, where: str) -> Any:
    """The structure's map of ``name``; an unknown name is an InputError naming ``where``."""
    try:
        return structure.point(name)
    except InputError as exc:
        raise InputError(exc.what, where=where, fix=exc.fix) from None


def run_analysis(
    model: Any,
    opts: AnalysisOptions,
    *,
    progress: Callable[[str], None] | None = None,
    requirement: Requirement | None = None,
    command: str | None = None,
) -> Analysis:
    """Run the main job on a model with validated options (see :func:`analyze`).

    Parameters
    ----------
    model : Station, modal model or Structure
    opts : AnalysisOptions
    progress : callable, optional
        Called with a stage name as each stage starts (for a progress bar).
    requirement : Requirement, optional
        Overrides ``opts.requirement`` (a custom requirement object).
    command : str, optional
        The command line, for the provenance record.
    """
    step = progress or (lambda _s: None)
    _check_options(opts)
    req = requirement or requirement_object(opts.requirement)
    step("structure")
    structure = _structure(model, opts)
    for d in opts.disturbances:
        _point(structure, d.point, "at")
    if opts.sources is not None:
        opts.sources.validate_points(structure.points)
    for name in opts.observe:
        _point(structure, name, "observe")
    step("modes")
    n_req = None
    if structure.is_sparse:
        # the vibratory regime reaches 300 Hz: sources need the modes well above it
        default = DEFAULT_SOURCE_MODES if opts.sources is not None else DEFAULT_N_MODES
        n_req = min(structure.n_dof - 1, opts.n_modes or default)
    modes = solve_modes(structure, n_req)
    # the model file's hash runs beside the response and assessment (compute-bound), not the
    # structure and modes, whose scans of the mode shapes compete with it for memory bandwidth
    provenance = Provenance(model, command)
    warnings: list[str] = []
    elastic = modes.elastic
    used = modes.rigid | (np.asarray(elastic) & (modes.freq_hz <= opts.max_freq_hz))
    name = str(getattr(model, "name", None) or structure.meta.get("model", "model"))
    observations: dict[str, Observation] = {}
    t = np.zeros(0)
    if opts.disturbances:
        warnings += check_modes_used(modes, np.asarray(elastic, bool), used, opts.max_freq_hz)
        observations, t, w = transient(structure, modes, used, opts, req, step)
        warnings += w
    vib = None
    if opts.sources is not None:
        step("frequency domain")
        from microg.environment.vibratory import assess_sources

        zeta_all = np.where(modes.rigid, 0.0, opts.zeta)
        vib = assess_sources(modes, opts.sources, list(opts.observe), req, zeta_all)
        warnings += [f"frequency domain: {w}" for w in vib.warnings]
    for pname, ob in observations.items():
        warnings += [f"{pname}: {w}" for w in ob.assessment.warnings]
    notes = _notes(model, opts, observations)
    return Analysis(
        model=name,
        options=opts,
        structure=structure,
        modes=modes,
        used=used,
        observations=observations,
        timepts=t,
        requirement=req,
        warnings=warnings,
        notes=notes,
        meta=provenance.result(),
        frequency_domain=vib,
    )


def _notes(model: Any, opts: AnalysisOptions, obs: Mapping[str, Observation]) -> list[str]:
    notes = []
    if obs:
        notes.append(
            f"the band verdict is judged on the band RMS over the whole {opts.duration_s:g}-s "
            f"record: a choice (a transient's band RMS falls as the record grows); the margin "
            f"over the worst {REQUIREMENT_INTERVAL_S:g}-s interval is given beside it"
        )
    masses = getattr(model, "all_masses", None)
    fitted = [pm.name for pm in masses() if pm.fitted] if callable(masses) else []
    if fitted:
        # one entry per name, with how many items carry it: the count and the list agree
        count = Counter(fitted)
        listed = ", ".join(
            name if count[name] == 1 else f"{name} ({count[name]} items)" for name in sorted(count)
        )
        notes.append(
            f"{len(fitted)} mass items of model {getattr(model, 'name', '')!r} carry fitted "
            f"values (marked fitted = true in the model file: {listed}); "
            "for the shipped IOC models these were fitted to the seed report's Appendix C "
            "because the OCR lost them, so local results near them (the keel) inherit that "
            "uncertainty"
        )
    return notes
