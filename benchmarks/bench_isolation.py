"""Benchmark of the isolation kernels against strong baselines run in the same process.

1. The M_a kernel (Eq. 4.3) on a 4-D grid (20 k x 20 mu x 10 zeta x 2500 r = 10^7 points)
   against a BATCHED numpy solve of the 2x2 complex system of Eq. 4.3 (``numpy.linalg.solve``
   on stacked matrices, chunked over k so the stack fits in memory) -- the best a plain numpy
   user would write; no per-point Python loop.
2. The exact first-order-hold package response (``package_response``) on 10^6 samples against a
   sequential FOH loop compiled with numba (the ``bench`` extra; skipped without it), the same
   recurrence with the same matrices.  microg takes the diagonal path on every grid (the
   4-state model diagonalises well: eigen-coordinates, scalar O(N) recurrences by
   :func:`microg._scan.scalar_scan`); ``--scans`` times the matrix scans instead (the fallback
   for a defective A: shared-map scan, refinement, per-run scans).  Grids: uniform; 3 step
   lengths 0.5, 1, 2 ms in random order (commensurate); 3 step lengths 0.5, 0.73, 1.1 ms in
   random order (not commensurate); 1 ms then 1.37 ms steps (two uniform runs).  On the
   commensurate grid the loop uses the exact step lengths 0.5, 1, 2 ms while
   ``t = cumsum(steps)`` has drifted from their multiples by ~1e-8 s of rounding; microg's
   grouped steps keep every sample within the rounding of its given time, hence a difference
   of order 1e-12..1e-10 (of peak) between the two, at the rounding of the times, not of the
   method.

BLAS is limited to 1 thread for the comparisons.
Run: ``.venv/bin/python benchmarks/bench_isolation.py [--cpu] [--scans]`` (about 60 s; ``--cpu``
times this thread's CPU time, for a machine whose cores other processes share).
"""

from __future__ import annotations

import importlib.util
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from microg.isolation.timedomain import (
    IsolatorModel,
    foh_discretize,
    package_response,
    state_space,
)
from microg.isolation.transmissibility import accel_magnification, accel_magnification_grid

#: the clock: wall time by default; ``--cpu`` takes this thread's CPU time (robust when other
#: processes share the cores; the multi-threaded grid row then counts the main thread only)
CLOCK: Callable[[], float] = time.perf_counter


def best_of(fn: Callable[[], Any], repeat: int = 5) -> tuple[float, Any]:
    times, out = [], None
    for _ in range(repeat):
        t0 = CLOCK()
        out = fn()
        times.append(CLOCK() - t0)
    return min(times), out


def batched_solve(k: np.ndarray, mu: np.ndarray, zeta: np.ndarray, r: np.ndarray) -> np.ndarray:
    """|u1 / u0| of Eq. 4.3 by numpy.linalg.solve on stacked 2x2 systems (m1 = k1 = 1)."""
    out = np.empty((k.size, mu.size, zeta.size, r.size))
    MU, Z, R = np.meshgrid(mu, zeta, r, indexing="ij")
    for i, kk in enumerate(k):  # one stack of mu x zeta x r systems per k value
        k2, m2 = 1.0 / kk, MU
        c = 2.0 * Z * np.sqrt(m2 * k2)
        w = R
        a = np.empty((*MU.shape, 2, 2), complex)
        a[..., 0, 0] = 1.0 + k2 - w * w + 1j * c * w
        a[..., 0, 1] = a[..., 1, 0] = -(k2 + 1j * c * w)
        a[..., 1, 1] = k2 - m2 * w * w + 1j * c * w
        rhs = np.zeros((*MU.shape, 2, 1), complex)
        rhs[..., 0, 0] = 1.0
        out[i] = np.abs(np.linalg.solve(a, rhs)[..., 0, 0])
    return out


def numba_foh() -> Callable[..., np.ndarray] | None:
    """A sequential first-order-hold loop compiled with numba (None without numba)."""
    if importlib.util.find_spec("numba") is None:
        return None
    import numba  # type: ignore[import-not-found]

    @numba.njit(cache=False)
    def run(
        Phi: np.ndarray,
        G1: np.ndarray,
        G2: np.ndarray,
        index: np.ndarray,
        C: np.ndarray,
        u: np.ndarray,
        t: np.ndarray,
    ) -> np.ndarray:
        n = Phi.shape[1]
        N = u.size
        y = np.empty((N, 2))
        x = np.zeros(n)
        xn = np.zeros(n)
        y[0, 0] = 0.0
        y[0, 1] = 0.0
        for j in range(N - 1):
            q = index[j]
            s = (u[j + 1] - u[j]) / (t[j + 1] - t[j])
            for i in range(n):
                acc = G1[q, i] * u[j] + G2[q, i] * s
                for k in range(n):
                    acc += Phi[q, i, k] * x[k]
                xn[i] = acc
            out = 0.0
            for i in range(n):
                x[i] = xn[i]
                out += C[i] * x[i]
            y[j + 1, 0] = out
            y[j + 1, 1] = x[0]
        return y

    return run  # type: ignore[no-any-return]


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
    t_grid, _ = best_of(lambda: accel_magnification_grid(k, mu, zeta, r), repeat=3)
    with threadpool_limits(1):
        t_grid1, grid = best_of(
            lambda: accel_magnification_grid(k, mu, zeta, r, workers=1), repeat=3
        )
        kk, mm, zz = k[:, None, None, None], mu[None, :, None, None], zeta[None, None, :, None]
        t_plain, _ = best_of(lambda: accel_magnification(kk, mm, zz, r), repeat=3)
        t_solve, ref = best_of(lambda: batched_solve(k, mu, zeta, r), repeat=2)
    err = float(np.max(np.abs(grid - ref) / ref))
    print(f"{'grid kernel, ' + str(cpus) + ' threads':40s} {t_grid:8.3f} s")
    print(f"{'grid kernel, 1 thread':40s} {t_grid1:8.3f} s")
    print(f"{'plain broadcasting kernel, 1 thread':40s} {t_plain:8.3f} s")
    print(f"{'batched numpy.linalg.solve (baseline)':40s} {t_solve:8.3f} s")
    print(
        f"speed-up over the batched solve: grid kernel {t_solve / t_grid:.3g}x "
        f"({cpus} threads), {t_solve / t_grid1:.3g}x (1 thread); plain {t_solve / t_plain:.3g}x"
    )
    print(f"max relative difference kernel vs batched solve: {err:.2e}")

    model = IsolatorModel.from_dimensionless(450.0, 135.0, k=10.0, mu=0.05, zeta=0.2)
    A, B, C = state_space(model)
    foh = numba_foh()
    rng = np.random.default_rng(1)
    t_uni = np.linspace(0.0, 1000.0, 1_000_001)
    t_non = np.cumsum(np.r_[0.0, rng.choice([5e-4, 1e-3, 2e-3], 999_999)])
    t_inc = np.cumsum(np.r_[0.0, rng.choice([5e-4, 7.3e-4, 1.1e-3], 999_999)])
    t_pw = np.r_[0.0, np.cumsum(np.r_[np.full(500_000, 1e-3), np.full(499_999, 1.37e-3)])]
    print("\nexact FOH package response, 4 states, 10^6 samples (1 BLAS thread)")
    grids = (
        ("uniform", t_uni),
        ("steps 0.5/1/2 ms (commensurate)", t_non),
        ("steps 0.5/0.73/1.1 ms (general)", t_inc),
        ("1 ms then 1.37 ms (two runs)", t_pw),
    )
    for label, t in grids:
        a = np.sin(1.02 * t) + 0.1 * np.sin(17.0 * t)
        with threadpool_limits(1):
            t_td, res = best_of(lambda t=t, a=a: package_response(model, t, a), repeat=3)
        line = f"  {label:33s} microg {t_td * 1e3:7.1f} ms"
        if foh is not None:
            h = np.diff(t)
            span = (t[-1] - t[0]) / h.size
            if np.max(np.abs(h - span)) < 1e-12:
                hu, index = np.array([span]), np.zeros(h.size, np.int64)
            else:
                hu, index = np.unique(np.round(h, 12), return_inverse=True)
            Phi, G1, G2 = foh_discretize(A, B, hu)
            index = index.astype(np.int64)
            args = (Phi, G1, G2, index, C[0].copy(), a, t)
            foh(Phi, G1, G2, index[:2], C[0].copy(), a[:3], t[:3])  # compile on a short record
            t_nb, y = best_of(lambda args=args: foh(*args), repeat=3)
            diff = np.max(np.abs(res.package_accel - y[:, 0])) / np.max(np.abs(y[:, 0]))
            line += f"   numba sequential loop {t_nb * 1e3:7.1f} ms   ratio {t_td / t_nb:5.2f}x"
            line += f"   max difference {diff:.1e} of peak"
        print(line)


if __name__ == "__main__":
    import sys

    if "--scans" in sys.argv[1:]:
        import microg.isolation.timedomain as td

        td._DIAGONAL = False
        print("package response: the matrix scans (--scans)")
    if "--cpu" in sys.argv[1:]:
        CLOCK = time.thread_time
        print("timing: this thread's CPU time (--cpu)")
    main()
