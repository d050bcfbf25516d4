"""HTML of ``microg assess`` and ``microg quasi-steady`` (reads their JSON results).

Each page is one self-contained file (figures embedded as data URIs) whose verdict lines follow
from the fields beside them: a band verdict is "complies" only where the result says so, "fails"
where a judged band's margin is below 1, and otherwise "not shown" with the reason.
"""

from __future__ import annotations

import math
from typing import Any

from microg._io import to_jsonable

__all__ = ["band_verdict", "render_assessment", "render_quasi_steady"]


def band_verdict(obs: dict[str, Any]) -> tuple[str, str]:
    """(verdict text, CSS class) of one observation's band criterion, from its own fields.

    Parameters
    ----------
    obs : an observation of the assess contract (``complies``, ``worst_band``,
        ``third_octave.unresolved_exceeding_hz``)
    """
    worst = obs.get("worst_band") or {}
    margin = worst.get("margin")
    if obs.get("complies") is True:
        return "complies", "pass"
    if isinstance(margin, int | float) and margin < 1.0:
        return f"fails (margin {margin:.3g})", "fail"
    if obs.get("third_octave", {}).get("unresolved_exceeding_hz"):
        return "not shown: bands the record cannot resolve exceed their limits", "undecided"
    return "not shown", "undecided"


def _transient_verdict(tr: dict[str, Any] | None) -> tuple[str, str]:
    if not tr:
        return "", ""
    if tr.get("complies") is True:
        return "complies", "pass"
    if tr.get("complies") is False and tr.get("verified"):
        return "fails", "fail"
    if tr.get("complies") is False:
        return "exceeded (an unverified criterion: reported, not judged)", "warn"
    return "undecided", "undecided"


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
        verdict, css = band_verdict(obs)
        tv, tc = _transient_verdict(obs.get("transient"))
        sensors.append(
            {
                "name": key,
                "data": obs,
                "band_verdict": verdict,
                "band_class": css,
                "transient_verdict": tv,
                "transient_class": tc,
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
