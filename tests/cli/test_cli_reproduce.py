"""``microg reproduce``: the JSON contract, options, files written, and bad input."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from microg.cli import main

CASES = {"xz_orbiter", "xz_no_orbiter", "yz_orbiter", "yz_no_orbiter"}


def _run(capsys, args: list[str]) -> tuple[int, str, str]:
    rc = main(args)
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def default_out(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("rep") / "r"
    rc = main(["reproduce", "--out", str(out), "--json"])
    assert rc == 0
    return out


@pytest.fixture(scope="module")
def default_json(default_out: Path) -> dict:
    return json.loads((default_out / "results.json").read_text())


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
    assert "written to" in stdout


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
    # a directory microg wrote is replaced whole, with nothing left beside it
    mine = tmp_path / "run"
    assert _run(capsys, ["reproduce", "--out", str(mine)])[0] == 0
    assert _run(capsys, ["reproduce", "--out", str(mine)])[0] == 0
    assert [p.name for p in mine.parent.iterdir() if p.name.startswith(".")] == []
    # ... but a file a user added there is never deleted: the run is refused, naming it
    (mine / "my-figure.png").write_bytes(b"mine")
    rc, stdout, err = _run(capsys, ["reproduce", "--out", str(mine)])
    assert rc == 2 and "my-figure.png" in err and err.count("\n") == 1
    assert (mine / "my-figure.png").read_bytes() == b"mine"


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--out", "/proc/microg-no-such-dir/x"], "--out"),
        (["--f0", "-5"], "--f0"),
        (["--z-e", "nan ft"], "--z-e"),
        (["--z-e", "1e400 ft"], "--z-e"),
        (["--z-e", "100 ft"], "--z-e"),  # on the keel: Eq. 3.1 does not hold there
        (["--z-a", "-200 ft"], "--z-a"),  # below the main body
        (["--z-a", "5000"], "--z-a"),  # bare number: ft
        (["--z-e", "3 kg"], "--z-e"),
    ],
)
def test_more_bad_input(tmp_path: Path, capsys, args, needle) -> None:
    out_args = [] if "--out" in args else ["--out", str(tmp_path / "never")]
    rc, _, err = _run(capsys, ["reproduce", *out_args, *args])
    assert rc == 2 and needle in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "never").exists()


TITLE = (
    "Analytical determination of space station response to crew motion and design of "
    "suspension system for microgravity experiments"
)


def test_json_names_the_seed_report(default_json: dict) -> None:
    sr = default_json["seed_report"]
    assert sr["title"] == TITLE
    assert sr["program"] == "NASA/ASEE"
    # not legible in the OCR'd copy: null, with the reason beside it
    assert sr["authors"] is None and sr["authors_note"]
    assert sr["year"] is None and "August 1984" in sr["year_note"]
    assert sr["file_name"] == "000_21c0b08f89afe689.txt"


def test_json_meta_is_the_provenance(tmp_path: Path, capsys) -> None:
    import hashlib

    import microg

    out = tmp_path / "rep"
    args = ["reproduce", "--out", str(out), "--json", "--f0", "25 lbf"]
    rc, stdout, _ = _run(capsys, args)
    assert rc == 0
    meta = json.loads(stdout)["meta"]
    assert meta["microg_version"] == microg.__version__
    assert meta["command"] == "microg reproduce --out " + str(out) + " --json --f0 '25 lbf'"
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", meta["created_utc"])
    data = Path(microg.__file__).parent / "data"
    sha = {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in data.glob("*.toml")}
    assert meta["printed_values_sha256"] == sha["_seed_printed.toml"]
    assert {m["name"]: m["sha256"] for m in meta["models"]} == {
        "ioc": sha["ioc.toml"],
        "ioc-no-orbiter": sha["ioc-no-orbiter.toml"],
    }
    assert meta["seed_report_file"] == "000_21c0b08f89afe689.txt"
    assert len(meta["seed_report_sha256"]) == 64
    page = (out / "report.html").read_text()
    text = _unescaped(page)
    for value in (meta["command"], meta["printed_values_sha256"], meta["seed_report_sha256"]):
        assert value in text
    assert "<h2>Provenance</h2>" in page and meta["created_utc"] in page


def _unescaped(page: str) -> str:
    import html

    return html.unescape(page)


def test_report_states_the_agreement(default_out: Path, default_json: dict) -> None:
    page = (default_out / "report.html").read_text()
    text = _unescaped(page)
    a = default_json["agreement"]
    # the page's headline and counts are the JSON's, which are the comparisons'
    assert a["headline"] in text
    comps = default_json["comparisons"]
    for g in a["groups"]:
        mine = [c for c in comps if c["group"] == g["key"]]
        assert g["compared"] == len(mine) and g["agree"] == sum(c["agrees"] for c in mine)
        shade = "ok" if g["compared"] and not g["differ"] else ""
        assert f'<td>{g["compared"]}</td><td class="{shade}">{g["agree"]}</td>' in page
        assert g["tolerance"] in text and g["justification"] in text
    assert a["reproduction"]["compared"] == sum(
        g["compared"] for g in a["groups"] if g["kind"] == "reproduction"
    )
    # every difference links its erratum, which has an anchor on the page
    for c in comps:
        if not c["agrees"]:
            assert f'href="#{c["erratum"]}"' in page and f'<tr id="{c["erratum"]}">' in page
    assert TITLE in text and "<h2>Symbols and units</h2>" in page


def test_console_summary_states_the_agreement(tmp_path: Path, capsys, default_json) -> None:
    rc, stdout, _ = _run(capsys, ["reproduce", "--out", str(tmp_path / "o")])
    assert rc == 0 and default_json["agreement"]["headline"] in stdout


def test_other_inputs_are_not_compared_with_printed_accelerations(tmp_path, capsys) -> None:
    rc, stdout, _ = _run(
        capsys, ["reproduce", "--out", str(tmp_path / "o"), "--json", "--z-e", "-30 ft"]
    )
    d = json.loads(stdout)
    assert rc == 0 and d["options"]["report_inputs"] is False
    groups = {g["key"]: g for g in d["agreement"]["groups"]}
    assert groups["table4_bending_accel"]["compared"] == 0
    assert "not compared" in groups["table4_bending_accel"]["note"]
    assert groups["appendix_c_omega2"]["compared"] == 8


def test_case_filter_counts_only_that_case(tmp_path: Path, capsys) -> None:
    rc, stdout, _ = _run(
        capsys, ["reproduce", "--out", str(tmp_path / "o"), "--json", "--case", "yz_orbiter"]
    )
    d = json.loads(stdout)
    wheres = {c["where"] for c in d["comparisons"]}
    assert wheres == {
        "Appendix C-3",
        "Table 4 yz_orbiter",
        "Appendix C-3 vs model",
        "Section 3, centre-of-mass table",
        "Table 2 vs model",
    }
    assert d["agreement"]["reproduction"]["compared"] == 2 + 8 + 2 + 2 + 2 + 1 + 1
    assert [m["name"] for m in d["meta"]["models"]] == ["ioc"]


def test_help_names_units_and_defaults(capsys) -> None:
    rc, out, _ = _run(capsys, ["reproduce", "--help"])
    assert rc == 0
    text = " ".join(out.split())
    for option, default, unit in [
        ("--f0", "25 lbf", "bare number: lbf"),
        ("--t1", "1 s", "bare number: s"),
        ("--t13", "13 s", "bare number: s"),
        ("--t14", "14 s", "bare number: s"),
        ("--z-e", "-55 ft", "bare number: ft"),
        ("--z-a", "-55 ft", "bare number: ft"),
        ("--out", "microg-reproduce", "report.html"),
    ]:
        block = text[text.index(option + " ") :]
        block = block[: block.index("[default:") + 60]
        assert unit in block and f"[default: {default}]" in block, option
    assert "-126.66 ft <= z <= 0" in text  # the range of --z-e and --z-a
    assert "[default: all four]" in text
    assert TITLE.split(" and ")[0] in text  # the seed report, by its title


def test_id_ranges() -> None:
    from microg.report.html import id_ranges

    assert id_ranges(["E9", "E10", "E11", "E14"]) == [("E9-E11", "E9"), ("E14", "E14")]
    assert id_ranges([]) == []
