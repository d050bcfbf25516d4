"""CLI contract of ``microg quasi-steady``: JSON keys, values from the library, files, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from microg.cli import main
from microg.environment.quasisteady import AtmosphereInputs, Drag, OrbitInputs, quasi_steady
from microg.models.toml import load_station
from microg.units import G0


def _run(capsys, *args):
    rc = main(["quasi-steady", *args])
    out, err = capsys.readouterr()
    return rc, out, err


def test_json_contract(capsys):
    rc, out, err = _run(capsys, "ioc", "--ballistic-coefficient", "120 kg/m^2", "--json")
    assert rc == 0 and err == ""
    data = json.loads(out)
    assert {"center_of_mass_m", "mean_motion_rad_s", "orbit", "attitude", "atmosphere"} <= set(data)
    assert {"drag", "requirement", "points", "map", "complies", "warnings"} <= set(data)
    assert data["attitude"]["kind"] == "lvlh"
    assert {"date_utc", "f107_sfu", "f107a_sfu", "ap", "model"} <= set(data["atmosphere"])
    assert {"radius_m", "inclination_deg", "period_s"} <= set(data["orbit"])
    assert "cm" in data["points"] and "lab" in data["points"]
    keys = {"position_m", "accel_g", "gravity_gradient_g", "rotation_g", "drag_g"}
    keys |= {"magnitude_g", "complies", "lvlh", "peak_magnitude_g"}
    for name, p in data["points"].items():
        assert keys <= set(p), name
        assert len(p["accel_g"]) == 3 and len(p["lvlh"]["accel_g"]) == 3
        parts = np.add(np.add(p["gravity_gradient_g"], p["rotation_g"]), p["drag_g"])
        # the total is the sum of its parts, in g
        np.testing.assert_allclose(p["accel_g"], parts, rtol=1e-12, atol=1e-24)
    # reference: the library called directly with the same inputs (the command computes
    # nothing else)
    st = load_station("ioc")
    ref = quasi_steady(
        st,
        orbit=OrbitInputs(radius_m=st.orbit.radius, mu_m3_per_s2=st.orbit.mu),
        drag=Drag(ballistic_coefficient_kg_per_m2=120.0),
        atmosphere=AtmosphereInputs(),
    )
    np.testing.assert_allclose(data["center_of_mass_m"], ref.center_of_mass_m, rtol=0, atol=1e-12)
    assert data["mean_motion_rad_s"] == pytest.approx(ref.mean_motion_rad_s, rel=1e-15)
    lab = data["points"]["lab"]
    np.testing.assert_allclose(lab["accel_g"], ref.points["lab"].accel_mps2 / G0, rtol=1e-12)
    assert lab["complies"] is False and data["complies"] is False
    assert data["requirement"]["limit_ug"] == pytest.approx(1.0)


def test_table_output_and_a_fail_certain_without_drag(capsys):
    # without drag input the lab's 1.41 micro-g from gravity gradient and rotation already
    # exceeds 1 micro-g: the verdict is a fail, and it says no drag input would change it
    rc, out, err = _run(capsys, "ioc")
    assert rc == 0 and err == ""
    assert "verdict: DOES NOT COMPLY whatever the drag" in out and "no drag input" in out
    lab = next(line for line in out.splitlines() if line.strip().startswith("lab "))
    assert "EXCEEDS whatever the drag (>= 1.41)" in lab
    assert "cm" in out


def test_out_directory(tmp_path, capsys):
    out_dir = tmp_path / "qs"
    rc, out, err = _run(
        capsys,
        "ioc",
        "--area",
        "900 m^2",
        "--cd",
        "2.1",
        "--atmosphere",
        "exponential",
        "--out",
        str(out_dir),
    )
    assert rc == 0, err
    names = {p.name for p in out_dir.iterdir()}
    assert {"quasi-steady.json", "quasi-steady-map.csv", "quasi-steady-map.png"} <= names
    data = json.loads((out_dir / "quasi-steady.json").read_text())
    assert data["atmosphere"]["model"].startswith("exponential")
    assert data["drag"]["cd"] == 2.1 and data["drag"]["area_m2"] == pytest.approx(900.0)
    # the map's CSV as the csv module reads it: one field per column on every row, labels
    # with commas whole (the IOC's "main/Horizontal lab, SAA0207 and SAA0201")
    import csv

    with open(out_dir / "quasi-steady-map.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    head, body = rows[0], rows[1:]
    assert body and all(len(r) == len(head) for r in body)
    labels = {r[0] for r in body}
    assert any("," in lab for lab in labels), sorted(labels)[:5]


def test_rate_attitude_with_units(capsys):
    rc, out, err = _run(
        capsys,
        "ioc",
        "--attitude",
        "rate",
        "--rate",
        "0 0.0635 0 deg/s",
        "--angular-acceleration",
        "0 0 1e-7",
        "--json",
    )
    assert rc == 0, err
    w = json.loads(out)["attitude"]["omega_rad_s"]
    # 0.0635 deg/s in rad/s
    assert w[1] == pytest.approx(np.radians(0.0635), rel=1e-12)


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (["--radius", "1000 km"], "--radius"),
        (["--altitude", "-200 km"], "--radius"),
        (["--area", "-5 m^2"], "--area"),
        (["--area", "5 m^2", "--cd", "-1"], "--cd"),
        (["--cd", "2"], "--cd"),
        (["--ballistic-coefficient", "5 kg"], "--ballistic-coefficient"),
        (["--attitude", "tumbling"], "--attitude"),
        (["--rate", "0 1e-3 0"], "--rate"),
        (["--attitude", "rate"], "--rate"),
        (["--attitude", "rate", "--rate", "1 2"], "--rate"),
        (["--date", "yesterday"], "--date"),
        (["--f107", "-3"], "--f107"),
        (["--observe", "galley"], "--observe: unknown point 'galley'"),
        (["--inclination", "51.6 m"], "--inclination: '51.6 m' is not an angle"),
        (["--raan", "1 rad/s"], "--raan"),
        (["--radius", "7000 km", "--altitude", "400 km"], "--radius"),
    ],
)
def test_bad_input_is_one_line_exit_2(capsys, tmp_path, args, flag):
    out_dir = tmp_path / "never"
    rc, out, err = _run(capsys, "ioc", *args, "--out", str(out_dir))
    assert rc == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and flag in lines[0], err
    assert "Traceback" not in err and not out_dir.exists()


def test_angles_take_units_and_bare_degrees(capsys) -> None:
    # --inclination took a bare number of degrees only; now a quantity, bare = degrees
    docs = []
    for value in ("28.5", "28.5 deg", "0.4974188368 rad"):
        rc, out, err = _run(capsys, "ioc", "--inclination", value, "--samples", "12", "--json")
        assert rc == 0, err
        docs.append(json.loads(out)["orbit"]["inclination_deg"])
    # 0.4974188368 rad = 28.5 deg to the 10 digits written (28.5 pi / 180 = 0.49741883681838...)
    assert docs[0] == docs[1] == pytest.approx(28.5, rel=1e-15)
    assert docs[2] == pytest.approx(28.5, rel=1e-9)
