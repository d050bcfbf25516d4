"""RBE3 (rotations, UM), MPC and SPOINT in real NX decks against NX's own output.

References: NX 9's GM matrix (the m-set as a function of the n-set) of nine one-RBE3 decks from
pyyeti's wheel (``tests/data/nastran/gm/``: the ``.mat`` beside each deck holds NX's GM and USET
from the same run); NX's first real eigenvalue table in ``outboard.out`` of
``nas2cam_extseout`` (a deck with SPOINTs, an RBE2, an RBE3 and an MPC on one grid).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.models.bdf import load_bdf
from microg.models.graph_model import Constraint
from microg.structure.assembly import assemble_frame
from microg.structure.frame import build_frame

DATA = Path(__file__).resolve().parents[1] / "data" / "nastran"
GM_DECKS = sorted(p.stem for p in (DATA / "gm").glob("make_gm_nx9_rbe3_*.dat"))


def _nx_gm(stem: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """NX's GM (m x n), and the USET's grid ids, components and m-set flags (g-set order)."""
    sio = pytest.importorskip("scipy.io")
    d = sio.loadmat(DATA / "gm" / f"{stem}.mat")
    gm = d["gm"][0][0][0]
    uset = d["uset"][0][0][0]
    ids = uset[:, 0].astype(int)
    comp = uset[:, 1].astype(int)
    m_set = (uset[:, 2].astype(int) & 1) != 0  # USET bit 1: the m-set (pyyeti mkusetmask)
    return gm, ids, comp, m_set


def test_nine_decks_found():
    assert len(GM_DECKS) == 9


@pytest.mark.parametrize("stem", GM_DECKS)
def test_rbe3_constraint_matrix_equals_nx_gm(stem):
    gm, ids, comp, m_set = _nx_gm(stem)
    # units "m, N, s" keep the deck's own numbers: GM's translation-rotation terms are lengths
    g = load_bdf(DATA / "gm" / f"{stem}.dat", units="m, N, s")
    fm = assemble_frame(g)
    idx = g.node_index()
    # NX's g-set DOFs (each grid's components along its CD axes) from microg's basic DOFs
    A = np.zeros((ids.size, fm.transform.shape[0]))
    for r, (gid, c) in enumerate(zip(ids, comp, strict=True)):
        i = idx[f"grid:{gid}"]
        b = 3 * ((c - 1) // 3)
        A[r, 6 * i + b : 6 * i + b + 3] = g.nodes[i].axes[(c - 1) % 3]
    U = A @ fm.transform.toarray()  # g-set from microg's independent coordinates
    Un, Um = U[~m_set], U[m_set]
    assert Un.shape[0] == Un.shape[1] == fm.transform.shape[1]  # same number of dependents
    mine = Um @ np.linalg.inv(Un)  # the m-set as a function of NX's n-set
    # tolerance: pyyeti's independent formrbe3 differs from NX's GM by up to 2.6e-8 of the
    # largest term on these decks (rbe3_1, rbe3_um_1), microg from pyyeti by round-off; 1e-7
    # is 4x that, and any formulation slip (the L_c^2 scaling, an axis, a UM solve) is > 1e-3
    np.testing.assert_allclose(mine, gm, rtol=0, atol=1e-7 * np.abs(gm).max())


def test_outboard_with_spoints_rbe2_rbe3_mpc_matches_nx_fixed_interface_modes():
    g = load_bdf(DATA / "extseout_outboard.dat", units="m, N, s", coupled_mass="coupled-nx9")
    assert [m.terms for m in g.mpcs] == [(("grid:60", 4, 1.0), ("spoint:1995003", 1, 1.0))]
    assert g.interpolations[0].components == "26" and g.rigid_links[0].components == "1"
    assert sum(n.scalar for n in g.nodes) == 22
    # free-free: exactly 6 rigid-body modes with all these elements
    free = solve_modes(build_frame(g), n_modes=8)
    assert int(np.sum(free.omega == 0.0)) == 6
    # NX's first eigenvalue table of outboard.out: the b-set (grids 3, 11, 19, 27) fixed
    nx_hz = np.array(
        [1.650001, 1.650249, 1.674265, 1.674687, 7.025350, 7.025411, 10.91274, 10.91454]
        + [13.98578, 13.99172, 25.13473]
    )
    fixed = dataclasses.replace(
        g, constraints=tuple(Constraint(f"grid:{i}", "123456") for i in (3, 11, 19, 27))
    )
    f = solve_modes(build_frame(fixed, constrained=True), n_modes=11).omega / (2 * np.pi)
    # the run is NX Nastran 9.1 (outboard.out's header) with COUPMASS 1: its coupled CBAR
    # mass ("coupled-nx9"); measured 2.3e-7, the F06 prints 7 digits (rounding 5e-7): 1e-6
    np.testing.assert_allclose(f, nx_hz, rtol=1e-6)


@pytest.mark.parametrize("stem", ["make_gm_nx9_rbe3_um_5", "make_gm_nx9_rbe3_um_6"])
def test_um_decks_solve_as_the_same_deck_without_um(stem, tmp_path):
    # UM only moves the RBE3's dependency from its reference grid (124, which nothing else
    # reaches and which has no mass) onto independent grids: the constraint equations, hence
    # the modes, are those of the same deck with the UM entry removed.  These two decks were
    # refused as a "massless mechanism" because the components UM frees at grid 124 keep
    # ~1e-20 of round-off stiffness and ~1e-35 of mass from the RBE3 coefficients
    text = (DATA / "gm" / f"{stem}.dat").read_text()
    um = [ln for ln in text.splitlines() if ln.split()[:1] == ["UM"]]
    assert len(um) == 1  # the RBE3's one UM continuation
    plain = tmp_path / "plain.dat"
    plain.write_text("\n".join(ln for ln in text.splitlines() if ln not in um) + "\n")
    with_um = solve_modes(build_frame(load_bdf(DATA / "gm" / f"{stem}.dat", units="m, N, s")), 20)
    without = solve_modes(build_frame(load_bdf(plain, units="m, N, s")), 20)
    assert with_um.n_rigid == without.n_rigid == 6
    assert np.all(with_um.omega[:6] == 0.0)
    # two parametrisations of one constrained system, each condensed and solved densely: the
    # stiffness spans ~1e12 (rotations of 4-mm bars against the lowest modal stiffness), so
    # round-off may move an eigenvalue by up to eps * 1e12 ~ 2e-4; measured 3.6e-8 on a
    # frequency, and 1e-6 is 28x that, while a wrong UM solve or a dropped coupling of the
    # coordinate change moves these modes by more than 1e-3
    np.testing.assert_allclose(with_um.omega[6:], without.omega[6:], rtol=1e-6)
