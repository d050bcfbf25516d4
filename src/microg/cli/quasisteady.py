"""``microg quasi-steady``: the quasi-steady environment (gravity gradient, rotation, drag).

Parse -> :func:`microg.environment.quasisteady.quasi_steady` -> format.  The library's errors
name its parameters; :data:`FLAGS` maps them back to the options.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import click

from microg.cli._common import Option, num, written
from microg.cli.params import Integer, Number, PathType, QuantityType
from microg.environment.drag import AP_DEFAULT, CD_DEFAULT, DATE_DEFAULT, F107_DEFAULT
from microg.environment.orbit import INCLINATION_DEG
from microg.errors import InputError

__all__ = ["quasi_steady", "FLAGS"]

#: library parameter -> command-line option
FLAGS = {
    "radius": "--radius/--altitude",
    "inclination": "--inclination",
    "raan": "--raan",
    "samples": "--samples",
    "attitude": "--attitude",
    "omega": "--rate",
    "alpha": "--angular-acceleration",
    "ballistic_coefficient": "--ballistic-coefficient",
    "area": "--area",
    "cd": "--cd",
    "mass": "--mass",
    "atmosphere": "--atmosphere",
    "date": "--date",
    "f107": "--f107",
    "f107a": "--f107a",
    "ap": "--ap",
    "points": "--observe",
    "lvlh_from_station": "--attitude",
}

_NUMBER = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(.*?)\s*$")


def _derived(text: str, where: str, unit_si: str, base: str, times: str) -> float:
    """A quantity of a unit the registry has no dimension name for (kg/m^2, m^2, rad/s^2).

    The number is read as one number; the unit is checked by converting ``1 unit*times`` as
    ``base`` (e.g. kg/m^2 * m^2 is a mass).  A bare number takes ``unit_si``.
    """
    from microg.units import parse_quantity

    m = _NUMBER.match(str(text))
    if m is None:
        raise InputError(
            f"{text!r} is not a number with a unit", where=where, fix=f"write e.g. '100 {unit_si}'"
        )
    number, unit = float(m.group(1)), m.group(2) or unit_si
    try:
        factor = parse_quantity(f"1 {unit}*{times}", base, where=where)
    except InputError:
        raise InputError(
            f"{text!r} is not a quantity in {unit_si} (or a unit of the same kind)",
            where=where,
            fix=f"write e.g. '100 {unit_si}'",
        ) from None
    return number * factor


def _vector(text: str | None, where: str, *, accel: bool = False) -> list[float] | None:
    """Three components ``"x y z [unit]"`` (rad/s or rad/s^2 by default)."""
    from microg.units import LIMITS, parse_quantity

    if text is None:
        return None
    parts = [p for p in re.split(r"[,\s]+", str(text).strip()) if p]
    unit = None
    if len(parts) == 4:
        unit = parts.pop()
    if len(parts) != 3:
        raise InputError(
            f"expected three components, got {text!r}",
            where=where,
            fix="write e.g. '0 1.1e-3 0' or '0 0.063 0 deg/s'",
        )
    out = []
    for p in parts:
        if accel:
            out.append(
                _derived(f"{p} {unit or 'rad/s^2'}", where, "rad/s^2", "angular_frequency", "s")
            )
        else:
            q = parse_quantity(f"{p} {unit or 'rad/s'}", "angular_frequency", where=where)
            if abs(q) > LIMITS["angular_frequency"]:  # a rate, however small, may be 0 or tiny
                raise InputError(
                    f"{p} {unit or 'rad/s'} is beyond the physical limit of "
                    f"{num(LIMITS['angular_frequency'])} rad/s",
                    where=where,
                    fix="check the value and its unit",
                )
            out.append(q)
    return out


@click.command(name="quasi-steady", short_help="Quasi-steady acceleration (below 0.01 Hz).")
@click.argument("model")
@click.option(
    "--attitude",
    type=click.Choice(["lvlh", "inertial", "rate"]),
    default="lvlh",
    show_default=True,
    help="LVLH hold, fixed in inertial space (aligned with LVLH at the first sample), or a "
    "constant body rate (--rate).",
)
@click.option("--rate", default=None, help="Body rate 'wx wy wz [unit]' (bare numbers: rad/s).")
@click.option(
    "--angular-acceleration",
    "angular_acceleration",
    default=None,
    help="Angular acceleration 'ax ay az [unit]' (bare numbers: rad/s^2), with --attitude rate.",
)
@click.option(
    "--radius",
    default=None,
    cls=Option,
    show_default="the model's orbit",
    help="Orbit radius, e.g. '6778 km' (bare number: m).",
)
@click.option(
    "--altitude",
    default=None,
    help="Orbit altitude above the equatorial radius, e.g. '400 km' (bare number: m).",
)
@click.option(
    "--inclination",
    type=QuantityType("angle", "deg"),
    default=f"{INCLINATION_DEG:g} deg",
    help="Orbit inclination, e.g. '51.6 deg' (bare number: degrees).",
)
@click.option(
    "--raan",
    type=QuantityType("angle", "deg"),
    default="0 deg",
    help="Right ascension of the ascending node (bare number: degrees).",
)
@click.option("--samples", type=Integer(), default=180, help="Samples over one orbit.")
@click.option(
    "--ballistic-coefficient",
    "ballistic_coefficient",
    default=None,
    help="m / (Cd A), e.g. '100 kg/m^2' (or give --area and --cd).",
)
@click.option("--area", default=None, help="Reference area for drag, e.g. '900 m^2'.")
@click.option(
    "--cd",
    type=Number(),
    default=None,
    cls=Option,
    show_default=f"{CD_DEFAULT:g}",
    help="Drag coefficient with --area.",
)
@click.option(
    "--mass",
    default=None,
    cls=Option,
    show_default="the model's",
    help="Mass for drag with --area, e.g. '4.2e5 kg'.",
)
@click.option(
    "--atmosphere",
    type=click.Choice(["msis", "exponential"]),
    default="msis",
    show_default=True,
    help="NRLMSIS 2.1 (pymsis) or the exponential atmosphere (Vallado 2013 Table 8-4).",
)
@click.option(
    "--date",
    default=None,
    cls=Option,
    show_default=DATE_DEFAULT,
    help="UTC date and time of the atmosphere, e.g. 2024-03-20T12:00:00.",
)
@click.option(
    "--f107",
    type=Number(),
    default=None,
    cls=Option,
    show_default=f"{F107_DEFAULT:g}",
    help="Daily F10.7 solar flux, sfu.",
)
@click.option(
    "--f107a",
    type=Number(),
    default=None,
    cls=Option,
    show_default="--f107",
    help="81-day mean F10.7, sfu.",
)
@click.option(
    "--ap",
    type=Number(),
    default=None,
    cls=Option,
    show_default=f"{AP_DEFAULT:g}",
    help="Daily Ap index.",
)
@click.option(
    "--observe",
    "points",
    multiple=True,
    cls=Option,
    show_default="every named point",
    help="Named point to report (repeatable).",
)
@click.option(
    "--elements",
    type=Integer(1, 200),
    default=20,
    help="Frame elements per beam of the map's sample points.",
)
@click.option(
    "--out",
    "out_dir",
    type=PathType(file_okay=False, path_type=Path),
    default=None,
    help="Directory for quasi-steady.json, the map (CSV), its figure and report.html (replaced "
    "as a whole).",
)
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@click.option(
    "--static",
    is_flag=True,
    help="Write report.html with the PNG figure only (no interactive 3-D map, ~4.8 MB smaller).",
)
def quasi_steady(
    model: str,
    attitude: str,
    rate: str | None,
    angular_acceleration: str | None,
    radius: str | None,
    altitude: str | None,
    inclination: float,
    raan: float,
    samples: int,
    ballistic_coefficient: str | None,
    area: str | None,
    cd: float | None,
    mass: str | None,
    atmosphere: str,
    date: str | None,
    f107: float | None,
    f107a: float | None,
    ap: float | None,
    points: tuple[str, ...],
    elements: int,
    out_dir: Path | None,
    as_json: bool,
    static: bool,
) -> None:
    """Quasi-steady acceleration (below 0.01 Hz) of MODEL at its named points and the CM.

    Gravity gradient (the exact two-body difference about the centre of mass), rotation of the
    attitude, and drag (NRLMSIS 2.1 density); orbital averages and peaks, in the station frame
    and in LVLH; a map over the structure with the 1 micro-g zone; the verdict against the
    ISS quasi-steady requirement (1 micro-g at internal payload locations, NASA-CR-205357).
    """
    from microg.cli._errors import flag_errors
    from microg.environment import quasisteady as qs
    from microg.models.toml import load_station
    from microg.units import parse_quantity

    if out_dir is not None:
        from microg._io import check_writable

        check_writable(out_dir, where="--out")
    if radius is not None and altitude is not None:
        raise InputError("give --radius or --altitude, not both", where="--radius")
    if attitude != "rate" and (rate is not None or angular_acceleration is not None):
        raise InputError(
            "applies to --attitude rate only", where="--rate", fix="add --attitude rate"
        )
    if attitude == "rate" and rate is None:
        raise InputError("--attitude rate needs the body rate", where="--rate")
    station = load_station(model)
    with flag_errors(FLAGS):
        if radius is not None:
            r = parse_quantity(radius, "length", where="radius", default_unit="m")
        elif altitude is not None:
            h = parse_quantity(altitude, "length", where="radius", default_unit="m")
            r = qs.EARTH_EQUATORIAL_RADIUS_M + h
        else:
            r = station.orbit.radius
        orbit = qs.OrbitInputs(
            radius_m=r,
            mu_m3_per_s2=station.orbit.mu,
            inclination_deg=math.degrees(inclination),
            raan_deg=math.degrees(raan),
            n_samples=samples,
        )
        att = qs.Attitude(
            kind=attitude,
            omega_rad_s=_vector(rate, "omega"),
            alpha_rad_per_s2=_vector(angular_acceleration, "alpha", accel=True),
        )
        drag = qs.Drag(
            ballistic_coefficient_kg_per_m2=None
            if ballistic_coefficient is None
            else _derived(ballistic_coefficient, "ballistic_coefficient", "kg/m^2", "mass", "m^2"),
            area_m2=None if area is None else _derived(area, "area", "m^2", "length", "m^-1"),
            cd=cd,
            mass_kg=None if mass is None else parse_quantity(mass, "mass", where="mass"),
        )
        given = {"date": date, "f107": f107, "f107a": f107a, "ap": ap}
        defaulted = tuple(k for k, v in given.items() if v is None)
        atm = qs.AtmosphereInputs(
            model=atmosphere,
            date_utc=date or qs.DATE_DEFAULT,
            f107_sfu=qs.F107_DEFAULT if f107 is None else f107,
            f107a_sfu=(f107 if f107 is not None else qs.F107_DEFAULT) if f107a is None else f107a,
            ap=qs.AP_DEFAULT if ap is None else ap,
            defaulted=defaulted,
        )
        result = qs.quasi_steady(
            station,
            orbit=orbit,
            attitude=att,
            drag=drag,
            atmosphere=atm,
            points=list(points) or None,
            elements=elements,
        )
    data = result.to_dict()
    if out_dir is not None:
        _write(result, data, out_dir, static=static)
    if as_json:
        from microg._io import dumps

        click.echo(dumps(data))
    else:
        _summary(result, out_dir)


def _write(result: Any, data: dict[str, Any], out_dir: Path, *, static: bool = False) -> None:
    import io

    from microg._io import dumps, write_run_directory
    from microg.report.environment import render_quasi_steady

    files: dict[str, bytes | str] = {"quasi-steady.json": dumps(data)}
    png = None
    if result.map is not None:
        files["quasi-steady-map.csv"] = result.map.to_csv()
        buf = io.BytesIO()
        result.plot().savefig(buf, format="png", dpi=110)
        png = files["quasi-steady-map.png"] = buf.getvalue()
    chart = None if static or result.map is None else result.plot3d()
    files["report.html"] = render_quasi_steady(data, png, chart)
    write_run_directory(out_dir, files, where="--out")


def _summary(result: Any, out_dir: Path | None) -> None:
    from microg.units import G0

    ug = 1e6 / G0
    cm = result.center_of_mass_m
    click.echo(
        f"{result.model}: centre of mass ({num(cm[0])}, {num(cm[1])}, {num(cm[2])}) m, "
        f"mass {num(result.mass_kg)} kg; orbit radius {num(result.orbit.radius_m / 1e3)} km, "
        f"n = {num(result.mean_motion_rad_s)} rad/s; attitude {result.attitude.kind}"
    )
    rho = result.density_kg_per_m3
    click.echo(
        f"atmosphere: {result.atmosphere_model}, density {num(rho.min())}-{num(rho.max())} kg/m^3"
    )
    limit = result.requirement.limit_g * 1e6
    click.echo(
        f"{'point':>14} {'x':>8} {'y':>8} {'z':>8}  {'avg ax':>9} {'avg ay':>9} {'avg az':>9}"
        f" {'peak |a|':>9}  verdict (limit {limit:g} ug, micro-g below)"
    )
    for name, p in result.points.items():
        a = p.accel_mps2 * ug
        verdict = {True: "complies", False: "EXCEEDS", None: "undecided"}[p.complies]
        if p.complies is False and p.peak_lower_bound_mps2 is not None:
            verdict += f" whatever the drag (>= {p.peak_lower_bound_mps2 * ug:.3g})"
        click.echo(
            f"{name:>14} {p.position_m[0]:8.3g} {p.position_m[1]:8.3g} {p.position_m[2]:8.3g}  "
            f"{a[0]:9.3g} {a[1]:9.3g} {a[2]:9.3g} {p.peak_magnitude_mps2 * ug:9.3g}  {verdict}"
        )
    if result.map is not None:
        m = result.map.to_dict()
        click.echo(
            f"map: {m['n_within_limit']} of {m['n_samples']} sample points within {limit:g} ug"
            + (
                f"; ideal zone half-widths y {num(m['zone_half_width_m']['y'])} m, "
                f"z {num(m['zone_half_width_m']['z'])} m about the CM"
                if m["zone_half_width_m"]
                else ""
            )
        )
    overall = {True: "complies", False: "DOES NOT COMPLY", None: "UNDECIDED"}[result.complies]
    if result.complies is False and result.drag.beta(result.mass_kg) is None:
        overall += " whatever the drag (no drag input needed)"
    click.echo(f"verdict: {overall}")
    for w in result.warnings:
        click.echo(f"warning: {w}")
    if out_dir is not None:
        written(out_dir)
