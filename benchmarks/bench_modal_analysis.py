"""Benchmark: the fixed cost of a modal-model analysis against reading the model.

Problem: a 20,000-grid x 200-mode modal model (bench_modal_io.make_model: random geometry,
exact rigid modes, orthogonal elastic shapes; microg's own .npz, in the page cache), analysed as
a user calls it: ``microg.analyze(model, force="crew-pushoff", at="grid:1", observe=[10
grids], duration=200 s, dt=0.01 s)`` with the default isolation advice (every observed point
exceeds its bands and no passive mount can be designed, so each of the 10 points gets the
active isolator's design and verification: controller, loop margins, transmissibility, noise
floor, closed-loop time response).

Baseline: reading the file (``microg.load_model``), timed in the same rounds.  Target: the
analysis's fixed cost (the work that does not grow with the grids, chiefly the isolation
advice) at most equal to the read.  Printed: read, analysis, analysis without the isolation
advice, the isolation stage alone, each over the read; the stages of one analysis (``progress``
callback); ``--profile`` adds the costliest functions of one analysis (cProfile on CPU time).

The rounds run in one process, so from the second analysis on, what microg keeps per plant and
controller (the isolator's channel gains and margin checks, closed loops, loop margins,
frequency responses: every observed point of one analysis checks the same controller) is
already there.  ``--cold`` adds the first analysis of a new process, its modules imported but
nothing kept (``--cold-rounds`` processes, the median), beside that process's read.

Timing: CPU time of the process (``time.process_time``; the machine's 2 cores are shared, so
wall time would count other processes), BLAS limited to 1 thread, ``--rounds`` interleaved
rounds (read, analysis, analysis without isolation), the median of each.

Run: .venv/bin/python benchmarks/bench_modal_analysis.py [--grids N] [--modes M] [--rounds R]
[--profile] [--cold]  (about 1 minute at the defaults on the 2-core machine).
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from threadpoolctl import threadpool_limits

import microg
from microg.models.modal import save_modal_model

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_modal_io import DT_S, DURATION_S, make_model, observed  # noqa: E402

CLOCK = time.process_time


def analyse(model: Any, g: int, *, isolation: bool = True) -> dict[str, float]:
    """CPU time of each stage of ``microg.analyze`` and the total (key ``total``), s."""
    stages: dict[str, float] = {}
    state: dict[str, Any] = {"t": 0.0, "stage": None}

    def step(name: str) -> None:
        now = CLOCK()
        if state["stage"] is not None:
            stages[state["stage"]] = now - state["t"]
        state["t"], state["stage"] = now, name

    t0 = CLOCK()
    microg.analyze(
        model,
        force="crew-pushoff",
        at="grid:1",
        observe=observed(g),
        duration=DURATION_S,
        dt=DT_S,
        isolation=isolation,
        progress=step,
    )
    end = CLOCK()
    stages[state["stage"]] = end - state["t"]
    stages["total"] = end - t0
    return stages


COLD = """
import sys, time, json
sys.path.insert(0, {bench!r})
from threadpoolctl import threadpool_limits
import control, scipy.signal, scipy.interpolate  # noqa: F401  (imports, not timed)
import microg
import microg.isolation.active.design, microg.isolation.advise  # noqa: F401
from microg.isolation.active.presets import load_preset
from bench_modal_io import DT_S, DURATION_S, observed
with threadpool_limits(1):
    load_preset("aris")
    t0 = time.process_time(); m = microg.load_model({path!r}); read = time.process_time() - t0
    t0 = time.process_time()
    microg.analyze(m, force="crew-pushoff", at="grid:1", observe=observed({g}),
                   duration=DURATION_S, dt=DT_S)
    print(json.dumps({{"read": read, "analysis": time.process_time() - t0}}))
"""


def cold(path: Path, g: int) -> dict[str, float]:
    """The first analysis (and the read) of a new process: modules imported, nothing kept."""
    import json
    import subprocess

    code = COLD.format(bench=str(Path(__file__).resolve().parent), path=str(path), g=g)
    out = subprocess.run(
        [sys.executable, "-c", code], check=True, capture_output=True, text=True
    ).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--grids", type=int, default=20000)
    ap.add_argument("--modes", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--cold", action="store_true")
    ap.add_argument("--cold-rounds", type=int, default=3)
    a = ap.parse_args()
    model = make_model(a.grids, a.modes)
    print(
        f"model: {a.grids} grids x {a.modes} modes; crew push-off at grid:1, 10 grids observed, "
        f"{DURATION_S:g} s at {DT_S:g} s; CPU time, 1 BLAS thread, median of {a.rounds} "
        f"interleaved rounds"
    )
    with tempfile.TemporaryDirectory() as d, threadpool_limits(1):
        p = Path(d) / "m.npz"
        save_modal_model(model, p)
        back = microg.load_model(p)
        analyse(back, a.grids)  # warm: imports, caches of the first call
        reads, full, bare = [], [], []
        for _ in range(a.rounds):
            t0 = CLOCK()
            back = microg.load_model(p)
            reads.append(CLOCK() - t0)
            full.append(analyse(back, a.grids))
            bare.append(analyse(back, a.grids, isolation=False))
        tr = statistics.median(reads)
        ta = statistics.median(s["total"] for s in full)
        tn = statistics.median(s["total"] for s in bare)
        ti = statistics.median(s.get("isolation", 0.0) for s in full)
        names = [k for k in full[0] if k != "total"]
        print(f"{'':36s} {'CPU s':>8s} {'/ read':>8s}")
        for label, v in (
            ("read (load_model)", tr),
            ("analysis", ta),
            ("analysis without isolation advice", tn),
            ("isolation advice (stage)", ti),
            ("analysis - without (advice's cost)", ta - tn),
        ):
            print(f"{label:36s} {v:8.3f} {v / tr:8.2f}")
        print(
            "stages (median): "
            + ", ".join(f"{k} {statistics.median(s[k] for s in full):.3f}" for k in names)
        )
        if a.cold:
            runs = [cold(p, a.grids) for _ in range(a.cold_rounds)]
            cr = statistics.median(r["read"] for r in runs)
            ca = statistics.median(r["analysis"] for r in runs)
            print(
                f"{'first analysis of a new process':36s} {ca:8.3f} {ca / cr:8.2f}  (its read "
                f"{cr:.3f} s; median of {a.cold_rounds} processes)"
            )
            print(
                f"{'  less the analysis without advice':36s} {ca - tn:8.3f} {(ca - tn) / cr:8.2f}"
            )
        print("(target: the isolation advice, the fixed cost, at most the read: ratio <= 1)")
        if a.profile:
            prof = cProfile.Profile(CLOCK)
            prof.enable()
            analyse(back, a.grids)
            prof.disable()
            buf = io.StringIO()
            pstats.Stats(prof, stream=buf).sort_stats("cumulative").print_stats(35)
            print(buf.getvalue())


if __name__ == "__main__":
    main()
