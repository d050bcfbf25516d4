"""What the interactive charts share: compact data, the size limit of a line, axes, the page.

Every chart's numbers go to plotly as float32 arrays (7 significant digits, far below a pixel),
which plotly writes as base64 typed arrays instead of decimal lists.  A line longer than
:data:`MAX_POINTS` is drawn through its min/max envelope (:func:`microg.plotting.common.envelope`
on a linear abscissa, :func:`log_envelope` on a logarithmic one): every extreme is kept and the
chart says so in a note.  Nothing here writes JavaScript: plotly builds the page's script.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import plotly.graph_objects as go

__all__ = [
    "AXIS_COLOURS",
    "MAX_POINTS",
    "chart",
    "envelope_note",
    "f32",
    "linear_line",
    "log_envelope",
    "log_line",
    "plotly_html",
]

#: largest number of points drawn for one line; longer ones are drawn through their envelope
MAX_POINTS = 4000
#: one colour per axis, in every chart (x, y, z, then the RSS / magnitude in black)
AXIS_COLOURS = {"x": "#1f77b4", "y": "#ff7f0e", "z": "#2ca02c", "rss": "#111111"}


def f32(a: Any) -> np.ndarray:
    """``a`` as a flat float32 array (plotly writes it as a compact typed array)."""
    return np.ascontiguousarray(np.asarray(a, float).ravel(), dtype=np.float32)


def log_envelope(x: np.ndarray, y: np.ndarray, limit: int) -> tuple[np.ndarray, np.ndarray]:
    """A line on a logarithmic abscissa reduced to the min and max of log-spaced slices.

    The first ``limit // 4`` samples are kept as they are (the lowest frequencies, far apart
    on a log axis); the rest is cut into slices evenly spaced in ``log(index)``, of which the
    smallest and the largest sample are kept in order.  Every extreme (a spectral line's peak)
    is kept exactly.  Lines of at most ``limit`` samples are returned unchanged.

    Parameters
    ----------
    x : ndarray (n,)
        Increasing positive abscissae (Hz).
    y : ndarray (n,)
        Ordinates.
    limit : int
        Largest number of samples returned (about).
    """
    x = np.asarray(x)
    y = np.asarray(y)
    n = y.size
    if n <= limit:
        return x, y
    head = max(limit // 4, 1)
    edges = np.unique(np.geomspace(head, n, max((limit - head) // 2, 2)).astype(int))
    edges = edges[(edges >= head) & (edges <= n)]
    if edges[-1] != n:
        edges = np.r_[edges, n]
    keep = [np.arange(head)]
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        seg = y[lo:hi]
        if seg.size:
            keep.append(lo + np.array([int(np.argmin(seg)), int(np.argmax(seg))]))
    idx = np.unique(np.concatenate(keep + [np.array([n - 1])]))
    return x[idx], y[idx]


def linear_line(x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, bool]:
    """x, y of a line on a linear abscissa, enveloped above :data:`MAX_POINTS`; cut or not."""
    from microg.plotting.common import envelope

    x = np.asarray(x, float)
    y = np.asarray(y, float)
    if y.size <= MAX_POINTS:
        return f32(x), f32(y), False
    xe, ye = envelope(x, y, bins=MAX_POINTS // 2 - 1)
    return f32(xe), f32(ye), True


def log_line(x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, bool]:
    """x, y of a line on a logarithmic abscissa, enveloped above :data:`MAX_POINTS`."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    if y.size <= MAX_POINTS:
        return f32(x), f32(y), False
    xe, ye = log_envelope(x, y, MAX_POINTS)
    return f32(xe), f32(ye), True


def chart(
    traces: list[Any],
    *,
    title: str,
    x_title: str,
    y_title: str,
    x_log: bool = False,
    y_log: bool = False,
    notes: list[str] | None = None,
    height: int = 420,
    y_range: tuple[float, float] | None = None,
) -> go.Figure:
    """A 2-D chart: traces, titled axes with their units, the notes under the title.

    Parameters
    ----------
    traces : plotly traces
    title : chart title
    x_title, y_title : axis titles, each with its unit in brackets
    x_log, y_log : logarithmic axes
    notes : lines shown under the title (decimation, what is not judged)
    height : px
    y_range : the y axis's range (in log10 units on a log axis), optional
    """
    import plotly.graph_objects as go

    yaxis: dict[str, Any] = {
        "title": {"text": y_title},
        "type": "log" if y_log else "linear",
        "exponentformat": "power",
    }
    if y_range is not None:
        yaxis["range"] = list(y_range)
    layout: dict[str, Any] = {
        "title": {"text": title, "font": {"size": 14}},
        "xaxis": {
            "title": {"text": x_title},
            "type": "log" if x_log else "linear",
            "exponentformat": "power",
        },
        "yaxis": yaxis,
        "height": height,
        "margin": {"l": 70, "r": 20, "t": 60 + 14 * len(notes or []), "b": 50},
        "legend": {"orientation": "h", "y": -0.18},
        "hovermode": "closest",
        "template": "plotly_white",
    }
    if notes:
        layout["annotations"] = [
            {
                "text": "<br>".join(notes),
                "showarrow": False,
                "x": 0,
                "y": 1.0,
                "xref": "paper",
                "yref": "paper",
                "xanchor": "left",
                "yanchor": "bottom",
                "align": "left",
                "font": {"size": 11, "color": "#555"},
            }
        ]
    return go.Figure(data=traces, layout=layout)


def envelope_note(cut: bool, what: str = "lines") -> list[str]:
    """The note a chart carries when a line was drawn through its envelope."""
    if not cut:
        return []
    return [
        f"{what} longer than {MAX_POINTS:,} points are drawn through their min/max envelope "
        "(every extreme kept)"
    ]


def plotly_html(fig: go.Figure, *, div_id: str, include_plotlyjs: bool) -> str:
    """A figure as an HTML fragment (plotly.js inlined when ``include_plotlyjs``: once a page).

    Parameters
    ----------
    fig : plotly.graph_objects.Figure
    div_id : the element id of the figure in the page
    include_plotlyjs : inline plotly.js (the page then works offline)
    """
    return str(
        fig.to_html(
            full_html=False,
            include_plotlyjs=include_plotlyjs,
            div_id=div_id,
            config={"displaylogo": False, "responsive": True},
            auto_play=False,
        )
    )
