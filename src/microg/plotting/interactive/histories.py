"""Interactive charts of quantities against time: acceleration, integrated acceleration, intervals.

Units are those of the report's tables, one per quantity: acceleration in micro-g, the
integral of acceleration over a window in micro-g s (``m/s / G0 * 1e6``), interval statistics
and band-limited RMS in micro-g; time in s.  Each point's hover shows its value with the unit.
Records longer than :data:`~microg.plotting.interactive.common.MAX_POINTS` samples are drawn
through their min/max envelope, and the chart says so.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.plotting.interactive.common import (
    AXIS_COLOURS,
    chart,
    envelope_note,
    f32,
    linear_line,
)
from microg.units import G0

if TYPE_CHECKING:
    import plotly.graph_objects as go

    from microg.environment.integrated import IntegratedAcceleration, IntegratedBlocks
    from microg.environment.intervals import BandLimitedRMS, IntervalStats

__all__ = ["band_limited_chart", "history_chart", "integrated_chart", "interval_stats_chart"]

_UG = 1e6 / G0  # m/s^2 -> micro-g (and m/s -> micro-g s)


def _lines(
    t: np.ndarray, rows: np.ndarray, axes: Sequence[str], unit: str, t_name: str
) -> tuple[list[Any], bool]:
    """One line per row against ``t`` (enveloped when long), hover with ``unit``."""
    import plotly.graph_objects as go

    traces, cut = [], False
    for name, row in zip(axes, rows, strict=False):
        x, y, c = linear_line(t, row)
        cut |= c
        traces.append(
            go.Scatter(
                x=x,
                y=y,
                mode="lines",
                name=name,
                line={"width": 1, "color": AXIS_COLOURS.get(name)},
                hovertemplate=f"{name}: %{{y:.4g}} {unit}<br>{t_name} %{{x:.5g}} s<extra></extra>",
            )
        )
    return traces, cut


def history_chart(
    timepts: np.ndarray,
    accel_mps2: np.ndarray,
    *,
    axes: Sequence[str] = ("x", "y", "z"),
    title: str = "Acceleration",
) -> go.Figure:
    """Acceleration (m/s^2 in, shown in micro-g) against time (s), one line per axis.

    Parameters
    ----------
    timepts : ndarray (n,)
        Times, s.
    accel_mps2 : ndarray (naxes, n)
        Acceleration per axis, m/s^2.
    axes : the rows' names
    title : chart title
    """
    a = np.atleast_2d(np.asarray(accel_mps2, float)) * _UG
    traces, cut = _lines(np.asarray(timepts, float), a, axes, "micro-g", "t")
    return chart(
        traces,
        title=title,
        x_title="time [s]",
        y_title="acceleration [micro-g]",
        notes=envelope_note(cut, "histories"),
    )


def integrated_chart(
    integ: IntegratedAcceleration | IntegratedBlocks,
    *,
    axes: Sequence[str] = ("x", "y", "z"),
    rows: Sequence[int] | None = None,
    title: str = "",
) -> go.Figure:
    """Each window's (or block's) integral of the acceleration against its start, micro-g s.

    The integral ``integral a dt`` over a window (m/s inside, shown as ``/ G0 * 1e6``: micro-g
    s, the unit of the transient criteria's tables).

    Parameters
    ----------
    integ : IntegratedAcceleration or IntegratedBlocks
        Windows' starts (s) and integrals (m/s).
    axes : the names of the rows of ``integ.delta_v``
    rows : the rows drawn (default: all)
    title : chart title (default: the kind and the window)
    """
    kind = "consecutive blocks" if hasattr(integ, "block_samples") else "sliding windows"
    dv = np.atleast_2d(np.asarray(integ.delta_v, float)) * _UG
    pick = list(range(dv.shape[0])) if rows is None else list(rows)
    traces, cut = _lines(
        np.asarray(integ.t_start, float),
        dv[pick],
        [axes[i] for i in pick],
        "micro-g s",
        "window start",
    )
    return chart(
        traces,
        title=title or f"Integrated acceleration, {kind} of {integ.window_s:g} s",
        x_title="window start [s]",
        y_title="integral of acceleration [micro-g s]",
        notes=envelope_note(cut, "series"),
    )


def interval_stats_chart(res: IntervalStats, *, title: str = "") -> go.Figure:
    """Each interval's minimum, maximum (a band) and mean (a line) per axis, micro-g.

    Parameters
    ----------
    res : IntervalStats
        Per-interval statistics (g).
    title : chart title
    """
    import plotly.graph_objects as go

    traces: list[Any] = []
    t = f32(res.t_start_s)
    for i, name in enumerate(res.axes):
        colour = AXIS_COLOURS.get(name)
        lo, hi, mean = (f32(np.asarray(v)[:, i] * 1e6) for v in (res.min_g, res.max_g, res.mean_g))
        hover = f"{name} %{{customdata}}: %{{y:.4g}} micro-g<br>interval from %{{x:.5g}} s"
        for values, label, extra in (
            (lo, "min", {}),
            (hi, "max", {"fill": "tonexty"}),
            (mean, "mean", {}),
        ):
            traces.append(
                go.Scatter(
                    x=t,
                    y=values,
                    mode="lines",
                    line={
                        "width": 1.2 if label == "mean" else 0.5,
                        "color": colour,
                        "shape": "hv",
                    },
                    opacity=1.0 if label == "mean" else 0.5,
                    name=f"{name} {label}",
                    legendgroup=name,
                    customdata=[label] * t.size,
                    hovertemplate=hover + "<extra></extra>",
                    **extra,
                )
            )
    return chart(
        traces,
        title=title or "Interval minimum, maximum (shaded) and mean",
        x_title="interval start [s]",
        y_title="acceleration [micro-g]",
    )


def band_limited_chart(res: BandLimitedRMS, *, title: str = "") -> go.Figure:
    """Band-limited RMS per axis and their RSS against each interval's start, micro-g.

    Parameters
    ----------
    res : BandLimitedRMS
        Per-interval RMS (g) in ``res.band_hz``.
    title : chart title
    """
    import plotly.graph_objects as go

    lo, hi = res.band_hz
    t = f32(res.t_start_s)
    rows = [(name, np.asarray(res.rms_g)[:, i]) for i, name in enumerate(res.axes)]
    traces = [
        go.Scatter(
            x=t,
            y=f32(v * 1e6),
            mode="lines",
            line={
                "shape": "hv",
                "width": 1.6 if name == "rss" else 1.0,
                "color": AXIS_COLOURS.get(name),
            },
            name="RSS" if name == "rss" else name,
            hovertemplate=f"{name}: %{{y:.4g}} micro-g<br>interval from %{{x:.5g}} s"
            "<extra></extra>",
        )
        for name, v in [*rows, ("rss", np.asarray(res.rss_g))]
    ]
    return chart(
        traces,
        title=title or f"RMS in {lo:.3g}-{hi:.3g} Hz per {res.interval_s:g}-s interval",
        x_title="interval start [s]",
        y_title="band-limited RMS [micro-g]",
    )
