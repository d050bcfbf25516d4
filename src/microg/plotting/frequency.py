"""Figures of the frequency-domain analysis.

FRFs, harmonic lines, band RMS, contributions, allocations.

Figures are built with ``matplotlib.figure.Figure`` (no pyplot, no backend switch); every
plot function takes ``ax=``, the matplotlib axes to draw into (default: a new figure), and
returns the figure.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from microg.units import G0

if TYPE_CHECKING:
    from microg.dynamics.frequency import AccelerationFRF, BandResponse, HarmonicResponse
    from microg.environment.allocation import Allocation
    from microg.environment.vibratory import VibratoryAssessment

__all__ = [
    "plot_frf",
    "plot_harmonic",
    "plot_band_response",
    "plot_vibratory",
    "plot_contributions",
    "plot_allocation",
]

_FLOOR = 1e-30


def _figure(ax: Any, title: str) -> Any:
    """The figure and axes to draw into (the caller's ``ax`` or a new one), titled."""
    from microg.plotting.common import figure_axes

    fig, ax = figure_axes(ax, 7.5, 4.5)
    if title:
        ax.set_title(title)
    return fig, ax


def _pick(points: tuple[str, ...], point: str | None) -> int:
    if point is None:
        return 0
    if point not in points:
        from microg.errors import InputError

        raise InputError(f"{point!r} is not an observed point", where="point")
    return points.index(point)


def plot_frf(
    frf: AccelerationFRF, *, point: str | None = None, title: str = "", ax: Any = None
) -> Any:
    """|acceleration FRF| per axis, in micro-g per newton against Hz (log-log)."""
    i = _pick(frf.points, point)
    fig, ax = _figure(ax, title or f"Acceleration FRF at {frf.points[i]} per N at {frf.at}")
    f = frf.freq_hz
    keep = f > 0
    for k, a in enumerate(frf.axes):
        mag = np.abs(frf.accel_per_n[i, k, keep]) / G0 * 1e6
        ax.loglog(f[keep], np.maximum(mag, _FLOOR), label=a, lw=0.8)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|acceleration| per force [micro-g/N]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def plot_harmonic(
    resp: HarmonicResponse, *, point: str | None = None, title: str = "", ax: Any = None
) -> Any:
    """Steady-state acceleration amplitude of each line per axis (micro-g, stems)."""
    i = _pick(resp.points, point)
    fig, ax = _figure(ax, title or f"Harmonic response at {resp.points[i]}")
    for k, a in enumerate(resp.axes):
        amp = np.abs(resp.accel_mps2[i, k]) / G0 * 1e6
        ax.semilogy(resp.freq_hz, np.maximum(amp, _FLOOR), "o", label=a, ms=4)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("amplitude [micro-g]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def plot_band_response(
    resp: BandResponse, *, point: str | None = None, title: str = "", ax: Any = None
) -> Any:
    """Band RMS per axis (micro-g) against band centre (log-log)."""
    i = _pick(resp.points, point)
    fig, ax = _figure(ax, title or f"1/3-octave band RMS at {resp.points[i]}")
    for k, a in enumerate(resp.axes):
        rms = resp.rms_mps2[i, k] / G0 * 1e6
        ax.loglog(resp.center_hz, np.maximum(rms, _FLOOR), marker="o", ms=3, lw=0.8, label=a)
    ax.set_xlabel("band centre [Hz]")
    ax.set_ylabel("band RMS [micro-g]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def plot_vibratory(
    va: VibratoryAssessment, *, point: str | None = None, title: str = "", ax: Any = None
) -> Any:
    """Band RMS per axis against the requirement's limit (micro-g, log-log)."""
    i = _pick(va.points, point)
    verdict = "complies" if va.complies[i] else "exceeds"
    fig, ax = _figure(
        ax, title or f"Vibratory environment at {va.points[i]} vs {va.requirement} ({verdict})"
    )
    top = max(float(np.max(va.rms_g[i], initial=0.0)), float(np.max(va.limit_g)))
    for k, a in enumerate(va.axes):
        ax.loglog(
            va.center_hz,
            np.maximum(va.rms_g[i, k] * 1e6, top * 1e-9 * 1e6),
            marker="o",
            ms=3,
            lw=0.8,
            label=a,
        )
    ax.step(va.center_hz, va.limit_g * 1e6, where="mid", color="k", lw=1.5, label="limit")
    ax.set_ylim(top * 1e6 * 1e-8, top * 1e6 * 3)
    ax.set_xlabel("band centre [Hz]")
    ax.set_ylabel("band RMS [micro-g]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def plot_contributions(
    va: VibratoryAssessment, *, point: str | None = None, title: str = "", ax: Any = None
) -> Any:
    """Each source's share of the band mean square, governing axis, stacked bars per band."""
    i = _pick(va.points, point)
    r = va.response
    fig, ax = _figure(ax, title or f"Source contributions at {va.points[i]} (governing axis)")
    gov = va.governing_axis(va.points[i])
    nb = va.center_hz.size
    share = r.source_share[i, gov, np.arange(nb)]  # (nb, ns)
    x = np.arange(nb)
    pos = np.zeros(nb)
    neg = np.zeros(nb)
    for j, name in enumerate(r.sources):
        s = share[:, j]
        if not np.any(s != 0):
            continue
        base = np.where(s >= 0, pos, neg)
        ax.bar(x, s, bottom=base, label=name, width=0.8)
        pos += np.where(s >= 0, s, 0)
        neg += np.where(s < 0, s, 0)
    ax.set_xticks(x[::3], [f"{c:.3g}" for c in va.center_hz[::3]], rotation=60)
    ax.set_xlabel("band centre [Hz]")
    ax.set_ylabel("share of band mean square")
    ax.grid(True, axis="y", alpha=0.3)
    if r.sources and ax.get_legend_handles_labels()[0]:  # no source drawn: no empty legend
        ax.legend(fontsize="small", ncol=2)
    return fig


def plot_allocation(alloc: Allocation, *, title: str = "", ax: Any = None) -> Any:
    """The allowed force RMS per band of a new source (N, log-log); exceeded bands marked."""
    fig, ax = _figure(
        ax, title or f"Allocation at {alloc.at} for site {alloc.site} ({alloc.requirement})"
    )
    a = alloc.allowed_rms_n
    finite = np.isfinite(a) & (a > 0)
    ax.loglog(alloc.center_hz[finite], a[finite], marker="o", ms=3, lw=1.0, label="allowed")
    if np.any(alloc.exceeded):
        ymin = float(np.min(a[finite])) if np.any(finite) else 1.0
        ax.plot(
            alloc.center_hz[alloc.exceeded],
            np.full(int(alloc.exceeded.sum()), ymin),
            "rx",
            label="already exceeded",
        )
    ax.set_xlabel("band centre [Hz]")
    ax.set_ylabel("allowed force RMS per band [N]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig
