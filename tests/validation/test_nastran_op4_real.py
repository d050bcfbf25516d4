"""OP4 matrices of real NASTRAN runs, their DOFs from the run's own USET/EQEXIN or EXTRN.

Files (tests/data/nastran/README.md): ``extseout_nas2cam.op2``/``.op4`` (NX 9, the nas2cam
DMAP's output of an assembly of two external superelements 101 and 102 and the residual 0:
per superelement USET, EQEXINS, CSTMS, BGPDTS in the OP2 and SE_START-marked MAA/KAA blocks
in the OP4), ``inboard.op4`` + ``inboard.pch`` (superelement 102's EXTSEOUT: MXX/KXX and the
punch with EXTRN), ``notall6_msc2017.op2``/``.op4`` (MSC 2017, 64-bit words, a boundary grid
with one component only).

References: pyyeti 1.4's ``nastran.op2.OP2.rdn2cop2`` and ``n2p.mksetpv`` (the a-set of each
superelement, positions, coordinate systems); NASTRAN's own eigenvalues of the same matrices
(the LAMBDA matrix of the residual's block in the same OP4); the A-set weight checks printed in
the run's F06 (``nas2cam_extseout/assemble.out`` of pyyeti's wheel, SUBCASES 2, 3, 10, values
copied below); scipy's QZ (``scipy.linalg.eig(K, M)``), which needs no positive-definite M.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from microg.errors import InputError
from microg.models.load import load_model

pytest.importorskip("pyyeti")

DATA = Path(__file__).resolve().parents[1] / "data" / "nastran"
N2C = DATA / "extseout_nas2cam.op4"
INBOARD = DATA / "inboard.op4"
NOTALL6 = DATA / "notall6_msc2017.op4"
UNITS = "mm, N, s"  # the runs' units: mass in tonnes (1 t = 1000 kg)

#: the F06's A-set weight checks (REFERENCE POINT = 0), M O in t, t mm, t mm^2: mass, the
#: (1, 5) entry and the (4, 4), (5, 5), (6, 6) inertias, copied from assemble.out
WEIGHT_CHECK = {
    101: (1.590384e00, 2.385576e02, (4.285000e05, 1.351617e05, 4.663309e05)),
    102: (1.755052e00, 2.632578e02, (1.148825e05, 2.305948e06, 2.305948e06)),
    0: (3.345436e00, 5.018153e02, (5.433826e05, 2.441110e06, 2.772279e06)),
}


def test_dof_tables_match_pyyeti_for_every_superelement():
    """USET a-set, positions and output systems of each SE as pyyeti reads them, exactly."""
    pytest.importorskip("pandas")
    from pyyeti.nastran import n2p, op2

    from microg.models.op2 import read_op2_dof_tables

    for op2file in (N2C.with_suffix(".op2"), NOTALL6.with_suffix(".op2")):
        with op2.OP2(str(op2file)) as o:
            ref = o.rdn2cop2()
        mine = {t.superelement: t for t in read_op2_dof_tables(op2file) if t.uset is not None}
        assert sorted(mine) == sorted(ref["uset"])
        for se, u in ref["uset"].items():
            t = mine[se]
            idx = u.index.to_frame().values
            a = t.a_set()
            # the same integers and bits: exact
            np.testing.assert_array_equal(
                np.column_stack([t.dof_ids[a], t.dof_components[a]]),
                idx[n2p.mksetpv(u, "p", "a")],
            )
            xyz = u[["x", "y", "z"]].values
            np.testing.assert_array_equal(t.xyz[t.kinds == 1], xyz[idx[:, 1] == 1])
            gr, rr = np.flatnonzero(t.kinds == 1), np.flatnonzero(idx[:, 1] == 1)
            for k, r in zip(gr, rr, strict=True):
                assert t.cd[k] == int(xyz[r + 1, 0])
                if t.cd[k]:
                    frame = t.coords[int(t.cd[k])]
                    # the same doubles, transposed (rows: axes in basic): exact
                    np.testing.assert_array_equal(frame.rotation.T, xyz[r + 3 : r + 6])


def test_residual_frequencies_are_nastrans_lambda():
    m = load_model(N2C, units=UNITS, superelement=0)
    from microg.models.nastran import read_op4

    lam = read_op4(N2C).blocks()[2].get("LAMBDA").ravel()
    f_ref = np.sqrt(np.abs(lam)) / (2 * np.pi)
    f = m.omega / (2 * np.pi)
    # 6 rigid (NASTRAN: below 3.1e-5 Hz, microg: exactly 0), then 48 elastic modes: NX's
    # Lanczos eigenvalues of these matrices agree with a dense solve to its convergence,
    # 2.5e-8 measured on the frequencies; 2e-7 is its documented 1e-6 on eigenvalues / 5
    assert m.replaced_rigid.count == 6 and np.all(f_ref[:6] < 3.1e-5)
    np.testing.assert_allclose(f[6:], f_ref[6:], rtol=2e-7)
    assert "DOF map from" in m.warnings[0] and "USETTAB" in m.warnings[0]
    assert m.meta["scalar_points"][:2] == [1995001, 1995002] and len(m.meta["scalar_points"]) == 30


@pytest.mark.parametrize("se", [101, 102, 0])
def test_rigid_body_mass_is_the_f06_a_set_weight_check(se):
    m = load_model(N2C, units=UNITS, superelement=se)
    mass_t, m15, inertia = WEIGHT_CHECK[se]
    rm = m.rigid_mass  # SI about the basic origin; t -> kg 1e3, mm -> m 1e-3
    # the F06 prints 7 significant digits: 5e-7 relative (1e-6 for rounding of both)
    assert rm[0, 0] == pytest.approx(mass_t * 1e3, rel=1e-6)
    assert rm[0, 4] == pytest.approx(m15 * 1e3 * 1e-3, rel=1e-6)
    np.testing.assert_allclose(np.diag(rm)[3:], np.array(inertia) * 1e3 * 1e-6, rtol=1e-6)


def test_punch_and_op2_give_the_same_map_and_the_same_model(tmp_path):
    """SE 102 from its own EXTSEOUT (OP4 + .pch) and from the assembly's nas2cam files."""
    from microg.models.dofmap import dof_map_from_op2, dof_map_from_pch

    a = dof_map_from_pch(INBOARD.with_suffix(".pch"))
    b = dof_map_from_op2(N2C.with_suffix(".op2"), superelement=102)
    np.testing.assert_array_equal(a.ids, b.ids)
    np.testing.assert_array_equal(a.components, b.components)
    np.testing.assert_array_equal(a.grid_ids, [3, 11, 19, 27])
    np.testing.assert_array_equal(a.scalar_points, np.arange(2995001, 2995009))
    # positions as printed on GRID (16-digit fields) and as BGPDTS holds them (doubles)
    np.testing.assert_allclose(a.xyz, b.xyz, rtol=0, atol=1e-9)
    # grid 11's CD 10: CORD2R 10 has z along basic x and x along basic y (cards above)
    np.testing.assert_allclose(a.axes[1], [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)
    np.testing.assert_allclose(a.axes, b.axes, atol=1e-15)
    own = load_model(INBOARD, units=UNITS)
    asm = load_model(N2C, units=UNITS, superelement=102)
    assert own.meta["mass"] == "MXX" and "inboard.pch" in own.meta["dof_map"]
    # the same run's matrices (EXTSEOUT written, INPUTT4 read): same modes to solver rounding
    np.testing.assert_allclose(own.omega[6:], asm.omega[6:], rtol=1e-10)
    np.testing.assert_allclose(own.rigid_mass, asm.rigid_mass, rtol=1e-10)


def test_singular_mass_matches_qz_on_the_full_problem():
    """SE 102's MAA has a massless direction (condensed): QZ on the uncondensed pencil."""
    import scipy.linalg as sla

    from microg.models.nastran import read_op4

    blk = read_op4(N2C).blocks()[1]
    w = sla.eig(blk.get("KAA"), blk.get("MAA"), right=False)
    f_qz = np.sort(np.sqrt(np.abs(w[np.isfinite(w)].real))) / (2 * np.pi)
    m = load_model(N2C, units=UNITS, superelement=102)
    assert any("massless" in w for w in m.warnings)
    f = m.omega / (2 * np.pi)
    assert f.size == f_qz.size == 31  # 32 a-set DOFs, one massless
    # QZ of a singular pencil: backward stable, 7.9e-10 measured on these frequencies
    np.testing.assert_allclose(f[6:], f_qz[6:], rtol=1e-8)


def test_64bit_msc_file_with_a_one_component_grid():
    m = load_model(NOTALL6, units=UNITS, superelement=0)
    from microg.models.dofmap import dof_map_for_op4
    from microg.models.nastran import read_op4

    d = dof_map_for_op4(NOTALL6, 29, superelement=0)
    assert list(d.components[d.ids == 475]) == [2]  # EXTRN 475, 2 in the run's punch
    lam = read_op4(NOTALL6).blocks()[1].get("LAMBDA").ravel()
    f_ref = np.sqrt(np.abs(lam)) / (2 * np.pi)
    # MSC's 10 modes (6 rigid below 7e-5 Hz): 7.3e-13 measured, double-precision solves
    np.testing.assert_allclose(m.omega[6:10] / (2 * np.pi), f_ref[6:10], rtol=1e-10)


def test_several_superelements_are_refused_without_a_choice():
    with pytest.raises(InputError, match=r"matrices of superelements 101, 102, 0") as exc:
        load_model(N2C, units=UNITS)
    assert "superelement=N" in exc.value.fix  # the library's parameter; the CLI says --superelement
    with pytest.raises(InputError, match=r"no superelement 7 in the file") as exc:
        load_model(N2C, units=UNITS, superelement=7)
    assert exc.value.where == "superelement"
    with pytest.raises(InputError, match="applies to OP4 files only"):
        load_model(DATA / "cla_residual.op2", units="in, lbf, s", superelement=0)


def test_duplicated_names_without_markers_are_listed_and_chosen_by_number(tmp_path):
    from pyyeti.nastran import op4

    from microg.models.nastran import read_op4

    k1, k2 = np.diag([1.0, 4.0]), np.diag([9.0, 16.0, 25.0])
    path = tmp_path / "two.op4"
    op4.write(str(path), ["MAA", "KAA", "MAA", "KAA"], [np.eye(2), k1, np.eye(3), k2])
    f = read_op4(path)
    with pytest.raises(InputError, match=r"2 matrices named KAA: KAA#1 \(2x2\), KAA#2 \(3x3\)"):
        f.get("KAA")
    np.testing.assert_array_equal(f.get("KAA#2"), k2)
    with pytest.raises(InputError, match=r"give KAA#1 to KAA#2"):
        f.get("KAA#3")
    with pytest.raises(InputError, match="2 matrices named MAA"):
        load_model(path, units="m, N, s")


def test_map_of_another_size_is_an_error_naming_both(tmp_path):
    shutil.copy(INBOARD, tmp_path / "inboard.op4")
    rows = "\n".join(f"1,{c},0,0,0" for c in range(1, 7))
    (tmp_path / "inboard.dofmap.csv").write_text(rows + "\n")
    with pytest.raises(InputError, match=r"inboard.dofmap.csv \(DOF map file\) has 6 DOFs, the "
                       r"matrices 32"):  # fmt: skip
        load_model(tmp_path / "inboard.op4", units=UNITS)
    (tmp_path / "inboard.dofmap.csv").unlink()
    with pytest.raises(InputError, match=r"none of inboard.op2 \(absent\), inboard.pch \(absent\)"):
        load_model(tmp_path / "inboard.op4", units=UNITS)
    # an OP2 beside it without USET (the component's own SOL 103 output) is passed over
    shutil.copy(DATA / "extseout_inboard.op2", tmp_path / "inboard.op2")
    shutil.copy(INBOARD.with_suffix(".pch"), tmp_path / "inboard.pch")
    m = load_model(tmp_path / "inboard.op4", units=UNITS)
    assert "inboard.pch" in m.meta["dof_map"]


def test_scalar_points_in_the_csv_fallback(tmp_path):
    """The .dofmap.csv takes SPOINT rows (component 0): the pch's map written as a file."""
    from microg.models.dofmap import dof_map_from_pch

    d = dof_map_from_pch(INBOARD.with_suffix(".pch"))
    pos = {int(g): p for g, p in zip(d.grid_ids, d.xyz, strict=True)}
    lines = [
        f"{i},{c},{','.join(repr(float(v)) for v in pos.get(int(i), np.zeros(3)))}"
        for i, c in zip(d.ids, d.components, strict=True)
    ]
    shutil.copy(INBOARD, tmp_path / "inboard.op4")
    (tmp_path / "inboard.dofmap.csv").write_text("\n".join(lines) + "\n")
    m = load_model(tmp_path / "inboard.op4", units=UNITS)
    ref = load_model(INBOARD, units=UNITS)
    assert "DOF map file" in m.meta["dof_map"]
    # the csv has no output systems: grid 11's rotations differ, the frequencies do not
    np.testing.assert_allclose(m.omega, ref.omega, rtol=1e-12, atol=0)


@pytest.mark.parametrize("name", ["extseout_inboard.op2", "csuper_assemble.op2"])
def test_eqexin_and_bgpdt_match_pynastran(name):
    """EQEXINS and BGPDTS of SOL 103 OP2s (no USET) as pyNastran 1.4.1 reads them, exactly
    (pyNastran cannot open the nas2cam DMAP's OP2s: their header says DBWRITE)."""
    pytest.importorskip("pyNastran")
    from pyNastran.op2.op2 import OP2

    from microg.models.op2 import read_op2_dof_tables

    o = OP2(debug=None)
    o.read_op2(str(DATA / name), build_dataframe=False)
    eq, bg = o.op2_results.eqexin, o.op2_results.bgpdt
    t = [x for x in read_op2_dof_tables(DATA / name) if "EQEXINS" in x.tables][-1]
    order = np.argsort(eq.dof)  # pyNastran keeps EQEXIN's external order; SIL sorts it
    np.testing.assert_array_equal(eq.nid[order], t.ids)
    np.testing.assert_array_equal(eq.doftype[order], t.kinds)
    np.testing.assert_array_equal(np.asarray(bg.xyz), t.xyz)
