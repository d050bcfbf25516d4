"""Figures of acceleration assessments: time history, PSD, 1/3-octave bands, integrals.

Figures are built with ``matplotlib.figure.Figure`` (no pyplot, no backend switch), so
they work in scripts, servers and notebooks alike.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from microg.environment.metrics import (
    Assessment,
    Spectrum,
    _as_axes,
    integrated_acceleration,
)
from microg.units import G0

__all__ = [
    "plot_time_history",
    "plot_psd",
    "plot_third_octave",
    "plot_integrated_acceleration",
]


def _figure(title: str) -> Any:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.5, 4.5), layout="constrained")
    ax = fig.add_subplot()
    if title:
        ax.set_title(title)
    return fig, ax


def plot_time_history(
    timepts: np.ndarray,
    accel: np.ndarray,
    *,
    axes: tuple[str, ...] = ("x", "y", "z"),
    title: str = "",
) -> Any:
    """Acceleration (m/s^2 in, plotted in micro-g) against time (s); returns a Figure."""
    fig, ax = _figure(title or "Acceleration")
    a = _as_axes(accel) / G0 * 1e6
    for name, row in zip(axes, a, strict=False):
        ax.plot(timepts, row, label=name, lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("acceleration [micro-g]")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig


def plot_psd(
    spectrum: Spectrum, *, axes: tuple[str, ...] = ("x", "y", "z"), title: str = ""
) -> Any:
    """PSD in g^2/Hz against frequency (log-log); returns a Figure."""
    fig, ax = _figure(title or f"PSD ({spectrum.method})")
    f = spectrum.freq_hz[1:]
    top = max(float(np.max(spectrum.psd[:, 1:])) / G0**2, 1e-300)
    for name, row in zip(axes, spectrum.psd, strict=False):
        ax.loglog(f, np.maximum(row[1:] / G0**2, 1e-300), label=name, lw=0.8)
    ax.set_ylim(top * 1e-12, top * 10)  # 12 decades: below that is rounding noise
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("PSD [g^2/Hz]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def plot_third_octave(assessment: Assessment, *, title: str = "") -> Any:
    """1/3-octave band RMS per axis against the requirement (log-log, micro-g); returns a Figure."""
    to = assessment.third_octave
    fig, ax = _figure(title or f"1/3-octave band RMS vs {assessment.requirement}")
    for name, row in zip(assessment.axes, to.rms_g, strict=False):
        ax.loglog(to.center_hz, np.maximum(row * 1e6, 1e-12), marker="o", ms=3, lw=0.8, label=name)
    ax.step(to.center_hz, to.limit_g * 1e6, where="mid", color="k", lw=1.5, label="limit")
    ax.set_xlabel("band centre [Hz]")
    ax.set_ylabel("band RMS [micro-g]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def plot_integrated_acceleration(
    timepts: np.ndarray,
    accel: np.ndarray,
    *,
    window_s: float = 10.0,
    axes: tuple[str, ...] = ("x", "y", "z"),
    title: str = "",
) -> Any:
    """Integrated acceleration over sliding windows (m/s) against window start; returns a Figure."""
    integ = integrated_acceleration(timepts, accel, window_s)
    fig, ax = _figure(title or f"Integrated acceleration, {integ.window_s:g}-s windows")
    for name, row in zip(axes, integ.delta_v, strict=False):
        ax.plot(integ.t_start, row, label=name, lw=0.8)
    ax.set_xlabel("window start [s]")
    ax.set_ylabel("integral of acceleration [m/s]")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig
