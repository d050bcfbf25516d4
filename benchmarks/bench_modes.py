"""Benchmark: lowest modes of a >= 100,000-DOF free-free frame model against strong baselines.

The model is a generated "comb" station (model trees have no closed loops, so a lattice
truss cannot be a Station): a 300 m keel on a core body, booms of 60 m cantilevered from it
in four directions, each carrying two 30 m masts and a tip panel; elements of about 1 m.

Timed in one process, on the same matrices, for ``--modes`` 30 and 300 (rigid included) and
with 1 and 2 BLAS threads (threadpoolctl):

* ``microg.dynamics.modes.solve_modes``: exact rigid modes, the frame's exact tree
  flexibility (no factorisation), ARPACK on ``G_e M`` (its inverse-form Ritz pairs,
  M-orthonormalised), residual checks, effective masses;
* baseline ``cholmod``: ``eigsh(K, k, M, sigma, OPinv=CHOLMOD(K - sigma M))`` with
  scikit-sparse's supernodal Cholesky (the best factorisation available; skipped with a note
  when scikit-sparse is not installed);
* baseline ``splu``: the same with SuperLU and a symmetric ordering (MMD on A^T + A);
* baseline ``eigsh``: plain ``eigsh(K, k, M, sigma)`` (scipy factorises internally).

Every baseline has ARPACK's default basis (``ncv = 2k + 1``), a negative shift
``sigma = -1e-12 max(K_ii/M_ii)``, nothing deflated and nothing checked; the ratio printed is
microg's time over the fastest baseline.  (The thread setting applies to microg and the
baselines alike: microg's library calls never change it.)
Run: ``.venv/bin/python benchmarks/bench_modes.py`` (the 103k-DOF model, 30 modes, one
thread: under a minute); the full table is
``.venv/bin/python benchmarks/bench_modes.py --modes 30 300 --threads 1 2`` (about 15 minutes
on the 2-core machine: the 300-mode runs are dominated by ARPACK's orthogonalisation).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from threadpoolctl import threadpool_limits

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


def _shift(K: sp.csr_matrix, M: sp.csr_matrix) -> float:
    return -1e-12 * float(np.max(K.diagonal() / M.diagonal()))


def _cholmod(K: sp.csr_matrix, M: sp.csr_matrix, k: int) -> np.ndarray | None:
    try:
        from sksparse.cholmod import cholesky
    except ImportError:
        return None
    sigma = _shift(K, M)
    factor = cholesky((K - sigma * M).tocsc())
    n = K.shape[0]
    op = spla.LinearOperator((n, n), matvec=factor, matmat=factor, dtype=float)
    lam, _ = spla.eigsh(K, k=k, M=M, sigma=sigma, which="LM", OPinv=op)
    return lam


def _splu(K: sp.csr_matrix, M: sp.csr_matrix, k: int) -> np.ndarray:
    sigma = _shift(K, M)
    lu = spla.splu((K - sigma * M).tocsc(), permc_spec="MMD_AT_PLUS_A")
    n = K.shape[0]
    op = spla.LinearOperator((n, n), matvec=lu.solve, matmat=lu.solve, dtype=float)
    lam, _ = spla.eigsh(K, k=k, M=M, sigma=sigma, which="LM", OPinv=op)
    return lam


def _plain(K: sp.csr_matrix, M: sp.csr_matrix, k: int) -> np.ndarray:
    lam, _ = spla.eigsh(K, k=k, M=M, sigma=_shift(K, M), which="LM")
    return lam


def _timed(fn: Callable[[], Any], threads: int) -> tuple[float, Any]:
    with threadpool_limits(limits=threads, user_api="blas"):
        t0 = time.perf_counter()
        out = fn()
        return time.perf_counter() - t0, out


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--booms", type=int, default=140)
    ap.add_argument("--modes", type=int, nargs="+", default=[30])
    ap.add_argument("--threads", type=int, nargs="+", default=[1])
    ap.add_argument("--no-plain", action="store_true", help="skip the plain eigsh baseline")
    args = ap.parse_args()

    t0 = time.perf_counter()
    s = build_fem(comb_station(args.booms), max_element_length=1.0)
    t_build = time.perf_counter() - t0
    K, M = s.stiffness.tocsr(), s.mass.tocsr()
    print(
        f"model: {s.meta['n_elements']} elements, {s.n_dof} DOF, nnz(K) = {K.nnz}; "
        f"assembly {t_build:.2f} s"
    )
    for k in args.modes:
        for th in args.threads:
            t_ours, modes = _timed(lambda k=k: solve_modes(s, n_modes=k), th)
            base: dict[str, float] = {}
            lam_ref = None
            t, lam = _timed(lambda k=k: _cholmod(K, M, k), th)
            if lam is not None:
                base["cholmod"], lam_ref = t, lam
            t, lam = _timed(lambda k=k: _splu(K, M, k), th)
            base["splu"] = t
            lam_ref = lam if lam_ref is None else lam_ref
            if not args.no_plain:
                base["eigsh"], _ = _timed(lambda k=k: _plain(K, M, k), th)
            best = min(base, key=lambda b: base[b])
            ref = np.sqrt(np.clip(np.sort(lam_ref), 0.0, None))
            el = modes.omega[~modes.rigid]
            agree = float(np.max(np.abs(el / ref[6 : 6 + el.size] - 1)))
            note = "" if "cholmod" in base else " (scikit-sparse not installed: no CHOLMOD)"
            print(
                f"modes={k:>4} threads={th}: solve_modes {t_ours:6.2f} s; "
                + ", ".join(f"{b} {t:6.2f} s" for b, t in base.items())
                + f"; ratio to best ({best}) = {t_ours / base[best]:.2f}; "
                f"frequencies agree to {agree:.1e}{note}"
            )


if __name__ == "__main__":
    main()
