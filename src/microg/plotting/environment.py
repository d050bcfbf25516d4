"""Figures of acceleration assessments: time history, PSD, 1/3-octave bands, integrals, overlay.

Figures are built with ``matplotlib.figure.Figure`` (no pyplot, no backend switch), so
they work in scripts, servers and notebooks alike.  Requirement limits are drawn as steps on
the band edges (each band's limit from its lower to its upper edge), as PIMS draws them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from microg.environment.metrics import (
    Assessment,
    Spectrum,
    ThirdOctave,
    _as_axes,
    integrated_acceleration,
)
from microg.plotting.common import envelope, figure_axes, figure_grid
from microg.units import G0

if TYPE_CHECKING:
    from microg.environment.metrics import IntegratedAcceleration, IntegratedBlocks
    from microg.environment.overlay import BandOverlay
    from microg.environment.requirements import Requirement

__all__ = [
    "limit_steps",
    "plot_time_history",
    "plot_psd",
    "plot_bands",
    "plot_third_octave",
    "plot_requirement",
    "plot_integrated",
    "plot_integrated_acceleration",
    "plot_overlay",
    "plot_band_overlay",
]


def _figure(ax: Axes | None, title: str) -> tuple[Figure, Axes]:
    """The figure and axes to draw into (the caller's ``ax`` or a new one), titled."""
    fig, ax = figure_axes(ax, 7.5, 4.5)
    if title:
        ax.set_title(title)
    return fig, ax


def limit_steps(
    lower_hz: np.ndarray, upper_hz: np.ndarray, limit: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """x, y of a step line: each band's ``limit`` from its lower to its upper edge (Hz)."""
    x = np.column_stack([lower_hz, upper_hz]).ravel()
    y = np.repeat(np.asarray(limit, float), 2)
    return x, y


def plot_time_history(
    timepts: np.ndarray,
    accel: np.ndarray,
    *,
    axes: tuple[str, ...] = ("x", "y", "z"),
    title: str = "",
    ax: Axes | None = None,
) -> Figure:
    """Acceleration (m/s^2 in, plotted in micro-g) against time (s); returns the Figure.

    ``ax``: the matplotlib axes to draw into (default: a new figure), as for every plot
    function of this module.
    """
    fig, ax = _figure(ax, title or "Acceleration")
    a = _as_axes(accel) / G0 * 1e6
    for name, row in zip(axes, a, strict=False):
        ax.plot(*envelope(timepts, row), label=name, lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("acceleration [micro-g]")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig


def plot_psd(
    spectrum: Spectrum,
    *,
    axes: tuple[str, ...] = ("x", "y", "z"),
    title: str = "",
    ax: Axes | None = None,
) -> Figure:
    """PSD in g^2/Hz against frequency (log-log, the 0-Hz bin left out); returns the Figure."""
    fig, ax = _figure(ax, title or f"PSD ({spectrum.method})")
    f = spectrum.freq_hz[1:]
    top = max(float(np.max(spectrum.psd[:, 1:], initial=0.0)) / G0**2, 1e-300)
    for name, row in zip(axes, spectrum.psd, strict=False):
        ax.loglog(f, np.maximum(row[1:] / G0**2, 1e-300), label=name, lw=0.8)
    ax.set_ylim(top * 1e-12, top * 10)  # 12 decades: below that is rounding noise
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("PSD [g^2/Hz]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def _bands_on(ax: Any, to: ThirdOctave, axes: tuple[str, ...], style: str, label: str) -> None:
    """Band RMS per axis, micro-g.

    A line through the centres, resolved bands filled, the others hollow.
    """
    res = np.asarray(to.resolved, bool)
    line, marker = style[1:] or "-", style[0]
    for name, row in zip(axes, to.rms_g, strict=False):
        y = np.maximum(row * 1e6, 1e-12)
        (ln,) = ax.loglog(to.center_hz, y, line, lw=0.8, label=f"{label}{name}")
        c = ln.get_color()
        if np.any(res):
            ax.plot(to.center_hz[res], y[res], marker, ms=4, color=c, label="_judged")
        if np.any(~res):
            ax.plot(
                to.center_hz[~res], y[~res], marker, ms=4, mfc="none", color=c, label="_unjudged"
            )


def _band_axes(ax: Any) -> None:
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("frequency [Hz] (markers at band centres, limit on band edges)")
    ax.set_ylabel("band RMS [micro-g]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


def _limit_on(ax: Any, lower_hz: np.ndarray, upper_hz: np.ndarray, limit_g: np.ndarray) -> None:
    x, y = limit_steps(lower_hz, upper_hz, np.asarray(limit_g, float) * 1e6)
    ax.plot(x, y, color="k", lw=1.5, label="limit")


def plot_bands(
    to: ThirdOctave,
    *,
    axes: tuple[str, ...] = ("x", "y", "z"),
    title: str = "",
    verdict_range_hz: tuple[float, float] | None = None,
    ax: Axes | None = None,
) -> Figure:
    """1/3-octave band RMS per axis against the limit's steps (micro-g); returns a Figure.

    Parameters
    ----------
    to : ThirdOctave
        Band RMS (g), limits (g), resolution.
    axes : tuple of str
        Names of the rows of ``to.rms_g``.
    title : str
        Figure title (default: a generic one).
    verdict_range_hz : (float, float), optional
        The frequency range the verdict covers, Hz, shaded (default: the judged bands').
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).

    Filled markers: bands the verdict judges; hollow: bands the record does not resolve (left
    out of the verdict).
    """
    fig, ax = _figure(ax, title or "1/3-octave band RMS")
    _bands_on(ax, to, axes, "o-", "")
    _limit_on(ax, to.lower_hz, to.upper_hz, to.limit_g)
    vr = verdict_range_hz if verdict_range_hz is not None else to.verdict_range_hz
    if vr is not None:
        ax.axvspan(vr[0], vr[1], color="0.85", alpha=0.4, lw=0, label="judged bands")
    _band_axes(ax)
    return fig


def plot_third_octave(assessment: Assessment, *, title: str = "", ax: Axes | None = None) -> Figure:
    """1/3-octave band RMS per axis against the requirement's steps (micro-g); returns a Figure.

    Filled markers: bands the verdict judges; hollow: bands the record does not resolve (left
    out of the verdict); shaded: the range the verdict covers.
    """
    return plot_bands(
        assessment.third_octave,
        axes=assessment.axes,
        title=title or f"1/3-octave band RMS vs {assessment.requirement}",
        verdict_range_hz=assessment.verdict_range_hz,
        ax=ax,
    )


def plot_requirement(req: Requirement, *, title: str = "", ax: Axes | None = None) -> Figure:
    """A requirement's band-RMS limit as steps on the band edges (micro-g); returns a Figure."""
    fig, ax = _figure(ax, title or f"Requirement {req.name}")
    b = req.bands
    _limit_on(ax, b.lower_hz, b.upper_hz, req.limit_g)
    ax.plot(b.center_hz, np.asarray(req.limit_g, float) * 1e6, "o", ms=3, color="k", label="_c")
    if req.peak_limit_g is not None:
        ax.axhline(req.peak_limit_g * 1e6, color="crimson", ls="--", lw=1.0, label="peak limit")
    _band_axes(ax)
    ax.set_ylabel("band-RMS limit [micro-g]")
    return fig


def plot_integrated(
    integ: IntegratedAcceleration | IntegratedBlocks,
    *,
    axes: tuple[str, ...] = ("x", "y", "z"),
    title: str = "",
    ax: Axes | None = None,
) -> Figure:
    """Each window's (or block's) integral of the acceleration against its start, s.

    In micro-g s (``m/s / G0 * 1e6``), the unit of the transient criteria and of the report's
    tables: one unit per quantity.
    """
    kind = "blocks" if hasattr(integ, "block_samples") else "sliding"
    fig, ax = _figure(ax, title or f"Integrated acceleration, {kind} {integ.window_s:g}-s windows")
    for name, row in zip(axes, integ.delta_v, strict=False):
        ax.plot(*envelope(integ.t_start, np.asarray(row) / G0 * 1e6), label=name, lw=0.8)
    ax.set_xlabel("window start [s]")
    ax.set_ylabel("integral of acceleration [micro-g s]")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig


def plot_integrated_acceleration(
    timepts: np.ndarray,
    accel: np.ndarray,
    *,
    window_s: float = 10.0,
    axes: tuple[str, ...] = ("x", "y", "z"),
    title: str = "",
    ax: Axes | None = None,
) -> Figure:
    """Integrated acceleration over sliding windows (micro-g s) of a record (times s, m/s^2)."""
    return plot_integrated(
        integrated_acceleration(timepts, accel, window_s), axes=axes, title=title, ax=ax
    )


def plot_overlay(
    prediction: Assessment,
    measurement: Assessment,
    *,
    labels: tuple[str, str] = ("prediction", "measurement"),
    title: str = "",
    ax: Any = None,
) -> Figure:
    """A prediction and a measurement at one site: band RMS per axis and PSD; returns a Figure.

    Top: 1/3-octave band RMS of both (solid: the first, dashed: the second) against the
    first's requirement steps.  Bottom: their PSDs, worst axis by RMS, in g^2/Hz.  ``ax``:
    the two matplotlib axes to draw into (default: a new figure).
    """
    fig, grid = figure_grid(ax, 2, 1, width_in=7.5, height_in=7.0)
    ax1, ax2 = grid[:, 0]
    ax1.set_title(title or f"{labels[0]} and {labels[1]} vs {prediction.requirement}")
    _bands_on(ax1, prediction.third_octave, prediction.axes, "o-", f"{labels[0]} ")
    _bands_on(ax1, measurement.third_octave, measurement.axes, "s--", f"{labels[1]} ")
    to = prediction.third_octave
    x, y = limit_steps(to.lower_hz, to.upper_hz, to.limit_g * 1e6)
    ax1.plot(x, y, color="k", lw=1.5, label="limit")
    ax1.set_xscale("log")
    ax1.set_yscale("log")
    ax1.set_xlabel("frequency [Hz]")
    ax1.set_ylabel("band RMS [micro-g]")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=7, ncol=2)
    for a, lab, style in ((prediction, labels[0], "-"), (measurement, labels[1], "--")):
        s = a.spectrum
        i = int(np.argmax(np.sum(s.psd[:, 1:], axis=1)))
        ax2.loglog(
            s.freq_hz[1:],
            np.maximum(s.psd[i, 1:] / G0**2, 1e-300),
            style,
            lw=0.8,
            label=f"{lab} ({a.axes[i]})",
        )
    ax2.set_xlabel("frequency [Hz]")
    ax2.set_ylabel("PSD [g^2/Hz]")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=8)
    return fig


def plot_band_overlay(overlay: BandOverlay, *, title: str = "", ax: Axes | None = None) -> Figure:
    """A prediction's and a measurement's band RMS (worst axis) against the limit's steps.

    In micro-g, on the band centres: circles and a solid line for the prediction, squares and
    a dashed line for the measurement; hollow markers where that side does not resolve the band
    (it is not compared there).  Returns the Figure.

    Parameters
    ----------
    overlay : BandOverlay
        The paired bands (:func:`microg.environment.overlay.band_overlay`).
    title : str
        Figure title (default: the point, the sensor and the requirement).
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).
    """
    fig, ax = _figure(
        ax,
        title
        or f"prediction at {overlay.point} and measurement {overlay.sensor} vs "
        f"{overlay.requirement}",
    )
    f = overlay.center_hz
    # three decades below the lowest limit: what lies lower is far inside it (and a tone-free
    # band of a clean signal is rounding noise, not a level to draw)
    floor = float(np.min(overlay.limit_g, initial=np.inf)) * 1e6 * 1e-3
    floor = floor if np.isfinite(floor) and floor > 0 else 1e-12
    for y_g, res, style, label in (
        (overlay.predicted_g, overlay.predicted_resolved, "o-", "prediction"),
        (overlay.measured_g, overlay.measured_resolved, "s--", "measurement"),
    ):
        y = np.maximum(np.asarray(y_g, float) * 1e6, floor)
        r = np.asarray(res, bool)
        (ln,) = ax.plot(f, y, style[1:], lw=0.9, label=f"{label} (worst axis)")
        c = ln.get_color()
        if np.any(r):
            ax.plot(f[r], y[r], style[0], ms=4, color=c, label="_resolved")
        if np.any(~r):
            ax.plot(f[~r], y[~r], style[0], ms=4, mfc="none", color=c, label="_unresolved")
    _limit_on(ax, overlay.lower_hz, overlay.upper_hz, overlay.limit_g)
    _band_axes(ax)
    ax.set_ylim(bottom=floor)
    ax.set_ylabel(f"band RMS [micro-g] (floor {floor:.2g})")
    ax.set_xlabel("frequency [Hz] (hollow: band not resolved, not compared)")
    return fig
