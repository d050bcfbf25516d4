"""Benchmark: studies at scale (microg.study) against the per-case path, same run.

1. **10,080 cases on one process** (the shipped IOC model with 38 sample points added by the
   study file: 4 crew activities x 28 application points x 3 directions x 10 observed points x
   3 damping values; 200-s records at 0.01 s, modes to 10 Hz), streamed to a zarr store in a
   temporary directory.  Baseline in the same run: 20 of those cases, each by
   ``microg.analyze`` alone (isolation advice off, one observed point: the cheapest per-case
   call); the ratio is per case.
2. **Memory**: the same study at two sizes (2,520 and 10,080 cases), each in its own
   process: the peak resident set (``resource.getrusage``; it includes the interpreter and
   the imports, ~250 MB).  The store holds the results; the process holds one block.
3. **8 model variants of >= 20,000 DOF** (IOC, 1150 frame elements per beam: 20,736 DOF; the
   orbiter docked at 8 places along the main body): one eigen-solve per variant, the solves
   as Dask tasks, with 1 and with 2 local worker processes (1 thread and 1 BLAS thread each;
   the clusters are started, and their workers have imported microg, before timing).

BLAS is limited to 1 thread everywhere (the sweep's own rule: the same bits on every path).
The machine is shared: the figures carry its load average.

Run:  .venv/bin/python benchmarks/bench_sweep.py            (about 2 minutes)
      .venv/bin/python benchmarks/bench_sweep.py --quick    (part 1 at 2,520 cases)
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ACTIVITIES = ["foot-pushoff-max", "foot-pushoff-mean", "hand-pushoff-max", "hand-pushoff-mean"]
N_AT, N_OBS = 28, 10
DAMPING = [0.002, 0.005, 0.01]
N_VARIANT_ELEMENTS = 1150


def study_text(n_at: int = N_AT, n_obs: int = N_OBS, damping: list[float] | None = None) -> str:
    """The study: sample points along the keel and booms (at) and on every component (observe)."""
    damping = damping or DAMPING
    pts, at, obs = [], [], []
    for i in range(n_at):
        beam = ("keel", "boom+y", "boom-y")[i % 3]
        length = 296.0 if beam == "keel" else 132.0
        s = length * (i // 3 + 1) / (n_at // 3 + 2)
        pts.append(f'[[point]]\nname = "a{i}"\non = "{beam}"\ns = "{s:.3f} ft"\n')
        at.append(f"a{i}")
    for i in range(n_obs):
        where = ("keel", "boom+y", "boom-y", "main")[i % 4]
        if where == "main":
            z = -10.0 - 8.0 * i
            pts.append(f'[[point]]\nname = "o{i}"\non = "main"\nat = ["0 ft", "0 ft", "{z} ft"]\n')
        else:
            length = 296.0 if where == "keel" else 132.0
            s = length * (i // 4 + 1.5) / (n_obs // 4 + 3)
            pts.append(f'[[point]]\nname = "o{i}"\non = "{where}"\ns = "{s:.3f} ft"\n')
        obs.append(f"o{i}")
    return (
        f'[study]\nname = "bench"\nmodel = "ioc"\n[axes]\nforce = {json.dumps(ACTIVITIES)}\n'
        f'at = {json.dumps(at)}\ndirection = ["x", "y", "z"]\nobserve = {json.dumps(obs)}\n'
        f"damping = {json.dumps(damping)}\n\n" + "\n".join(pts)
    )


def variants_text(n_variants: int = 8) -> str:
    """8 positions of the docked orbiter on the IOC main body, a 20,022-DOF frame model."""
    zs = [-126.66 + 12.0 * k for k in range(n_variants)]
    var = ",\n  ".join(
        f'{{ name = "z{k}", move = "main/Orbiter", to = ["0 ft", "0 ft", "{z:.2f} ft"] }}'
        for k, z in enumerate(zs)
    )
    return f"""[study]
name = "variants"
model = "ioc"
n = {N_VARIANT_ELEMENTS}
[axes]
force = ["foot-pushoff-max", "hand-pushoff-mean"]
at = ["crew", "vertical-lab"]
direction = ["x", "y", "z"]
observe = ["lab", "keel-tip", "boom-tip"]
damping = [0.005]
variant = [
  {var},
]
"""


def _load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


# ------------------------------------------------------------------------------ children


def child(n_at: int) -> None:
    """One sweep of the study at a size, in this process: print time and memory as JSON."""
    import resource

    from threadpoolctl import threadpool_limits

    from microg.study import loads_study, sweep

    with threadpool_limits(1, user_api="blas"):
        study = loads_study(study_text(n_at=n_at), filename="bench.toml")
        with tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            r = sweep(study, Path(d) / "out")
            elapsed = time.perf_counter() - t0
            cases = r.summary().cases
    rss_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(json.dumps({"cases": cases, "seconds": elapsed, "rss_mb": rss_kb / 1024}))


def run_child(n_at: int) -> dict[str, Any]:
    out = subprocess.run(
        [sys.executable, __file__, "--child", str(n_at)],
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


# ------------------------------------------------------------------------------ parts


def per_case_baseline(n: int = 20) -> float:
    """Seconds per case of microg.analyze on cases of the study, one at a time."""
    from threadpoolctl import threadpool_limits

    import microg
    from microg.study import loads_study

    study = loads_study(study_text(), filename="bench.toml")
    model = study.models[0].model
    t0 = time.perf_counter()
    with threadpool_limits(1, user_api="blas"):
        for k in range(n):
            microg.analyze(
                model,
                force=ACTIVITIES[k % 4],
                at=study.at[(7 * k) % len(study.at)],
                direction="xyz"[k % 3],
                observe=[study.observe[(3 * k) % len(study.observe)]],
                damping=DAMPING[k % 3],
                isolation=False,
            )
    return (time.perf_counter() - t0) / n


def variants_part() -> tuple[dict[int, float], int, int]:
    import logging

    from distributed import LocalCluster

    from microg.study import loads_study, sweep

    study = loads_study(variants_text(), filename="variants.toml")
    warm = loads_study('[study]\nmodel = "ioc"\n[record]\nduration = "20 s"\n', filename="w")
    times: dict[int, float] = {}
    dof = 0
    options = {"threads_per_worker": 1, "processes": True, "dashboard_address": None}
    for n in (1, 2):
        with LocalCluster(n_workers=n, silence_logs=logging.ERROR, **options) as cluster:
            sweep(warm, scheduler=cluster.scheduler_address)  # the workers import microg
            t0 = time.perf_counter()
            r = sweep(study, scheduler=cluster.scheduler_address)
            times[n] = time.perf_counter() - t0
            dof = next(iter(r.bases.values()))["n_dof"]
    return times, dof, study.n_cases


def main() -> None:
    quick = "--quick" in sys.argv
    print(f"microg sweep benchmark ({_load()})")
    print("\n1. one process, streamed to zarr")
    full = run_child(7 if quick else N_AT)
    per_case = per_case_baseline()
    sweep_case = full["seconds"] / full["cases"]
    print(f"   sweep: {full['cases']:,} cases in {full['seconds']:.1f} s "
          f"({1e3 * sweep_case:.2f} ms per case)")  # fmt: skip
    print(f"   microg.analyze, 20 cases one at a time: {1e3 * per_case:.0f} ms per case")
    print(f"   ratio per case: {per_case / sweep_case:.0f}x")
    print("\n2. memory (each size in its own process)")
    small = run_child(7) if not quick else full
    for r in (small, full) if not quick else (full,):
        print(f"   {r['cases']:>6,} cases: peak RSS {r['rss_mb']:.0f} MB ({r['seconds']:.1f} s)")
    if not quick:
        print(f"   4x the cases: peak RSS x{full['rss_mb'] / small['rss_mb']:.2f}")
    print(f"\n3. 8 model variants, one eigen-solve each, on local Dask workers ({_load()})")
    times, dof, cases = variants_part()
    print(f"   {dof:,} DOF per variant, {cases} cases")
    for n, t in times.items():
        print(f"   {n} worker{'s' if n > 1 else ''}: {t:.1f} s")
    print(f"   speed-up on 2 workers: {times[1] / times[2]:.2f}x")


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--child":
        child(int(sys.argv[2]))
    else:
        main()
