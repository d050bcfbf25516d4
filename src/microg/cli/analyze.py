"""``microg analyze``: the main job on a station model (default: the shipped IOC model)."""

from __future__ import annotations

from pathlib import Path

import click

from microg.cli.params import PositiveFloat, QuantityType

__all__ = ["analyze"]


@click.command()
@click.argument("model", required=False, default="ioc")
@click.option(
    "--force",
    "forces",
    multiple=True,
    help="Disturbance: crew-pushoff, crew-pushoff:f0=40lbf,t1=0.5s, a library activity "
    "(foot-pushoff-max, hand-pushoff-mean, ...) or a CSV file. Repeatable. [default: crew-pushoff]",
)
@click.option(
    "--at",
    "at_points",
    multiple=True,
    help="Named point where each --force acts (one for all, or one per --force). "
    "[default: the model's first crew point]",
)
@click.option(
    "--direction",
    "directions",
    multiple=True,
    help="Force direction: x, y, z, -x, ... or 'dx dy dz' (one for all, or one per --force). "
    "A CSV force's own direction wins. [default: x]",
)
@click.option(
    "--observe",
    multiple=True,
    help="Named point to assess (repeatable). [default: the model's experiment points]",
)
@click.option(
    "--damping",
    "zeta",
    type=PositiveFloat(0.0, strict=False),
    default=0.005,
    show_default=True,
    help="Modal damping ratio of the elastic modes (0 <= zeta < 1).",
)
@click.option(
    "--method",
    type=click.Choice(["fem", "ritz"]),
    default="fem",
    show_default=True,
    help="3-D frame finite elements, or the report's planar assumed modes.",
)
@click.option(
    "--plane",
    type=click.Choice(["3d", "xz", "yz"]),
    default="3d",
    show_default=True,
    help="--method ritz: the three-dimensional assumed-modes model, or the report's planar "
    "model in the X-Z or Y-Z plane.",
)
@click.option(
    "--elements",
    type=click.IntRange(1, 10000),
    default=10,
    show_default=True,
    help="Elements per beam (fem) or assumed functions per beam (ritz).",
)
@click.option(
    "--max-freq",
    type=QuantityType("frequency", "Hz", minimum=0.0, strict=True),
    default="10 Hz",
    show_default=True,
    help="Elastic modes up to this frequency enter the response.",
)
@click.option(
    "--duration",
    type=QuantityType("time", "s", minimum=0.0, strict=True),
    default="200 s",
    show_default=True,
    help="Length of the response record.  Band RMS (compliance) is taken over this whole "
    "interval, so a transient's band RMS falls as the record grows.",
)
@click.option(
    "--dt",
    type=QuantityType("time", "s", minimum=0.0, strict=True),
    default="0.01 s",
    show_default=True,
    help="Output sample interval.",
)
@click.option(
    "--requirement",
    type=click.Choice(["iss", "flat"]),
    default="iss",
    show_default=True,
    help="ISS vibratory requirement (1/3-octave), or the report's flat 1e-5 g.",
)
@click.option(
    "--package-weight",
    type=QuantityType("force", "lbf", minimum=0.0, strict=True),
    default="1000 lbf",
    show_default=True,
    help="Experiment package weight (on Earth) for the isolation advice.",
)
@click.option(
    "--absorber-mu",
    type=PositiveFloat(0.0, strict=True),
    default=None,
    help="Add a vibration absorber of this mass ratio to the advised mount.",
)
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("microg-analysis"),
    show_default=True,
    help="Directory for report.html, figures and results.json.",
)
@click.option("--json", "as_json", is_flag=True, help="Also print results.json to stdout.")
@click.option("--no-progress", is_flag=True, help="Hide the progress bar.")
def analyze(
    model: str,
    forces: tuple[str, ...],
    at_points: tuple[str, ...],
    directions: tuple[str, ...],
    observe: tuple[str, ...],
    zeta: float,
    method: str,
    plane: str,
    elements: int,
    max_freq: float,
    duration: float,
    dt: float,
    requirement: str,
    package_weight: float,
    absorber_mu: float | None,
    out_dir: Path,
    as_json: bool,
    no_progress: bool,
) -> None:
    """Microgravity environment of MODEL (a model file or a shipped name; default: ioc).

    Solves the free-free modes, applies the crew disturbances, assesses the acceleration at
    the observed points against the ISS vibratory requirement, and advises isolation.
    Writes OUT/report.html (self-contained), PNG figures and OUT/results.json.
    """
    from tqdm import tqdm

    from microg._vectors import parse_direction
    from microg.analysis import AnalysisOptions, Disturbance, run_analysis
    from microg.dynamics.forces import parse_force_spec
    from microg.errors import InputError
    from microg.models.toml import load_station
    from microg.units import G0

    if zeta >= 1.0:
        raise click.BadParameter(f"must be < 1, got {zeta:g}", param_hint="--damping")
    station = load_station(model)
    forces = forces or ("crew-pushoff",)
    names = [p.name for p in station.points]
    if not at_points:
        crew = [p.name for p in station.points if p.kind == "crew"]
        if not crew:
            raise InputError(
                "the model has no crew point", where="--at", fix=f"name one of: {', '.join(names)}"
            )
        at_points = (crew[0],)
    if not observe:
        observe = tuple(p.name for p in station.points if p.kind == "experiment") or tuple(names)
    directions = directions or ("x",)
    n = len(forces)
    for opt, vals in (("--at", at_points), ("--direction", directions)):
        if len(vals) not in (1, n):
            raise InputError(
                f"{len(vals)} values for {n} --force", where=opt, fix="give one, or one per --force"
            )
    for opt, pts in (("--at", at_points), ("--observe", observe)):
        for p in pts:
            if p not in names:
                raise InputError(
                    f"unknown point {p!r}", where=opt, fix=f"known points: {', '.join(names)}"
                )
    dists = []
    for i, spec in enumerate(forces):
        f = parse_force_spec(spec)
        d = parse_direction(directions[i if len(directions) == n else 0], "--direction")
        dists.append(Disturbance(f, at_points[i if len(at_points) == n else 0], d))
    opts = AnalysisOptions(
        disturbances=dists,
        observe=observe,
        method=method,
        plane=plane,
        elements_per_beam=elements,
        zeta=zeta,
        max_freq_hz=max_freq,
        duration=duration,
        dt=dt,
        requirement=requirement,
        package_mass=package_weight / G0,
        absorber_mu=absorber_mu,
    )
    stages = ["structure", "modes", "response", "assessment", "isolation", "report"]
    bar = tqdm(total=len(stages), desc="microg analyze", disable=no_progress or None, leave=False)

    def progress(stage: str) -> None:
        bar.set_postfix_str(stage)
        if stage != "structure":
            bar.update(1)

    result = run_analysis(station, opts, progress=progress)
    progress("report")
    path = write_outputs(result, out_dir)
    bar.update(1)
    bar.close()
    if as_json:
        from microg._io import dumps

        click.echo(dumps(result.to_dict()))
    else:
        _summary(result, path)


def write_outputs(result, out_dir: Path) -> Path:
    """Render figures, HTML and JSON, and write them into ``out_dir`` atomically."""
    from microg._io import dumps, write_output_files
    from microg.report.analysis import figures, render_analysis

    figs = figures(result)
    html = render_analysis(result, figs)
    text = dumps(result.to_dict())
    files: dict[str, bytes | str] = {**figs, "report.html": html, "results.json": text}
    return write_output_files(out_dir, files, where="--out")


def _summary(result, path: Path) -> None:
    m = result.modes
    el = ~m.rigid & result.used
    click.echo(
        f"{result.model}: {m.n_rigid} rigid-body modes, {int(el.sum())} elastic modes up to "
        f"{result.options.max_freq_hz:g} Hz (first {m.freq_hz[el][0]:.4g} Hz)"
        if el.any()
        else f"{result.model}: {m.n_rigid} rigid-body modes"
    )
    for name, a in result.assessments.items():
        verdict = "complies" if a.complies else "DOES NOT COMPLY"
        flat = "within" if a.peak_accel_g <= 1e-5 else "above"
        click.echo(
            f"  {name}: peak {a.peak_accel_g:.3g} g ({flat} the report's 1e-5 g), "
            f"RMS {a.rms_accel_g:.3g} g, {verdict} with {a.requirement}"
        )
        adv = result.isolation[name]
        click.echo(f"    isolation: {adv.note}")
        if adv.design is not None:
            d = adv.design
            click.echo(
                f"    report's rule (Sec. 4.2): k1 <= {d.k1:.4g} N/m "
                f"({d.k1_lbf_per_in:.4g} lbf/in), natural frequency {d.freq_hz_n:.3g} Hz, "
                f"sag under 1 g {d.sag_1g:.3g} m"
            )
    for w in result.warnings:
        click.echo(f"  warning: {w}")
    click.echo(f"report written to {path / 'report.html'}")
