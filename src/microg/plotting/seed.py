"""Figures of the reproduction (Figures 3 and 4 of the report) and the point response.

Every plot function takes ``ax=``, the matplotlib axes to draw into (default: a new figure),
and returns the figure.
"""

from __future__ import annotations

from typing import Any

from matplotlib.axes import Axes
from matplotlib.figure import Figure

from microg.plotting.common import figure_axes, figure_grid
from microg.seed.reproduce import CurveSet
from microg.units import G0

__all__ = ["figure3", "figure4", "point_response_figure"]


def _curves(curves: CurveSet, which: str, title: str, ylabel: str, ax: Axes | None) -> Figure:
    fig, ax = figure_axes(ax, 7.5, 4.2)
    data = curves.u if which == "u" else curves.a
    for w, y in zip(curves.omega, data, strict=True):
        ax.plot(curves.timepts, y, lw=1.3, label=f"w = {w:g} rad/s")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def figure3(curves: CurveSet, *, ax: Axes | None = None) -> Figure:
    """Figure 3: dimensionless displacement U(t) (Eq. 2.17) for several w."""
    return _curves(curves, "u", "Figure 3 - displacement functions U(t), Eq. 2.17", "U(t)", ax)


def figure4(curves: CurveSet, *, ax: Axes | None = None) -> Figure:
    """Figure 4: dimensionless acceleration A(t) (Eq. 2.19) for several w."""
    return _curves(curves, "a", "Figure 4 - acceleration functions A(t), Eq. 2.19", "A(t)", ax)


def point_response_figure(
    responses: dict[str, Any], z_e_ft: float, z_a_ft: float, *, ax: Any = None
) -> Figure:
    """Acceleration at z_e from the crew force at z_a per case (Eq. 2.20b), in micro-g.

    Parameters
    ----------
    responses : dict of str to PointResponse
        Case name -> the response (times in s, accelerations in m/s^2).
    z_e_ft, z_a_ft : float
        The observation and crew positions, ft (for the title).
    ax : array of matplotlib.axes.Axes, optional
        The four axes to draw into, row by row (default: a new 2 x 2 figure, titled).
    """
    new = ax is None
    fig, axes = figure_grid(ax, 2, 2, width_in=9.5, height_in=6.0, sharex=True)
    for ax, (case, r) in zip(axes.ravel(), responses.items(), strict=False):
        for j, a in enumerate(r.accel_modes, 1):
            ax.plot(r.timepts, a / G0 * 1e6, lw=0.9, label=f"mode {j}")
        ax.plot(r.timepts, r.accel / G0 * 1e6, "k", lw=1.1, label="sum")
        ax.set_title(case, fontsize=10)
        ax.grid(alpha=0.3)
        ax.set_ylabel("micro-g")
    axes[0, 0].legend(fontsize=8)
    for ax in axes[1]:
        ax.set_xlabel("time t (s)")
    if new:
        fig.suptitle(
            f"Acceleration at z_e = {z_e_ft:.4g} ft, crew force at z_a = {z_a_ft:.4g} ft "
            "(Eq. 2.20b)"
        )
    return fig
