"""``microg locate`` and ``microg optimize``: where to put the laboratory (conclusions 6, 7, 9).

Both commands parse options (units at the boundary), call :func:`microg.location.amap.locate`
or :func:`microg.location.layout.optimize_layout`, and print or write their results
(``--json`` is the result's ``to_dict()``).  Defaults live in the library.  Library errors
name parameters (``crew``, ``experiment``, ``movable``...); :func:`_as_flags` maps them to
this command's options.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import click
import numpy as np

from microg._io import dumps
from microg.cli.params import Integer, PathType, PositiveFloat, QuantityType
from microg.errors import InputError
from microg.location.amap import DEFAULTS as LOCATE_DEFAULTS
from microg.location.layout import DEFAULTS as LAYOUT_DEFAULTS
from microg.location.layout import MAX_GENERATIONS
from microg.units import FT, G0

__all__ = ["locate", "optimize", "MovableType", "CarryType", "FLAGS"]

#: library parameter names -> options of these commands
FLAGS: dict[str, str] = {
    "crew": "--crew",
    "crew_point": "--crew",
    "experiment": "--experiment",
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
    "force": "--f0",
    "f0": "--f0",
    "t1": "--t1",
    "t13": "--t13",
    "t14": "--t14",
    "units": "--units",
    "wtmass": "--wtmass",
    "points": "--points",
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


def _force_options(f: Callable[..., Any]) -> Callable[..., Any]:
    opts = [
        click.option(
            "--f0",
            type=QuantityType("force", "lbf"),
            default="25 lbf",
            show_default=True,
            help="Crew force peak (Eq. 2.16; bare number: lbf).",
        ),
        click.option(
            "--t1",
            type=QuantityType("time", "s", minimum=0.0, strict=True),
            default="1 s",
            show_default=True,
            help="Push-off ramp duration (bare number: s).",
        ),
        click.option(
            "--t13",
            type=QuantityType("time", "s"),
            default="13 s",
            show_default=True,
            help="Landing start, >= t1 (bare number: s).",
        ),
        click.option(
            "--t14",
            type=QuantityType("time", "s"),
            default="14 s",
            show_default=True,
            help="Landing end, > t13 (bare number: s).",
        ),
    ]
    for o in reversed(opts):
        f = o(f)
    return f


def _crew(f0: float, t1: float, t13: float, t14: float) -> Any:
    from microg.dynamics.crew import CrewPushoff

    return CrewPushoff.checked(f0, t1, t13, t14)


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


@click.command()
@click.argument("model")
@click.option(
    "--crew",
    "crew_point",
    default=None,
    help="Named point where the crew pushes (default: the model's first crew point).",
)
@click.option(
    "--direction",
    default=None,
    help="Force direction: x, y, z, -x... or 'X Y Z' (default: the plane's lateral axis).",
)
@click.option(
    "--plane",
    type=click.Choice(["xz", "yz", "3d"]),
    default=LOCATE_DEFAULTS["plane"],
    show_default=True,
    help="Ritz: the planar model, or 3d; FE: sets the default direction only.",
)
@click.option(
    "--method",
    type=click.Choice(["ritz", "fem"]),
    default=LOCATE_DEFAULTS["method"],
    show_default=True,
)
@click.option("--functions", type=Integer(1, 40), default=None, help="Ritz: per beam (1).")
@click.option("--elements", type=Integer(1, 2000), default=None, help="FE: per beam (10).")
@click.option(
    "--n-modes",
    "n_modes",
    type=Integer(min=1),
    default=None,
    help="Modes used (default: the solver's).",
)
@_force_options
@click.option(
    "--damping",
    type=PositiveFloat(0.0, strict=False),
    default=LOCATE_DEFAULTS["zeta"],
    show_default=True,
    help="Modal damping ratio zeta, 0 <= zeta < 1 (0: exact [A]max per mode).",
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
    help="Write OUT/map.json and OUT/map.png.",
)
def locate(
    model: str,
    crew_point: str | None,
    direction: str | None,
    plane: str,
    method: str,
    functions: int | None,
    elements: int | None,
    n_modes: int | None,
    f0: float,
    t1: float,
    t13: float,
    t14: float,
    damping: float,
    no_rigid: bool,
    component: str | None,
    measure: str,
    units: str | None,
    wtmass: float | None,
    points_file: Path | None,
    as_json: bool,
    out_dir: Path | None,
) -> None:
    """Where to put the laboratory: peak acceleration along MODEL from a crew push-off.

    Per mode, Eq. 3.1 (|phi_j(s)| |phi_j(crew)| f0 [A_j]max / (M_jj omega_j t1)); the total
    is the peak over time of the modal sum.  Also the nodes of the fundamental elastic
    mode (report conclusion 7, Figure 9) and the quietest sample.

    MODEL is a station (TOML or a shipped name) or an imported model: a NASTRAN .op2/.op4,
    a UFF .unv/.uff, microg's own .npz modal-model file (mapped over every grid, named
    points added as 'points': --on points picks the quietest of them), or a .bdf/.dat deck
    (solved by microg's frame FE, nodes of the fundamental along its straight chains of
    beams and rods).  --crew accepts grid:N for imported models; --method, --functions and
    --elements apply to stations only.
    """
    from microg.location.amap import locate as run_locate

    if method == "ritz" and elements is not None:
        raise InputError("applies to --method fem only", where="--elements")
    if method == "fem" and functions is not None:
        raise InputError("applies to --method ritz only", where="--functions")
    if out_dir is not None:
        _check_writable(out_dir, "--out")
    n_flag = "--functions" if method == "ritz" else "--elements"
    with _as_flags({"n": n_flag}):
        result = run_locate(
            model,
            crew_point,
            force=_crew(f0, t1, t13, t14),
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
        )
    text = dumps(result.to_dict())
    if out_dir is not None:
        from microg._io import write_output_files
        from microg.plotting.common import png_bytes

        png = png_bytes(result.plot())
        path = write_output_files(out_dir, {"map.json": text, "map.png": png}, where="--out")
    if as_json:
        click.echo(text)
        return
    _summary(result)
    if out_dir is not None:
        click.echo(f"map written to {path / 'map.json'} and {path / 'map.png'}")


def _summary(result: Any) -> None:
    amap, loc, label = result.amap, result.best, result.model
    g = 1.0 / G0
    where = f", plane {amap.plane}" if amap.plane else ""
    click.echo(
        f"{label} ({amap.method}{where}): push-off at {amap.crew_point!r} along "
        f"{'xyz'[int(np.argmax(np.abs(amap.direction)))]}, {amap.n_samples} samples, "
        f"window {amap.window[0]:g}-{amap.window[1]:.4g} s"
    )
    if amap.fundamental is not None:
        click.echo(f"fundamental elastic mode: omega = {amap.omega[amap.fundamental]:.6g} rad/s")
    for n in amap.nodes:
        p = n.position
        click.echo(
            f"  node on {n.component}: ({p[0]:.4g}, {p[1]:.4g}, {p[2]:.4g}) m"
            f" = ({p[0] / FT:.4g}, {p[1] / FT:.4g}, {p[2] / FT:.4g}) ft"
        )
    for comp in dict.fromkeys(amap.component.tolist()):
        sel = amap.component == comp
        tot = amap.total_peak[sel] * g
        el = amap.elastic_peak[sel] * g
        click.echo(
            f"  {comp:>12}: total peak {tot.min():.3g} .. {tot.max():.3g} g, "
            f"elastic {el.min():.3g} .. {el.max():.3g} g"
        )
    p = loc.position
    name = f" {loc.label}" if loc.label else ""
    click.echo(
        f"best location ({loc.measure}) on {loc.component}{name}: "
        f"({p[0]:.4g}, {p[1]:.4g}, {p[2]:.4g}) m = z {p[2] / FT:.4g} ft, {loc.peak_g:.3g} g"
    )
    for w in result.warnings:
        click.echo(f"warning: {w}")


@click.command()
@click.argument("model")
@click.option(
    "--experiment",
    "experiment_point",
    default=None,
    help="Named experiment site (default: the model's first experiment point).",
)
@click.option(
    "--crew",
    "crew_point",
    default=None,
    help="Named point where the crew pushes (default: the model's first crew point).",
)
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
    type=click.Choice(["xz", "yz"]),
    default=LAYOUT_DEFAULTS["plane"],
    show_default=True,
)
@click.option(
    "--functions",
    type=Integer(1, 40),
    default=None,
    help="Admissible functions per beam (default 1, the report's model).",
)
@_force_options
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
    experiment_point: str | None,
    crew_point: str | None,
    movable: tuple[tuple[str, str, str], ...],
    carry: tuple[tuple[str, str], ...],
    plane: str,
    functions: int | None,
    f0: float,
    t1: float,
    t13: float,
    t14: float,
    measure: str,
    seed: int,
    maxiter: int,
    no_progress: bool,
    as_json: bool,
) -> None:
    """Move MODEL's movable masses to minimise the crew-induced peak at the experiment site.

    Objective (report conclusion 9): the site's peak acceleration over time, rigid-body
    modes included (--measure), on the assumed-modes model of each trial layout.
    """
    from microg.cli._progress import progress_bar
    from microg.location.layout import optimize_layout
    from microg.models.toml import load_station

    with _as_flags():
        crew = _crew(f0, t1, t13, t14)
    station = load_station(model)
    overrides = {name: (lo, hi) for name, lo, hi in movable}
    bar = progress_bar(maxiter, "microg optimize", hide=no_progress, unit="gen")

    def progress(generation: int, total: int) -> None:
        bar.update(generation - bar.n)

    try:
        with _as_flags({"n": "--functions"}):
            res = optimize_layout(
                station,
                experiment_point,
                crew_point,
                crew,
                movable=overrides,
                carry=dict(carry),
                plane=plane,
                n=functions,
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
        f"{res.n_evaluations} evaluations)"
    )
    for mm, x0, x1 in zip(res.masses, res.initial, res.optimal, strict=True):
        coord = "z" if mm.kind == "body" else "s"
        click.echo(
            f"  {mm.key}: {coord} {x0:.4g} m ({x0 / FT:.4g} ft) -> {x1:.4g} m ({x1 / FT:.4g} ft)"
            f"  [range {mm.bounds[0]:.4g} .. {mm.bounds[1]:.4g} m]"
        )
    a, b = res.initial_peak, res.optimal_peak
    gain = res.improvement
    gain_text = f"x{gain:.3g} lower" if np.isfinite(gain) else "to zero"
    click.echo(
        f"{res.measure} peak (objective): {res.objective_initial * g:.4g} g -> "
        f"{res.objective_optimal * g:.4g} g ({gain_text})"
    )
    click.echo(
        f"  total {a.total_mps2 * g:.4g} -> {b.total_mps2 * g:.4g} g; its parts (peaks over "
        f"time, not additive): rigid-body {a.rigid_mps2 * g:.4g} -> {b.rigid_mps2 * g:.4g} g, "
        f"elastic {a.elastic_mps2 * g:.4g} -> {b.elastic_mps2 * g:.4g} g"
    )
