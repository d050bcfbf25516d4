"""What every figure module shares: where a figure draws, envelopes, point labels, PNG bytes.

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
    "place_labels",
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


#: offsets (points) a point's label tries, nearest first: beside the point, then further above
#: and below it, to the right and then to the left
_LABEL_OFFSETS = tuple(
    (dx, dy) for dy in (4, -4, 15, -15, 26, -26, 37, -37, 48, -48) for dx in (5, -5)
)


def _renderer(fig: Figure) -> Any:
    """A renderer of ``fig`` to measure text with (an Agg canvas when it has none)."""
    get = getattr(fig.canvas, "get_renderer", None)
    if get is None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        get = FigureCanvasAgg(fig).get_renderer
    return get()


def _overlap(a: Any, b: Any) -> float:
    w = min(a.x1, b.x1) - max(a.x0, b.x0)
    h = min(a.y1, b.y1) - max(a.y0, b.y0)
    return max(w, 0.0) * max(h, 0.0)


def place_labels(
    ax: Axes,
    labels: list[tuple[float, float, str, str]],
    *,
    fontsize: float = 8.0,
    merge_pt: float = 6.0,
) -> list[Any]:
    """Label points of ``ax`` so that no two labels overlap; returns the annotations.

    Call it once the rest of the figure is drawn (colour bars, titles): it lays the figure
    out, merges the labels of points of one colour closer than ``merge_pt`` on the page into
    one block (one line each), then puts each label at the first offset of
    ``_LABEL_OFFSETS`` whose box overlaps no text of the axes (or the least overlapping one),
    and checks once more after the layout settles.

    Parameters
    ----------
    ax : the axes
    labels : (x, y, text, colour) per point, x and y in data coordinates
    fontsize : points
    merge_pt : distance on the page (points) under which two points share one label
    """
    fig = figure_of(ax)
    renderer = _renderer(fig)
    fig.draw_without_rendering()
    if not labels:
        return []
    xy = ax.transData.transform(np.array([(x, y) for x, y, _, _ in labels], float))
    tol = merge_pt * fig.dpi / 72.0
    blocks: list[tuple[int, list[str]]] = []  # (index of the anchor label, texts)
    for i, (_, _, text, colour) in enumerate(labels):
        for k, texts in blocks:
            if labels[k][3] == colour and float(np.hypot(*(xy[i] - xy[k]))) <= tol:
                if text not in texts:
                    texts.append(text)
                break
        else:
            blocks.append((i, [text]))
    anns = [
        ax.annotate(
            "\n".join(texts),
            (labels[k][0], labels[k][1]),
            xytext=_LABEL_OFFSETS[0],
            textcoords="offset points",
            fontsize=fontsize,
            color=labels[k][3],
            annotation_clip=False,
        )
        for k, texts in blocks
    ]
    for _ in range(2):
        mine = {id(a) for a in anns}
        fixed = [
            t.get_window_extent(renderer)
            for t in ax.texts
            if id(t) not in mine and t.get_text().strip()
        ]
        placed: list[Any] = []
        clash = False
        for a in anns:
            best, least = _LABEL_OFFSETS[0], math.inf
            for dx, dy in _LABEL_OFFSETS:
                a.xyann = (dx, dy)
                a.set_horizontalalignment("left" if dx > 0 else "right")
                a.set_verticalalignment("bottom" if dy > 0 else "top")
                box = a.get_window_extent(renderer)
                hit = sum(_overlap(box, o) for o in fixed + placed)
                if hit < least:
                    best, least = (dx, dy), hit
                if hit == 0.0:
                    break
            clash = clash or least > 0.0
            a.xyann = best
            a.set_horizontalalignment("left" if best[0] > 0 else "right")
            a.set_verticalalignment("bottom" if best[1] > 0 else "top")
            placed.append(a.get_window_extent(renderer))
        fig.draw_without_rendering()
        boxes = [a.get_window_extent(renderer) for a in anns]
        if not clash and all(
            _overlap(p, q) == 0.0 for i, p in enumerate(boxes) for q in boxes[i + 1 :]
        ):
            break
    return anns
