"""Benchmark: a 20,000-grid, 200-mode modal model written and read back, then a push-off
analysed at 10 grids.  The analysis (Structure with maps for the 11 grids used, modes,
exact response) must take less than 3x the time of reading the file alone.

Run: .venv/bin/python benchmarks/bench_modal_io.py [--grids N] [--modes M] [--uff]
(--uff also times the full-size UFF text file, ~0.4 GB: minutes).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from microg.dynamics.forces import ForceHistory
from microg.dynamics.modes import solve_modes
from microg.dynamics.response import generalized_force_vector, response_at_points
from microg.models.modal import (
    build_modal_model,
    load_modal_model,
    parse_units,
    rigid_basis_at,
    save_modal_model,
)
from microg.models.uff import modal_model_from_uff, write_uff_modes
from microg.structure.modal import modal_structure


def make_model(g: int, m: int):
    rng = np.random.default_rng(0)
    xyz = rng.uniform(-50, 50, (g, 3))
    R = rigid_basis_at(xyz).reshape(-1, 6)
    q, _ = np.linalg.qr(R)
    el = rng.standard_normal((6 * g, m - 6))
    el -= q @ (q.T @ el)  # orthogonal to the rigid span (identity-mass stand-in)
    phi = np.concatenate([q, el / np.linalg.norm(el, axis=0)], axis=1).reshape(g, 6, m)
    f = np.r_[rng.uniform(1e-4, 1e-2, 6), np.sort(rng.uniform(0.1, 10.0, m - 6))]
    return build_modal_model(
        name="bench",
        grid_ids=np.arange(1, g + 1),
        xyz_m=xyz,
        freq_hz_signed=f,
        phi=phi,
        units=parse_units("m, N, s"),
        source="bench",
        rigid_mass=None,
    )


def analyse(model) -> float:
    t0 = time.perf_counter()
    obs = [f"grid:{i}" for i in range(100, 20000, 1990)][:10]
    st = modal_structure(model, ["grid:1", *obs], samples=False)
    md = solve_modes(st)
    f = ForceHistory(np.array([0.0, 0.5, 1.0, 1.5]), np.array([0.0, 100.0, 100.0, 0.0]))
    b = generalized_force_vector(st.point("grid:1").translation, np.array([1.0, 0.0, 0.0]))
    z = np.where(md.rigid, 0.0, 0.005)
    maps = {n: st.point(n).translation for n in obs}
    response_at_points(md.omega, z, md.phi, maps, f, b, np.arange(0.0, 200.0, 0.01))
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--grids", type=int, default=20000)
    ap.add_argument("--modes", type=int, default=200)
    ap.add_argument("--uff", action="store_true")
    a = ap.parse_args()
    model = make_model(a.grids, a.modes)
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "m.npz"
        t0 = time.perf_counter()
        save_modal_model(model, p)
        tw = time.perf_counter() - t0
        t0 = time.perf_counter()
        back = load_modal_model(p)
        tr = time.perf_counter() - t0
        ta = analyse(back)
        print(f"own .npz ({p.stat().st_size / 1e6:.0f} MB): write {tw:.2f} s, read {tr:.2f} s")
        print(f"analysis (push-off at 1 grid, 10 observed, 200 s at 0.01 s): {ta:.2f} s")
        print(f"ratio analysis / read (own format): {ta / tr:.2f} (must be < 3)")
        g_uff = a.grids if a.uff else 2000
        small = model if a.uff else make_model(g_uff, a.modes)
        u = Path(d) / "m.unv"
        t0 = time.perf_counter()
        write_uff_modes(small, u)
        tw = time.perf_counter() - t0
        t0 = time.perf_counter()
        modal_model_from_uff(u)
        tr = time.perf_counter() - t0
        print(
            f"UFF ({g_uff} grids, {u.stat().st_size / 1e6:.0f} MB): "
            f"write {tw:.2f} s, read {tr:.2f} s"
        )


if __name__ == "__main__":
    main()
