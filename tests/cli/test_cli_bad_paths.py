"""Paths and plain numbers the operating system or the model cannot take: one line, exit 2."""

from __future__ import annotations

from pathlib import Path

import pytest

from microg.cli import main

OP2 = Path(__file__).resolve().parents[1] / "data" / "nastran" / "beam_modes" / "beam_modes_m2.op2"


def _run(capsys, args: list[str]) -> tuple[int, str]:
    rc = main(args)
    return rc, capsys.readouterr().err


@pytest.mark.parametrize(
    "args",
    [
        ["analyze", "ioc", "--out", "a\x00b"],
        ["quasi-steady", "ioc", "--out", "a\x00b"],
        ["assess", "a\x00b"],
        ["reproduce", "--out", "a\x00b"],
        ["sweep", "study.toml", "--out", "a\x00b"],
        ["locate", "ioc", "--out", "a\x00b"],
        ["modes", "ioc", "--uff", "a\x00b.unv"],
    ],
    ids=lambda a: a[0],
)
def test_a_nul_in_a_path_is_one_line(args, capsys, tmp_path, monkeypatch) -> None:
    # os.stat raises ValueError on a NUL, which click does not catch (it was exit 3)
    monkeypatch.chdir(tmp_path)
    rc, err = _run(capsys, args)
    assert rc == 2 and "NUL" in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("target", ["", "   ", "/proc/x.unv"])
def test_an_unwritable_uff_file_is_refused_before_the_solve(target, capsys) -> None:
    # '' used to be renamed onto '.', /proc/x.unv failed after the solve (exit 3 both)
    rc, err = _run(capsys, ["modes", "ioc", "--uff", target])
    assert rc == 2 and err.startswith("microg: error: --uff:") and err.count("\n") == 1, err


@pytest.mark.parametrize("value", ["nan", "inf", "0", "-1"])
def test_wtmass_must_be_a_positive_finite_number(value, capsys) -> None:
    # 0 was taken as "not given", nan was accepted
    rc, err = _run(capsys, ["modes", str(OP2), "--units", "in,lbf,s", "--wtmass", value])
    assert rc == 2 and err.startswith("microg: error: --wtmass:"), err


@pytest.mark.parametrize(
    "args",
    [
        ["modes", "ioc", "--elements", "\u0661\u0660"],  # Arabic-Indic 10: int() reads it
        ["modes", "ioc", "--elements", "1_0"],  # int() reads 10
        ["quasi-steady", "ioc", "--samples", "1_80"],
        ["isolate", "curve", "--k", "1_0", "--mu", "0.05", "--zeta", "0.1"],
        ["isolate", "curve", "--k", "1", "--mu", "0.05", "--zeta", "0.1", "--r2", "0:\u0662:10"],
        ["isolate", "tune", "--mu", "0.05", "--band", "0:1_0"],
    ],
    ids=lambda a: "-".join(a[:3]),
)
def test_plain_numbers_take_ascii_digits_only(args, capsys) -> None:
    # the unit grammar takes ASCII digits only; the plain-number options now agree with it
    rc, err = _run(capsys, args)
    assert rc == 2 and "ASCII digits" in err and err.count("\n") == 1, err


def test_an_overflowing_body_rate_is_refused(capsys) -> None:
    # 1e300 rad/s gave 155 nulls and "complies": null with exit 0
    rc, err = _run(capsys, ["quasi-steady", "ioc", "--attitude", "rate", "--rate", "0 0 1e300"])
    assert rc == 2 and err.startswith("microg: error: --rate:") and err.count("\n") == 1, err


def test_warnings_before_an_error_are_not_shown(capsys, monkeypatch) -> None:
    # a numpy RuntimeWarning raised on the way to a refusal: the error is the one line
    import warnings

    import microg.cli.modes as modes_cli
    from microg.errors import InputError

    def load(*a, **k):
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        raise InputError("bad model", where="MODEL")

    monkeypatch.setattr(modes_cli, "discretize", load, raising=False)
    monkeypatch.setattr("microg.structure.discretize.discretize", load)
    rc, err = _run(capsys, ["modes", "ioc"])
    assert rc == 2 and err == "microg: error: MODEL: bad model\n", err


def test_a_warning_after_success_is_one_line(capsys, monkeypatch) -> None:
    import warnings

    import microg.isolation

    real = microg.isolation.check_section42_claims

    def claims(*a, **k):
        for _ in range(2):  # the same warning twice is shown once
            warnings.warn("first line\nsecond line", UserWarning, stacklevel=1)
        return real(*a, **k)

    monkeypatch.setattr("microg.isolation.check_section42_claims", claims)
    rc, err = _run(capsys, ["isolate", "claims"])
    assert rc == 0 and err == "microg: warning: first line second line (UserWarning)\n", err


@pytest.mark.parametrize(
    "args",
    [
        ["analyze", "ioc", "--wtmass", "1"],
        ["modes", "ioc", "--units", "in,lbf,s"],
        ["modes", "ioc", "--units", "parsecs,N,s"],
    ],
    ids=lambda a: a[2],
)
def test_reader_options_for_a_station_are_refused(args, capsys, tmp_path) -> None:
    # a station declares its own units: --units/--wtmass were accepted and ignored (exit 0)
    rc, err = _run(capsys, [*args, "--out", str(tmp_path / "o")] if args[0] == "analyze" else args)
    assert rc == 2 and f"{args[2]}: applies to NASTRAN and UFF files only" in err, err
    assert not (tmp_path / "o").exists()
