"""``microg reproduce``: the seed report's Appendix C, Table 4 and Figures 3-4, with errata."""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import TYPE_CHECKING

import click

from microg import defaults
from microg.cli._common import Option, num, written
from microg.cli.params import PathType, QuantityType
from microg.seed.ioc import CASES
from microg.units import LBF

if TYPE_CHECKING:
    from microg.seed.reproduce import Reproduction

__all__ = ["reproduce"]

#: library parameter -> command-line option
FLAGS = {"z_e": "--z-e", "z_a": "--z-a", "cases": "--case"}

_MAIN_BODY = "on the rigid main body, -126.66 ft <= z <= 0 (Eq. 3.1 holds there only)"


class _RecordedCommand(click.Command):
    """A command that keeps its own argument list, for the provenance's command line."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        ctx.meta["microg.reproduce.argv"] = list(args)
        return super().parse_args(ctx, args)


@click.command(cls=_RecordedCommand, short_help="The seed report recomputed, with errata.")
@click.option(
    "--out",
    "out_dir",
    type=PathType(file_okay=False, path_type=Path),
    default=Path("microg-reproduce"),
    show_default=True,
    help="Directory written as a whole: report.html (self-contained), results.json, "
    "figure3.png, figure4.png and lab-response.png.",
)
@click.option(
    "--json",
    "as_json",
    is_flag=True,
    help="Print results.json to stdout instead of the summary (the file is written too).",
)
@click.option(
    "--f0",
    type=QuantityType("force", "lbf"),
    default=f"{defaults.CREW_F0_N / LBF:g} lbf",
    help="Crew force peak f0 (Eq. 2.16), > 0, e.g. '111 N' (bare number: lbf).",
)
@click.option(
    "--t1",
    type=QuantityType("time", "s", minimum=0.0, strict=True),
    default=f"{defaults.CREW_T1_S:g} s",
    help="End of the push-off ramp t1 (Eq. 2.16), > 0 (bare number: s).",
)
@click.option(
    "--t13",
    type=QuantityType("time", "s"),
    default=f"{defaults.CREW_T13_S:g} s",
    help="Start of the landing t13, >= t1 (bare number: s).",
)
@click.option(
    "--t14",
    type=QuantityType("time", "s"),
    default=f"{defaults.CREW_T14_S:g} s",
    help="End of the landing t14, > t13 (bare number: s).",
)
@click.option(
    "--z-e",
    "z_e",
    type=QuantityType("length", "ft"),
    default="-55 ft",
    show_default=True,
    help=f"Observation point z_e along the keel axis from the keel joint, {_MAIN_BODY} "
    "(bare number: ft).",
)
@click.option(
    "--z-a",
    "z_a",
    type=QuantityType("length", "ft"),
    default="-55 ft",
    show_default=True,
    help=f"Crew force point z_a along the keel axis from the keel joint, {_MAIN_BODY} "
    "(bare number: ft).",
)
@click.option(
    "--case",
    "cases",
    type=click.Choice(list(CASES)),
    multiple=True,
    cls=Option,
    show_default="all four",
    help="Restrict to a case of Appendix C (repeatable): X-Z or Y-Z plane, with or without "
    "the orbiter (C-1..C-4).",
)
def reproduce(
    out_dir: Path,
    as_json: bool,
    f0: float,
    t1: float,
    t13: float,
    t14: float,
    z_e: float,
    z_a: float,
    cases: tuple[str, ...],
) -> None:
    """Recompute the seed report's Appendix C, Table 4 and Figures 3-4, with an errata.

    The seed report: "Analytical determination of space station response to crew motion
    and design of suspension system for microgravity experiments" (NASA/ASEE).  Every
    printed value is compared with its recomputation within a stated tolerance, and every
    difference is explained.  Writes OUT/report.html (self-contained), OUT/results.json,
    OUT/figure3.png, OUT/figure4.png and OUT/lab-response.png (Eq. 2.20b at z_e).  Every
    computed value follows the crew-force and point options; the printed accelerations are
    compared only with the report's own inputs (the defaults).
    """
    from microg._io import check_writable, dumps, write_run_directory
    from microg.cli._errors import flag_errors
    from microg.dynamics.crew import CrewPushoff
    from microg.plotting.common import png_bytes
    from microg.plotting.seed import figure3, figure4, point_response_figure
    from microg.report.html import png_data_uri, render_reproduction
    from microg.seed.ioc import FT
    from microg.seed.reproduce import ReproduceOptions
    from microg.seed.reproduce import reproduce as run

    argv = click.get_current_context().meta.get("microg.reproduce.argv", [])
    command = shlex.join(["microg", "reproduce", *argv])
    check_writable(out_dir, "--out")  # before computing: a bad --out fails at once
    crew = CrewPushoff.checked(f0, t1, t13, t14)
    with flag_errors(FLAGS):
        rep = run(ReproduceOptions(crew, z_e, z_a), cases=cases or None, command=command)
    fig3 = png_bytes(figure3(rep.curves))
    fig4 = png_bytes(figure4(rep.curves))
    fig_resp = png_bytes(point_response_figure(rep.point_response, z_e / FT, z_a / FT))
    html = render_reproduction(rep, png_data_uri(fig3), png_data_uri(fig4), png_data_uri(fig_resp))
    text = dumps(rep.contract())

    files: dict[str, bytes | str] = {
        "figure3.png": fig3,
        "figure4.png": fig4,
        "lab-response.png": fig_resp,
        "report.html": html,
        "results.json": text,
    }
    path = write_run_directory(out_dir, files, where="--out")
    if as_json:
        click.echo(text)
    else:
        _summary(rep, path)


def _summary(rep: Reproduction, path: Path) -> None:
    """The console summary: Table 4 printed and recomputed, the agreement, the errata."""
    click.echo("Table 4 (printed -> recomputed)")
    for case, t4 in rep.table4.items():
        for j, b in enumerate(t4.bending, 1):
            click.echo(
                f"  {case:14s} bending {j}: w {num(b.printed_omega)} -> {num(b.omega)} rad/s, "
                f"a_e {num(b.printed_accel_g)} -> {num(b.accel_g)} g"
            )
        lib = t4.libration
        click.echo(
            f"  {case:14s} libration: w {num(lib.printed_omega)} -> {num(lib.omega)} rad/s, "
            f"a_e {num(lib.printed_accel_g)} -> {num(lib.accel_g)} g"
        )
    if rep.agreement is not None:
        click.echo(rep.agreement.headline)
    click.echo(f"{len(rep.errata)} errata entries")
    written(path)
