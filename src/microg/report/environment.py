"""HTML of ``microg assess`` and ``microg quasi-steady`` (reads their JSON results).

Each page is one self-contained file (figures embedded as data URIs) whose verdict lines follow
from the fields beside them: one row per criterion of the result's ``criteria`` (judged,
reported only, or undecided, as :mod:`microg.environment.criteria` decides), with its margin,
value, limit, why and source.
"""

from __future__ import annotations

import math
from typing import Any

from microg._io import to_jsonable
from microg.report.html import criterion_verdict  # the one wording (analyze's page uses it too)

__all__ = ["criterion_verdict", "figure_entries", "render_assessment", "render_quasi_steady"]


def figure_entries(
    pngs: dict[str, bytes], charts: dict[str, list[Any]] | None, first_id: int = 0
) -> list[dict[str, Any]]:
    """The page's figures in order: each a PNG data URI, or its interactive charts' fragments.

    Parameters
    ----------
    pngs : PNG bytes by file name (report order)
    charts : plotly Figures by the PNG's file name they stand for (None: PNGs only)
    first_id : the element ids are ``chart-N`` from ``first_id + 1`` on

    Returns
    -------
    list of dict
        ``file``, ``png`` (a data URI, None when a chart stands for it), ``charts`` (HTML
        fragments, or None).
    """
    from microg.report.html import chart_fragment, png_data_uri

    out, n = [], first_id
    for name, png in pngs.items():
        figs = (charts or {}).get(name)
        frags = None
        if figs:
            frags = []
            for f in figs:
                n += 1
                frags.append(chart_fragment(f, div_id=f"chart-{n}"))
        out.append({"file": name, "png": None if frags else png_data_uri(png), "charts": frags})
    return out


def render_assessment(
    payload: dict[str, Any],
    figs: dict[str, dict[str, bytes]],
    charts: dict[str, dict[str, list[Any]]] | None = None,
) -> str:
    """Self-contained HTML of an assessment.

    Parameters
    ----------
    payload : the ``microg assess --json`` document
    figs : per sensor key, PNG bytes by figure name (report order)
    charts : per sensor key, the interactive charts (plotly Figures) standing for a PNG, by
        its name; None: the page shows the PNGs only, without plotly.js
    """
    from microg import __version__
    from microg.report.html import environment, plotly_js

    d = to_jsonable(payload)
    sensors = []
    n = 0
    for key, obs in d["observations"].items():
        rows = [{**c, "verdict": criterion_verdict(c)} for c in obs.get("criteria", [])]
        entries = figure_entries(figs.get(key, {}), None if charts is None else charts.get(key), n)
        n += sum(len(e["charts"] or ()) for e in entries)
        sensors.append(
            {
                "name": key,
                "data": obs,
                "criteria": rows,
                "overlay": (d.get("prediction") or {}).get(key),
                "figs": entries,
            }
        )
    tmpl = environment().get_template("assess.html")
    return str(
        tmpl.render(
            version=__version__,
            d=d,
            sensors=sensors,
            plotlyjs=None if charts is None else plotly_js(),
        )
    )


def _norm(v: Any) -> float:
    try:
        return math.sqrt(sum(float(x) ** 2 for x in v))
    except (TypeError, ValueError):
        return math.nan


def render_quasi_steady(
    data: dict[str, Any], map_png: bytes | None, map_3d: Any | None = None
) -> str:
    """Self-contained HTML of a quasi-steady result.

    Parameters
    ----------
    data : the ``microg quasi-steady --json`` document
    map_png : PNG bytes of the map figure, if there is a map
    map_3d : the map in 3-D (a plotly Figure, ``QuasiSteadyResult.plot3d()``), shown above the
        PNG with plotly.js inlined once; None: the PNG only
    """
    from microg import __version__
    from microg.report.html import chart_fragment, environment, plotly_js, png_data_uri

    tmpl = environment().get_template("quasi-steady.html")
    return str(
        tmpl.render(
            version=__version__,
            d=to_jsonable(data),
            norm=_norm,
            map_fig=None if map_png is None else png_data_uri(map_png),
            map3d=None if map_3d is None else chart_fragment(map_3d, div_id="map3d"),
            plotlyjs=None if map_3d is None else plotly_js(),
        )
    )
