"""Benchmark: exact response at points (microg.dynamics.response) against the strongest baseline.

Problem: m = 100, 316 and 1,000 modes (6 rigid, omega = 0; the rest 0.1-40 Hz, zeta 0, 0.005
or 0.02), 20,001 output times over 0-200 s (dt = 0.01 s), the report's crew push-off (Eq. 2.16:
f0 = 25 lbf = 111.2 N, t1 = 1 s, t13 = 13 s, t14 = 14 s, with its jumps) at one point, random
mode shapes on 2 m DOFs, and ten observed points: displacement, velocity and acceleration of
each (``response_at_points``, 30 rows x 20,001 samples x 3 derivatives).

Baseline (the ``bench`` extra's numba): the strongest compiled recurrence, advancing ALL modes
together per time step (the inner loop runs over modes, contiguous, vectorised by the compiler)
with the exact step functions g, h, S, R of dt computed once per mode, a step split exactly at
every force breakpoint inside it, and the modal block of 512 steps projected on the points'
rows ``T phi`` by one BLAS product per derivative (the (3, m, nt) modal array is never built,
as microg never builds it).  ``T phi`` is formed by both.

What is timed: microg's ``response_at_points`` call (its per-point results), and the baseline's
blocks written into its one (3, 30, nt) array; microg's results are stacked into that layout
for the comparison outside the timing (the copy is not part of either's work).

Equal accuracy: both are checked against the direct closed form (microg's kernel with the
table path switched off, each time from its exact segment start state) at 400 of the times;
the largest error over each output's peak is printed for both.

Timing: CPU time of this thread (``time.thread_time``; the machine's 2 cores are shared, so
wall time would count other processes), BLAS limited to 1 thread (threadpoolctl) for both,
ROUNDS interleaved rounds (microg, baseline, microg, ...) and the median of each; the numba
kernel is compiled before the first round.  Without numba the baseline row says so.

Run:  .venv/bin/python benchmarks/bench_response.py [--modes 100 316 1000] [--rounds 7]
(about 1 minute).
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from microg.dynamics import pwl
from microg.dynamics.forces import crew_pushoff
from microg.dynamics.oscillator import oscillator_functions
from microg.dynamics.response import response_at_points

T_END, N_T, N_POINTS, N_RIGID = 200.0, 20_001, 10, 6
BLOCK = 512
CLOCK: Callable[[], float] = time.thread_time


def numba_kernel() -> Callable[..., None] | None:
    """The compiled all-modes recurrence over one block of steps (None without numba)."""
    if importlib.util.find_spec("numba") is None:
        return None
    import numba  # type: ignore[import-not-found]

    @numba.njit(cache=False)
    def funcs(w: float, z: float, tau: float) -> tuple[float, float, float, float]:
        """g, h, S, R of one mode over tau (series where w tau is small, as the kernel does)."""
        if w == 0.0:
            return 1.0, tau, 0.5 * tau * tau, tau * tau * tau / 6.0
        sig = z * w
        wd = w * np.sqrt(1.0 - z * z)
        e = np.exp(-sig * tau)
        c, s = np.cos(wd * tau), np.sin(wd * tau)
        h = e * s / wd
        g = e * (c + sig * s / wd)
        x = w * tau
        if x < 0.5:
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
    def advance(eta, v, p, s, omega, zeta, tau):  # type: ignore[no-untyped-def]
        for j in range(omega.size):
            w = omega[j]
            g, h, S, R = funcs(w, zeta[j], tau)
            ts = 2.0 * zeta[j] * w
            e2 = eta[j] * g + v[j] * h + p[j] * S + s[j] * R
            v[j] = -w * w * h * eta[j] + (g - ts * h) * v[j] + p[j] * h + s[j] * S
            eta[j] = e2
            p[j] += s[j] * tau

    @numba.njit(cache=False)
    def run_block(  # type: ignore[no-untyped-def]
        coef, omega, zeta, tb, pb, t, dt, i0, i1, state, kpos, out
    ):
        """Steps i0..i1-1 of the grid t into out (3, i1 - i0, m); state and kpos carried."""
        g, h, S, R, a21, a22, w2, ts = coef
        eta, v, p, s = state[0], state[1], state[2], state[3]
        m, nb = omega.size, tb.size
        k = kpos[0]
        for i in range(i0, i1):
            ti = t[i]
            tprev = t[i - 1] if i > 0 else tb[0]
            if k < nb and tb[k] <= ti:  # breakpoints in (tprev, ti]: split the step exactly
                tcur = tprev
                while k < nb and tb[k] <= ti:
                    tau = tb[k] - tcur
                    if tau > 0.0:
                        advance(eta, v, p, s, omega, zeta, tau)
                    tcur = tb[k]
                    while k + 1 < nb and tb[k + 1] == tb[k]:
                        k += 1
                    for j in range(m):
                        p[j] = pb[j, k]
                        s[j] = (pb[j, k + 1] - p[j]) / (tb[k + 1] - tb[k]) if k + 1 < nb else 0.0
                    k += 1
                tau = ti - tcur
                if tau > 0.0:
                    advance(eta, v, p, s, omega, zeta, tau)
            elif i > 0:  # a whole step of dt: the coefficients computed once
                for j in range(m):
                    e2 = eta[j] * g[j] + v[j] * h[j] + p[j] * S[j] + s[j] * R[j]
                    v[j] = a21[j] * eta[j] + a22[j] * v[j] + p[j] * h[j] + s[j] * S[j]
                    eta[j] = e2
                    p[j] += s[j] * dt
            r = i - i0
            for j in range(m):
                out[0, r, j] = eta[j]
                out[1, r, j] = v[j]
                out[2, r, j] = p[j] - ts[j] * v[j] - w2[j] * eta[j]
        kpos[0] = k

    return run_block  # type: ignore[no-any-return]


def baseline(
    kernel: Callable[..., None],
    omega: np.ndarray,
    zeta: np.ndarray,
    phi: np.ndarray,
    tmaps: np.ndarray,
    tb: np.ndarray,
    fb: np.ndarray,
    b: np.ndarray,
    t: np.ndarray,
) -> np.ndarray:
    """(3, 3 P, nt): the all-modes recurrence block by block, each block projected by BLAS."""
    proj = tmaps @ phi  # (3 P, m), as microg forms it
    pb = np.outer(phi.T @ b, fb)
    m = omega.size
    dt = t[1] - t[0]
    g, h, S, R = oscillator_functions(omega, zeta, np.full(m, dt))  # exact, once per mode
    ts = 2.0 * zeta * omega
    coef = np.stack([g, h, S, R, -(omega**2) * h, g - ts * h, omega**2, ts])
    state = np.zeros((4, m))
    kpos = np.zeros(1, np.int64)
    nt = t.size
    out = np.empty((3, proj.shape[0], nt))
    buf = np.empty((3, BLOCK, m))
    for i0 in range(0, nt, BLOCK):
        i1 = min(i0 + BLOCK, nt)
        kernel(coef, omega, zeta, tb, pb, t, dt, i0, i1, state, kpos, buf)
        for q in range(3):
            np.matmul(proj, buf[q, : i1 - i0].T, out=out[q, :, i0:i1])
    return out


def microg_run(
    omega: np.ndarray,
    zeta: np.ndarray,
    phi: np.ndarray,
    maps: dict[str, np.ndarray],
    force: Any,
    b: np.ndarray,
    t: np.ndarray,
) -> dict[str, Any]:
    """microg's responses at the points (what is timed)."""
    return response_at_points(omega, zeta, phi, maps, force, b, t)


def stacked(res: dict[str, Any]) -> np.ndarray:
    """(3, 3 P, nt) of microg's responses, the baseline's layout (for the comparison only)."""
    return np.stack(
        [
            np.concatenate([getattr(r, k) for r in res.values()])
            for k in ("displacement", "velocity", "acceleration")
        ]
    )


def problem(m: int) -> tuple[Any, ...]:
    rng = np.random.default_rng(2024 + m)
    n_dof = 2 * m
    omega = np.r_[np.zeros(N_RIGID), 2 * np.pi * np.geomspace(0.1, 40.0, m - N_RIGID)]
    zeta = np.r_[np.zeros(N_RIGID), rng.choice([0.0, 0.005, 0.02], m - N_RIGID)]
    phi = rng.normal(size=(n_dof, m)) / np.sqrt(n_dof)
    maps = {f"p{i}": rng.normal(size=(3, n_dof)) for i in range(N_POINTS)}
    b = maps["p0"].T @ np.array([1.0, 0.0, 0.0])
    return omega, zeta, phi, maps, b


def direct_reference(
    omega: np.ndarray,
    zeta: np.ndarray,
    phi: np.ndarray,
    maps: dict[str, np.ndarray],
    force: Any,
    b: np.ndarray,
    t: np.ndarray,
    idx: np.ndarray,
) -> np.ndarray:
    """The direct closed form at t[idx] (no tables: each time from its segment's exact start)."""
    saved = pwl._MIN_RUN
    pwl._MIN_RUN = 10**12
    try:
        return stacked(microg_run(omega, zeta, phi, maps, force, b, t[idx]))
    finally:
        pwl._MIN_RUN = saved


def error_of_peak(a: np.ndarray, ref: np.ndarray, full: np.ndarray) -> float:
    """Largest |a - ref| of each row over that row's peak (over all samples of ``full``)."""
    scale = np.max(np.abs(full), axis=-1, keepdims=True) + 1e-300
    return float(np.max(np.abs(a - ref) / scale))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--modes", type=int, nargs="+", default=[100, 316, 1000])
    ap.add_argument("--rounds", type=int, default=7)
    a = ap.parse_args()
    t = np.linspace(0.0, T_END, N_T)
    force = crew_pushoff()
    tb, fb = force.breakpoints
    kernel = numba_kernel()
    print(
        f"response at {N_POINTS} points (displacement, velocity, acceleration), {N_T} samples, "
        f"dt {t[1] - t[0]:g} s, crew push-off; CPU time of this thread, 1 BLAS thread, "
        f"median of {a.rounds} interleaved rounds"
    )
    if kernel is None:
        print("numba is not installed (the bench extra): the baseline is skipped")
    rows = []
    with threadpool_limits(1):
        for m in a.modes:
            omega, zeta, phi, maps, b = problem(m)
            tmaps = np.concatenate(list(maps.values()))

            def mine(omega=omega, zeta=zeta, phi=phi, maps=maps, b=b) -> dict[str, Any]:
                return microg_run(omega, zeta, phi, maps, force, b, t)

            def base(omega=omega, zeta=zeta, phi=phi, tmaps=tmaps, b=b) -> np.ndarray:
                assert kernel is not None
                return baseline(kernel, omega, zeta, phi, tmaps, tb, fb, b, t)

            out_m = stacked(mine())
            out_b = base() if kernel is not None else None  # compiles on the first call
            tm, tbl = [], []
            for _ in range(a.rounds):
                t0 = CLOCK()
                mine()
                tm.append(CLOCK() - t0)
                if kernel is not None:
                    t0 = CLOCK()
                    base()
                    tbl.append(CLOCK() - t0)
            idx = np.unique(np.linspace(0, N_T - 1, 400).astype(int))
            ref = direct_reference(omega, zeta, phi, maps, force, b, t, idx)
            err_m = error_of_peak(out_m[..., idx], ref, out_m)
            err_b = error_of_peak(out_b[..., idx], ref, out_m) if out_b is not None else None
            rows.append(
                (m, statistics.median(tm), statistics.median(tbl) if tbl else None, err_m, err_b)
            )
    print(
        f"\n{'modes':>6s} {'microg':>10s} {'numba':>10s} {'ratio':>7s} {'err microg':>11s} "
        f"{'err numba':>10s}"
    )
    for m, tm_, tb_, em, eb in rows:
        if tb_ is None:
            print(f"{m:6d} {tm_ * 1e3:7.1f} ms {'-':>10s} {'-':>7s} {em:11.1e} {'-':>10s}")
        else:
            print(
                f"{m:6d} {tm_ * 1e3:7.1f} ms {tb_ * 1e3:7.1f} ms {tm_ / tb_:6.2f}x "
                f"{em:11.1e} {eb:10.1e}"
            )
    print(
        "(err: largest difference from the direct closed form at 400 times, over each "
        "output's peak; target ratio <= 1.2)"
    )


if __name__ == "__main__":
    main()
