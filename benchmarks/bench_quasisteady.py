"""Benchmark: the quasi-steady map over 10^5 points against a fused compiled loop.

Problem: the peak quasi-steady magnitude over one orbit (180 samples; LVLH hold; drag from
NRLMSIS 2.1 with B = 100 kg/m^2) at 10^5 random points within 100 m of the shipped IOC
model's centre of mass (``QuasiSteadyResult.peak_at``).  microg keeps only the drag samples on
their convex hull and takes ``|q|^2 + max_s (|d_s|^2 + 2 q . d_s)`` by one matrix product per
block of points.

Baselines, timed in the same process:

* ``numba fused`` (the strongest; the ``bench`` extra): ONE compiled loop over the points that
  forms each point's exact gravity-gradient and rotation terms (the same two-body formula, no
  linearisation) and the largest ``|q + d_s|^2`` over the samples, without any temporary array;
  timed twice: over all 180 samples, and over the convex hull's vertices (microg's reduction
  given to the baseline too); the ratio is against the faster;
* ``numpy broadcast``: the (points, samples, 3) total formed by broadcasting in blocks of 2000
  points and its largest norm (secondary row).

The inertial attitude (gravity gradient varying over the orbit) is timed against the numpy
baseline only.  Timing: CPU time of this thread (``time.thread_time``: the machine's cores are
shared), BLAS limited to 1 thread, ROUNDS interleaved rounds, the median of each.  Accuracy:
the largest relative difference from each baseline is printed.

Run: ``.venv/bin/python benchmarks/bench_quasisteady.py`` (about 20 s).
"""

from __future__ import annotations

import importlib.util
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from microg.environment import quasisteady as qs
from microg.models.toml import load_station

N_POINTS = 100_000
ROUNDS = 7
CLOCK: Callable[[], float] = time.thread_time


def numpy_baseline(res: qs.QuasiSteadyResult, pos: np.ndarray) -> np.ndarray:
    """Plain numpy: broadcast the (points, samples, 3) total per block, take the largest norm.

    In LVLH hold the gradient term is computed once per point, as microg does."""
    omega, alpha = res.attitude.rates(res.mean_motion_rad_s)
    rho = pos - res.center_of_mass_m
    r_cm = res.orbit.radius_m * res.samples.r_hat  # (S, 3)
    drag = res.drag_samples_mps2
    lvlh = res.attitude.kind == "lvlh"  # then the gradient is the same at every sample
    out = np.empty(pos.shape[0])
    for c0 in range(0, pos.shape[0], 2000):
        r = rho[c0 : c0 + 2000]
        rc = r_cm[None, :1, :] if lvlh else r_cm[None, :, :]
        gg = qs.gravity_gradient_accel(r[:, None, :], rc, res.orbit.mu_m3_per_s2)
        rot = qs.rotation_accel(r, omega, alpha)
        a = gg + rot[:, None, :] + drag[None, :, :]
        out[c0 : c0 + 2000] = np.sqrt(np.max(np.sum(a * a, axis=-1), axis=1))
    return out


def numba_fused() -> Callable[..., np.ndarray] | None:
    """The fused LVLH-hold loop (None without numba)."""
    if importlib.util.find_spec("numba") is None:
        return None
    import numba  # type: ignore[import-not-found]

    @numba.njit(cache=False)
    def run(rho, rc, mu, m, drag):  # type: ignore[no-untyped-def]
        n, ns = rho.shape[0], drag.shape[0]
        out = np.empty(n)
        R2 = rc[0] * rc[0] + rc[1] * rc[1] + rc[2] * rc[2]
        R = np.sqrt(R2)
        for i in range(n):
            x, y, z = rho[i, 0], rho[i, 1], rho[i, 2]
            s0, s1, s2 = rc[0] + x, rc[1] + y, rc[2] + z
            S2 = s0 * s0 + s1 * s1 + s2 * s2
            S = np.sqrt(S2)
            rms = -(2.0 * (x * rc[0] + y * rc[1] + z * rc[2]) + x * x + y * y + z * z) / (R + S)
            S3 = S2 * S
            inv = rms * (R2 + R * S + S2) / (R2 * R * S3)
            q0 = mu * (x / S3 + rc[0] * inv) + m[0, 0] * x + m[0, 1] * y + m[0, 2] * z
            q1 = mu * (y / S3 + rc[1] * inv) + m[1, 0] * x + m[1, 1] * y + m[1, 2] * z
            q2 = mu * (z / S3 + rc[2] * inv) + m[2, 0] * x + m[2, 1] * y + m[2, 2] * z
            best = 0.0
            for k in range(ns):
                a0, a1, a2 = q0 + drag[k, 0], q1 + drag[k, 1], q2 + drag[k, 2]
                v = a0 * a0 + a1 * a1 + a2 * a2
                if v > best:
                    best = v
            out[i] = np.sqrt(best)
        return out

    return run  # type: ignore[no-any-return]


def interleaved(fns: dict[str, Callable[[], Any]], rounds: int) -> dict[str, float]:
    """Median CPU time of each function over ``rounds`` interleaved rounds, s."""
    times: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(rounds):
        for k, f in fns.items():
            t0 = CLOCK()
            f()
            times[k].append(CLOCK() - t0)
    return {k: statistics.median(v) for k, v in times.items()}


def main() -> None:
    station = load_station("ioc")
    rng = np.random.default_rng(0)
    drag = qs.Drag(ballistic_coefficient_kg_per_m2=100.0)
    fused = numba_fused()
    with threadpool_limits(1):
        res = qs.quasi_steady(station, drag=drag)
        pos = res.center_of_mass_m + rng.uniform(-100.0, 100.0, (N_POINTS, 3))
        print(
            f"IOC model, {res.orbit.n_samples} orbit samples, {res.atmosphere_model}; "
            f"{N_POINTS:,} points; CPU time of this thread, 1 BLAS thread, median of {ROUNDS} "
            f"interleaved rounds"
        )
        mine = res.peak_at(pos)
        fns: dict[str, Callable[[], Any]] = {"microg": lambda: res.peak_at(pos)}
        refs: dict[str, np.ndarray] = {"numpy broadcast": numpy_baseline(res, pos)}
        fns["numpy broadcast"] = lambda: numpy_baseline(res, pos)
        if fused is None:
            print("numba is not installed (the bench extra): no fused baseline")
        else:
            omega, alpha = res.attitude.rates(res.mean_motion_rad_s)
            w = np.asarray(omega, float)
            a = np.asarray(alpha, float)
            mat = np.outer(w, w) - float(w @ w) * np.eye(3)
            mat += np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
            rho = np.ascontiguousarray(pos - res.center_of_mass_m)
            rc = res.orbit.radius_m * res.samples.r_hat[0]
            mu = res.orbit.mu_m3_per_s2
            d_all = np.ascontiguousarray(res.drag_samples_mps2)
            d_hull = np.ascontiguousarray(d_all[qs._hull_vertices(d_all)])

            def f_all() -> np.ndarray:
                return fused(pos - res.center_of_mass_m, rc, mu, mat, d_all)

            def f_hull() -> np.ndarray:
                return fused(pos - res.center_of_mass_m, rc, mu, mat, d_hull)

            del rho
            refs[f"numba fused, {d_all.shape[0]} samples"] = f_all()  # compiles
            refs[f"numba fused, {d_hull.shape[0]} hull vertices"] = f_hull()
            fns[f"numba fused, {d_all.shape[0]} samples"] = f_all
            fns[f"numba fused, {d_hull.shape[0]} hull vertices"] = f_hull
        med = interleaved(fns, ROUNDS)
        base = [k for k in med if k.startswith("numba")]
        best = min(base, key=lambda k: med[k]) if base else "numpy broadcast"
        print(
            f"\n{'LVLH map, 10^5 points':34s} {'CPU ms':>8s} {'microg/it':>9s} "
            f"{'max rel diff':>12s}"
        )
        for k, t in med.items():
            ratio = "" if k == "microg" else f"{med['microg'] / t:8.2f}x"
            err = (
                "" if k == "microg" else f"{float(np.max(np.abs(mine - refs[k]) / refs[k])):12.1e}"
            )
            print(f"{k:34s} {t * 1e3:8.1f} {ratio:>9s} {err:>12s}")
        print(
            f"(ratio against the strongest baseline, {best}: {med['microg'] / med[best]:.2f}; "
            "target <= 1.2)"
        )
        r_in = qs.quasi_steady(station, drag=drag, attitude=qs.Attitude("inertial"), with_map=False)
        med_in = interleaved(
            {"microg": lambda: r_in.peak_at(pos), "numpy": lambda: numpy_baseline(r_in, pos)}, 2
        )
        err = float(np.max(np.abs(r_in.peak_at(pos) - numpy_baseline(r_in, pos))))
        print(
            f"inertial map of {N_POINTS:,} points: microg {med_in['microg'] * 1e3:.1f} ms, numpy "
            f"broadcast {med_in['numpy'] * 1e3:.1f} ms (median of 2; "
            f"max difference {err:.1e} m/s^2)"
        )


if __name__ == "__main__":
    main()
