"""Benchmark: studies at scale (microg.study) against one process and their arithmetic, same run.

1. **Scaling, one process** (the shipped IOC model with sample points added by the study
   file: 4 crew activities x N_AT application points x 3 directions x 10 observed points x 3
   damping values, 200-s records at 0.01 s, modes to 10 Hz), streamed to a zarr store in a
   temporary directory, at 2,520, 5,040 and 10,080 cases (N_AT = 7, 14, 28).  Baseline in the
   same run, interleaved: the **arithmetic lower bound**, a minimal numpy doing exactly the
   per-case work of the kernel on arrays of the same shapes (each case's record ``c @ h``
   over 20,001 samples for its sampled peaks, ``|r c|^2`` for the RMS, ``|R_b c|^2`` over the
   bands for the band RMS, the verdict), without the per-group work (modal responses, their
   spectra, band factors), the store or the modal solve.  Printed: medians, the ratio, the
   growth exponent between sizes (d log t / d log n) and the marginal cost per case.
2. **Memory**: 2,520 and 10,080 cases, each in its own process: the peak resident set
   (``resource.getrusage``, which includes the interpreter and the imports).
3. **Dask** (``--dask``): the 10,080-case study on local clusters of 1 and 2 worker processes
   (1 thread, 1 BLAS thread each; each started in its round, and the study run on it once
   untimed), with microg's worker settings (:data:`microg.study.run.WORKER_ENVIRON`) and with
   distributed's own (``MALLOC_TRIM_THRESHOLD_=65536``); each row's ratio to one process
   timed in the same round (only the cluster being timed alive: a local cluster's scheduler
   runs in this process, and idle ones slowed the one-process row), and each worker's peak
   resident set.  Wall-clock times (the work is in the workers).

Timing: CPU time of this process (``time.process_time``) for parts 1-2 and wall-clock for
part 3, interleaved rounds, medians of ``--rounds`` (default 5).  BLAS is limited to 1 thread
everywhere (the sweep's own rule: the same bits on every path).  The machine may be shared:
the figures carry its load average.

Run:  .venv/bin/python benchmarks/bench_sweep.py                (parts 1-2, ~3 minutes)
      .venv/bin/python benchmarks/bench_sweep.py --dask         (and part 3)
      .venv/bin/python benchmarks/bench_sweep.py --quick        (2,520 and 5,040, 3 rounds)
      .venv/bin/python benchmarks/bench_sweep.py --variants     (8 model variants on Dask)
"""

from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

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


def _arg(name: str, default: int) -> int:
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


# ------------------------------------------------------------------------------ children


def child(n_at: int) -> None:
    """One sweep of the study at a size, in this process: print time and memory as JSON."""
    import resource

    from threadpoolctl import threadpool_limits

    from microg.study import loads_study, sweep

    with threadpool_limits(1, user_api="blas"):
        study = loads_study(study_text(n_at=n_at), filename="bench.toml")
        with tempfile.TemporaryDirectory() as d:
            t0 = time.process_time()
            r = sweep(study, Path(d) / "out")
            elapsed = time.process_time() - t0
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


# ------------------------------------------------------------------------ lower bound


def group_arrays() -> dict[str, np.ndarray]:
    """The arrays a case's work reads: one modal group of the study (h, r, R_b) and its shapes."""
    from microg.study import loads_study
    from microg.study.kernel import kernel_plan, modal_group, solve_basis
    from microg.study.run import _solve_args

    s = loads_study(study_text(n_at=1), filename="bench.toml")
    model, kw = _solve_args(s, 0, 0)
    g = modal_group(solve_basis(model, **kw), kernel_plan(s), 0, 0, 0)
    return {"h": g.h, "gram_r": g.gram_r, "band_r": g.band_r, "limit": g.limit_g}


def lower_bound(arrays: dict[str, np.ndarray], n: int, seed: int = 0) -> float:
    """CPU seconds of the minimal numpy for ``n`` cases' own work (see the module docstring)."""
    h, gram_r, band_r, limit = arrays["h"], arrays["gram_r"], arrays["band_r"], arrays["limit"]
    m, nt = h.shape
    nb = band_r.shape[0]
    c = np.random.default_rng(seed).standard_normal((n, 3, m)) * 1e-4
    rt = band_r.reshape(nb * m, m).T
    t0 = time.process_time()
    step = 64  # cases per product: a (192, 20,001) record block, 31 MB
    peak = np.empty(n)
    peak_ax = np.empty((n, 3))
    rms = np.empty((n, 3))
    band = np.empty((n, 3, nb))
    for c0 in range(0, n, step):
        cc = c[c0 : c0 + step]
        k = cc.shape[0]
        a = cc.reshape(3 * k, m) @ h  # the records
        a *= a
        a3 = a.reshape(k, 3, nt)
        peak[c0 : c0 + k] = np.sqrt((a3[:, 0] + a3[:, 1] + a3[:, 2]).max(axis=1))
        peak_ax[c0 : c0 + k] = np.sqrt(a3.max(axis=2))
        y = cc @ gram_r.T
        rms[c0 : c0 + k] = np.sqrt(np.einsum("kaj,kaj->ka", y, y) / nt)
        yb = (cc.reshape(3 * k, m) @ rt).reshape(3 * k, nb, m)
        band[c0 : c0 + k] = np.sqrt(np.einsum("abj,abj->ab", yb, yb)).reshape(k, 3, nb)
    _ = np.all(band <= limit, axis=(1, 2))  # the verdict
    return time.process_time() - t0


def sweep_cpu(n_at: int) -> tuple[int, float, float]:
    """(cases, CPU seconds of the sweep into a temporary zarr store, of its summary)."""
    from microg.study import loads_study, sweep

    study = loads_study(study_text(n_at=n_at), filename="bench.toml")
    with tempfile.TemporaryDirectory() as d:
        t0 = time.process_time()
        r = sweep(study, Path(d) / "out")
        t1 = time.process_time()
        s = r.summary()
        t2 = time.process_time()
    return s.cases, t1 - t0, t2 - t1


def scaling_part(sizes: list[int], rounds: int) -> None:
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1, user_api="blas"):
        arrays = group_arrays()
        sweep_cpu(1)  # imports and caches warmed
        runs: dict[int, dict[str, list[float]]] = {
            n: {"sweep": [], "summary": [], "bound": []} for n in sizes
        }
        cases: dict[int, int] = {}
        for _ in range(rounds):
            for n_at in sizes:
                n, t_sweep, t_sum = sweep_cpu(n_at)
                cases[n_at] = n
                runs[n_at]["sweep"].append(t_sweep)
                runs[n_at]["summary"].append(t_sum)
                runs[n_at]["bound"].append(lower_bound(arrays, n))
    m, nt = arrays["h"].shape
    nb = arrays["band_r"].shape[0]
    flop = 2 * 3 * m * nt + 2 * 3 * m * m + 2 * 3 * m * nb * m
    print(f"   per case: {m} modal rows x {nt:,} samples, {nb} bands: "
          f"{flop / 1e6:.2f} MFlop (records, RMS, bands)")  # fmt: skip
    print("   cases    sweep s  (summary s)  bound s   ratio   ms/case sweep  bound")
    med = {k: {q: statistics.median(v) for q, v in r.items()} for k, r in runs.items()}
    for n_at in sizes:
        n, r = cases[n_at], med[n_at]
        print(f"   {n:>6,}  {r['sweep']:8.2f}  ({r['summary']:6.2f})    {r['bound']:6.2f}  "
              f"{r['sweep'] / r['bound']:6.2f}x   {1e3 * r['sweep'] / n:8.3f}  "
              f"{1e3 * r['bound'] / n:6.3f}")  # fmt: skip
    for a, b in zip(sizes, sizes[1:], strict=False):
        na, nb_ = cases[a], cases[b]
        ex = [math.log(med[b][q] / med[a][q]) / math.log(nb_ / na) for q in ("sweep", "bound")]
        marg = (med[b]["sweep"] - med[a]["sweep"]) / (nb_ - na)
        margb = (med[b]["bound"] - med[a]["bound"]) / (nb_ - na)
        print(f"   {na:,} -> {nb_:,}: growth exponent sweep {ex[0]:.2f}, bound {ex[1]:.2f}; "
              f"marginal cost per case {1e3 * marg:.3f} ms vs {1e3 * margb:.3f} ms "
              f"({marg / margb:.2f}x)")  # fmt: skip


# ------------------------------------------------------------------------------ Dask


def _cluster(n: int, microg_env: bool) -> Any:
    import logging

    import dask
    from distributed import LocalCluster

    from microg.study.run import _local_environ, worker_environ

    base = {"MALLOC_TRIM_THRESHOLD_": 65536, "OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1,
            "OPENBLAS_NUM_THREADS": 1}  # fmt: skip  (distributed's own default)
    env = worker_environ(base) if microg_env else {k: str(v) for k, v in base.items()}
    with dask.config.set({"distributed.nanny.pre-spawn-environ": env}), _local_environ(env):
        return LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                            dashboard_address=":0", silence_logs=logging.ERROR)  # fmt: skip


def dask_part(n_at: int, rounds: int) -> None:
    from distributed import Client
    from threadpoolctl import threadpool_limits

    from microg.study import loads_study, sweep

    study = loads_study(study_text(n_at=n_at), filename="bench.toml")
    configs = [(1, True), (2, True), (1, False), (2, False)]
    times: dict[Any, list[float]] = {k: [] for k in (*configs, "one")}
    rss: dict[Any, list[float]] = {}

    def peak_mb() -> float:
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    # only the cluster being timed is alive: a local cluster's scheduler and client run in
    # this process (event-loop threads), and idle ones would slow whatever else runs here
    for _ in range(rounds):
        with threadpool_limits(1, user_api="blas"), tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            sweep(study, Path(d) / "one")
            times["one"].append(time.perf_counter() - t0)
        for k in configs:
            cluster = _cluster(*k)
            client = Client(cluster)
            try:
                with tempfile.TemporaryDirectory() as d:  # the workers' first sweep: untimed
                    sweep(study, Path(d) / "warm", scheduler=cluster.scheduler_address)
                with tempfile.TemporaryDirectory() as d:
                    t0 = time.perf_counter()
                    sweep(study, Path(d) / "out", scheduler=cluster.scheduler_address)
                    times[k].append(time.perf_counter() - t0)
                rss[k] = list(client.run(peak_mb).values())
            finally:
                client.close()
                cluster.close()
    one = statistics.median(times["one"])
    print(f"   {study.n_cases:,} cases; one process: {one:.2f} s (median of {rounds})")
    for k in configs:
        t = statistics.median(times[k])
        n, mine = k
        which = "microg's worker settings" if mine else "distributed's MALLOC_TRIM_THRESHOLD_=65536"
        mem = ", ".join(f"{x:.0f}" for x in rss[k])
        print(f"   {n} worker{'s' if n > 1 else ' '} ({which}): {t:.2f} s, {t / one:.2f}x one "
              f"process (speed-up {one / t:.2f}); peak RSS per worker {mem} MB")  # fmt: skip


def variants_part() -> tuple[dict[int, float], int, int]:
    import logging

    from distributed import LocalCluster

    from microg.study import loads_study, sweep

    study = loads_study(variants_text(), filename="variants.toml")
    warm = loads_study('[study]\nmodel = "ioc"\n[record]\nduration = "20 s"\n', filename="w")
    times: dict[int, float] = {}
    dof = 0
    t0 = time.perf_counter()
    sweep(study)
    times[0] = time.perf_counter() - t0
    options = {"threads_per_worker": 1, "processes": True, "dashboard_address": ":0"}
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
    rounds = _arg("--rounds", 3 if quick else 5)
    sizes = [7, 14] if quick else [7, 14, 28]
    print(f"microg sweep benchmark ({_load()})")
    print(f"\n1. one process against the arithmetic lower bound (CPU time, median of {rounds} "
          "interleaved rounds)")  # fmt: skip
    scaling_part(sizes, rounds)
    print(f"   ({_load()})")
    print("\n2. memory (each size in its own process)")
    rows = [run_child(n) for n in (sizes[0], sizes[-1])]
    for r in rows:
        print(f"   {r['cases']:>6,} cases: peak RSS {r['rss_mb']:.0f} MB "
              f"({r['seconds']:.1f} s CPU)")  # fmt: skip
    print(f"   {rows[1]['cases'] / rows[0]['cases']:.0f}x the cases: peak RSS "
          f"x{rows[1]['rss_mb'] / rows[0]['rss_mb']:.2f}")  # fmt: skip
    if "--dask" in sys.argv:
        print(f"\n3. Dask, local worker processes (wall-clock, median of {rounds}; {_load()})")
        dask_part(sizes[-1], rounds)
        print(f"   ({_load()})")
    if "--variants" in sys.argv:
        print(f"\n4. 8 model variants, one eigen-solve each ({_load()})")
        times, dof, cases = variants_part()
        print(f"   {dof:,} DOF per variant, {cases} cases; one process {times[0]:.1f} s")
        for n in (1, 2):
            print(f"   {n} worker{'s' if n > 1 else ''}: {times[n]:.1f} s "
                  f"({times[n] / times[0]:.2f}x one process)")  # fmt: skip


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--child":
        child(int(sys.argv[2]))
    else:
        main()
