"""Rigid-body identification on real free-free and partial-output NASTRAN runs.

Fixtures (tests/data/nastran/, from pyyeti's wheel, LICENSE-pyyeti.txt, README.md):

* ``extseout_inboard_v2007.op2``: 3 modes of a constrained component, output on 2 grids
  (4, 16).  Truth: pyNastran 1.4.1 ``read_op2(...).eigenvalues['INBOARD'].cycles`` =
  6.129346, 6.130134, 23.631876 Hz.  Elastic modes: none may become rigid.
* ``csuper_assemble.op2`` (NX 9, CSUPER assembly) and ``extseout_assemble.op2`` (external
  superelements): free-free, 54 modes.  Truth: their F06s (``assemble.out`` beside the OP2s
  in pyyeti's wheel, "R E A L   E I G E N V A L U E S"): six modes below 4.6e-5 Hz, then
  1.699652 / 1.698800 Hz.  Grid 70 is partly connected (RBE2 in x, RBE3, an MPC on its rx
  to the modal grid 9990002); 9990001/2 carry the modal DOFs of SE 102 (CSUPER).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from microg.models.modal import parse_units, rigid_basis_at
from microg.models.nastran import modal_model_from_op2, read_op2_modes

pytestmark = pytest.mark.nastran

DATA = Path(__file__).parent.parent / "data" / "nastran"
V2007 = DATA / "extseout_inboard_v2007.op2"
CSUPER = DATA / "csuper_assemble.op2"
EXTSE = DATA / "extseout_assemble.op2"
IN = parse_units("in, lbf, s")

# F06 cycles of modes 1-7 (assemble.out); signed by the sign of the printed eigenvalue
F06_CSUPER = [-2.776567e-05, -1.754059e-05, 1.183176e-05, 1.708013e-05, 2.299500e-05,
              4.592735e-05, 1.699652]  # fmt: skip
F06_EXTSE = [-2.060897e-05, -1.587540e-05, 1.090935e-05, 1.817337e-05, 2.096848e-05,
             3.049347e-05, 1.698800]  # fmt: skip


def test_two_grid_output_keeps_its_elastic_modes():
    m = modal_model_from_op2(V2007, IN)
    # pyNastran 1.4.1 cycles; the OP2 holds float32 eigenvalues (6e-8) and pyNastran
    # prints its cycles from them: 1e-6 relative covers both roundings
    assert m.replaced_rigid is None and not m.rigid.any()
    np.testing.assert_allclose(m.freq_hz, [6.129346, 6.130134, 23.631876], rtol=1e-6)
    assert m.n_grids == 2


@pytest.mark.parametrize(
    "path, f06, excluded",
    [(CSUPER, F06_CSUPER, (70, 9990001, 9990002)), (EXTSE, F06_EXTSE, ())],
)
def test_free_free_assemblies_get_six_exact_rigid_modes(path, f06, excluded):
    m = modal_model_from_op2(path, IN)
    r = m.replaced_rigid
    assert r is not None and r.count == 6
    assert np.all(m.omega[:6] == 0.0) and m.rigid[:6].all() and not m.rigid[6:].any()
    # the replaced modes' file frequencies are the F06's (printed to 7 digits: 5e-7, and the
    # OP2's float32 eigenvalue: 6e-8 -> 1e-6 relative)
    np.testing.assert_allclose(sorted(r.file_freq_hz, key=abs), sorted(f06[:6], key=abs), rtol=1e-6)
    assert r.first_elastic_hz == pytest.approx(f06[6], rel=1e-6)
    assert m.freq_hz[6] == pytest.approx(f06[6], rel=1e-6)
    assert r.excluded_grids == excluded
    # exact rigid motions on the fitted grids: a 6-column fit of R reproduces them to
    # rounding (1e-12 of the shapes)
    op2 = read_op2_modes(path)
    keep = np.isin(m.grid_ids, op2.grid_ids) & ~np.isin(m.grid_ids, excluded)
    R = rigid_basis_at(m.xyz_m[keep]).reshape(-1, 6)
    ph = m.phi[keep, :, :6].reshape(-1, 6)
    act = np.any(m.phi[keep, :, :6] != 0, axis=2).ravel()  # DOFs the file leaves at zero
    a, *_ = np.linalg.lstsq(R[act], ph[act], rcond=None)
    assert np.linalg.norm(R[act] @ a - ph[act]) <= 1e-12 * np.linalg.norm(ph)
    # ... spanning the file's own rigid modes there (float32 file: 1e-6)
    filem = np.asarray(op2.shapes_basic(), float)
    rows = np.searchsorted(op2.grid_ids, m.grid_ids[keep])
    fr = filem[rows][:, :, :6] / np.sqrt(op2.generalized_mass[:6] * IN.mass_kg)
    fr[:, 3:] /= IN.length_m  # to SI as modal_model_from_op2 does (file_units docstring)
    fr = fr.reshape(-1, 6)
    q, _ = np.linalg.qr(ph[act])
    assert np.linalg.norm(fr[act] - q @ (q.T @ fr[act])) <= 1e-5 * np.linalg.norm(fr[act])


def test_against_pynastran_eigenvalues():
    pytest.importorskip("pyNastran")
    from pyNastran.op2.op2 import read_op2

    for path in (V2007, CSUPER, EXTSE):
        ref = read_op2(str(path), debug=None, build_dataframe=False)
        cycles = np.sort(np.abs(next(iter(ref.eigenvalues.values())).cycles))
        mine = np.sort(np.abs(read_op2_modes(path).freq_hz_signed))
        np.testing.assert_allclose(mine, cycles, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("path, f06", [(CSUPER, F06_CSUPER), (EXTSE, F06_EXTSE)])
def test_free_free_assemblies_run_from_the_command_line(path, f06, capsys):
    # the modal structure checks the rigid modes against rigid motion at the grids the
    # reader fitted: the grids it left out (70, the modal grids) and the DOFs no mode moves
    # (grid 70 of extseout has no x, ry, rz) keep the file's motion and are not checked
    from microg.cli import main
    from microg.structure.modal import modal_structure

    s = modal_structure(modal_model_from_op2(path, IN))
    assert s.total_mass > 0
    assert main(["modes", str(path), "--units", "in, lbf, s", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert [m["rigid"] for m in doc["modes"]].count(True) == 6
    assert doc["modes"][6]["freq_hz"] == pytest.approx(f06[6], rel=1e-6)  # as above
