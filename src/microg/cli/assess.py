"""``microg assess FILE``: the assessment and PIMS-style products of a measured record."""

from __future__ import annotations

import datetime as _dt
import hashlib
import sys
from pathlib import Path
from typing import Any

import click

from microg.cli._common import Option, num, written
from microg.cli.params import PathType, QuantityType

__all__ = ["assess", "merge_assessments", "run_assessment"]

#: library parameter -> command-line option, for error messages
FLAGS = {
    "interval_s": "--interval",
    "requirement": "--requirement",
    "segment_s": "--segment",
    "psd_method": "--psd",
    "transient": "--transient",
    "out": "--out",
    "predicted": "--predicted",
    "point": "--observe",
}


@click.command(short_help="Assess a measured acceleration record FILE.")
@click.argument("file", type=PathType(path_type=Path))
@click.option(
    "--interval",
    type=QuantityType("time", "s", minimum=0.0, strict=True),
    default="100 s",
    show_default=True,
    help="Interval of the PIMS-style per-interval band RMS and percentiles.  A record "
    "shorter than the default is taken as one interval.",
)
@click.option(
    "--requirement",
    default="iss",
    show_default=True,
    help="Band requirement: iss (NASA PIMS's table), ssp41000 (the continuous curve), flat.",
)
@click.option(
    "--psd",
    "psd_method",
    type=click.Choice(["periodogram", "welch"]),
    default="periodogram",
    show_default=True,
    help="Spectrum: boxcar periodogram of each interval/record, or Hann Welch (long "
    "stationary records).",
)
@click.option(
    "--segment",
    type=QuantityType("time", "s", minimum=0.0, strict=True),
    default=None,
    cls=Option,
    show_default="each interval, and the whole record for its PSD",
    help="Welch segment length.",
)
@click.option(
    "--transient",
    default="iss",
    show_default=True,
    help="Transient criteria set (iss, report-1e-5g) or 'none'.",
)
@click.option(
    "--sensor",
    default=None,
    cls=Option,
    show_default="the file's",
    help="Name of the record in the output (files of one record).",
)
@click.option(
    "--predicted",
    type=PathType(exists=True, dir_okay=False, path_type=Path),
    default=None,
    help="results.json of a `microg analyze` run: its bands are overlaid on the "
    "measurement's, band by band (table, figure, JSON `prediction`).",
)
@click.option(
    "--observe",
    "point",
    default=None,
    cls=Option,
    show_default="the point named like the sensor, or the prediction's only point",
    help="--predicted: the predicted point to compare with.",
)
@click.option("--json", "as_json", is_flag=True, help="Print the results as JSON to stdout.")
@click.option(
    "--out",
    "out_dir",
    type=PathType(file_okay=False, path_type=Path),
    default=None,
    help="Also write results.json, the figures and report.html into this directory.",
)
@click.option(
    "--static",
    is_flag=True,
    help="Write report.html with PNG figures only (no interactive chart, ~4.8 MB smaller).",
)
def assess(
    file: Path,
    interval: float,
    requirement: str,
    psd_method: str,
    segment: float | None,
    transient: str,
    sensor: str | None,
    predicted: Path | None,
    point: str | None,
    as_json: bool,
    out_dir: Path | None,
    static: bool,
) -> None:
    """Assess a measured acceleration record FILE against a requirement.

    FILE is a PIMS/SAMS PAD data file (32-bit little-endian floats t, x, y, z in g, with its
    .header beside it), a CSV with units in its header (time [s], x [m/s^2], y [g], z [ug]),
    or a UFF file of time histories (.unv/.uff, datasets 58 with 164 units: x, y, z of each
    node, every sensor assessed).  Prints the band verdict, the PIMS-style interval
    statistics and the transient criteria; --json prints the observations contract of
    `microg analyze`, keyed by sensor name.  --predicted RESULTS.json sets a prediction's
    1/3-octave bands beside the measurement's (worst axis of each, and their ratio).
    """
    from microg._io import check_writable, dumps
    from microg.cli._errors import flag_errors
    from microg.environment.measured import read_measured_all

    ctx = click.get_current_context()
    explicit_interval = (
        ctx.get_parameter_source("interval") is not click.core.ParameterSource.DEFAULT
    )
    with flag_errors(FLAGS):
        if out_dir is not None:
            check_writable(out_dir, "out")  # before computing anything
        prediction = None
        if predicted is not None:
            from microg.environment.overlay import read_prediction

            prediction = read_prediction(predicted)
        elif point is not None:
            from microg.errors import InputError

            raise InputError(
                "chooses the predicted point, and no prediction is given",
                where="point",
                fix="add --predicted RESULTS.json or leave --observe out",
            )
        records = read_measured_all(file)
        if sensor is not None and len(records) > 1:
            from microg.errors import InputError

            raise InputError(
                f"names a single record; {file} holds {len(records)} sensors "
                f"({', '.join(r.key for r in records)})",
                where="--sensor",
                fix="leave it out: each sensor keeps its name",
            )
        results = [
            run_assessment(
                record,
                interval_s=interval,
                explicit_interval=explicit_interval,
                requirement=requirement,
                psd_method=psd_method,
                segment_s=segment,
                transient=None if transient.strip().lower() == "none" else transient,
                sensor=sensor,
            )
            for record in records
        ]
        if prediction is not None:
            from microg.environment.overlay import band_overlay

            for r in results:
                r["overlay"] = band_overlay(
                    prediction,
                    r["assessment"],
                    point=point,
                    sensor=r["key"],
                    path=str(predicted),
                )
                r["json"]["prediction"] = {r["key"]: r["overlay"].to_dict()}
        payload = merge_assessments(results)
        if out_dir is not None:
            from microg._io import write_output_files
            from microg.report.environment import render_assessment

            files: dict[str, bytes | str] = {"results.json": dumps(payload)}
            per_sensor: dict[str, dict[str, bytes]] = {}
            charts: dict[str, dict[str, list[Any]]] = {}
            for r in results:
                figs = _figures(r)
                per_sensor[r["key"]] = {k: v for k, v in figs.items() if isinstance(v, bytes)}
                files.update(figs)
                if not static:
                    charts[r["key"]] = _charts(r)
            files["report.html"] = render_assessment(
                payload, per_sensor, None if static else charts
            )
            path = write_output_files(out_dir, files, where="out")
    if as_json:
        click.echo(dumps(payload))
    else:
        for r in results:
            _summary(r)
        if out_dir is not None:
            written(path)


def merge_assessments(results: list[dict[str, Any]]) -> dict[str, Any]:
    """One ``--json`` document for the sensors of one file (each a :func:`run_assessment`).

    ``observations`` and ``intervals`` are keyed by sensor; ``complies`` holds for all of
    them, and ``verdict`` is theirs combined (a fail anywhere fails); ``warnings`` carry the
    sensor's name when the file has several.  With one sensor the document is that sensor's
    own.
    """
    from microg.environment.criteria import combine_verdicts

    if len(results) == 1:
        return results[0]["json"]
    docs = [r["json"] for r in results]
    keys = [r["key"] for r in results]
    if len(set(keys)) != len(keys):
        from microg.errors import InputError

        raise InputError(
            "two sensors of the file have one name", where=str(results[0]["record"].path)
        )
    first = results[0]["record"]
    return {
        "meta": docs[0]["meta"],
        "source": {
            "path": first.path,
            "format": first.format,
            "sensors": {k: d["source"] for k, d in zip(keys, docs, strict=True)},
        },
        "requirement": docs[0]["requirement"],
        "requirement_source": docs[0]["requirement_source"],
        "observations": {k: d["observations"][k] for k, d in zip(keys, docs, strict=True)},
        "intervals": {k: d["intervals"][k] for k, d in zip(keys, docs, strict=True)},
        **(
            {"prediction": {k: d["prediction"][k] for k, d in zip(keys, docs, strict=True)}}
            if "prediction" in docs[0]
            else {}
        ),
        "complies": all(bool(d["complies"]) for d in docs),
        "verdict": combine_verdicts(d["verdict"] for d in docs),
        "warnings": [f"{k}: {w}" for k, d in zip(keys, docs, strict=True) for w in d["warnings"]],
    }


def run_assessment(
    record: Any,
    *,
    interval_s: float = 100.0,
    explicit_interval: bool = True,
    requirement: str = "iss",
    psd_method: str = "periodogram",
    segment_s: float | None = None,
    transient: str | None = "iss",
    sensor: str | None = None,
) -> dict[str, Any]:
    """Assessment and interval products of a :class:`~microg.environment.measured.MeasuredRecord`.

    Returns a dict with ``record``, ``key``, ``assessment``, ``intervals`` and ``json`` (the
    ``--json`` document).
    """
    from microg import __version__
    from microg.environment.intervals import interval_products
    from microg.environment.metrics import assess as assess_record
    from microg.environment.requirements import requirement as requirement_by_name

    req = requirement_by_name(requirement)
    a = assess_record(
        record.timepts,
        record.accel,
        req,
        axes=record.axes,
        psd_method=psd_method,
        segment_s=segment_s,
        transient=transient,
        transient_basis="pims",
        cutoff_hz=record.cutoff_hz,
        sample_rate_hz=record.sample_rate_hz,
    )
    warnings = list(getattr(record, "warnings", ())) + list(a.warnings)
    length = interval_s
    if record.duration_s < interval_s and not explicit_interval:
        length = record.duration_s
        warnings.append(
            f"the record ({num(record.duration_s)} s) is shorter than the default "
            f"{interval_s:g}-s interval: the interval products take it as one interval"
        )
    iv = interval_products(
        record.timepts,
        record.accel,
        req,
        axes=record.axes,
        interval_s=length,
        psd_method=psd_method,
        segment_s=segment_s,
        cutoff_hz=record.cutoff_hz,
        sample_rate_hz=record.sample_rate_hz,
    )
    warnings.extend(iv.warnings)
    key = sensor or record.key
    data = Path(record.path)
    try:
        digest = hashlib.sha256(data.read_bytes()).hexdigest()
    except OSError:
        digest = None
    doc = {
        "meta": {
            "microg_version": __version__,
            "created_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "command": " ".join(["microg", *sys.argv[1:]]) if sys.argv else "microg assess",
            "file_path": str(data.resolve()),
            "file_sha256": digest,
        },
        "source": record.to_dict(),
        "requirement": req.name,
        "requirement_source": req.source,
        "observations": {key: a.to_dict()},
        "intervals": {key: iv.to_dict()},
        "complies": bool(a.complies),
        "verdict": a.verdict,
        "warnings": warnings,
    }
    return {"record": record, "key": key, "assessment": a, "intervals": iv, "json": doc}


def _integrated(a: Any) -> Any:
    """The integral the transient criteria judge: PIMS's blocks when there is one, else sliding."""
    pims = a.transient_basis == "pims" and a.integrated_pims is not None
    return a.integrated_pims if pims else a.integrated_sliding


def _figures(result: dict[str, Any]) -> dict[str, bytes | str]:
    """The PNG figures of one sensor, by file name, in report order."""
    from microg._io import safe_filenames
    from microg.plotting.common import png_bytes
    from microg.plotting.environment import (
        plot_integrated,
        plot_psd,
        plot_third_octave,
        plot_time_history,
    )

    a, iv, key, rec = result["assessment"], result["intervals"], result["key"], result["record"]
    s = safe_filenames([key])[key]
    figs = {
        "history": plot_time_history(
            rec.timepts, rec.accel, axes=a.axes, title=f"Acceleration at {key}"
        ),
        "integrated": plot_integrated(_integrated(a), axes=a.axes),
        "third-octave": plot_third_octave(
            a, title=f"1/3-octave band RMS at {key} vs {a.requirement}"
        ),
        "psd": plot_psd(a.spectrum, axes=a.axes, title=f"PSD at {key} ({a.spectrum.method})"),
        "percentiles": iv.bands.plot(row="rss"),
        "spectrogram": iv.spectrogram.plot(),
        "cumulative-rms": iv.cumulative.plot(),
        "band-rms-time": iv.band_limited.plot(),
        "interval-stats": iv.stats.plot(),
    }
    if "overlay" in result:
        figs["prediction-overlay"] = result["overlay"].plot()
    return {f"{s}-{k}.png": png_bytes(f) for k, f in figs.items()}


def _charts(result: dict[str, Any]) -> dict[str, list[Any]]:
    """The interactive charts of one sensor (plotly Figures), by the PNG each stands for."""
    from microg._io import safe_filenames
    from microg.plotting.interactive.histories import history_chart, integrated_chart

    a, iv, key, rec = result["assessment"], result["intervals"], result["key"], result["record"]
    s = safe_filenames([key])[key]
    charts = {
        "history": history_chart(
            rec.timepts, rec.accel, axes=a.axes, title=f"Acceleration at {key}"
        ),
        "integrated": integrated_chart(_integrated(a), axes=a.axes),
        "third-octave": a.plot_interactive("third_octave"),
        "psd": a.plot_interactive("psd"),
        "percentiles": iv.bands.plot_interactive(row="rss"),
        "spectrogram": iv.spectrogram.plot_interactive(),
        "cumulative-rms": iv.cumulative.plot_interactive(),
        "band-rms-time": iv.band_limited.plot_interactive(),
        "interval-stats": iv.stats.plot_interactive(),
    }
    if "overlay" in result:
        charts["prediction-overlay"] = result["overlay"].plot_interactive()
    return {f"{s}-{k}.png": [c] for k, c in charts.items()}


def _summary(result: dict[str, Any]) -> None:
    from microg.environment.criteria import HEADLINE
    from microg.units import G0

    rec, a, iv, key = result["record"], result["assessment"], result["intervals"], result["key"]
    ug = 1e6
    cut = f", cutoff {rec.cutoff_hz:g} Hz" if rec.cutoff_hz else ""
    click.echo(
        f"{rec.path}: {key} ({rec.format.upper()}, {rec.sample_rate_hz:g} Hz{cut}), "
        f"{num(rec.duration_s)} s"
    )
    mean = ", ".join(f"{n} {num(v * ug)}" for n, v in zip(a.axes, a.mean_accel_g_axis, strict=True))
    click.echo(f"  mean (quasi-steady or sensor bias, removed before the bands): {mean} micro-g")
    vr = a.verdict_range_hz
    cover = (
        f"bands {num(vr[0])}-{num(vr[1])} Hz judged ({int(a.third_octave.judged.sum())} of "
        f"{a.third_octave.center_hz.size})"
        if vr
        else "no band judged"
    )
    click.echo(
        f"  verdict vs {a.requirement}: {HEADLINE[a.verdict]} (from the criteria below); {cover}"
    )
    wb = a.worst_band
    if wb is not None:
        click.echo(
            f"  worst band {num(wb.center_hz)} Hz ({wb.axis}): {num(wb.rms_g * ug)} micro-g RMS, "
            f"limit {num(wb.limit_g * ug)}, margin {num(wb.margin)}"
        )
    b = iv.bands
    at99 = b.complies_at(99.0) if 99.0 in b.percentiles and b.resolved.any() else None
    p99 = "" if at99 is None else f"; 99th percentile within the limit: {'yes' if at99 else 'NO'}"
    click.echo(f"  intervals: {b.t_start_s.size} x {num(b.interval_s)} s{p99}")
    pb = a.integrated_pims
    if pb is not None:
        worst = max(pb.max_mps) / G0 * ug
        click.echo(
            f"  integrated acceleration (PIMS, {pb.n_blocks} blocks of {pb.window_s:g} s): "
            f"max {num(worst)} micro-g s"
        )
    ov = result.get("overlay")
    if ov is not None:
        i = ov.worst_ratio_band
        worst = (
            "no band resolved by both"
            if i is None
            else f"measured/predicted band RMS (worst axis) up to {num(ov.ratio[i])} at "
            f"{num(ov.center_hz[i])} Hz ({int(ov.judged.sum())} bands compared)"
        )
        click.echo(f"  prediction {ov.predicted_path} at {ov.point}: {worst}")
    click.echo("  verdict per criterion:")
    for c in a.criteria:
        click.echo(f"    {c.line()}")
    for w in result["json"]["warnings"]:
        click.echo(f"  warning: {w}")
