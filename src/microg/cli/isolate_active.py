"""``microg isolate active``: design and verify an active isolator (ARIS / g-LIMIT class).

Parses options (units at the boundary), computes the station's response at the mount point
with :func:`microg.analyze` (the main job's exact crew-disturbance response), calls
:func:`microg.isolation.design_active` and prints or writes its result.
"""

from __future__ import annotations

from typing import Any

import click

from microg._io import dumps
from microg.cli._common import num, written
from microg.cli.params import PathType, PositiveFloat, QuantityType
from microg.errors import InputError

__all__ = ["active"]


@click.command("active", short_help="Design and verify an active isolator.")
@click.option(
    "--preset",
    type=click.Choice(["aris", "g-limit"]),
    default="aris",
    show_default=True,
    help="the isolator's defaults (each parameter's source is in the output)",
)
@click.option(
    "--mass",
    type=QuantityType("mass", "kg", minimum=0, strict=True),
    default=None,
    help="platform mass, e.g. '700 kg'",
)
@click.option(
    "--umbilical-stiffness",
    type=QuantityType("stiffness", "N/m", minimum=0),
    default=None,
    help="umbilical stiffness per translational axis, e.g. '300 N/m'",
)
@click.option(
    "--umbilical-damping",
    type=QuantityType("damping", "N*s/m", minimum=0),
    default=None,
    help="umbilical damping per translational axis, e.g. '20 N*s/m'",
)
@click.option(
    "--rattlespace",
    type=QuantityType("length", "m", minimum=0, strict=True),
    default=None,
    help="largest relative translation, e.g. '12.5 mm'",
)
@click.option(
    "--actuator-force",
    type=QuantityType("force", "N", minimum=0, strict=True),
    default=None,
    help="actuator force per axis, e.g. '20 N'",
)
@click.option(
    "--sample-rate",
    type=QuantityType("frequency", "Hz", minimum=0, strict=True),
    default=None,
    help="controller sampling rate, e.g. '1 kHz'",
)
@click.option(
    "--delay",
    type=QuantityType("time", "s", minimum=0),
    default=None,
    help="computation delay, e.g. '1 ms'",
)
@click.option(
    "--accel-noise",
    type=PositiveFloat(0.0, strict=False),
    default=None,
    help="accelerometer noise, micro-g per sqrt(Hz)",
)
@click.option(
    "--accel-bandwidth",
    type=QuantityType("frequency", "Hz", minimum=0, strict=True),
    default=None,
    help="accelerometer bandwidth, e.g. '100 Hz'",
)
@click.option(
    "--max-loop",
    type=QuantityType("frequency", "Hz", minimum=0, strict=True),
    default=None,
    help="highest acceleration-loop gain the platform allows, e.g. '3 Hz'",
)
@click.option(
    "--target",
    type=click.Choice(["preset", "g-limit", "aris"]),
    default="preset",
    show_default=True,
    help="the transmissibility target",
)
@click.option(
    "--controller",
    type=click.Choice(["designed", "off", "h2"]),
    default="designed",
    show_default=True,
    help="acceleration feedback with centring, H2 (slycot), or none",
)
@click.option(
    "--station/--no-station",
    default=True,
    show_default=True,
    help="check the station's own response at the mount point in the time domain",
)
@click.option("--model", default="ioc", show_default=True, help="station model (name or file)")
@click.option(
    "--force",
    "force_spec",
    default="foot-pushoff-max",
    show_default=True,
    help="crew disturbance (activity name or spec)",
)
@click.option("--at", "at", default="crew", show_default=True, help="point the disturbance acts at")
@click.option("--direction", default="x", show_default=True, help="direction of the disturbance")
@click.option("--observe", default="lab", show_default=True, help="the mount point")
@click.option(
    "--allow-miss",
    is_flag=True,
    help="print the result even when the target is out of reach, instead of exit status 2",
)
@click.option("--json", "as_json", is_flag=True, help="print the result as JSON")
@click.option(
    "--out",
    "out_dir",
    type=PathType(file_okay=False),
    default=None,
    help="write report.html, figures and result.json to this directory",
)
def active(
    preset: str,
    mass: float | None,
    umbilical_stiffness: float | None,
    umbilical_damping: float | None,
    rattlespace: float | None,
    actuator_force: float | None,
    sample_rate: float | None,
    delay: float | None,
    accel_noise: float | None,
    accel_bandwidth: float | None,
    max_loop: float | None,
    target: str,
    controller: str,
    station: bool,
    model: str,
    force_spec: str,
    at: str,
    direction: str,
    observe: str,
    allow_miss: bool,
    as_json: bool,
    out_dir: str | None,
) -> None:
    """Design an active isolator to a target and verify it (stability, margins, stroke, force)."""
    from microg._io import check_writable, write_run_directory
    from microg.isolation.active.design import design_active
    from microg.isolation.active.presets import load_preset

    if out_dir is not None:
        check_writable(out_dir, "--out")
    over: dict[str, Any] = {
        "mass_kg": mass,
        "umbilical_k_N_per_m": None if umbilical_stiffness is None else [umbilical_stiffness] * 3,
        "umbilical_c_N_s_per_m": None if umbilical_damping is None else [umbilical_damping] * 3,
        "rattlespace_m": rattlespace,
        "position_range_m": rattlespace,
        "actuator_force_N": actuator_force,
        "sample_rate_hz": sample_rate,
        "delay_s": delay,
        "accel_noise_ug_per_rthz": accel_noise,
        "accel_bandwidth_hz": accel_bandwidth,
        "max_loop_hz": max_loop,
    }
    flags = {
        "mass": "--mass",
        "umbilical-stiffness": "--umbilical-stiffness",
        "umbilical-damping": "--umbilical-damping",
        "rattlespace": "--rattlespace",
        "position-range": "--rattlespace",
        "actuator-force": "--actuator-force",
        "sample-rate": "--sample-rate",
        "delay": "--delay",
        "accel-noise": "--accel-noise",
        "accel-bandwidth": "--accel-bandwidth",
        "max-loop": "--max-loop",
    }
    try:
        plant, preset_target = load_preset(preset, **over)
    except InputError as exc:
        raise InputError(
            exc.what, where=flags.get(exc.where or "", exc.where), fix=exc.fix
        ) from None
    tgt = preset_target if target == "preset" else target
    timepts = base = None
    if station:
        import microg

        run = microg.analyze(
            model, force=force_spec, at=at, direction=direction, observe=[observe], isolation=False
        )
        resp = run.observations[observe].response
        timepts, base = resp.timepts, resp.acceleration
    try:
        res = design_active(
            plant,
            target=tgt,
            controller=controller,
            timepts=timepts,
            base_accel=base,
            point=observe,
        )
    except InputError as exc:
        raise InputError(
            exc.what, where=flags.get(exc.where or "", exc.where), fix=exc.fix
        ) from None
    if not res.stable:
        raise InputError(
            "the closed loop is unstable: " + "; ".join(n for n in res.notes if "unstable" in n),
            where="--controller",
        )
    missed = controller != "off" and not res.meets_target and not allow_miss
    if missed and res.binding_limit is None and not res.margins_kept:
        least = min(res.margins, key=lambda m: m.phase_margin_deg)
        raise InputError(
            f"the {res.controller.kind} design does not keep the loop margins (loop {least.loop}: "
            f"{least.phase_margin_deg:.3g} deg of phase, {least.gain_margin_db:.3g} dB of gain)",
            where="--controller",
            fix="use another controller or relax the plant's limits, or pass --allow-miss",
        )
    if controller != "off" and not res.meets_target and not allow_miss:
        raise InputError(
            f"target {res.target.name} is out of reach: the {res.binding_limit} limit binds ("
            + "; ".join(n for n in res.notes if "exceeds" in n or "not met" in n)
            + ")",
            where=f"binding limit {res.binding_limit}",
            fix="relax the target or the limit, or pass --allow-miss to see the design",
        )
    d = res.to_dict()
    if out_dir is not None:
        from microg.plotting.active import active_figures
        from microg.report.active import render_active

        figs = active_figures(res)
        files: dict[str, bytes | str] = {
            "result.json": dumps(d),
            "report.html": render_active(res, figs),
        }
        files.update(figs)
        write_run_directory(out_dir, files, where="--out")
    if as_json:
        click.echo(dumps(d))
        return
    click.echo(f"{res.plant.name}: {res.controller.kind} controller, target {res.target.name}")
    click.echo(
        f"stable: {res.stable}; meets target: {res.meets_target}; binding limit: {res.binding_limit}"  # noqa: E501
    )
    att = res.attenuation_at(0.1)
    click.echo(
        "attenuation at 0.1 Hz: "
        + ", ".join(f"{a} {num(v)}x" for a, v in zip("xyz", att, strict=True))
    )
    for m in res.margins:
        click.echo(
            f"  loop {m.loop:2} {m.model:10} GM {m.gain_margin_db:7.3g} dB  PM {m.phase_margin_deg:7.3g} deg"  # noqa: E501
        )
    if res.time is not None:
        tm = res.time
        click.echo(
            f"at {tm.point}: complies {res.complies}; stroke {num(tm.peak_stroke[:3].max())} m, "
            f"force {num(tm.peak_force[:3].max())} N"
        )
    for n in res.notes:
        click.echo(f"  - {n}")
    if out_dir is not None:
        written(out_dir)
