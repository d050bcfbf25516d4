# ruff: noqa: E501  (the page template's HTML lines)
"""The HTML page of ``microg isolate active --out DIR``: the verdict, the margins, the figures.

Self-contained (figures as data URIs); it computes nothing, it formats
:class:`~microg.isolation.active.result.ActiveIsolation`'s ``to_dict()`` and its figures.
"""

from __future__ import annotations

from html import escape
from typing import TYPE_CHECKING, Any

from microg.report.html import png_data_uri

if TYPE_CHECKING:
    from microg.isolation.active.result import ActiveIsolation

__all__ = ["render_active"]


def _num(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return escape(str(v))


def render_active(res: ActiveIsolation, figures: dict[str, bytes]) -> str:
    """The page: verdict, binding limit, plant and its sources, margins per loop, figures."""
    d = res.to_dict()
    rows = []
    for loop, models in d["margins"].items():
        for model, m in models.items():
            rows.append(
                f"<tr><td>{loop}</td><td>{model}</td><td>{_num(m['gain_margin_db'])}</td>"
                f"<td>{_num(m['phase_margin_deg'])}</td><td>{_num(m['gain_crossover_hz'])}</td></tr>"
            )
    plant = d["plant"]
    src = "".join(
        f"<tr><td>{escape(k)}</td><td>{escape(v)}</td></tr>" for k, v in plant["sources"].items()
    )
    figs = "".join(
        f'<figure><img alt="{escape(n)}" src="{png_data_uri(b)}"><figcaption>{escape(n)}</figcaption></figure>'
        for n, b in figures.items()
    )
    notes = "".join(f"<li>{escape(n)}</li>" for n in d["notes"])
    verdict = "meets its target" if d["meets_target"] else "does not meet its target"
    extra = (
        f"; at {escape(d['time_check']['point'])} the platform "
        f"{'complies' if d['complies'] else 'does not comply'} with the requirement "
        f"(stroke {_num(d['stroke_m'])} m of {_num(d['stroke_limit_m'])} m, force "
        f"{_num(d['force_N'])} N of {_num(d['force_limit_N'])} N)"
        if d["time_check"] is not None
        else ""
    )
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>microg isolate active: {escape(plant["name"])}</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:1em auto}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:2px 6px;font-size:90%}}img{{max-width:100%}}</style></head>
<body><h1>Active isolation: {escape(plant["name"])}, {escape(d["controller"]["kind"])} controller</h1>
<p><b>The design {verdict}</b> ({escape(d["target"]["name"])}: {escape(d["target"]["source"])});
stable: {d["stable"]}; binding limit: {escape(str(d["binding_limit"]))}{extra}.</p>
<p>Attenuation at 0.1 Hz: {", ".join(f"{a} {_num(v)}x" for a, v in d["attenuation_at_0_1_hz"].items())}.</p>
<ul>{notes}</ul>
<h2>Margins per loop (each broken at its actuator, the others closed)</h2>
<table><tr><th>loop</th><th>model</th><th>gain margin (dB)</th><th>phase margin (deg)</th><th>crossover (Hz)</th></tr>
{"".join(rows)}</table>
<h2>Figures</h2>{figs}
<h2>Plant parameters and their sources</h2>
<p>mass {_num(plant["mass_kg"])} kg; umbilical k {escape(str(plant["umbilical"]["k_N_per_m"]))} N/m,
c {escape(str(plant["umbilical"]["c_N_s_per_m"]))} N s/m; rattlespace {_num(plant["rattlespace_m"])} m;
actuator force {_num(plant["actuator_force_N"])} N; sampling {_num(plant["sample_rate_hz"])} Hz, delay {_num(plant["delay_s"])} s.</p>
<table><tr><th>parameter</th><th>source</th></tr>{src}</table>
</body></html>
"""
