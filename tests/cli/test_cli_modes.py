"""CLI contract of ``microg modes``: JSON keys, table, bad input (exit 2, one line)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from microg.cli import main
from microg.dynamics.modes import solve_modes
from microg.models.toml import load_station
from microg.structure.ritz import build_ritz


def _run(capsys, *args):
    rc = main(["modes", *args])
    out, err = capsys.readouterr()
    return rc, out, err


def test_json_contract_ritz(capsys):
    # the report's model: planar X-Z assumed modes with the gravity-gradient restraint
    rc, out, err = _run(
        capsys, "ioc", "--method", "ritz", "--plane", "xz", "--gravity-gradient", "--json"
    )
    assert rc == 0 and err == ""
    data = json.loads(out)
    assert {"method", "model", "plane", "modes"} <= set(data)
    assert data["method"] == "ritz" and data["plane"] == "xz" and data["model"] == "ioc"
    keys = {"omega", "freq_hz", "rigid", "modal_mass", "effective_mass"}
    assert all(keys <= set(m) for m in data["modes"])
    omega = np.array([m["omega"] for m in data["modes"]])
    assert np.all(np.diff(omega) >= 0)
    # reference: the library called directly (the command must not compute anything else)
    ref = solve_modes(build_ritz(load_station("ioc"), "xz", 1, gravity_gradient=True))
    np.testing.assert_allclose(omega, ref.omega, rtol=1e-12, atol=0)
    np.testing.assert_allclose([m["freq_hz"] for m in data["modes"]], omega / (2 * np.pi))
    assert data["modes"][0]["rigid"] is True and data["modes"][0]["omega"] == 0.0


def test_functions_plane_and_n_modes(capsys):
    rc, out, _ = _run(
        capsys, "ioc-no-orbiter", "--method", "ritz", "--plane", "yz", "--functions", "3", "--json"
    )
    assert rc == 0
    data = json.loads(out)
    assert data["plane"] == "yz" and len(data["modes"]) == 2 + 3 * 3
    rc, out, _ = _run(capsys, "ioc", "--method", "ritz", "--n-modes", "3", "--json")
    assert rc == 0 and len(json.loads(out)["modes"]) == 3
    # a free-free frame model always reports its six rigid-body modes
    rc, out, _ = _run(capsys, "ioc", "--n-modes", "3", "--json")
    assert rc == 0 and len(json.loads(out)["modes"]) == 6


def test_default_is_the_library_default(capsys):
    # `microg modes MODEL` = microg.solve_modes(MODEL): 3-D frame elements, free-free
    import microg

    rc, out, _ = _run(capsys, "ioc", "--json")
    assert rc == 0
    data = json.loads(out)
    ref = microg.solve_modes("ioc", n_modes=len(data["modes"]))
    assert data["method"] == "fem" and data["plane"] is None
    np.testing.assert_allclose([m["omega"] for m in data["modes"]], ref.omega, rtol=1e-12)
    assert sum(m["rigid"] for m in data["modes"]) == 6


def test_fem_plane_filter(capsys):
    rc, out, _ = _run(capsys, "ioc", "--method", "fem", "--elements", "2", "--json")
    assert rc == 0
    everything = json.loads(out)["modes"]
    from microg.dynamics.modes import DEFAULT_N_MODES

    assert len(everything) == DEFAULT_N_MODES and sum(m["rigid"] for m in everything) == 6
    rc, out, _ = _run(
        capsys,
        "ioc",
        "--method",
        "fem",
        "--elements",
        "2",
        "--plane",
        "xz",
        "--n-modes",
        "8",
        "--json",
    )
    assert rc == 0
    data = json.loads(out)
    assert data["method"] == "fem" and data["plane"] == "xz" and len(data["modes"]) == 8
    # the X-Z fundamental (1.0086 rad/s, see tests/validation/test_ritz_vs_fem.py) is kept,
    # the Y-Z bending mode at 0.885 rad/s (all its energy out of the plane) is not
    w = np.array([m["omega"] for m in data["modes"]])
    assert np.min(np.abs(w - 1.0086)) < 1e-3
    assert np.min(np.abs(w - 0.8854)) > 1e-2


def test_table(capsys):
    rc, out, _ = _run(capsys, "ioc", "--method", "ritz", "--plane", "xz")
    assert rc == 0
    assert "omega (rad/s)" in out and "f (Hz)" in out and "eff x %" in out
    assert len(out.strip().splitlines()) == 2 + 5 + 1  # header lines, modes, modal mass
    assert out.strip().splitlines()[-1].startswith("  modal mass: shape scaled to")


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["no-such-model"], "no such file"),
        (["ioc", "--n-modes", "0"], "--n-modes"),
        (["ioc", "--method", "nope"], "--method"),
        (["ioc", "--plane", "xy"], "--plane"),
        (["ioc", "--functions", "0"], "--functions"),
        (["ioc", "--method", "ritz", "--elements", "4"], "--elements"),
        (["ioc", "--method", "fem", "--functions", "2"], "--functions"),
    ],
)
def test_bad_input_is_one_line_exit_2(capsys, args, needle):
    rc, out, err = _run(capsys, *args)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and needle in err


def test_bad_model_file_is_one_line(capsys, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[station]\nname = 3\n", encoding="utf-8")
    rc, out, err = _run(capsys, str(bad))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1 and "bad.toml" in err


def test_massless_beam_is_condensed_not_refused(tmp_path, capsys) -> None:
    # a beam with no mass, clamped to a massive body, is restrained, so its
    # coordinates are condensed statically; the free-free model still has its 6 rigid modes
    model = tmp_path / "massless.toml"
    model.write_text(
        '[station]\nname = "m"\n[orbit]\naltitude = "400 km"\n[[body]]\nname = "core"\n'
        '  [[body.mass]]\n  name = "m"\n  at = ["0 m", "0 m", "0 m"]\n  mass = "1000 kg"\n'
        '  inertia = { xx = "100 kg*m^2", yy = "100 kg*m^2", zz = "100 kg*m^2" }\n'
        '[[beam]]\nname = "arm"\nparent = "core"\nroot = ["0 m", "0 m", "0 m"]\n'
        'direction = [0, 0, 1]\nlength = "10 m"\nei = "1e6 N*m^2"\ngj = "1e6 N*m^2"\n'
        'mass_per_length = "0 kg/m"\n'
    )
    for method in ("ritz", "fem"):
        rc = main(["modes", str(model), "--method", method, "--json"])
        out, err = capsys.readouterr()
        assert rc == 0, err
        modes = json.loads(out)["modes"]
        assert sum(m["rigid"] for m in modes) == 6


NASTRAN = Path(__file__).resolve().parents[1] / "data" / "nastran"


def test_op2_modes_contract_with_replaced_rigid(capsys):
    # a free-free SOL 103 (pyyeti's cla_residual.op2): the file's six near-zero modes come out
    # as exact rigid-body modes, and the JSON says what was replaced and how far from zero
    rc, out, err = _run(capsys, str(NASTRAN / "cla_residual.op2"), "--units", "in,lbf,s", "--json")
    assert rc == 0, err
    d = json.loads(out)
    rigid = [m for m in d["modes"] if m["rigid"]]
    assert len(rigid) == 6 and all(m["omega"] == 0.0 for m in rigid)
    assert d["replaced_rigid"]["count"] == 6
    assert 0 < d["replaced_rigid"]["max_file_freq_hz"] < 1e-3
    assert d["method"] == "modal"


def test_op2_needs_units(capsys):
    rc, out, err = _run(capsys, str(NASTRAN / "cla_residual.op2"))
    assert rc == 2 and out == "" and err.count("\n") == 1 and "units" in err


def test_uff_export_round_trip_through_the_cli(capsys, tmp_path):
    # modes exported as UFF 15+55 and read back (a modal model) give the same frequencies
    # (6 printed digits in the standard single-precision datasets: 1e-5)
    unv = tmp_path / "ioc.unv"
    rc, out, _ = _run(capsys, "ioc", "--n-modes", "12", "--uff", str(unv), "--json")
    assert rc == 0 and unv.is_file()
    fe = np.array([m["omega"] for m in json.loads(out)["modes"]])
    rc, out, err = _run(capsys, str(unv), "--json")
    assert rc == 0, err
    back = np.array([m["omega"] for m in json.loads(out)["modes"]])
    np.testing.assert_allclose(back, fe, rtol=1e-5, atol=0)


def test_uff_export_of_an_imported_modal_model(capsys, tmp_path):
    # a NASTRAN OP2 (clamped beam: no rigid mode) written as UFF and read back: the same
    # frequencies to the 6 printed digits (1e-5), and replaced_rigid says none was replaced
    unv = tmp_path / "beam.unv"
    op2 = str(NASTRAN / "beam_modes" / "beam_modes_m2.op2")
    rc, out, err = _run(capsys, op2, "--units", "in,lbf,s", "--uff", str(unv), "--json")
    assert rc == 0 and unv.is_file(), err
    first = json.loads(out)
    assert first["replaced_rigid"]["count"] == 0
    rc, out, err = _run(capsys, str(unv), "--json")
    assert rc == 0, err
    a = np.array([m["freq_hz"] for m in first["modes"]])
    b = np.array([m["freq_hz"] for m in json.loads(out)["modes"]])
    np.testing.assert_allclose(b, a, rtol=1e-5, atol=0)
    assert a[0] == pytest.approx(456.66, rel=1e-4)  # the F06's first frequency


DECK = NASTRAN / "beam_modes"


def test_a_decks_spc_is_said_and_applied_on_request(capsys):
    # the beam_modes NASTRAN fixture is clamped by SPC = 1: free-free by default, with a warning
    # that the SPC is not applied; --constrained applies it and gives NASTRAN's first
    # frequency (F06: 456.6603 Hz; tests/models/test_bdf.py holds every mode to 0.5 %)
    deck = str(DECK / "beam_modes.dat")
    rc, out, err = _run(capsys, deck, "--units", "in,lbf,s", "--json")
    assert rc == 0, err
    free = json.loads(out)
    assert any("SPC" in w and "not applied" in w for w in free["warnings"])
    assert sum(m["rigid"] for m in free["modes"]) == 6
    rc, out, err = _run(capsys, deck, "--units", "in,lbf,s", "--constrained", "--json")
    assert rc == 0, err
    clamped = json.loads(out)
    assert not any("not applied" in w for w in clamped.get("warnings", []))
    assert clamped["modes"][0]["freq_hz"] == pytest.approx(456.6603, rel=5e-3)
    rc, _, err = _run(capsys, "ioc", "--constrained")
    assert rc == 2 and "--constrained" in err and "\n" not in err.strip()


def test_uff_export_of_a_deck_keeps_its_grids(capsys, tmp_path):
    # a NASTRAN deck (frame elements, no named points): its grids are the UFF's nodes, by
    # their own ids, and the file read back gives the same frequencies (6 printed digits:
    # 1e-5) and, at a grid, the deck's own shape (the structure's point map of that grid)
    from microg.dynamics.modes import solve_modes
    from microg.models.load import load_model
    from microg.models.uff import modal_model_from_uff
    from microg.structure.discretize import discretize

    deck = NASTRAN / "rdop2gpwg_1.dat"
    unv = tmp_path / "deck.unv"
    rc, out, err = _run(capsys, str(deck), "--units", "in,lbf,s", "--n-modes", "12", "--uff",
                        str(unv), "--json")  # fmt: skip
    assert rc == 0 and unv.is_file(), err
    fe = np.array([m["freq_hz"] for m in json.loads(out)["modes"]])
    back = modal_model_from_uff(unv)
    grids = [int(i) for i in back.grid_ids]
    st = discretize(load_model(deck, units="in,lbf,s"))
    assert grids == sorted(int(lab.split(":")[1]) for lab in st.samples.labels)
    rc, out, err = _run(capsys, str(unv), "--json")
    assert rc == 0, err
    np.testing.assert_allclose([m["freq_hz"] for m in json.loads(out)["modes"]], fe, rtol=1e-5)
    md = solve_modes(st, 12)
    j = 8  # an elastic mode; the sign of a shape is arbitrary
    name = f"grid:{grids[3]}"
    mine = st.points[name].translation @ md.phi[:, j]
    theirs = back.phi[3, :3, j]
    s = np.sign(mine @ theirs)
    np.testing.assert_allclose(s * theirs, mine, rtol=0, atol=1e-5 * np.abs(mine).max())
