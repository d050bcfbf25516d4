"""Benchmark: the quasi-steady map over 10^5 points.

The peak quasi-steady magnitude over one orbit (180 samples; LVLH hold; drag from NRLMSIS
2.1 with B = 100 kg/m^2) at 10^5 random points within 100 m of the shipped IOC model's centre
of mass, timed in one process against a plain numpy baseline: the same exact gravity-gradient
and rotation terms, then the (points, samples, 3) total formed by broadcasting (in blocks of
2000 points so it fits in memory) and its largest norm (in LVLH hold the gradient is computed
once per point, as microg does).  microg instead keeps only the drag
samples on their convex hull and takes ``|q|^2 + max_s (|d_s|^2 + 2 q . d_s)`` by one matrix
product per block.  The inertial attitude (gravity gradient varying over the orbit, no
shortcut) is timed too.  BLAS limited to 1 thread.

Run: ``.venv/bin/python benchmarks/bench_quasisteady.py`` (about 15 s).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from microg.environment import quasisteady as qs
from microg.models.toml import load_station

N_POINTS = 100_000


def best_of(fn: Callable[[], Any], repeat: int = 7) -> tuple[float, Any]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def baseline(res: qs.QuasiSteadyResult, pos: np.ndarray) -> np.ndarray:
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


def main() -> None:
    station = load_station("ioc")
    rng = np.random.default_rng(0)
    drag = qs.Drag(ballistic_coefficient_kg_per_m2=100.0)
    with threadpool_limits(1):
        t_job, res = best_of(lambda: qs.quasi_steady(station, drag=drag), repeat=3)
        pos = res.center_of_mass_m + rng.uniform(-100.0, 100.0, (N_POINTS, 3))
        print(
            f"IOC model, {res.orbit.n_samples} orbit samples, {res.atmosphere_model}; "
            f"the whole job (named points + {res.map.within.size} map samples): "
            f"{t_job * 1e3:.1f} ms"
        )
        for kind in ("lvlh", "inertial"):
            r = (
                res
                if kind == "lvlh"
                else qs.quasi_steady(
                    station, drag=drag, attitude=qs.Attitude("inertial"), with_map=False
                )
            )
            t_map, mine = best_of(lambda r=r: r.peak_at(pos), repeat=7 if kind == "lvlh" else 2)
            t_base, ref = best_of(lambda r=r: baseline(r, pos), repeat=3 if kind == "lvlh" else 1)
            err = float(np.max(np.abs(mine - ref) / ref))
            print(
                f"{kind:9s} map of {N_POINTS:,} points: microg {t_map * 1e3:8.1f} ms, "
                f"plain numpy broadcast {t_base * 1e3:8.1f} ms ({t_base / t_map:5.1f}x), "
                f"max relative difference {err:.1e}"
            )
    print("(target: the LVLH map under 100 ms)")


if __name__ == "__main__":
    main()
