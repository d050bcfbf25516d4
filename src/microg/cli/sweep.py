"""``microg sweep STUDY.toml``: every case of a study, serially or on a Dask cluster.

Parse -> :func:`microg.study.sweep` -> summary -> ``OUT/report.html``.  The results stream to
``OUT/results.zarr`` as they are computed; running the same command again resumes a sweep
that stopped (finished blocks are not recomputed).
"""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import click

from microg.cli._common import Option, num, written
from microg.cli._errors import flag_errors
from microg.cli.params import Integer, Number, PathType

__all__ = ["sweep"]

#: library parameter -> command-line option
FLAGS = {
    "out": "--out",
    "workers": "--workers",
    "scheduler": "--scheduler",
    "timeout": "--timeout",
    "heatmap": "--heatmap",
    "restart": "--restart",
}


@click.command(short_help="Every case of a study by superposition.")
@click.argument("study_file", metavar="STUDY.toml", type=PathType(path_type=Path))
@click.option(
    "--out",
    "out_dir",
    type=PathType(file_okay=False, path_type=Path),
    default=Path("microg-sweep"),
    show_default=True,
    help="Directory for results.zarr (written as the sweep goes; resumed if it holds this "
    "study's results) and report.html.",
)
@click.option(
    "--workers",
    type=Integer(1, 1024),
    default=None,
    help="Start a local Dask cluster of N worker processes (one thread each).",
)
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Use a running Dask scheduler, e.g. tcp://host:8786 (see docs/scale.md).",
)
@click.option(
    "--timeout",
    type=Number(0, 3600, min_open=True),
    default=10.0,
    show_default=True,
    help="Seconds to wait for --scheduler to answer and to have a worker.",
)
@click.option(
    "--heatmap",
    default=None,
    metavar="AXIS1,AXIS2",
    cls=Option,
    show_default="at,observe when both vary",
    help="The two axes of the margin heat map.",
)
@click.option(
    "--restart",
    is_flag=True,
    help="Discard results of another study in --out instead of refusing.",
)
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON to stdout.")
@click.option("--no-progress", is_flag=True, help="Hide the progress bar.")
def sweep(
    study_file: Path,
    out_dir: Path,
    workers: int | None,
    scheduler: str | None,
    timeout: float,
    heatmap: str | None,
    restart: bool,
    as_json: bool,
    no_progress: bool,
) -> None:
    """Every case of STUDY.toml, by linearity: one modal solve per model variant.

    The cases are forces x points x directions x observed points x damping x isolators x
    model variants.  Writes OUT/results.zarr (an xarray Dataset, one dimension per axis) as it
    goes and OUT/report.html (worst cases, margin heat map, complying fraction, and the microg
    analyze command that reproduces any case).
    """
    from microg._io import atomic_write_text, dumps
    from microg.cli._progress import progress_bar
    from microg.errors import InputError
    from microg.study import load_study
    from microg.study.run import SweepIncompleteError
    from microg.study.run import sweep as run_sweep
    from microg.study.summary import check_heatmap

    if workers is not None and scheduler is not None:
        raise InputError("give --workers or --scheduler, not both", where="--workers")
    argv = sys.argv[1:] if sys.argv and Path(sys.argv[0]).name.startswith("microg") else None
    command = "microg " + " ".join(shlex.quote(a) for a in argv) if argv else None
    again = command or (
        f"microg sweep {shlex.quote(str(study_file))} --out {shlex.quote(str(out_dir))}"
        + (f" --workers {workers}" if workers else "")
        + (f" --scheduler {shlex.quote(scheduler)}" if scheduler else "")
    )
    study = load_study(study_file)
    with flag_errors(FLAGS):
        dims = check_heatmap(study, heatmap.split(",") if heatmap else None)
    bar = progress_bar(study.n_cases, f"microg sweep {study.name}", hide=no_progress, unit="case")

    def progress(done: int, total: int) -> None:
        bar.update(done - bar.n)

    try:
        with flag_errors(FLAGS):
            result = run_sweep(
                study,
                out_dir,
                workers=workers,
                scheduler=scheduler,
                timeout_s=timeout,
                restart=restart,
                progress=progress,
                resume_hint=f"run the same command again: {again}",
            )
    except SweepIncompleteError as exc:
        bar.close()
        click.echo(f"microg: error: {' '.join(str(exc).split())}", err=True)
        # a stop is never a success: 128 + the signal's number (the shell's convention: 143
        # for SIGTERM, 130 for Ctrl-C), 1 for a failure part-way
        stop = 1 if exc.signal_number is None else 128 + int(exc.signal_number)
        raise click.exceptions.Exit(stop) from None
    bar.close()
    from microg.environment.requirements import requirement
    from microg.report.study import figures, render_sweep

    summary = result.summary(heatmap=dims)
    html = render_sweep(
        summary,
        figures(summary),
        command=command,
        requirement_source=requirement(study.record.requirement).source,
    )
    assert result.out is not None
    try:
        atomic_write_text(result.out / "report.html", html)
    except OSError as exc:
        raise InputError(f"cannot write the report: {exc.strerror or exc}", where="--out") from None
    if as_json:
        click.echo(dumps(summary.to_dict()))
        return
    frac = summary.complying_fraction
    click.echo(
        f"{study.name}: {summary.cases:,} cases"
        + (f" ({result.resumed_blocks} blocks resumed)" if result.resumed_blocks else "")
        + (f", {100 * frac:.1f} % comply with {summary.requirement}" if frac is not None else "")
    )
    click.echo(f"  exact peaks certified for {summary.peaks_certified:,} of {summary.cases:,} "
               f"cases (record.peaks = {study.record.peaks}; the others' verdicts do not "
               "depend on them: their peaks are the sampled record's)")  # fmt: skip
    for row in summary.worst_list()[:10]:
        c = row["case"]
        label = ", ".join(f"{k}={c[k]}" for k in c if len(study.coords[k]) > 1) or "the case"
        click.echo(f"  worst at {c['observe']}: margin {num(row['margin'])} ({label})")
    for w in summary.warnings:
        click.echo(f"  warning: {w}")
    written(result.out)
