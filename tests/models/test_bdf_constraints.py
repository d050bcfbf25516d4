"""Scalar points, scalar elements, MPC and RBE3 from decks, against hand solutions.

References: the fixed-free chain of n equal springs and masses,
``omega_j^2 = 4 k/m sin^2((2j - 1) pi / (2 (2n + 1)))`` (e.g. Meirovitch, *Fundamentals of
Vibrations*, sec. 7.x, the lumped string); two DOFs tied by ``u_1 = c u_2`` have
``omega^2 = (c^2 k_1 + k_2) / (c^2 m_1 + m_2)`` (energy of the one remaining DOF); an RBE3
whose reference point is the weighted centroid of its independent grids moves with the
weighted mean of their translations (its normal equations decouple: sum w_k d_k = 0).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.bdf import load_bdf
from microg.structure.assembly import assemble_frame
from microg.structure.frame import build_frame


def _deck(tmp_path: Path, body: str, name: str = "deck.bdf") -> Path:
    p = tmp_path / name
    p.write_text(body)
    return p


# a free grid carrying a rigid mass, plus a chain of three scalar points grounded at one end
CHAIN = """\
SOL 103
CEND
BEGIN BULK
GRID,10,,0.,0.,0.
CONM2,1,10,,5.,,,,,+
+,1.,,1.,,,1.
SPOINT,1,THRU,3
PELAS,7,400.
CELAS1,21,7,1,,,
CELAS2,22,400.,1,,2,
CELAS2,23,400.,2,0,3,0
PMASS,8,2.
CMASS1,31,8,1
CMASS2,32,2.,2
CMASS2,33,2.,,,3
ENDDATA
"""


def test_spoint_spring_mass_chain(tmp_path):
    g = load_bdf(_deck(tmp_path, CHAIN), units="m, N, s")
    assert [n.name for n in g.nodes] == ["spoint:1", "spoint:2", "spoint:3", "grid:10"]
    assert all(n.scalar for n in g.nodes[:3])
    s = build_frame(g)
    assert s.n_dof == 9  # the grid's 6 and one per scalar point (their 5 empty slots dropped)
    m = solve_modes(s)
    assert int(np.sum(m.omega == 0.0)) == 6  # the free grid's rigid-body modes, exactly
    k, mass, n = 400.0, 2.0, 3
    j = np.arange(1, n + 1)
    exact = np.sqrt(4 * k / mass * np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1))) ** 2)
    # tolerance: a 3x3 symmetric eigenproblem, exact to round-off
    np.testing.assert_allclose(np.sort(m.omega[6:]), exact, rtol=1e-12)
    # a scalar point is not a point in space: it cannot be observed
    with pytest.raises(InputError, match="scalar point"):
        s.point("spoint:2")


def test_spoint_misuse_is_refused(tmp_path):
    for bad, what in (
        ("SPOINT,10", "both a GRID and an SPOINT"),
        ("CELAS2,24,1.,3,1", "component is 0 or blank"),
        ("CBUSH,40,41,10,3,,,,0\nPBUSH,41,K,1.,1.,1.,1.,1.,1.", "GB grid 3 is not defined"),
        ("CELAS2,24,1.,99,0", "neither a GRID nor an SPOINT"),
        ("ESPOINT,50", "ESPOINT"),
    ):
        text = CHAIN.replace("ENDDATA", bad + "\nENDDATA")
        with pytest.raises(InputError, match=what):
            load_bdf(_deck(tmp_path, text, "bad.bdf"), units="m, N, s")


def _tie(a2: float, mpc_case: str = "MPC = 5\n", extra: str = "") -> str:
    return (
        f"SOL 103\nCEND\n{mpc_case}BEGIN BULK\n"
        "GRID,1,,0.,0.,0.,,23456\nGRID,2,,1.,0.,0.,,23456\n"
        "CONM2,1,1,,3.\nCONM2,2,2,,7.\n"
        "CELAS2,11,100.,1,1\nCELAS2,12,900.,2,1\n"
        f"MPC,5,1,1,1.,2,1,{a2}\n{extra}ENDDATA\n"
    )


@pytest.mark.parametrize("c", [1.0, 2.0, -0.5])
def test_mpc_ties_two_grids(tmp_path, c):
    # u_1 = c u_2 (MPC 1 u_1 - c u_2 = 0): one DOF left, energy (c^2 k1 + k2) u_2^2 / 2
    g = load_bdf(_deck(tmp_path, _tie(-c)), units="m, N, s")
    assert g.mpcs[0].terms == (("grid:1", 1, 1.0), ("grid:2", 1, -c))
    s = build_frame(g, constrained=True)  # GRID PS 23456 holds all but x
    assert s.n_dof == 1
    w2 = float(s.stiffness[0, 0] / s.mass[0, 0])
    # tolerance: a 1x1 ratio of sums of exact products, round-off only
    assert w2 == pytest.approx((c * c * 100.0 + 900.0) / (c * c * 3.0 + 7.0), rel=1e-14)


def test_mpc_selection_as_nastran(tmp_path):
    # no MPC = n in the case control: NASTRAN applies no MPC; a selected set the bulk data
    # lacks is NX's USER WARNING 2047 (no MPC); asked for by the caller, it is an error
    for case, note in (("", "none selected"), ("MPC = 9\n", "does not define")):
        g = load_bdf(_deck(tmp_path, _tie(-1.0, case), "n.bdf"), units="m, N, s")
        assert g.mpcs == () and any(note in w for w in g.meta["warnings"])
    with pytest.raises(InputError, match="MPC set 9 is not defined"):
        load_bdf(_deck(tmp_path, _tie(-1.0), "e.bdf"), units="m, N, s", mpc=9)
    # MPCADD combines sets
    text = _tie(-1.0, "MPC = 6\n", "MPCADD,6,5\n")
    assert len(load_bdf(_deck(tmp_path, text, "a.bdf"), units="m, N, s").mpcs) == 1


def test_a_dof_dependent_twice_names_both(tmp_path):
    text = _tie(-1.0, extra="GRID,3,,2.,0.,0.\nRBE2,8,3,1,1\n")
    g = load_bdf(_deck(tmp_path, text, "twice.bdf"), units="m, N, s")
    with pytest.raises(InputError, match=r"dependent in both rbe2:8 and mpc:5#1"):
        build_frame(g)


def _rbe3_deck(extra: str = "") -> str:
    xs = [(0.0, 0.0, 0.0), (4.0, 1.0, 0.0), (1.0, 3.0, 2.0), (-2.0, 1.0, 5.0)]
    w = [1.0, 2.0, 0.5, 3.0]
    cen = np.average(np.array(xs), axis=0, weights=w)
    lines = [f"GRID,{i + 1},,{x:.1f},{y:.1f},{z:.1f}" for i, (x, y, z) in enumerate(xs)]
    lines.append(f"GRID,9,,{float(cen[0])!r},{float(cen[1])!r},{float(cen[2])!r}")
    # free field: the name and 8 fields per line, then a continuation
    card = "RBE3,20,,9,123456,1.0,123,1,2.0,+\n+,123,2,0.5,123,3,3.0,123,4\n"
    return "SOL 103\nCEND\nBEGIN BULK\n" + "\n".join(lines) + "\n" + card + extra + "ENDDATA\n"


def test_rbe3_reference_at_weighted_centroid_moves_with_weighted_mean(tmp_path):
    g = load_bdf(_deck(tmp_path, _rbe3_deck(), "r.bdf"), units="m, N, s")
    ip = g.interpolations[0]
    assert [w for _, _, w in ip.sources] == [1.0, 2.0, 0.5, 3.0]
    fm = assemble_frame(g)
    T = fm.transform.toarray()
    rng = np.random.default_rng(7)
    q = rng.normal(size=T.shape[1])
    u = (T @ q).reshape(-1, 6)
    idx = g.node_index()
    src = np.array([u[idx[f"grid:{k}"], :3] for k in (1, 2, 3, 4)])
    mean = np.average(src, axis=0, weights=[1.0, 2.0, 0.5, 3.0])
    # tolerance: the decoupling is exact; a 6x6 solve of O(10) numbers, round-off ~1e-14
    np.testing.assert_allclose(u[idx["grid:9"], :3], mean, atol=1e-13)


def test_rbe3_um_must_match_refc(tmp_path):
    text = _rbe3_deck().replace(",3.0,123,4\n", ",3.0,123,4,+\n+,UM,1,12\n")
    g = load_bdf(_deck(tmp_path, text, "um.bdf"), units="m, N, s")
    assert g.interpolations[0].moved == (("grid:1", "12"),)
    with pytest.raises(InputError, match="UM names 2 distinct component"):
        assemble_frame(g)


TIED = """\
SOL 103
CEND
BEGIN BULK
GRID,10,,0.,0.,0.
CONM2,1,10,,5.,,,,,+
+,1.,,1.,,,1.
SPOINT,1
CELAS2,22,400.,10,1,1,
CMASS2,32,2.,1
ENDDATA
"""


def test_scalar_point_tied_to_a_grid_keeps_six_rigid_modes(tmp_path):
    # the scalar point moves with the grid in x under rigid translation (the static
    # extension of the rigid vector); the one elastic mode is the two-mass oscillator,
    # omega^2 = k (1/m1 + 1/m2)
    m = solve_modes(build_frame(load_bdf(_deck(tmp_path, TIED, "tied.bdf"), units="m, N, s")))
    assert int(np.sum(m.omega == 0.0)) == 6
    # tolerance: a 2x2 eigenproblem, round-off only
    assert m.omega[6:] == pytest.approx([np.sqrt(400.0 * (1 / 5.0 + 1 / 2.0))], rel=1e-12)


def test_cli_refuses_to_observe_a_scalar_point(tmp_path):
    import os
    import subprocess
    import sys

    deck = _deck(tmp_path, TIED, "tied.bdf")
    out = subprocess.run(
        [sys.executable, "-m", "microg", "analyze", str(deck), "--units", "m,N,s"]
        + ["--observe", "spoint:1", "--at", "grid:10", "--out", str(tmp_path / "run")],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2] / "src")},
        timeout=300,
    )
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "'spoint:1' is a scalar point (SPOINT)" in lines[0]
