"""What every figure module shares: PNG rendering and data URIs.

Figures are ``matplotlib.figure.Figure`` objects built without pyplot, so the caller's
backend (a notebook's, a GUI's) is never switched and no global figure state is kept.
"""

from __future__ import annotations

import base64
import io

from matplotlib.figure import Figure

__all__ = ["new_figure", "png_bytes", "png_data_uri"]


def new_figure(width_in: float = 7.5, height_in: float = 4.2, **kwargs: object) -> Figure:
    """A pyplot-free Figure of the given size, in inches."""
    return Figure(figsize=(width_in, height_in), **kwargs)  # type: ignore[arg-type]


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
