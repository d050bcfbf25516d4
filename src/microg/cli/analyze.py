"""``microg analyze``: the main job on a model (default: the shipped IOC model).

Parse -> :func:`microg.analyze` -> format.  Option values are handed to the library as the
user wrote them (a bare number takes the model's unit system there); the library's errors
name its parameters, which :func:`flag_errors` maps back to the options.
"""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Any

import click

from microg import defaults
from microg.analysis import DEFAULTS
from microg.cli._common import (
    MODEL_FILE_FLAGS,
    Option,
    discretisation_options,
    given,
    model_file_options,
    preset_option,
    written,
)
from microg.cli._errors import flag_errors
from microg.cli.params import Integer, Number, PathType, PositiveFloat
from microg.units import LB

__all__ = ["analyze", "flag_errors", "write_outputs"]

#: library parameter -> command-line option
FLAGS = {
    "force": "--force",
    "at": "--at",
    "direction": "--direction",
    "observe": "--observe",
    "damping": "--damping",
    "method": "--method",
    "plane": "--plane",
    "n": "--elements",
    "functions": "--functions",
    "n_modes": "--n-modes",
    "max_freq": "--max-freq",
    "duration": "--duration",
    "dt": "--dt",
    "requirement": "--requirement",
    "package_mass": "--package-mass/--package-weight",
    "absorber_mu": "--absorber-mu",
    "sources": "--sources",
    "units": "--units",
    "wtmass": "--wtmass",
    "points": "--points",
    "out": "--out",
    "gravity_gradient": "--gravity-gradient",
    **MODEL_FILE_FLAGS,
}


def _weight_to_mass(text: str) -> str:
    """A weight on Earth (a bare number is lbf) as a mass string; a mass passes through."""
    from microg.errors import InputError
    from microg.units import G0, parse_quantity

    try:
        w = parse_quantity(text, "force", where="--package-weight", default_unit="lbf")
    except InputError:
        try:
            return f"{parse_quantity(text, 'mass', where='--package-weight')!r} kg"
        except InputError:
            raise InputError(
                f"{text!r} is neither a weight nor a mass",
                where="--package-weight",
                fix="write e.g. '1000 lbf' or '450 kg'",
            ) from None
    return f"{w / G0!r} kg"


#: preset key -> this command's parameter
PRESET_PARAMS = {k: k for k in ("method", "plane", "damping", "functions")}


@click.command(short_help="Microgravity environment of MODEL (the main job).")
@click.argument("model", required=False, default="ioc")
@preset_option(PRESET_PARAMS)
@click.option(
    "--force",
    "forces",
    multiple=True,
    cls=Option,
    show_default=f"{DEFAULTS['force']}; none with --sources",
    help="Disturbance: crew-pushoff, crew-pushoff:f0=40lbf,t1=0.5s, a library activity "
    "(foot-pushoff-max, hand-pushoff-mean, ...) or a CSV file. Repeatable.",
)
@click.option(
    "--at",
    "at_points",
    multiple=True,
    cls=Option,
    show_default="the model's first crew point",
    help="Named point where each --force acts (one for all, or one per --force).",
)
@click.option(
    "--direction",
    "directions",
    multiple=True,
    cls=Option,
    show_default=DEFAULTS["direction"],
    help="Force direction: x, y, z, -x, ... or 'dx dy dz' (one for all, or one per --force). "
    "A CSV force's own direction wins.",
)
@click.option(
    "--observe",
    multiple=True,
    cls=Option,
    show_default="the model's experiment points",
    help="Named point to assess (repeatable).",
)
@click.option(
    "--damping",
    type=Number(),
    default=DEFAULTS["damping"],
    help="Modal damping ratio of the elastic modes, 0 <= zeta < 1.",
)
@click.option(
    "--method",
    type=click.Choice(["fem", "ritz"]),
    default=DEFAULTS["method"],
    help="3-D frame finite elements, or assumed modes.",
)
@click.option(
    "--plane",
    type=click.Choice(["3d", "xz", "yz"]),
    default=DEFAULTS["plane"],
    help="--method ritz: the 3-D assumed-modes model, or the report's planar model.",
)
@discretisation_options
@click.option(
    "--n-modes",
    type=Integer(1, 2000),
    default=None,
    cls=Option,
    show_default=f"{defaults.N_MODES} of a sparse model, all of a dense one",
    help="Modes solved (the elastic ones up to --max-freq are used).",
)
@click.option(
    "--gravity-gradient/--free-free",
    default=DEFAULTS["gravity_gradient"],
    help="Restrain the rigid rotations by gravity gradient (libration), or leave the "
    "structure free-free.",
)
@click.option(
    "--max-freq",
    default=f"{DEFAULTS['max_freq_hz']:g} Hz",
    help="Elastic modes up to this frequency enter the response.",
)
@click.option(
    "--duration",
    default=f"{DEFAULTS['duration_s']:g} s",
    help="Length of the response record; band RMS is taken over it, so a transient's band RMS "
    "falls as the record grows.",
)
@click.option("--dt", default=f"{DEFAULTS['dt_s']:g} s", help="Output sample interval.")
@click.option(
    "--requirement",
    type=click.Choice(["iss", "ssp41000", "flat"]),
    default=DEFAULTS["requirement"],
    help="ISS vibratory requirement as NASA PIMS codes it, the continuous SSP 41000 curve, or "
    "the report's flat 1e-5 g.",
)
@click.option(
    "--package-mass",
    default=None,
    cls=Option,
    show_default=f"{DEFAULTS['package_mass_kg'] / LB:g} lb",
    help="Experiment package mass for the isolation advice (a bare number takes the model's "
    "unit system).",
)
@click.option(
    "--package-weight",
    default=None,
    help="The package's weight on Earth instead of its mass (a bare number is lbf).",
)
@click.option(
    "--absorber-mu",
    type=Number(),
    default=None,
    help="Add a vibration absorber of this mass ratio to the report-rule mount.",
)
@click.option("--units", default=None, help="Units of a NASTRAN/UFF model: 'LENGTH,FORCE,TIME'.")
@model_file_options
@click.option(
    "--wtmass",
    type=PositiveFloat(),
    default=None,
    help="NASTRAN PARAM WTMASS of the run (a deck's own PARAM WTMASS must agree).",
)
@click.option(
    "--points",
    "points_file",
    type=PathType(dir_okay=False, path_type=Path),
    default=None,
    help='TOML file naming grids of an imported model (lab = "grid:2001", with kinds).',
)
@click.option(
    "--sources",
    default=None,
    help="Source catalogue (TOML [[source]] tables; 'example' for the shipped illustrative one): "
    "continuous vibratory sources judged in the frequency domain, beside the transient "
    "analysis, or instead of it when no --force is given.",
)
@click.option(
    "--out",
    "out_dir",
    type=PathType(file_okay=False, path_type=Path),
    default=Path("microg-analysis"),
    show_default=True,
    help="Directory for report.html, figures and results.json (replaced as a whole).",
)
@click.option("--json", "as_json", is_flag=True, help="Also print results.json to stdout.")
@click.option(
    "--static",
    is_flag=True,
    help="Write report.html with PNG figures only (no interactive 3-D view, ~4.8 MB smaller).",
)
@click.option("--no-progress", is_flag=True, help="Hide the progress bar.")
def analyze(
    model: str,
    forces: tuple[str, ...],
    at_points: tuple[str, ...],
    directions: tuple[str, ...],
    observe: tuple[str, ...],
    damping: float,
    method: str,
    plane: str,
    functions: int,
    elements: int,
    n_modes: int | None,
    gravity_gradient: bool,
    max_freq: str,
    duration: str,
    dt: str,
    requirement: str,
    package_mass: str | None,
    package_weight: str | None,
    absorber_mu: float | None,
    units: str | None,
    wtmass: float | None,
    points_file: Path | None,
    subcase: int | None,
    superelement: int | None,
    coupled_mass: str | None,
    sources: str | None,
    out_dir: Path,
    as_json: bool,
    static: bool,
    no_progress: bool,
) -> None:
    """Microgravity environment of MODEL (a model file or a shipped name; default: ioc).

    Solves the free-free modes, applies the crew disturbances, assesses the acceleration at
    the observed points against the ISS vibratory requirement, and advises isolation.
    Writes OUT/report.html (self-contained), PNG figures and OUT/results.json.
    """
    import microg
    from microg.cli._progress import progress_bar
    from microg.errors import InputError

    _check_out(out_dir)
    ctx = click.get_current_context()
    if method == "ritz" and given(ctx, "elements"):
        raise InputError("applies to --method fem only", where="--elements")
    if method == "fem" and given(ctx, "functions"):
        raise InputError("applies to --method ritz only", where="--functions")
    if package_mass is not None and package_weight is not None:
        raise InputError(
            "give --package-mass or --package-weight, not both", where="--package-mass"
        )
    kwargs: dict[str, Any] = {}
    kwargs["n"] = functions if method == "ritz" else elements
    for key, value in (
        ("damping", damping),
        ("max_freq", max_freq),
        ("duration", duration),
        ("dt", dt),
        ("n_modes", n_modes),
        ("absorber_mu", absorber_mu),
    ):
        if value is not None:
            kwargs[key] = value
    with flag_errors({"package_mass": "--package-weight"}):
        if package_weight is not None:
            kwargs["package_mass"] = _weight_to_mass(package_weight)
    if package_mass is not None:
        kwargs["package_mass"] = package_mass
    stages = ["structure", "modes", "response", "assessment", "isolation", "report"]
    command = "microg " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    reader = {
        k: v
        for k, v in (
            ("units", units),
            ("wtmass", wtmass),
            ("points", points_file),
            ("subcase", subcase),
            ("superelement", superelement),
            ("coupled_mass", coupled_mass),
        )
        if v is not None
    }
    flags = {**FLAGS, "n": "--functions" if method == "ritz" else "--elements"}
    with flag_errors(flags):
        bar = progress_bar(len(stages), "microg analyze", hide=no_progress)

        def progress(stage: str) -> None:
            bar.set_postfix_str(stage)
            if stage != "structure":
                bar.update(1)

        mdl = microg.load_model(model, **reader)
        result = microg.analyze(
            mdl,
            force=list(forces) or None,
            sources=sources,
            at=list(at_points) or None,
            direction=list(directions) or None,
            observe=list(observe) or None,
            method=method,
            plane=plane,
            requirement=requirement,
            gravity_gradient=gravity_gradient,
            progress=progress,
            command=command,
            **kwargs,
        )
        progress("report")
        path, text = write_outputs(result, out_dir, static=static)
    bar.update(1)
    bar.close()
    if as_json:
        click.echo(text)
    else:
        summary(result, path)


def _check_out(out_dir: Path) -> None:
    from microg.errors import InputError

    if str(out_dir).strip() == "":
        raise InputError("an empty directory name", where="--out", fix="name a directory")
    try:
        from microg._io import check_writable
    except ImportError:
        return
    check_writable(out_dir, where="--out")


def write_outputs(result: Any, out_dir: Path, *, static: bool = False) -> tuple[Path, str]:
    """Render figures, HTML and JSON, and write them into ``out_dir`` as one run.

    ``static``: the report with PNG figures only.  Returns the directory and the JSON text
    (``result.to_dict()``, what ``--json`` prints).
    """
    from microg._io import dumps, write_output_files
    from microg.report.analysis import report_files

    summary = result.to_dict()
    text = dumps(summary)
    files: dict[str, bytes | str] = {
        **report_files(result, summary, static=static),
        "results.json": text,
    }
    return write_output_files(out_dir, files, where="--out"), text


#: what each headline verdict rests on (the criteria lines printed under it)
_BASIS = {
    "complies": "every judged criterion below complies",
    "fails": "a judged criterion below fails",
    "undecided": "no judged criterion below fails, but the record cannot decide one: not a pass",
}


def summary(result: Any, path: Path) -> None:
    """The console summary: modes, each point's verdict per criterion, isolation, warnings."""
    from microg.analysis.result import report_criterion
    from microg.environment.criteria import HEADLINE

    m = result.modes
    el = (m.omega > 0) & result.used
    click.echo(
        f"{result.model}: {m.n_rigid} rigid-body modes, {int(el.sum())} elastic modes up to "
        f"{result.options.max_freq_hz:g} Hz (first {m.freq_hz[el][0]:.4g} Hz)"
        if el.any()
        else f"{result.model}: {m.n_rigid} rigid-body modes"
    )
    if "mass_formulation_note" in result.meta:
        click.echo(f"  mass: {result.meta['mass_formulation_note']}")
    for name, ob in result.observations.items():
        a = ob.assessment
        click.echo(
            f"  {name}: {HEADLINE[a.verdict]} with {a.requirement} ({_BASIS[a.verdict]}; peak "
            f"{a.peak_accel_g:.3g} g, RMS {a.rms_accel_g:.3g} g)"
        )
        for c in (*a.criteria, report_criterion(a)):
            click.echo(f"    {c.line()}")
        click.echo(f"    isolation: {ob.isolation.status}: {ob.isolation.note}")
    fd = result.frequency_domain
    if fd is not None:
        click.echo(f"  frequency domain ({len(fd.sources)} sources, {fd.requirement}):")
        for i, name in enumerate(fd.points):
            d = fd.point_dict(name)
            wb = d["worst_band"]
            worst = (
                f"worst band {wb['center_hz']:.3g} Hz ({wb['axis']}), margin {wb['margin']:.3g}"
                if wb
                else "no response"
            )
            verdict = "complies" if fd.complies[i] else "DOES NOT COMPLY"
            click.echo(f"    {name}: {verdict}; {worst}")
    for w in result.warnings:
        click.echo(f"  warning: {w}")
    written(path)
