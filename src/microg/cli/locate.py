"""``microg locate`` and ``microg optimize``: where to put the laboratory (conclusions 6, 7, 9).

Both commands parse options (units at the boundary), call :func:`microg.location.amap.locate`
or :func:`microg.location.layout.optimize_layout`, and print or write their results
(``--json`` is the result's ``to_dict()``).  Defaults are :mod:`microg.defaults`' (those of
``microg analyze``); ``--at``, ``--observe`` and ``--force`` are ``analyze``'s words and force
grammar.  Library errors name parameters (``crew``, ``experiment``, ``movable``...);
:func:`_as_flags` maps them to this command's options.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import click
import numpy as np

from microg import defaults
from microg._io import dumps
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
from microg.cli.params import Integer, Number, PathType, PositiveFloat
from microg.errors import InputError
from microg.location.amap import DEFAULTS as LOCATE_DEFAULTS
from microg.location.layout import DEFAULTS as LAYOUT_DEFAULTS
from microg.location.layout import MAX_GENERATIONS
from microg.structure.ritz import MAX_FUNCTIONS
from microg.units import FT, G0

__all__ = ["locate", "optimize", "MovableType", "CarryType", "FLAGS"]

#: library parameter names -> options of these commands
FLAGS: dict[str, str] = {
    "crew": "--at",
    "crew_point": "--at",
    "experiment": "--observe",
    "movable": "--movable",
    "carry": "--carry",
    "direction": "--direction",
    "zeta": "--damping",
    "on": "--on",
    "measure": "--measure",
    "plane": "--plane",
    "method": "--method",
    "n_modes": "--n-modes",
    "maxiter": "--maxiter",
    "seed": "--seed",
    "force": "--force",
    "units": "--units",
    "wtmass": "--wtmass",
    "points": "--points",
    **MODEL_FILE_FLAGS,
}


def _flag(where: str | None, extra: dict[str, str]) -> str | None:
    """``where`` with a leading parameter name replaced by its option (else unchanged)."""
    if not where:
        return where
    table = {**FLAGS, **extra}
    head = where.split(" ", 1)[0].split("[", 1)[0]
    if head in table:
        return table[head] + where[len(head) :]
    return where


@contextlib.contextmanager
def _as_flags(extra: dict[str, str] | None = None) -> Iterator[None]:
    """Re-raise a library InputError whose ``where`` is a parameter with the option's name."""
    try:
        yield
    except InputError as exc:
        where = _flag(exc.where, extra or {})
        if where == exc.where:
            raise
        raise type(exc)(exc.what, where=where, fix=exc.fix) from None


class MovableType(click.ParamType):
    """``NAME=LO:HI`` -> ``(name, lo, hi)`` texts; lengths are read with the model's units."""

    name = "NAME=LO:HI"

    def convert(self, value: Any, param: Any, ctx: Any) -> tuple[str, str, str]:
        """``(name, lo, hi)`` texts of ``NAME=LO:HI``; a tuple passes through."""
        from microg.location.layout import parse_movable

        if isinstance(value, tuple):
            return value
        try:
            return parse_movable(str(value))
        except InputError as exc:
            self.fail(f"{exc.what} ({exc.fix})" if exc.fix else exc.what, param, ctx)


class CarryType(click.ParamType):
    """``POINT=MASS`` -> ``(point, mass)``."""

    name = "POINT=MASS"

    def convert(self, value: Any, param: Any, ctx: Any) -> tuple[str, str]:
        """``(point, mass)`` texts of ``POINT=MASS``; a tuple passes through."""
        if isinstance(value, tuple):
            return value
        text = str(value)
        point, sep, mass = text.partition("=")
        if not sep or not point.strip() or not mass.strip():
            self.fail(f"expected POINT=MASS (e.g. 'lab=Horizontal lab'), got {text!r}", param, ctx)
        return (point.strip(), mass.strip())


#: preset key -> the parameter of ``locate`` and ``optimize``
PRESET_PARAMS = {k: k for k in ("method", "plane", "damping", "functions")}


def _push_options(what: str) -> Callable[[Any], Any]:
    """``--at``, ``--force`` and ``--direction``, as in ``microg analyze``."""

    def decorate(f: Callable[..., Any]) -> Callable[..., Any]:
        opts = [
            click.option(
                "--at",
                "at_point",
                default=None,
                cls=Option,
                show_default="the model's first crew point",
                help=f"Named point where the --force acts{what}.",
            ),
            click.option(
                "--force",
                "force",
                default=defaults.FORCE,
                help="Disturbance, as in microg analyze: crew-pushoff, "
                "crew-pushoff:f0=40lbf,t1=0.5s (bare numbers in the model's unit system), a "
                "library activity (foot-pushoff-max, ...) or a CSV file.",
            ),
            click.option(
                "--direction",
                default=None,
                cls=Option,
                show_default="x (y for --plane yz)",
                help="Force direction: x, y, z, -x, ... or 'dx dy dz'; a planar model moves "
                "along its lateral axis only.",
            ),
        ]
        for o in reversed(opts):
            f = o(f)
        return f

    return decorate


def _check_writable(path: Path, where: str) -> None:
    """Fail now, not after the computation, when ``path`` cannot hold output files.

    Uses ``microg._io.check_writable`` when it exists; otherwise creates the directory (and
    a temporary file in it) and removes what it created.
    """
    from microg import _io

    check = getattr(_io, "check_writable", None)
    if callable(check):
        check(path, where)
        return
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{str(path)!r} exists and is not a directory", where=where)
    missing = []
    p = path
    while not p.exists() and p != p.parent:
        missing.append(p)
        p = p.parent
    try:
        path.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".microg-check.", dir=path)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise InputError(
            f"cannot write {exc.filename or path}: {exc.strerror or exc}",
            where=where,
            fix="choose a writable directory",
        ) from None
    finally:
        for d in missing:  # deepest first
            with contextlib.suppress(OSError):
                d.rmdir()


def _unit_system(station: Any, model: str) -> str | None:
    """The model's declared unit system (``[station] units``), or None.

    ``Station.unit_system`` when the model loader provides it; otherwise read from the
    model file's ``[station]`` table (the file has already been validated by the loader).
    """
    if hasattr(station, "unit_system"):
        return station.unit_system
    import tomllib
    from importlib import resources

    from microg.models.toml import shipped_models

    if model in shipped_models():
        text = resources.files("microg").joinpath("data", f"{model}.toml").read_text("utf-8")
    else:
        text = Path(model).read_text(encoding="utf-8")
    units = tomllib.loads(text).get("station", {}).get("units")
    return str(units) if units else None


@click.command(short_help="Where to put the laboratory: the acceleration map.")
@click.argument("model")
@preset_option(PRESET_PARAMS)
@_push_options("")
@click.option(
    "--method",
    type=click.Choice(["fem", "ritz"]),
    default=LOCATE_DEFAULTS["method"],
    help="3-D frame finite elements, or assumed modes (stations only).",
)
@click.option(
    "--plane",
    type=click.Choice(["3d", "xz", "yz"]),
    default=LOCATE_DEFAULTS["plane"],
    help="--method ritz: the 3-D assumed-modes model, or the report's planar model; otherwise "
    "it sets the default direction only.",
)
@discretisation_options
@click.option(
    "--n-modes",
    "n_modes",
    type=Integer(min=1),
    default=None,
    cls=Option,
    show_default=f"{defaults.N_MODES} of a sparse model, all of a dense one",
    help="Lowest modes used.",
)
@click.option(
    "--damping",
    type=Number(),
    default=LOCATE_DEFAULTS["zeta"],
    help="Modal damping ratio of the elastic modes, 0 <= zeta < 1 (0: the exact [A]max per mode).",
)
@click.option("--no-rigid", "no_rigid", is_flag=True, help="Leave out the rigid-body modes.")
@click.option(
    "--on",
    "component",
    default=None,
    help="Restrict the best location to this body or beam (e.g. main); imported models: "
    "points (the named points), grids (a modal model's grids) or grid (a deck's nodes).",
)
@click.option(
    "--measure",
    type=click.Choice(["total", "elastic", "bound"]),
    default=LOCATE_DEFAULTS["measure"],
    show_default=True,
    help="Peak minimised for the best location.",
)
@click.option(
    "--units", default=None, help="Units of a NASTRAN/UFF model file: 'LENGTH,FORCE,TIME'."
)
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
    help='TOML file naming grids of an imported model (crew = "grid:55").',
)
@click.option("--json", "as_json", is_flag=True, help="Print the map as JSON.")
@click.option(
    "--out",
    "out_dir",
    type=PathType(file_okay=False, path_type=Path),
    default=None,
    help="Write OUT/map.json, OUT/map.png and OUT/report.html (the map in 3-D).",
)
@click.option(
    "--static",
    is_flag=True,
    help="Write report.html with the PNG map only (no interactive 3-D map, ~4.8 MB smaller).",
)
def locate(
    model: str,
    at_point: str | None,
    force: str,
    direction: str | None,
    method: str,
    plane: str,
    functions: int,
    elements: int,
    n_modes: int | None,
    damping: float,
    no_rigid: bool,
    component: str | None,
    measure: str,
    units: str | None,
    wtmass: float | None,
    points_file: Path | None,
    subcase: int | None,
    superelement: int | None,
    coupled_mass: str | None,
    as_json: bool,
    out_dir: Path | None,
    static: bool,
) -> None:
    """Where to put the laboratory: peak acceleration along MODEL from a crew push-off.

    Per mode, Eq. 3.1 (|phi_j(s)| |phi_j(crew)| f0 [A_j]max / (M_jj omega_j t1)); the total
    is the peak over time of the modal sum.  Also the nodes of the fundamental elastic
    mode (report conclusion 7, Figure 9) and the quietest sample.

    MODEL is a station (TOML or a shipped name) or an imported model: a NASTRAN .op2/.op4,
    a UFF .unv/.uff, microg's own .npz modal-model file (mapped over every grid, named
    points added as 'points': --on points picks the quietest of them), or a .bdf/.dat deck
    (solved by microg's frame FE, nodes of the fundamental along its straight chains of
    beams and rods).  --at accepts grid:N for imported models; --method, --functions and
    --elements apply to stations only.
    """
    from microg.location.amap import locate as run_locate

    ctx = click.get_current_context()
    if method == "ritz" and given(ctx, "elements"):
        raise InputError("applies to --method fem only", where="--elements")
    if method == "fem" and given(ctx, "functions"):
        raise InputError("applies to --method ritz only", where="--functions")
    if out_dir is not None:
        _check_writable(out_dir, "--out")
    n_flag = "--functions" if method == "ritz" else "--elements"
    with _as_flags({"n": n_flag}):
        result = run_locate(
            model,
            at_point,
            force=force,
            direction=direction,
            method=method,
            plane=plane,
            n=functions if method == "ritz" else elements,
            n_modes=n_modes,
            zeta=damping,
            include_rigid=not no_rigid,
            on=component,
            measure=measure,
            units=units,
            wtmass=wtmass,
            points=points_file,
            subcase=subcase,
            superelement=superelement,
            coupled_mass=coupled_mass,
        )
    text = dumps(result.to_dict())
    if out_dir is not None:
        from microg._io import write_output_files
        from microg.plotting.common import png_bytes
        from microg.report.location import render_locate

        png = png_bytes(result.plot())
        command = " ".join(["microg", *sys.argv[1:]]) if sys.argv else "microg locate"
        html = render_locate(result, png, static=static, command=command)
        files: dict[str, bytes | str] = {"map.json": text, "map.png": png, "report.html": html}
        path = write_output_files(out_dir, files, where="--out")
    if as_json:
        click.echo(text)
        return
    _summary(result)
    if out_dir is not None:
        written(path)


def _summary(result: Any) -> None:
    amap, loc, label = result.amap, result.best, result.model
    g = 1.0 / G0
    where = f", plane {amap.plane}" if amap.plane else ""
    click.echo(
        f"{label} ({amap.method}{where}): push-off at {amap.crew_point!r} along "
        f"{'xyz'[int(np.argmax(np.abs(amap.direction)))]}, {amap.n_samples} samples, "
        f"window {amap.window[0]:g}-{num(amap.window[1])} s"
    )
    if result.mass_formulation is not None:
        click.echo(f"mass: {result.mass_formulation}")
    if amap.fundamental is not None:
        click.echo(f"fundamental elastic mode: omega = {num(amap.omega[amap.fundamental])} rad/s")
    for n in amap.nodes:
        p = n.position
        click.echo(
            f"  node on {n.component}: ({num(p[0])}, {num(p[1])}, {num(p[2])}) m"
            f" = ({num(p[0] / FT)}, {num(p[1] / FT)}, {num(p[2] / FT)}) ft"
        )
    for comp in dict.fromkeys(amap.component.tolist()):
        sel = amap.component == comp
        tot = amap.total_peak[sel] * g
        el = amap.elastic_peak[sel] * g
        click.echo(
            f"  {comp:>12}: total peak {num(tot.min())} .. {num(tot.max())} g, "
            f"elastic {num(el.min())} .. {num(el.max())} g"
        )
    p = loc.position
    name = f" {loc.label}" if loc.label else ""
    click.echo(
        f"best location ({loc.measure}) on {loc.component}{name}: "
        f"({num(p[0])}, {num(p[1])}, {num(p[2])}) m = z {num(p[2] / FT)} ft, {num(loc.peak_g)} g"
    )
    for w in result.warnings:
        click.echo(f"warning: {w}")


@click.command(short_help="Move the movable masses to quieten the experiment site.")
@click.argument("model")
@preset_option(PRESET_PARAMS)
@click.option(
    "--observe",
    "observe",
    default=None,
    cls=Option,
    show_default="the model's first experiment point",
    help="Named experiment site whose peak is minimised.",
)
@_push_options("")
@click.option(
    "--movable",
    "movable",
    type=MovableType(),
    multiple=True,
    help="NAME=LO:HI: let mass NAME (or CARRIER/NAME) move over LO..HI (z on a body, s on a "
    "beam; bare numbers in the model's unit system).  Repeatable; overrides the file's ranges.",
)
@click.option(
    "--carry",
    "carry",
    type=CarryType(),
    multiple=True,
    help="POINT=MASS: the named point moves with the movable mass (repeatable).",
)
@click.option(
    "--plane",
    type=click.Choice(["3d", "xz", "yz"]),
    default=LAYOUT_DEFAULTS["plane"],
    help="The 3-D assumed-modes model, or the report's planar model.",
)
@click.option(
    "--functions",
    type=Integer(1, MAX_FUNCTIONS),
    default=defaults.FUNCTIONS,
    help="Admissible functions per beam and deformation kind.",
)
@click.option(
    "--damping",
    type=Number(),
    default=LAYOUT_DEFAULTS["zeta"],
    help="Modal damping ratio of the elastic modes, 0 <= zeta < 1 (0: the exact [A]max per mode).",
)
@click.option(
    "--measure",
    type=click.Choice(["total", "elastic", "bound"]),
    default=LAYOUT_DEFAULTS["measure"],
    show_default=True,
    help="Objective at the site: total peak (rigid + elastic), elastic part, or bound.",
)
@click.option(
    "--seed", type=Integer(0, 2**32 - 1), default=LAYOUT_DEFAULTS["seed"], show_default=True
)
@click.option(
    "--maxiter",
    type=Integer(1, MAX_GENERATIONS),
    default=LAYOUT_DEFAULTS["maxiter"],
    show_default=True,
    help=f"Differential-evolution generations (at most {MAX_GENERATIONS}).",
)
@click.option("--no-progress", "no_progress", is_flag=True, help="No progress bar.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
def optimize(
    model: str,
    observe: str | None,
    at_point: str | None,
    force: str,
    direction: str | None,
    movable: tuple[tuple[str, str, str], ...],
    carry: tuple[tuple[str, str], ...],
    plane: str,
    functions: int,
    damping: float,
    measure: str,
    seed: int,
    maxiter: int,
    no_progress: bool,
    as_json: bool,
) -> None:
    """Move MODEL's movable masses to minimise the crew-induced peak at the experiment site.

    Objective (report conclusion 9): the site's peak acceleration over time, rigid-body
    modes included (--measure), on the assumed-modes model of each trial layout (re-assembled
    incrementally; a frame model would be re-meshed and re-solved for every trial).
    """
    from microg.cli._progress import progress_bar
    from microg.location.layout import optimize_layout
    from microg.models.toml import load_station

    station = load_station(model)
    overrides = {name: (lo, hi) for name, lo, hi in movable}
    bar = progress_bar(maxiter, "microg optimize", hide=no_progress, unit="gen")

    def progress(generation: int, total: int) -> None:
        bar.update(generation - bar.n)

    try:
        with _as_flags({"n": "--functions"}):
            res = optimize_layout(
                station,
                observe,
                at_point,
                force,
                movable=overrides,
                carry=dict(carry),
                plane=plane,
                n=functions,
                direction=direction,
                zeta=damping,
                measure=measure,
                seed=seed,
                maxiter=maxiter,
                unit_system=_unit_system(station, model) if overrides else None,
                progress=progress,
            )
    finally:
        bar.close()
    if as_json:
        click.echo(dumps(res.to_dict()))
        return
    _optimize_summary(res)


def _optimize_summary(res: Any) -> None:
    from microg.structure.discretize import DEFAULT_FUNCTIONS

    g = 1.0 / G0
    click.echo(
        f"{res.model}: peak at {res.experiment!r} from a push-off at {res.crew!r} "
        f"({res.method} {res.plane}, {res.n or DEFAULT_FUNCTIONS} function(s) per beam, "
        f"damping {num(res.zeta)}, "
        f"{res.n_evaluations} evaluations)"
    )
    for mm, x0, x1 in zip(res.masses, res.initial, res.optimal, strict=True):
        coord = "z" if mm.kind == "body" else "s"
        click.echo(
            f"  {mm.key}: {coord} {num(x0)} m ({num(x0 / FT)} ft) -> "
            f"{num(x1)} m ({num(x1 / FT)} ft)"
            f"  [range {num(mm.bounds[0])} .. {num(mm.bounds[1])} m]"
        )
    a, b = res.initial_peak, res.optimal_peak
    gain = res.improvement
    gain_text = f"x{num(gain)} lower" if np.isfinite(gain) else "to zero"
    click.echo(
        f"{res.measure} peak (objective): {num(res.objective_initial * g)} g -> "
        f"{num(res.objective_optimal * g)} g ({gain_text})"
    )
    click.echo(
        f"  total {num(a.total_mps2 * g)} -> {num(b.total_mps2 * g)} g; its parts (peaks over "
        f"time, not additive): rigid-body {num(a.rigid_mps2 * g)} -> {num(b.rigid_mps2 * g)} g, "
        f"elastic {num(a.elastic_mps2 * g)} -> {num(b.elastic_mps2 * g)} g"
    )
