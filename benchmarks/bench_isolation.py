"""Benchmark of the M_a kernel on a 4-D grid against a per-point direct solve of Eq. 4.3.

Run: ``.venv/bin/python benchmarks/bench_isolation.py`` (about 20 s).  Prints evaluations per
second of the cache-blocked threaded grid kernel, of the plain broadcasting kernel, and of the
baseline (numpy.linalg.solve on the 2x2 complex system of Eq. 4.3, one point per Python call,
measured on a random sample and extrapolated per point), and their ratios.  Also times the
exact first-order-hold time response on 10^6 samples.
"""

from __future__ import annotations

import os
import time

import numpy as np

from microg.isolation.timedomain import IsolatorModel, package_response
from microg.isolation.transmissibility import accel_magnification, accel_magnification_grid


def best_of(fn, repeat: int = 5) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def direct_point(k: float, mu: float, zeta: float, r: float) -> float:
    m1, k1 = 1.0, 1.0
    k2, m2 = k1 / k, mu * m1
    c = 2.0 * zeta * np.sqrt(m2 * k2)
    w = r
    mat = np.array(
        [
            [k1 + k2 - m1 * w * w + 1j * c * w, -(k2 + 1j * c * w)],
            [-(k2 + 1j * c * w), k2 - m2 * w * w + 1j * c * w],
        ]
    )
    return float(abs(np.linalg.solve(mat, np.array([k1, 0.0]))[0]))


def main() -> None:
    k = np.linspace(2.0, 40.0, 20)
    mu = np.geomspace(0.005, 0.25, 20)
    zeta = np.linspace(0.02, 0.5, 10)
    r = np.linspace(0.0, 3.0, 2500)
    n = k.size * mu.size * zeta.size * r.size
    cpus = os.cpu_count() or 1
    print(
        f"grid {k.size} k x {mu.size} mu x {zeta.size} zeta x {r.size} r = {n:,} points, "
        f"{cpus} CPUs"
    )

    t_grid = best_of(lambda: accel_magnification_grid(k, mu, zeta, r))
    t_grid1 = best_of(lambda: accel_magnification_grid(k, mu, zeta, r, workers=1))
    kk, mm, zz = k[:, None, None, None], mu[None, :, None, None], zeta[None, None, :, None]
    t_plain = best_of(lambda: accel_magnification(kk, mm, zz, r), repeat=3)

    rng = np.random.default_rng(0)
    ns = 2000
    pts = np.column_stack(
        [rng.choice(k, ns), rng.choice(mu, ns), rng.choice(zeta, ns), rng.choice(r, ns)]
    )
    t0 = time.perf_counter()
    ref = np.array([direct_point(*p) for p in pts])
    t_direct_per_point = (time.perf_counter() - t0) / ns
    # the kernel agrees with the baseline on the sample
    err = np.max(np.abs(accel_magnification(*pts.T) - ref) / ref)

    rate = {
        f"grid kernel ({cpus} threads)": n / t_grid,
        "grid kernel (1 thread)": n / t_grid1,
        "plain broadcasting kernel": n / t_plain,
        "direct 2x2 solve per point (baseline)": 1.0 / t_direct_per_point,
    }
    for name, v in rate.items():
        print(f"{name:40s} {v:12.4g} evaluations/s")
    base = rate["direct 2x2 solve per point (baseline)"]
    grid_rate = rate[f"grid kernel ({cpus} threads)"]
    plain_rate = rate["plain broadcasting kernel"]
    print(f"speed-up of grid kernel over baseline     {grid_rate / base:12.4g}x")
    print(f"speed-up of plain kernel over baseline    {plain_rate / base:12.4g}x")
    print(
        f"extrapolated baseline time for the grid   {n * t_direct_per_point:12.4g} s "
        f"(grid kernel: {t_grid:.3g} s)"
    )
    print(f"max relative difference kernel vs baseline on the sample: {err:.2e}")

    model = IsolatorModel.from_dimensionless(450.0, 135.0, k=10.0, mu=0.05, zeta=0.2)
    t = np.linspace(0.0, 1000.0, 1_000_001)
    a = np.sin(1.02 * t)
    t_td = best_of(lambda: package_response(model, t, a), repeat=2)
    print(f"time response, 4 states, 10^6 samples (FOH expm + prefix scan): {t_td:.3g} s")


if __name__ == "__main__":
    main()
