"""Isolation figures.

Figure 8 of the report (``M_a`` against ``r^2``), an absorber's, a mount design's and a
screened mount's curves, and the isolation advice.  They draw the numbers of the result
objects' ``to_xarray()``; they compute nothing of their own.  Every plot function takes
``ax=``, the matplotlib axes to draw into (default: a new figure), and returns the figure.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from microg.isolation.design import FIGURE8_CURVES
from microg.isolation.transmissibility import (
    accel_magnification,
    accel_magnification_no_absorber,
)
from microg.plotting.common import envelope, figure_axes, figure_grid

if TYPE_CHECKING:
    from microg.isolation.absorber import AbsorberTuning
    from microg.isolation.advise import IsolationAdvice
    from microg.isolation.design import MountDesign
    from microg.isolation.mount import MountChoice

__all__ = [
    "figure8",
    "write_png_atomic",
    "plot_absorber",
    "plot_mount_design",
    "plot_mount_choice",
    "plot_isolation_advice",
    "plot_package_response",
]


def write_png_atomic(fig: Figure, path: str | Path, dpi: int = 150) -> Path:
    """Render ``fig`` to PNG in memory, then write it to ``path`` through a rename.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or Path
        Destination file.
    dpi : int
        Resolution, dots per inch.
    """
    from microg._io import atomic_write_bytes

    path = Path(path)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    atomic_write_bytes(path, buf.getvalue())
    return path


def figure8(
    path: str | Path | None = None,
    *,
    zeta: float = 0.2,
    r2_max: float = 6.0,
    n_points: int = 3001,
    ax: Any = None,
) -> Figure:
    """Figure 8: six panels of ``M_a`` versus ``r^2`` at ``zeta = 0.2`` (Section 4.2).

    Panels 1-3: ``mu = 0.01, 0.025, 0.05`` with several ``k``; panels 4-6: ``k = 10, 15, 20`` with
    several ``mu`` (values in :data:`~microg.isolation.design.FIGURE8_CURVES`).  Each panel also
    draws the package without absorber, ``1/|1 - r^2|`` (dashed), and the ``M_a = 1`` line.

    Parameters
    ----------
    path : str or Path, optional
        Write the figure there as PNG (atomically).
    zeta : float
        Absorber damping ratio (Eq. 4.6).
    r2_max : float
        Upper end of the ``r^2`` axis.
    n_points : int
        Samples of ``r^2`` per curve.
    ax : array of matplotlib.axes.Axes, optional
        The six axes to draw into, row by row (default: a new 2 x 3 figure, titled).
    """
    r2 = np.linspace(0.0, r2_max, n_points)
    r = np.sqrt(r2)
    new = ax is None
    fig, axes = figure_grid(ax, 2, 3, width_in=13, height_in=8, sharex=True, sharey=True)
    base = accel_magnification_no_absorber(r)
    panels: list[tuple[str, list[tuple[float, float, str]]]] = []
    for mu in FIGURE8_CURVES["mu_panels"]:
        panels.append((f"mu = {mu:g}", [(k, mu, f"k = {k:g}") for k in FIGURE8_CURVES["k_values"]]))
    for k in FIGURE8_CURVES["k_panels"]:
        panels.append(
            (f"k = {k:g}", [(k, mu, f"mu = {mu:g}") for mu in FIGURE8_CURVES["mu_values"]])
        )
    for ax, (title, curves) in zip(axes.ravel(), panels, strict=True):
        ax.semilogy(r2, base, "k--", lw=0.9, label="no absorber")
        for k, mu, label in curves:
            ax.semilogy(r2, accel_magnification(k, mu, zeta, r), lw=1.3, label=label)
        ax.axhline(1.0, color="0.5", lw=0.6)
        ax.axvline(2.0, color="0.5", lw=0.6, ls=":")
        ax.set_title(f"{title}, zeta = {zeta:g}")
        ax.set_ylim(0.05, 50.0)
        ax.set_xlim(0.0, r2_max)
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
        ax.legend(fontsize=8, loc="upper right")
    for ax in axes[1]:
        ax.set_xlabel("r^2 = (omega/omega_n)^2")
    for ax in axes[:, 0]:
        ax.set_ylabel("M_a = |U1/U0|")
    if new:
        fig.suptitle("Figure 8: acceleration magnification factor (Eq. 4.3 solved)")
    if path is not None:
        write_png_atomic(fig, path)
    return fig


def _log_axes(ax: Any, xlabel: str, ylabel: str) -> None:
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


def plot_absorber(tuning: AbsorberTuning, *, ax: Axes | None = None) -> Figure:
    """``M_a`` of a tuned absorber against ``r = omega/omega_n``; returns a Figure.

    The package alone dashed, the design band shaded and the peak marked.
    """
    ds = tuning.to_xarray()
    r = ds["r"].values
    fig, ax = figure_axes(ax, 7.5, 4.2)
    ax.semilogy(r, ds["Ma"].values, lw=1.3, label=f"absorber (k = {tuning.k:.4g})")
    ax.semilogy(r, ds["Ma_no_absorber"].values, "k--", lw=0.9, label="no absorber")
    ax.plot([tuning.r_peak], [tuning.peak_Ma], "o", color="crimson", label="peak")
    if tuning.band is not None:
        ax.axvspan(*tuning.band, color="0.85", alpha=0.5, lw=0, label="band")
    ax.axhline(1.0, color="0.5", lw=0.6)
    ax.set_ylim(0.05, 50.0)
    ax.set_xlabel("r = omega/omega_n")
    ax.set_ylabel("M_a = |U1/U0|")
    ax.set_title(
        f"Absorber, mu = {tuning.mu:g}, zeta = {tuning.zeta:.3g} ({tuning.criterion})",
        fontsize=10,
    )
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_mount_design(design: MountDesign, *, ax: Axes | None = None) -> Figure:
    """A mount design's ``M_a`` against support frequency (Hz); returns a Figure.

    The disturbance band shaded and the target drawn.
    """
    ds = design.to_xarray()
    fig, ax = figure_axes(ax, 7.5, 4.2)
    ax.plot(ds["freq_hz"].values, ds["Ma"].values, lw=1.3, label="M_a")
    ax.axvspan(*design.band_hz, color="0.85", alpha=0.5, lw=0, label="disturbance band")
    ax.axhline(design.target, color="crimson", ls="--", lw=1.0, label="target")
    ax.axvline(design.freq_hz_n, color="0.5", lw=0.6, ls=":", label="natural frequency")
    ax.set_title(f"Mount k1 = {design.k1:.4g} N/m, f_n = {design.freq_hz_n:.3g} Hz", fontsize=10)
    _log_axes(ax, "support frequency [Hz]", "M_a = |U1/U0|")
    return fig


def plot_mount_choice(choice: MountChoice, *, ax: Axes | None = None) -> Figure:
    """A screened spring-damper mount's ``|U1/U0|`` against frequency (Hz); returns a Figure."""
    ds = choice.to_xarray()
    fig, ax = figure_axes(ax, 7.5, 4.2)
    ax.plot(ds["freq_hz"].values, ds["transmissibility"].values, lw=1.3, label="|U1/U0|")
    ax.axvline(choice.freq_hz_n, color="0.5", lw=0.6, ls=":", label="natural frequency")
    ax.axhline(1.0, color="0.5", lw=0.6)
    state = "complies" if choice.found else "best, does not comply"
    ax.set_title(
        f"Screened mount: k1 = {choice.k1:.4g} N/m, zeta1 = {choice.zeta1:g} ({state})",
        fontsize=10,
    )
    _log_axes(ax, "support frequency [Hz]", "transmissibility |U1/U0|")
    return fig


def plot_isolation_advice(advice: IsolationAdvice, *, ax: Axes | None = None) -> Figure:
    """The largest ``M_a`` each exceeding band allows against the mounts'; returns a Figure.

    The allowed ``M_a`` is 1 / attenuation needed; the mounts' are the report-rule design's
    ``M_a`` and the screened mount's ``|U1/U0|``.
    """
    ds = advice.to_xarray()
    fig, ax = figure_axes(ax, 7.5, 4.2)
    ax.set_title(f"Isolation at {advice.point}: {advice.status}", fontsize=10)
    if ds.sizes["center_hz"] == 0 and ds.sizes["freq_hz"] == 0:
        ax.text(0.5, 0.5, advice.note or advice.status, ha="center", va="center", wrap=True)
        ax.set_axis_off()
        return fig
    f = ds["freq_hz"].values
    if "design_Ma" in ds:
        ax.plot(f, ds["design_Ma"].values, lw=1.2, label="report-rule design M_a")
    if "mount_transmissibility" in ds:
        ax.plot(f, ds["mount_transmissibility"].values, lw=1.2, label="screened mount |U1/U0|")
    if ds.sizes["center_hz"]:
        ax.plot(
            ds["center_hz"].values,
            ds["required_Ma"].values,
            "v",
            color="crimson",
            ms=6,
            label="largest M_a allowed (1 / attenuation needed)",
        )
    _log_axes(ax, "frequency [Hz]", "magnification")
    return fig


def plot_package_response(response: Any, *, title: str = "", ax: Axes | None = None) -> Figure:
    """Mount (support) and isolated-package accelerations against time, in micro-g.

    Parameters
    ----------
    response : IsolationTimeResponse
        ``timepts`` in s, ``mount_accel`` and ``package_accel`` in m/s^2.
    title : str, optional
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from microg.units import G0

    t = np.asarray(response.timepts, float)
    fig, ax = figure_axes(ax, 7.5, 3.8)
    ax.plot(*envelope(t, np.asarray(response.mount_accel) / G0 * 1e6), lw=0.8, label="mount")
    ax.plot(*envelope(t, np.asarray(response.package_accel) / G0 * 1e6), lw=0.8, label="package")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("acceleration [micro-g]")
    ax.set_title(
        title
        or f"Isolated package: peak ratio {response.peak_ratio:.3g}, "
        f"RMS ratio {response.rms_ratio:.3g}"
    )
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig
