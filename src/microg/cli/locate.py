"""``microg locate`` and ``microg optimize``: where to put the laboratory (conclusions 6, 7, 9).

Both commands only parse options (units at the boundary), call :mod:`microg.location.amap` and
print or write its result objects.
"""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from microg._io import dumps
from microg.cli.params import PositiveFloat, QuantityType
from microg.errors import InputError
from microg.units import FT, G0, parse_quantity

__all__ = ["locate", "optimize", "MovableType", "CarryType"]

_FT = FT
_LATERAL = {"xz": "x", "yz": "y"}


class MovableType(click.ParamType):
    """``NAME=LO:HI`` -> ``(name, lo, hi)``, lengths with units (bare numbers: ft)."""

    name = "NAME=LO:HI"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        text = str(value)
        if "=" not in text:
            self.fail(f"expected NAME=LO:HI (e.g. 'Horizontal lab=-91ft:-5ft'), got {text!r}")
        name, rng = text.rsplit("=", 1)
        parts = rng.split(":")
        if not name.strip() or len(parts) != 2:
            self.fail(f"expected NAME=LO:HI (e.g. 'Horizontal lab=-91ft:-5ft'), got {text!r}")
        try:
            lo = parse_quantity(parts[0], "length", where="LO", default_unit="ft")
            hi = parse_quantity(parts[1], "length", where="HI", default_unit="ft")
        except InputError as exc:
            self.fail(f"{text!r}: {exc}")
        if not lo < hi:
            self.fail(f"need LO < HI, got {text!r}")
        return (name.strip(), lo, hi)


class CarryType(click.ParamType):
    """``POINT=MASS`` -> ``(point, mass)``."""

    name = "POINT=MASS"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        text = str(value)
        point, sep, mass = text.partition("=")
        if not sep or not point.strip() or not mass.strip():
            self.fail(f"expected POINT=MASS (e.g. 'lab=Horizontal lab'), got {text!r}")
        return (point.strip(), mass.strip())


def _force_options(f):
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


def _crew(f0: float, t1: float, t13: float, t14: float):
    from microg.dynamics.crew import CrewPushoff

    return CrewPushoff.checked(f0, t1, t13, t14)


def _map_json(amap, loc, model: str, crew) -> dict:
    g = 1.0 / G0
    lt = amap.long_time_peak
    return {
        "model": model,
        "method": amap.method,
        "plane": amap.plane,
        "crew_point": amap.crew_point,
        "crew_position_m": amap.crew_position,
        "direction": amap.direction,
        "force": {"f0_N": crew.f0, "t1_s": crew.t1, "t13_s": crew.t13, "t14_s": crew.t14},
        "zeta": amap.zeta,
        "include_rigid": amap.include_rigid,
        "window_s": list(amap.window),
        "n_timepts": amap.n_timepts,
        "per_mode_exact": amap.exact_per_mode,
        "modes": [
            {
                "omega": float(w),
                "freq_hz": float(w / (2 * np.pi)),
                "rigid": bool(r),
                "elastic": bool(e),
            }
            for w, r, e in zip(amap.omega, amap.rigid, amap.elastic, strict=True)
        ],
        "fundamental": (
            None
            if amap.fundamental is None
            else {"index": amap.fundamental, "omega": float(amap.omega[amap.fundamental])}
        ),
        "nodes": [
            {"component": n.component, "position_m": n.position, "distance_m": n.distance}
            for n in amap.nodes
        ],
        "best_location": {
            "component": loc.component,
            "position_m": loc.position,
            "measure": loc.measure,
            "peak_g": loc.peak_g,
        },
        "samples": [
            {
                "component": str(amap.component[i]),
                "position_m": amap.positions[i],
                "total_peak_g": float(amap.total_peak[i] * g),
                "elastic_peak_g": float(amap.elastic_peak[i] * g),
                "peak_bound_g": float(amap.peak_bound[i] * g),
                "long_time_peak_g": None if lt is None else float(lt[i] * g),
                "per_mode_g": amap.per_mode[:, i] * g,
            }
            for i in range(amap.n_samples)
        ],
    }


@click.command()
@click.argument("model")
@click.option("--crew", "crew_point", required=True, help="Named point where the crew pushes.")
@click.option(
    "--direction",
    type=click.Choice(["x", "y", "z"]),
    default=None,
    help="Force direction (default: the plane's lateral axis, x for xz, y for yz).",
)
@click.option(
    "--plane",
    type=click.Choice(["xz", "yz"]),
    default="xz",
    show_default=True,
    help="Ritz: the planar model; FE: sets the default direction only.",
)
@click.option("--method", type=click.Choice(["ritz", "fem"]), default="ritz", show_default=True)
@click.option("--functions", type=click.IntRange(1, 40), default=None, help="Ritz: per beam (1).")
@click.option("--elements", type=click.IntRange(1, 2000), default=None, help="FE: per beam (10).")
@click.option(
    "--n-modes", "n_modes", type=click.IntRange(min=1), default=None, help="Modes used (FE: 20)."
)
@_force_options
@click.option(
    "--damping",
    type=PositiveFloat(0.0, strict=False),
    default=0.0,
    show_default=True,
    help="Modal damping ratio zeta, 0 <= zeta < 1 (0: exact [A]max per mode).",
)
@click.option("--no-rigid", "no_rigid", is_flag=True, help="Leave out the rigid-body modes.")
@click.option(
    "--on",
    "component",
    default=None,
    help="Restrict the best location to this body or beam (e.g. main).",
)
@click.option(
    "--measure",
    type=click.Choice(["total", "elastic", "bound"]),
    default="total",
    show_default=True,
    help="Peak minimised for the best location.",
)
@click.option("--json", "as_json", is_flag=True, help="Print the map as JSON.")
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Write OUT/map.json and OUT/map.png.",
)
def locate(
    model: str,
    crew_point: str,
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
    as_json: bool,
    out_dir: Path | None,
) -> None:
    """Where to put the laboratory: peak acceleration along MODEL from a crew push-off.

    Per mode, Eq. 3.1 (|phi_j(s)| |phi_j(crew)| f0 [A_j]max / (M_jj omega_j t1)); the total
    is the peak over time of the modal sum.  Also the nodes of the fundamental elastic
    mode (report conclusion 7, Figure 9) and the quietest sample.
    """
    from microg.cli.modes import build_structure, solve_for_cli
    from microg.location.amap import acceleration_map, best_location, map_figure

    if not damping < 1:
        raise InputError(f"must be < 1, got {damping:g}", where="--damping")
    crew = _crew(f0, t1, t13, t14)
    direction = direction or _LATERAL[plane]
    if method == "ritz" and direction != _LATERAL[plane]:
        raise InputError(
            f"the {plane} assumed-modes model moves along {_LATERAL[plane]} only",
            where="--direction",
            fix=f"use --direction {_LATERAL[plane]}, another --plane, or --method fem",
        )
    _, structure = build_structure(model, method, plane, functions, elements)
    structure.point(crew_point)  # unknown point: one line listing the known ones
    m = solve_for_cli(structure, method, None, n_modes)
    amap = acceleration_map(
        structure, m, crew_point, direction, crew, zeta=damping, include_rigid=not no_rigid
    )
    loc = best_location(amap, component=component, measure=measure)
    label = str(structure.meta.get("model", model))
    data = _map_json(amap, loc, label, crew)
    text = dumps(data)
    if out_dir is not None:
        from microg._io import write_output_files
        from microg.plotting.seed import png_bytes

        png = png_bytes(map_figure(amap, measure=measure, title=f"{label}: {method}", best=loc))
        path = write_output_files(out_dir, {"map.json": text, "map.png": png}, where="--out")
    if as_json:
        click.echo(text)
        return
    _summary(amap, loc, label)
    if out_dir is not None:
        click.echo(f"map written to {path / 'map.json'} and {path / 'map.png'}")


def _summary(amap, loc, label: str) -> None:
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
            f" = ({p[0] / _FT:.4g}, {p[1] / _FT:.4g}, {p[2] / _FT:.4g}) ft"
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
    click.echo(
        f"best location ({loc.measure}) on {loc.component}: ({p[0]:.4g}, {p[1]:.4g}, {p[2]:.4g}) m"
        f" = z {p[2] / _FT:.4g} ft, {loc.peak_g:.3g} g"
    )


@click.command()
@click.argument("model")
@click.option("--experiment", "experiment_point", required=True, help="Named experiment site.")
@click.option("--crew", "crew_point", required=True, help="Named point where the crew pushes.")
@click.option(
    "--movable",
    "movable",
    type=MovableType(),
    multiple=True,
    help="NAME=LO:HI: let mass NAME (or CARRIER/NAME) move over LO..HI (z on a body, s on a "
    "beam; bare numbers: ft).  Repeatable; overrides the file's ranges.",
)
@click.option(
    "--carry",
    "carry",
    type=CarryType(),
    multiple=True,
    help="POINT=MASS: the named point moves with the movable mass (repeatable).",
)
@click.option("--plane", type=click.Choice(["xz", "yz"]), default="xz", show_default=True)
@click.option(
    "--functions",
    type=click.IntRange(1, 40),
    default=1,
    show_default=True,
    help="Admissible functions per beam.",
)
@_force_options
@click.option("--seed", type=int, default=0, show_default=True, help="Optimiser seed.")
@click.option(
    "--maxiter",
    type=click.IntRange(1, 10000),
    default=60,
    show_default=True,
    help="Differential-evolution generations.",
)
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
def optimize(
    model: str,
    experiment_point: str,
    crew_point: str,
    movable: tuple[tuple[str, float, float], ...],
    carry: tuple[tuple[str, str], ...],
    plane: str,
    functions: int,
    f0: float,
    t1: float,
    t13: float,
    t14: float,
    seed: int,
    maxiter: int,
    as_json: bool,
) -> None:
    """Move MODEL's movable masses to minimise the crew-induced peak at the experiment site.

    Objective (report conclusion 9): Eq. 3.1 summed over the elastic modes at the experiment
    site, exact [A]max, assumed-modes model rebuilt for every trial layout.
    """
    from microg.location.amap import optimize_layout
    from microg.models.toml import load_station

    crew = _crew(f0, t1, t13, t14)
    station = load_station(model)
    overrides = {name: (lo, hi) for name, lo, hi in movable}
    res = optimize_layout(
        station,
        experiment_point,
        crew_point,
        crew,
        movable=overrides,
        carry=dict(carry),
        plane=plane,
        n_functions=functions,
        seed=seed,
        maxiter=maxiter,
    )
    g = 1.0 / G0
    data = {
        "model": station.name,
        "plane": plane,
        "experiment_point": experiment_point,
        "crew_point": crew_point,
        "masses": [
            {
                "key": mm.key,
                "kind": mm.kind,
                "bounds_m": list(mm.bounds),
                "initial_m": float(x0),
                "optimal_m": float(x1),
            }
            for mm, x0, x1 in zip(res.masses, res.initial, res.optimal, strict=True)
        ],
        "objective_initial_g": res.objective_initial * g,
        "objective_optimal_g": res.objective_optimal * g,
        "per_mode_initial_g": res.per_mode_initial * g,
        "per_mode_optimal_g": res.per_mode_optimal * g,
        "omega_initial": res.omega_initial,
        "omega_optimal": res.omega_optimal,
        "n_evaluations": res.n_evaluations,
        "success": res.success,
        "message": res.message,
    }
    if as_json:
        click.echo(dumps(data))
        return
    click.echo(
        f"{station.name}: peak at {experiment_point!r} from a push-off at {crew_point!r} "
        f"({plane}, {functions} function(s) per beam, {res.n_evaluations} evaluations)"
    )
    for mm, x0, x1 in zip(res.masses, res.initial, res.optimal, strict=True):
        coord = "z" if mm.kind == "body" else "s"
        click.echo(
            f"  {mm.key}: {coord} {x0:.4g} m ({x0 / _FT:.4g} ft) -> {x1:.4g} m ({x1 / _FT:.4g} ft)"
            f"  [range {mm.bounds[0]:.4g} .. {mm.bounds[1]:.4g} m]"
        )
    click.echo(
        f"objective: {res.objective_initial * g:.4g} g -> {res.objective_optimal * g:.4g} g"
        f" (x{res.improvement:.3g} lower)"
    )
