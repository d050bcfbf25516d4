"""``microg modes``: natural frequencies, rigid-body modes, modal and effective masses.

The command computes nothing itself: it loads the model, builds the assumed-modes
(:func:`~microg.structure.ritz.build_ritz`) or frame finite-element
(:func:`~microg.structure.fem.build_fem`)
structure, solves it with :func:`microg.dynamics.modes.solve_modes` and prints the result.
"""

from __future__ import annotations

import click
import numpy as np

from microg._io import dumps
from microg.errors import InputError

__all__ = ["modes", "build_structure", "DEFAULT_FEM_MODES"]

#: modes reported by --method fem when --n-modes is not given
DEFAULT_FEM_MODES = 20


def build_structure(
    model: str,
    method: str,
    plane: str | None,
    functions: int | None,
    elements: int | None,
):
    """Load ``model`` and discretise it; option conflicts are InputErrors (exit 2)."""
    from microg.models.toml import load_station

    if method == "ritz" and elements is not None:
        raise InputError("applies to --method fem only", where="--elements")
    if method == "fem" and functions is not None:
        raise InputError("applies to --method ritz only", where="--functions")
    station = load_station(model)
    if method == "ritz":
        from microg.structure.ritz import build_ritz

        ritz_plane = None if plane == "3d" else (plane or "xz")
        return station, build_ritz(station, ritz_plane, functions or 1)
    from microg.structure.fem import build_fem

    return station, build_fem(station, elements_per_beam=elements)


def solve_for_cli(structure, method: str, plane: str | None, n_modes: int | None):
    """Modes of ``structure``; for frame models with ``plane``, only the in-plane modes.

    A frame mode is in ``plane`` when more than half of its kinetic energy is in-plane
    motion (:func:`microg.location.amap.in_plane_fraction`).  ``n_modes`` counts reported modes.
    """
    from microg.dynamics.modes import solve_modes
    from microg.location.amap import in_plane_fraction

    if method == "ritz":
        return solve_modes(structure, n_modes)
    want = n_modes or DEFAULT_FEM_MODES
    if plane is None:
        return solve_modes(structure, want)
    ask = min(max(3 * want, want + 6), structure.n_dof)
    m = solve_modes(structure, ask)
    keep = np.flatnonzero(in_plane_fraction(structure, m, plane) > 0.5)[:want]
    return m.subset(keep)


def _effective_percent(structure, m) -> dict[str, np.ndarray]:
    """Effective mass per direction as a percentage of the station's r^T M r."""
    out = {}
    for d, r in structure.rigid_body.items():
        r = np.asarray(r, float)
        total = float(r @ (structure.mass @ r))
        if d in m.effective_mass and total > 0:
            out[d] = 100.0 * np.asarray(m.effective_mass[d]) / total
    return out


@click.command()
@click.argument("model")
@click.option(
    "--method",
    type=click.Choice(["ritz", "fem"]),
    default="ritz",
    show_default=True,
    help="Assumed modes (the report's method) or 3-D frame finite elements.",
)
@click.option(
    "--plane",
    type=click.Choice(["xz", "yz", "3d"]),
    default=None,
    help="Ritz: the report's planar model in this plane (default xz), or 3d for the "
    "three-dimensional assumed-modes model.  FE: report only the modes with more than half "
    "of their kinetic energy in this plane.",
)
@click.option(
    "--functions",
    type=click.IntRange(1, 16),
    default=None,
    help="Ritz: admissible functions per beam (default 1, the report's model).",
)
@click.option(
    "--elements",
    type=click.IntRange(1, 2000),
    default=None,
    help="FE: minimum elements per beam (default 10; more where masses and joints cut it).",
)
@click.option(
    "--n-modes",
    "n_modes",
    type=click.IntRange(min=1),
    default=None,
    help=f"Number of lowest modes (Ritz default: all; FE default: {DEFAULT_FEM_MODES}).",
)
@click.option("--json", "as_json", is_flag=True, help="Print the modes as JSON.")
def modes(
    model: str,
    method: str,
    plane: str | None,
    functions: int | None,
    elements: int | None,
    n_modes: int | None,
    as_json: bool,
) -> None:
    """Natural frequencies and mode properties of a station MODEL (file or shipped name).

    Rigid-body modes are exact (omega = 0).  Modal mass is the generalized mass of each shape
    scaled to a largest point translation of 1 m; effective mass is (phi^T M r)^2 per
    rigid-body direction r (zero for the elastic modes of a free-free structure, which are
    M-orthogonal to the rigid motions; non-zero where gravity gradient restrains a rotation).
    """
    _, structure = build_structure(model, method, plane, functions, elements)
    if plane == "3d":
        plane = None
    m = solve_for_cli(structure, method, plane, n_modes)
    plane_out = structure.plane if method == "ritz" else plane
    if as_json:
        data = m.to_dict()
        out = {"method": data["method"], "model": structure.meta.get("model", model)}
        out["plane"] = plane_out
        out["modes"] = data["modes"]
        click.echo(dumps(out))
        return
    pct = _effective_percent(structure, m)
    dirs = list(pct)
    label = structure.meta.get("model", model)
    where = f", plane {plane_out}" if plane_out else ""
    click.echo(f"{label}: {m.n_modes} modes ({method}{where}, {structure.n_dof} coordinates)")
    head = f"{'#':>3} {'omega (rad/s)':>14} {'f (Hz)':>11} {'rigid':>5} {'modal mass (kg)':>16}"
    head += "".join(f" {'eff ' + d + ' %':>9}" for d in dirs)
    click.echo(head)
    for j in range(m.n_modes):
        row = (
            f"{j + 1:>3} {m.omega[j]:>14.6g} {m.freq_hz[j]:>11.5g} "
            f"{'yes' if m.rigid[j] else 'no':>5} {m.modal_mass[j]:>16.6g}"
        )
        row += "".join(f" {pct[d][j]:>9.3g}" for d in dirs)
        click.echo(row)
