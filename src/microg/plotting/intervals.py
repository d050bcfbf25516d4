"""Figures of the PIMS-style interval products (:mod:`microg.environment.intervals`).

The percentile plot follows PIMS's ``otorunhist`` box plot: per band, the median as a
horizontal line across the band, whiskers from the 1st to the 25th and from the 75th to the
99th percentile at the band centre, and the requirement as steps on the band edges.  Every
plot function takes ``ax=``, the matplotlib axes to draw into (default: a new figure), and
returns the figure.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from microg.plotting.common import figure_axes, figure_grid
from microg.plotting.environment import limit_steps

if TYPE_CHECKING:
    from microg.environment.intervals import (
        BandLimitedRMS,
        CumulativeRMS,
        IntervalBandRMS,
        IntervalStats,
        Spectrogram,
    )

__all__ = [
    "plot_interval_percentiles",
    "plot_interval_stats",
    "plot_band_limited_rms",
    "plot_spectrogram",
    "plot_cumulative_rms",
]

_UG = 1e6


def _fig(ax: Axes | None, title: str, h: float = 4.5) -> tuple[Figure, Axes]:
    """The figure and axes to draw into (the caller's ``ax`` or a new one), titled."""
    fig, ax = figure_axes(ax, 7.5, h)
    ax.set_title(title)
    return fig, ax


def plot_interval_percentiles(
    res: IntervalBandRMS, *, row: str = "rss", title: str = "", ax: Axes | None = None
) -> Figure:
    """Percentiles of interval band RMS (one axis or ``rss``) against the requirement steps."""
    rows = res.rows
    if row not in rows:
        from microg.errors import InputError

        raise InputError(f"unknown row {row!r}", where="row", fix=f"use one of {rows}")
    k = rows.index(row)
    p = res.percentile_rms_g[:, k, :] * _UG  # (np, nb)
    b = res.bands
    label = "RSS(x, y, z)" if row == "rss" else f"{row}-axis"
    fig, ax = _fig(
        ax,
        title
        or f"Band RMS over {res.t_start_s.size} intervals of {res.interval_s:g} s, {label}, "
        f"vs {res.requirement}",
        5.0,
    )
    x, y = limit_steps(b.lower_hz, b.upper_hz, res.limit_g * _UG)
    ax.plot(x, y, color="tab:blue", alpha=0.6, lw=1.5, label="limit")
    pc = list(res.percentiles)
    floor = 1e-6
    if 50.0 in pc:
        med = np.maximum(p[pc.index(50.0)], floor)
        ax.hlines(med, b.lower_hz, b.upper_hz, color="red", lw=1.5, label="median")
    for lo_p, hi_p in ((1.0, 25.0), (75.0, 99.0)):
        if lo_p in pc and hi_p in pc:
            ax.vlines(
                b.center_hz,
                np.maximum(p[pc.index(lo_p)], floor),
                np.maximum(p[pc.index(hi_p)], floor),
                color="k",
                lw=1.2,
                label=f"{lo_p:g}-{hi_p:g} %",
            )
    for j, i in enumerate(np.nonzero(~np.asarray(res.resolved, bool))[0]):
        ax.axvspan(
            b.lower_hz[i], b.upper_hz[i], color="0.9", lw=0, label="not judged" if j == 0 else None
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("band RMS [micro-g]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_interval_stats(res: IntervalStats, *, title: str = "", ax: Any = None) -> Figure:
    """Interval minimum, maximum (bars) and mean (line) per axis against time, micro-g.

    ``ax``: one matplotlib axes per axis of the record (default: a new figure, titled).
    """
    n = len(res.axes)
    new = ax is None
    fig, grid = figure_grid(ax, n, 1, width_in=7.5, height_in=2.2 * n + 0.8, sharex=True)
    axs = grid[:, 0]
    if new:
        fig.suptitle(title or "Interval minimum, maximum and mean")
    else:
        axs[0].set_title(title or "Interval minimum, maximum and mean")
    for i, (ax, name) in enumerate(zip(axs, res.axes, strict=True)):
        ax.fill_between(
            res.t_start_s, res.min_g[:, i] * _UG, res.max_g[:, i] * _UG, step="post", alpha=0.3,
            label="min-max",
        )  # fmt: skip
        ax.step(res.t_start_s, res.mean_g[:, i] * _UG, where="post", lw=1.0, label="mean")
        ax.set_ylabel(f"{name} [micro-g]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    axs[-1].set_xlabel("interval start [s]")
    return fig


def plot_band_limited_rms(
    res: BandLimitedRMS, *, title: str = "", ax: Axes | None = None
) -> Figure:
    """Band-limited RMS per axis and RSS against time (interval starts), micro-g."""
    lo, hi = res.band_hz
    fig, ax = _fig(ax, title or f"RMS in {lo:.3g}-{hi:.3g} Hz per {res.interval_s:g}-s interval")
    for i, name in enumerate(res.axes):
        ax.step(res.t_start_s, res.rms_g[:, i] * _UG, where="post", lw=0.9, label=name)
    ax.step(res.t_start_s, res.rss_g * _UG, where="post", color="k", lw=1.2, label="RSS")
    ax.set_xlabel("interval start [s]")
    ax.set_ylabel("band-limited RMS [micro-g]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_spectrogram(
    res: Spectrogram, *, axis: str | None = None, title: str = "", ax: Axes | None = None
) -> Figure:
    """log10 PSD (g^2/Hz) against time and frequency for one axis."""
    if axis is None:
        i = int(np.argmax(res.psd_g2_per_hz.sum(axis=(1, 2))))
    else:
        i = list(res.axes).index(axis)
    fig, ax = _fig(
        ax, title or f"Spectrogram, {res.axes[i]}-axis (Hann, {res.segment_s:.3g}-s segments)"
    )
    z = res.psd_g2_per_hz[i]
    top = float(np.max(z, initial=0.0))
    lz = np.log10(np.maximum(z, max(top, 1e-300) * 1e-12))
    mesh = ax.pcolormesh(res.time_s, res.freq_hz, lz, shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="log10 PSD [g^2/Hz]")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("frequency [Hz]")
    return fig


def plot_cumulative_rms(res: CumulativeRMS, *, title: str = "", ax: Axes | None = None) -> Figure:
    """Cumulative RMS per axis and RSS against frequency (log x), micro-g."""
    fig, ax = _fig(ax, title or "Cumulative RMS against frequency")
    f = res.freq_hz
    for i, name in enumerate(res.axes):
        ax.semilogx(f, res.rms_g[i] * _UG, lw=0.9, label=name)
    ax.semilogx(f, res.rss_g * _UG, color="k", lw=1.2, label="RSS")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("cumulative RMS [micro-g]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig
