"""Benchmark: a lumped-mass shell model above the dense-condensation limit, solved sparsely.

A generated free-free CQUAD4 plate deck (``n x n`` elements, 2.0 x 1.3 m, t = 10 mm,
aluminium, an offset CONM2 at grid 1; no PARAM,COUPMASS: NASTRAN's lumped mass, every
rotation massless) is read, built and solved for 30 modes.  Its massless rotations are more
than :data:`~microg.structure.frame.CONDENSE_MAX` allows to condense into a dense stiffness,
so :func:`~microg.structure.frame.build_frame` keeps them as coordinates (sparse K, sparse
positive semi-definite M) and :func:`~microg.dynamics.eigsparse.solve_sparse` solves the
pencil.  The baseline, in the same run, is scipy's shift-invert Lanczos on the same pencil
(``eigsh(K, 30, M, sigma=-sigma0)`` with ``sigma0`` 1e-3 of the mean ``K_ii/M_ii`` of the
massive coordinates, so that ``K + sigma0 M`` is positive definite; scipy factors it with
SuperLU's defaults): no exact rigid modes, no residual check, the frequencies compared.
(The shells' consistent mass is translational too, so ``mass="consistent"`` is no
massless-free baseline: its rotations are kept in the same way.)

Each solve runs in a fresh process so that its peak resident size (``VmHWM``, reset before
the build) is its own.

Run: ``.venv/bin/python benchmarks/bench_lumped_shell.py [n]`` (default 45: 2,116 grids,
12,696 DOFs; about 15 s).
"""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def plate_deck(path: Path, nx: int, ny: int, lx: float = 2.0, ly: float = 1.3) -> int:
    """Write the plate deck; return the number of grids."""
    lines = ["BEGIN BULK", "MAT1,1,7.0+10,,0.3,2700.", "PSHELL,1,1,0.01,1,,1"]

    def gid(i: int, j: int) -> int:
        return 1 + i + (nx + 1) * j

    for j in range(ny + 1):
        for i in range(nx + 1):
            lines.append(f"GRID,{gid(i, j)},,{lx * i / nx:.6f},{ly * j / ny:.6f},0.")
    for e, (i, j) in enumerate(((i, j) for j in range(ny) for i in range(nx)), start=1):
        lines.append(
            f"CQUAD4,{e},1,{gid(i, j)},{gid(i + 1, j)},{gid(i + 1, j + 1)},{gid(i, j + 1)}"
        )
    lines += ["CONM2,90001,1,,5.0,0.01,0.02,0.03", "ENDDATA"]
    path.write_text("\n".join(lines) + "\n")
    return (nx + 1) * (ny + 1)


def _peak_rss() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def worker(path: str, solver: str) -> None:
    """Build and solve in this process; print JSON (times, peak bytes, sizes, frequencies)."""
    import numpy as np

    from microg.dynamics.modes import solve_modes
    from microg.models.bdf import load_bdf
    from microg.structure.frame import build_frame

    g = load_bdf(path, units="m, N, s")
    with contextlib.suppress(OSError):  # reset the peak-RSS mark to the present (Linux >= 4)
        Path("/proc/self/clear_refs").write_text("5")
    t0 = time.perf_counter()
    s = build_frame(g)
    t1 = time.perf_counter()
    out = {"n_dof": s.n_dof, "massless_kept": s.meta["massless_kept"], "build": t1 - t0}
    if solver == "microg":
        md = solve_modes(s, 30)
        f = md.freq_hz
        out["n_rigid"] = md.n_rigid
        out["eff"] = {d: float(np.sum(md.effective_mass[d]) / s.total_mass) for d in "xyz"}
    else:
        import scipy.sparse as sp
        import scipy.sparse.linalg as spla

        K, M = sp.csc_matrix(s.stiffness), sp.csc_matrix(s.mass)
        dm, dk = M.diagonal(), K.diagonal()
        sigma0 = 1e-3 * float(np.mean(dk[dm > 0] / dm[dm > 0]))
        lam = np.sort(spla.eigsh(K, 30, M, sigma=-sigma0, which="LM")[0])
        f = np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)
    out["solve"] = time.perf_counter() - t1
    out["peak"] = _peak_rss()
    out["f_hz"] = np.asarray(f, float).tolist()
    print(json.dumps(out))


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker(sys.argv[2], sys.argv[3])
        return
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 45
    with tempfile.TemporaryDirectory() as tmp:
        deck = Path(tmp) / "plate.dat"
        nn = plate_deck(deck, n, n)
        print(f"lumped CQUAD4 plate: {nn} grids, {n * n} elements, 1 CONM2")
        out = {}
        for solver in ("microg", "scipy"):
            run = subprocess.run(
                [sys.executable, __file__, "--worker", str(deck), solver],
                check=True,
                capture_output=True,
                text=True,
            )
            out[solver] = r = json.loads(run.stdout.strip().splitlines()[-1])
            print(
                f"{solver:7s} {r['n_dof']} DOFs ({r['massless_kept']} massless kept): build "
                f"{r['build']:.2f} s, 30 modes {r['solve']:.2f} s, peak RSS "
                f"{r['peak'] / 2**20:.0f} MiB; f7-10 "
                f"{', '.join(f'{f:.6f}' for f in r['f_hz'][6:10])} Hz"
            )
        mg, sc = out["microg"], out["scipy"]
        eff = " ".join(f"{mg['eff'][d]:.12f}" for d in "xyz")
        rel = max(abs(a / b - 1) for a, b in zip(mg["f_hz"][6:], sc["f_hz"][6:], strict=True))
        print(f"microg: {mg['n_rigid']} rigid modes (exact 0), effective mass x/y/z {eff}")
        print(
            f"microg / scipy: solve {mg['solve'] / sc['solve']:.2f}x, peak RSS "
            f"{mg['peak'] / sc['peak']:.2f}x; elastic frequencies agree to {rel:.1e}"
        )


if __name__ == "__main__":
    main()
