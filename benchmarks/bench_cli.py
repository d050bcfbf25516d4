"""Benchmark: the main job's commands as a user runs them, against ``python -c "import numpy"``.

Each command is run as a fresh subprocess, ``--runs`` times
(default 5), round-robin with the baseline so that a machine loaded by other work slows them
alike; the median wall time of each is printed, with its ratio to the baseline's median:

* baseline ``python -c "import numpy"`` (the least any numpy program pays to start);
* ``import microg`` (target: at most 2x, and neither matplotlib, scipy.signal nor pint loaded);
* ``microg modes ioc --json`` (target: at most 4x);
* ``microg analyze --json`` on the default IOC model, writing its report (report.html, the
  PNG figures and results.json) into a temporary ``--out`` as it always does (target: at most
  8x).

The medians of the children's CPU time (user + system) are printed beside the wall times:
on a loaded machine they move less than the wall clock.

Then a per-stage profile of ``microg analyze`` (median over ``--profile-runs`` fresh
processes, each doing what the command does, stage by stage): imports (what the command loads
before it computes), model load, structure, modes, response, assessment, exact peaks,
isolation, figures (build and save), HTML, write; each stage lists the heavy libraries it
loads first.  The stage times add up to the in-process total; the command's own wall time
adds the interpreter start.  Each profiled process starts as the ``microg`` process does
(:func:`microg.cli.one_blas_thread`: BLAS on one thread unless the environment sets a count).

Run:  .venv/bin/python benchmarks/bench_cli.py            (about 40 s on the 2-core machine)
      .venv/bin/python benchmarks/bench_cli.py --figures  (also the time of each figure)
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

#: heavy libraries whose first import a stage is charged with (listed in the profile)
WATCH = (
    "numpy",
    "scipy.linalg",
    "scipy.sparse",
    "scipy.signal",
    "scipy.optimize",
    "scipy.integrate",
    "scipy.special",
    "pint",
    "pydantic",
    "matplotlib",
    "PIL",
    "jinja2",
    "tqdm",
    "threadpoolctl",
    "pandas",
    "xarray",
    "numba",
)

#: ratio targets of the main job's speed
TARGETS = {"import microg": 2.0, "microg modes ioc --json": 4.0, "microg analyze --json": 8.0}

#: libraries ``import microg`` must not load
FORBIDDEN = ("matplotlib", "scipy.signal", "pint")

STAGES = (
    "imports",
    "model load",
    "structure",
    "modes",
    "response",
    "assessment",
    "exact peaks",
    "isolation",
    "figures",
    "HTML",
    "write",
)


def child_env() -> dict[str, str]:
    """The environment of every timed process: byte-compiled modules, as installed.

    A development shell may set ``PYTHONDONTWRITEBYTECODE``, so that modules whose source
    changed are compiled again in every process (0.1-0.2 s for a large one), which an
    installed package never does.  The children write and read their bytecode under one
    cache directory of their own (``PYTHONPYCACHEPREFIX``), the baseline's as well; the
    untimed first round fills it.
    """
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPYCACHEPREFIX"] = str(Path(tempfile.gettempdir()) / "microg-bench-pycache")
    return env


def _microg_command() -> list[str]:
    """The installed ``microg`` script beside this interpreter, else ``python -m microg``."""
    script = Path(sys.executable).with_name("microg")
    return [str(script)] if script.exists() else [sys.executable, "-m", "microg"]


def _run(argv: list[str], env: dict[str, str]) -> tuple[float, float, bytes]:
    """Wall time (s), children's CPU time (s) and stdout of one subprocess; fails loudly."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, env=env, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if proc.returncode != 0:
        raise SystemExit(
            f"{' '.join(argv)} failed ({proc.returncode}):\n{proc.stderr.decode(errors='replace')}"
        )
    return wall, cpu, proc.stdout


def timings(runs: int, tmp: Path) -> dict[str, dict[str, float]]:
    """Median wall and CPU time of each command over ``runs`` round-robin runs."""
    py = sys.executable
    mg = _microg_command()
    env = child_env()
    analyze = "microg analyze --json"
    cases: dict[str, list[str]] = {
        "python -c 'import numpy'": [py, "-c", "import numpy"],
        "import microg": [py, "-c", "import microg"],
        "microg modes ioc --json": [*mg, "modes", "ioc", "--json"],
        analyze: [*mg, "analyze"],
    }
    walls: dict[str, list[float]] = {k: [] for k in cases}
    cpus: dict[str, list[float]] = {k: [] for k in cases}

    def argv_of(name: str, out: Path) -> list[str]:
        argv = cases[name]
        if name == analyze:  # a fresh --out per run
            argv = [*argv, "--json", "--no-progress", "--out", str(out)]
        return argv

    # one untimed round: byte-compiled files and the page cache as a user's second run has them
    for name in cases:
        _run(argv_of(name, tmp / "warm"), env)
    for r in range(runs):
        for k, name in enumerate(cases):
            out = tmp / f"run{r}-{k}"
            wall, cpu, stdout = _run(argv_of(name, out), env)
            if name == analyze:
                data = json.loads(stdout)
                assert "observations" in data, "analyze --json printed no observations"
                assert (out / "report.html").is_file(), "no report.html written"
            walls[name].append(wall)
            cpus[name].append(cpu)
    return {
        k: {"wall": statistics.median(walls[k]), "cpu": statistics.median(cpus[k])} for k in cases
    }


def forbidden_imports() -> list[str]:
    """The libraries of :data:`FORBIDDEN` that ``import microg`` loads (should be none)."""
    code = f"import sys, microg; print(' '.join(m for m in {FORBIDDEN!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, check=True).stdout
    return out.decode().split()


# ------------------------------------------------------------------------- stage profile


def _profile_child(out_dir: str, per_figure: bool) -> dict[str, Any]:
    """One in-process run of what ``microg analyze --json`` does, timed stage by stage."""
    stamps: list[tuple[str, float, float, set[str]]] = []

    def mark(stage: str) -> None:
        stamps.append((stage, time.perf_counter(), time.process_time(), set(sys.modules)))

    t0, c0 = time.perf_counter(), time.process_time()
    mods0 = set(sys.modules)

    import microg.cli

    microg.cli.one_blas_thread()  # what the microg process does first
    import microg
    import microg.cli.analyze as cli_analyze

    mark("model load")
    import microg.dynamics.superposition as sp
    import microg.report.analysis as rep

    extra: dict[str, float] = {"exact peaks": 0.0, "exact peaks cpu": 0.0}
    figure_times: dict[str, float] = {}

    def timed(fn: Any) -> Any:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            t, c = time.perf_counter(), time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                extra["exact peaks"] += time.perf_counter() - t
                extra["exact peaks cpu"] += time.process_time() - c

        return wrapper

    sp.certified_peaks = timed(sp.certified_peaks)  # type: ignore[attr-defined]

    def staged(name: str, fn: Any) -> Any:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            mark(name)
            try:
                return fn(*args, **kwargs)
            finally:
                mark("write")

        return wrapper

    def builders_timed(fn: Any) -> Any:
        def wrapper(result: Any) -> Any:
            def clock(name: str, build: Any) -> Any:
                def draw() -> Any:
                    t = time.perf_counter()
                    try:
                        return build()
                    finally:
                        figure_times[name] = time.perf_counter() - t

                return draw

            return {name: clock(name, b) for name, b in fn(result).items()}

        return wrapper

    # report_files: figures() (build and save) and render_analysis() are the two stages
    rep.figures = staged("figures", rep.figures)  # type: ignore[assignment]
    rep.render_analysis = staged("HTML", rep.render_analysis)  # type: ignore[assignment]
    if per_figure:
        rep.figure_builders = builders_timed(rep.figure_builders)  # type: ignore[assignment]

    result = microg.analyze(progress=mark, command="microg analyze --json")
    mark("write")
    cli_analyze.write_outputs(result, Path(out_dir))  # + the JSON --json prints
    mark("end")

    # stage durations from consecutive stamps; "write" collects the time outside figures/HTML
    wall: dict[str, float] = {s: 0.0 for s in STAGES}
    cpu: dict[str, float] = {s: 0.0 for s in STAGES}
    loaded: dict[str, list[str]] = {s: [] for s in STAGES}
    wall["imports"] = stamps[0][1] - t0
    cpu["imports"] = stamps[0][2] - c0
    loaded["imports"] = [m for m in WATCH if m in stamps[0][3] - mods0]
    for (stage, t, c, mods), (_, t_next, c_next, mods_next) in zip(
        stamps[:-1], stamps[1:], strict=True
    ):
        key = stage if stage in wall else "write"
        wall[key] += t_next - t
        cpu[key] += c_next - c
        loaded[key] += [m for m in WATCH if m in mods_next - mods]
    wall["assessment"] -= extra["exact peaks"]
    wall["exact peaks"] = extra["exact peaks"]
    cpu["assessment"] -= extra["exact peaks cpu"]
    cpu["exact peaks"] = extra["exact peaks cpu"]
    return {
        "wall": wall,
        "cpu": cpu,
        "total": stamps[-1][1] - t0,
        "total cpu": stamps[-1][2] - c0,
        "loaded": loaded,
        "figures": figure_times,
        "threads": _blas_threads(),
    }


def _blas_threads() -> str:
    try:
        from threadpoolctl import threadpool_info
    except ImportError:
        return "unknown"
    return ", ".join(f"{i['internal_api']} {i['num_threads']}" for i in threadpool_info()) or "-"


def profile(runs: int, tmp: Path, per_figure: bool) -> list[dict[str, Any]]:
    """The stage profile of ``runs`` fresh processes."""
    out = []
    for r in range(runs):
        argv = [
            sys.executable,
            __file__,
            "--child",
            str(tmp / f"profile{r}"),
            *(["--figures"] if per_figure else []),
        ]
        proc = subprocess.run(argv, capture_output=True, env=child_env(), check=False)
        if proc.returncode != 0:
            raise SystemExit(f"profile run failed:\n{proc.stderr.decode(errors='replace')}")
        out.append(json.loads(proc.stdout))
    return out


def _median_of(rows: list[dict[str, Any]], key: str, sub: str | None = None) -> float:
    vals = [r[key][sub] if sub is not None else r[key] for r in rows]
    return statistics.median(vals)


def main() -> None:
    """Run the benchmark and print the table and the profile."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--runs", type=int, default=5, help="runs of each command (median)")
    ap.add_argument("--profile-runs", type=int, default=3, help="fresh processes profiled")
    ap.add_argument("--figures", action="store_true", help="also time each figure (in-process)")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        print(json.dumps(_profile_child(args.child, args.figures)))
        return

    tmp = Path(tempfile.mkdtemp(prefix="bench_cli-"))
    try:
        print(
            f"python {sys.version.split()[0]}, {os.cpu_count()} CPUs, load average "
            f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}"
        )
        res = timings(args.runs, tmp)
        base = res["python -c 'import numpy'"]
        print(f"\nmedian of {args.runs} fresh processes (round-robin with the baseline)")
        print(
            f"{'command':<40} {'wall [s]':>9} {'ratio':>7} {'target':>7} {'cpu [s]':>8}"
            f" {'cpu ratio':>9}"
        )
        for name, t in res.items():
            target = TARGETS.get(name, TARGETS.get(name.split(" (")[0]))
            ratio = t["wall"] / base["wall"]
            flag = "" if target is None else ("  ok" if ratio <= target else "  OVER")
            print(
                f"{name:<40} {t['wall']:>9.3f} {ratio:>6.2f}x "
                f"{'' if target is None else f'{target:.0f}x':>7} {t['cpu']:>8.3f} "
                f"{t['cpu'] / base['cpu']:>8.2f}x{flag}"
            )
        bad = forbidden_imports()
        listed = ", ".join(bad) if bad else "none of " + ", ".join(FORBIDDEN)
        print(f"import microg loads {listed}")

        serial = profile(args.profile_runs, tmp, args.figures)
        print(
            f"\nmicrog analyze, stage by stage (median of {len(serial)} fresh processes; "
            f"BLAS: {serial[0]['threads']})"
        )
        print(f"  {'stage':<12} {'wall [s]':>9} {'cpu [s]':>8}   (first loaded in the stage)")
        for stage in STAGES:
            libs = sorted({m for r in serial for m in r["loaded"][stage]})
            note = f"   {', '.join(libs)}" if libs else ""
            print(
                f"  {stage:<12} {_median_of(serial, 'wall', stage):>9.3f} "
                f"{_median_of(serial, 'cpu', stage):>8.3f}{note}"
            )
        print(
            f"  {'total':<12} {_median_of(serial, 'total'):>9.3f} "
            f"{_median_of(serial, 'total cpu'):>8.3f}"
            "   (in-process, without the interpreter start)"
        )
        if args.figures:
            print("\ndrawing of each figure, in-process (median, s)")
            for name in serial[0]["figures"]:
                vals = [r["figures"].get(name, float("nan")) for r in serial]
                print(f"  {statistics.median(vals):7.3f}  {name}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
