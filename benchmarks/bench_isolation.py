"""Benchmark of the isolation kernels against strong baselines run in the same process.

1. The M_a kernel (Eq. 4.3) on a 4-D grid (20 k x 20 mu x 10 zeta x 2500 r = 10^7 points),
   microg's cache-blocked grid kernel (``accel_magnification_grid``, 1 thread), against the
   strongest of: microg's own closed form by plain broadcasting (``accel_magnification``, the
   same real formula ``M_a^2 = (a^2 + t)/(D_r^2 + t b^2)`` without blocking), a fused numba
   loop of that formula (the ``bench`` extra: one pass, no temporaries), and a batched
   ``numpy.linalg.solve`` of the 2x2 complex system (secondary row: what a numpy user without
   the closed form would write).
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

BLAS is limited to 1 thread for the comparisons.  Timing: CPU time of this thread
(``time.thread_time``: the machine's 2 cores are shared, so wall time would count other
processes), ROUNDS interleaved rounds, the median of each; the threaded grid row is wall time
(the CPU time of one thread would not count its pool) and only indicative on a shared machine.
Run: ``.venv/bin/python benchmarks/bench_isolation.py [--scans]`` (about 90 s).
"""

from __future__ import annotations

import importlib.util
import os
import statistics
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

CLOCK: Callable[[], float] = time.thread_time
ROUNDS = 5


def interleaved(
    fns: dict[str, Callable[[], Any]], rounds: int = ROUNDS
) -> tuple[dict[str, float], dict[str, Any]]:
    """Median CPU time of each function over interleaved rounds (s), and each one's result."""
    times: dict[str, list[float]] = {k: [] for k in fns}
    outs: dict[str, Any] = {}
    for _ in range(rounds):
        for k, f in fns.items():
            t0 = CLOCK()
            outs[k] = f()
            times[k].append(CLOCK() - t0)
    return {k: statistics.median(v) for k, v in times.items()}, outs


def numba_ma() -> Callable[..., np.ndarray] | None:
    """The closed form of M_a in one fused compiled loop over the grid (None without numba)."""
    if importlib.util.find_spec("numba") is None:
        return None
    import numba  # type: ignore[import-not-found]

    @numba.njit(cache=False)
    def run(k, mu, zeta, r):  # type: ignore[no-untyped-def]
        out = np.empty((k.size, mu.size, zeta.size, r.size))
        q = r * r
        for i in range(k.size):
            for j in range(mu.size):
                s2 = mu[j] * k[i]
                mu1 = 1.0 + mu[j]
                for z in range(zeta.size):
                    t0 = 4.0 * zeta[z] * zeta[z] * s2
                    for n in range(r.size):
                        qq = q[n]
                        a = 1.0 - s2 * qq
                        b = 1.0 - mu1 * qq
                        dr = (1.0 - qq) * a - mu[j] * qq
                        t = t0 * qq
                        out[i, j, z, n] = np.sqrt((a * a + t) / (dr * dr + t * b * b))
        return out

    return run  # type: ignore[no-any-return]


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
    t0 = time.perf_counter()
    accel_magnification_grid(k, mu, zeta, r)
    t_grid_wall = time.perf_counter() - t0
    kk, mm, zz = k[:, None, None, None], mu[None, :, None, None], zeta[None, None, :, None]
    fns: dict[str, Callable[[], Any]] = {
        "grid kernel (microg), 1 thread": lambda: accel_magnification_grid(
            k, mu, zeta, r, workers=1
        ),
        "closed form by broadcasting (microg)": lambda: accel_magnification(kk, mm, zz, r),
    }
    fused = numba_ma()
    if fused is None:
        print("numba is not installed (the bench extra): no fused baseline")
    else:
        fused(k[:1], mu[:1], zeta[:1], r[:2])  # compile
        fns["fused numba loop"] = lambda: fused(k, mu, zeta, r)
    with threadpool_limits(1):
        med, outs = interleaved(fns)
        med_s, outs_s = interleaved(
            {"batched linalg.solve": lambda: batched_solve(k, mu, zeta, r)}, 2
        )
    med.update(med_s)
    outs.update(outs_s)
    mine = outs["grid kernel (microg), 1 thread"]
    ref = outs["batched linalg.solve"]
    print(
        f"{'M_a on the grid (CPU time, 1 thread)':40s} {'s':>8s} {'microg/it':>10s} "
        f"{'max rel diff':>12s}"
    )
    for name, t in med.items():
        ratio = (
            "" if name.startswith("grid") else f"{med['grid kernel (microg), 1 thread'] / t:9.2f}x"
        )
        err = float(np.max(np.abs(outs[name] - ref) / ref))
        print(f"{name:40s} {t:8.3f} {ratio:>10s} {err:12.1e}")
    cands = [n for n in med if not n.startswith("grid") and n != "batched linalg.solve"]
    best = min(cands, key=lambda n: med[n])
    print(
        f"ratio grid kernel / strongest baseline ({best}): "
        f"{med['grid kernel (microg), 1 thread'] / med[best]:.2f}; grid kernel on {cpus} threads "
        f"{t_grid_wall:.3f} s wall (indicative: shared cores); max difference from the "
        f"batched solve {float(np.max(np.abs(mine - ref) / ref)):.1e}"
    )

    model = IsolatorModel.from_dimensionless(450.0, 135.0, k=10.0, mu=0.05, zeta=0.2)
    A, B, C = state_space(model)
    foh = numba_foh()
    rng = np.random.default_rng(1)
    t_uni = np.linspace(0.0, 1000.0, 1_000_001)
    t_non = np.cumsum(np.r_[0.0, rng.choice([5e-4, 1e-3, 2e-3], 999_999)])
    t_inc = np.cumsum(np.r_[0.0, rng.choice([5e-4, 7.3e-4, 1.1e-3], 999_999)])
    t_pw = np.r_[0.0, np.cumsum(np.r_[np.full(500_000, 1e-3), np.full(499_999, 1.37e-3)])]
    print(
        "\nexact FOH package response, 4 states, 10^6 samples (1 BLAS thread, CPU time, "
        f"median of {ROUNDS} interleaved rounds)"
    )
    grids = (
        ("uniform", t_uni),
        ("steps 0.5/1/2 ms (commensurate)", t_non),
        ("steps 0.5/0.73/1.1 ms (general)", t_inc),
        ("1 ms then 1.37 ms (two runs)", t_pw),
    )
    for label, t in grids:
        a = np.sin(1.02 * t) + 0.1 * np.sin(17.0 * t)
        line = f"  {label:33s}"
        fns = {"microg": lambda t=t, a=a: package_response(model, t, a)}
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
            fns["numba"] = lambda args=args: foh(*args)
        with threadpool_limits(1):
            med, outs = interleaved(fns)
        res = outs["microg"]
        t_td = med["microg"]
        line += f" microg {t_td * 1e3:7.1f} ms"
        if foh is not None:
            t_nb, y = med["numba"], outs["numba"]
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
    main()
