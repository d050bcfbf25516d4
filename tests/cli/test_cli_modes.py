"""CLI contract of ``microg modes``: JSON keys, table, bad input (exit 2, one line)."""

from __future__ import annotations

import json

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
    assert len(everything) == 20 and sum(m["rigid"] for m in everything) == 6
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
    assert len(out.strip().splitlines()) == 2 + 5


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


def test_massless_beam_named(tmp_path, capsys) -> None:
    # a beam with no mass makes M singular: the error names the coordinates that carry none
    model = tmp_path / "massless.toml"
    model.write_text(
        '[station]\nname = "m"\n[orbit]\naltitude = "400 km"\n[[body]]\nname = "core"\n'
        '  [[body.mass]]\n  name = "m"\n  at = ["0 m", "0 m", "0 m"]\n  mass = "1000 kg"\n'
        '[[beam]]\nname = "arm"\nparent = "core"\nroot = ["0 m", "0 m", "0 m"]\n'
        'direction = [0, 0, 1]\nlength = "10 m"\nei = "1e6 N*m^2"\ngj = "1e6 N*m^2"\n'
        'mass_per_length = "0 kg/m"\n'
    )
    from microg.cli import main as _main

    for method in ("ritz", "fem"):
        rc = _main(["modes", str(model), "--method", method])
        err = capsys.readouterr().err
        assert rc == 2 and "arm" in err and "no mass" in err and err.count("\n") == 1
