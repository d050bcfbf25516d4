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
from matplotlib.colors import TwoSlopeNorm
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
    """Worst margin (log10 of limit / band RMS, min over the other axes) over two axes.

    Below 0 (red) some case does not comply; NaN cells (grey) were not computed.
    """
    d1, d2 = summary.heatmap_dims
    lab1, lab2 = summary.heatmap_labels
    m = np.asarray(summary.heatmap, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.log10(m)
    finite = v[np.isfinite(v)]
    span = float(np.max(np.abs(finite))) if finite.size else 1.0
    span = max(span, 1e-3)
    v = np.clip(v, -span, span)
    fig, ax = figure_axes(ax, 7.5, max(3.2, 0.9 + 0.22 * len(lab1)))
    cmap = _cmap()
    im = ax.imshow(np.ma.masked_invalid(v), cmap=cmap, aspect="auto",
                   norm=TwoSlopeNorm(0.0, -span, span), interpolation="nearest")  # fmt: skip
    _ticks(ax, len(lab2), lab2, "x")
    _ticks(ax, len(lab1), lab1, "y")
    ax.set_xlabel(d2)
    ax.set_ylabel(d1)
    ax.set_title(f"Worst margin over the other axes (log10; < 0 fails {summary.requirement})",
                 fontsize=9)  # fmt: skip
    cb = fig.colorbar(im, ax=ax)
    cb.set_label("log10(limit / band RMS)")
    if m.size <= 400:
        for i in range(m.shape[0]):
            for j in range(m.shape[1]):
                if np.isfinite(m[i, j]):
                    ax.text(j, i, f"{m[i, j]:.2g}", ha="center", va="center", fontsize=6)
    return fig


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
