"""OP2 reader details (SORT2, bad files), OP4 models, units at the boundary, load_model."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.load import load_model
from microg.models.nastran import Op2File, read_op2_modes
from microg.models.toml import load_station
from microg.structure.discretize import discretize
from microg.structure.modal import modal_structure

pytestmark = pytest.mark.nastran

DATA = Path(__file__).parent.parent / "data" / "nastran"
BEAM = DATA / "beam_modes" / "beam_modes_m2.op2"


def _write_op2(tables, path):
    """Write OUTPUT2 records (32-bit little-endian): the layout Op2File reads."""
    out = bytearray()

    def rec(b):
        out.extend(struct.pack("<i", len(b)) + b + struct.pack("<i", len(b)))

    def key(v):
        rec(struct.pack("<i", v))

    for name, trailer, records in tables:
        key(2)
        rec(name.ljust(8).encode()[:8])
        key(-1)
        key(7)
        rec(np.asarray(trailer, "<i4").tobytes())
        key(-2)
        key(1)
        key(0)
        for r, data in enumerate(records):
            key(len(data) // 4)
            rec(data)
            key(-(r + 3))
            key(1)
            key(0)
        key(0)
    key(0)
    path.write_bytes(bytes(out))
    return path


def _sort2_copy(tmp_path):
    """The beam OP2 with its OUGV1 rewritten in SORT2 (one record pair per grid)."""
    f = Op2File(BEAM)
    tables = []
    for name, trailer, recs in f.tables:
        if name != "OUGV1":
            tables.append((name, trailer, recs))
            continue
        pairs = [(recs[i], recs[i + 1]) for i in range(1, len(recs) - 1, 2)]
        n = len(pairs[0][1]) // 32
        data = np.stack([np.frombuffer(d, "<f4").reshape(n, 8) for _, d in pairs])  # (m, n, 8)
        ints = np.frombuffer(pairs[0][1], "<i4").reshape(n, 8)
        new = [recs[0]]
        for gi in range(n):
            ident = np.frombuffer(pairs[0][0], "<i4").copy()
            ident[1] = 2007  # SORT2 real eigenvectors
            ident[4] = ints[gi, 0]  # grid id * 10 + device code
            rows = data[:, gi, :].copy()
            rows_i = rows.view("<i4")
            rows_i[:, 0] = np.arange(1, data.shape[0] + 1)  # mode numbers
            rows_i[:, 1] = ints[gi, 1]
            new += [ident.tobytes(), rows.tobytes()]
        tables.append((name, trailer, new))
    return _write_op2(tables, tmp_path / "sort2.op2")


def test_sort2_equals_sort1(tmp_path):
    s1 = read_op2_modes(BEAM)
    s2 = read_op2_modes(_sort2_copy(tmp_path))
    assert s1.sort == "SORT1" and s2.sort == "SORT2"
    assert np.array_equal(s2.grid_ids, s1.grid_ids)
    assert np.array_equal(s2.shapes, s1.shapes)  # same float32 values, other layout
    assert np.array_equal(s2.eigenvalue, s1.eigenvalue)


def test_op2_without_eigenvectors(tmp_path):
    f = Op2File(BEAM)
    bad = _write_op2([t for t in f.tables if t[0] != "OUGV1"], tmp_path / "noeig.op2")
    with pytest.raises(InputError, match="no real eigenvectors") as exc:
        read_op2_modes(bad)
    assert exc.value.where == str(bad) and "\n" not in str(exc.value)


@pytest.mark.parametrize("cut", [100, 20000, 60000])
def test_truncated_op2(tmp_path, cut):
    bad = tmp_path / "cut.op2"
    bad.write_bytes(BEAM.read_bytes()[:cut])
    with pytest.raises(InputError, match="truncated or corrupt") as exc:
        read_op2_modes(bad)
    assert exc.value.where == str(bad)


def test_not_an_op2(tmp_path):
    bad = tmp_path / "x.op2"
    bad.write_bytes(b"hello world, not fortran records")
    with pytest.raises(InputError, match="not an OP2"):
        read_op2_modes(bad)


def test_units_required_and_grid_not_in_file(tmp_path):
    with pytest.raises(InputError, match="declare no units") as exc:
        load_model(BEAM)
    assert exc.value.where == str(BEAM)
    pts = tmp_path / "p.toml"
    pts.write_text('units = "in, lbf, s"\n[points]\nlab = "grid:40"\n')
    with pytest.raises(
        InputError, match=r"nearest grids: grid:8, grid:9, grid:10, grid:11, grid:12"
    ):
        load_model(BEAM, points=pts)
    pts.write_text('units = "in, kg, s"\n')
    with pytest.raises(InputError, match="cannot be derived"):
        load_model(BEAM, points=pts)


def test_units_conversion_of_the_beam(tmp_path):
    a = load_model(BEAM, units="in, lbf, s")
    b = load_model(BEAM, units="m, N, s")
    # same numbers read as inches: positions scale by 0.0254, frequencies do not change,
    # mass-normalised translations by 1/sqrt(slinch/kg) (module docstring of modal.py)
    assert np.allclose(a.xyz_m, 0.0254 * b.xyz_m)
    assert np.allclose(a.omega, b.omega)
    assert np.allclose(a.phi[:, :3], b.phi[:, :3] / np.sqrt(175.12683524647636))
    assert np.allclose(a.phi[:, 3:], b.phi[:, 3:] / np.sqrt(175.12683524647636) / 0.0254)


def test_op4_model_from_maa_kaa(tmp_path):
    """MAA/KAA of microg's own FE model of IOC written by pyyeti, read back and solved."""
    pytest.importorskip("pyyeti")
    from pyyeti.nastran import op4

    s = discretize(load_station("ioc-no-orbiter"))
    m, k = s.dense()
    n = m.shape[0] // 6
    op4.write(str(tmp_path / "ioc.op4"), {"MAA": m, "KAA": k})
    pos = np.asarray(s.meta["node_positions"])
    rows = [(g + 1, c, *pos[g]) for g in range(n) for c in range(1, 7)]
    np.savetxt(tmp_path / "ioc.dofmap.csv", rows, delimiter=",", fmt="%d,%d,%.17g,%.17g,%.17g")
    mm = load_model(tmp_path / "ioc.op4", units="m, N, s")
    ref = solve_modes(s)
    r = mm.replaced_rigid
    assert r.count == 6 and r.mass_source == "MAA"
    # reference: microg's exact free-free solve of the same matrices (dense, rigid exact)
    el = ~ref.rigid
    ne = int(el.sum())
    assert np.allclose(mm.omega[6 : 6 + ne], ref.omega[el], rtol=1e-7)
    st = modal_structure(mm, samples=False)
    assert st.total_mass == pytest.approx(s.total_mass, rel=1e-10)


def test_op2_without_geometry_takes_it_from_the_deck_beside_it(tmp_path):
    # rdop2gpwg_1.op2 carries no GEOM1/BGPDT: its grids come from rdop2gpwg_1.dat beside it
    # (microg's own deck reader, GRID/CORD2* only).  References: the deck's GRID cards read
    # as plain fixed fields (all CP = 0, basic; in inches), and a deck of the same grids in
    # a rotated and shifted CORD2R giving the same basic positions (exact for 0/90-degree
    # axes up to rounding, 1e-12)
    import microg
    from microg.models.bdf import grid_geometry

    dat = Path(__file__).resolve().parents[1] / "data" / "nastran" / "rdop2gpwg_1.dat"
    rows = [ln for ln in dat.read_text().splitlines() if ln.startswith("GRID")]
    ids = np.array([int(r[8:16]) for r in rows])
    ref = np.array([[float(r[24 + 8 * k : 32 + 8 * k]) for k in range(3)] for r in rows])
    xyz, cd, systems = grid_geometry(dat, ids)
    np.testing.assert_array_equal(xyz, ref)
    assert not cd.any() and systems == {}
    # the same grids in CS 5 (origin (10, 0, 0), x along basic y, z along basic z)
    lines = ["BEGIN BULK", "CORD2R  5       0       10.     0.      0.      10.     0.      1.",
             "+       10.     1.      0."]  # fmt: skip
    for g, p in zip(ids, ref, strict=True):
        # basic p = origin + x_cs * e_y + y_cs * (-e_x) + z_cs * e_z
        x_cs, y_cs, z_cs = p[1], 10.0 - p[0], p[2]
        lines.append(f"GRID    {g:<8d}5       {x_cs:<8.4g}{y_cs:<8.4g}{z_cs:<8.4g}")
    lines.append("ENDDATA")
    deck = tmp_path / "cs5.dat"
    deck.write_text("\n".join(lines) + "\n")
    xyz5, _, systems5 = grid_geometry(deck, ids)
    np.testing.assert_allclose(xyz5, ref, atol=1e-12 * np.abs(ref).max())
    assert set(systems5) == {5}
    # the OP2 reads through it: the rigid-body replacement fits the file's modes there
    model = microg.load_model(dat.with_suffix(".op2"), units="in,lbf,s")
    np.testing.assert_allclose(model.xyz_m, ref * 0.0254, rtol=1e-15, atol=0)


@pytest.mark.parametrize(
    "file, wtmass, message",
    [
        # rdop2gpwg_1.op2's PVT0 holds PARAM,WTMASS,0.00259
        ("rdop2gpwg_1.op2", 1.0, r"WTMASS 1 declared, but the run used PARAM,WTMASS,0.00259"),
        ("rdop2gpwg_1.op2", 0.5, r"WTMASS 0.5 declared"),
        ("rdop2gpwg_1.op2", 0, r"must be > 0"),
        ("rdop2gpwg_1.op2", 1e-300, r"outside 1e-06 to 1000"),
        # extseout_assemble.op2's PVT0 has PARAMs but no WTMASS: the run used 1
        ("extseout_assemble.op2", 0.00259, r"the run used no PARAM,WTMASS \(1\)"),
    ],
)
def test_wtmass_contradicting_the_op2_is_an_error(file, wtmass, message):
    with pytest.raises(InputError, match=message) as exc:
        load_model(DATA / file, units="in, lbf, s", wtmass=wtmass)
    assert exc.value.where == "wtmass"


def test_wtmass_agreeing_with_the_op2_is_accepted():
    m = load_model(DATA / "rdop2gpwg_1.op2", units="in, lbf, s", wtmass=0.00259)
    assert m.units.wtmass == pytest.approx(0.00259, rel=1e-7)  # PVT0 holds a float32


def test_subcase_reaches_the_op2_reader_and_only_it(tmp_path):
    with pytest.raises(InputError, match=r"no modes of subcase 2 in the file \(subcases: 1\)"):
        load_model(DATA / "cla_residual.op2", units="in, lbf, s", subcase=2)
    assert load_model(DATA / "cla_residual.op2", units="in, lbf, s", subcase=1).meta["subcase"] == 1
    with pytest.raises(InputError, match="applies to OP2 files only") as exc:
        load_model("ioc", subcase=1)
    assert exc.value.where == "subcase"
