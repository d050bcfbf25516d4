"""Figure of a modal solution: a stem chart of the natural frequencies.

Built with ``matplotlib.figure.Figure`` (no pyplot, no backend switch).  Rigid-body modes
(exactly 0 Hz) are listed in the title, not drawn on the logarithmic axis; unstable modes are
drawn at their growth rate (in Hz, as ``growth_rate / 2 pi``) in a separate colour.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from microg.plotting.common import envelope, figure_axes

__all__ = ["plot_modal_response", "plot_modes"]


def plot_modes(modes: Any, *, title: str | None = None, ax: Axes | None = None) -> Figure:
    """Stem chart of the frequencies of ``modes`` (a :class:`~microg.dynamics.modes.Modes`).

    Parameters
    ----------
    modes : Modes
        omega in rad/s; rigid, unstable and growth_rate as documented there.
    title : str, optional
        Figure title (default: method and the number of rigid modes).
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_axes(ax, 7.5, 4.0)
    number = np.arange(1, modes.n_modes + 1)
    el = np.asarray(modes.elastic, bool)
    unstable = np.asarray(modes.unstable, bool)
    f = np.asarray(modes.freq_hz, float)
    if el.any():
        ax.vlines(number[el], 0.0, f[el], color="C0")
        ax.plot(number[el], f[el], "o", color="C0", label="elastic (Hz)")
    if unstable.any():
        g = np.asarray(modes.growth_rate, float)[unstable] / (2.0 * np.pi)
        ax.vlines(number[unstable], 0.0, g, color="C3")
        ax.plot(number[unstable], g, "x", color="C3", label="unstable: growth rate / 2 pi")
    if el.any() or unstable.any():
        ax.set_yscale("log")
        ax.legend(loc="upper left")
    ax.set_xlabel("mode number")
    ax.set_ylabel("frequency (Hz)")
    n_rigid = int(np.count_nonzero(modes.rigid))
    ax.set_title(title or f"{modes.method}: {modes.n_modes} modes, {n_rigid} rigid at 0 Hz")
    ax.grid(True, which="both", alpha=0.3)
    return fig


def plot_modal_response(
    response: Any, *, n_show: int = 6, title: str = "", ax: Axes | None = None
) -> Figure:
    """Modal accelerations against time: the ``n_show`` modes with the largest peak.

    Parameters
    ----------
    response : ModalResponse
        ``timepts`` in s; ``eta_ddot`` (m, nt) in the modal unit (m/s^2 per unit modal
        coordinate times sqrt(kg) for mass-normalised modes).
    n_show : int
        Modes drawn (the others are listed by count in the title).
    title : str, optional
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
    """
    acc = np.atleast_2d(np.asarray(response.eta_ddot, float))
    t = np.asarray(response.timepts, float)
    peak = np.max(np.abs(acc), axis=1) if acc.size else np.zeros(acc.shape[0])
    order = np.argsort(-peak, kind="stable")[: max(int(n_show), 0)]
    fig, ax = figure_axes(ax, 7.5, 4.0)
    for j in order:
        ax.plot(*envelope(t, acc[j]), lw=0.8, label=f"mode {j + 1}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("modal acceleration")
    rest = acc.shape[0] - order.size
    ax.set_title(
        title
        or f"Modal accelerations ({order.size} largest"
        + (f"; {rest} more not drawn)" if rest > 0 else ")")
    )
    ax.grid(True, alpha=0.3)
    if order.size:
        ax.legend(fontsize=8)
    return fig
