"""Benchmark: lowest 30 modes (rigid ones included) of a >= 100,000-DOF free-free frame model.

The model is a generated "comb" station (model trees have no closed loops, so a lattice
truss cannot be a Station): a 300 m keel on a core body, 140 booms of 60 m cantilevered from
it in four directions, each carrying two 30 m masts and a tip panel; elements of about 1 m.

Timed in one process, on the same matrices:

* ``microg.dynamics.modes.solve_modes`` (exact rigid modes + deflated shift-invert, checks);
* baseline: ``scipy.sparse.linalg.eigsh(K, k=36, M=M, sigma=<same shift>, which="LM")``,
  the plain shift-invert call with nothing deflated or checked.

Run: ``.venv/bin/python benchmarks/bench_modes.py`` (add ``--booms 40`` for a quick run).
"""

from __future__ import annotations

import argparse
import resource
import time
import tracemalloc

import numpy as np
import scipy.sparse.linalg as spla

from microg.dynamics.eigsparse import SHIFT_FRACTION
from microg.dynamics.modes import solve_modes
from microg.models.station import Beam, NamedPoint, Orbit, PointMass, RigidBody, Station
from microg.structure.fem import build_fem


def comb_station(n_booms: int = 140) -> Station:
    """A keel with ``n_booms`` booms, two masts per boom, point masses, named points."""
    z = np.array([0.0, 0.0, 1.0])
    core = RigidBody(
        "core",
        tuple(
            PointMass(
                f"module{i}", 2.0e4, np.array([0.0, 0.0, -5.0 - 6.0 * i]), np.diag([1e5, 1e5, 2e4])
            )
            for i in range(5)
        ),
    )
    keel = Beam(
        "keel", "core", np.zeros(3), z, 300.0, np.array([1.0, 0, 0]), 5e8, 5e8, 4e8, 2e10, 200.0
    )
    beams = [keel]
    dirs = [np.array(d, float) for d in ((0, 1, 0), (1, 0, 0), (0, -1, 0), (-1, 0, 0))]
    for i in range(n_booms):
        d = dirs[i % 4]
        root = np.array([0.0, 0.0, 300.0 * (i + 1) / (n_booms + 1)])
        tip = root + 60.0 * d
        name = f"boom{i}"
        beams.append(
            Beam(
                name,
                "keel",
                root,
                d,
                60.0,
                z,
                1e8,
                1e8,
                8e7,
                5e9,
                40.0,
                (PointMass("panel", 500.0, tip, np.diag([50.0, 50.0, 50.0])),),
            )
        )
        for j, s in enumerate((20.0, 45.0)):
            beams.append(
                Beam(f"{name}m{j}", name, root + s * d, z, 30.0, d, 2e7, 2e7, 1.5e7, 1e9, 15.0)
            )
    points = (
        NamedPoint("lab", "core", np.array([0.0, 0.0, -11.0]), "experiment"),
        NamedPoint("keel-tip", "keel", np.array([0.0, 0.0, 300.0])),
    )
    return Station("comb", (core,), tuple(beams), points, Orbit(6.87e6))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--booms", type=int, default=140)
    ap.add_argument("--modes", type=int, default=30)
    args = ap.parse_args()

    t0 = time.perf_counter()
    station = comb_station(args.booms)
    s = build_fem(station, max_element_length=1.0)
    t_build = time.perf_counter() - t0
    n = s.n_dof
    print(
        f"model: {len(station.beams)} beams, {s.meta['n_elements']} elements, {n} DOF, "
        f"nnz(K) = {s.stiffness.nnz}; assembly {t_build:.2f} s"
    )

    tracemalloc.start()
    t0 = time.perf_counter()
    modes = solve_modes(s, n_modes=args.modes)
    t_ours = time.perf_counter() - t0
    peak_ours = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    rss_ours = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    sigma = -SHIFT_FRACTION * float(np.max(s.stiffness.diagonal() / s.mass.diagonal()))
    tracemalloc.start()
    t0 = time.perf_counter()
    lam, _ = spla.eigsh(s.stiffness, k=args.modes + 6, M=s.mass, sigma=sigma, which="LM")
    t_base = time.perf_counter() - t0
    peak_base = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    rss_all = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    base = np.sqrt(np.clip(np.sort(lam), 0, None))
    el = modes.omega[~modes.rigid]
    n_el = el.size
    agree = np.max(np.abs(el / base[6 : 6 + n_el] - 1))
    print(
        f"solve_modes: {modes.n_modes} modes ({modes.n_rigid} rigid, omega = 0 exactly) "
        f"in {t_ours:.2f} s, tracemalloc peak {peak_ours / 2**20:.0f} MiB, "
        f"maxrss {rss_ours:.0f} MiB"
    )
    print(
        f"baseline eigsh(k={args.modes + 6}, sigma={sigma:.3e}): {t_base:.2f} s, "
        f"tracemalloc peak {peak_base / 2**20:.0f} MiB, maxrss after both {rss_all:.0f} MiB"
    )
    print(f"  baseline's 6 lowest |omega| (should be 0): {np.max(base[:6]):.2e} rad/s")
    print(
        f"ratio time solve_modes / eigsh = {t_ours / t_base:.2f}; "
        f"elastic frequencies agree to {agree:.1e} relative"
    )
    print(f"first elastic frequencies (Hz): {np.round(el[:6] / (2 * np.pi), 5)}")
    print(f"whole modal analysis (assembly + solve_modes): {t_build + t_ours:.2f} s")


if __name__ == "__main__":
    main()
