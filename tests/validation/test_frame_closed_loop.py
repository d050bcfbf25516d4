"""Validation: a free-free closed-loop truss deck against an independent dense solution.

The test writes a NASTRAN deck (mixed small-field and free-field cards, units mm-N-s): a
box truss of CBARs (two rings and four posts: many closed loops) with CROD diagonals,
CONM2s (with offsets and inertia tensors) and a payload on a CBUSH isolator.  It is imported
with :func:`microg.models.bdf.load_bdf` and solved free-free with microg's frame FE.

The reference is a plain dense assembly written here from the textbook element matrices
(Przemieniecki, *Theory of Matrix Structural Analysis*: Eq. 5.115 beam stiffness, Eq. 11.42
consistent mass in NASTRAN's coupled CBAR form under COUPMASS; rod ``EA/L``; the CONM2
rigid-body mass; the CBUSH ``[[k, -k], [-k, k]]``), solved in the deck's own units by scipy
(QZ on the singular lumped-mass pencil, ``eigh`` for the coupled one).  It shares no code
with microg's kernels, assembler, link elimination or condensation.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from microg.dynamics.modes import solve_modes
from microg.models.bdf import load_bdf
from microg.structure.frame import build_frame

E, NU, RHO = 2.1e5, 0.3, 7.85e-9  # N/mm^2, -, t/mm^3 (N s^2/mm^4): steel in mm-N-s
G = E / (2 * (1 + NU))
BAR = dict(A=120.0, I1=3.1e3, I2=1.9e3, J=4.4e3)  # mm^2, mm^4
ROD_A = 30.0
GRIDS = {
    1: (0, 0, 0),
    2: (800, 0, 0),
    3: (800, 600, 0),
    4: (0, 600, 0),
    5: (0, 0, 1000),
    6: (800, 0, 1000),
    7: (800, 600, 1000),
    8: (0, 600, 1000),
    9: (800, 0, 1000),  # payload, coincident with grid 6, on the CBUSH
}
BARS = {
    1: (1, 2, (0, 0, 1)),
    2: (2, 3, (0, 0, 1)),
    3: (3, 4, (0, 0, 1)),
    4: (4, 1, (0, 0, 1)),
    5: (5, 6, (0, 0, 1)),
    6: (6, 7, (0.3, 0, 1)),
    7: (7, 8, (0, 0, 1)),
    8: (8, 5, (0, 0, 1)),
    9: (1, 5, (1, 0, 0)),
    10: (2, 6, (1, 0.2, 0)),
    11: (3, 7, (0, 1, 0)),
    12: (4, 8, (1, 0, 0)),
}
RODS = {21: (1, 6), 22: (2, 7), 23: (3, 8), 24: (4, 5), 25: (1, 3)}
CONM2 = {  # eid: grid, mass (t), offset (mm), (I11, I21, I22, I31, I32, I33) in t mm^2
    31: (1, 0.02, (10.0, 0, 5.0), (40.0, 2.0, 50.0, 0.0, 1.0, 60.0)),
    32: (3, 0.03, (0.0, 0, 0.0), (0.0,) * 6),
    33: (9, 0.05, (0.0, 0, 30.0), (300.0, 10.0, 200.0, 5.0, 0.0, 250.0)),
}
BUSH_K = (2e3, 3e3, 5e3, 4e5, 6e5, 8e5)  # N/mm (1-3), N mm/rad (4-6)


def _f8(x: float) -> str:
    s = f"{x:.8g}"
    if "e" in s:
        m, e = s.split("e")
        s = f"{m if '.' in m else m + '.'}{int(e):+d}"  # NASTRAN's 1.5+3 form
    elif "." not in s:
        s += "."
    return s[:8].rjust(8)


def write_deck(path, coupmass=False):
    lines = ["SOL 103", "CEND", "TITLE = closed-loop truss", "METHOD = 1", "BEGIN BULK"]
    lines.append("PARAM,GRDPNT,0")
    if coupmass:
        lines.append("PARAM,COUPMASS,1")
    for gid, (x, y, z) in GRIDS.items():
        lines.append("GRID    " + f"{gid:>8d}" + " " * 8 + _f8(x) + _f8(y) + _f8(z))
    lines.append(f"MAT1,1,{E:.6e},,{NU},{RHO:.6e}")
    lines.append(f"PBAR,10,1,{BAR['A']},{BAR['I1']},{BAR['I2']},{BAR['J']}")
    lines.append(f"PROD,20,1,{ROD_A}")
    for eid, (a, b, v) in BARS.items():
        lines.append("CBAR    " + f"{eid:>8d}{10:>8d}{a:>8d}{b:>8d}" + "".join(_f8(c) for c in v))
    for eid, (a, b) in RODS.items():
        lines.append(f"CROD,{eid},20,{a},{b}")
    for eid, (g, m, off, inertia) in CONM2.items():
        lines.append(f"CONM2,{eid},{g},0,{m},{off[0]},{off[1]},{off[2]},,+C{eid}")
        lines.append("+C" + str(eid) + "," + ",".join(str(v) for v in inertia))
    lines.append("CBUSH   100     40      6       9                               0")
    lines.append("PBUSH,40,K," + ",".join(f"{k:.6e}" for k in BUSH_K))
    lines.append("EIGRL,1,,,20")
    lines.append("ENDDATA")
    path.write_text("\n".join(lines) + "\n")
    return path


# --------------------------------------------------------------------------- reference


def _beam_k(L, A, I1, I2, J):
    """Przemieniecki Eq. 5.115 in local axes (u, v, w, tx, ty, tz per node)."""
    k = np.zeros((12, 12))
    ea, gj = E * A / L, G * J / L
    k[0, 0] = k[6, 6] = ea
    k[0, 6] = k[6, 0] = -ea
    k[3, 3] = k[9, 9] = gj
    k[3, 9] = k[9, 3] = -gj
    for (v, tz, v2, tz2), ei, s in (((1, 5, 7, 11), E * I1, 1.0), ((2, 4, 8, 10), E * I2, -1.0)):
        c = ei / L**3
        k[v, v] = k[v2, v2] = 12 * c
        k[v, v2] = k[v2, v] = -12 * c
        k[v, tz] = k[tz, v] = k[v, tz2] = k[tz2, v] = s * 6 * L * c
        k[v2, tz] = k[tz, v2] = k[v2, tz2] = k[tz2, v2] = -s * 6 * L * c
        k[tz, tz] = k[tz2, tz2] = 4 * L**2 * c
        k[tz, tz2] = k[tz2, tz] = 2 * L**2 * c
    return k


def _beam_m_coupled(L, m):
    """NASTRAN's coupled CBAR mass as Simcenter Nastran 2020.2 forms it (the deck's COUPMASS).

    Przemieniecki Eq. 11.42 without rotary inertia, no torsional inertia, and without the
    coupling of the two ends' bending rotations (``-3 L^2 m L / 420``): the form fitted to
    that release's runs in ``test_nastran_bar_mass.py``.
    """
    M = np.zeros((12, 12))
    for a, b in ((0, 6),):
        M[a, a] = M[b, b] = m * L / 3
        M[a, b] = M[b, a] = m * L / 6
    c = m * L / 420
    for (v, t, v2, t2), s in (((1, 5, 7, 11), 1.0), ((2, 4, 8, 10), -1.0)):
        M[v, v] = M[v2, v2] = 156 * c
        M[v, v2] = M[v2, v] = 54 * c
        M[v, t] = M[t, v] = s * 22 * L * c
        M[v2, t2] = M[t2, v2] = -s * 22 * L * c
        M[v, t2] = M[t2, v] = -s * 13 * L * c
        M[v2, t] = M[t, v2] = s * 13 * L * c
        M[t, t] = M[t2, t2] = 4 * L**2 * c
    return M


def _skew(d):
    return np.array([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])


def reference(coupmass: bool) -> np.ndarray:
    """Elastic eigenvalues (1/s^2) of the deck by plain dense assembly in mm-N-s."""
    ids = sorted(GRIDS)
    pos = {g: np.array(GRIDS[g], float) for g in ids}
    n = 6 * len(ids)
    K = np.zeros((n, n))
    M = np.zeros((n, n))

    def dofs(g):
        i = ids.index(g)
        return np.arange(6 * i, 6 * i + 6)

    for a, b, v in BARS.values():
        d = pos[b] - pos[a]
        L = np.linalg.norm(d)
        ex = d / L
        ey = np.array(v, float) - np.dot(v, ex) * ex
        ey /= np.linalg.norm(ey)
        lam = np.array([ex, ey, np.cross(ex, ey)])
        Tm = np.kron(np.eye(4), lam)
        ke = Tm.T @ _beam_k(L, **BAR) @ Tm
        mpl = RHO * BAR["A"]
        if coupmass:
            me = Tm.T @ _beam_m_coupled(L, mpl) @ Tm
        else:  # NASTRAN CBAR lumped: half the mass on each end's translations
            me = np.diag(np.r_[[mpl * L / 2] * 3, [0.0] * 3, [mpl * L / 2] * 3, [0.0] * 3])
        d12 = np.r_[dofs(a), dofs(b)]
        K[np.ix_(d12, d12)] += ke
        M[np.ix_(d12, d12)] += me
    for a, b in RODS.values():
        d = pos[b] - pos[a]
        L = np.linalg.norm(d)
        nn = np.outer(d, d) / L**2
        ka = E * ROD_A / L * np.block([[nn, -nn], [-nn, nn]])
        mrod = RHO * ROD_A * L
        mm = (
            mrod / 6 * np.block([[2 * np.eye(3), np.eye(3)], [np.eye(3), 2 * np.eye(3)]])
            if coupmass
            else mrod / 2 * np.eye(6)
        )
        t = np.r_[dofs(a)[:3], dofs(b)[:3]]
        K[np.ix_(t, t)] += ka
        M[np.ix_(t, t)] += mm
    for g, m, off, (i11, i21, i22, i31, i32, i33) in CONM2.values():
        dd = np.array(off, float)
        J = np.array([[i11, -i21, -i31], [-i21, i22, -i32], [-i31, -i32, i33]])
        S = _skew(dd)
        blk = np.block(
            [[m * np.eye(3), -m * S], [m * S, J + m * (dd @ dd * np.eye(3) - np.outer(dd, dd))]]
        )
        M[np.ix_(dofs(g), dofs(g))] += blk
    kb = np.diag(BUSH_K)
    d12 = np.r_[dofs(6), dofs(9)]
    K[np.ix_(d12, d12)] += np.block([[kb, -kb], [-kb, kb]])
    if coupmass:
        lam = sla.eigh(K, M, eigvals_only=True)
    else:
        w = sla.eig(K, M, right=False)
        lam = np.sort(np.real(w[np.isfinite(w)]))
    return lam[lam > 1e-6 * lam.max()]


@pytest.mark.parametrize("coupmass", [False, True], ids=["lumped", "coupmass"])
def test_closed_loop_truss_matches_dense_reference(tmp_path, coupmass):
    deck = write_deck(tmp_path / "truss.bdf", coupmass)
    graph = load_bdf(deck, units="mm, N, s")
    assert graph.mass_formulation == ("coupled" if coupmass else "lumped")
    assert len(graph.beams) == 12 and len(graph.rods) == 5 and len(graph.springs) == 1
    structure = build_frame(graph)
    modes = solve_modes(structure, structure.n_dof)  # all modes
    # exactly six rigid-body modes, exactly zero: free-free
    assert modes.n_rigid == 6
    assert np.all(modes.omega[modes.rigid] == 0.0)
    assert np.all(modes.omega[~modes.rigid] > 0.0)
    lam = np.sort(modes.omega[~modes.rigid] ** 2)
    ref = reference(coupmass)
    # same count and values; frequencies are unit-free (1/s^2) so the mm-N-s reference
    # checks the unit conversion too.  Tolerance: the reference's QZ/eigh error is ~eps of
    # the largest eigenvalue (spread ~1e5 here): 1e-8 relative is far above it and far
    # below any modelling difference (a 1e-3 change of one stiffness moves modes by ~1e-4)
    assert lam.size == ref.size
    np.testing.assert_allclose(lam, ref, rtol=1e-8)


def test_truss_mass_matches_hand_sum(tmp_path):
    # total mass: bars rho A L, rods rho A L, CONM2s; 1 t = 1000 kg
    graph = load_bdf(write_deck(tmp_path / "truss.bdf"), units="mm, N, s")
    s = build_frame(graph)
    pos = {g: np.array(v, float) for g, v in GRIDS.items()}
    lb = sum(np.linalg.norm(pos[b] - pos[a]) for a, b, _ in BARS.values())
    lr = sum(np.linalg.norm(pos[b] - pos[a]) for a, b in RODS.values())
    total_t = RHO * (BAR["A"] * lb + ROD_A * lr) + sum(c[1] for c in CONM2.values())
    assert s.total_mass == pytest.approx(1000.0 * total_t, rel=1e-12)
