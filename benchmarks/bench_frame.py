"""Benchmark of the general frame FE (graph assembly and BDF import) against strong baselines.

A generated lattice truss deck (CBARs along x, y and z between the nodes of an
``n x n x m`` grid, closed loops everywhere, CONM2s on one face, PARAM,COUPMASS,1) is:

1. read: ``microg.models.bdf.read_cards`` against the lower bound of any card reader in
   Python, a ``str.split`` of every line into its fields and ``float()`` of each (no
   continuation, card or error logic);
2. assembled: ``microg.structure.frame.build_frame`` (element kernels, transformation,
   COO assembly, rigid vectors, maps) against scipy's CSR conversion of precomputed
   element matrices scattered to the same DOFs, the unavoidable cost of any sparse
   assembler (the element matrices themselves are free in the baseline);
3. with ``--modes``, solved for 30 modes (``microg.dynamics.modes.solve_modes``), for scale
   only: the sparse shift-invert's SuperLU factorisation of a 3-D lattice this size takes
   about a minute (35,000 DOFs, 78 million factor entries with COLAMD), which is the
   solver's, not the assembly's, cost.

Run: ``.venv/bin/python benchmarks/bench_frame.py [n] [m] [--modes]`` (default 22 x 22 x 12
nodes, about 16,000 elements; about 20 s without ``--modes``).
"""

from __future__ import annotations

import contextlib
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from microg.dynamics.modes import solve_modes
from microg.models.bdf import load_bdf, read_cards
from microg.structure.frame import build_frame


def best_of(fn: Callable[[], Any], repeat: int = 3) -> tuple[float, Any]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def lattice_deck(path: Path, n: int, m: int) -> tuple[int, int]:
    """Write the lattice deck; return (nodes, elements)."""
    lines = [
        "BEGIN BULK",
        "PARAM,COUPMASS,1",
        "MAT1,1,7.0+10,,0.3,2700.",
        "PBAR,1,1,1.0-3,2.0-7,3.0-7,4.0-7",
    ]

    def gid(i: int, j: int, k: int) -> int:
        return 1 + i + n * (j + n * k)

    for k in range(m):
        for j in range(n):
            for i in range(n):
                lines.append(f"GRID,{gid(i, j, k)},,{0.5 * i},{0.5 * j},{0.7 * k}")
    eid = 0
    for k in range(m):
        for j in range(n):
            for i in range(n):
                for di, dj, dk, v in (
                    (1, 0, 0, "0.,0.,1."),
                    (0, 1, 0, "0.,0.,1."),
                    (0, 0, 1, "1.,0.,0."),
                ):
                    a, b, c = i + di, j + dj, k + dk
                    if a < n and b < n and c < m:
                        eid += 1
                        lines.append(f"CBAR,{eid},1,{gid(i, j, k)},{gid(a, b, c)},{v}")
    for j in range(n):
        for i in range(n):
            lines.append(f"CONM2,{900000 + gid(i, j, 0)},{gid(i, j, 0)},,5.0,,,,,+")
            lines.append("+,0.1,,0.1,,,0.1")
    lines.append("ENDDATA")
    path.write_text("\n".join(lines) + "\n")
    return n * n * m, eid


def split_baseline(path: Path) -> int:
    """Lower bound of a card reader: split each line at commas and convert the numbers."""
    count = 0
    for line in path.read_text().splitlines():
        for f in line.split(",")[1:]:
            with contextlib.suppress(ValueError):
                float(f)
            count += 1
    return count


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    n = int(args[0]) if args else 22
    m = int(args[1]) if len(args) > 1 else 12
    with tempfile.TemporaryDirectory() as tmp:
        deck = Path(tmp) / "lattice.bdf"
        nn, ne = lattice_deck(deck, n, m)
        size_mb = deck.stat().st_size / 1e6
        print(f"lattice deck: {nn} grids, {ne} CBARs, {n * n} CONM2s ({size_mb:.1f} MB)")
        t_read, _ = best_of(lambda: read_cards(deck))
        t_split, _ = best_of(lambda: split_baseline(deck))
        print(
            f"read_cards {t_read:.3f} s; split+float baseline {t_split:.3f} s; "
            f"ratio {t_read / t_split:.1f}"
        )
        t_load, graph = best_of(lambda: load_bdf(deck, units="m, N, s"))
        print(f"load_bdf (read + convert + validate) {t_load:.3f} s")
    t_build, s = best_of(lambda: build_frame(graph))
    # baseline: scatter precomputed 12x12 element matrices to the same DOFs (CSR conversion)
    index = graph.node_index()
    a = np.array([index[b.nodes[0]] for b in graph.beams])
    b = np.array([index[b.nodes[1]] for b in graph.beams])
    dofs = np.concatenate([6 * a[:, None] + np.arange(6), 6 * b[:, None] + np.arange(6)], 1)
    vals = np.random.default_rng(0).standard_normal((ne, 12, 12))
    rows = np.broadcast_to(dofs[:, :, None], (ne, 12, 12)).ravel()
    cols = np.broadcast_to(dofs[:, None, :], (ne, 12, 12)).ravel()
    size = 6 * nn

    def scatter() -> sp.csr_matrix:
        k = sp.coo_matrix((vals.ravel(), (rows, cols)), shape=(size, size)).tocsr()
        mm = sp.coo_matrix((vals.ravel(), (rows, cols)), shape=(size, size)).tocsr()
        return k + mm

    t_scatter, _ = best_of(scatter)
    print(
        f"build_frame {t_build:.3f} s ({s.n_dof} DOFs); scatter-only baseline (K and M) "
        f"{t_scatter:.3f} s; ratio {t_build / t_scatter:.1f}"
    )
    if "--modes" not in sys.argv:
        return
    t_modes, modes = best_of(lambda: solve_modes(s, 30), repeat=1)
    print(
        f"solve_modes 30 modes {t_modes:.2f} s: {modes.n_rigid} rigid, "
        f"first elastic {modes.freq_hz[6]:.3f} Hz"
    )


if __name__ == "__main__":
    main()
