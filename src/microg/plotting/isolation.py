"""Figure 8 of the report: acceleration magnification factor ``M_a`` against ``r^2``."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from microg.isolation.design import FIGURE8_CURVES
from microg.isolation.transmissibility import (
    accel_magnification,
    accel_magnification_no_absorber,
)

__all__ = ["figure8", "write_png_atomic"]


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
    """
    r2 = np.linspace(0.0, r2_max, n_points)
    r = np.sqrt(r2)
    fig = Figure(figsize=(13, 8), layout="constrained")
    axes = fig.subplots(2, 3, sharex=True, sharey=True)
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
    fig.suptitle("Figure 8: acceleration magnification factor (Eq. 4.3 solved)")
    if path is not None:
        write_png_atomic(fig, path)
    return fig
