"""Real NASTRAN decks solved by microg's frame FE, against NASTRAN's own output.

Fixtures (tests/data/nastran/, from pyyeti's wheel, LICENSE-pyyeti.txt, README.md):

* ``extseout_full.dat``: 117 CBAR + RBE2, free-free (no SPC), COUPMASS 1.  Truth: its F06
  (``full.out`` in pyyeti's wheel, NX Nastran 9.1, "R E A L   E I G E N V A L U E S", CYCLES
  of modes 7-60, recorded below), solved with that release's coupled CBAR mass
  (``coupled_mass="coupled-nx9"``, ``test_nastran_bar_mass.py``): measured 2.4e-7 over
  modes 7-20 (the F06's 7 digits) and 2.6e-6 to mode 60.  (microg's own consistent mass,
  with torsional inertia, was 8.5e-5 and 2.5e-4 off; Simcenter 2020.2's form 2%.)
* ``extseout_cant_beam.dat``: 8,221 CBARs written with ``=``/``=N`` replication, a free-free
  bar 82,210 long of radius of gyration 1 (L/r 8.2e4).  Truth: Euler-Bernoulli free-free
  beam, f_n = (beta_n L)^2 / (2 pi L^2) sqrt(E I / (rho A)), beta_1 L = 4.73004074.
* ``rdop2gpwg_1.dat`` with its MAT4 (thermal): truth its own run's OP2 (``rdop2gpwg_1.op2``,
  LAMA), read by microg's reader (itself checked against pyNastran).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.bdf import load_bdf, read_cards
from microg.models.nastran import read_op2_modes
from microg.structure.discretize import discretize

pytestmark = pytest.mark.nastran

DATA = Path(__file__).parent.parent / "data" / "nastran"

F06_FULL = [
    1.698800, 1.767487, 1.857720, 3.419612, 7.024210, 7.025409, 10.72361, 10.98255,
    13.86678, 14.38990, 14.65085, 15.19276, 25.20153, 25.31348, 29.12879, 42.43667,
    43.08599, 46.89437, 47.80359, 53.67440, 53.70487, 68.29281, 68.37682, 88.81801,
    89.35085, 92.82552, 93.38004, 93.88227, 94.15884, 95.53525, 97.83368, 98.27869,
    100.8308, 100.9174, 101.1715, 101.1837, 102.5093, 103.8108, 103.9068, 104.4783,
    108.7838, 110.9373, 117.4238, 118.2975, 119.5876, 121.9283, 122.4124, 123.9191,
    125.6743, 128.1617, 129.1987, 135.6376, 139.4382, 140.1176,
]  # fmt: skip


def _bending_pair_within_rounding(s, md, first: int) -> None:
    """The first bending pair against Euler-Bernoulli, each to its own rounding bound.

    Rounding each entry of the assembled K by eps moves lambda by up to eps |phi|^T |K| |phi|
    (first-order perturbation, phi M-normalised), half of that relative on a frequency; the
    bound is computed here from the shapes, independently of the solver's note, which must
    say it.  Discretisation (8,221 elements) adds ~3e-7.  A wrong mass or stiffness term is
    off by 20% or more, far beyond the bound (~5%: the stiffness spans 4e15 ~ 1/eps).
    """
    ref = 4.730040744862704**2 / (2 * np.pi * 82210.0**2) * np.sqrt(6.894e7 / 2.74e-6)
    pair = np.arange(first, first + 2)
    phi = np.abs(md.phi[:, pair])
    energy = np.einsum("ij,ij->j", phi, np.asarray(abs(s.stiffness) @ phi))
    bound = 0.5 * np.finfo(float).eps * energy / md.omega[pair] ** 2
    assert np.all(bound < 0.1)  # the bound itself is meaningful (the deck solves)
    err = np.abs(md.freq_hz[pair] / ref - 1.0)
    assert np.all(err <= bound + 1e-6), (err, bound)
    assert any("rounding bounds" in n for n in md.notes)  # and the output says so


@pytest.mark.parametrize("constrained", [False, True])
def test_full_deck_solves_free_and_constrained_and_matches_nastran(constrained):
    # the deck has no SPC: --constrained is the same free-free structure; before the
    # round-off floor of the rigid-body test, the rz rotation failed on a row where both
    # K r and |K| |r| were round-off (8e-16) and the deck was refused as a mechanism
    g = load_bdf(DATA / "extseout_full.dat", units="in, lbf, s", coupled_mass="coupled-nx9")
    md = solve_modes(discretize(g, constrained=constrained), 60)
    assert md.n_rigid == 6 and np.all(md.omega[:6] == 0.0)
    f = md.freq_hz[6:60]
    rel = np.abs(f - F06_FULL) / np.asarray(F06_FULL)
    assert rel[:14].max() < 1e-6  # modes 7-20: measured 2.4e-7, the F06's 7 printed digits
    assert rel.max() < 1e-5  # modes 7-60: measured 2.6e-6 (NX's Lanczos tolerance up there)


def test_replicated_cards_expand_and_the_slender_bar_solves():
    cards, _ = read_cards(DATA / "extseout_cant_beam.dat")
    grids = [c for c in cards if c.name == "GRID"]
    bars = [c for c in cards if c.name == "CBAR"]
    # GRID,1,,0.,0.,0. / =,*1,,*10.,== / =8220: grids 1..8222 every 10 along x
    assert len(grids) == 8222 and grids[-1].fields == ("GRID", 8222, None, 82210.0, 0.0, 0.0)
    # CBAR,1,100,1,2,150.,150.,300. / =,*1,=,*1,*1,== / =8219
    assert len(bars) == 8221 and bars[-1].fields[:5] == ("CBAR", 8221, 100, 8221, 8222)
    assert bars[-1].fields[5:] == (150.0, 150.0, 300.0)
    # NASTRAN's coupled CBAR mass has no torsional inertia: a straight line of CBARs would have
    # a massless rotation about its axis, so the bending check takes microg's consistent mass
    g = load_bdf(DATA / "extseout_cant_beam.dat", units="mm, N, s", coupled_mass="consistent")
    md = solve_modes(discretize(g), 10)
    assert md.n_rigid == 6
    # Euler-Bernoulli: PBAR A = I = 12.566 (r = 1), MAT1 E 6.894e7, rho 2.74e-6, L 82210,
    # each of the pair to its rounding bound (measured -2.1% and -1.1% against bounds of ~5%;
    # the two planes, equal in exact arithmetic, split by 1%)
    _bending_pair_within_rounding(md.structure, md, 6)


def test_cant_beam_with_its_own_mass_holds_the_massless_rotation_about_its_axis():
    # read as written (PARAM,COUPMASS,1: NASTRAN's coupled CBAR mass, which has no torsional
    # inertia), the straight bar's rotation about its own axis has neither mass nor stiffness
    # (every grid lies on the axis): it is no mode.  One DOF of it is held (as NASTRAN's
    # AUTOSPC), which changes no finite mode, and the rest solves sparsely: 5 rigid-body
    # modes, and the bending pair of the consistent-mass reading above, each to its rounding
    # bound (measured: the same -2.1% and -1.1% from Euler-Bernoulli, the two readings equal
    # to 1e-7).  NASTRAN's own run (EIGRL ND=4) kept 4 rigid
    # modes in pyyeti's OP2, so beam theory is the truth.
    g = load_bdf(DATA / "extseout_cant_beam.dat", units="mm, N, s")
    s = discretize(g)
    said = [w for w in s.meta["warnings"] if "rigid-body motion(s) move only" in w]
    assert len(said) == 1 and "held at grid:1:rx" in said[0]
    md = solve_modes(s, 10)
    assert md.n_rigid == 5 and np.all(md.omega[:5] == 0.0)
    _bending_pair_within_rounding(s, md, 5)
    for d in ("x", "y", "z"):
        assert md.effective_mass[d].sum() == pytest.approx(s.total_mass, rel=1e-10)


def test_cant_beam_as_lumped_cbeams_solves_sparsely_with_massless_rotations(tmp_path):
    # the same 8,221 elements as CBEAMs with NASTRAN's default lumped mass (no COUPMASS): half
    # of each element's mass on each end's translations, half its polar moment on the axial
    # rotation, the 16,444 bending rotations massless.  Condensed they would leave 41,110
    # DOFs (dense: refused before); they are kept as coordinates, M singular, and solved
    # sparsely.  Truth: Euler-Bernoulli (as the consistent-mass test above), each of the pair
    # to its rounding bound; lumping errs by O((beta Le)^2) ~ 3e-7 at Le/L = 1/8221
    text = (DATA / "extseout_cant_beam.dat").read_text()
    text = (
        text.replace("PARAM,COUPMASS,1\n", "")
        .replace("CBAR,", "CBEAM,")
        .replace(
            "PBAR,100,300,12.566,12.566,12.566,25.133", "PBEAM,100,300,12.566,12.566,12.566,,25.133"
        )
    )
    deck = tmp_path / "cant_beam_cbeam.dat"
    deck.write_text(text)
    g = load_bdf(deck, units="mm, N, s")
    assert g.mass_formulation == "lumped" and len(g.beams) == 8221
    s = discretize(g)
    assert s.is_sparse and s.meta["condensed"] == 0 and s.meta["massless_kept"] == 16444
    md = solve_modes(s, 10)
    assert md.n_rigid == 6 and np.all(md.omega[:6] == 0.0)
    _bending_pair_within_rounding(s, md, 6)
    for d in ("x", "y", "z"):
        assert md.effective_mass[d].sum() == pytest.approx(s.total_mass, rel=1e-10)


def test_slender_bar_l_over_r_1e5_against_beam_theory(tmp_path):
    # a free-free bar of 200 CBARs along a skew line, L/r = 1e5: every rigid-body vector
    # passes the rigid test (no false mechanism), and the first bending pair is
    # Euler-Bernoulli's: discretisation error ~1e-9 at Le/L = 1/200; the rest is the round-off
    # of a stiffness spread 3e12 times omega_1^2 (bound eps * 3e12 / 2 ~ 3e-4 on a frequency;
    # measured 4.3e-6 and, with another scipy/OpenBLAS build, 1.7e-5 on the second of the pair:
    # 5e-5 is 3x the larger, and a wrong transform or mass term is off by more than 1e-3)
    L, A, E, rho, n = 100.0, 1e-4, 7e10, 2700.0, 200
    i_ = A * (L / 1e5) ** 2
    d = np.array([1.0, 2.0, 0.5]) / np.linalg.norm([1.0, 2.0, 0.5])
    v = np.cross(d, [0.0, 0.0, 1.0])
    lines = ["BEGIN BULK", "PARAM,COUPMASS,1", f"MAT1,1,{E:.6e},,0.3,{rho:.6e}",
             f"PBAR,1,1,{A:.6e},{i_:.6e},{i_:.6e},{2 * i_:.6e}"]  # fmt: skip
    for k in range(n + 1):
        p = np.array([3.0, -7.0, 11.0]) + d * L * k / n
        lines.append(f"GRID*,{k + 1},,{p[0]:.15e},{p[1]:.15e}\n*,{p[2]:.15e}")
    lines += [f"CBAR,{k + 1},1,{k + 1},{k + 2},{v[0]:.6f},{v[1]:.6f},{v[2]:.6f}" for k in range(n)]
    deck = tmp_path / "bar.dat"
    deck.write_text("\n".join([*lines, "ENDDATA"]) + "\n")
    md = solve_modes(discretize(load_bdf(deck, units="m, N, s", coupled_mass="consistent")), 8)
    ref = 4.730040744862704**2 / (2 * np.pi * L**2) * np.sqrt(E * i_ / (rho * A))
    assert md.n_rigid == 6
    np.testing.assert_allclose(md.freq_hz[6:8], ref, rtol=5e-5)


def test_thermal_material_is_skipped_and_listed_once():
    g = load_bdf(DATA / "rdop2gpwg_1.dat", units="in, lbf, s")
    listed = [w for w in g.meta["warnings"] if "MAT4 (1)" in w]
    assert len(listed) == 1 and listed[0].startswith("cards ignored")
    md = solve_modes(discretize(g), 12)
    ref = read_op2_modes(DATA / "rdop2gpwg_1.op2")
    # the same run's LAMA (float32: 6e-8) against microg's CBAR: measured 2e-5
    np.testing.assert_allclose(md.freq_hz[6:10], ref.freq_hz_signed[6:10], rtol=5e-5)


def test_missing_executive_include_is_skipped_bulk_include_is_not(tmp_path):
    bulk = DATA / "rdop2gpwg_1.dat"
    text = bulk.read_text()
    (tmp_path / "bulk.inc").write_text(text.split("BEGIN BULK", 1)[1].split("ENDDATA")[0])
    deck = tmp_path / "deck.dat"
    deck.write_text(
        "INCLUDE '/no/such/dir/alter.v9'\nSOL 103\nCEND\nINCLUDE 'case.inc'\n"
        "BEGIN BULK\nINCLUDE 'bulk.inc'\nENDDATA\n"
    )
    g = load_bdf(deck, units="in, lbf, s")
    notes = [w for w in g.meta["warnings"] if "before BEGIN BULK not found: skipped" in w]
    assert len(notes) == 2
    (tmp_path / "bulk.inc").unlink()
    with pytest.raises(InputError, match="INCLUDE 'bulk.inc': file not found"):
        load_bdf(deck, units="in, lbf, s")


def test_single_beam_deck_with_a_missing_dmap_alter_has_six_rigid_modes():
    # nas2cam_no_se.dat (pyyeti nas2cam/no_se.dat, NX 5/1/14): one CBEAM, lumped mass, free;
    # its executive control INCLUDEs a DMAP alter by an absolute path that is not here.
    # Truth, its F06 (no_se.out): six modes at 3.35e-9 Hz and none other below the EIGRL
    # limit of 100 Hz.  The bar's transverse rows, after its massless rotations are
    # condensed, hold only round-off: the rigid-body test must not read them as a restraint
    g = load_bdf(DATA / "nas2cam_no_se.dat", units="in, lbf, s")
    assert any("before BEGIN BULK not found: skipped" in w for w in g.meta["warnings"])
    md = solve_modes(discretize(g))
    assert md.n_rigid == 6 and np.all(md.omega[:6] == 0.0)
    assert md.freq_hz[6] > 100.0
