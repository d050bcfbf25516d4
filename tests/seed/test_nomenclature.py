"""Every symbol of the reproduction page is explained, with its unit in US customary and SI.

References: the rendered page itself (its symbols are found by scanning its text) and pint
(the SI size of each US unit, independently of microg.units).
"""

from __future__ import annotations

import html
import re

import pint
import pytest

from microg.report.html import png_data_uri, render_reproduction
from microg.seed.nomenclature import NOMENCLATURE, nomenclature
from microg.seed.reproduce import reproduce

#: the symbols a reader of the report looks up by name
REQUIRED = [
    "a_e", "I_x", "I_y", "z_a", "z_e", "l_k", "l_s", "EI", "m_ij", "k_ij", "w", "[A]max",
    "M_a", "r", "mu", "M_jj", "phi_ij", "w_j", "f0", "t1", "t13", "t14", "R", "Z", "CG",
]  # fmt: skip


def _defined() -> set[str]:
    out = set()
    for s in NOMENCLATURE:
        for part in re.split(r",\s*(?![^()]*\))", s.symbol):  # commas outside parentheses
            out.add(re.sub(r"\s+\(.*\)$", "", part.strip()))  # "mu (Eq. 2.29)" -> "mu"
    return out


@pytest.fixture(scope="module")
def page_text() -> str:
    png = png_data_uri(b"\x89PNG\r\n\x1a\n")
    page = render_reproduction(reproduce(), png, png, png)
    body = page[page.index("<body>") :]
    a, b = body.index("<h2>Symbols and units</h2>"), body.index("<h2>Table 4")
    return html.unescape(re.sub(r"<[^>]+>", " ", body[:a] + body[b:])), page


def _normalise(token: str) -> str | None:
    """The nomenclature entry a token of the page is an instance of (None: not a symbol)."""
    rules = [
        (r"E\d+", None),  # errata ids
        (r"(xz|yz)_(no_)?orbiter|no_orbiter", None),  # case keys
        (r"t2", None),  # the misprint "cos w(t2 - t13)" that the errata corrects
        (r"m\d\d", "m_ij"),
        (r"k\d\d", "k_ij"),
        (r"M_\d\d", "M_jj"),
        (r"phi_\d", "phi_j"),
        (r"w_\d", "w_j"),
        (r"f_a", "f_a(t)"),
    ]
    for pattern, name in rules:
        if re.fullmatch(pattern, token):
            return name
    return token


def test_every_symbol_on_the_page_is_explained(page_text) -> None:
    text, _ = page_text
    tokens = set(
        re.findall(
            r"(?<![\w.])([A-Za-z]{1,5}(?:_[A-Za-z0-9]+)+|\[A\]max|[a-zA-Z]\d{1,2})(?![\w])",
            text,
        )
    )
    assert {"a_e", "I_x", "l_k", "m24", "M_11", "[A]max", "w0"} <= tokens  # the scan works
    defined = _defined()
    missing = sorted(n for t in tokens if (n := _normalise(t)) and n not in defined)
    assert missing == []


def test_the_named_symbols_are_explained() -> None:
    defined = _defined()
    assert [s for s in REQUIRED if s not in defined] == []


def test_nomenclature_is_on_the_page_with_units(page_text) -> None:
    _, page = page_text
    assert "<h2>Symbols and units</h2>" in page
    for s in NOMENCLATURE:
        assert html.escape(s.symbol) in page and s.unit_us and s.unit_si and s.meaning
    assert nomenclature()[0] == NOMENCLATURE[0].to_dict()


_UREG = pint.UnitRegistry()


def _pint_unit(text: str) -> str:
    return {"g": "standard_gravity"}.get(text, text.replace(" ", "*").replace("^", "**"))


@pytest.mark.parametrize("sym", [s for s in NOMENCLATURE if s.si_per_us is not None])
def test_si_factor_is_pints(sym) -> None:
    # reference: pint's definitions (ft = 0.3048 m, lbf = 4.4482216152605 N, slug, g0); for
    # entries that list several units ("ft; ft; ft/s^2") the factor is the first's, which
    # must be the same for all
    units_us = [u.strip() for u in re.split(r"[;,]", sym.unit_us)]
    units_si = [u.strip() for u in re.split(r"[;,]", sym.unit_si)]
    checked = 0
    for us, si in zip(units_us, units_si, strict=True):
        if us == "-":
            continue
        factor = _UREG.Quantity(1.0, _pint_unit(us)).to(_pint_unit(si)).magnitude
        assert factor == pytest.approx(sym.si_per_us, rel=1e-9), (sym.symbol, us)
        checked += 1
    assert checked >= 1
