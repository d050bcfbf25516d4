"""``microg isolate``: the JSON contract other tools parse, and one-line errors with exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from microg.cli import main
from microg.isolation import accel_magnification, den_hartog


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(["isolate", *args])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_curve_json_contract(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(
        capsys, "curve", "--k", "10", "--mu", "0.05", "--zeta", "0.2", "--r2", "0.5:3:6", "--json"
    )
    assert code == 0
    data = json.loads(out)
    assert set(data) == {"r2", "Ma"}
    np.testing.assert_allclose(data["r2"], np.linspace(0.5, 3, 6), rtol=1e-15)
    np.testing.assert_allclose(
        data["Ma"], accel_magnification(10, 0.05, 0.2, np.sqrt(data["r2"])), rtol=1e-15
    )
    code, out, _ = run(capsys, "curve", "--k", "10", "--mu", "0.05", "--zeta", "0.2")
    assert code == 0 and "M_a" in out


def test_tune_json_contract(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "tune", "--mu", "0.05", "--json")
    assert code == 0
    data = json.loads(out)
    assert set(data) == {"k", "zeta", "f", "peak_Ma", "criterion"}
    assert data["criterion"] == "peak"
    assert data["f"] == pytest.approx(1 / np.sqrt(data["k"] * 0.05), rel=1e-12)
    # Den Hartog's peak is an upper bound of the minimax optimum (see test_isolation_absorber)
    assert data["peak_Ma"] <= den_hartog(0.05).peak_Ma
    code, out, _ = run(capsys, "tune", "--mu", "0.05", "--band", "1.6:3", "--criterion", "peak")
    assert code == 0 and "numerical" in out


def test_design_and_claims(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "design", "--weight", "1000 lbf", "--omega", "1.02", "--json")
    assert code == 0
    d = json.loads(out)
    # k1 = m1 w^2 target/(1 + target), m1 = 1000 lbf / g0
    m1 = 1000 * 4.4482216152605 / 9.80665
    assert d["k1_N_per_m"] == pytest.approx(m1 * 1.02**2 * 0.5 / 1.5, rel=1e-12)
    code, out, _ = run(capsys, "design", "--mass", "453.6 kg", "--freq", "0.16 Hz")
    assert code == 0 and "lbf/in" in out
    code, out, _ = run(capsys, "claims")
    assert code == 0 and "(c) DOES NOT HOLD" in out


def test_figure8_writes_png(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "sub" / "fig8.png"
    code, _, _ = run(capsys, "figure8", "--out", str(out))
    assert code == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in out.parent.iterdir()] == ["fig8.png"]  # no temporaries left


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["curve", "--k", "0", "--mu", "0.1", "--zeta", "0.1"], "--k"),
        (["curve", "--k", "1", "--mu", "0", "--zeta", "0.1"], "--mu"),
        (["curve", "--k", "1", "--mu", "-0.1", "--zeta", "0.1"], "--mu"),
        (["curve", "--k", "1", "--mu", "0.1", "--zeta", "-0.1"], "--zeta"),
        (["curve", "--k", "1", "--mu", "0.1", "--zeta", "0.1", "--r2", "1:2"], "--r2"),
        (["curve", "--k", "1", "--mu", "0.1", "--zeta", "0.1", "--r2", "2:1:5"], "--r2"),
        (["curve", "--k", "1", "--mu", "0.1", "--zeta", "0.1", "--r2", "-1:1:5"], "--r2"),
        (["tune", "--mu", "0"], "--mu"),
        (["tune", "--mu", "0.1", "--band", "1:x"], "--band"),
        (["tune", "--mu", "0.1", "--criterion", "rms"], "--criterion"),
        (["design", "--weight", "1000 furlong", "--omega", "1"], "--weight"),
        (["design", "--weight", "1000", "--omega", "1 kg"], "--omega"),
        (["design", "--weight", "1000", "--omega", "1", "--target", "2"], "--target"),
        (["design", "--weight", "1000", "--omega-band", "0:1"], "--omega-band"),
        (["design", "--weight", "1000", "--omega", "1", "--mu", "0.1"], "--mu"),
        (["design", "--weight", "1000"], "--omega"),
    ],
)
def test_bad_input_one_line_exit_2(
    capsys: pytest.CaptureFixture[str], args: list[str], option: str
) -> None:
    code, out, err = run(capsys, *args)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and option in lines[0] and "Traceback" not in err


def test_hz_and_rad_per_s_agree(capsys) -> None:
    # 1 Hz is 2 pi rad/s: the two spellings must give the same design (pint alone would not)
    import json as _json

    from microg.cli import main as _main

    assert _main(["isolate", "design", "--weight", "1000 lbf", "--omega", "1 Hz", "--json"]) == 0
    a = _json.loads(capsys.readouterr().out)
    assert (
        _main(
            ["isolate", "design", "--weight", "1000 lbf", "--omega", "6.283185307179586", "--json"]
        )
        == 0
    )
    b = _json.loads(capsys.readouterr().out)
    assert a["k1_N_per_m"] == b["k1_N_per_m"]


def test_range_too_large(capsys) -> None:
    from microg.cli import main as _main

    rc = _main(
        ["isolate", "curve", "--k", "10", "--mu", "0.05", "--zeta", "0.2", "--r2", "0:6:2000000000"]
    )
    err = capsys.readouterr().err
    assert rc == 2 and "--r2" in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (["design", "--mass", "100 kg", "--freq", "1e-300 Hz", "--mu", "0.05"], "--freq"),
        (["design", "--mass", "100 kg", "--freq", "1e-320 Hz"], "--freq"),
        (["design", "--mass", "100 kg", "--omega", "1e-300 rad/s", "--mu", "0.05"], "--omega"),
        (["design", "--mass", "100 kg", "--freq-band", "1e-320:1", "--mu", "0.05"], "band"),
        (["design", "--mass", "100 kg", "--freq-band", "0.1:1e300", "--mu", "0.05"], "band"),
        (["design", "--mass", "100 kg", "--freq-band", "0.1:1", "--mu", "1e-320"], "--mu"),
        (["design", "--mass", "100 kg", "--freq-band", "0.1:1", "--mu", "1e300"], "--mu"),
        (["tune", "--mu", "1e-320"], "--mu"),
        (["tune", "--mu", "1e300"], "--mu"),
        (["tune", "--mu", "0.05", "--band", "1e-320:1"], "--band"),
        (["claims", "--mu-max", "1e-320"], "--mu-max"),
        (["claims", "--mu-max", "1e300"], "--mu-max"),
    ],
)
def test_extreme_values_are_refused_in_one_line(args, flag, capsys) -> None:
    # each was an internal error (overflow in 1/(f^2 mu), a bisection on 1e-300): now outside
    # the documented ranges (microg.units.SMALLEST, absorber.MU_RANGE), one line, exit 2
    from microg.cli import main

    rc = main(["isolate", *args])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and flag in err.split(":")[2], err
