"""Figures of a sweep: the margin heat map, the complying fraction per axis, the worst bands.

They read a :class:`~microg.study.summary.Summary` only (figures are built without pyplot).
Every figure function takes ``ax=``, the matplotlib axes to draw into (default: a new
figure), and returns the figure.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from microg.plotting.common import figure_axes, figure_grid

if TYPE_CHECKING:
    from microg.study.summary import Summary

__all__ = ["heatmap_figure", "fraction_figure", "worst_bands_figure"]

#: most labels drawn along a heat map's axis
_MAX_TICKS = 40


def _ticks(ax: Any, n: int, labels: Sequence[object], axis: str) -> None:
    step = max(1, int(np.ceil(n / _MAX_TICKS)))
    pos = np.arange(0, n, step)
    text = [str(labels[int(i)]) for i in pos]
    if axis == "x":
        ax.set_xticks(pos, text, rotation=60, ha="right", fontsize=7)
    else:
        ax.set_yticks(pos, text, fontsize=7)


def heatmap_figure(summary: Summary, *, ax: Axes | None = None) -> Figure:
    """Worst margin (limit / band RMS, min over the other axes) over two axes.

    The colour scale is logarithmic in the margin itself (the colour bar reads margins, 1 at
    its middle: a margin of 0.1 is as far below as 10 is above), the cells are labelled with
    their margin, and the 1.0 contour (the limit) is drawn between the cells that fail and
    those that comply.  Red: some case does not comply; grey (NaN): not computed.
    """
    from matplotlib.colors import LogNorm

    d1, d2 = summary.heatmap_dims
    lab1, lab2 = summary.heatmap_labels
    m = np.asarray(summary.heatmap, float)
    finite = m[np.isfinite(m) & (m > 0)]
    # symmetric in log about 1 (vmin * vmax = 1), so the colour map's middle is the limit
    span = float(np.max(np.abs(np.log10(finite)))) if finite.size else 1.0
    span = max(span, 1e-3)
    shown = np.clip(m, 10.0**-span, 10.0**span)
    fig, ax = figure_axes(ax, 7.5, max(3.2, 0.9 + 0.22 * len(lab1)))
    im = ax.imshow(np.ma.masked_invalid(shown), cmap=_cmap(), aspect="auto",
                   norm=LogNorm(10.0**-span, 10.0**span), interpolation="nearest")  # fmt: skip
    _ticks(ax, len(lab2), lab2, "x")
    _ticks(ax, len(lab1), lab1, "y")
    ax.set_xlabel(d2)
    ax.set_ylabel(d1)
    ax.set_title(f"Worst margin over the other axes (below 1 fails {summary.requirement}; "
                 "black line: margin 1)", fontsize=9)  # fmt: skip
    cb = fig.colorbar(im, ax=ax)
    cb.set_label("margin = limit / band RMS (log scale)")
    cb.ax.axhline(1.0, color="k", lw=1.5)
    _limit_contour(ax, m)
    if m.size <= 400:
        for i in range(m.shape[0]):
            for j in range(m.shape[1]):
                if np.isfinite(m[i, j]):
                    ax.text(j, i, f"{m[i, j]:.2g}", ha="center", va="center", fontsize=6)
    return fig


def _limit_contour(ax: Any, margin: np.ndarray) -> None:
    """The margin-1 line: the cell edges between a failing cell and a complying neighbour.

    Drawn on the cell boundaries (not interpolated between cell centres): each cell is one set
    of cases, and a margin between two cells means nothing.  Its label is ``margin 1``.
    """
    fail = np.isfinite(margin) & (margin < 1.0)
    ok = np.isfinite(margin) & (margin >= 1.0)
    segs = []
    n1, n2 = margin.shape
    for i in range(n1):
        for j in range(n2):
            if j + 1 < n2 and (fail[i, j] and ok[i, j + 1] or ok[i, j] and fail[i, j + 1]):
                segs.append([(j + 0.5, i - 0.5), (j + 0.5, i + 0.5)])
            if i + 1 < n1 and (fail[i, j] and ok[i + 1, j] or ok[i, j] and fail[i + 1, j]):
                segs.append([(j - 0.5, i + 0.5), (j + 0.5, i + 0.5)])
    if segs:
        from matplotlib.collections import LineCollection

        ax.add_collection(LineCollection(segs, colors="k", linewidths=2.0, label="margin 1"))


def _cmap() -> Any:
    import matplotlib

    return matplotlib.colormaps["RdYlGn"].with_extremes(bad="0.85")


def fraction_figure(summary: Summary, *, ax: Any = None) -> Figure:
    """The complying fraction for each value of every axis that varies.

    ``ax``: one matplotlib axes per axis that varies (one when none does).
    """
    dims = [d for d, v in summary.fraction_by.items() if len(v) > 1]
    n = max(1, len(dims))
    fig, grid = figure_grid(ax, n, 1, width_in=7.5, height_in=1.0 + 1.7 * n)
    axes = grid[:, 0]
    if not dims:
        axes[0].text(0.5, 0.5, "every axis has one value", ha="center", va="center")
        axes[0].set_axis_off()
        return fig
    for ax, d in zip(axes, dims, strict=True):
        rows = summary.fraction_by[d]
        labels = [str(lab) for lab, _ in rows]
        vals = [np.nan if fr is None else fr for _, fr in rows]
        ax.bar(range(len(rows)), vals, color="tab:green")
        ax.set_ylim(0, 1)
        ax.set_ylabel(f"{d}\ncomplying", fontsize=8)
        _ticks(ax, len(labels), labels, "x")
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].set_title("Fraction of cases that comply, by the value of each axis", fontsize=9)
    return fig


def worst_bands_figure(summary: Summary, *, ax: Axes | None = None) -> Figure:
    """Band RMS of the worst case of each observed point (governing axis) against the limit."""
    fig, ax = figure_axes(ax, 7.5, 4.2)
    limit = None
    for name, b in summary.worst_bands.items():
        rms = np.asarray(b["rms_g"], float)
        gov = np.nanmax(rms, axis=0)
        ax.loglog(b["center_hz"], np.maximum(gov * 1e6, 1e-30), "o-", ms=3, lw=0.8,
                  label=f"{name}")  # fmt: skip
        limit = b
    if limit is not None:
        c = np.asarray(limit["center_hz"], float)
        ax.loglog(c, np.asarray(limit["limit_g"], float) * 1e6, "k-", lw=1.4, label="limit")
        judged = np.asarray(limit["judged"], bool)
        if judged.any() and not judged.all():
            ax.axvspan(c[~judged].min(), c[judged].min(), color="0.9", zorder=0,
                       label="not judged (record)")  # fmt: skip
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("band RMS, worst axis [micro-g]")
    ax.set_title("The worst case of each observed point against the requirement", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    return fig
