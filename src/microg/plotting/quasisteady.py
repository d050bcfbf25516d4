"""Figure of the quasi-steady environment: peak magnitude over the structure, the 1 micro-g zone.

Two views of the station (side: x-z, front: y-z), the structure's sample points coloured by the
peak quasi-steady magnitude over the orbit (micro-g, logarithmic), the centre of mass, the named
points, and the requirement's contour (the boundary of the "1 micro-g zone") computed on a grid
in each view's plane through the centre of mass.  Built with ``matplotlib.figure.Figure``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from microg.plotting.common import figure_grid, place_labels
from microg.units import G0

__all__ = ["plot_quasi_steady_map"]

#: grid points per side of the contour grids
_GRID = 121


def _limits(values: np.ndarray, cm: float) -> tuple[float, float]:
    lo, hi = float(min(values.min(initial=cm), cm)), float(max(values.max(initial=cm), cm))
    pad = max(0.08 * (hi - lo), 5.0)
    return lo - pad, hi + pad


def plot_quasi_steady_map(result: Any, *, ax: Any = None) -> Figure:
    """The peak quasi-steady magnitude over the structure and the 1 micro-g zone; a Figure.

    Parameters
    ----------
    result : microg.environment.quasisteady.QuasiSteadyResult
    ax : pair of matplotlib.axes.Axes, optional
        The side and front views' axes (default: a new figure, titled).
    """
    new = ax is None
    fig, grid = figure_grid(ax, 1, 2, width_in=10.0, height_in=4.8)
    axes = grid[0]
    cm = np.asarray(result.center_of_mass_m, float)
    limit_ug = result.requirement.limit_g * 1e6
    qmap = result.map
    pos = qmap.positions_m if qmap is not None else np.zeros((0, 3))
    pk = qmap.peak_magnitude_mps2 / G0 * 1e6 if qmap is not None else np.zeros(0)
    named = {n: p for n, p in result.points.items() if n != "cm"}
    every = np.vstack([pos, *[p.position_m[None, :] for p in named.values()], cm[None, :]])
    values = [pk] + [np.array([p.peak_magnitude_mps2 / G0 * 1e6]) for p in named.values()]
    allv = np.concatenate(values) if values else np.zeros(0)
    positive = allv[allv > 0]
    vmin = float(max(positive.min(initial=limit_ug) * 0.8, 1e-3 * limit_ug))
    vmax = float(max(positive.max(initial=limit_ug) * 1.2, 2.0 * limit_ug))
    norm = LogNorm(vmin=vmin, vmax=vmax)
    sc = None
    labels: dict[int, list[tuple[float, float, str, str]]] = {id(a): [] for a in axes}
    for ax, (i, j), title in zip(
        axes, ((0, 2), (1, 2)), ("side view (x-z)", "front view (y-z)"), strict=True
    ):
        xlo, xhi = _limits(every[:, i], cm[i])
        ylo, yhi = _limits(every[:, j], cm[j])
        gx, gy = np.meshgrid(np.linspace(xlo, xhi, _GRID), np.linspace(ylo, yhi, _GRID))
        grid = np.tile(cm, (gx.size, 1))
        grid[:, i] = gx.ravel()
        grid[:, j] = gy.ravel()
        mag = result.peak_at(grid).reshape(gx.shape) / G0 * 1e6
        ax.contourf(gx, gy, mag <= limit_ug, levels=[0.5, 1.5], colors=["#cfe8cf"], alpha=0.8)
        ax.contour(gx, gy, mag, levels=[limit_ug], colors=["green"], linewidths=1.2)
        if pos.size:
            sc = ax.scatter(
                pos[:, i], pos[:, j], c=np.maximum(pk, vmin), norm=norm, s=14, cmap="viridis"
            )
        ax.plot(
            cm[i],
            cm[j],
            marker="*",
            color="crimson",
            markersize=12,
            linestyle="none",
            label="centre of mass",
        )
        for name, p in named.items():
            ax.plot(
                p.position_m[i],
                p.position_m[j],
                marker="o",
                mfc="none",
                color="k",
                linestyle="none",
            )
            labels[id(ax)].append(
                (
                    p.position_m[i],
                    p.position_m[j],
                    f"{name} {p.peak_magnitude_mps2 / G0 * 1e6:.3g} ug",
                    "k",
                )
            )
        ax.set_xlabel(f"{'xyz'[i]} (m)")
        ax.set_ylabel(f"{'xyz'[j]} (m)")
        ax.set_title(title)
        ax.set_aspect("equal", adjustable="datalim")
    axes[0].legend(loc="lower right", fontsize=7)
    if sc is not None:
        fig.colorbar(
            sc, ax=list(axes), label="peak quasi-steady magnitude over the orbit (micro-g)"
        )
    if new:
        fig.suptitle(
            f"{result.model}: quasi-steady acceleration, {result.attitude.kind} attitude; "
            f"shaded: within {limit_ug:g} micro-g (contour in the plane through the CM)"
        )
    for a in axes:  # once the figure is laid out: labels kept apart
        place_labels(a, labels[id(a)], fontsize=7)
    return fig
