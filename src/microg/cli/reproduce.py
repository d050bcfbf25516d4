"""``microg reproduce``: the seed report's Appendix C, Table 4 and Figures 3-4, with errata."""

from __future__ import annotations

from pathlib import Path

import click

from microg.cli.params import QuantityType
from microg.seed.ioc import CASES

__all__ = ["reproduce"]


@click.command()
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("microg-reproduce"),
    show_default=True,
    help="Directory for report.html, figure3.png, figure4.png and results.json.",
)
@click.option("--json", "as_json", is_flag=True, help="Also print results.json to stdout.")
@click.option(
    "--f0",
    type=QuantityType("force", "lbf"),
    default="25 lbf",
    show_default=True,
    help="Crew force peak (bare number: lbf).",
)
@click.option(
    "--t1",
    type=QuantityType("time", "s", minimum=0.0, strict=True),
    default="1 s",
    show_default=True,
    help="Push-off ramp duration (bare number: s).",
)
@click.option(
    "--t13",
    type=QuantityType("time", "s"),
    default="13 s",
    show_default=True,
    help="Landing start, >= t1 (bare number: s).",
)
@click.option(
    "--t14",
    type=QuantityType("time", "s"),
    default="14 s",
    show_default=True,
    help="Landing end, > t13 (bare number: s).",
)
@click.option(
    "--z-e",
    "z_e",
    type=QuantityType("length", "ft"),
    default="-55 ft",
    show_default=True,
    help="Observation point z from the keel joint (bare number: ft).",
)
@click.option(
    "--z-a",
    "z_a",
    type=QuantityType("length", "ft"),
    default="-55 ft",
    show_default=True,
    help="Crew force z from the keel joint (bare number: ft).",
)
@click.option(
    "--case",
    "cases",
    type=click.Choice(list(CASES)),
    multiple=True,
    help="Restrict to these cases (repeatable; default: all four).",
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

    Writes OUT/report.html (self-contained), OUT/figure3.png, OUT/figure4.png,
    OUT/lab-response.png (Eq. 2.20b at z_e) and OUT/results.json; every computed value
    follows the crew-force and point options.
    """
    from microg._io import check_writable, dumps, write_run_directory
    from microg.dynamics.crew import CrewPushoff
    from microg.plotting.common import png_bytes, png_data_uri
    from microg.plotting.seed import figure3, figure4, point_response_figure
    from microg.report.html import render_reproduction
    from microg.seed.ioc import FT
    from microg.seed.reproduce import ReproduceOptions
    from microg.seed.reproduce import reproduce as run

    check_writable(out_dir, "--out")  # before computing: a bad --out fails at once
    crew = CrewPushoff.checked(f0, t1, t13, t14)
    rep = run(ReproduceOptions(crew, z_e, z_a))
    if cases:
        rep = type(rep)(
            rep.options,
            {k: v for k, v in rep.appendix_c.items() if k in cases},
            {k: v for k, v in rep.table4.items() if k in cases},
            rep.curves,
            rep.errata,
            rep.model_mass,
            {k: v for k, v in rep.point_response.items() if k in cases},
        )
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


def _summary(rep, path: Path) -> None:
    click.echo("Table 4 (printed -> recomputed)")
    for case, t4 in rep.table4.items():
        for j, b in enumerate(t4.bending, 1):
            click.echo(
                f"  {case:14s} bending {j}: w {b.printed_omega:.4g} -> {b.omega:.4g} rad/s, "
                f"a_e {b.printed_accel_g:.3g} -> {b.accel_g:.3g} g"
            )
        lib = t4.libration
        click.echo(
            f"  {case:14s} libration: w {lib.printed_omega:.4g} -> {lib.omega:.4g} rad/s, "
            f"a_e {lib.printed_accel_g:.3g} -> {lib.accel_g:.3g} g"
        )
    click.echo(f"{len(rep.errata)} errata entries; report written to {path / 'report.html'}")
