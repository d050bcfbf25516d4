"""CLI contract of ``microg locate`` and ``microg optimize``: JSON, files, bad input."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from microg import defaults
from microg.cli import main
from microg.dynamics.crew import CrewPushoff
from microg.dynamics.forces import REPORT_F0_N
from microg.dynamics.modes import solve_modes
from microg.location.amap import acceleration_map, locate
from microg.models.toml import load_station
from microg.structure.discretize import discretize
from microg.units import FT, G0

SI_MODEL = """
[station]
name = "small"
units = "SI"
[orbit]
altitude = "500 km"
[[body]]
name = "core"
  [[body.mass]]
  name = "hab"
  mass = "20000 kg"
  at = ["0 m", "0 m", "-4 m"]
  [[body.mass]]
  name = "dock"
  mass = "30000 kg"
  at = ["0 m", "0 m", "-20 m"]
[[beam]]
name = "keel"
parent = "core"
root = ["0 m", "0 m", "0 m"]
direction = "+z"
length = "60 m"
ei = "4e8 N*m^2"
gj = "1e8 N*m^2"
mass_per_length = "20 kg/m"
[[point]]
name = "lab"
on = "core"
at = ["0 m", "0 m", "-12 m"]
kind = "experiment"
[[point]]
name = "crew"
on = "core"
at = ["0 m", "0 m", "-12 m"]
kind = "crew"
"""


def _run(capsys, *args):
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture
def si_model(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SI_MODEL)
    return path


@pytest.fixture
def unitless_model(tmp_path):
    # the same model with no unit system: every value carries its unit, bare numbers do not
    path = tmp_path / "plain.toml"
    path.write_text(SI_MODEL.replace('units = "SI"\n', ""))
    return path


@pytest.fixture
def crewless_model(tmp_path):
    path = tmp_path / "nocrew.toml"
    path.write_text(SI_MODEL.replace('kind = "crew"\n', ""))
    return path


def test_locate_json_matches_library(capsys):
    # the report preset: the planar assumed-modes model, one function per beam, no damping
    args = ["locate", "ioc", "--preset", "report", "--at", "crew", "--json", "--on", "main"]
    rc, out, err = _run(capsys, *args)
    assert rc == 0 and err == ""
    data = json.loads(out)
    for key in ("samples", "nodes", "best_location", "modes", "fundamental", "window_s"):
        assert key in data
    s = discretize(load_station("ioc"), "ritz", plane="xz", n=1)
    ref = acceleration_map(s, solve_modes(s), "crew", "x", CrewPushoff(25 * 4.4482216152605))
    total = np.array([x["total_peak_g"] for x in data["samples"]])
    np.testing.assert_allclose(total, ref.total_peak / G0, rtol=1e-12)
    assert data["best_location"]["component"] == "main"
    on_main = [x["total_peak_g"] for x in data["samples"] if x["component"] == "main"]
    assert data["best_location"]["peak_g"] == min(on_main)
    assert len(data["samples"][0]["per_mode_g"]) == len(data["modes"])
    assert {n["component"] for n in data["nodes"]} >= {"main"}
    # the JSON is the library result's to_dict()
    same_force = CrewPushoff(data["force"]["f0_N"])
    assert data == json.loads(
        json.dumps(
            locate(
                "ioc",
                "crew",
                force=same_force,
                on="main",
                **{"method": "ritz", "plane": "xz"},
                n=1,
                zeta=0.0,
            ).to_dict()
        )
    )


def test_locate_defaults_to_the_models_crew_point(capsys):
    # `microg locate ioc` printed "microg: error: --at: " (no message)
    rc, out, err = _run(capsys, "locate", "ioc", "--json")
    assert rc == 0 and err == ""
    data = json.loads(out)
    first_crew = [p.name for p in load_station("ioc").points if p.kind == "crew"][0]
    assert data["crew_point"] == first_crew == "crew"


def test_locate_writes_png_and_json(capsys, tmp_path):
    out_dir = tmp_path / "map"
    rc, out, _ = _run(capsys, "locate", "ioc-no-orbiter", "--at", "lab", "--out", str(out_dir))
    assert rc == 0 and "best location" in out and "node on main" in out
    assert (out_dir / "map.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.loads((out_dir / "map.json").read_text())["crew_point"] == "lab"


def test_locate_fem_and_damping(capsys):
    rc, out, _ = _run(
        capsys,
        "locate",
        "ioc",
        "--at",
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


def test_out_is_checked_before_computing(capsys, tmp_path, monkeypatch):
    # an unwritable --out failed only after the computation
    import microg.location.amap as amap

    def boom(*args, **kwargs):
        raise AssertionError("computed before checking --out")

    monkeypatch.setattr(amap, "locate", boom)
    blocker = tmp_path / "file"
    blocker.write_text("x")
    rc, out, err = _run(capsys, "locate", "ioc", "--out", str(blocker / "sub"))
    assert rc == 2 and out == "" and err.startswith("microg: error: --out: ")


BAD = [
    (["locate", "ioc", "--at", "nowhere"], "--at: unknown point 'nowhere'"),
    (["locate", "ioc", "--at", "nowhere"], "known points: boom-tip, crew"),
    (["locate", "ioc", "--preset", "report", "--direction", "z"], "--direction"),
    (["locate", "ioc", "--at", "crew", "--direction", "w"], "--direction"),
    (["locate", "ioc", "--at", "crew", "--damping", "1.5"], "--damping"),
    (["locate", "ioc", "--at", "crew", "--force", "crew-pushoff:f0=3m"], "--force"),
    (["locate", "ioc", "--force", "crew-pushoff:f0=0lbf"], "--force crew-pushoff:f0=0lbf: f0"),
    (["locate", "ioc", "--force", "stomp"], "--force: unknown force 'stomp'"),
    (
        ["optimize", "ioc", "--force", "crew-pushoff:t14=12s", "--movable", "Horizontal lab=0:1"],
        "--force crew-pushoff:t14=12s: t14",
    ),
    (["locate", "ioc", "--at", "crew", "--on", "hull"], "--on: no samples on 'hull'"),
    (["locate", "ioc", "--at", "crew", "--on", "hull"], "known components"),
    (["locate", "ioc", "--method", "ritz", "--elements", "3"], "--elements"),
    (["locate", "ioc", "--crew", "crew"], "no such option --crew"),
    (["locate", "ioc", "--method", "fem", "--functions", "3"], "--functions"),
    (["locate", "nope", "--at", "crew"], "no such file"),
    (["optimize", "ioc", "--observe", "lab", "--at", "crew"], "--movable: no movable"),
    (
        ["optimize", "ioc", "--observe", "lab", "--at", "crew", "--movable", "Piano=0:1"],
        "known masses",
    ),
    (
        ["optimize", "ioc", "--observe", "lab", "--at", "crew", "--movable", "x"],
        "NAME=LO:HI",
    ),
    (
        ["optimize", "ioc", "--observe", "lab", "--at", "crew", "--movable", "TDM 2010=0:10"],
        "ambiguous",
    ),
    (
        [
            "optimize",
            "ioc",
            "--observe",
            "lab",
            "--at",
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
            "--observe",
            "nowhere",
            "--at",
            "crew",
            "--movable",
            "Horizontal lab=-91ft:-5ft",
        ],
        "--observe: unknown point",
    ),
    (
        ["optimize", "ioc", "--movable", "Horizontal lab=-91ft:-5ft", "--carry", "lab=Piano"],
        "--carry lab",
    ),
    (["optimize", "ioc", "--movable", "Horizontal lab=-91ft:-5ft", "--maxiter", "0"], "--maxiter"),
    (
        ["optimize", "ioc", "--movable", "Horizontal lab=-91ft:-5ft", "--maxiter", "1001"],
        "--maxiter",
    ),
]


@pytest.mark.parametrize(("args", "needle"), BAD)
def test_bad_input_is_one_line_exit_2(capsys, tmp_path, args, needle):
    rc, out, err = _run(capsys, *args)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and needle in err
    # never a blank message ("microg: error: --at: " and nothing after it)
    assert re.match(r"^microg: error: (--[\w-]+( [^:]+)?: )?\S", err), err


def test_model_without_crew_point_is_a_message(capsys, crewless_model):
    rc, out, err = _run(capsys, "locate", str(crewless_model))
    assert rc == 2 and out == ""
    assert err.startswith("microg: error: --at: the model has no crew point")
    assert "name one of: lab, crew" in err


def test_bad_input_writes_nothing(capsys, tmp_path):
    out_dir = tmp_path / "never"
    rc, _, _ = _run(capsys, "locate", "ioc", "--at", "nowhere", "--out", str(out_dir))
    assert rc == 2 and not out_dir.exists()


def test_optimize_json(capsys):
    rc, out, err = _run(
        capsys,
        "optimize",
        "ioc",
        "--observe",
        "lab",
        "--at",
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
    # the objective is the total peak, with its rigid and elastic parts beside it
    assert data["measure"] == "total"
    assert data["objective_optimal_g"] == data["optimal"]["total_g"]
    assert data["optimal"]["rigid_g"] > 0 and data["optimal"]["elastic_g"] > 0


def test_optimize_readme_example_reports_total_and_parts(capsys):
    # README: microg optimize ioc --preset report --observe lab --movable "Horizontal lab=..."
    args = ["optimize", "ioc", "--preset", "report", "--observe", "lab", "--at", "crew"]
    rc, out, err = _run(capsys, *args, "--movable", "Horizontal lab=-91ft:-5ft")
    assert rc == 0 and err == ""  # not a TTY: no progress bar
    m = re.search(r"total peak \(objective\): (\S+) g -> (\S+) g \(x(\S+) lower\)", out)
    assert m, out
    before, after, gain = (float(v) for v in m.groups())
    # the rigid translation f0/M alone (4.1e-5 g for the IOC) bounds what a layout can reach;
    # the report's gain must be of that order
    f0_over_m = 25 * 4.4482216152605 / load_station("ioc").mass_properties()[0] / G0
    assert after > 0.5 * f0_over_m and 1.0 <= gain <= before / (0.5 * f0_over_m)
    assert "rigid-body" in out and "elastic" in out


def test_bare_numbers_in_movable_take_the_models_units(capsys, si_model, unitless_model):
    # bare numbers were ft even in an SI model (the dock at -20 m is outside
    # -20 ft .. -4 ft = -6.1 .. -1.2 m, so ft would be an error)
    base = ["optimize", "--maxiter", "2", "--json", "--no-progress"]
    rc, out, err = _run(capsys, *base[:1], str(si_model), *base[1:], "--movable", "dock=-20:-4")
    assert rc == 0, err
    assert json.loads(out)["masses"][0]["bounds_m"] == [-20.0, -4.0]
    # the US model: ft
    rc, out, err = _run(capsys, "optimize", "ioc", *base[1:], "--movable", "Horizontal lab=-91:-5")
    assert rc == 0, err
    lo, hi = json.loads(out)["masses"][0]["bounds_m"]
    assert (lo, hi) == pytest.approx((-91 * FT, -5 * FT), rel=1e-15)
    # no unit system: an error naming the option and the fix
    rc, out, err = _run(
        capsys, "optimize", str(unitless_model), *base[1:], "--movable", "dock=-20:-4"
    )
    assert rc == 2 and out == ""
    assert err.startswith("microg: error: --movable core/dock: bare number '-20' has no unit")
    assert "units = " in err


def test_progress_bar_on_a_tty_only(capsys, monkeypatch):
    args = ["optimize", "ioc", "--movable", "Horizontal lab=-91ft:-5ft", "--maxiter", "2"]
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    rc, out, err = _run(capsys, *args)
    assert rc == 0 and "microg optimize" in err
    rc, out, err = _run(capsys, *args, "--no-progress")
    assert rc == 0 and err == ""


# --------------------------------------------------------------------------- imported models


@pytest.fixture(scope="module")
def ioc_uff(tmp_path_factory):
    """The IOC FE modes written as UFF (double) with a points file naming the crew grid."""
    from microg.models.uff import write_uff_modes

    s = discretize(load_station("ioc"))
    md = solve_modes(s, 30)
    d = tmp_path_factory.mktemp("uff")
    uff = write_uff_modes(md, d / "ioc.unv", precision="double", points_path=d / "ioc.toml")
    # the CLI default: the report's push-off, the default damping
    ref = acceleration_map(s, md, "crew", "x", CrewPushoff(REPORT_F0_N), zeta=defaults.DAMPING)
    return uff, d / "ioc.toml", ref, len(s.samples.labels)


def test_locate_cli_on_a_uff_modal_model(capsys, ioc_uff):
    uff, pts, ref, p = ioc_uff
    rc, out, err = _run(
        capsys,
        "locate",
        str(uff),
        "--points",
        str(pts),
        "--at",
        "crew",
        "--direction",
        "x",
        "--json",
    )
    assert rc == 0, err
    data = json.loads(out)
    assert data["method"] == "modal" and data["crew_point"] == "crew"
    total = np.array([x["total_peak_g"] for x in data["samples"][:p]])
    # reference: the FE model's own map at the exported nodes (lossless file: rounding)
    np.testing.assert_allclose(total, ref.total_peak[:p] / G0, rtol=1e-9)
    labels = [x["label"] for x in data["samples"]]
    assert labels[:2] == ["grid:1", "grid:2"] and labels[-5:][1] == "crew"
    assert any("no beam line" in w for w in data["warnings"])
    rc, out, err = _run(
        capsys, "locate", str(uff), "--points", str(pts), "--at", "crew", "--on", "points"
    )
    assert rc == 0, err
    assert "best location (total) on points" in out and "grids: total peak" in out


def test_locate_cli_on_a_deck(capsys, tmp_path):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "validation"))
    from test_frame_closed_loop import write_deck

    deck = write_deck(tmp_path / "truss.bdf")
    rc, out, err = _run(
        capsys, "locate", str(deck), "--units", "mm, N, s", "--at", "grid:1", "--json"
    )
    assert rc == 0, err
    data = json.loads(out)
    assert data["method"] == "fem" and data["nodes"]
    assert {n["component"] for n in data["nodes"]} <= {
        f"grid:{a}..grid:{b}" for a in range(1, 10) for b in range(1, 10)
    }
    # bad input: one line naming the option, exit 2, nothing on stdout
    for args, where in (
        (["--at", "grid:1"], "truss.bdf"),  # NASTRAN deck without units
        (["--units", "mm, N, s", "--at", "grid:77"], "--at"),
        (["--units", "N, N, s", "--at", "grid:1"], "--units"),
    ):
        rc, out, err = _run(capsys, "locate", str(deck), *args)
        assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, (args, err)
        assert where in err, (args, err)
