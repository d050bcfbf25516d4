"""The OP2 reader against NASTRAN's own printed output and against pyyeti's/pyNastran's readers.

Fixtures (tests/data/nastran/): beam_modes/beam_modes_m2.op2 + beam_modes.f06, a Simcenter
Nastran SOL 103 run (pyNastran models/, BSD, LICENSE-pyNastran.md); cla_residual.op2, a
free-free SOL 103 residual run with a CORD2R output system (pyyeti
tests/cla_test_data_2020, LICENSE-pyyeti.txt).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from microg.models.modal import parse_units, rigid_basis_at
from microg.models.nastran import modal_model_from_op2, read_op2_modes

pytestmark = pytest.mark.nastran

DATA = Path(__file__).parent.parent / "data" / "nastran"
BEAM = DATA / "beam_modes" / "beam_modes_m2.op2"
F06 = DATA / "beam_modes" / "beam_modes.f06"
CLA = DATA / "cla_residual.op2"


def _f06():
    """Parse the F06 eigenvalue table and eigenvectors (independent of the OP2 reader)."""
    text = F06.read_text()
    table = text.split("R E A L   E I G E N V A L U E S")[1].split("\n1 ")[0]
    rows = [ln.split() for ln in table.splitlines() if re.match(r"\s+\d+\s+\d+\s+[-\d.]", ln)]
    eig = np.array([[float(v) for v in r[2:7]] for r in rows])
    vecs = {}
    for block in text.split("R E A L   E I G E N V E C T O R   N O .")[1:]:
        mode = int(block.split()[0])
        vals = {}
        for ln in block.splitlines()[1:]:
            p = ln.split()
            if len(p) == 8 and p[1] == "G":
                vals[int(p[0])] = [float(v) for v in p[2:]]
            elif vals and ln.startswith("1"):
                break
        vecs[mode] = np.array([vals[g] for g in sorted(vals)])
    return eig, vecs


def test_eigenvalues_equal_the_f06_to_its_printed_digits():
    eig, _ = _f06()
    op2 = read_op2_modes(BEAM)
    assert op2.mode.tolist() == list(range(1, 11))
    # F06 prints 7 significant digits (half a unit in the last: 5e-7 relative); the OP2 holds
    # float32 (6e-8 relative): both roundings together
    assert np.allclose(op2.eigenvalue, eig[:, 0], rtol=5.6e-7, atol=0)
    assert np.allclose(op2.freq_hz_signed, eig[:, 2], rtol=5.6e-7, atol=0)


def test_eigenvectors_equal_the_f06():
    eig, vecs = _f06()
    op2 = read_op2_modes(BEAM)
    s = op2.shapes  # (12, 6, 10), grids 1..12, basic (CD 0)
    tol = 5.6e-7  # printed 7 digits of values scaled to a unit largest component, + float32
    # distinct eigenvalues: the printed vector itself
    for j in (5, 6):
        assert np.max(np.abs(s[:, :, j - 1] - vecs[j])) <= tol * np.max(np.abs(vecs[j]))
    # double eigenvalues (the round section bends alike in y and z): the OP2 and the F06
    # print different bases of the same eigenspace, so compare the mass-normalised pairs:
    # F06 pair = OP2 pair @ Q with Q orthogonal (both M-orthonormal bases)
    gm_f06 = eig[:, 3]
    for j in (1, 3, 7, 9):
        op = np.stack(
            [
                s[:, :, j - 1].ravel() / np.sqrt(op2.generalized_mass[j - 1]),
                s[:, :, j].ravel() / np.sqrt(op2.generalized_mass[j]),
            ],
            axis=1,
        )
        f6 = np.stack(
            [vecs[j].ravel() / np.sqrt(gm_f06[j - 1]), vecs[j + 1].ravel() / np.sqrt(gm_f06[j])],
            axis=1,
        )
        q, *_ = np.linalg.lstsq(op, f6, rcond=None)
        assert np.allclose(q.T @ q, np.eye(2), atol=5e-6)
        assert np.max(np.abs(op @ q - f6)) <= 5e-6 * np.max(np.abs(f6))


def test_beam_model_in_si():
    m = modal_model_from_op2(BEAM, parse_units("in, lbf, s"))
    eig, _ = _f06()
    assert m.replaced_rigid is None  # clamped: no rigid modes
    assert np.allclose(m.omega, eig[:, 1], rtol=6e-7)
    assert m.xyz_m[10] == pytest.approx([10 * 0.0254, 0, 0])
    # the OGPWG rigid-body mass (input mass, no WTMASS): 0.0261 lbf s^2/in of beam + CONM2
    assert m.rigid_mass[0, 0] == pytest.approx(0.026105 * 175.12683524647636, rel=1e-4)


def test_free_free_rigid_modes_replaced_and_cd_rotation():
    op2 = read_op2_modes(CLA)
    assert set(np.unique(op2.cd)) == {0, 10}  # grids with output in CORD2R 10
    m = modal_model_from_op2(CLA, parse_units("in, lbf, s"))
    r = m.replaced_rigid
    assert r.count == 6 and r.mass_source == "OGPWG"
    assert 1e-6 < r.max_file_freq_hz < 1e-4 and r.first_elastic_hz == pytest.approx(
        1.6965, rel=1e-4
    )
    assert np.all(m.omega[:6] == 0.0)
    # the file's rigid shapes, rotated from CD 10 to basic, are rigid motions in basic to the
    # float32 precision of the file: a wrong rotation would leave residuals of order 1
    assert r.max_rigid_residual < 1e-5


def test_cla_against_pyyeti():
    pytest.importorskip("pyyeti")
    import warnings

    from pyyeti.nastran import n2p
    from pyyeti.nastran import op2 as yop2

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = yop2.rdpostop2(str(CLA), getougv1=True)
    ref = d["mats"]["ougv1"][0]
    mine = read_op2_modes(CLA)
    assert np.allclose(mine.eigenvalue, ref["lambda"], rtol=1e-7, atol=1e-12)
    # pyyeti's OUGV1 rows: [grid, dof] in the file's output systems
    dof = ref["dof"]
    grids = np.isin(dof[:, 0], mine.grid_ids)
    rows = np.searchsorted(mine.grid_ids, dof[grids, 0])
    got = mine.shapes[rows, dof[grids, 1] - 1, :]
    assert np.array_equal(got.astype(np.float32), ref["ougv1"][grids].astype(np.float32))
    # rotation to basic: pyyeti's rigid-body modes in each grid's output system (n2p.rbgeom_uset)
    uset = d["uset"]
    rb = n2p.rbgeom_uset(uset, np.zeros(3))  # (ndof, 6), global (CD) systems, about origin
    ids = uset.index.get_level_values(0).to_numpy()
    comp = uset.index.get_level_values(1).to_numpy()
    sel = np.isin(ids, mine.grid_ids) & (comp > 0)
    cd_rb = np.zeros((mine.grid_ids.size, 6, 6))
    cd_rb[np.searchsorted(mine.grid_ids, ids[sel]), comp[sel] - 1, :] = rb[sel]
    # mine: the same rigid motions, rotated from CD to basic, must be basic rigid motions
    rot = type(mine)(**{**mine.__dict__, "shapes": cd_rb}).shapes_basic()
    # SE 101's interior grids have no position in this OP2 (NaN): SE 0's grids are compared
    placed = ~np.isnan(mine.xyz_basic).any(axis=1)
    R0 = rigid_basis_at(mine.xyz_basic[placed])
    assert np.allclose(rot[placed], R0, atol=1e-9 * np.abs(R0).max())


def test_cla_against_pynastran():
    pytest.importorskip("pyNastran")
    from pyNastran.op2.op2 import read_op2

    model = read_op2(str(CLA), debug=None, build_dataframe=False)
    ev = next(iter(model.eigenvectors.values()))
    mine = read_op2_modes(CLA)
    nid = ev.node_gridtype[:, 0]
    grid = ev.node_gridtype[:, 1] == 1
    rows = np.searchsorted(mine.grid_ids, nid[grid])
    ref = np.transpose(ev.data[:, grid, :], (1, 2, 0))  # (g, 6, m)
    assert np.array_equal(mine.shapes[rows].astype(np.float32), ref.astype(np.float32))
