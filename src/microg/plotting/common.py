"""What every figure module shares: lean figures, PNG rendering and data URIs.

Figures are ``matplotlib.figure.Figure`` objects built without pyplot, so the caller's
backend (a notebook's, a GUI's) is never switched and no global figure state is kept.

They are drawn for speed as well as legibility (issue 8, "Speed of the main job"):

* fixed margins in inches (:func:`new_figure`, :func:`set_margins`) instead of matplotlib's
  constrained layout, which measures every label twice before the figure is drawn (40 % of
  the figure time of ``microg analyze``);
* logarithmic axes labelled ``10⁻⁵`` in Unicode superscripts (:class:`PlainLogFormatter`)
  instead of the same label typeset by mathtext, whose parser is the costliest part of a
  first draw;
* long time histories drawn through a min/max envelope (:func:`envelope`): every extreme of
  the record is drawn exactly, at its own time, so no peak is lost; only the samples between
  the extremes of each of ~2,000 slices of the record are left out of the *drawing*.  The
  results (``results.json``, the result objects) are never decimated.
"""

from __future__ import annotations

import base64
import io
import math
import re
from typing import Any

import numpy as np
from matplotlib import rcParams
from matplotlib.artist import Artist
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.lines import Line2D
from matplotlib.ticker import LogFormatterSciNotation, NullLocator

__all__ = [
    "ENVELOPE_BINS",
    "PlainLogFormatter",
    "envelope",
    "finish",
    "new_figure",
    "png_bytes",
    "png_data_uri",
    "set_margins",
]

#: slices of a record drawn as their min and max (>= 2 per pixel column of a 7.5-in figure)
ENVELOPE_BINS = 2000

#: default margins, inches: room for tick labels and an axis label (left, bottom), a title
_MARGINS = {"left": 0.85, "right": 0.2, "bottom": 0.55, "top": 0.35}

_SUPERSCRIPT = str.maketrans(
    "-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079"
)
_MATHDEFAULT = re.compile(r"^\$\\mathdefault\{(.*)\}\$$")
_POWER = re.compile(r"\^\{(-?\d+)\}")


class PlainLogFormatter(LogFormatterSciNotation):
    """Log-axis labels as :class:`~matplotlib.ticker.LogFormatterSciNotation` writes them.

    Set in Unicode (``10⁻⁵``, ``2×10³``) instead of mathtext; same ticks, same text.
    """

    def __call__(self, x: float, pos: int | None = None) -> str:
        """The label of the tick at ``x``."""
        label = str(super().__call__(x, pos))
        m = _MATHDEFAULT.match(label)
        if m is None:
            return label
        body = _POWER.sub(lambda g: g.group(1).translate(_SUPERSCRIPT), m.group(1))
        body = body.replace(r"\times", "\u00d7").replace("-", "\u2212")
        if "\\" in body or "{" in body or "^" in body:
            return label  # not a plain power: leave it to mathtext
        return body


def new_figure(
    width_in: float = 7.5,
    height_in: float = 4.2,
    *,
    margins: dict[str, float] | None = None,
    **kwargs: object,
) -> Figure:
    """A pyplot-free Figure of the given size, in inches, with fixed margins.

    Parameters
    ----------
    width_in, height_in : float
        Figure size, inches.
    margins : dict, optional
        Margins in inches (``left``, ``right``, ``bottom``, ``top``, ``hspace``, ``wspace``),
        see :func:`set_margins`; ignored when a ``layout`` is given.
    **kwargs
        Passed to :class:`~matplotlib.figure.Figure` (e.g. ``layout="constrained"`` to let
        matplotlib place the axes instead).
    """
    fig = Figure(figsize=(width_in, height_in), **kwargs)  # type: ignore[arg-type]
    if kwargs.get("layout") is None:
        set_margins(fig, **(margins or {}))
    return fig


def set_margins(
    fig: Figure,
    left: float = _MARGINS["left"],
    right: float = _MARGINS["right"],
    bottom: float = _MARGINS["bottom"],
    top: float = _MARGINS["top"],
    hspace: float = 0.75,
    wspace: float = 0.6,
) -> None:
    """Place the subplots with fixed margins and gaps, all in inches.

    Parameters
    ----------
    fig : Figure
    left, right, bottom, top : float
        Distance of the subplot area from each figure edge, inches.
    hspace, wspace : float
        Gap between rows and between columns of subplots, inches.
    """
    w, h = fig.get_size_inches()
    nrows, ncols = _grid_shape(fig)
    aw = max((w - left - right - (ncols - 1) * wspace) / ncols, 0.1)
    ah = max((h - top - bottom - (nrows - 1) * hspace) / nrows, 0.1)
    fig.subplots_adjust(
        left=left / w,
        right=1.0 - right / w,
        bottom=bottom / h,
        top=1.0 - top / h,
        hspace=hspace / ah,
        wspace=wspace / aw,
    )


def _grid_shape(fig: Figure) -> tuple[int, int]:
    """Rows and columns of the figure's subplot grid (1, 1 before any subplot exists)."""
    for ax in fig.get_axes():
        spec = ax.get_subplotspec()
        if spec is not None:
            g = spec.get_gridspec()
            return int(g.nrows), int(g.ncols)
    return 1, 1


def finish(fig: Figure, **margins: float) -> Figure:
    """Finish a figure for fast drawing: Unicode log labels and fixed margins.

    The left margin and the gap between columns grow, when the y tick labels need it, to
    hold the longest label (estimated from its characters; nothing is drawn to measure it).

    Parameters
    ----------
    fig : Figure
    **margins : float
        Margins and gaps in inches (see :func:`set_margins`), applied after the subplots
        exist (so gaps are sized to the grid); ``left`` and ``wspace`` are minimums.
    """
    axes = fig.get_axes()
    for ax in axes:
        for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
            if scale == "log":
                axis.set_major_formatter(PlainLogFormatter())
                axis.set_minor_formatter(PlainLogFormatter(labelOnlyBase=False))
                _lean_minor_ticks(ax, axis)
    if fig.get_layout_engine() is not None:
        return fig
    left = margins.pop("left", _MARGINS["left"])
    wspace = margins.pop("wspace", 0.6)
    for ax in axes:
        spec = ax.get_subplotspec()
        need = _left_need_in(ax)
        if spec is None or spec.colspan.start == 0:
            left = max(left, need)
        else:
            wspace = max(wspace, need + 0.1)
    set_margins(fig, left=left, wspace=wspace, **margins)
    return fig


#: widths of characters of the default font (DejaVu Sans), in em
_CHAR_EM = {".": 0.32, ",": 0.32, " ": 0.32, "\u2212": 0.84, "\u00d7": 0.84, "-": 0.36}


def _left_need_in(ax: Any) -> float:
    """Inches left of an axes that its y tick labels and y label take (an estimate)."""
    if not ax.yaxis.get_visible() or not ax.yaxis.get_majorticklocs().size:
        width = 0.0
    else:
        lo, hi = sorted(ax.get_ylim())
        locs = [v for v in ax.yaxis.get_major_locator()() if lo <= v <= hi]
        labels = ax.yaxis.get_major_formatter().format_ticks(locs) if locs else []
        size = FontProperties(size=rcParams["ytick.labelsize"]).get_size_in_points()
        em = max((sum(_char_em(c) for c in lab) for lab in labels), default=0.0)
        width = (em * size + rcParams["ytick.major.size"] + rcParams["ytick.major.pad"]) / 72
    label = 0.0
    if ax.get_ylabel():
        size = FontProperties(size=rcParams["axes.labelsize"]).get_size_in_points()
        label = (1.2 * size + rcParams["axes.labelpad"]) / 72
    return width + label + 0.08


def _char_em(c: str) -> float:
    if c.isdigit():
        return 0.64
    if c in "\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079\u207b":
        return 0.42
    return _CHAR_EM.get(c, 0.72)


class _MinorTicks(Artist):
    """The minor ticks and grid lines of a log axis drawn as two artists.

    Instead of one :class:`~matplotlib.axis.Tick` (five artists) per tick; styled as the
    axis' own ticks.
    """

    def __init__(self, ax: Any, axis: Any, locator: Any, grid: Any, mark: Any) -> None:
        super().__init__()
        self._ax, self._axis, self._locator = ax, axis, locator
        self._grid = grid  # the template tick's grid line (None: no minor grid)
        self._mark = mark  # the template tick's tick mark (None: not drawn)
        self.set_zorder(axis.get_zorder())

    def draw(self, renderer: Any) -> None:
        """Draw the marks and grid lines at the minor locations in view."""
        lo, hi = sorted(self._axis.get_view_interval())
        major = np.log10(np.asarray(self._axis.get_majorticklocs(), float))
        locs = np.asarray(self._locator(), float)
        locs = locs[(locs >= lo) & (locs <= hi)]
        if major.size and locs.size:  # as matplotlib: no minor tick on a major one
            close = np.abs(np.log10(locs)[:, None] - major[None, :]).min(axis=1) < 1e-9
            locs = locs[~close]
        if not locs.size:
            return
        is_x = self._axis is self._ax.xaxis
        trans = self._ax.get_xaxis_transform() if is_x else self._ax.get_yaxis_transform()
        if self._grid is not None:
            g = self._grid
            segs = [[(v, 0.0), (v, 1.0)] if is_x else [(0.0, v), (1.0, v)] for v in locs]
            lines = LineCollection(
                segs,
                colors=[g.get_color()],
                linewidths=g.get_linewidth(),
                linestyles=g.get_linestyle(),
                alpha=g.get_alpha(),
                transform=trans,
            )
            lines.set_figure(self._ax.figure)
            lines.set_clip_path(self._ax.patch)
            lines.draw(renderer)
        if self._mark is not None:
            m = self._mark
            xy = (locs, np.zeros_like(locs)) if is_x else (np.zeros_like(locs), locs)
            marks = Line2D(
                *xy,
                linestyle="none",
                marker=m.get_marker(),
                markersize=m.get_markersize(),
                markeredgewidth=m.get_markeredgewidth(),
                color=m.get_color(),
                transform=trans,
                clip_on=False,
            )
            marks.set_figure(self._ax.figure)
            marks.draw(renderer)


def _lean_minor_ticks(ax: Any, axis: Any) -> None:
    """Replace a log axis' minor Tick objects by one :class:`_MinorTicks` artist.

    Only where the axis spans more than 1.5 decades: there matplotlib labels no minor tick,
    so the drawing is the same (marks and grid lines in the axis' own style).
    """
    lo, hi = sorted(axis.get_view_interval())
    if not (lo > 0 and np.log10(hi / lo) > 1.5):
        return
    template = axis.get_minor_ticks(1)[0]
    grid = template.gridline if template.gridline.get_visible() else None
    mark = template.tick1line if template.tick1line.get_visible() else None
    locator = axis.get_minor_locator()
    axis.set_minor_locator(NullLocator())
    ax.add_artist(_MinorTicks(ax, axis, locator, grid, mark))


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
    """Render ``fig`` to PNG bytes (Agg, in memory).

    Parameters
    ----------
    fig : Figure
    dpi : int
        Dots per inch.
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def png_data_uri(png: bytes) -> str:
    """A ``data:image/png;base64,...`` URI for embedding ``png`` in HTML."""
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")
