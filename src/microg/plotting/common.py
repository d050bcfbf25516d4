"""What every figure module shares: where a figure draws, drawing envelopes, PNG bytes.

Figures are ``matplotlib.figure.Figure`` objects built without pyplot, so the caller's
backend (a notebook's, a GUI's) is never switched and no global figure state is kept.  Every
plot function takes ``ax=``: it draws into the caller's axes (and returns their figure), or,
without one, into a new figure laid out by matplotlib's constrained layout
(:func:`figure_axes`, :func:`figure_grid`).

Long time histories are drawn through a min/max envelope (:func:`envelope`): every extreme
of the record is drawn exactly, at its own time, so no peak is lost; only the samples between
the extremes of each of ~2,000 slices of the record are left out of the *drawing*.  The
results (``results.json``, the result objects) are never decimated.
"""

from __future__ import annotations

import io
import math
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from microg.errors import InputError

__all__ = [
    "ENVELOPE_BINS",
    "envelope",
    "figure_axes",
    "figure_grid",
    "figure_of",
    "png_bytes",
]

#: slices of a record drawn as their min and max (>= 2 per pixel column of a 7.5-in figure)
ENVELOPE_BINS = 2000


def figure_of(ax: Axes) -> Figure:
    """The figure an axes belongs to (the top-level one, for an axes in a subfigure)."""
    fig = getattr(ax.figure, "figure", None)  # a Figure's and a SubFigure's root figure
    if not isinstance(fig, Figure):
        raise InputError("the axes belong to no figure", where="ax")
    return fig


def figure_axes(
    ax: Axes | None, width_in: float = 7.5, height_in: float = 4.5
) -> tuple[Figure, Axes]:
    """The figure and axes to draw into: the caller's ``ax``, or a new one-axes figure.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or None
        The caller's axes (its figure is left as it is: size, layout, other axes).
    width_in, height_in : float
        Size of a new figure, inches (constrained layout).
    """
    if ax is None:
        fig = Figure(figsize=(width_in, height_in), layout="constrained")
        return fig, fig.add_subplot()
    if not isinstance(ax, Axes):
        raise InputError(f"expected a matplotlib Axes, got {type(ax).__name__}", where="ax")
    return figure_of(ax), ax


def figure_grid(
    ax: Any,
    nrows: int,
    ncols: int = 1,
    *,
    width_in: float = 7.5,
    height_in: float = 6.4,
    **subplots: Any,
) -> tuple[Figure, np.ndarray]:
    """The figure and the (nrows, ncols) array of axes a multi-panel plot draws into.

    Parameters
    ----------
    ax : sequence of matplotlib.axes.Axes, or None
        The caller's axes, ``nrows * ncols`` of them (any shape, read row by row); None: a
        new figure with a grid of subplots.
    nrows, ncols : int
        The panels.
    width_in, height_in : float
        Size of a new figure, inches (constrained layout).
    **subplots
        Passed to :meth:`~matplotlib.figure.Figure.subplots` for a new figure (``sharex``).
    """
    if ax is None:
        fig = Figure(figsize=(width_in, height_in), layout="constrained")
        return fig, np.asarray(fig.subplots(nrows, ncols, squeeze=False, **subplots))
    axes = np.asarray(ax, dtype=object).ravel()
    if axes.size != nrows * ncols or not all(isinstance(a, Axes) for a in axes):
        raise InputError(
            f"expected {nrows * ncols} matplotlib Axes (one per panel), got {axes.size}",
            where="ax",
        )
    return figure_of(axes[0]), axes.reshape(nrows, ncols)


def envelope(
    x: np.ndarray, y: np.ndarray, bins: int = ENVELOPE_BINS
) -> tuple[np.ndarray, np.ndarray]:
    """A long line reduced, for drawing only, to the min and max of each of ``bins`` slices.

    The samples kept are the first, the last, and in each slice of consecutive samples the
    smallest and the largest, in time order: the line drawn through them touches every
    extreme of the record exactly (the peak sample is always kept), and within a slice narrower
    than a pixel column it covers the same vertical range as the full line.

    Parameters
    ----------
    x : ndarray (n,)
        Abscissae (e.g. times in s), increasing.
    y : ndarray (n,)
        Ordinates.
    bins : int
        Number of slices; lines of at most ``2 * bins + 2`` samples are returned unchanged.

    Returns
    -------
    x, y : ndarray
        The samples kept (views of the input when nothing is left out).
    """
    x = np.asarray(x)
    y = np.asarray(y)
    n = y.shape[-1]
    if n <= 2 * bins + 2:
        return x, y
    k = math.ceil(n / bins)  # samples per slice
    m = n // k  # full slices
    body = y[: m * k].reshape(m, k)
    start = np.arange(m) * k
    parts = [np.array([0, n - 1]), start + np.argmin(body, axis=1), start + np.argmax(body, axis=1)]
    if m * k < n:
        tail = y[m * k :]
        parts.append(np.array([m * k + int(np.argmin(tail)), m * k + int(np.argmax(tail))]))
    keep = np.unique(np.concatenate(parts))
    return x[keep], y[keep]


def png_bytes(fig: Figure, dpi: int = 110) -> bytes:
    """The PNG file of ``fig`` as ``fig.savefig`` writes it, in memory.

    For the reports, which embed the bytes in the HTML page and write them into the run
    directory as a whole.

    Parameters
    ----------
    fig : Figure
    dpi : int
        Dots per inch.
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()
