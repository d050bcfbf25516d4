"""``microg reproduce``: the JSON contract, options, files written, and bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from microg.cli import main

CASES = {"xz_orbiter", "xz_no_orbiter", "yz_orbiter", "yz_no_orbiter"}


def _run(capsys, args: list[str]) -> tuple[int, str, str]:
    rc = main(args)
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def default_json(tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("rep") / "r"
    rc = main(["reproduce", "--out", str(out), "--json"])
    assert rc == 0
    return json.loads((out / "results.json").read_text())


def test_contract_keys(default_json: dict) -> None:
    d = default_json
    assert set(d["appendix_c"]) == CASES and set(d["table4"]) == CASES
    for case in CASES:
        ac = d["appendix_c"][case]
        for key in ("printed_mass_matrix", "model_mass_matrix"):
            assert len(ac[key]) == 4 and all(len(r) == 4 for r in ac[key])
        assert len(ac["omega2"]) == 2 and len(ac["printed_omega2"]) == 2
        t4 = d["table4"][case]
        assert len(t4["bending"]) == 2
        for row in t4["bending"]:
            assert {"omega", "accel_g", "printed_omega", "printed_accel_g"} <= set(row)
        assert {"omega", "accel_g", "printed_omega", "printed_accel_g"} <= set(t4["libration"])


def test_files_written(tmp_path: Path, capsys) -> None:
    out = tmp_path / "rep"
    rc, stdout, _ = _run(capsys, ["reproduce", "--out", str(out)])
    assert rc == 0
    assert sorted(p.name for p in out.iterdir()) == [
        ".microg-run",  # the marker of a directory microg wrote (and may replace whole)
        "figure3.png",
        "figure4.png",
        "lab-response.png",
        "report.html",
        "results.json",
    ]
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") == 3  # figures embedded: self-contained
    assert "Errata" in html
    assert (out / "figure3.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "report written" in stdout


def test_stdout_json_equals_file(tmp_path: Path, capsys) -> None:
    out = tmp_path / "rep"
    rc, stdout, _ = _run(capsys, ["reproduce", "--out", str(out), "--json"])
    assert rc == 0
    assert json.loads(stdout) == json.loads((out / "results.json").read_text())


@pytest.mark.parametrize(
    ("option", "value"),
    [("--f0", "40"), ("--t1", "0.5"), ("--t13", "10"), ("--t14", "15"), ("--z-e", "-30")],
)
def test_options_change_results(tmp_path: Path, capsys, default_json: dict, option, value) -> None:
    rc, stdout, _ = _run(
        capsys, ["reproduce", "--out", str(tmp_path / "o"), "--json", option, value]
    )
    assert rc == 0
    d = json.loads(stdout)
    a0 = default_json["table4"]["xz_orbiter"]["bending"][0]
    a1 = d["table4"]["xz_orbiter"]["bending"][0]
    assert a1["omega"] == a0["omega"]  # the structure does not change
    assert a1["accel_g"] != a0["accel_g"]  # every computed acceleration follows the force/point
    lib0 = default_json["table4"]["xz_orbiter"]["libration"]
    lib1 = d["table4"]["xz_orbiter"]["libration"]
    if option in ("--t13", "--t14"):
        # Eq. 3.2 uses the push-off impulse only; the exact rigid-rotation peak sees the landing
        assert lib1["accel_g"] == lib0["accel_g"]
    else:
        assert lib1["accel_g"] != lib0["accel_g"]


def test_f0_linear(tmp_path: Path, capsys, default_json: dict) -> None:
    # accelerations are linear in f0 (Eq. 3.1, 3.2): doubling f0 doubles them exactly
    rc, stdout, _ = _run(
        capsys, ["reproduce", "--out", str(tmp_path / "o"), "--json", "--f0", "50 lbf"]
    )
    d = json.loads(stdout)
    for case in CASES:
        for r0, r1 in zip(
            default_json["table4"][case]["bending"], d["table4"][case]["bending"], strict=True
        ):
            assert r1["accel_g"] == pytest.approx(2 * r0["accel_g"], rel=1e-12)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--t1", "-1"], "--t1"),
        (["--t13", "0.5"], "--t13"),
        (["--t14", "12"], "--t14"),
        (["--t1", "abc"], "--t1"),
        (["--f0", "3 m"], "--f0"),
        (["--case", "xy_orbiter"], "--case"),
        (["--bogus"], "--bogus"),
    ],
)
def test_bad_input_one_line_exit_2_nothing_written(tmp_path: Path, capsys, args, needle) -> None:
    out = tmp_path / "never"
    rc, stdout, err = _run(capsys, ["reproduce", "--out", str(out), *args])
    assert rc == 2
    assert needle in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []  # no temporary directory left behind either


def test_case_filter(tmp_path: Path, capsys) -> None:
    rc, stdout, _ = _run(
        capsys, ["reproduce", "--out", str(tmp_path / "o"), "--json", "--case", "yz_orbiter"]
    )
    assert rc == 0
    assert set(json.loads(stdout)["table4"]) == {"yz_orbiter"}


def test_a_directory_microg_did_not_write_is_refused(tmp_path: Path, capsys) -> None:
    # --out into a directory that holds other files: a run replaces its directory as a whole,
    # so a directory without microg's marker is refused, untouched, before any computation
    out = tmp_path / "mine"
    out.mkdir()
    (out / "keep.txt").write_text("precious")
    (out / "figure3.png").write_bytes(b"old")
    rc, stdout, err = _run(capsys, ["reproduce", "--out", str(out)])
    assert rc == 2 and stdout == "" and "--out" in err and err.count("\n") == 1
    assert (out / "keep.txt").read_text() == "precious"
    assert (out / "figure3.png").read_bytes() == b"old"
    # a directory microg wrote is replaced whole, with nothing stale left beside it
    mine = tmp_path / "run"
    assert _run(capsys, ["reproduce", "--out", str(mine)])[0] == 0
    (mine / "stale.png").write_bytes(b"old")
    assert _run(capsys, ["reproduce", "--out", str(mine)])[0] == 0
    assert not (mine / "stale.png").exists()
    assert [p.name for p in mine.parent.iterdir() if p.name.startswith(".")] == []


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--out", "/proc/microg-no-such-dir/x"], "--out"),
        (["--f0", "-5"], "--f0"),
        (["--z-e", "nan ft"], "--z-e"),
        (["--z-e", "1e400 ft"], "--z-e"),
    ],
)
def test_more_bad_input(tmp_path: Path, capsys, args, needle) -> None:
    out_args = [] if "--out" in args else ["--out", str(tmp_path / "never")]
    rc, _, err = _run(capsys, ["reproduce", *out_args, *args])
    assert rc == 2 and needle in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "never").exists()
