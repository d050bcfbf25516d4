"""Figures and HTML of ``microg sweep`` (reads a :class:`~microg.study.summary.Summary`)."""

from __future__ import annotations

import datetime as _dt
from typing import TYPE_CHECKING

from microg._io import to_jsonable

if TYPE_CHECKING:
    from microg.study.summary import Summary

__all__ = ["figures", "render_sweep"]


def figures(summary: Summary) -> dict[str, bytes]:
    """PNG bytes of the report's figures: ``heatmap``, ``fraction``, ``bands``."""
    from microg.plotting.common import png_bytes
    from microg.plotting.study import fraction_figure, heatmap_figure, worst_bands_figure

    return {
        "heatmap": png_bytes(heatmap_figure(summary)),
        "fraction": png_bytes(fraction_figure(summary)),
        "bands": png_bytes(worst_bands_figure(summary)),
    }


def render_sweep(
    summary: Summary,
    figs: dict[str, bytes],
    *,
    command: str | None = None,
    requirement_source: str = "",
) -> str:
    """Self-contained HTML of a sweep's summary, figures embedded as data URIs.

    Parameters
    ----------
    summary : the Summary
    figs : PNG bytes from :func:`figures`
    command : the command line, for the provenance record
    requirement_source : citation of the requirement
    """
    from microg import __version__
    from microg.report.html import environment, png_data_uri
    from microg.study.plan import CASE_DIMS

    data = to_jsonable(summary.to_dict())
    data["study"] = to_jsonable(summary.study)
    return (
        environment()
        .get_template("sweep.html")
        .render(
            version=__version__,
            created=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
            command=command,
            requirement_source=requirement_source,
            s=data,
            dims=list(CASE_DIMS),
            figs={k: png_data_uri(v) for k, v in figs.items()},
        )
    )
