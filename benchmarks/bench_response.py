"""Benchmark: exact modal response (microg.dynamics.response) against strong baselines, same run.

Problem: 100 modes (6 rigid, omega = 0; 94 elastic, 0.1-40 Hz, zeta 0 to
0.02), 20,001 output times over 0-200 s, the report's crew push-off (Eq. 2.16: f0 = 25 lbf =
111.2 N, t1 = 1 s, t13 = 13 s, t14 = 14 s), random mode shapes and three observed points.

Baselines, timed in the same process:

* a compiled per-mode recurrence (numba, the ``bench`` extra): for each mode, step from output
  time to output time with the exact step functions g, h, S, R of the elapsed time (computed once
  per distinct step length), splitting a step at every force breakpoint inside it.  This is the
  fastest way to get the same exact values on any grid; single-threaded, like microg's 1-thread
  figures.  The aim is microg within 1.5x of it.
* scipy.signal.lsim on ONE block-diagonal state-space system of all modes (200 states), the
  best lsim can do (per-mode calls are ~30 times slower).  lsim interpolates the input linearly
  between samples, so for the agreement check both solvers get the push-off as lsim sees it.
* pyyeti's SolveUnc (when installed).

Grids: the uniform 0.01 s grid; a piecewise-uniform grid (0.01 s to 50 s, 0.02 s to 200 s, with
the force breakpoints inserted: every uniform piece of each force segment takes the table path);
and the uniform grid with the landing jump off the grid (t13 = 13.000000001 s), for the response
and the exact peak.  BLAS is limited to 1 thread for the
comparisons (2-thread figures printed beside them: on 2 cores they are often slower).  The
"memory floor" rows time allocating and writing an output array of the same size: on this
kind of machine, first-touch page faults of arrays above glibc's 32 MB mmap threshold cost as
much as the arithmetic, for both solvers.  The numba recurrence differs from microg by up to
~5e-9 on the piecewise grid (~1e-9 with the off-grid jump): it reuses the step functions of
one step length for steps that differ by rounding, and that phase error accumulates; microg
evaluates every time from the exact segment start state (tests: to 1e-12 of the direct form).

Run:  .venv/bin/python benchmarks/bench_response.py [--cpu]   (about 30 s; ``--cpu`` times this
thread's CPU time instead of wall time, for a machine whose cores other processes share)
"""

from __future__ import annotations

import importlib.util
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import signal
from scipy.linalg import block_diag
from threadpoolctl import threadpool_limits

from microg.dynamics import pwl
from microg.dynamics.forces import crew_pushoff, piecewise_linear
from microg.dynamics.response import modal_pwl_response, peak_response, response_at_points

N_MODES, N_RIGID, N_DOF = 100, 6, 300
T_END, N_T = 200.0, 20_001
REPEAT = 7


#: the clock: wall time by default; ``--cpu`` takes this thread's CPU time (robust when other
#: processes share the cores: scheduling gaps are not counted, page faults still are)
CLOCK: Callable[[], float] = time.perf_counter


def best_of(fn: Callable[[], Any], repeat: int = REPEAT) -> tuple[float, Any]:
    times, out = [], None
    for _ in range(repeat):
        t0 = CLOCK()
        out = fn()
        times.append(CLOCK() - t0)
    return min(times), out


def numba_recurrence() -> Callable[..., np.ndarray] | None:
    """The compiled per-mode exact recurrence (None when numba is not installed)."""
    if importlib.util.find_spec("numba") is None:
        return None
    import numba  # type: ignore[import-not-found]

    @numba.njit(cache=False)
    def funcs(w: float, z: float, tau: float) -> tuple[float, float, float, float]:
        if w == 0.0:
            return 1.0, tau, 0.5 * tau * tau, tau * tau * tau / 6.0
        sig = z * w
        wd = w * np.sqrt(1.0 - z * z)
        e = np.exp(-sig * tau)
        c, s = np.cos(wd * tau), np.sin(wd * tau)
        h = e * s / wd
        g = e * (c + sig * s / wd)
        x = w * tau
        if x < 0.5:  # series, as the kernel does (cancellation in 1 - g)
            S = 0.0
            R = 0.0
            a_prev, a_cur = 0.0, 0.5 * tau * tau
            r_prev, r_cur = 0.0, tau * tau * tau / 6.0
            S, R = a_cur, r_cur
            tst = 2.0 * sig * tau
            for n in range(1, 24):
                nxt = -((n + 1) * tst * a_cur + x * x * a_prev) / ((n + 2) * (n + 1))
                a_prev, a_cur = a_cur, nxt
                S += nxt
                k = n + 1
                rn = -((k + 1) * tst * r_cur + x * x * r_prev) / ((k + 2) * (k + 1))
                r_prev, r_cur = r_cur, rn
                R += rn
            return g, h, S, R
        S = (1.0 - g) / (w * w)
        R = (tau - h - 2.0 * sig * S) / (w * w)
        return g, h, S, R

    @numba.njit(cache=False)
    def run(
        omega: np.ndarray, zeta: np.ndarray, tb: np.ndarray, pb: np.ndarray, t: np.ndarray
    ) -> np.ndarray:
        m, nt, nb = omega.size, t.size, tb.size
        out = np.empty((3, m, nt))
        for j in range(m):
            w, z = omega[j], zeta[j]
            w2, ts = w * w, 2.0 * z * w
            eta = 0.0
            v = 0.0
            p = 0.0
            s = 0.0
            tcur = tb[0]
            k = 0
            last_tau = -1.0
            g = h = S = R = 0.0
            for i in range(nt):
                ti = t[i]
                if ti < tb[0]:
                    out[0, j, i] = 0.0
                    out[1, j, i] = 0.0
                    out[2, j, i] = 0.0
                    continue
                while k < nb and tb[k] <= ti:  # cross the breakpoints up to ti
                    tau = tb[k] - tcur
                    if tau > 0.0:
                        g2, h2, S2, R2 = funcs(w, z, tau)
                        e2 = eta * g2 + v * h2 + p * S2 + s * R2
                        v = -w2 * h2 * eta + (g2 - ts * h2) * v + p * h2 + s * S2
                        eta = e2
                    tcur = tb[k]
                    while k + 1 < nb and tb[k + 1] == tb[k]:
                        k += 1
                    p = pb[j, k]
                    s = (pb[j, k + 1] - p) / (tb[k + 1] - tb[k]) if k + 1 < nb else 0.0
                    k += 1
                tau = ti - tcur
                if tau > 0.0:
                    if abs(tau - last_tau) > 1.8e-15 * max(ti, 1.0):  # 8 roundings of t
                        g, h, S, R = funcs(w, z, tau)
                        last_tau = tau
                    e2 = eta * g + v * h + p * S + s * R
                    v = -w2 * h * eta + (g - ts * h) * v + p * h + s * S
                    eta = e2
                    p = p + s * tau
                    tcur = ti
                out[0, j, i] = eta
                out[1, j, i] = v
                out[2, j, i] = p - ts * v - w2 * eta
        return out

    return run  # type: ignore[no-any-return]


def rel_diff(a: np.ndarray, b: np.ndarray) -> float:
    """Largest difference per mode (row) over that mode's peak."""
    scale = np.max(np.abs(b), axis=-1, keepdims=True) + 1e-300
    return float(np.max(np.abs(a - b) / scale))


def main() -> None:
    rng = np.random.default_rng(2024)
    omega = np.r_[np.zeros(N_RIGID), 2 * np.pi * np.geomspace(0.1, 40.0, N_MODES - N_RIGID)]
    zeta = np.r_[np.zeros(N_RIGID), rng.choice([0.0, 0.005, 0.02], N_MODES - N_RIGID)]
    phi = rng.normal(size=(N_DOF, N_MODES)) / np.sqrt(N_DOF)  # "mass-normalised" shapes
    points = {f"p{i}": rng.normal(size=(3, N_DOF)) for i in range(3)}
    b = points["p0"].T @ np.array([1.0, 0.0, 0.0])  # force at p0 along x
    gamma = phi.T @ b
    t = np.linspace(0.0, T_END, N_T)
    dt = t[1] - t[0]
    force = crew_pushoff()  # Eq. 2.16 with its jumps
    mf = np.outer(gamma, force.force)
    piecewise = np.unique(
        np.r_[np.arange(0.0, 50.0, 0.01), np.linspace(50.0, T_END, 7501), force.timepts]
    )
    print(
        f"modes {N_MODES} ({N_RIGID} rigid), output times {N_T}, dt {dt:g} s, "
        f"push-off f0 {force.force.max():.4g} N"
    )
    nb = numba_recurrence()
    rows: list[tuple[str, float, float | None]] = []
    with threadpool_limits(1):
        off_jump = crew_pushoff(t13=13.000000001, t14=14.000000001)
        cases = (
            ("uniform", t, force),
            ("piecewise-uniform", piecewise, force),
            ("uniform, off-grid jump", t, off_jump),
        )
        for label, grid, f_ in cases:
            tp, mf_ = f_.timepts, np.outer(gamma, f_.force)
            t_k, mine = best_of(
                lambda g=grid, tp=tp, mf_=mf_: modal_pwl_response(omega, zeta, tp, mf_, g)
            )
            t_nb = None
            if nb is not None:
                nb(omega, zeta, tp, mf_, grid[:10])  # compile
                t_nb, ref = best_of(lambda g=grid, tp=tp, mf_=mf_: nb(omega, zeta, tp, mf_, g))
                err = max(
                    rel_diff(getattr(mine, k), ref[q])
                    for q, k in enumerate(("eta", "eta_dot", "eta_ddot"))
                )
                print(f"  {label}: microg vs numba recurrence, max difference {err:.1e} of peak")
            rows.append((f"modal_pwl_response, {label} ({grid.size} times)", t_k, t_nb))
            if label == "piecewise-uniform":  # the same grid without the table path
                saved = pwl._MIN_RUN
                pwl._MIN_RUN = 10**12
                try:
                    t_d, _ = best_of(
                        lambda g=grid: modal_pwl_response(omega, zeta, force.timepts, mf, g),
                        repeat=3,
                    )
                finally:
                    pwl._MIN_RUN = saved
                rows.append(("  same grid, direct closed form only (no tables)", t_d, t_nb))
            if f_ is off_jump:
                continue  # the same memory as the uniform grid
            t_mem, _ = best_of(lambda g=grid: np.empty((3, N_MODES, g.size)).fill(1.0))
            rows.append((f"  memory floor: allocate and write (3, m, {grid.size})", t_mem, None))
        t_pts, pts = best_of(lambda: response_at_points(omega, zeta, phi, points, force, b, t))
        t_nbp = None
        if nb is not None:

            def nb_points() -> dict[str, np.ndarray]:
                modal = nb(omega, zeta, force.timepts, mf, t)
                return {n: (m_ @ phi) @ modal[2] for n, m_ in points.items()}

            t_nbp, ref_p = best_of(nb_points)
            err = max(
                float(np.max(np.abs(pts[n].acceleration - ref_p[n])) / np.max(np.abs(ref_p[n])))
                for n in points
            )
            print(f"  points: microg vs numba + projection, max difference {err:.1e} of peak")
        rows.append(("response_at_points, 3 points, uniform", t_pts, t_nbp))
        off = crew_pushoff(t13=13.000000001, t14=14.000000001)
        t_pk, pk = best_of(lambda: peak_response(omega, zeta, phi, points, [(off, b)], t), repeat=3)
        rows.append(("peak_response, 3 points, jump off the grid", t_pk, None))
    with threadpool_limits(2):
        t_pts2, _ = best_of(lambda: response_at_points(omega, zeta, phi, points, force, b, t))
        t_k2, _ = best_of(lambda: modal_pwl_response(omega, zeta, force.timepts, mf, t))
    print(f"\n{'case (1 BLAS thread)':58s} {'microg':>9s} {'numba':>9s} {'ratio':>7s}")
    for name, tm, tb_ in rows:
        extra = f"{tb_ * 1e3:8.1f}  {tm / tb_:6.2f}x" if tb_ else f"{'-':>8s}  {'-':>7s}"
        print(f"{name:58s} {tm * 1e3:7.1f} ms {extra}")
    print(
        f"(2 BLAS threads: modal_pwl_response {t_k2 * 1e3:.1f} ms, "
        f"response_at_points {t_pts2 * 1e3:.1f} ms)"
    )
    for n in points:
        p = pk[n]
        print(
            f"  exact peak at {n}: {p.peak_accel_mps2:.6e} m/s^2 at {p.peak_time_s:.9f} s "
            f"({p.peak_side}); bound {p.upper_bound_mps2 / p.peak_accel_mps2 - 1:.1e} above; "
            f"sampled {p.sampled_peak_accel_mps2:.6e} ({p.rounds} rounds)"
        )

    # --- lsim on the block-diagonal system, fed the push-off as it sees it (samples joined)
    f0 = force.force.max()
    lsim_force = piecewise_linear(
        [0.0, 1.0 - dt, 1.0, 13.0 - dt, 13.0, 14.0],
        [0.0, f0 * (1.0 - dt), 0.0, 0.0, -f0, 0.0],
        name="push-off as sampled",
    )
    u = lsim_force.at(t)
    assert np.allclose(u, force.at(t), rtol=0, atol=1e-9 * f0)  # same samples
    A = block_diag(
        *[np.array([[0.0, 1.0], [-(w**2), -2 * z * w]]) for w, z in zip(omega, zeta, strict=True)]
    )
    B = np.zeros((2 * N_MODES, 1))
    B[1::2, 0] = gamma
    C = np.zeros((3 * N_MODES, 2 * N_MODES))
    D = np.zeros((3 * N_MODES, 1))
    idx = np.arange(N_MODES)
    C[idx, 2 * idx] = 1.0
    C[N_MODES + idx, 2 * idx + 1] = 1.0
    C[2 * N_MODES + idx, 2 * idx] = -(omega**2)
    C[2 * N_MODES + idx, 2 * idx + 1] = -2 * zeta * omega
    D[2 * N_MODES :, 0] = gamma
    with threadpool_limits(1):
        t_lsim, (_, y, _) = best_of(lambda: signal.lsim((A, B, C, D), u, t), repeat=3)
        t_kl, mine = best_of(
            lambda: modal_pwl_response(
                omega, zeta, lsim_force.timepts, np.outer(gamma, lsim_force.force), t
            )
        )
    ref = {"eta": y[:, :N_MODES].T, "eta_dot": y[:, N_MODES : 2 * N_MODES].T}
    ref["eta_ddot"] = y[:, 2 * N_MODES :].T
    print(f"\nscipy lsim, block-diagonal: {t_lsim * 1e3:8.1f} ms ({t_lsim / t_kl:.1f}x microg)")
    for key in ("eta", "eta_dot", "eta_ddot"):
        print(f"max difference {key:9s}: {rel_diff(getattr(mine, key), ref[key]):.2e} of peak")
    exact = response_at_points(omega, zeta, phi, points, force, b, t)
    acc_lsim = points["p1"] @ phi @ ref["eta_ddot"]
    err = np.max(np.abs(acc_lsim - exact["p1"].acceleration))
    print(f"(lsim on the true push-off with jumps is off by {err / np.abs(acc_lsim).max():.1e})")

    if importlib.util.find_spec("pyyeti") is None:
        print("pyyeti: not installed, comparison skipped")
    else:  # pragma: no cover - optional
        from pyyeti import ode

        ts = ode.SolveUnc(np.ones(N_MODES), 2 * zeta * omega, omega**2, dt, rf=None)
        with threadpool_limits(1):
            t_yeti, sol = best_of(lambda: ts.tsolve(np.outer(gamma, u)), repeat=3)
        print(
            f"pyyeti SolveUnc.tsolve    : {t_yeti * 1e3:8.1f} ms, max diff "
            f"{rel_diff(sol.d, ref['eta']):.2e}"
        )


if __name__ == "__main__":
    import sys

    if "--cpu" in sys.argv[1:]:
        CLOCK = time.thread_time
        print("timing: this thread's CPU time (--cpu)")
    main()
