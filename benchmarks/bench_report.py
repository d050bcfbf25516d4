"""Benchmark: the HTML report's size and its load time in headless Chromium, IOC and large.

Problem: the ``microg analyze`` report (interactive: plotly.js inlined once, the model in 3-D
with a frame per elastic mode, four charts per observed point) of the IOC model (the README's
run: crew push-off, lab observed, 200 s) and of a 20,000-grid x 200-mode modal model
(bench_modal_io.make_model, its ten observed grids, 200 s), where the 3-D view decimates
(above ``microg.plotting.interactive``'s sample and frame limits, said on the page).

Measured: the page's size (bytes); its load time, the wall time of headless Chromium opening it
(``--virtual-time-budget``: the page's own scripts run to completion, timers fast-forwarded)
less that of a blank page in the same rounds (Chromium's start-up), the median of
``--rounds``; and a probe's findings on the page: console errors (must be 0) and plotly figures
drawn of those in the page.  Baseline: the blank page.  No target is set beyond "usable": the
figures are for the closing notes and docs/architecture.md.

Run: .venv/bin/python benchmarks/bench_report.py [--grids N] [--modes M] [--rounds R]
(about 2 minutes at the defaults on the 2-core machine; needs Debian's chromium).
"""

from __future__ import annotations

import argparse
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import microg
from microg.models.modal import save_modal_model
from microg.report.analysis import report_files

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_modal_io import make_model, observed  # noqa: E402

#: put first in <head>: console errors and uncaught errors are counted
CATCHER = """<script>window.__errors = 0; const __e = console.error.bind(console);
console.error = (...a) => { window.__errors += 1; __e(...a); };
window.addEventListener("error", () => { window.__errors += 1; });</script>"""
#: appended: how many plotly figures were drawn, and the error count
PROBE = """<script>window.addEventListener("load", () => {
const divs = Array.from(document.querySelectorAll(".plotly-graph-div"));
const drawn = divs.filter(
  (d) => d.classList.contains("js-plotly-plot") && d.querySelector(".main-svg")).length;
document.body.setAttribute("data-probe", divs.length + " " + drawn + " " + window.__errors);
});</script>"""
_PROBE = re.compile(r'data-probe="(\d+) (\d+) (\d+)"')


def chromium_seconds(chromium: str, page: Path) -> tuple[float, str]:
    """Wall time of headless Chromium loading ``page`` and dumping its DOM, s; and the DOM."""
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        proc = subprocess.run(
            [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
             "--no-first-run", "--disable-background-networking", "--disable-component-update",
             "--disable-sync", f"--user-data-dir={tmp}/profile", "--virtual-time-budget=2000",
             "--dump-dom", page.as_uri()],
            capture_output=True, text=True, timeout=300,
        )  # fmt: skip
        return time.perf_counter() - t0, proc.stdout


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--grids", type=int, default=20000)
    ap.add_argument("--modes", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        sys.exit("bench_report: needs headless Chromium (Debian's package chromium)")
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        npz = save_modal_model(make_model(args.grids, args.modes), d / "large.npz")
        runs = {
            "IOC (README run)": microg.analyze("ioc", observe=["lab"]),
            f"{args.grids:,} grids x {args.modes} modes": microg.analyze(
                microg.load_model(npz),
                force="crew-pushoff",
                at="grid:1",
                observe=observed(args.grids),
                duration=200.0,
                dt=0.01,
            ),
        }
        pages = {"blank": d / "blank.html"}
        pages["blank"].write_text("<!doctype html><html><head></head><body></body></html>")
        sizes = {}
        for name, result in runs.items():
            html = report_files(result)["report.html"]
            sizes[name] = len(html.encode())
            p = d / f"{len(pages)}.html"
            p.write_text(html.replace("<head>", "<head>" + CATCHER, 1) + PROBE)
            pages[name] = p
        times: dict[str, list[float]] = {k: [] for k in pages}
        probes: dict[str, str] = {}
        for _ in range(args.rounds):
            for name, page in pages.items():
                s, dom = chromium_seconds(chromium, page)
                times[name].append(s)
                m = _PROBE.search(dom)
                probes[name] = (
                    "no probe"
                    if m is None
                    else f"{m.group(2)} of {m.group(1)} figures drawn, {m.group(3)} errors"
                )
    blank = statistics.median(times["blank"])
    print(f"headless Chromium, median of {args.rounds}; blank page {blank:.2f} s (start-up)")
    print(f"{'report':32s} {'bytes':>12s} {'load s':>8s}  probe")
    for name in runs:
        load = statistics.median(times[name]) - blank
        print(f"{name:32s} {sizes[name]:12,d} {load:8.2f}  {probes[name]}")


if __name__ == "__main__":
    main()
