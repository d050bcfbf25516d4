"""Benchmark: lowest modes of a >= 100,000-DOF free-free frame model against the strongest baseline.

The model is a generated "comb" station (model trees have no closed loops, so a lattice
truss cannot be a Station): a 300 m keel on a core body, booms of 60 m cantilevered from it
in four directions, each carrying two 30 m masts and a tip panel; elements of about 1 m
(103,344 DOF at the default 140 booms).

Solvers, each on the same matrices, for ``--modes`` 30 and 300 (rigid included):

* ``microg``: ``microg.dynamics.modes.solve_modes``: exact rigid modes, the frame's exact
  tree flexibility (no factorisation), ARPACK on ``G_e M`` (its inverse-form Ritz pairs,
  M-orthonormalised), residual checks, effective masses;
* ``cholmod`` (the strongest baseline): ``eigsh(K, k, M, sigma, OPinv=CHOLMOD(K - sigma M))``
  with scikit-sparse's supernodal Cholesky (the ``cholmod`` extra; when scikit-sparse is not
  installed the table says so and falls back to ``splu``);
* ``splu``: the same with SuperLU and a symmetric ordering (MMD on A^T + A).

Equal accuracy: every baseline gets microg's ARPACK tolerance (``ARPACK_TOL`` = 1e-12) and its
Lanczos basis size (``lanczos_basis_size``), a negative shift ``sigma = -1e-12 max(K_ii/M_ii)``,
nothing deflated and nothing checked, and each Ritz vector's Rayleigh quotient as its eigenvalue
(ARPACK's own values of the near-singular shifted pencil are up to 7e-7 off for the lowest
elastic mode; the quotient, like microg's values, is second order in the vector's error); the
eigenvalues' agreement with microg is printed.

Measurement: each solve runs in its own fresh subprocess (the structure passed as a pickle),
which reports its CPU time (``time.process_time``: the machine's cores are shared, so wall
time would count other processes) and its peak memory above the resident size before the
solve (the kernel's peak-RSS mark, ``VmHWM``, reset before the solve, minus psutil's RSS then:
this sees ARPACK's, SuperLU's and CHOLMOD's own allocations, which tracemalloc does not;
``ru_maxrss`` would count the parent's size at the fork).  ``--rounds`` rounds (default 5), the
solvers interleaved in each, and the median of each solver's times and peaks; BLAS limited to
``--threads`` (default 1) in each subprocess.  Ratios are microg over the strongest baseline.

Run: ``.venv/bin/python benchmarks/bench_modes.py`` (30 modes, 5 rounds: about 1.5 minutes on
the 2-core machine); ``--modes 30 300`` adds the 300-mode row (about 20 minutes: the
300-mode solves are dominated by ARPACK's orthogonalisation).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import pickle
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from threadpoolctl import threadpool_limits

from microg.dynamics.eigsparse import ARPACK_TOL, lanczos_basis_size
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


def have_cholmod() -> bool:
    try:
        import sksparse.cholmod  # noqa: F401
    except ImportError:
        return False
    return True


def _eigsh(K: sp.csr_matrix, M: sp.csr_matrix, k: int, solve: Any, sigma: float) -> np.ndarray:
    n = K.shape[0]
    op = spla.LinearOperator((n, n), matvec=solve, matmat=solve, dtype=float)
    _, vecs = spla.eigsh(
        K,
        k=k,
        M=M,
        sigma=sigma,
        which="LM",
        OPinv=op,
        tol=ARPACK_TOL,
        ncv=lanczos_basis_size(k, n),
    )
    # the Ritz vectors' Rayleigh quotients: ARPACK's values of the near-singular K - sigma M
    # are 7e-7 off for the lowest elastic mode here, the quotient is second order in the
    # vector's error (microg's own values are quotients too): equal accuracy for a few products
    rq = np.einsum("ij,ij->j", vecs, K @ vecs) / np.einsum("ij,ij->j", vecs, M @ vecs)
    return np.sort(rq)


def _cholmod(K: sp.csr_matrix, M: sp.csr_matrix, k: int) -> np.ndarray:
    from sksparse.cholmod import cholesky

    sigma = _shift(K, M)
    factor = cholesky((K - sigma * M).tocsc())
    return _eigsh(K, M, k, factor, sigma)


def _splu(K: sp.csr_matrix, M: sp.csr_matrix, k: int) -> np.ndarray:
    sigma = _shift(K, M)
    lu = spla.splu((K - sigma * M).tocsc(), permc_spec="MMD_AT_PLUS_A")
    return _eigsh(K, M, k, lu.solve, sigma)


def _peak_rss() -> int:
    """This process's peak resident size, bytes: VmHWM (its own address space, reset above);
    ``ru_maxrss`` elsewhere (on Linux it also counts the parent's size at the fork)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def worker(solver: str, path: str, k: int, threads: int) -> None:
    """One solve in this fresh process: prints JSON (CPU s, peak bytes above the start, lam)."""
    import psutil

    with open(path, "rb") as f:
        s = pickle.load(f)
    with contextlib.suppress(OSError):  # reset the peak-RSS mark to the present (Linux >= 4)
        Path("/proc/self/clear_refs").write_text("5")
    rss0 = psutil.Process().memory_info().rss
    with threadpool_limits(limits=threads, user_api="blas"):
        t0 = time.process_time()
        if solver == "microg":
            modes = solve_modes(s, n_modes=k)
            lam = np.sort(modes.omega) ** 2
        else:
            K, M = s.stiffness.tocsr(), s.mass.tocsr()
            lam = (_cholmod if solver == "cholmod" else _splu)(K, M, k)
        cpu = time.process_time() - t0
    peak = _peak_rss()
    print(json.dumps({"cpu": cpu, "peak": max(peak - rss0, 0), "lam": lam.tolist()}))


def run(solver: str, path: str, k: int, threads: int) -> dict[str, Any]:
    cmd = [sys.executable, __file__, "--worker", solver, path, str(k), str(threads)]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--booms", type=int, default=140)
    ap.add_argument("--modes", type=int, nargs="+", default=[30])
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()

    t0 = time.process_time()
    s = build_fem(comb_station(args.booms), max_element_length=1.0)
    t_build = time.process_time() - t0
    K = s.stiffness.tocsr()
    print(
        f"model: {s.meta['n_elements']} elements, {s.n_dof} DOF, nnz(K) = {K.nnz}; "
        f"assembly {t_build:.2f} s CPU; each solve in a fresh subprocess, {args.threads} BLAS "
        f"thread(s), CPU time, median of {args.rounds} interleaved rounds"
    )
    solvers = ["microg", "cholmod", "splu"] if have_cholmod() else ["microg", "splu"]
    if "cholmod" not in solvers:
        print(
            "scikit-sparse is not installed: no CHOLMOD; the strongest baseline falls back to splu"
        )
    rows = []
    with tempfile.TemporaryDirectory() as d:
        path = str(Path(d) / "structure.pkl")
        with open(path, "wb") as f:
            pickle.dump(s, f)
        for k in args.modes:
            res: dict[str, list[dict[str, Any]]] = {v: [] for v in solvers}
            for r in range(args.rounds):
                order = solvers[r % len(solvers) :] + solvers[: r % len(solvers)]
                for v in order:
                    res[v].append(run(v, path, k, args.threads))
            med = {
                v: (
                    statistics.median(x["cpu"] for x in res[v]),
                    statistics.median(x["peak"] for x in res[v]),
                )
                for v in solvers
            }
            ref = np.sqrt(np.clip(np.asarray(res[solvers[1]][0]["lam"]), 0.0, None))
            ours = np.sqrt(np.clip(np.asarray(res["microg"][0]["lam"]), 0.0, None))
            el = slice(6, min(ours.size, ref.size))
            agree = float(np.max(np.abs(ours[el] / ref[el] - 1)))
            rows.append((k, med, agree))
    best = solvers[1]
    print(
        f"\n{'modes':>5s} "
        + " ".join(f"{v + ' s':>10s} {v + ' MB':>11s}" for v in solvers)
        + f" {'time ratio':>10s} {'mem ratio':>9s}  agree"
    )
    for k, med, agree in rows:
        cells = " ".join(f"{med[v][0]:10.2f} {med[v][1] / 1e6:11.0f}" for v in solvers)
        print(
            f"{k:5d} {cells} {med['microg'][0] / med[best][0]:10.2f} "
            f"{med['microg'][1] / med[best][1]:9.2f}  {agree:.1e}"
        )
    print(
        f"(ratios: microg over {best}; targets: time <= 1.2, memory <= 1.5; MB: peak above "
        f"the resident size before the solve; agree: largest relative difference of the "
        f"elastic eigenvalues omega^2)"
    )


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker(sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]))
    else:
        main()
