"""HTML pages of ``microg assess`` and ``microg quasi-steady``: every verdict line follows from
the fields beside it, and every band row and named point is on the page."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from microg.cli import main
from microg.report.environment import criterion_verdict

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    ("criterion", "verdict", "css"),
    [
        ({"status": "judged", "complies": True, "margin": 5.6}, "complies (margin 5.6)", "pass"),
        ({"status": "judged", "complies": False, "margin": 0.4}, "fails (margin 0.4)", "fail"),
        (
            {"status": "reported", "complies": False, "margin": 0.33},
            "reported only: exceeds its limit (margin 0.33)",
            "warn",
        ),
        (
            {"status": "reported", "complies": True, "margin": "inf"},
            "reported only: within its limit",
            "",
        ),
        ({"status": "undecided", "complies": None, "margin": None}, "undecided", "undecided"),
    ],
)
def test_each_criterion_verdict_follows_its_fields(criterion, verdict, css):
    # "complies" or "fails" only for a judged criterion, by its own complies field
    assert criterion_verdict(criterion) == (verdict, css)


def test_assess_writes_a_report_with_every_band(tmp_path: Path) -> None:
    out = tmp_path / "a"
    assert main(["assess", str(ROOT / "examples" / "measured.csv"), "--out", str(out)]) == 0
    html = (out / "report.html").read_text()
    d = json.loads((out / "results.json").read_text())
    ((key, obs),) = d["observations"].items()
    to = obs["third_octave"]
    rows = re.findall(r'<tr class="(unjudged|fail|)">\s*<td>', html)
    assert len(rows) == len(to["center_hz"])
    # a band the record does not resolve is marked on its row, whatever its value
    assert [r == "unjudged" for r in rows] == [not r for r in to["resolved"]]
    assert key in html
    for c in obs["criteria"]:
        row = html.split(f'<td class="l">{c["name"]}</td>', 1)[1].split("</tr>", 1)[0]
        assert criterion_verdict(c)[0] in row and c["why"] in row
    assert ("Verdict: complies" in html) == obs["complies"]
    # every PNG written is on the page: as an image, or as the interactive chart standing for it
    n_img = len(re.findall(r'<img [^>]*src="data:image/png;base64,', html))
    archived = set(re.findall(r"Archived as <code>([^<]+)</code>", html))
    pngs = {p.name for p in out.glob("*.png")}
    assert n_img + len(archived) == len(pngs) and archived <= pngs


def test_static_pages_have_pngs_only(tmp_path: Path) -> None:
    # --static: every figure a PNG, no chart, no plotly.js (about 4.8 MB less)
    runs = {
        "assess": ["assess", str(ROOT / "examples" / "measured.csv")],
        "quasi-steady": ["quasi-steady", "ioc"],
        "locate": ["locate", "ioc"],
    }
    for name, args in runs.items():
        out = tmp_path / name
        assert main([*args, "--out", str(out), "--static"]) == 0
        html = (out / "report.html").read_text()
        assert "plotly" not in html.lower(), name
        n_img = len(re.findall(r'<img [^>]*src="data:image/png;base64,', html))
        assert n_img == len(list(out.glob("*.png"))) >= 1, name


def test_quasi_steady_writes_a_report_with_every_point(tmp_path: Path) -> None:
    out = tmp_path / "q"
    assert main(["quasi-steady", "ioc", "--out", str(out)]) == 0
    html = (out / "report.html").read_text()
    d = json.loads((out / "quasi-steady.json").read_text())
    for name, p in d["points"].items():
        row = html.split(f'<td class="l">{name}</td>', 1)[1].split("</tr>", 1)[0]
        assert f"{p['magnitude_g'] * 1e6:.3g}" in row
        word = {True: "complies", False: "fails", None: "undecided"}[p["complies"]]
        assert word in row
