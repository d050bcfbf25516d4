"""Figures of the main job.

The model with its points and mode shapes, the forces, the modes, and each observed point's
history and bands.  They read result objects only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from microg.errors import InputError
from microg.plotting.common import envelope, figure_axes, figure_grid, figure_of, place_labels
from microg.units import G0

if TYPE_CHECKING:
    from microg.analysis import Analysis, Observation
    from microg.dynamics.modes import Modes
    from microg.structure.structure import Structure

__all__ = [
    "analysis_figure",
    "force_figure",
    "isolation_figure",
    "live_axes",
    "model_figure",
    "modes_figure",
    "observation_figure",
    "sample_displacements",
]

#: micro-g per m/s^2
_UG = 1e6 / G0

#: most components whose roots are looked up (each look-up scans the samples once)
_MAX_JOINED = 500


def sample_displacements(structure: Structure, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions (p, 3) of the structure's samples and their displacements (p, 3, m) for phi."""
    s = structure.samples
    if s is None:
        pos = np.array([p.position for p in structure.points.values()]).reshape(-1, 3)
        u = np.array([p.translation @ phi for p in structure.points.values()]).reshape(
            -1, 3, phi.shape[1]
        )
        return pos, u
    pos = np.asarray(s.position, float).reshape(-1, 3)
    if hasattr(s, "displacement"):
        return pos, np.asarray(s.displacement(phi)).reshape(pos.shape[0], 3, -1)
    return pos, np.einsum("pin,nm->pim", np.asarray(s.translation, float), phi)


def _groups(structure: Structure, n: int) -> list[np.ndarray]:
    """Sample indices per component (a beam's nodes, a body's masses), ordered along it.

    Each beam's group starts at its root, the sample where it joins its parent (a beam's own
    samples begin one element out), so the drawn model is connected: on a frame model the
    sample on the parent node of the beam's first node (:class:`~microg.structure.fem.
    FrameTree`), otherwise the nearest sample of another component to either end of the beam.
    The first component (the root body) is left as it is.
    """
    s = structure.samples
    labels = getattr(s, "labels", None)
    comp = getattr(s, "component", None)
    if labels is not None:
        keys = np.array([lab.split("/", 1)[0].split(":", 1)[0] for lab in labels])
    elif comp is not None:
        keys = np.asarray(comp)
    else:
        return [np.arange(n)]
    groups = [np.flatnonzero(keys == k) for k in dict.fromkeys(keys.tolist())]
    pos = np.asarray(getattr(s, "position", np.zeros((0, 3))), float).reshape(-1, 3)
    if not 2 <= len(groups) <= _MAX_JOINED or pos.shape[0] != n:
        return groups
    roots = _tree_roots(structure, groups)
    out = [groups[0]]
    for g, root in zip(groups[1:], roots[1:], strict=True):
        if root is None:
            root = _nearest_root(pos, g)
        out.append(g if root is None or root in g else np.r_[root, g])
    return out


def _tree_roots(structure: Structure, groups: list[np.ndarray]) -> list[int | None]:
    """Per group, the sample on the parent node of its root-most node (frame models), or None."""
    s = structure.samples
    tree = getattr(structure, "tree", None)
    dof = getattr(s, "dof_index", None)
    offset = getattr(s, "offset", None)
    if tree is None or dof is None or offset is None:
        return [None] * len(groups)
    node = np.asarray(dof, int)[:, 0] // 6  # each node's six coordinates, translations first
    child = np.asarray(tree.child, int).tolist()
    parent = dict(zip(child, np.asarray(tree.parent, int).tolist(), strict=True))
    on_node = np.linalg.norm(np.asarray(offset, float), axis=1) == 0.0
    roots: list[int | None] = []
    for g in groups:
        mine = set(node[g].tolist())
        above = [parent[k] for k in mine if k in parent and parent[k] not in mine]
        hits = np.flatnonzero(on_node & (node == above[0])) if len(above) == 1 else np.zeros(0)
        roots.append(int(hits[0]) if hits.size else None)
    return roots


def _nearest_root(pos: np.ndarray, g: np.ndarray) -> int | None:
    """The sample outside ``g`` nearest to either end of the group (ordered along it)."""
    p = pos[g]
    axis = int(np.argmax(np.ptp(p, axis=0))) if g.size > 1 else 0
    order = g[np.argsort(p[:, axis], kind="stable")]
    others = np.setdiff1d(np.arange(pos.shape[0]), g)
    if others.size == 0:
        return None
    best = None
    for end in (order[0], order[-1]):
        d = np.linalg.norm(pos[others] - pos[end], axis=1)
        k = int(np.argmin(d))
        if best is None or d[k] < best[0]:
            best = (float(d[k]), int(others[k]))
    return None if best is None else best[1]


def _draw(ax: Any, pos: np.ndarray, groups: list[np.ndarray], h: int, v: int, **kw: Any) -> None:
    """Each group drawn as a line along it (one line artist, broken by NaN between groups)."""
    parts = []
    for g in groups:
        if g.size == 0:
            continue
        p = pos[g]
        axis = int(np.argmax(np.ptp(p, axis=0))) if g.size > 1 else 0
        order = np.argsort(p[:, axis], kind="stable")
        parts += [p[order][:, [h, v]], np.full((1, 2), np.nan)]
    if parts:
        xy = np.concatenate(parts[:-1])
        ax.plot(xy[:, 0], xy[:, 1], **kw)


def _views(pos: np.ndarray) -> list[tuple[int, int]]:
    """The two projections with the largest extent: (horizontal axis, vertical axis)."""
    ext = np.ptp(pos, axis=0) if pos.size else np.ones(3)
    order = [int(i) for i in np.argsort(-ext, kind="stable")]
    return [(order[1], order[0]), (order[2], order[0])]


def _in_view(pos: np.ndarray, disp: np.ndarray, hv: tuple[int, int]) -> float:
    """How well a view shows a mode: in-view motion times the view's extent."""
    h, v = hv
    motion = float(np.sum(disp[:, h] ** 2 + disp[:, v] ** 2))
    extent = float(np.ptp(pos[:, h]) + np.ptp(pos[:, v])) if pos.size else 1.0
    return motion * extent


def model_figure(
    structure: Structure,
    modes: Modes,
    force_points: dict[str, np.ndarray],
    observed: list[str],
    n_shapes: int = 3,
    *,
    ax: Any = None,
) -> Figure:
    """The model with its force and observed points (two views), and the first mode shapes.

    Parameters
    ----------
    structure : Structure
    modes : Modes
        Mass-normalised modes; the first ``n_shapes`` elastic ones are drawn, each in the
        view where it moves most, scaled to 10 % of the model's size.
    force_points : dict of str to ndarray (3,)
        Point name -> force direction (unit), drawn as arrows.
    observed : list of str
        Observed point names, drawn as squares.
    n_shapes : int
        Elastic mode shapes to draw.
    ax : sequence of matplotlib.axes.Axes, optional
        Where to draw: the two views, then one axes per mode shape (shapes beyond the axes
        given are not drawn).  Default: a new figure, the views above the shapes.
    """
    elastic = np.flatnonzero(~modes.rigid & (modes.omega > 0))[:n_shapes]
    pos, u = sample_displacements(structure, modes.phi[:, elastic])
    groups = _groups(structure, pos.shape[0])
    views = _views(pos)
    size = float(np.max(np.ptp(pos, axis=0))) if pos.size else 1.0
    if ax is None:
        ncol = max(len(elastic), 2)
        fig = Figure(figsize=(7.8, 7.6), layout="constrained")
        grid = fig.add_gridspec(2, ncol * 2)
        panels = [fig.add_subplot(grid[0, c * ncol : (c + 1) * ncol]) for c in range(2)]
        panels += [fig.add_subplot(grid[1, 2 * k : 2 * k + 2]) for k in range(len(elastic))]
    else:
        panels = list(np.asarray(ax, dtype=object).ravel())
        if len(panels) < 2 or not all(isinstance(a, Axes) for a in panels):
            raise InputError(
                f"expected at least 2 matplotlib Axes (two views, then mode shapes), got "
                f"{len(panels)}",
                where="ax",
            )
        fig = figure_of(panels[0])
        elastic = elastic[: len(panels) - 2]
    names = "xyz"
    labels: dict[int, list[tuple[float, float, str, str]]] = {id(a): [] for a in panels[:2]}
    for a, (h, v) in zip(panels[:2], views, strict=True):
        _draw(a, pos, groups, h, v, color="0.35", lw=1.6, marker=".", ms=3)
        for name, d in force_points.items():
            p = structure.points[name].position
            a.annotate(
                "",
                xy=(p[h] + 0.1 * size * d[h], p[v] + 0.1 * size * d[v]),
                xytext=(p[h], p[v]),
                arrowprops={"arrowstyle": "->", "color": "crimson", "lw": 1.8},
            )
            a.plot(p[h], p[v], "o", color="crimson", ms=6)
            labels[id(a)].append((p[h], p[v], f"force at {name}", "crimson"))
        for name in observed:
            p = structure.points[name].position
            a.plot(p[h], p[v], "s", color="navy", ms=7, mfc="none", mew=1.5)
            labels[id(a)].append((p[h], p[v], name, "navy"))
        a.set_aspect("equal", adjustable="datalim")
        a.set_xlabel(f"{names[h]} [m]")
        a.set_ylabel(f"{names[v]} [m]")
        a.set_title(f"{names[h]}-{names[v]} view (force red, observed blue)", fontsize=9)
        a.grid(True, alpha=0.3)
    for k, j in enumerate(elastic):
        disp = u[:, :, k]
        # the view in which this mode moves most
        candidates = [*views, (views[0][0], views[1][0])]
        h, v = max(candidates, key=lambda hv: _in_view(pos, disp, hv))
        peak = float(np.max(np.abs(disp))) or 1.0
        shape = pos + 0.1 * size * disp / peak
        a = panels[2 + k]
        _draw(a, pos, groups, h, v, color="0.75", lw=1.0)
        _draw(a, shape, groups, h, v, color=f"C{k}", lw=1.6)
        a.set_aspect("equal", adjustable="datalim")
        a.set_title(f"mode {j + 1}: {modes.freq_hz[j]:.3g} Hz ({names[h]}-{names[v]})", fontsize=9)
        a.set_xticks([])
        a.set_yticks([])
    for a in panels[:2]:  # once the figure is laid out: labels kept apart
        place_labels(a, labels[id(a)])
    return fig


def force_figure(disturbances: list[Any], duration_s: float, *, ax: Axes | None = None) -> Figure:
    """Each force history f(t) over the record (N), from its breakpoints.

    Parameters
    ----------
    disturbances : list of Disturbance
        Their force histories (breakpoints in s and N) and points.
    duration_s : float
        The record's length, s (the last force value is held to it).
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).
    """
    fig, ax = figure_axes(ax, 7.5, 3.2)
    for d in disturbances:
        f = d.force
        t = np.r_[0.0, f.timepts, max(duration_s, float(f.timepts[-1]))]
        y = np.r_[0.0, f.force, f.force[-1]]
        ax.plot(t, y, lw=1.2, label=f"{f.name} at {d.point}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("force [N]")
    ax.set_title("Disturbances")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def modes_figure(result: Analysis, *, ax: Axes | None = None) -> Figure:
    """Frequencies of the computed modes, numbered as in the modes table, used ones filled.

    Parameters
    ----------
    result : Analysis
        Its ``modes``, ``used``, ``options.max_freq_hz`` (Hz) and ``model`` are drawn.
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).
    """
    fig, ax = figure_axes(ax, 7.5, 3.6)
    m = result.modes
    num = np.arange(1, m.n_modes + 1)
    el = m.omega > 0
    used = result.used & el
    ax.semilogy(num[used], m.freq_hz[used], "o", ms=4, label="in the response")
    ax.semilogy(num[el & ~used], m.freq_hz[el & ~used], "o", ms=4, mfc="none", label="not used")
    ax.axhline(result.options.max_freq_hz, color="k", lw=0.8, ls="--", label="max_freq")
    ax.set_xlabel("mode number (as in the modes table)")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title(f"Modes of {result.model} ({m.n_rigid} rigid-body modes at 0 Hz, not drawn)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def live_axes(accel: np.ndarray) -> list[int]:
    """Axes whose signal is more than round-off of the largest (above 1e-9 of it).

    An axis the force cannot excite (y and z of a push along x on a symmetric station)
    carries ~1e-16 of the others' signal: rounding, not physics.  Figures leave it out.
    """
    peak = np.max(np.abs(accel), axis=1)
    top = float(peak.max()) if peak.size else 0.0
    return [i for i in range(accel.shape[0]) if top > 0 and peak[i] > 1e-9 * top] or [0]


def observation_figure(ob: Observation, *, ax: Any = None, kind: str | None = None) -> Figure:
    """Acceleration history (micro-g) and 1/3-octave band RMS against the limit at a point.

    Parameters
    ----------
    ob : Observation
        The point's response (m/s^2, drawn in micro-g) and assessment (band RMS in g).
    ax : matplotlib.axes.Axes or a pair of them, optional
        Where to draw: one axes for one panel, or two for the history and the bands.
        Default: a new figure with both panels.
    kind : {"history", "bands"}, optional
        One panel only.  Default: both, or the history when ``ax`` is one axes.
    """
    if kind not in (None, "history", "bands"):
        raise InputError(f"unknown kind {kind!r}", where="kind", fix="use history or bands")
    if kind is None and (ax is None or not isinstance(ax, Axes)):
        fig, grid = figure_grid(ax, 2, 1, width_in=7.5, height_in=6.4)
        _history_on(grid[0, 0], ob)
        _bands_on(grid[1, 0], ob)
        return fig
    fig, one = figure_axes(ax, 7.5, 3.6)
    (_bands_on if kind == "bands" else _history_on)(one, ob)
    return fig


def _history_on(ax: Any, ob: Observation) -> None:
    """The acceleration history at a point, micro-g, its live axes."""
    r = ob.response
    for i in live_axes(r.acceleration):
        ax.plot(*envelope(r.timepts, r.acceleration[i] * _UG), lw=0.8, label="xyz"[i])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("acceleration [micro-g]")
    ax.set_title(f"Acceleration at {ob.name} (peak {ob.assessment.peak_accel_g:.3g} g)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)


def _bands_on(ax: Any, ob: Observation) -> None:
    """The 1/3-octave band RMS at a point against the limit's steps, micro-g.

    As the assess plot (``plotting.environment.plot_bands``): filled markers on the bands the
    verdict judges, hollow on the bands the record does not resolve, the judged range shaded.
    """
    to = ob.assessment.third_octave
    res = np.asarray(to.resolved, bool)
    for i in live_axes(ob.response.acceleration):
        y = np.maximum(to.rms_g[i] * 1e6, 1e-30)
        (ln,) = ax.loglog(to.center_hz, y, "-", lw=0.8, label="xyz"[i])
        c = ln.get_color()
        ax.plot(to.center_hz[res], y[res], "o", ms=3, color=c, label="_judged")
        ax.plot(to.center_hz[~res], y[~res], "o", ms=3, mfc="none", color=c, label="_unjudged")
    edges = np.r_[to.lower_hz, to.upper_hz[-1:]]
    ax.stairs(to.limit_g * 1e6, edges, color="k", lw=1.4, label="limit")
    vr = to.verdict_range_hz
    if vr is not None:
        ax.axvspan(vr[0], vr[1], color="0.85", alpha=0.4, lw=0, label="judged bands")
    if np.any(~res):
        ax.plot([], [], "o", ms=3, mfc="none", color="0.3", label="not judged (hollow)")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("band RMS [micro-g]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


def isolation_figure(ob: Observation, *, ax: Axes | None = None) -> Figure:
    """Mount acceleration against what the isolated package feels, on the dominant axis.

    Parameters
    ----------
    ob : Observation
        The point's response and isolation advice (accelerations in m/s^2, drawn in micro-g).
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).
    """
    adv = ob.isolation
    pkg = adv.package_accel
    r = ob.response
    fig, ax = figure_axes(ax, 7.5, 3.8)
    axis = int(np.argmax(np.max(np.abs(r.acceleration), axis=1)))
    ax.plot(*envelope(r.timepts, r.acceleration[axis] * _UG), lw=0.8, label="mount (station)")
    if pkg is not None:
        label = "isolated package" + ("" if adv.recommended else " (mount NOT recommended)")
        ax.plot(*envelope(r.timepts, pkg[axis] * _UG), lw=0.9, label=label)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"acceleration, {'xyz'[axis]} [micro-g]")
    ax.set_title(f"Isolation check at {ob.name}: {adv.status}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def analysis_figure(result: Analysis, *, ax: Axes | None = None) -> Figure:
    """Peak acceleration at each observed point against the report's 1e-5 g.

    Parameters
    ----------
    result : Analysis
        Its observations' peaks (g) and verdicts.
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).
    """
    from microg.analysis import REPORT_LIMIT_G

    fig, ax = figure_axes(ax, 7.5, 3.4)
    names = list(result.observations)
    peaks = [result.observations[n].peak_accel_g for n in names]
    colors = ["tab:green" if result.observations[n].complies else "tab:red" for n in names]
    ax.bar(names, peaks, color=colors)
    ax.axhline(REPORT_LIMIT_G, color="k", ls="--", lw=0.8, label="report's 1e-5 g")
    ax.set_yscale("log")
    ax.set_ylabel("peak acceleration [g]")
    ax.set_title("Peak at each observed point (green: band verdict complies)")
    ax.legend(fontsize=8)
    return fig
