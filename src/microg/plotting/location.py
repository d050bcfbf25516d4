"""Figures of the location stage: the acceleration map, a layout's gain, conclusion 7.

Figures are built with ``matplotlib.figure.Figure`` (no pyplot, no backend switch), so
they work in scripts, servers and notebooks alike.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from microg.units import FT, G0

if TYPE_CHECKING:
    from microg.location.amap import AccelerationMap, Location
    from microg.location.layout import LayoutResult
    from microg.seed.conclusion7 import Conclusion7

__all__ = ["plot_conclusion7", "plot_layout", "plot_map"]


def _figure(ax: Any, width: float, height: float) -> Any:
    """The figure and axes to draw into: the caller's ``ax``, or a new figure of this size."""
    from microg.plotting.common import figure_axes

    return figure_axes(ax, width, height)


def plot_map(
    amap: AccelerationMap,
    *,
    measure: str = "total",
    title: str | None = None,
    best: Location | None = None,
    ax: Any = None,
) -> Any:
    """The map drawn on the structure: lines in the view plane, colour = log10 peak (g).

    The view plane is spanned by the two axes along which the samples extend most (the
    IOC: y-z, keel vertical and boom horizontal).  Nodes of the fundamental are black
    crosses, the crew point a red star, ``best`` (if given) a magenta circle.

    Parameters
    ----------
    amap : AccelerationMap
    measure : str
        The map's measure drawn (see :meth:`AccelerationMap.measure`).
    title : str, optional
    best : Location, optional
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize

    values = amap.measure(measure) / G0
    ext = np.ptp(amap.positions, axis=0)
    ax_idx = np.sort(np.argsort(ext)[-2:])
    names = "xyz"
    logv = np.log10(np.maximum(values, 1e-30))
    finite = values > 0
    vmin = float(logv[finite].min()) if np.any(finite) else -12.0
    vmax = float(logv[finite].max()) if np.any(finite) else -6.0
    if vmax <= vmin:
        vmin, vmax = vmin - 0.5, vmax + 0.5
    fig, ax = _figure(ax, 7.5, 6.0)
    norm = Normalize(vmin, vmax)
    for line in amap.lines:
        xy = amap.positions[line.index][:, ax_idx]
        segs = np.stack([xy[:-1], xy[1:]], axis=1)
        seg_val = 0.5 * (logv[line.index][:-1] + logv[line.index][1:])
        # matplotlib's stub wants a Sequence; an (nseg, 2, 2) ndarray is accepted at run time
        lc = LineCollection(segs, cmap="viridis", norm=norm, linewidths=5)  # type: ignore[arg-type]
        lc.set_array(seg_val)
        ax.add_collection(lc)
    sc = ax.scatter(
        amap.positions[:, ax_idx[0]],
        amap.positions[:, ax_idx[1]],
        c=logv,
        cmap="viridis",
        norm=norm,
        s=12,
        zorder=3,
    )
    fig.colorbar(sc, ax=ax, label=f"log10 peak acceleration ({measure}), g")
    if amap.nodes:
        npos = np.array([n.position for n in amap.nodes])
        ax.scatter(
            npos[:, ax_idx[0]],
            npos[:, ax_idx[1]],
            marker="x",
            c="k",
            s=80,
            zorder=4,
            label="nodes of the fundamental",
        )
    ax.scatter(
        [amap.crew_position[ax_idx[0]]],
        [amap.crew_position[ax_idx[1]]],
        marker="*",
        c="r",
        s=160,
        zorder=5,
        label=f"crew point {amap.crew_point!r}",
    )
    if best is not None:
        ax.scatter(
            [best.position[ax_idx[0]]],
            [best.position[ax_idx[1]]],
            marker="o",
            facecolors="none",
            edgecolors="m",
            s=160,
            linewidths=2,
            zorder=5,
            label=f"best location ({best.measure})",
        )
    ax.set_xlabel(f"{names[ax_idx[0]]} (m)")
    ax.set_ylabel(f"{names[ax_idx[1]]} (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(title or f"Peak acceleration from a push-off at {amap.crew_point!r}")
    return fig


def plot_layout(result: LayoutResult, *, ax: Any = None) -> Any:
    """Peaks at the experiment site before and after the optimiser (bars, log scale, g).

    Parameters
    ----------
    result : LayoutResult
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _figure(ax, 7.5, 4.5)
    a, b = result.initial_peak, result.optimal_peak
    labels = ["total", "rigid", "elastic"]
    before = [a.total_mps2, a.rigid_mps2, a.elastic_mps2]
    after = [b.total_mps2, b.rigid_mps2, b.elastic_mps2]
    el_a = a.per_mode_mps2[a.elastic]
    el_b = b.per_mode_mps2[b.elastic]
    for j in range(min(el_a.size, el_b.size)):
        labels.append(f"mode {j + 1}\n{b.omega[b.elastic][j]:.3g} rad/s")
        before.append(float(el_a[j]))
        after.append(float(el_b[j]))
    x = np.arange(len(labels))
    floor = 1e-30
    ax.bar(x - 0.2, np.maximum(np.array(before) / G0, floor), 0.4, label="initial layout")
    ax.bar(x + 0.2, np.maximum(np.array(after) / G0, floor), 0.4, label="optimal layout")
    ax.set_yscale("log")
    top = max(max(before), max(after)) / G0
    ax.set_ylim(max(top * 1e-6, floor), top * 3)
    ax.set_xticks(x, labels, fontsize=8)
    ax.set_ylabel("peak acceleration at the site, g")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    ax.set_title(
        f"{result.model}: {result.measure} peak at {result.experiment!r}, "
        f"x{result.improvement:.3g} lower"
    )
    return fig


def plot_conclusion7(c7: Conclusion7, *, ax: Any = None) -> Any:
    """Figure 9 recomputed: elastic and total peak along the main body, with and without orbiter.

    Parameters
    ----------
    c7 : Conclusion7
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _figure(ax, 7.5, 4.8)
    for case, color in ((c7.orbiter, "C0"), (c7.no_orbiter, "C1")):
        amap = case.amap
        sel = amap.component == case.body
        z = amap.positions[sel, 2]
        o = np.argsort(z)
        ax.semilogy(
            z[o] / FT, amap.elastic_peak[sel][o] / G0, color=color, label=f"{case.model}: elastic"
        )
        ax.semilogy(
            z[o] / FT,
            amap.total_peak[sel][o] / G0,
            color=color,
            ls="--",
            label=f"{case.model}: total",
        )
        for zn in case.body_nodes_z:
            ax.axvline(zn / FT, color=color, lw=0.8, ls=":")
        ax.axvline(case.cm_z / FT, color=color, lw=0.8, ls="-.")
    ax.axvline(c7.orbiter.lab_z / FT, color="k", lw=0.8, label="laboratory")
    ax.set_xlabel("z along the main body (ft)")
    ax.set_ylabel("peak acceleration, g")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ax.set_title("Conclusion 7: node of the fundamental (dotted), centre of mass (dash-dot)")
    return fig
