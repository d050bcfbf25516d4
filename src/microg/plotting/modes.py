"""Figure of a modal solution: a stem chart of the natural frequencies.

Built with ``matplotlib.figure.Figure`` (no pyplot, no backend switch).  Rigid-body modes
(exactly 0 Hz) are listed in the title, not drawn on the logarithmic axis; unstable modes are
drawn at their growth rate (in Hz, as ``growth_rate / 2 pi``) in a separate colour.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure

__all__ = ["plot_modes"]


def plot_modes(modes: Any, *, title: str | None = None) -> Figure:
    """Stem chart of the frequencies of ``modes`` (a :class:`~microg.dynamics.modes.Modes`).

    Parameters
    ----------
    modes : Modes
        omega in rad/s; rigid, unstable and growth_rate as documented there.
    title : str, optional
        Figure title (default: method and the number of rigid modes).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = Figure(figsize=(7.5, 4.0), layout="constrained")
    ax = fig.add_subplot()
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
