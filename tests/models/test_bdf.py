"""Tests of microg.models.bdf (and bdf_properties): card conversions, units and bad input.

References: the NASTRAN Quick Reference Guide's field layouts and conventions (cited per
test), hand calculations of coordinate transformations, and, in the ``nastran`` extra's
environment, pyNastran's parse of the same decks.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.bdf import load_bdf
from microg.structure.discretize import discretize
from microg.structure.frame import assemble_frame, build_frame
from microg.units import IN, LBF

FIXTURE = Path(__file__).resolve().parents[1] / "data" / "nastran" / "beam_modes"

# reader tests run in the main environment and again in the pyNastran one (.ci/nastran-extra.sh)
pytestmark = pytest.mark.nastran


def _deck(tmp_path: Path, body: str, name: str = "deck.bdf") -> Path:
    p = tmp_path / name
    p.write_text(body)
    return p


BASE = """\
GRID,1,,0.,0.,0.
GRID,2,,1.,0.,0.
MAT1,1,1.0+7,,0.3,1.0-4
PBAR,10,1,0.5,0.02,0.03,0.04
CBAR,1,10,1,2,0.,1.,0.
"""


#: coordinate systems (CORD2C, a CORD2R referencing it, CORD2S) and grids in them
DECK_CS = (
    "CORD2C,1,0,1.,2.,3.,1.,2.,4.,+\n+,2.,2.,3.\n"
    "CORD2R,2,1,1.,0.,0.,1.,0.,1.,+\n+,1.,90.,0.\n"
    "CORD2S,3,0,0.,0.,0.,0.,0.,1.,+\n+,1.,0.,0.\n"
    "GRID,1,1,2.,90.,1.,1\n"
    "GRID,2,2,1.,0.,0.\n"
    "GRID,3,3,1.,90.,0.,3\n"
    "CONM2,1,1,,1.0\nCONM2,2,2,,1.0\nCONM2,3,3,,1.0\n"
)
#: concentrated masses: products of inertia, offsets, CID = -1 and a rotated CID
DECK_CONM2 = (
    "PARAM,WTMASS,0.5\n"
    "CORD2R,5,0,0.,0.,0.,0.,0.,1.,+\n+,0.,1.,0.\n"  # x' = +y, z' = +z, y' = -x
    "GRID,1,,1.,0.,0.\n"
    "CONM2,1,1,0,4.0,0.1,0.2,0.3,,+\n+,10.,1.,20.,2.,3.,30.\n"
    "CONM2,2,1,-1,4.0,1.5,0.,0.\n"
    "CONM2,3,1,5,4.0,0.1,0.,0.,,+\n+,10.,0.,20.,0.,0.,30.\n"
)
#: bar and beam properties: PBAR with and without K, PBEAM, PBARL ROD
DECK_PROPS = (
    "GRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\nGRID,3,,2.,0.,0.\nGRID,4,,3.,0.,0.\n"
    "MAT1,1,2.0+11,8.0+10,,7800.\n"
    "PBAR,10,1,0.5,0.02,0.03,0.04,1.5\n"
    "PBAR,11,1,0.5,0.02,0.03,0.04,,,+\n+,,,,,,,,,+\n+,0.8,0.7\n"
    "PBEAM,12,1,0.5,0.02,0.03,0.,0.04\n"
    "PBARL,13,1,,ROD,,,,,+\n+,0.1\n"
    "CBAR,1,10,1,2,0.,1.,0.\nCBAR,2,11,2,3,0.,1.,0.\nCBEAM,3,12,3,4,0.,1.,0.\n"
    "CBAR,4,13,1,3,0.,0.,1.\n"
)


def test_units_declared_and_converted(tmp_path):
    # the same deck in in-lbf-s and in mm-N-ms: positions scale by the length unit, E by
    # force/length^2; a missing or malformed declaration is one line naming the fix
    deck = _deck(tmp_path, BASE)
    a = load_bdf(deck, units="in, lbf, s")
    b = load_bdf(deck, units="mm,N,ms")
    assert a.node("grid:2").position[0] == pytest.approx(IN, rel=1e-15)
    assert b.node("grid:2").position[0] == pytest.approx(1e-3, rel=1e-15)
    assert a.beams[0].section.ea_N == pytest.approx(1e7 * 0.5 * LBF, rel=1e-14)  # E A: psi in^2
    # density 1e-4 (force time^2 / length^4): mm-N-ms gives 1e-4 N ms^2/mm^4 = 1e2 kg/mm^3...
    rho_si = 1e-4 * 1.0 * 1e-3**2 / 1e-3**4
    assert b.beams[0].section.mass_per_length_kg_per_m == pytest.approx(rho_si * 0.5e-6, rel=1e-14)
    for bad, what in (
        (None, "declare no units"),
        ("in, lbf", "LENGTH, FORCE, TIME"),
        ("in, kg, s", "force"),
        ("in, lbf, s, kg", "inconsistent"),
    ):
        with pytest.raises(InputError, match=what) as exc:
            load_bdf(deck, units=bad)
        assert "\n" not in str(exc.value) and "(" in str(exc.value)


# --------------------------------------------------------------------------- conversions


def test_coordinate_systems_positions_and_displacement_axes(tmp_path):
    # CORD2C 1: origin (1, 2, 3), z along basic z, x along basic x.  Grid 1 at (r, theta, z)
    # = (2, 90 deg, 1) is basic (1, 4, 4) by hand; its CD = 1 axes there are radial = +y,
    # tangential = -x, axial = +z.  CORD2R 2 references 1 (RID chain): origin at cyl
    # (1, 0, 0) = basic (2, 2, 3), z along the cyl z, x towards cyl (1, 90, 0) = basic (1, 3, 3)
    # from it: x' = (-1, 1, 0)/sqrt 2.  CORD2S 3: r = 1, theta = 90, phi = 0 -> basic +x.
    g = load_bdf(_deck(tmp_path, DECK_CS), units="m, N, s")
    pos = {n.name: n for n in g.nodes}
    np.testing.assert_allclose(pos["grid:1"].position, [1, 4, 4], atol=1e-14)
    np.testing.assert_allclose(pos["grid:1"].axes, [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(
        pos["grid:2"].position, [2 - 1 / math.sqrt(2), 2 + 1 / math.sqrt(2), 3], atol=1e-14
    )
    np.testing.assert_allclose(pos["grid:3"].position, [1, 0, 0], atol=1e-15)
    # spherical axes at +x (theta = 90, phi = 0): radial +x, meridional -z, azimuthal +y
    np.testing.assert_allclose(pos["grid:3"].axes, [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-15)


def test_conm2_inertia_signs_offsets_and_systems(tmp_path):
    # QRG CONM2: inertia matrix [[I11, -I21, -I31], [-I21, I22, -I32], [-I31, -I32, I33]];
    # offsets in CID (CID = -1: X is the c.g. in basic); WTMASS scales mass and inertia
    g = load_bdf(_deck(tmp_path, DECK_CONM2), units="m, N, s")
    m = {c.name: c for c in g.masses}
    assert m["conm2:1"].mass_kg == 2.0  # 4 x WTMASS 0.5
    np.testing.assert_allclose(m["conm2:1"].offset_m, [0.1, 0.2, 0.3])
    np.testing.assert_allclose(
        m["conm2:1"].inertia_kg_m2, 0.5 * np.array([[10, -1, -2], [-1, 20, -3], [-2, -3, 30.0]])
    )
    np.testing.assert_allclose(m["conm2:2"].offset_m, [0.5, 0, 0])
    np.testing.assert_allclose(m["conm2:3"].offset_m, [0, 0.1, 0], atol=1e-16)
    # the inertia about x' (= basic y) is 10, about y' (= -x) 20
    np.testing.assert_allclose(np.diag(m["conm2:3"].inertia_kg_m2), 0.5 * np.array([20, 10, 30.0]))


def test_wtmass_from_deck_or_argument_and_contradiction(tmp_path):
    plain = _deck(tmp_path, BASE)
    with_wt = _deck(tmp_path, BASE + "PARAM,WTMASS,0.00259\n", "wt.bdf")
    a = load_bdf(plain, units="in, lbf, s", wtmass=0.00259)
    b = load_bdf(with_wt, units="in, lbf, s")
    assert a.meta["wtmass"] == b.meta["wtmass"] == 0.00259
    assert a.beams[0].section.mass_per_length_kg_per_m == pytest.approx(
        0.00259 * 1e-4 * 0.5 * LBF / IN / IN, rel=1e-14
    )  # rho A WTMASS in lbf s^2/in per in, in kg/m
    assert load_bdf(with_wt, units="in, lbf, s", wtmass=0.00259).meta["wtmass"] == 0.00259
    with pytest.raises(InputError, match="contradicts wtmass") as exc:
        load_bdf(with_wt, units="in, lbf, s", wtmass=1.0)
    assert "wt.bdf:" in str(exc.value)


def test_bar_shear_factors_and_property_types(tmp_path):
    # PBAR K1/K2 blank: no shear flexibility (QRG PBAR remark: infinite); PBEAM K default
    # 1.0; PBARL ROD r: A = pi r^2, I = pi r^4/4, J = 2 I, K = 0.9
    g = load_bdf(_deck(tmp_path, DECK_PROPS), units="m, N, s")
    s = {b.name: b.section for b in g.beams}
    assert s["cbar:1"].shear_y_N is None and s["cbar:1"].shear_z_N is None
    assert s["cbar:1"].mass_per_length_kg_per_m == pytest.approx(7800 * 0.5 + 1.5)
    assert s["cbar:2"].shear_y_N == pytest.approx(0.8 * 8e10 * 0.5)
    assert s["cbar:2"].shear_z_N == pytest.approx(0.7 * 8e10 * 0.5)
    assert s["cbeam:3"].shear_y_N == pytest.approx(8e10 * 0.5)
    # I1 (plane 1, deflection along y) -> bending about local z; I2 -> about local y
    assert s["cbar:1"].ei_z_N_m2 == pytest.approx(2e11 * 0.02)
    assert s["cbar:1"].ei_y_N_m2 == pytest.approx(2e11 * 0.03)
    r = 0.1
    assert s["cbar:4"].ea_N == pytest.approx(2e11 * math.pi * r**2)
    assert s["cbar:4"].gj_N_m2 == pytest.approx(8e10 * math.pi * r**4 / 2)
    assert s["cbar:4"].shear_y_N == pytest.approx(0.9 * 8e10 * math.pi * r**2)
    assert {b.name: b.kind for b in g.beams}["cbeam:3"] == "beam"


def test_bar_orientation_offsets_and_pins(tmp_path):
    # G0: v from GA to G0; BAROR supplies a missing vector; OFFT "BGG": v in basic while GA
    # has rotated CD axes; offsets WA/WB in the grids' displacement systems (QRG CBAR)
    text = (
        "CORD2R,1,0,0.,0.,0.,0.,0.,1.,+\n+,0.,1.,0.\n"  # x' = +y, y' = -x
        "GRID,1,,0.,0.,0.,1\nGRID,2,,1.,0.,0.\nGRID,3,,0.,0.,5.\n"
        "MAT1,1,2.0+11,8.0+10\nPBAR,10,1,0.5,0.02,0.03,0.04\n"
        "BAROR,,10,,,0.,0.,1.\n"
        "CBAR,1,10,1,2,3\n"
        "CBAR,2,,1,2\n"
        "CBAR,3,10,1,2,1.,0.,0.,GGG\n"
        "CBAR,4,10,1,2,0.,1.,0.,BGG,+\n+,,456,0.1,0.,0.,0.,0.,0.2\n"
    )
    g = load_bdf(_deck(tmp_path, text), units="m, N, s")
    b = {e.name: e for e in g.beams}
    np.testing.assert_allclose(b["cbar:1"].orientation, [0, 0, 5])
    np.testing.assert_allclose(b["cbar:2"].orientation, [0, 0, 1])  # from BAROR
    np.testing.assert_allclose(b["cbar:3"].orientation, [0, 1, 0], atol=1e-15)  # x' of grid 1 = +y
    np.testing.assert_allclose(b["cbar:4"].orientation, [0, 1, 0])
    np.testing.assert_allclose(b["cbar:4"].offsets, [[0, 0.1, 0], [0, 0, 0.2]], atol=1e-15)
    assert b["cbar:4"].releases == ("", "456")


def test_cbush_axes_location_and_celas(tmp_path):
    text = (
        "CORD2R,7,0,0.,0.,0.,1.,0.,0.,+\n+,0.,1.,0.\n"  # z' = +x, x' = +y
        "GRID,1,,0.,0.,0.\nGRID,2,,0.,0.,0.\nGRID,3,,2.,0.,0.\n"
        "PBUSH,5,K,1.,2.,3.,4.,5.,6.,+\n+,,B,0.1\n"
        "CBUSH,1,5,1,2,,,,7\n"  # coincident: CID gives the axes
        "CBUSH,2,5,1,3,0.,0.,1.,,+\n+,0.25\n"  # x from 1 to 3, y from v; point at S = 0.25
        "CBUSH,3,5,3\n"  # grounded, no orientation: needs K2 = K3 ... (fails below)
        "PELAS,8,100.\n"
        "CELAS1,4,8,1,1,3,5\n"
        "CELAS2,5,7.,3,1\n"
        "CONM2,9,1,,1.\nCONM2,10,2,,1.\nCONM2,11,3,,1.\n"
    )
    with pytest.raises(InputError, match="CBUSH 3") as exc:
        load_bdf(_deck(tmp_path, text), units="in, lbf, s")
    assert "coordinate system" in str(exc.value)
    g = load_bdf(
        _deck(tmp_path, text.replace("CBUSH,3,5,3\n", "CBUSH,3,5,3,,,,,0\n")), units="in, lbf, s"
    )
    sp = {s.name: s for s in g.springs}
    np.testing.assert_allclose(sp["cbush:1"].axes, [[0, 1, 0], [0, 0, 1], [1, 0, 0]], atol=1e-15)
    np.testing.assert_allclose(sp["cbush:2"].axes, [[1, 0, 0], [0, 0, 1], [0, -1, 0]], atol=1e-15)
    np.testing.assert_allclose(sp["cbush:2"].location, [0.5 * IN, 0, 0], rtol=1e-15)
    assert sp["cbush:3"].nodes == ("grid:3", None)
    # K1-3 in lbf/in, K4-6 in lbf in (per rad), B1 in lbf s/in
    k = np.diag(sp["cbush:1"].stiffness)
    np.testing.assert_allclose(
        k, np.r_[np.array([1, 2, 3]) * LBF / IN, np.array([4, 5, 6]) * LBF * IN]
    )
    assert sp["cbush:1"].damping[0, 0] == pytest.approx(0.1 * LBF / IN)
    cel = {c.name: c for c in g.scalar_springs}
    assert cel["celas1:4"].dofs == (("grid:1", 1), ("grid:3", 5))
    assert cel["celas1:4"].stiffness == pytest.approx(100.0 * LBF)  # translation-rotation: lbf/rad
    assert cel["celas2:5"].dofs == (("grid:3", 1), None)
    assert cel["celas2:5"].stiffness == pytest.approx(7.0 * LBF / IN)


def test_rigid_elements_and_constraints(tmp_path):
    text = (
        "SOL 103\nCEND\nSUBCASE 1\n  SPC = 3\nBEGIN BULK\n"
        + "".join(f"GRID,{i},,{float(i)},0.,0.\n" for i in range(1, 7))
        + "RBE2,10,1,123456,2,3\n"
        "RBE3,11,,4,123456,1.0,123,5,6,+\n+,2.0,12,2\n"
        "CONM2,1,5,,1.\nCONM2,2,6,,1.\nCONM2,3,1,,1.,,,,,+\n+,1.,,1.,,,1.\n"
        "SPC1,1,123,1,THRU,3\nSPC,2,6,456\nSPCADD,3,1,2\nENDDATA\n"
    )
    g = load_bdf(_deck(tmp_path, text), units="m, N, s")
    assert g.rigid_links[0].dependents == ("grid:2", "grid:3")
    ip = g.interpolations[0]
    assert ip.reference == "grid:4" and ip.components == "123456"
    assert ip.sources == (("grid:5", "123", 1.0), ("grid:6", "123", 1.0), ("grid:2", "12", 2.0))
    cons = {(c.node, c.components) for c in g.constraints}
    assert cons == {("grid:1", "123"), ("grid:2", "123"), ("grid:3", "123"), ("grid:6", "456")}
    # RBE3 with rotational independent components and UM (the moved dependent components)
    # are read as written; ALPHA and what follows (thermal) are ignored
    full = "RBE3,11,,4,123,1.0,123456,5,6,+\n+,UM,5,1,6,23,ALPHA,1.-5\n"
    g2 = load_bdf(
        _deck(tmp_path, text.replace(text[text.index("RBE3") :].split("CONM2")[0], full), "um.bdf"),
        units="m, N, s",
    )
    ip = g2.interpolations[0]
    assert ip.sources == (("grid:5", "123456", 1.0), ("grid:6", "123456", 1.0))
    assert ip.moved == (("grid:5", "1"), ("grid:6", "23"))
    for bad, what in (
        ("RBE3,11,,4,123,1.0,123,5,6,UM,4,1", "holds 8 data fields"),  # no field dropped
        ("RBE3,11,,4,123,-1.0,123,5,6", "must be > 0"),
        ("RBE3,11,,4,123,1.0,123,5,6,+\n+,UM,99,1", "GM grid 99 is not defined"),
    ):
        t2 = text.replace("RBE3,11,,4,123456,1.0,123,5,6,+\n+,2.0,12,2\n", bad + "\n")
        with pytest.raises(InputError, match=what):
            load_bdf(_deck(tmp_path, t2, "bad.bdf"), units="m, N, s")


def test_coupmass_selects_coupled_mass(tmp_path):
    g = load_bdf(_deck(tmp_path, BASE), units="m, N, s", coupled_mass="coupled-nx9")
    assert g.mass_formulation == "lumped"  # no COUPMASS: lumped whatever coupled_mass says
    assert g.meta["mass_formulation_note"].startswith("lumped (no PARAM,COUPMASS > 0")
    deck = _deck(tmp_path, BASE + "PARAM,COUPMASS,1\n", "c.bdf")
    assert load_bdf(deck, units="m, N, s").mass_formulation == "coupled"  # current Simcenter
    for form in ("coupled-nx9", "consistent"):
        assert load_bdf(deck, units="m, N, s", coupled_mass=form).mass_formulation == form


def test_fixture_deck_cards_and_ignored_ones():
    g = load_bdf(FIXTURE / "beam_modes.dat", units="in, lbf, s")
    assert len(g.nodes) == 12 and len(g.beams) == 10 and len(g.masses) == 1
    assert g.meta["ignored_cards"] == {"EIGRL": 1, "USET": 1}
    assert "K6ROT" not in g.meta["params_ignored"]  # read: it scales the shells' drilling
    assert any("K6ROT" in w for w in g.meta["warnings"])


def test_analysis_sets_are_said_to_be_unapplied(tmp_path):
    # a NASTRAN run with BSET/QSET prints fixed-boundary modes: the free-free modes microg
    # solves are not that table, and the deck's sets are named in one warning
    plain = load_bdf(_deck(tmp_path, BASE), units="m, N, s")
    assert not any("analysis sets" in w for w in plain.meta["warnings"])
    g = load_bdf(_deck(tmp_path, BASE + "BSET1,123456,1\nQSET1,0,2\n", "s.bdf"), units="m, N, s")
    said = [w for w in g.meta["warnings"] if w.startswith("analysis sets")]
    assert len(said) == 1 and "(BSET1, QSET1) are not applied" in said[0]
    assert "fixed-boundary" in said[0]


# --------------------------------------------------------------------------- bad input


def _one_line(exc: pytest.ExceptionInfo, *parts: str) -> str:
    text = str(exc.value)
    assert "\n" not in text
    for p in parts:
        assert p in text, (p, text)
    return text


def test_unsupported_cards_listed_by_name_and_count(tmp_path):
    text = BASE + "CHEXA,5,20,1,2,2,1\nCHEXA,6,20,1,2,2,1\nPSOLID,20,1\nMAT8,3,1.\n"
    with pytest.raises(InputError) as exc:
        load_bdf(_deck(tmp_path, text), units="m, N, s")
    _one_line(exc, "deck.bdf", "unsupported cards: CHEXA (2), MAT8 (1), PSOLID (1)", "GRID")


def test_an_included_file_that_is_not_a_deck_is_never_echoed(tmp_path):
    # INCLUDE '/etc/passwd' was read and the error listed the first 8 characters of each of
    # its lines ("ROOT:X:0 (1), DAEMON:X ..."); a user name that looks like a card name
    # ("messagebus" -> MESSAGEB) leaked too.  Now: the count and the first line's place only
    secret = tmp_path / "secrets.txt"
    secret.write_text("root:x:0:0:root:/root:/bin/bash\nmessagebus:x:101:102::/x\nTOKEN12 abc\n")
    text = BASE + f"INCLUDE '{secret}'\n"
    with pytest.raises(InputError) as exc:
        load_bdf(_deck(tmp_path, text), units="m, N, s")
    msg = _one_line(exc, "3 line(s) that are not NASTRAN cards", f"{secret}:1")
    for leak in ("ROOT", "MESSAGEB", "TOKEN12", "abc", "bash"):
        assert leak not in msg.replace(str(tmp_path), "").upper(), leak


def test_missing_property_material_grid_zero_length_include(tmp_path):
    cases = [
        (BASE.replace("CBAR,1,10", "CBAR,1,11"), ("deck.bdf:5: CBAR 1", "property 11", "add")),
        (BASE.replace("PBAR,10,1", "PBAR,10,2"), ("deck.bdf:4: PBAR 10", "material 2", "MAT1")),
        (BASE.replace("CBAR,1,10,1,2", "CBAR,1,10,1,7"), ("CBAR 1", "GB grid 7", "nearest: 2, 1")),
        (
            BASE.replace("GRID,2,,1.,0.,0.", "GRID,2,,0.,0.,0."),
            ("deck.bdf:5: CBAR 1", "zero length"),
        ),
        (BASE + "INCLUDE 'nowhere.blk'\n", ("deck.bdf:6", "INCLUDE 'nowhere.blk': file not found")),
        (
            BASE.replace("CBAR,1,10,1,2,0.,1.,0.", "CBAR,1,10,1,2"),
            ("CBAR 1", "no orientation vector"),
        ),
        (BASE.replace("CBAR,1,10,1,2,0.,1.,0.", "CBAR,1,10,1,2,1.,0.,0."), ("CBAR 1", "parallel")),
    ]
    for text, parts in cases:
        with pytest.raises(InputError) as exc:
            load_bdf(_deck(tmp_path, text), units="m, N, s")
        msg = _one_line(exc, *parts)
        assert "(" in msg  # every message carries its fix


def test_cbush_without_needed_orientation(tmp_path):
    text = (
        "GRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\nPBUSH,5,K,1.,2.,3.,4.,5.,6.\n"
        "CBUSH,1,5,1,2\nCONM2,2,2,,1.\n"
    )
    with pytest.raises(InputError) as exc:
        load_bdf(_deck(tmp_path, text), units="m, N, s")
    _one_line(exc, "deck.bdf:4: CBUSH 1", "no orientation", "X1-X3 or G0")
    # equal K2 = K3 and K5 = K6: the orientation does not matter, so none is needed
    ok = text.replace("K,1.,2.,3.,4.,5.,6.", "K,1.,2.,2.,4.,5.,5.")
    assert (
        load_bdf(_deck(tmp_path, ok, "ok.bdf"), units="m, N, s").springs[0].axes[0] @ [1, 0, 0]
        == 1.0
    )


def test_cli_exit_status_two_for_a_bad_deck(tmp_path, capsys):
    # microg modes DECK: a bad deck is one line on stderr and exit status 2 (the CLI maps the
    # library's InputError)
    from microg.cli import main

    deck = _deck(tmp_path, BASE + "CHEXA,5,20,1,2,2,1\n")
    assert main(["modes", str(deck), "--units", "m, N, s"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "unsupported cards: CHEXA (1)" in err
    assert main(["modes", str(_deck(tmp_path, BASE, "ok.bdf"))]) == 2
    assert "units" in capsys.readouterr().err
    bad = {
        "prop.bdf": (BASE.replace("CBAR,1,10", "CBAR,1,11"), "CBAR 1: property 11"),
        "zero.bdf": (BASE.replace("GRID,2,,1.,0.,0.", "GRID,2,,0.,0.,0."), "zero length"),
        "bush.bdf": (
            "GRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\nPBUSH,5,K,1.,2.,3.\nCBUSH,1,5,1,2\n",
            "CBUSH 1",
        ),
    }
    for name, (text, part) in bad.items():
        assert main(["modes", str(_deck(tmp_path, text, name)), "--units", "in,lbf,s"]) == 2
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and name in err and part in err, err


def test_structure_of_a_deck_solves(tmp_path):
    g = load_bdf(_deck(tmp_path, BASE + "CONM2,5,2,,1.0,,,,,+\n+,1.,,1.,,,1.\n"), units="m, N, s")
    s = build_frame(g)
    fm = assemble_frame(g)
    assert s.total_mass == pytest.approx(1.0 + 1e-4 * 0.5, rel=1e-14)
    assert fm.stiffness.shape == (12, 12)


# --------------------------------------------------------------------------- pyNastran


def test_reader_agrees_with_pynastran(tmp_path):
    # in the nastran extra's environment: pyNastran's parse of the same decks (grid positions
    # in basic through CORD2R/C/S chains, CONM2 mass, c.g. and inertia, PBARL section
    # properties, element connectivity, the deck's total mass and c.g.) equals microg's
    # (1e-12 relative: both are exact arithmetic on the same fields)
    pn = pytest.importorskip("pyNastran.bdf.bdf")
    decks = {"cs": DECK_CS, "conm2": DECK_CONM2, "props": DECK_PROPS}
    paths = {k: _deck(tmp_path, v, f"{k}.bdf") for k, v in decks.items()}
    paths["fixture"] = FIXTURE / "beam_modes.dat"
    checked = 0
    for key, path in paths.items():
        ours = load_bdf(path, units="m, N, s")
        # bulk-only decks are "punch" files to pyNastran
        theirs = pn.read_bdf(str(path), xref=True, debug=None, punch=key != "fixture")
        for nid, node in theirs.nodes.items():
            np.testing.assert_allclose(
                ours.node(f"grid:{nid}").position, node.get_position(), rtol=1e-12, atol=1e-12
            )
        masses = {m.name: m for m in ours.masses}
        wt = ours.meta["wtmass"]
        for eid, m in theirs.masses.items():
            mine = masses[f"conm2:{eid}"]
            assert mine.mass_kg == pytest.approx(m.Mass() * wt, rel=1e-12), key
            cg = ours.node(mine.node).position + mine.offset_m
            np.testing.assert_allclose(cg, m.Centroid(), rtol=1e-12, atol=1e-12)
            if m.Cid() in (0, -1):  # pyNastran gives the inertia in the CONM2's system
                np.testing.assert_allclose(
                    mine.inertia_kg_m2, np.asarray(m.Inertia()) * wt, rtol=1e-12
                )
        beams = {b.name: b for b in ours.beams}
        for eid, e in theirs.elements.items():
            if e.type in ("CBAR", "CBEAM"):
                mine = beams[f"{e.type.lower()}:{eid}"]
                assert mine.nodes == tuple(f"grid:{n}" for n in e.node_ids)
                prop = e.pid_ref
                mat = prop.mid_ref
                pairs = (
                    (mine.section.ea_N, mat.e, prop.Area),
                    (mine.section.ei_z_N_m2, mat.e, prop.I11),
                    (mine.section.ei_y_N_m2, mat.e, prop.I22),
                    (mine.section.gj_N_m2, mat.g, prop.J),
                    (mine.section.mass_per_length_kg_per_m, wt, prop.MassPerLength),
                )
                for value, factor, getter in pairs:
                    theirs_value = getter()
                    if theirs_value is None:  # some pyNastran versions leave PBARL J out
                        continue
                    assert value == pytest.approx(factor * theirs_value, rel=1e-12), key
                    checked += 1
    # positions, masses and section values were compared (not a vacuous loop)
    assert checked >= 20


def test_declared_wtmass_one_contradicting_the_deck_is_an_error(tmp_path):
    # a UnitSystem whose wtmass was declared counts as given, 1.0 included (load_model
    # passes --wtmass this way); the default (not declared) takes the deck's value
    from microg.models.file_units import parse_units

    with_wt = _deck(tmp_path, BASE + "PARAM,WTMASS,0.00259\n", "wt.bdf")
    with pytest.raises(InputError, match="contradicts wtmass = 1"):
        load_bdf(with_wt, units=parse_units("in, lbf, s", wtmass=1.0))
    assert load_bdf(with_wt, units=parse_units("in, lbf, s")).meta["wtmass"] == 0.00259


def test_identical_repeated_cards_count_once_different_ones_are_errors(tmp_path):
    # a boundary GRID in two INCLUDEd files (cla_test_data_2020's outboard.asm, large field
    # with CD/PS/SEID written as 0, and inboard.blk, small field with them blank) is one grid
    same = (
        "GRID*   1               0               0.0             0.0\n"
        "*       0.0             0               0               0\n"
    )
    deck = _deck(tmp_path, BASE + same)
    g = load_bdf(deck, units="in, lbf, s")
    assert sum(1 for n in g.nodes if n.name == "grid:1") == 1
    other = _deck(tmp_path, BASE + "GRID,1,,0.5,0.,0.\n", "other.bdf")
    with pytest.raises(InputError, match="duplicate grid id 1"):
        load_bdf(other, units="in, lbf, s")


def _conm1_fields(m, d, j):
    """CONM1's lower triangle of the rigid-body mass [[m I, -m S], [m S, J + m S^T S]]."""
    s = np.array([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])
    mm = np.zeros((6, 6))
    mm[:3, :3] = m * np.eye(3)
    mm[:3, 3:] = -m * s
    mm[3:, :3] = m * s
    mm[3:, 3:] = j + m * s.T @ s
    return [mm[i, k] for i in range(6) for k in range(i + 1)]


def _card_lines(name, fields):
    """A free-field card with continuations of 8 fields."""
    vals = [str(v) if isinstance(v, int) else f"{v:.16e}" for v in fields]
    first, rest = vals[:8], vals[8:]
    lines = [",".join([name, *first])]
    while rest:
        lines.append(",".join(["", *rest[:8]]))
        rest = rest[8:]
    return "\n".join(lines) + "\n"


def test_conm1_of_a_rigid_body_equals_the_conm2_it_encodes(tmp_path):
    # hand reference: the 6x6 mass of a body of mass m at offset d with inertia J about its
    # centre (Geradin & Rixen, rigid-body kinetic energy), written in a rotated CORD2R 7
    m, d, j = (
        3.0,
        np.array([0.1, -0.2, 0.3]),
        np.array([[4.0, 0.5, 0.0], [0.5, 5.0, 0.2], [0.0, 0.2, 6.0]]),
    )
    cord = "CORD2R,7,,0.,0.,0.,0.,0.,1.\n,1.,1.,0.\n"  # z along basic z, x along (1,1,0)
    deck = _deck(tmp_path, BASE + cord + _card_lines("CONM1", [5, 1, 7, *_conm1_fields(m, d, j)]))
    g = load_bdf(deck, units="m, N, s")
    (cm,) = [x for x in g.masses if x.name == "conm1:5"]
    ax = np.array([[1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) / np.array(
        [[2**0.5], [2**0.5], [1.0]]
    )
    # CID 7 values rotated to basic: rows of ax are CID 7's axes in basic
    assert cm.mass_kg == pytest.approx(m, rel=1e-14)
    np.testing.assert_allclose(cm.offset_m, ax.T @ d, atol=1e-14)
    np.testing.assert_allclose(cm.inertia_kg_m2, ax.T @ j @ ax, atol=1e-13)


def test_conm1_masses_on_a_massless_bar_give_the_hand_frequencies(tmp_path):
    # two CONM1 (mass m, polar inertia jx about the bar) on a massless CBAR of length 1:
    # axial mode omega^2 = 2 E A / (L m), torsion omega^2 = 2 G J / (L jx) (two equal
    # masses on a spring, free-free), to the eigen solver's rounding
    E, nu, A, J, m, jx = 2.0e5, 0.3, 1e-2, 2e-5, 2.0, 0.05
    G = E / (2 * (1 + nu))
    body = [
        "GRID,1,,0.,0.,0.", "GRID,2,,1.,0.,0.", f"MAT1,1,{E},,{nu},0.",
        f"PBAR,10,1,{A},1e-5,1e-5,{J}", "CBAR,1,10,1,2,0.,1.,0.",
    ]  # fmt: skip
    jj = np.diag([jx, 0.01, 0.01])
    text = "\n".join(body) + "\n"
    for eid, gid in ((11, 1), (12, 2)):
        text += _card_lines("CONM1", [eid, gid, 0, *_conm1_fields(m, np.zeros(3), jj)])
    md = solve_modes(discretize(load_bdf(_deck(tmp_path, text), units="m, N, s")))
    f = md.freq_hz
    for w2 in (2 * E * A / m, 2 * G * J / jx):
        assert np.min(np.abs(f - np.sqrt(w2) / (2 * np.pi))) <= 1e-9 * np.sqrt(w2)


def test_conm1_that_is_not_a_rigid_body_is_refused(tmp_path):
    fields = _conm1_fields(1.0, np.zeros(3), np.eye(3))
    fields[2] = 2.0  # M22 != M11
    deck = _deck(tmp_path, BASE + _card_lines("CONM1", [5, 1, 0, *fields]))
    with pytest.raises(InputError, match="only the mass of a rigid body"):
        load_bdf(deck, units="m, N, s")


def test_celas2_and_cbush_frequencies_equal_the_hand_solution(tmp_path):
    # hand solutions, one-DOF oscillators: a grid with CONM2 mass 2 and inertia diag(1, 2, 3)
    # on six grounded CELAS2 springs k = 10..60 gives omega^2 = k_i / m_i; two coincident
    # grids (masses 1 and 3, inertias 1 and 2) joined by a CBUSH K = 1..6 (CID 0 axes) give
    # six rigid modes and omega^2 = k_i (1/m_a + 1/m_b); to the eigen solver's rounding
    ks = [10.0, 20.0, 30.0, 40.0, 50.0, 60.0]
    text = "GRID,1,,0.,0.,0.\nCONM2,1,1,,2.,,,,,+\n+,1.,,2.,,,3.\n"
    text += "".join(f"CELAS2,{10 + c},{k},1,{c}\n" for c, k in enumerate(ks, start=1))
    md = solve_modes(discretize(load_bdf(_deck(tmp_path, text), units="m, N, s")))
    want = np.sqrt(np.array(ks) / np.array([2.0, 2.0, 2.0, 1.0, 2.0, 3.0]))
    np.testing.assert_allclose(np.sort(md.omega), np.sort(want), rtol=1e-12)
    text = (
        "GRID,2,,0.,0.,0.\nGRID,3,,0.,0.,0.\n"
        "CONM2,2,2,,1.,,,,,+\n+,1.,,1.,,,1.\nCONM2,3,3,,3.,,,,,+\n+,2.,,2.,,,2.\n"
        "PBUSH,5,K,1.,2.,3.,4.,5.,6.\nCBUSH,1,5,2,3,,,,0\n"
    )
    md = solve_modes(discretize(load_bdf(_deck(tmp_path, text, "bush.bdf"), units="m, N, s")))
    assert md.n_rigid == 6
    inv = np.array([1 / 1 + 1 / 3] * 3 + [1 / 1 + 1 / 2] * 3)
    want = np.sqrt(np.arange(1.0, 7.0) * inv)
    np.testing.assert_allclose(np.sort(md.omega[6:]), np.sort(want), rtol=1e-12)


def test_a_deck_cut_short_is_refused_not_read_as_a_smaller_model(tmp_path):
    # the same deck, whole and cut after its first element: the cut one must not read as a
    # one-element model (NASTRAN's bulk data runs from BEGIN BULK to ENDDATA)
    head = "SOL 103\nCEND\nBEGIN BULK\n"
    body = BASE + "GRID,3,,2.,0.,0.\nCBAR,2,10,2,3,0.,1.,0.\n"
    whole = load_bdf(_deck(tmp_path, head + body + "ENDDATA\n"), units="m, N, s")
    assert len(whole.beams) == 2
    cut = head + body[: body.index("GRID,3")]
    with pytest.raises(InputError, match="no ENDDATA.*cut short") as exc:
        load_bdf(_deck(tmp_path, cut, "cut.bdf"), units="m, N, s")
    assert "end it with an ENDDATA line" in str(exc.value)
    # bulk data alone (an INCLUDEd part, a .blk) needs no ENDDATA
    assert len(load_bdf(_deck(tmp_path, body, "part.blk"), units="m, N, s").beams) == 2
