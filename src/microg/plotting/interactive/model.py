"""The model in 3-D and its modes (plotly), for notebooks and the HTML report.

The structure's samples are drawn as lines (each beam or body along itself, broken between
components), the named points as labelled markers, force points in red with a cone along the
force, observed points in blue and ringed (their own trace).  Every elastic mode is an animation
frame chosen with a slider: the deformed shape scaled so its largest translation is 10 % of the
model's size, titled with its frequency, modal mass and the effective-mass fractions of the
directions it participates in (above :data:`EFFECTIVE_MASS_SHOWN`).  Above :data:`MAX_SAMPLES`
samples the lines are decimated (every k-th sample of each component, its ends kept) and the
figure says so; above :data:`MAX_FRAMES` elastic modes only the lowest are framed, also said.

plotly builds the figure (``plotly.graph_objects``); nothing here writes JavaScript.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.plotting.analysis import _groups, sample_displacements

if TYPE_CHECKING:
    import plotly.graph_objects as go

    from microg.dynamics.modes import Modes

__all__ = ["EFFECTIVE_MASS_SHOWN", "MAX_FRAMES", "MAX_SAMPLES", "modes_3d"]

#: largest number of samples drawn as lines; more are decimated per component
MAX_SAMPLES = 4000
#: largest number of elastic modes given an animation frame
MAX_FRAMES = 40
#: smallest effective-mass fraction (of the station's r^T M r) a frame's title lists
EFFECTIVE_MASS_SHOWN = 0.01
#: a named point's hover text: its name and coordinates with their unit
_HOVER = "%{text}<br>x %{x:.4g} m<br>y %{y:.4g} m<br>z %{z:.4g} m<extra></extra>"


def _decimated(groups: list[np.ndarray], limit: int) -> tuple[list[np.ndarray], int]:
    """Each component's samples thinned to about ``limit`` in all (ends kept); the step."""
    total = sum(g.size for g in groups)
    step = max(1, int(np.ceil(total / max(limit, 1))))
    if step == 1:
        return groups, 1
    out = []
    for g in groups:
        keep = g[::step]
        if g.size and keep[-1] != g[-1]:
            keep = np.r_[keep, g[-1]]
        out.append(keep)
    return out, step


def _ordered(pos: np.ndarray, groups: list[np.ndarray]) -> list[np.ndarray]:
    """Each component's samples in order along its longest extent (a beam from root to tip)."""
    out = []
    for g in groups:
        if g.size > 1:
            axis = int(np.argmax(np.ptp(pos[g], axis=0)))
            g = g[np.argsort(pos[g][:, axis], kind="stable")]
        out.append(g)
    return out


def _lines(p: np.ndarray, groups: list[np.ndarray]) -> tuple[np.ndarray, ...]:
    """x, y, z arrays of the components, each broken from the next by NaN (a gap in the line).

    float32 (7 digits: far below a pixel of the view), so plotly writes them as compact typed
    arrays and validates them without looping over the values.
    """
    parts = [np.vstack([p[g], np.full((1, 3), np.nan)]) for g in groups if g.size]
    xyz = np.concatenate(parts).astype(np.float32) if parts else np.zeros((0, 3), np.float32)
    return xyz[:, 0], xyz[:, 1], xyz[:, 2]


def _mode_title(modes: Modes, j: int) -> str:
    """'mode 7: 0.1269 Hz, modal mass 1.2e+04 kg, effective mass x 35%, ry 12%'.

    The modal mass is the shape's at a largest point motion of 1 m (``Modes.modal_mass``).  The
    effective masses are given as fractions of the station's ``r_d^T M r_d``
    (``Modes.effective_mass_fraction``), every direction above :data:`EFFECTIVE_MASS_SHOWN`;
    a free-free structure's elastic modes have none (their fractions are exactly zero), said
    as "below 1 % in every direction".  A structure without rigid-body vectors (clamped) has
    no fractions, and the title gives none.
    """
    text = f"mode {j + 1}: {modes.freq_hz[j]:.4g} Hz, modal mass {modes.modal_mass[j]:.3g} kg"
    frac = {d: float(np.asarray(v)[j]) for d, v in modes.effective_mass_fraction.items()}
    shown = [f"{d} {100 * v:.3g}%" for d, v in frac.items() if v > EFFECTIVE_MASS_SHOWN]
    if shown:
        text += ", effective mass " + ", ".join(shown)
    elif frac:
        text += f", effective mass below {100 * EFFECTIVE_MASS_SHOWN:g}% in every direction"
    return text


def modes_3d(
    modes: Modes,
    *,
    force_points: Mapping[str, np.ndarray] | None = None,
    observed: Sequence[str] = (),
    title: str | None = None,
) -> go.Figure:
    """The model in 3-D with a slider over its elastic modes (a plotly Figure).

    Parameters
    ----------
    modes : Modes
        Mass-normalised modes of a structure with samples or named points (m).
    force_points : mapping of str to ndarray (3,), optional
        Named points where forces act -> unit direction (model frame), drawn in red.
    observed : sequence of str
        Named points assessed, drawn in blue and ringed.
    title : str, optional
        Figure title (default: the method and the number of modes).

    Returns
    -------
    plotly.graph_objects.Figure
        Trace 0 the undeformed model, trace 1 the deformed shape of the frame shown, then the
        named points, the observed points (``"observed points"``, at their positions, in the
        order given) and the force cones (``"force direction"``, at each force point along its
        direction); ``frames`` one per elastic mode (``name`` ``"mode N"``).
    """
    import plotly.graph_objects as go

    structure = modes.structure
    elastic = np.flatnonzero(~np.asarray(modes.rigid, bool) & (np.asarray(modes.omega) > 0))
    framed = elastic[:MAX_FRAMES]
    pos, u = sample_displacements(structure, modes.phi[:, framed])
    groups = _ordered(pos, _groups(structure, pos.shape[0]))
    groups, step = _decimated(groups, MAX_SAMPLES)
    size = float(np.max(np.ptp(pos, axis=0))) if pos.size else 1.0
    x0, y0, z0 = _lines(pos, groups)
    base = go.Scatter3d(
        x=x0,
        y=y0,
        z=z0,
        mode="lines",
        name="model (undeformed)",
        line={"color": "#999", "width": 3},
        hoverinfo="skip",
    )

    def shape(k: int) -> np.ndarray:
        d = u[:, :, k]
        peak = float(np.max(np.abs(d))) or 1.0
        return pos + 0.1 * size * d / peak

    first = shape(0) if framed.size else pos
    x1, y1, z1 = _lines(first, groups)
    deformed = go.Scatter3d(
        x=x1,
        y=y1,
        z=z1,
        mode="lines",
        name="mode shape",
        line={"color": "#1f77b4", "width": 5},
        hoverinfo="skip",
    )
    traces: list[Any] = [base, deformed]
    pts = structure.points
    forces = dict(force_points or {})
    names = list(pts)
    if names:
        p = np.array([pts[n].position for n in names], float).reshape(-1, 3)
        colour = [
            "#d62728" if n in forces else "#08306b" if n in observed else "#555" for n in names
        ]
        traces.append(
            go.Scatter3d(
                x=p[:, 0],
                y=p[:, 1],
                z=p[:, 2],
                mode="markers+text",
                text=names,
                name="named points (force red, observed blue)",
                textposition="top center",
                marker={"size": 4, "color": colour},
                hovertemplate=_HOVER,
            )
        )
    seen = [n for n in observed if n in pts]
    if seen:
        op = np.array([pts[n].position for n in seen], float).reshape(-1, 3)
        traces.append(
            go.Scatter3d(
                x=op[:, 0],
                y=op[:, 1],
                z=op[:, 2],
                mode="markers",
                text=seen,
                name="observed points",
                marker={"size": 9, "color": "#08306b", "symbol": "circle-open"},
                hovertemplate=_HOVER,
            )
        )
    if forces:
        fp = np.array([pts[n].position for n in forces if n in pts], float).reshape(-1, 3)
        fd = np.array([forces[n] for n in forces if n in pts], float).reshape(-1, 3)
        if fp.size:
            traces.append(
                go.Cone(
                    x=fp[:, 0],
                    y=fp[:, 1],
                    z=fp[:, 2],
                    u=fd[:, 0],
                    v=fd[:, 1],
                    w=fd[:, 2],
                    sizemode="absolute",
                    sizeref=0.06 * size,
                    anchor="tail",
                    showscale=False,
                    colorscale=[[0, "#d62728"], [1, "#d62728"]],
                    name="force direction",
                    hoverinfo="name",
                )
            )
    frames = []
    for k, j in enumerate(framed):
        xk, yk, zk = _lines(shape(k), groups)
        frames.append(
            go.Frame(
                name=f"mode {j + 1}",
                data=[go.Scatter3d(x=xk, y=yk, z=zk)],
                traces=[1],
                layout={"title": {"text": _mode_title(modes, int(j))}},
            )
        )
    notes = []
    if step > 1:
        notes.append(f"lines show every {step}th of {pos.shape[0]:,} samples")
    if elastic.size > framed.size:
        notes.append(f"the lowest {framed.size} of {elastic.size} elastic modes are framed")
    n_rigid = int(np.count_nonzero(modes.rigid))
    head = title or (
        _mode_title(modes, int(framed[0]))
        if framed.size
        else f"{modes.method}: {modes.n_modes} modes, {n_rigid} rigid"
    )
    layout: dict[str, Any] = {
        "title": {"text": head},
        "scene": {
            "aspectmode": "data",
            "xaxis": {"title": {"text": "x (m)"}},
            "yaxis": {"title": {"text": "y (m)"}},
            "zaxis": {"title": {"text": "z (m)"}},
        },
        "margin": {"l": 0, "r": 0, "t": 40, "b": 0},
        "legend": {"orientation": "h"},
        "height": 620,
    }
    if notes:
        layout["annotations"] = [
            {
                "text": "; ".join(notes),
                "showarrow": False,
                "x": 0,
                "y": 1.0,
                "xref": "paper",
                "yref": "paper",
                "xanchor": "left",
                "font": {"size": 11},
            }
        ]
    if frames:
        layout["sliders"] = [
            {
                "active": 0,
                "currentvalue": {"prefix": "shown: "},
                "pad": {"t": 10},
                "steps": [
                    {
                        "label": f.name.split()[1],
                        "method": "animate",
                        "args": [
                            [f.name],
                            {
                                "mode": "immediate",
                                "frame": {"duration": 0, "redraw": True},
                                "transition": {"duration": 0},
                            },
                        ],
                    }
                    for f in frames
                ],
            }
        ]
    return go.Figure(data=traces, frames=frames, layout=layout)
