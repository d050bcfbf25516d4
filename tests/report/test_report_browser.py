"""Every HTML report in headless Chromium: no console error, every image and chart rendered.

Reports of ``analyze``, ``assess``, ``quasi-steady`` and ``locate`` are written once (small
runs), then each is opened as a copy with an error catcher first in its head and a probe last
(the report itself untouched): every ``<img>`` decoded; every plotly figure drawn (its SVG
layer with one drawn trace per 2-D trace; a 3-D scene with its WebGL canvas, in software);
no console error, uncaught error or rejected promise.  On the analyze page the mode slider is
moved as the slider moves it (its own animate arguments) and the shape shown must change.
Numbers do not wrap: every rendered numeric table cell (a ``td`` without class ``l``) holds one
line, its content's height below 1.5 of its line height, in a window narrow enough (900 px)
that long value-and-unit cells would break without the page's ``nowrap`` rule.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

from microg.cli import main

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")

#: put first in <head>: every console.error, uncaught error and rejected promise is collected
CATCHER = """
<script>
window.__errors = [];
const __err = console.error.bind(console);
console.error = (...a) => { window.__errors.push(a.join(" ")); __err(...a); };
window.addEventListener("error", (e) => window.__errors.push(String(e.message)));
window.addEventListener("unhandledrejection", (e) => window.__errors.push(String(e.reason)));
</script>
"""

#: appended: images decoded; each plotly figure drawn; on the analyze page, the mode slider's
#: step 4 applied exactly as the slider applies it, and the deformed shape it shows changed
PROBE = """
<script>
window.addEventListener("load", async () => {
  const imgs = Array.from(document.images);
  const decoded = imgs.filter((im) => im.complete && im.naturalWidth > 0).length;
  const divs = Array.from(document.querySelectorAll(".plotly-graph-div"));
  const bad = [];
  let drawn = 0;
  for (const gd of divs) {
    let ok = false;
    try {
      const full = gd._fullLayout, data = gd._fullData || [];
      const gl3d = full && full._has && full._has("gl3d");
      if (gd.classList.contains("js-plotly-plot") && gd.querySelector(".main-svg") && data.length) {
        if (gl3d) {
          ok = !!gd.querySelector(".gl-container canvas, canvas");
        } else {
          // one drawn group per visible 2-D trace (scatter paths, the heat map's image)
          const shown = data.filter((t) => t.visible === true).length;
          const groups = gd.querySelectorAll(".cartesianlayer .trace, .heatmaplayer .hm").length;
          ok = groups >= shown && shown > 0;
        }
      }
    } catch (e) { window.__errors.push("probe: " + e); }
    if (ok) { drawn += 1; } else { bad.push(gd.id); }
  }
  let changed = -1, title = "";
  const gd = document.getElementById("model3d");
  if (gd && gd.layout.sliders) {
    try {
      const before = JSON.stringify(Array.from(gd._fullData[1].x).slice(0, 30));
      const step = gd.layout.sliders[0].steps[3];
      await Plotly.animate(gd, ...step.args);
      changed = JSON.stringify(Array.from(gd._fullData[1].x).slice(0, 30)) !== before ? 1 : 0;
      title = gd.layout.title.text;
    } catch (e) { window.__errors.push("probe: " + e); }
  }
  // numeric cells: the height of the cell's content (a range over it: its line boxes) against
  // its line height ("normal" is about 1.2 font sizes; two lines are >= 2 line heights)
  let cells = 0;
  const wrapped = [];
  for (const td of document.querySelectorAll("td:not(.l)")) {
    if (!td.textContent.trim()) continue;
    const range = document.createRange();
    range.selectNodeContents(td);
    const box = range.getBoundingClientRect();
    if (box.height === 0) continue;  // not rendered (in a closed <details>)
    const st = getComputedStyle(td);
    const lh = parseFloat(st.lineHeight) || 1.2 * parseFloat(st.fontSize);
    cells += 1;
    if (box.height > 1.5 * lh) wrapped.push(td.textContent.trim().slice(0, 40));
  }
  const b = document.body;
  b.setAttribute("data-images", imgs.length);
  b.setAttribute("data-decoded", decoded);
  b.setAttribute("data-charts", divs.length);
  b.setAttribute("data-drawn", drawn);
  b.setAttribute("data-bad", bad.join(" "));
  b.setAttribute("data-changed", changed);
  b.setAttribute("data-title", title);
  b.setAttribute("data-cells", cells);
  b.setAttribute("data-wrapped", wrapped.length);
  b.setAttribute("data-first-wrapped", (wrapped[0] || "").replace(/"/g, "'"));
  b.setAttribute("data-errors", window.__errors.length);
  b.setAttribute("data-first-error", (window.__errors[0] || "").slice(0, 200));
});
</script>
"""

_ATTRS = re.compile(
    r'data-images="(\d+)" data-decoded="(\d+)" data-charts="(\d+)" data-drawn="(\d+)" '
    r'data-bad="([^"]*)" data-changed="(-?\d)" data-title="([^"]*)" data-cells="(\d+)" '
    r'data-wrapped="(\d+)" data-first-wrapped="([^"]*)" data-errors="(\d+)" '
    r'data-first-error="([^"]*)"'
)

FAST = ["--duration", "40", "--dt", "0.02", "--no-progress"]
#: each command's report (out directory made by the fixture), with the options of a small run
RUNS = {
    "analyze": ["analyze", "--observe", "lab", "--observe", "keel-tip", *FAST],
    "assess": ["assess", str(ROOT / "examples" / "measured.csv")],
    "quasi-steady": ["quasi-steady", "ioc"],
    "locate": ["locate", "ioc"],
}


@pytest.fixture(scope="module")
def reports(tmp_path_factory) -> dict[str, Path]:
    base = tmp_path_factory.mktemp("reports")
    out = {}
    for name, args in RUNS.items():
        assert main([*args, "--out", str(base / name)]) == 0, name
        out[name] = base / name / "report.html"
    return out


def open_in_chromium(html: str) -> dict[str, str]:
    """The probe's findings on a copy of ``html`` opened in headless Chromium."""
    assert CHROMIUM is not None
    with tempfile.TemporaryDirectory() as tmp:
        page = Path(tmp) / "page.html"
        page.write_text(html.replace("<head>", "<head>" + CATCHER, 1) + PROBE)
        proc = subprocess.run(
            [
                CHROMIUM,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--enable-unsafe-swiftshader",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                f"--user-data-dir={tmp}/profile",
                "--virtual-time-budget=8000",
                "--window-size=900,1200",
                "--dump-dom",
                page.as_uri(),
            ],
            capture_output=True,
            text=True,
            timeout=120,
        )
    m = _ATTRS.search(proc.stdout)
    assert m is not None, proc.stderr[-2000:]
    keys = (
        "images", "decoded", "charts", "drawn", "bad", "changed", "title",
        "cells", "wrapped", "first_wrapped", "errors", "first",
    )  # fmt: skip
    return dict(zip(keys, m.groups(), strict=True))


@pytest.mark.browser
@pytest.mark.skipif(
    CHROMIUM is None and not os.environ.get("CI"),
    reason="headless Chromium not installed (.ci/run installs it; in CI its absence fails)",
)
@pytest.mark.parametrize("command", list(RUNS))
def test_report_in_headless_chromium(reports: dict[str, Path], command: str) -> None:
    assert CHROMIUM is not None, "CI must install Debian's chromium (.ci/run does)"
    html = reports[command].read_text()
    assert html.count("plotly.js v") == 1  # plotly.js inlined once: the page works offline
    assert "<script src=" not in html  # nothing fetched: the page is self-contained
    n_png = len(re.findall(r'<img [^>]*src="data:image/png;base64,', html))
    n_div = len(re.findall(r'<div id="[^"]+" class="plotly-graph-div"', html))
    # every PNG written is in the page, as an image or as the charts that stand for it
    archived = set(re.findall(r"Archived as <code>([^<]+)</code>", html))
    pngs = {p.name for p in reports[command].parent.glob("*.png")}
    assert n_png + len(archived) == len(pngs) and archived <= pngs
    want_charts = {"analyze": 1 + 4 * 2, "assess": 9, "quasi-steady": 1, "locate": 1}[command]
    assert n_div == want_charts  # analyze: the model, then 4 charts per observed point
    got = open_in_chromium(html)
    assert got["errors"] == "0", got["first"]
    assert int(got["images"]) == n_png and int(got["decoded"]) == n_png
    assert int(got["charts"]) == n_div and int(got["drawn"]) == n_div, got["bad"]
    # every numeric cell rendered holds one line (R2: no '4.48e-'/'06' or '30.3 micro-'/'g s');
    # 1.5 line heights: one line is 1, a second line makes it >= 2, whatever the font
    n_numeric = len(re.findall(r"<td(?![^>]*\bclass=\"l\b)[ >]", html))  # td without class l
    assert 0 < int(got["cells"]) <= n_numeric  # cells were measured (not a vacuous pass)
    assert got["wrapped"] == "0", got["first_wrapped"]
    if command == "analyze":
        assert got["changed"] == "1"
        assert got["title"].startswith("mode ") and " Hz" in got["title"]  # the frame's title
