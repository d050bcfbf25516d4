"""NASTRAN's coupled CBAR mass (PARAM,COUPMASS 1) as two releases form it, against their runs.

The same bulk data (``cla_outboard.blk``: 49 CBARs, PARAM,COUPMASS,1) was run by NX Nastran
9.1 (2014; pyyeti's ``nas2cam_extseout/outboard.out``) and by Simcenter Nastran 2020.2
(``cla_test_data_2020/outboard.out``), both SOL 103 with the b-set grids 3, 11, 19, 27 fixed
(the fixed-interface modes of a Craig-Bampton reduction, printed before the residual vectors).
Their weight checks differ (Simcenter's rotary inertia is larger by m'L^3/70 per bar across
its axis) and so do their eigenvalues (by up to 2.1%).  Fitting both to the printed digits:

* NX 9.1 (``coupled_mass="coupled-nx9"``): the cubic element's consistent translational mass,
  no torsional inertia;
* Simcenter 2020.2 (``"coupled"``, the default): the same without the coupling between the
  two ends' bending rotations.

Truth, recorded below from the F06s (7 significant digits): the eigenvalue tables' CYCLES and
the weight checks' G-set MO about the basic origin (kg, mm).  A third, independent run:
``cla_residual.op2`` (Simcenter 2020.2), whose OGPWG is that of its residual structure, the
bulk data ``cla_inboard.blk`` (66 CBARs, COUPMASS 1), read with microg's OP2 reader.
The NX deck adds a massless grid 60 (RBE2, RBE3, an MPC to a modal coordinate): no mass, and
no stiffness on the fixed-interface modes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.bdf import load_bdf
from microg.models.op2 import read_op2_modes
from microg.structure.assembly import assemble_frame
from microg.structure.discretize import discretize
from microg.structure.elements import bar_mass_coupled_local, rigid_link

pytestmark = pytest.mark.nastran

DATA = Path(__file__).parent.parent / "data" / "nastran"
UNITS = "mm, mN, s"  # the decks' own: MAT1 rho 2.74e-6 kg/mm^3, E 6.894e7 kg/(mm s^2)

# R E A L   E I G E N V A L U E S (before augmentation of residual vectors), CYCLES, modes 1-16
F06_SIMCENTER = [
    1.647887, 1.648135, 1.673163, 1.673585, 6.880648, 6.880707, 10.78884, 10.79060,
    13.94015, 13.94609, 25.01010, 25.01543, 42.35685, 42.37868, 46.71593, 46.89476,
]  # fmt: skip
F06_NX9 = [
    1.650001, 1.650249, 1.674265, 1.674687, 7.025350, 7.025411, 10.91274, 10.91454,
    13.98578, 13.99172, 25.13473, 25.13995, 42.17271, 42.19338, 46.71595, 46.89473,
]  # fmt: skip
# O U T P U T   F R O M   W E I G H T   C H E C K, DEGREES OF FREEDOM SET = G, reference point
# 0: MO's mass (kg), first moments (kg mm, row 1) and rotational block (kg mm^2)
GPWG = {
    "coupled": (1.590384, 2.385576e2, [[4.294770e5, -4.404722e4, -4.404722e4],
                                        [-4.404722e4, 1.363559e5, -3.591198e4],
                                        [-4.404722e4, -3.591198e4, 4.674728e5]]),
    "coupled-nx9": (1.590384, 2.385576e2, [[4.285000e5, -4.404722e4, -4.404722e4],
                                            [-4.404722e4, 1.351617e5, -3.589320e4],
                                            [-4.404722e4, -3.589320e4, 4.663309e5]]),
}  # fmt: skip


def _clamped_deck(tmp_path: Path) -> Path:
    deck = tmp_path / "outboard_fixed.dat"
    deck.write_text(
        "SOL 103\nCEND\nSPC = 1\nBEGIN BULK\n"
        f"INCLUDE '{(DATA / 'cla_outboard.blk').resolve()}'\n"
        "SPC1,1,123456,3,11,19,27\nENDDATA\n"
    )
    return deck


def _rigid_mass_mm(graph) -> np.ndarray:
    """D^T M D about the basic origin, in the deck's units (kg, kg mm, kg mm^2)."""
    fm = assemble_frame(graph)
    d = rigid_link(fm.positions).reshape(-1, 6)
    m6 = d.T @ fm.mass.toarray() @ d
    s = np.diag([1.0, 1.0, 1.0, 1e3, 1e3, 1e3])  # m -> mm on the rotations
    return s @ m6 @ s


def test_default_is_simcenter_and_stated():
    g = load_bdf(DATA / "cla_outboard.blk", units=UNITS)
    assert g.mass_formulation == "coupled"
    note = g.meta["mass_formulation_note"]
    assert note.startswith("coupled (PARAM,COUPMASS,1 in the deck") and "Simcenter" in note
    with pytest.raises(InputError, match="coupled_mass: unknown coupled mass 'msc'"):
        load_bdf(DATA / "cla_outboard.blk", units=UNITS, coupled_mass="msc")


@pytest.mark.parametrize(
    ("form", "truth", "other"),
    [("coupled", F06_SIMCENTER, F06_NX9), ("coupled-nx9", F06_NX9, F06_SIMCENTER)],
    ids=["simcenter2020", "nx9"],
)
def test_fixed_interface_modes_match_each_release(tmp_path, form, truth, other):
    g = load_bdf(_clamped_deck(tmp_path), units=UNITS, coupled_mass=form)
    md = solve_modes(discretize(g, constrained=True))
    assert md.n_rigid == 0
    f = md.freq_hz[:16]
    # the F06 prints 7 significant digits (rounding <= 5e-7 relative); measured: 4.1e-7
    # (Simcenter) and 2.3e-7 (NX 9.1) at the worst mode, so 1e-6 is the printed precision
    np.testing.assert_allclose(f, truth, rtol=1e-6)
    # and the other release's run is missed by far more (2.1% at mode 5): the test tells the
    # two forms apart
    assert np.max(np.abs(f / np.asarray(other) - 1.0)) > 0.02


@pytest.mark.parametrize("form", ["coupled", "coupled-nx9"])
def test_weight_check_matches_each_release(form):
    g = load_bdf(DATA / "cla_outboard.blk", units=UNITS, coupled_mass=form)
    mo = _rigid_mass_mm(g)
    mass, first, rot = GPWG[form]
    # 7 printed digits: each entry to 5e-7 of its size (the products of inertia too)
    assert mo[0, 0] == pytest.approx(mass, rel=1e-6)
    assert mo[0, 4] == pytest.approx(first, rel=1e-6)
    np.testing.assert_allclose(mo[3:, 3:], rot, rtol=1e-6)


def test_residual_ogpwg_of_simcenter_2020():
    # cla_residual.op2 (Simcenter 2020.2): the OGPWG of its residual structure, whose bulk data
    # is cla_inboard.blk (66 CBARs, COUPMASS 1; the run's PVT0 says COUPMASS 1 too)
    op2 = read_op2_modes(DATA / "cla_residual.op2")
    assert op2.params.get("COUPMASS") == 1
    assert np.allclose(op2.rigid_mass_ref, 0.0)
    g = load_bdf(DATA / "cla_inboard.blk", units=UNITS)
    mo = _rigid_mass_mm(g)
    # OGPWG is float32 (6e-8 relative): 2e-7 of the largest entry; measured 3.4e-8
    scale = np.abs(op2.rigid_mass).max()
    assert np.abs(mo - op2.rigid_mass).max() < 2e-7 * scale
    # NX 9.1's form misses it by 1.3e3 kg mm^2 on the rotary inertia (5.7e-4 relative)
    nx = _rigid_mass_mm(load_bdf(DATA / "cla_inboard.blk", units=UNITS, coupled_mass="coupled-nx9"))
    assert np.abs(nx - op2.rigid_mass).max() > 1e-4 * scale


def test_element_rigid_inertia_by_hand():
    # one bar of length L and m' along x rotating about local z through its centre: the
    # nodal motion is v = -+ theta L/2, theta_z = theta at both ends.  The exact (continuous)
    # inertia is m' L^3/12; NX 9.1's element gives it exactly (cubic shape functions hold
    # rigid motion), Simcenter's adds m' L^3/70 (2 x 3 m' L^3/420, the coupling left out)
    L, mpl = 0.3, 2.7
    q = np.zeros(12)
    q[1], q[5], q[7], q[11] = -L / 2, 1.0, L / 2, 1.0
    for coupling, ref in ((True, mpl * L**3 / 12), (False, mpl * L**3 / 12 + mpl * L**3 / 70)):
        m = bar_mass_coupled_local(np.array([L]), np.array([mpl]), end_rotation_coupling=coupling)
        assert q @ m[0] @ q == pytest.approx(ref, rel=1e-13)
        assert m[0, 3, 3] == m[0, 9, 9] == m[0, 3, 9] == 0.0  # no torsional inertia
        assert m[0, 0, 0] == pytest.approx(mpl * L / 3, rel=1e-14)  # axial, consistent
        assert m[0, 1, 1] == pytest.approx(156 * mpl * L / 420, rel=1e-14)
    # total translational mass m' L in each direction, whichever form
    u = np.zeros(12)
    u[[2, 8]] = 1.0
    assert u @ m[0] @ u == pytest.approx(mpl * L, rel=1e-14)


def test_modes_command_states_the_choice_and_takes_the_option(capsys, tmp_path):
    import json

    from microg.cli import main

    deck = tmp_path / "outboard.dat"
    deck.write_text((DATA / "cla_outboard.blk").read_text())
    rc = main(["modes", str(deck), "--units", UNITS, "--n-modes", "8"])
    out, err = capsys.readouterr()
    assert rc == 0 and err == ""
    assert out.splitlines()[1].startswith("  mass: coupled (PARAM,COUPMASS,1 in the deck;")
    rc = main(["modes", str(deck), "--units", UNITS, "--n-modes", "8"]
              + ["--coupled-mass", "coupled-nx9", "--json"])  # fmt: skip
    out, _ = capsys.readouterr()
    assert rc == 0 and json.loads(out)["mass_formulation"]["name"] == "coupled-nx9"
    # a reader option of decks only: an OP2's mass is the run's own
    rc = main(
        ["modes", str(DATA / "cla_residual.op2"), "--units", UNITS, "--coupled-mass", "coupled"]
    )
    _, err = capsys.readouterr()
    assert rc == 2 and err.count("\n") == 1 and "--coupled-mass: applies to NASTRAN decks" in err


def test_provenance_records_the_mass_formulation():
    from microg.analysis.provenance import provenance_record

    g = load_bdf(DATA / "cla_outboard.blk", units=UNITS, coupled_mass="coupled-nx9")
    rec = provenance_record(g, None)
    assert rec["mass_formulation"] == "coupled-nx9"
    assert rec["mass_formulation_note"].startswith("coupled-nx9 (PARAM,COUPMASS,1 in the deck")


def test_ogpwg_truth_read_by_pynastran_too():
    # the OGPWG truth above, read by pyNastran 1.4.1 (the numpy < 2 environment) as well
    op2 = pytest.importorskip("pyNastran.op2.op2")
    ref = op2.read_op2(str(DATA / "cla_residual.op2"), debug=None)
    mo = ref.grid_point_weight["SUPERELEMENT 0"].MO
    # the same float32 words widened to float64: equal to the bit (measured)
    np.testing.assert_array_equal(read_op2_modes(DATA / "cla_residual.op2").rigid_mass, mo)


def test_inboard_component_of_the_nx9_run():
    # nas2cam_extseout/inboard.dat (NX Nastran 9.1, its inboard.out's header): SOL 103 of the
    # bulk data cla_inboard.blk (the same file) with BSET1,123456,3,11,19,27 and a q-set, an
    # external superelement's run: its eigenvalues (extseout_inboard.op2, no LAMA: the OUGV1
    # record headers, read by pyNastran 1.4.1 as 6.129345508646885, 6.130134198333572 and
    # 23.631877671556406 Hz) are the fixed-interface modes, the b-set grids clamped
    import dataclasses

    from microg.models.graph_model import Constraint
    from microg.structure.frame import build_frame

    truth = np.array([6.129345508646885, 6.130134198333572, 23.631877671556406])
    op2 = read_op2_modes(DATA / "extseout_inboard.op2")
    # microg reads the same words (float32 eigenvalues widened): to 1e-15 of pyNastran's
    np.testing.assert_allclose(op2.freq_hz_signed, truth, rtol=1e-15)
    bset = tuple(Constraint(f"grid:{i}", "123456") for i in (3, 11, 19, 27))
    f = {}
    for form in ("coupled-nx9", "coupled"):
        g = load_bdf(DATA / "cla_inboard.blk", units=UNITS, coupled_mass=form)
        md = solve_modes(build_frame(dataclasses.replace(g, constraints=bset), constrained=True), 3)
        f[form] = md.freq_hz
    # the OUGV1 header's eigenvalue is float32 (6e-8 relative, 3e-8 on a frequency): measured
    # 2.6e-8 at the worst mode, 2e-7 is 7x the word's precision
    np.testing.assert_allclose(f["coupled-nx9"], truth, rtol=2e-7)
    # Simcenter's form is 1.8% off this NX 9.1 run at the third mode: the test tells them apart
    assert np.max(np.abs(f["coupled"] / truth - 1.0)) > 0.01
