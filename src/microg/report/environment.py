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

__all__ = ["criterion_verdict", "render_assessment", "render_quasi_steady"]


def criterion_verdict(c: dict[str, Any]) -> tuple[str, str]:
    """(verdict text, CSS class) of one criterion of the JSON ``criteria`` list, from its fields.

    The words are :meth:`microg.environment.criteria.CriterionVerdict.line`'s: ``judged`` is
    "complies" or "fails", ``reported`` adds "reported only" (its limit does not enter the
    verdict), ``undecided`` says so.

    Parameters
    ----------
    c : one entry of an observation's ``criteria`` (``status``, ``complies``, ``margin``)
    """
    if c.get("status") == "undecided" or c.get("complies") is None:
        return "undecided", "undecided"
    margin = c.get("margin")
    m = f" (margin {margin:.3g})" if isinstance(margin, int | float) else ""
    if c.get("status") == "judged":
        return ("complies" + m, "pass") if c["complies"] else ("fails" + m, "fail")
    if c["complies"]:
        return "reported only: within its limit" + m, ""
    return "reported only: exceeds its limit" + m, "warn"


def render_assessment(payload: dict[str, Any], figs: dict[str, dict[str, bytes]]) -> str:
    """Self-contained HTML of an assessment.

    Parameters
    ----------
    payload : the ``microg assess --json`` document
    figs : per sensor key, PNG bytes by figure name (report order)
    """
    from microg import __version__
    from microg.report.html import environment, png_data_uri

    d = to_jsonable(payload)
    sensors = []
    for key, obs in d["observations"].items():
        rows = [{**c, "verdict": criterion_verdict(c)} for c in obs.get("criteria", [])]
        sensors.append(
            {
                "name": key,
                "data": obs,
                "criteria": rows,
                "overlay": (d.get("prediction") or {}).get(key),
                "figs": [png_data_uri(b) for b in figs.get(key, {}).values()],
            }
        )
    tmpl = environment().get_template("assess.html")
    return str(tmpl.render(version=__version__, d=d, sensors=sensors))


def _norm(v: Any) -> float:
    try:
        return math.sqrt(sum(float(x) ** 2 for x in v))
    except (TypeError, ValueError):
        return math.nan


def render_quasi_steady(data: dict[str, Any], map_png: bytes | None) -> str:
    """Self-contained HTML of a quasi-steady result.

    Parameters
    ----------
    data : the ``microg quasi-steady --json`` document
    map_png : PNG bytes of the map figure, if there is a map
    """
    from microg import __version__
    from microg.report.html import environment, png_data_uri

    tmpl = environment().get_template("quasi-steady.html")
    return str(
        tmpl.render(
            version=__version__,
            d=to_jsonable(data),
            norm=_norm,
            map_fig=None if map_png is None else png_data_uri(map_png),
        )
    )
