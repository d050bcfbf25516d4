"""``microg isolate``: transmissibility curves, absorber tuning, mount design, Section 4.2 checks.

The command computes nothing itself; it parses options (units at the boundary), calls
:mod:`microg.isolation` and prints result objects.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any

import click
import numpy as np

from microg._io import dumps
from microg.cli._common import Option, num, written
from microg.cli.params import BandType, PathType, PositiveFloat, QuantityType, RangeType
from microg.units import LBF

__all__ = ["isolate"]

_LBF_PER_N = 1.0 / LBF


#: library parameter -> option, for the one-line errors
FLAGS = {
    "mu": "--mu",
    "mu_max": "--mu-max",
    "band": "--band",
    "omega band": "--omega-band/--freq-band",
    "mass": "--mass/--weight",
    "target": "--target",
}


def _flagged(command: Callable[..., Any]) -> Callable[..., Any]:
    """Run ``command`` with the library's parameter names shown as this group's options."""
    from microg.cli._errors import flag_errors

    @functools.wraps(command)
    def run(*args: Any, **kwargs: Any) -> Any:
        with flag_errors(FLAGS):
            return command(*args, **kwargs)

    return run


def _nonneg_range(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
    if value is not None and value[0] < 0:
        raise click.BadParameter(
            f"need START >= 0 (r^2 is a square), got {value[0]:g}:{value[1]:g}:{value[2]}"
        )
    return value


def _target(ctx: click.Context, param: click.Parameter, value: float) -> float:
    if not (0 < value <= 1):
        raise click.BadParameter(
            f"must be in (0, 1], got {value!r} (a rigid mount already gives M_a = 1)"
        )
    return value


@click.group(short_help="Suspension and vibration-absorber design.")
def isolate() -> None:
    """Isolation of an experiment package: spring mount plus damped absorber (Section 4).

    Parameters follow the report's Eq. 4.6: k = k1/k2, mu = m2/m1, zeta = c/(2 sqrt(m2 k2)),
    r = omega/omega_n with omega_n = sqrt(k1/m1).
    """


@isolate.command(short_help="M_a against r^2 of a mount and absorber.")
@click.option("--k", "k", type=PositiveFloat(), required=True, help="spring ratio k1/k2 (> 0)")
@click.option("--mu", type=PositiveFloat(), required=True, help="mass ratio m2/m1 (> 0)")
@click.option(
    "--zeta", type=PositiveFloat(0.0, strict=False), required=True, help="absorber damping ratio"
)
@click.option(
    "--r2",
    type=RangeType(),
    default="0:6:61",
    show_default=True,
    callback=_nonneg_range,
    help="r^2 samples START:STOP:N (inclusive)",
)
@click.option("--json", "as_json", is_flag=True, help="print {'r2': [...], 'Ma': [...]}")
@_flagged
def curve(k: float, mu: float, zeta: float, r2: tuple[float, float, int], as_json: bool) -> None:
    """M_a = |U1/U0| against r^2 (Eq. 4.3 solved; printed Eq. 4.7 is garbled)."""
    from microg.isolation import (
        absorber_tuning_ratio,
        accel_magnification,
        accel_magnification_no_absorber,
    )

    r2v = np.linspace(r2[0], r2[1], r2[2])
    ma = accel_magnification(k, mu, zeta, np.sqrt(r2v))
    if as_json:
        click.echo(dumps({"r2": r2v, "Ma": ma}))
        return
    base = accel_magnification_no_absorber(np.sqrt(r2v))
    click.echo(
        f"k = {k:g}, mu = {mu:g}, zeta = {zeta:g}, f = omega_a/omega_n = "
        f"{num(float(absorber_tuning_ratio(k, mu)))}"
    )
    click.echo(f"{'r^2':>10} {'M_a':>12} {'no absorber':>12}")
    for x, m, b in zip(r2v, ma, base, strict=True):
        click.echo(f"{x:10.4f} {m:12.5g} {b:12.5g}")


@isolate.command(short_help="The optimal absorber for mass ratio MU.")
@click.option("--mu", type=PositiveFloat(), required=True, help="mass ratio m2/m1 (> 0)")
@click.option(
    "--band",
    type=BandType(),
    default=None,
    cls=Option,
    show_default="all r",
    help="band of the frequency ratio r = omega/omega_n (not r^2), LO:HI",
)
@click.option(
    "--criterion",
    type=click.Choice(["peak", "h2"]),
    default="peak",
    show_default=True,
    help="minimise the peak of M_a over the band, or the integral of M_a^2 dr",
)
@click.option(
    "--zeta",
    type=PositiveFloat(0.0, strict=False),
    default=None,
    cls=Option,
    show_default="optimised",
    help="hold the absorber damping ratio fixed",
)
@click.option("--json", "as_json", is_flag=True, help="print {k, zeta, f, peak_Ma, criterion}")
@_flagged
def tune(
    mu: float,
    band: tuple[float, float] | None,
    criterion: str,
    zeta: float | None,
    as_json: bool,
) -> None:
    """Optimal absorber (k, zeta) for mass ratio MU, numerically, with the closed form beside it."""
    from microg.isolation import den_hartog, h2_closed_form, tune_absorber

    res = tune_absorber(mu, band, criterion, zeta=zeta)
    if as_json:
        click.echo(dumps(res.contract()))
        return
    closed = den_hartog(mu) if criterion == "peak" else h2_closed_form(mu)
    where = "all r" if band is None else f"{band[0]:g} <= r <= {band[1]:g}"
    click.echo(f"mu = {mu:g}, criterion = {criterion}, over {where}")
    click.echo(f"{'':22}{'numerical':>14}{closed.method:>28}")
    for name in ("k", "zeta", "f", "peak_Ma", "r_peak", "h2"):
        click.echo(f"{name:22}{getattr(res, name):14.6g}{getattr(closed, name):28.6g}")
    if band is not None:
        click.echo("(the closed form is for all r; its figures are over all r)")


@isolate.command(short_help="The stiffest mount spring meeting TARGET.")
@click.option(
    "--weight",
    type=QuantityType("force", "lbf", minimum=0, strict=True),
    default=None,
    help="package weight on Earth, e.g. '1000 lbf' (bare number: lbf)",
)
@click.option(
    "--mass",
    type=QuantityType("mass", "kg", minimum=0, strict=True),
    default=None,
    help="package mass, e.g. '450 kg' (instead of --weight)",
)
@click.option(
    "--omega",
    type=QuantityType("angular_frequency", "rad/s", minimum=0, strict=True),
    default=None,
    help="disturbance angular frequency (bare number: rad/s)",
)
@click.option(
    "--freq",
    type=QuantityType("frequency", "Hz", minimum=0, strict=True),
    default=None,
    help="disturbance frequency (bare number: Hz)",
)
@click.option(
    "--omega-band", type=BandType(), default=None, help="disturbance band LO:HI in rad/s (LO > 0)"
)
@click.option(
    "--freq-band", type=BandType(), default=None, help="disturbance band LO:HI in Hz (LO > 0)"
)
@click.option(
    "--target",
    type=PositiveFloat(),
    default=0.5,
    show_default=True,
    callback=_target,
    help="largest acceptable M_a over the band, in (0, 1]",
)
@click.option(
    "--mu",
    type=PositiveFloat(),
    default=None,
    help="add a tuned absorber of mass ratio m2/m1 (needs a band)",
)
@click.option(
    "--zeta",
    type=PositiveFloat(0.0, strict=False),
    default=None,
    help="with --mu: hold the absorber damping ratio fixed",
)
@click.option("--json", "as_json", is_flag=True, help="print the design as a JSON object")
@_flagged
def design(
    weight: float | None,
    mass: float | None,
    omega: float | None,
    freq: float | None,
    omega_band: tuple[float, float] | None,
    freq_band: tuple[float, float] | None,
    target: float,
    mu: float | None,
    zeta: float | None,
    as_json: bool,
) -> None:
    """Stiffest mount spring keeping M_a <= TARGET at every disturbance frequency given."""
    from microg.isolation import design_mount
    from microg.units import G0

    if (weight is None) == (mass is None):
        raise click.UsageError("give exactly one of --weight and --mass")
    given = [x is not None for x in (omega, freq, omega_band, freq_band)]
    if sum(given) != 1:
        raise click.UsageError("give exactly one of --omega, --freq, --omega-band, --freq-band")
    for name, b in (("--omega-band", omega_band), ("--freq-band", freq_band)):
        if b is not None and b[0] <= 0:
            raise click.BadParameter(f"need 0 < LO < HI, got {b[0]:g}:{b[1]:g}", param_hint=name)
    if zeta is not None and mu is None:
        raise click.UsageError("--zeta needs --mu (it is the absorber's damping)")
    m1 = mass if mass is not None else weight / G0  # type: ignore[operator]
    if omega is not None:
        band = (omega, omega)
    elif freq is not None:
        band = (2 * math.pi * freq, 2 * math.pi * freq)
    elif omega_band is not None:
        band = omega_band
    else:
        band = (2 * math.pi * freq_band[0], 2 * math.pi * freq_band[1])  # type: ignore[index]
    if mu is not None and band[0] == band[1]:
        raise click.UsageError(
            "--mu needs a band (--omega-band/--freq-band): at one frequency an undamped "
            "absorber tuned to it gives M_a = 0 for any mount"
        )
    res = design_mount(m1, band, target, mu=mu, zeta=zeta)
    if as_json:
        click.echo(dumps(res.to_dict()))
        return
    click.echo(f"package mass          {num(res.mass)} kg ({num(res.mass * G0 * _LBF_PER_N)} lbf)")
    click.echo(f"disturbance band      {num(band[0])} .. {num(band[1])} rad/s")
    click.echo(f"target M_a            <= {target:g}")
    click.echo(f"largest k1            {num(res.k1)} N/m = {num(res.k1_lbf_per_in)} lbf/in")
    click.echo(f"mount natural freq.   {num(res.omega_n)} rad/s = {num(res.freq_hz_n)} Hz")
    click.echo(f"r over the band       {num(res.r_band[0])} .. {num(res.r_band[1])}")
    click.echo(f"achieved max M_a      {num(res.achieved_Ma)}")
    click.echo(f"sag under 1 g         {num(res.sag_1g)} m (ground test)")
    if res.mu is not None:
        click.echo(
            f"absorber              mu = {res.mu:g}, k = {num(res.k)}, zeta = {num(res.zeta)},"
            f" f = {num(res.f)}"
        )
        click.echo(
            f"                      m2 = {num(res.m2)} kg, k2 = {num(res.k2)} N/m, "
            f"c = {num(res.c)} N s/m"
        )


@isolate.command(short_help="The numbers of Section 4.2, recomputed.")
@click.option(
    "--mu-max",
    type=PositiveFloat(),
    default=0.25,
    show_default=True,
    help="largest absorber mass ratio searched for claim (d)",
)
@click.option("--json", "as_json", is_flag=True, help="print the checks as JSON")
@_flagged
def claims(mu_max: float, as_json: bool) -> None:
    """Recompute the numerical claims of Section 4.2 and conclusion 5 of the report."""
    from microg.isolation import check_section42_claims

    res = check_section42_claims(mu_max=mu_max)
    if as_json:
        click.echo(dumps(res.to_dict()))
        return
    for c in res.checks:
        verdict = "HOLDS" if c.holds else "DOES NOT HOLD"
        click.echo(f'({c.id}) {verdict}: "{c.statement}"')
        click.echo(f"    printed:    {c.printed}")
        click.echo(f"    recomputed: {c.recomputed}")
        click.echo(f"    note:       {c.note}")


@isolate.command(short_help="Figure 8 of the report.")
@click.option(
    "--out",
    type=PathType(dir_okay=False),
    default="figure8.png",
    show_default=True,
    help="PNG file to write (atomically)",
)
@click.option(
    "--r2-max",
    type=PositiveFloat(),
    default=6.0,
    show_default=True,
    help="upper end of the r^2 axis",
)
@_flagged
def figure8(out: str, r2_max: float) -> None:
    """Figure 8: M_a against r^2, six panels at zeta = 0.2."""
    from pathlib import Path

    from microg._io import check_writable
    from microg.errors import InputError
    from microg.plotting.isolation import figure8 as make

    if Path(out).suffix.lower() != ".png":
        raise InputError(f"{out!r} is not a .png file", where="--out", fix="name it *.png")
    check_writable(out, "--out", directory=False)  # before drawing
    try:
        make(out, r2_max=r2_max)
    except OSError as exc:
        raise InputError(f"cannot write {out}: {exc.strerror or exc}", where="--out") from None
    written(out)


def _register_active() -> None:
    """``microg isolate active`` lives in its own module (:mod:`microg.cli.isolate_active`)."""
    from microg.cli.isolate_active import active

    isolate.add_command(active)


_register_active()
