"""HTML of ``microg locate``: the acceleration map in 3-D and its tables (reads a LocateResult).

One self-contained page: the run's inputs, the best location, the nodes of the fundamental, the
range of the peak along each component (g), the map coloured along the structure in 3-D
(plotly, plotly.js inlined once in the head) and the archived PNG of the map.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from microg._io import to_jsonable

if TYPE_CHECKING:
    from microg.location.pipeline import LocateResult

__all__ = ["component_ranges", "render_locate"]


def component_ranges(result: LocateResult) -> list[dict[str, Any]]:
    """Per component, in the map's order: samples, least and largest total and elastic peak, g.

    Parameters
    ----------
    result : LocateResult
    """
    from microg.units import G0

    amap = result.amap
    comp = np.asarray(amap.component).astype(str)
    rows = []
    for name in dict.fromkeys(comp.tolist()):
        sel = comp == name
        tot = np.asarray(amap.total_peak, float)[sel] / G0
        el = np.asarray(amap.elastic_peak, float)[sel] / G0
        rows.append(
            {
                "component": name,
                "n": int(sel.sum()),
                "total_min_g": float(tot.min()),
                "total_max_g": float(tot.max()),
                "elastic_min_g": float(el.min()),
                "elastic_max_g": float(el.max()),
            }
        )
    return rows


def render_locate(
    result: LocateResult, map_png: bytes, *, static: bool = False, command: str | None = None
) -> str:
    """Self-contained HTML of an acceleration map.

    Parameters
    ----------
    result : LocateResult
    map_png : PNG bytes of the map figure (``result.plot()``)
    static : the PNG only: no 3-D map, no plotly.js
    command : the command line that made the map, shown in the page
    """
    from microg import __version__
    from microg.report.html import chart_fragment, environment, plotly_js, png_data_uri

    d = to_jsonable(result.to_dict())
    d.pop("samples", None)
    tmpl = environment().get_template("locate.html")
    return str(
        tmpl.render(
            version=__version__,
            d=d,
            command=command,
            ranges=component_ranges(result),
            map_fig=png_data_uri(map_png),
            map3d=None if static else chart_fragment(result.plot3d(), div_id="map3d"),
            plotlyjs=None if static else plotly_js(),
        )
    )
