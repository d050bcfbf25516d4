"""CLI contract of ``microg locate`` and ``microg optimize``: JSON, files, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from microg.cli import main
from microg.dynamics.crew import CrewPushoff
from microg.dynamics.modes import solve_modes
from microg.location.amap import acceleration_map
from microg.models.toml import load_station
from microg.structure.ritz import build_ritz
from microg.units import G0


def _run(capsys, *args):
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def test_locate_json_matches_library(capsys):
    rc, out, err = _run(capsys, "locate", "ioc", "--crew", "crew", "--json", "--on", "main")
    assert rc == 0 and err == ""
    data = json.loads(out)
    for key in ("samples", "nodes", "best_location", "modes", "fundamental", "window_s"):
        assert key in data
    s = build_ritz(load_station("ioc"), "xz", 1)
    ref = acceleration_map(s, solve_modes(s), "crew", "x", CrewPushoff(25 * 4.4482216152605))
    total = np.array([x["total_peak_g"] for x in data["samples"]])
    np.testing.assert_allclose(total, ref.total_peak / G0, rtol=1e-12)
    assert data["best_location"]["component"] == "main"
    on_main = [x["total_peak_g"] for x in data["samples"] if x["component"] == "main"]
    assert data["best_location"]["peak_g"] == min(on_main)
    assert len(data["samples"][0]["per_mode_g"]) == len(data["modes"])
    assert {n["component"] for n in data["nodes"]} >= {"main"}


def test_locate_writes_png_and_json(capsys, tmp_path):
    out_dir = tmp_path / "map"
    rc, out, _ = _run(capsys, "locate", "ioc-no-orbiter", "--crew", "lab", "--out", str(out_dir))
    assert rc == 0 and "best location" in out and "node on main" in out
    assert (out_dir / "map.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.loads((out_dir / "map.json").read_text())["crew_point"] == "lab"


def test_locate_fem_and_damping(capsys):
    rc, out, _ = _run(
        capsys,
        "locate",
        "ioc",
        "--crew",
        "crew",
        "--method",
        "fem",
        "--elements",
        "2",
        "--n-modes",
        "12",
        "--damping",
        "0.01",
        "--no-rigid",
        "--json",
    )
    assert rc == 0
    data = json.loads(out)
    assert data["method"] == "fem" and data["per_mode_exact"] is False
    assert not any(m["rigid"] for m in data["modes"])
    # the fundamental of an x push is the X-Z bending mode, not the lower torsion mode
    assert data["fundamental"]["omega"] == pytest.approx(1.0086, rel=1e-3)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["locate", "ioc", "--crew", "nowhere"], "known points: boom-tip, crew"),
        (["locate", "ioc"], "--crew"),
        (["locate", "ioc", "--crew", "crew", "--direction", "z"], "--direction"),
        (["locate", "ioc", "--crew", "crew", "--damping", "1.5"], "--damping"),
        (["locate", "ioc", "--crew", "crew", "--f0", "3 m"], "--f0"),
        (["locate", "ioc", "--crew", "crew", "--on", "hull"], "known components"),
        (["locate", "nope", "--crew", "crew"], "no such file"),
        (["optimize", "ioc", "--experiment", "lab", "--crew", "crew"], "no movable"),
        (
            ["optimize", "ioc", "--experiment", "lab", "--crew", "crew", "--movable", "Piano=0:1"],
            "known masses",
        ),
        (
            ["optimize", "ioc", "--experiment", "lab", "--crew", "crew", "--movable", "x"],
            "NAME=LO:HI",
        ),
        (
            [
                "optimize",
                "ioc",
                "--experiment",
                "lab",
                "--crew",
                "crew",
                "--movable",
                "TDM 2010=0:10",
            ],
            "ambiguous",
        ),
        (
            [
                "optimize",
                "ioc",
                "--experiment",
                "lab",
                "--crew",
                "crew",
                "--movable",
                "Horizontal lab=-200ft:0ft",
            ],
            "leaves the body",
        ),
        (
            [
                "optimize",
                "ioc",
                "--experiment",
                "nowhere",
                "--crew",
                "crew",
                "--movable",
                "Horizontal lab=-91ft:-5ft",
            ],
            "unknown point",
        ),
    ],
)
def test_bad_input_is_one_line_exit_2(capsys, tmp_path, args, needle):
    rc, out, err = _run(capsys, *args)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and needle in err


def test_bad_input_writes_nothing(capsys, tmp_path):
    out_dir = tmp_path / "never"
    rc, _, _ = _run(capsys, "locate", "ioc", "--crew", "nowhere", "--out", str(out_dir))
    assert rc == 2 and not out_dir.exists()


def test_optimize_json(capsys):
    rc, out, err = _run(
        capsys,
        "optimize",
        "ioc",
        "--experiment",
        "lab",
        "--crew",
        "crew",
        "--movable",
        "boom+y/TDM 2010=10ft:120ft",
        "--movable",
        "boom-y/TDM 2010=10ft:120ft",
        "--maxiter",
        "3",
        "--json",
    )
    assert rc == 0 and err == ""
    data = json.loads(out)
    assert [m["key"] for m in data["masses"]] == ["boom+y/TDM 2010", "boom-y/TDM 2010"]
    for m in data["masses"]:
        assert m["bounds_m"][0] <= m["optimal_m"] <= m["bounds_m"][1]
    assert data["objective_optimal_g"] <= data["objective_initial_g"]
    assert data["n_evaluations"] >= 1
