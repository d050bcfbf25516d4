"""Values over the structure in 3-D: locate's acceleration map, the quasi-steady map (plotly).

The map's values colour the structure itself: each sampled line (a beam, a body) is drawn
through its samples with the colour of the value there, on a logarithmic colour scale whose bar
is labelled in the map's unit (g for the acceleration map, micro-g for the quasi-steady map);
every sample is a marker whose hover gives its component, label, position (m) and value with its
unit.  Above :data:`MAX_MAP_SAMPLES` samples every k-th sample of each line is drawn (its ends
kept) and the figure says so.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from microg.plotting.interactive.common import f32
from microg.units import G0

if TYPE_CHECKING:
    import plotly.graph_objects as go

    from microg.location.mapping import AccelerationMap, Location

__all__ = ["MAX_MAP_SAMPLES", "acceleration_map_3d", "log_colourbar", "quasi_steady_3d"]

#: largest number of map samples drawn; above it every k-th sample of each line is drawn
MAX_MAP_SAMPLES = 6000

_SCENE = {
    "aspectmode": "data",
    "xaxis": {"title": {"text": "x (m)"}},
    "yaxis": {"title": {"text": "y (m)"}},
    "zaxis": {"title": {"text": "z (m)"}},
}


def log_colourbar(values: np.ndarray, unit: str, label: str) -> tuple[np.ndarray, dict[str, Any]]:
    """log10 of positive ``values`` (others at the floor) and a colour bar labelled in ``unit``.

    Returns the colour values and the marker/line keywords (``cmin``, ``cmax``, the bar with
    ticks at each decade, or at the ends when the range is under a decade).
    """
    v = np.asarray(values, float)
    pos = v[v > 0]
    lo = float(np.log10(pos.min())) if pos.size else -12.0
    hi = float(np.log10(pos.max())) if pos.size else lo + 1.0
    if hi - lo < 1e-9:
        lo, hi = lo - 0.5, hi + 0.5
    c = np.log10(np.maximum(v, 10.0**lo))
    ticks = np.arange(np.ceil(lo), np.floor(hi) + 1)
    if ticks.size < 2:
        ticks = np.array([lo, hi])
    bar = {
        "title": {"text": f"{label}<br>[{unit}]"},
        "tickvals": [float(t) for t in ticks],
        "ticktext": [f"{10.0**t:.2g}" for t in ticks],
    }
    return c, {"cmin": lo, "cmax": hi, "colorscale": "Viridis", "colorbar": bar}


def _thinned(lines: list[np.ndarray], n: int, limit: int) -> tuple[list[np.ndarray], int]:
    step = max(1, int(np.ceil(n / max(limit, 1))))
    if step == 1:
        return lines, 1
    out = []
    for g in lines:
        keep = g[::step]
        if g.size and keep[-1] != g[-1]:
            keep = np.r_[keep, g[-1]]
        out.append(keep)
    return out, step


def _note(text: str) -> dict[str, Any]:
    return {
        "text": text,
        "showarrow": False,
        "x": 0,
        "y": 1.0,
        "xref": "paper",
        "yref": "paper",
        "xanchor": "left",
        "font": {"size": 11, "color": "#555"},
    }


def acceleration_map_3d(
    amap: AccelerationMap,
    *,
    measure: str = "total",
    best: Location | None = None,
    title: str | None = None,
) -> go.Figure:
    """The acceleration map coloured along the structure in 3-D (a plotly Figure).

    Parameters
    ----------
    amap : AccelerationMap
        Peak acceleration per sample (m/s^2, shown in g), the samples' lines and positions (m).
    measure : the map's measure drawn (:meth:`AccelerationMap.measure`)
    best : Location, optional
        The quietest sample, drawn as a ring.
    title : str, optional

    Returns
    -------
    plotly.graph_objects.Figure
        Trace 0 the structure's lines coloured by the value, trace 1 the samples (hover: value
        in g), then the crew point, the nodes of the fundamental and the best location.
    """
    import plotly.graph_objects as go

    values_g = np.asarray(amap.measure(measure), float) / G0
    pos = np.asarray(amap.positions, float)
    n = pos.shape[0]
    lines = [np.asarray(ln.index, int) for ln in amap.lines]
    on_line = np.zeros(n, bool)
    for g in lines:
        on_line[g] = True
    lines += [np.array([i]) for i in np.flatnonzero(~on_line)]  # samples on no line: markers
    lines, step = _thinned(lines, n, MAX_MAP_SAMPLES)
    colour, scale = log_colourbar(values_g, "g", f"peak acceleration ({measure})")
    idx = np.concatenate([np.r_[g, -1] for g in lines if g.size])
    xyz = np.where(idx[:, None] >= 0, pos[idx], np.nan)
    # a NaN vertex breaks the line; its colour is its neighbour's (plotly needs a number)
    col = colour[np.where(idx >= 0, idx, np.r_[idx[1:], 0])]
    shown = np.unique(idx[idx >= 0])
    comp = np.asarray(amap.component).astype(str)
    labels = (
        np.asarray(amap.labels).astype(str)
        if amap.labels is not None
        else np.full(n, "", dtype=object)
    )
    text = [f"{comp[i]} {labels[i]}".strip() for i in shown]
    traces: list[Any] = [
        go.Scatter3d(
            x=f32(xyz[:, 0]),
            y=f32(xyz[:, 1]),
            z=f32(xyz[:, 2]),
            mode="lines",
            name="structure, coloured by the peak",
            line={"width": 8, "color": f32(col), **scale, "showscale": False},
            hoverinfo="skip",
        ),
        go.Scatter3d(
            x=f32(pos[shown, 0]),
            y=f32(pos[shown, 1]),
            z=f32(pos[shown, 2]),
            mode="markers",
            name="samples (hover: peak, g)",
            marker={"size": 3, "color": f32(colour[shown]), **scale, "showscale": True},
            customdata=f32(values_g[shown]),
            text=text,
            hovertemplate="%{text}<br>peak %{customdata:.4g} g<br>"
            "(%{x:.4g}, %{y:.4g}, %{z:.4g}) m<extra></extra>",
        ),
    ]
    cp = np.asarray(amap.crew_position, float).reshape(1, 3)
    traces.append(
        go.Scatter3d(
            x=f32(cp[:, 0]),
            y=f32(cp[:, 1]),
            z=f32(cp[:, 2]),
            mode="markers+text",
            text=[f"force at {amap.crew_point}"],
            textposition="top center",
            name=f"force point {amap.crew_point!r}",
            marker={"size": 7, "color": "#d62728", "symbol": "diamond"},
            hovertemplate="%{text}<br>(%{x:.4g}, %{y:.4g}, %{z:.4g}) m<extra></extra>",
        )
    )
    if amap.nodes:
        npos = np.array([nd.position for nd in amap.nodes], float).reshape(-1, 3)
        traces.append(
            go.Scatter3d(
                x=f32(npos[:, 0]),
                y=f32(npos[:, 1]),
                z=f32(npos[:, 2]),
                mode="markers",
                name="nodes of the fundamental",
                text=[f"node on {nd.component}" for nd in amap.nodes],
                marker={"size": 6, "color": "black", "symbol": "x"},
                hovertemplate="%{text}<br>(%{x:.4g}, %{y:.4g}, %{z:.4g}) m<extra></extra>",
            )
        )
    if best is not None:
        bp = np.asarray(best.position, float).reshape(1, 3)
        traces.append(
            go.Scatter3d(
                x=f32(bp[:, 0]),
                y=f32(bp[:, 1]),
                z=f32(bp[:, 2]),
                mode="markers+text",
                text=[f"best ({best.measure}) {best.peak / G0:.3g} g"],
                textposition="bottom center",
                name=f"best location ({best.measure})",
                marker={"size": 9, "color": "magenta", "symbol": "circle-open"},
                hovertemplate="%{text}<br>(%{x:.4g}, %{y:.4g}, %{z:.4g}) m<extra></extra>",
            )
        )
    layout: dict[str, Any] = {
        "title": {"text": title or f"Peak acceleration from a force at {amap.crew_point!r}"},
        "scene": _SCENE,
        "margin": {"l": 0, "r": 0, "t": 50, "b": 0},
        "legend": {"orientation": "h"},
        "height": 620,
    }
    if step > 1:
        layout["annotations"] = [_note(f"every {step}th of {n:,} samples drawn (line ends kept)")]
    return go.Figure(data=traces, layout=layout)


def quasi_steady_3d(result: Any, *, title: str | None = None) -> go.Figure:
    """The peak quasi-steady magnitude over the orbit at the structure's samples, in 3-D.

    Parameters
    ----------
    result : microg.environment.quasisteady.QuasiSteadyResult
        Its ``map`` (positions m, peak magnitudes m/s^2, shown in micro-g), named points and
        centre of mass.
    title : str, optional

    Returns
    -------
    plotly.graph_objects.Figure
        Trace 0 the samples coloured by the peak (hover: micro-g, within the limit or not),
        then the named points and the centre of mass.
    """
    import plotly.graph_objects as go

    limit_ug = float(result.requirement.limit_g) * 1e6
    traces: list[Any] = []
    notes = []
    qmap = result.map
    if qmap is not None:
        pos = np.asarray(qmap.positions_m, float)
        pk = np.asarray(qmap.peak_magnitude_mps2, float) / G0 * 1e6
        n = pos.shape[0]
        step = max(1, int(np.ceil(n / MAX_MAP_SAMPLES)))
        keep = np.arange(0, n, step)
        if step > 1:
            notes.append(f"every {step}th of {n:,} samples drawn")
        colour, scale = log_colourbar(pk, "micro-g", "peak quasi-steady magnitude")
        within = np.asarray(qmap.within, bool)
        labels = list(qmap.labels)
        traces.append(
            go.Scatter3d(
                x=f32(pos[keep, 0]),
                y=f32(pos[keep, 1]),
                z=f32(pos[keep, 2]),
                mode="markers",
                name=f"samples (circle: within {limit_ug:g} micro-g, cross: above)",
                marker={
                    "size": 4,
                    "color": f32(colour[keep]),
                    "symbol": ["circle" if within[i] else "x" for i in keep],
                    **scale,
                    "showscale": True,
                },
                customdata=f32(pk[keep]),
                text=[labels[i] if i < len(labels) else "" for i in keep],
                hovertemplate="%{text}<br>peak %{customdata:.4g} micro-g<br>"
                "(%{x:.4g}, %{y:.4g}, %{z:.4g}) m<extra></extra>",
            )
        )
    named = {k: p for k, p in result.points.items() if k != "cm"}
    if named:
        p = np.array([v.position_m for v in named.values()], float).reshape(-1, 3)
        peaks = np.array([v.peak_magnitude_mps2 / G0 * 1e6 for v in named.values()], float)
        traces.append(
            go.Scatter3d(
                x=f32(p[:, 0]),
                y=f32(p[:, 1]),
                z=f32(p[:, 2]),
                mode="markers+text",
                text=list(named),
                textposition="top center",
                name="named points",
                marker={"size": 6, "color": "#333", "symbol": "diamond-open"},
                customdata=f32(peaks),
                hovertemplate="%{text}<br>peak %{customdata:.4g} micro-g<br>"
                "(%{x:.4g}, %{y:.4g}, %{z:.4g}) m<extra></extra>",
            )
        )
    cm = np.asarray(result.center_of_mass_m, float).reshape(1, 3)
    traces.append(
        go.Scatter3d(
            x=f32(cm[:, 0]),
            y=f32(cm[:, 1]),
            z=f32(cm[:, 2]),
            mode="markers",
            name="centre of mass",
            marker={"size": 7, "color": "crimson", "symbol": "diamond"},
            hovertemplate="centre of mass<br>(%{x:.4g}, %{y:.4g}, %{z:.4g}) m<extra></extra>",
        )
    )
    layout: dict[str, Any] = {
        "title": {
            "text": title
            or f"{result.model}: peak quasi-steady magnitude over the orbit "
            f"(limit {limit_ug:g} micro-g)"
        },
        "scene": _SCENE,
        "margin": {"l": 0, "r": 0, "t": 50, "b": 0},
        "legend": {"orientation": "h"},
        "height": 600,
    }
    if notes:
        layout["annotations"] = [_note("; ".join(notes))]
    return go.Figure(data=traces, layout=layout)
