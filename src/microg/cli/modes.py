"""``microg modes``: natural frequencies, rigid-body modes, modal and effective masses.

Parse -> :func:`microg.load_model` and :func:`microg.solve_modes` -> format.  Frame models
asked for a plane report only the modes with more than half their kinetic energy in it
(:func:`microg.dynamics.planar.in_plane_modes`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from microg import defaults
from microg.cli._common import (
    MODEL_FILE_FLAGS,
    Option,
    discretisation_options,
    given,
    model_file_options,
    num,
    preset_option,
    written,
)
from microg.cli.params import Integer, PathType, PositiveFloat

__all__ = ["modes"]

FLAGS = {
    "method": "--method",
    "plane": "--plane",
    "n": "--elements/--functions",
    "n_modes": "--n-modes",
    "units": "--units",
    "wtmass": "--wtmass",
    "points": "--points",
    "constrained": "--constrained",
    **MODEL_FILE_FLAGS,
}


def _default_modes() -> int:
    return defaults.N_MODES


def _effective_percent(m: Any) -> dict[str, Any]:
    """Effective mass per rigid-body direction, percent of the total (``Modes``)."""
    return {d: 100.0 * v for d, v in m.effective_mass_fraction.items()}


@click.command(short_help="Natural frequencies, modal and effective masses of MODEL.")
@click.argument("model")
@preset_option({k: k for k in ("method", "plane", "functions")})
@click.option(
    "--method",
    type=click.Choice(["fem", "ritz"]),
    default=defaults.METHOD,
    help="3-D frame finite elements, or assumed modes (the report's method). Imported modal "
    "models ignore it.",
)
@click.option(
    "--plane",
    type=click.Choice(["3d", "xz", "yz"]),
    default=defaults.PLANE,
    help="Ritz: the report's planar model in this plane, or the 3-D assumed-modes model. "
    "FE: report only the modes with more than half their kinetic energy in this plane.",
)
@discretisation_options
@click.option(
    "--n-modes",
    "n_modes",
    type=Integer(1, 2000),
    default=None,
    cls=Option,
    show_default=f"{defaults.N_MODES} of a sparse model, all of a dense one",
    help="Number of lowest modes, at least the rigid-body ones.",
)
@click.option(
    "--gravity-gradient/--free-free",
    default=False,
    help="Restrain the rigid rotations by gravity gradient (libration), as the report's "
    "Appendix B does, or leave the structure free-free.",
)
@click.option("--units", default=None, help="Units of a NASTRAN/UFF file: 'LENGTH,FORCE,TIME'.")
@click.option(
    "--wtmass",
    type=PositiveFloat(),
    default=None,
    help="NASTRAN PARAM WTMASS of the run (a deck's own PARAM WTMASS must agree).",
)
@click.option(
    "--points",
    type=PathType(dir_okay=False, path_type=Path),
    default=None,
    help='TOML file naming grids of an imported model (lab = "grid:2001").',
)
@click.option(
    "--uff",
    "uff_out",
    type=PathType(dir_okay=False, path_type=Path),
    default=None,
    help="Also write the modes as UFF datasets 15+55 (+164 units) to this file.",
)
@model_file_options
@click.option(
    "--constrained",
    is_flag=True,
    help="A NASTRAN deck or frame model: apply its SPCs (the clamped run) instead of the "
    "free-free structure.",
)
@click.option("--json", "as_json", is_flag=True, help="Print the modes as JSON.")
def modes(
    model: str,
    method: str,
    plane: str,
    functions: int,
    elements: int,
    n_modes: int | None,
    gravity_gradient: bool,
    units: str | None,
    wtmass: float | None,
    points: Path | None,
    uff_out: Path | None,
    subcase: int | None,
    coupled_mass: str | None,
    superelement: int | None,
    constrained: bool,
    as_json: bool,
) -> None:
    """Natural frequencies and mode properties of MODEL (a model file or a shipped name).

    Rigid-body modes are exact (omega = 0).  Modal mass and effective mass as defined in
    microg.dynamics.modes.Modes; effective mass is (phi^T M r)^2 per rigid-body direction r
    (zero for the elastic modes of a free-free structure, which are M-orthogonal to the rigid
    motions; non-zero where gravity gradient restrains a rotation).
    """
    import numpy as np

    import microg
    from microg._io import check_writable, dumps
    from microg.cli._errors import flag_errors
    from microg.errors import InputError
    from microg.structure.discretize import discretize

    ctx = click.get_current_context()
    if method == "ritz" and given(ctx, "elements"):
        raise InputError("applies to --method fem only", where="--elements")
    if method == "fem" and given(ctx, "functions"):
        raise InputError("applies to --method ritz only", where="--functions")
    if uff_out is not None:  # before any work: a file that cannot be written is bad input
        uff_out = check_writable(uff_out, where="--uff", directory=False)
    reader = (
        ("units", units),
        ("wtmass", wtmass),
        ("points", points),
        ("subcase", subcase),
        ("coupled_mass", coupled_mass),
        ("superelement", superelement),
    )
    options = {k: v for k, v in reader if v is not None}
    with flag_errors(FLAGS):
        mdl = microg.load_model(model, **options)
        fem_plane = method == "fem" and plane != "3d"
        structure = discretize(
            mdl,
            method,
            plane="3d" if fem_plane else plane,
            n=elements if method == "fem" else functions,
            gravity_gradient=gravity_gradient,
            constrained=constrained,
        )
        want = n_modes
        if structure.is_sparse and want is None:
            want = _default_modes()
        if fem_plane:
            from microg.dynamics.planar import in_plane_modes

            count = want or _default_modes()
            ask = min(max(3 * count, count + 6), structure.n_dof)
            m = in_plane_modes(structure, microg.solve_modes(structure, n_modes=ask), plane, count)
        else:
            m = microg.solve_modes(structure, n_modes=want)
        if uff_out is not None:
            from microg.models.modal import ModalModel
            from microg.models.uff import write_uff_modes

            # an imported modal model is written from its own grids and shapes
            write_uff_modes(mdl if isinstance(mdl, ModalModel) else m, uff_out)
    plane_out = structure.plane if structure.plane else (plane if fem_plane else None)
    name = getattr(mdl, "name", None) or structure.meta.get("model", model)
    replaced = structure.meta.get("replaced_rigid") or {"count": 0, "max_file_freq_hz": None}
    mass = _mass_formulation(structure.meta, method)
    if as_json:
        data = m.to_dict()
        out = {"model": name, "plane": plane_out, **data, "replaced_rigid": replaced}
        if mass is not None:
            out["mass_formulation"] = mass
        warnings = list(structure.meta.get("warnings", ()))
        if warnings:
            out["warnings"] = warnings
        click.echo(dumps(out))
        return
    pct = _effective_percent(m)
    dirs = list(pct)
    where = f", plane {plane_out}" if plane_out else ""
    click.echo(f"{name}: {m.n_modes} modes ({m.method}{where}, {structure.n_dof} coordinates)")
    if mass is not None:
        click.echo(f"  mass: {mass['note']}")
    if replaced and replaced.get("count"):
        click.echo(
            f"  {replaced['count']} of the file's modes replaced by exact rigid-body modes "
            f"(largest file frequency among them {num(replaced.get('max_file_freq_hz', 0))} Hz)"
        )
    head = f"{'#':>3} {'omega (rad/s)':>14} {'f (Hz)':>11} {'rigid':>5} {'modal mass (kg)':>16}"
    head += "".join(f" {'eff ' + d + ' %':>9}" for d in dirs)
    click.echo(head)
    unstable = np.asarray(m.unstable, bool)
    for j in range(m.n_modes):
        kind = "yes" if m.rigid[j] else ("UNST" if unstable[j] else "no")
        if unstable[j]:  # an imaginary frequency: omega = i * growth rate
            rate = float(np.asarray(m.growth_rate, float)[j])
            om, fr = f"{num(rate)}i", f"{num(rate / (2 * np.pi))}i"
        else:
            om, fr = f"{num(m.omega[j])}", f"{num(m.freq_hz[j])}"
        row = f"{j + 1:>3} {om:>14} {fr:>11} {kind:>5} {num(m.modal_mass[j]):>16}"
        row += "".join(f" {_pct(pct[d][j]):>9}" for d in dirs)
        click.echo(row)
    from microg.dynamics.modes import MODAL_MASS_NORMALISATION

    click.echo(f"  modal mass: {MODAL_MASS_NORMALISATION}")
    over = np.flatnonzero(m.modal_mass_exceeds_model) + 1
    if over.size:
        click.echo(
            f"  note: modes {', '.join(map(str, over))} have a modal mass above the model's "
            f"{structure.total_mass:.6g} kg: they barely move any point with a position (their "
            "motion is on coordinates without one, such as dropped scalar points), so that "
            "modal mass is not a physical mass"
        )
    for note in m.notes:
        click.echo(f"  note: {note}")
    if uff_out is not None:
        written(uff_out)
    for warning in structure.meta.get("warnings", ()):
        click.echo(f"  warning: {warning}")


def _mass_formulation(meta: Any, method: str) -> dict[str, str] | None:
    """The frame model's mass formulation and what chose it (None for other models)."""
    from microg.models.graph_model import MASS_NOTES

    form = meta.get("mass_formulation") if method == "fem" else None
    if form is None:
        return None
    note = dict(meta.get("graph_meta") or {}).get("mass_formulation_note")
    return {"name": form, "note": note or f"{form} ({MASS_NOTES.get(form, '')})"}


def _pct(v: float) -> str:
    """A percentage; below 1e-9 % it is the rounding of M-orthogonality, shown as 0."""
    return "0" if abs(v) < 1e-9 else f"{num(v)}"
