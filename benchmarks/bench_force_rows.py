"""Benchmark: a long force file costs what its pieces cost, not what its rows cost (same run).

Problem: ``microg.analyze`` on the shipped IOC model, 30 s record, one force at the crew point
read from a CSV file: a triangular push (0-0.5-1 s, 50 lbf peak) sampled at uniform rows over
the whole record, so most rows repeat the value zero.  Sizes: 10,000, 100,000 and 1,000,000
rows.

Baseline, timed in the same run: the same history with its repeated rows removed (a row is
dropped when its value equals both neighbours', so the function f(t) is unchanged) and written
as its own CSV file.  The rows that remain are the push's (one per sample inside 0-1 s), so the
baseline's pieces are the file's pieces; the ratio is what the rows cost beyond them (reading
and parsing the longer file).  Target: within 2x at a million rows.

The two runs' peak accelerations at every observed point are compared (to 1e-9: both are
certified to rtol 1e-9 of the same supremum).

Run:  python benchmarks/bench_force_rows.py   (about a minute)
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

import microg

SIZES = (10_000, 100_000, 1_000_000)
REPEAT = 3


def _write(path: Path, t: np.ndarray, f: np.ndarray) -> None:
    np.savetxt(path, np.c_[t, f], delimiter=",", header="time [s], force [lbf]",
               comments="", fmt="%.9g")


def _dedup(t: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    keep = np.ones(t.size, bool)
    same = f[1:] == f[:-1]
    keep[1:-1] = ~(same[:-1] & same[1:])
    return t[keep], f[keep]


def _run(path: Path) -> tuple[float, dict[str, float]]:
    best = np.inf
    peaks: dict[str, float] = {}
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        res = microg.analyze("ioc", force=str(path), duration="30 s")
        best = min(best, time.perf_counter() - t0)
        peaks = {name: o.peak_accel_g for name, o in res.observations.items()}
    return best, peaks


def main() -> None:
    print(f"{'rows':>10} {'pieces':>8} {'file s':>8} {'dedup s':>8} {'ratio':>6}  peaks agree")
    with tempfile.TemporaryDirectory() as tmp:
        for n in SIZES:
            t = np.linspace(0.0, 30.0, n)
            f = np.round(np.where(t < 0.5, 100.0 * t, np.where(t < 1.0, 100.0 * (1.0 - t), 0.0)), 9)
            td, fd = _dedup(t, f)
            full, short = Path(tmp) / f"full{n}.csv", Path(tmp) / f"dedup{n}.csv"
            _write(full, t, f)
            _write(short, td, fd)
            t_full, p_full = _run(full)
            t_short, p_short = _run(short)
            agree = all(abs(p_full[k] - p_short[k]) <= 1e-9 * abs(p_short[k]) for k in p_short)
            print(f"{n:>10,} {td.size:>8,} {t_full:>8.2f} {t_short:>8.2f} "
                  f"{t_full / t_short:>6.2f}  {agree}")


if __name__ == "__main__":
    main()
