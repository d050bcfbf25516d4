"""Benchmark: exact modal response (microg.dynamics.response) against scipy.signal.lsim, same run.

Problem (the issue's "Speed" item): 100 modes (6 rigid, omega = 0; 94 elastic, 0.1-40 Hz, zeta 0
to 0.02), 20,001 uniform output times over 0-200 s, the report's crew push-off (Eq. 2.16: f0 = 25
lbf = 111.2 N, t1 = 1 s, t13 = 13 s, t14 = 14 s), random mode shapes and three observed points.

Baseline: scipy.signal.lsim on ONE block-diagonal state-space system of all modes (200 states,
outputs eta, eta', eta'').  This is the fastest fair lsim baseline: lsim per mode (100 calls) was
measured ~30 times slower, because each call repeats lsim's Python loop over the 20,001 steps.

lsim interpolates the input linearly between samples, so it cannot represent the push-off's
jumps at t1 and t13: it sees a ramp over the one step before each jump.  For the agreement check
both solvers get exactly that force (breakpoints 0, 0.99, 1, 12.99, 13, 14 s); the size of lsim's
error on the true force (with jumps) is printed separately.

Run:  .venv/bin/python benchmarks/bench_response.py   (about 10 s)
"""

from __future__ import annotations

import importlib.util
import time

import numpy as np
from scipy import signal
from scipy.linalg import block_diag

from microg.dynamics.forces import crew_pushoff, piecewise_linear
from microg.dynamics.response import modal_pwl_response, response_at_points

N_MODES, N_RIGID, N_DOF = 100, 6, 300
T_END, N_T = 200.0, 20_001
REPEAT = 5


def best_of(fn, repeat=REPEAT):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


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

    true_force = crew_pushoff()  # Eq. 2.16 with its jumps
    f0 = true_force.force.max()
    # the force lsim sees: samples of the right-continuous force joined by straight lines
    lsim_force = piecewise_linear(
        [0.0, 1.0 - dt, 1.0, 13.0 - dt, 13.0, 14.0],
        [0.0, f0 * (1.0 - dt), 0.0, 0.0, -f0, 0.0],
        name="push-off as sampled",
    )
    u = lsim_force.at(t)
    assert np.allclose(u, true_force.at(t), rtol=0, atol=1e-9 * f0)  # same samples

    # --- microg: modal kernel, and the full point response (kernel + projection)
    t_kernel, mine = best_of(
        lambda: modal_pwl_response(
            omega, zeta, lsim_force.timepts, np.outer(gamma, lsim_force.force), t
        )
    )
    t_points, pts = best_of(lambda: response_at_points(omega, zeta, phi, points, lsim_force, b, t))

    # --- baseline: lsim on the block-diagonal system; outputs eta, eta', eta''
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
    t_lsim, (_, y, _) = best_of(lambda: signal.lsim((A, B, C, D), u, t), repeat=3)
    ref = {"eta": y[:, :N_MODES].T, "eta_dot": y[:, N_MODES : 2 * N_MODES].T}
    ref["eta_ddot"] = y[:, 2 * N_MODES :].T

    print(
        f"modes {N_MODES} ({N_RIGID} rigid), output times {N_T}, dt {dt:g} s, "
        f"push-off f0 {f0:.4g} N"
    )
    print(f"microg modal_pwl_response : {t_kernel * 1e3:8.1f} ms")
    print(f"microg response_at_points : {t_points * 1e3:8.1f} ms  (kernel + 3 points)")
    print(f"scipy lsim, block-diagonal: {t_lsim * 1e3:8.1f} ms")
    print(f"speed-up (lsim / kernel)  : {t_lsim / t_kernel:8.1f} x")
    for key in ("eta", "eta_dot", "eta_ddot"):
        r, m = ref[key], getattr(mine, key)
        per_mode = np.max(np.abs(m - r), axis=1) / np.max(np.abs(r), axis=1)
        print(f"max difference {key:9s}: {per_mode.max():.2e} of each mode's peak")
    worst = 0.0
    for name, tmap in points.items():
        acc_ref = tmap @ phi @ ref["eta_ddot"]
        diff = np.max(np.abs(pts[name].acceleration - acc_ref)) / np.max(np.abs(acc_ref))
        worst = max(worst, diff)
    print(f"max difference, point accelerations: {worst:.2e} of the peak")

    exact = response_at_points(omega, zeta, phi, points, true_force, b, t)
    acc_true = exact["p1"].acceleration
    acc_lsim = points["p1"] @ phi @ ref["eta_ddot"]
    err = np.max(np.abs(acc_lsim - acc_true)) / np.max(np.abs(acc_true))
    print(f"(lsim on the true push-off with jumps is off by {err:.1e} of the peak at p1)")

    if importlib.util.find_spec("pyyeti") is None:
        print("pyyeti: not installed, comparison skipped")
    else:  # pragma: no cover - optional
        from pyyeti import ode

        k = omega**2
        c = 2 * zeta * omega
        m_ = np.ones(N_MODES)
        force = np.outer(gamma, u)
        ts = ode.SolveUnc(m_, c, k, dt, rf=None)
        t_yeti, sol = best_of(lambda: ts.tsolve(force), repeat=3)
        d = np.max(np.abs(sol.d - ref["eta"]), axis=1) / np.max(np.abs(ref["eta"]), axis=1)
        print(f"pyyeti SolveUnc.tsolve    : {t_yeti * 1e3:8.1f} ms, max diff {d.max():.2e}")


if __name__ == "__main__":
    main()
