"""Interactive charts of 1/3-octave band tables against their limits (micro-g).

As the static figures (:mod:`microg.plotting.environment`): the limit is a step on the band
edges, each axis's band RMS a line through the band centres with a filled marker on the bands
the verdict judges and a hollow one on the bands it does not (the record does not resolve
them).  A marker's hover gives the band (centre and edges, Hz), the RMS and limit (micro-g), the
margin, and whether the band is judged (and why not).  Band tables have at most a few dozen
bands: nothing is decimated.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.plotting.interactive.common import AXIS_COLOURS, chart, f32

if TYPE_CHECKING:
    import plotly.graph_objects as go

    from microg.environment.intervals import IntervalBandRMS
    from microg.environment.overlay import BandOverlay
    from microg.environment.third_octave import ThirdOctave

__all__ = ["bands_chart", "limit_trace", "overlay_chart", "percentiles_chart"]

_HOVER = (
    "%{meta}: %{y:.4g} micro-g<br>band %{x:.4g} Hz (%{customdata[0]:.4g}-%{customdata[1]:.4g} Hz)"
    "<br>limit %{customdata[2]:.4g} micro-g, margin %{customdata[3]:.3g}<br>%{text}<extra></extra>"
)


def limit_trace(lower_hz: Any, upper_hz: Any, limit_g: Any, *, name: str = "limit") -> Any:
    """The limit as steps on the band edges (micro-g), hover with the band and the limit."""
    import plotly.graph_objects as go

    lo, hi = np.asarray(lower_hz, float), np.asarray(upper_hz, float)
    lim = np.asarray(limit_g, float) * 1e6
    x = np.column_stack([lo, hi, np.full_like(lo, np.nan)]).ravel()
    y = np.column_stack([lim, lim, np.full_like(lim, np.nan)]).ravel()
    # joined steps: each band's edges and the next band's, without the NaN breaks
    keep = np.isfinite(x)
    return go.Scatter(
        x=f32(x[keep]),
        y=f32(y[keep]),
        mode="lines",
        name=name,
        line={"color": "black", "width": 2},
        hovertemplate="limit %{y:.4g} micro-g at %{x:.4g} Hz<extra></extra>",
    )


def _judged_text(resolved: np.ndarray, reasons: Sequence[str]) -> list[str]:
    out = []
    for i, r in enumerate(np.asarray(resolved, bool)):
        why = reasons[i] if i < len(reasons) and reasons[i] else "not resolved by the record"
        out.append("judged" if r else f"NOT judged: {why}")
    return out


def bands_chart(
    to: ThirdOctave,
    *,
    axes: Sequence[str] = ("x", "y", "z"),
    rows: Sequence[int] | None = None,
    title: str = "1/3-octave band RMS",
    verdict_range_hz: tuple[float, float] | None = None,
) -> go.Figure:
    """Band RMS per axis against the limit's steps (micro-g, log-log), judged bands filled.

    Parameters
    ----------
    to : ThirdOctave
        Band edges and centres (Hz), RMS per axis, limits (g), margins, resolution.
    axes : names of the rows of ``to.rms_g``
    rows : the rows drawn (default: all)
    title : chart title
    verdict_range_hz : the range the verdict covers, Hz (default: the judged bands'), named in
        a note
    """
    import plotly.graph_objects as go

    res = np.asarray(to.resolved, bool)
    reasons = tuple(getattr(to, "reasons", ()) or ())
    text = _judged_text(res, reasons)
    lim = np.asarray(to.limit_g, float) * 1e6
    traces: list[Any] = [limit_trace(to.lower_hz, to.upper_hz, to.limit_g)]
    for i in range(len(axes)) if rows is None else rows:
        name = axes[i]
        y = np.maximum(np.asarray(to.rms_g[i], float) * 1e6, 1e-12)
        margin = np.asarray(to.margin[i], float)
        custom = np.column_stack([to.lower_hz, to.upper_hz, lim, margin]).astype(np.float32)
        colour = AXIS_COLOURS.get(name)
        symbols = ["circle" if r else "circle-open" for r in res]
        traces.append(
            go.Scatter(
                x=f32(to.center_hz),
                y=f32(y),
                mode="lines+markers",
                name=f"{name} (filled: judged, hollow: not judged)",
                meta=name,
                line={"width": 1, "color": colour},
                marker={"size": 7, "symbol": symbols, "color": colour},
                customdata=custom,
                text=text,
                hovertemplate=_HOVER,
            )
        )
    vr = verdict_range_hz if verdict_range_hz is not None else to.verdict_range_hz
    n_judged = int(res.sum())
    notes = [
        f"judged: {n_judged} of {res.size} bands"
        + (f", {vr[0]:.3g} to {vr[1]:.3g} Hz" if vr is not None and n_judged else "")
        + "; hollow markers: bands the record does not resolve (not judged)"
    ]
    return chart(
        traces,
        title=title,
        x_title="frequency [Hz] (markers at band centres, limit on band edges)",
        y_title="band RMS [micro-g]",
        x_log=True,
        y_log=True,
        notes=notes,
    )


def percentiles_chart(res: IntervalBandRMS, *, row: str = "rss", title: str = "") -> go.Figure:
    """Percentiles of the intervals' band RMS per band against the limit (micro-g).

    The median as a marker, the 1-25 % and 75-99 % ranges as error bars (PIMS's box plot),
    hover giving each percentile; bands not judged are hollow.

    Parameters
    ----------
    res : IntervalBandRMS
        Percentiles of the interval band RMS (g) per band.
    row : an axis name or ``"rss"``
    title : chart title
    """
    import plotly.graph_objects as go

    from microg.errors import InputError

    if row not in res.rows:
        raise InputError(f"unknown row {row!r}", where="row", fix=f"use one of {res.rows}")
    k = res.rows.index(row)
    p = np.asarray(res.percentile_rms_g, float)[:, k, :] * 1e6  # (n_percentiles, nb)
    pc = [float(v) for v in res.percentiles]
    b = res.bands
    resolved = np.asarray(res.resolved, bool)

    def at(q: float) -> np.ndarray | None:
        return p[pc.index(q)] if q in pc else None

    med = at(50.0)
    centre = med if med is not None else p[len(pc) // 2]
    lo, hi = at(1.0), at(99.0)
    err: dict[str, Any] = {}
    if lo is not None and hi is not None:
        err = {
            "error_y": {
                "type": "data",
                "symmetric": False,
                "array": f32(np.maximum(hi - centre, 0)),
                "arrayminus": f32(np.maximum(centre - lo, 0)),
                "color": "#333",
                "thickness": 1,
                "width": 3,
            }
        }
    custom = np.ascontiguousarray(p.T, dtype=np.float32)  # (nb, n_percentiles)
    parts = "<br>".join(f"{q:g} %: %{{customdata[{j}]:.4g}} micro-g" for j, q in enumerate(pc))
    label = "RSS(x, y, z)" if row == "rss" else f"{row}-axis"
    traces = [
        limit_trace(b.lower_hz, b.upper_hz, res.limit_g),
        go.Scatter(
            x=f32(b.center_hz),
            y=f32(np.maximum(centre, 1e-12)),
            mode="markers",
            name=f"median, bars 1-99 % ({label}); hollow: not judged",
            marker={
                "size": 8,
                "symbol": ["line-ew-open" if r else "circle-open" for r in resolved],
                "color": "#d62728",
                "line": {"width": 2},
            },
            customdata=custom,
            text=_judged_text(resolved, tuple(res.reasons)),
            hovertemplate="band %{x:.4g} Hz<br>" + parts + "<br>%{text}<extra></extra>",
            **err,
        ),
    ]
    return chart(
        traces,
        title=title
        or f"Band RMS over {res.t_start_s.size} intervals of {res.interval_s:g} s, {label}, "
        f"vs {res.requirement}",
        x_title="frequency [Hz]",
        y_title="band RMS [micro-g]",
        x_log=True,
        y_log=True,
    )


def overlay_chart(ov: BandOverlay, *, title: str = "") -> go.Figure:
    """A prediction's band RMS beside a measurement's, worst axis, against the limit (micro-g).

    Parameters
    ----------
    ov : BandOverlay
        Predicted and measured band RMS (g), limit (g), which side resolves each band.
    title : chart title
    """
    import plotly.graph_objects as go

    traces: list[Any] = [limit_trace(ov.lower_hz, ov.upper_hz, ov.limit_g)]
    for name, values, resolved, colour in (
        ("predicted", ov.predicted_g, ov.predicted_resolved, "#9467bd"),
        ("measured", ov.measured_g, ov.measured_resolved, "#d62728"),
    ):
        res = np.asarray(resolved, bool)
        traces.append(
            go.Scatter(
                x=f32(ov.center_hz),
                y=f32(np.maximum(np.asarray(values, float) * 1e6, 1e-12)),
                mode="lines+markers",
                name=f"{name} (hollow: not resolved)",
                line={"width": 1, "color": colour},
                marker={"size": 7, "symbol": ["circle" if r else "circle-open" for r in res]},
                text=["resolved" if r else "not resolved" for r in res],
                hovertemplate=f"{name}: %{{y:.4g}} micro-g at %{{x:.4g}} Hz, %{{text}}"
                "<extra></extra>",
            )
        )
    return chart(
        traces,
        title=title or f"Predicted at {ov.point} and measured at {ov.sensor}, worst axis",
        x_title="frequency [Hz]",
        y_title="band RMS [micro-g]",
        x_log=True,
        y_log=True,
    )
