"""OP2 tables as real runs write them: superelements, no LAMA, 64-bit words, subcases.

Fixtures (tests/data/nastran/, from pyyeti's wheel, LICENSE-pyyeti.txt, README.md):

* ``cla_residual.op2`` (Simcenter 2020.2): displacement tables of SE 0 (the residual, 26
  grids) and SE 101 (an external superelement, 26 grids, 4 of them the boundary grids 3, 11,
  19, 27 shared with SE 0); the OP2 places only SE 101's boundary grids, its interior grids
  (1, 2, 9, ... 35-48) are in ``cla_outboard.blk`` (the superelement's bulk data).
  Truth: pyNastran 1.4.1, ``read_op2(...).eigenvectors`` (two tables, "SUPERELEMENT 0" and
  "SUPERELEMENT 101"), values at grid 40 recorded below.
* ``extseout_inboard.op2`` (NX 5/1/14): no LAMA.  Truth: its F06 (``inboard.out``, "R E A L
  E I G E N V A L U E S"): 1.483160E+03, 1.483542E+03, 2.204734E+04, generalized masses 1.
* ``tugd_2020_32bit.op2`` / ``tugd_2020_64bit.op2``: the same Simcenter 2020 run written
  with 4- and 8-byte words (no modes: a TUGD matrix).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import microg.models.op2 as op2mod
from microg.errors import InputError
from microg.models.modal import parse_units
from microg.models.nastran import Op2File, modal_model_from_op2, read_op2_modes

pytestmark = pytest.mark.nastran

DATA = Path(__file__).parent.parent / "data" / "nastran"
CLA = DATA / "cla_residual.op2"
OUTBOARD = DATA / "cla_outboard.blk"
NOLAMA = DATA / "extseout_inboard.op2"
BEAM = DATA / "beam_modes" / "beam_modes_m2.op2"
IN = parse_units("in, lbf, s")

# pyNastran 1.4.1: eigenvectors[SUPERELEMENT 101].data[mode - 1, row of grid 40] (float32)
GRID40 = {
    7: [2.5987558364868164, 1.1733103519873112e-06, 5.707518994313432e-06,
        1.0682965623232121e-08, -1.0454030530127056e-08, -0.0033699790947139263],
    10: [-1.2026808690279722e-05, -3.4580068586365087e-06, 1.6035913228988647,
         0.004026420414447784, -5.715702577901993e-09, 3.522662694876999e-08],
}  # fmt: skip


def test_every_superelement_table_is_read():
    op2 = read_op2_modes(CLA)
    assert op2.superelements == (0, 101)
    # 26 + 26 grids, the 4 boundary grids given alike by both tables counted once
    assert op2.grid_ids.size == 48 and not op2.ambiguous
    assert {1, 2, 35, 40, 48} <= set(op2.grid_ids.tolist())
    row = int(np.flatnonzero(op2.grid_ids == 40)[0])
    for mode, ref in GRID40.items():
        # the same float32 numbers as pyNastran: exact after the float32 round trip
        np.testing.assert_array_equal(op2.shapes[row, :, mode - 1].astype(np.float32),
                                      np.float32(ref))  # fmt: skip


def test_grid_of_an_unplaced_superelement_says_why():
    m = modal_model_from_op2(CLA, IN)  # no deck beside the fixture
    assert m.n_grids == 26 and any("superelement 101" in w for w in m.warnings)
    with pytest.raises(InputError, match="superelement 101's displacement table") as exc:
        m.point("grid:40")
    assert "\n" not in str(exc.value)


def test_superelement_deck_places_its_grids():
    m = modal_model_from_op2(CLA, IN, bdf=OUTBOARD)
    assert m.n_grids == 48
    i = m.grid_index(40)
    # cla_outboard.blk: GRID 40 at (150, 1530, 150) in basic, inches
    np.testing.assert_allclose(m.xyz_m[i], np.array([150.0, 1530.0, 150.0]) * 0.0254, rtol=1e-15)
    # the whole free-free assembly moves rigidly in its rigid-body modes: all 48 grids fit
    assert m.replaced_rigid.count == 6 and m.replaced_rigid.fit_grids == 48
    # mode 7 at grid 40 (CD 0, LAMA generalized mass 1): the file's value in SI
    # (file_units docstring: translations / sqrt(slinch))
    j = 6  # six rigid modes first, then the file's mode 7
    assert m.phi[i, 0, j] == pytest.approx(GRID40[7][0] / np.sqrt(IN.mass_kg), rel=1e-6)


def test_eigenvalues_from_the_ougv1_headers_without_lama():
    op2 = read_op2_modes(NOLAMA)
    assert op2.eigenvalue_source == "OUGV1 headers"
    # F06 (7 printed digits: 5e-7) of float32 header values (6e-8)
    np.testing.assert_allclose(op2.eigenvalue, [1.483160e03, 1.483542e03, 2.204734e04],
                               rtol=5.6e-7)  # fmt: skip
    m = modal_model_from_op2(NOLAMA, IN)
    assert m.meta["eigenvalues"] == "OUGV1 headers" and "no LAMA" in m.warnings[0]
    np.testing.assert_allclose(m.freq_hz, [6.129345, 6.130134, 23.63188], rtol=6e-7)


def test_unit_max_vectors_without_lama_are_refused(monkeypatch):
    # beam_modes ran EIGRL NORM=MAX; without its LAMA the generalized masses are unknown
    monkeypatch.setattr(op2mod, "_lama", lambda f: None)
    with pytest.raises(InputError, match="NORM=MAX"):
        read_op2_modes(BEAM)


def test_64_bit_block_names_and_params_equal_the_32_bit_file():
    f32 = Op2File(DATA / "tugd_2020_32bit.op2")
    f64 = Op2File(DATA / "tugd_2020_64bit.op2")
    assert f64.word == 8 and f32.word == 4
    names = [t[0] for t in f64.tables]
    assert names == [t[0] for t in f32.tables]
    assert {"GEOM1S", "BGPDTS", "OGPWG", "EQEXINS"} <= set(names)
    p32, p64 = op2mod._pvt0(f32), op2mod._pvt0(f64)
    assert p32.keys() == p64.keys() and p64
    with pytest.raises(InputError, match="data blocks: BGPDTS, CASECC") as exc:
        read_op2_modes(DATA / "tugd_2020_64bit.op2")
    assert "OGPWG" in str(exc.value)


def test_unknown_subcase_is_an_error_naming_those_present():
    with pytest.raises(InputError, match=r"no modes of subcase 2 in the file \(subcases: 1\)"):
        read_op2_modes(CLA, subcase=2)
    assert read_op2_modes(CLA, subcase=1).subcase == 1


def test_superelement_tables_against_pynastran():
    pytest.importorskip("pyNastran")
    from pyNastran.op2.op2 import read_op2

    ref = read_op2(str(CLA), debug=None, build_dataframe=False)
    mine = read_op2_modes(CLA)
    for ev in ref.eigenvectors.values():
        grid = ev.node_gridtype[:, 1] == 1
        rows = np.searchsorted(mine.grid_ids, ev.node_gridtype[grid, 0])
        want = np.transpose(ev.data[:, grid, :], (1, 2, 0)).astype(np.float32)
        np.testing.assert_array_equal(mine.shapes[rows].astype(np.float32), want)
