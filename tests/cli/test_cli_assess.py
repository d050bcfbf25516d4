"""``microg assess FILE``: contract, CSV units, outputs, and bad input (one line, exit 2)."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest

from microg.cli import main
from microg.environment.metrics import assess as assess_record
from microg.units import G0

FS = 50.0


def _run(capsys, args: list[str]) -> tuple[int, str, str]:
    rc = main(args)
    out, err = capsys.readouterr()
    return rc, out, err


def _signal(n: int) -> np.ndarray:
    """m/s^2: x 20 ug RMS at 2 Hz, y a 3 ug bias, z 2 ug RMS at 0.5 Hz."""
    t = np.arange(n) / FS
    return G0 * np.vstack(
        [
            20e-6 * np.sqrt(2) * np.sin(2 * np.pi * 2.0 * t),
            np.full(n, 3e-6),
            2e-6 * np.sqrt(2) * np.sin(2 * np.pi * 0.5 * t),
        ]
    )


def _csv(path: Path, unit: str = "m/s^2", n: int = 12000, sensor: str | None = None) -> Path:
    scale = {"m/s^2": 1.0, "g": 1 / G0, "ug": 1e6 / G0}[unit]
    a = _signal(n) * scale
    t = np.arange(n) / FS
    head = f"# sensor: {sensor}\n" if sensor else ""
    head += f"time [s], x [{unit}], y [{unit}], z [{unit}]\n"
    body = "\n".join(
        f"{ti:.10g},{x:.17g},{y:.17g},{z:.17g}" for ti, x, y, z in zip(t, *a, strict=True)
    )
    path.write_text(head + body + "\n")
    return path


@pytest.fixture(scope="module")
def csv_file(tmp_path_factory) -> Path:
    return _csv(tmp_path_factory.mktemp("m") / "rec.csv")


def test_json_is_the_observations_contract(csv_file: Path, capsys) -> None:
    rc, out, err = _run(capsys, ["assess", str(csv_file), "--json"])
    assert rc == 0, err
    d = json.loads(out)
    assert set(d["observations"]) == {"sensor"}  # no sensor name in the file
    o = d["observations"]["sensor"]
    # the same keys as Assessment.to_dict() of the same record (PIMS transient basis)
    t = np.arange(12000) / FS
    ref = assess_record(t, _signal(12000), transient_basis="pims").to_dict()
    assert set(o) == set(ref)
    assert set(o["third_octave"]) == set(ref["third_octave"])
    assert o["complies"] is ref["complies"] is True
    assert np.allclose(o["third_octave"]["rms_g"], ref["third_octave"]["rms_g"], rtol=1e-9)
    assert o["mean_accel_g_axis"]["y"] == pytest.approx(3e-6, rel=1e-9)
    assert d["meta"]["file_sha256"] and d["source"]["format"] == "csv"
    iv = d["intervals"]["sensor"]
    assert iv["n_intervals"] == 2 and iv["interval_s"] == 100.0


@pytest.mark.parametrize("unit", ["g", "ug"])
def test_csv_units(tmp_path: Path, capsys, unit: str, csv_file: Path) -> None:
    path = _csv(tmp_path / f"r_{unit}.csv", unit=unit, sensor="121f05")
    rc, out, err = _run(capsys, ["assess", str(path), "--json", "--interval", "60 s"])
    assert rc == 0, err
    o = json.loads(out)["observations"]["121f05"]
    rc, out2, _ = _run(capsys, ["assess", str(csv_file), "--json", "--interval", "60 s"])
    base = json.loads(out2)["observations"]["sensor"]
    # the same accelerations in another unit: the same band RMS (17 printed digits)
    assert np.allclose(o["third_octave"]["rms_g"], base["third_octave"]["rms_g"], rtol=1e-9)


def test_summary_and_out(tmp_path: Path, csv_file: Path, capsys) -> None:
    out_dir = tmp_path / "res"
    rc, out, err = _run(
        capsys, ["assess", str(csv_file), "--out", str(out_dir), "--requirement", "ssp41000"]
    )
    assert rc == 0, err
    assert "vs ssp41000: complies" in out and "judged" in out
    # one line per criterion, the same list as the JSON's (judged, reported only, undecided)
    obs = json.loads((out_dir / "results.json").read_text())["observations"]
    crit = next(iter(obs.values()))["criteria"]
    i = out.index("  verdict per criterion:\n")
    lines = out[i:].splitlines()[1 : 1 + len(crit)]
    assert [ln.strip().split(":")[0] for ln in lines] == [c["name"] for c in crit]
    names = {p.name for p in out_dir.iterdir()}
    assert "results.json" in names
    assert {"sensor-third-octave.png", "sensor-percentiles.png", "sensor-spectrogram.png"} <= names
    d = json.loads((out_dir / "results.json").read_text())
    assert d["requirement"] == "ssp41000"


def test_welch_option(csv_file: Path, capsys) -> None:
    rc, out, err = _run(
        capsys, ["assess", str(csv_file), "--json", "--psd", "welch", "--segment", "50 s"]
    )
    assert rc == 0, err
    d = json.loads(out)
    assert d["observations"]["sensor"]["record"]["psd_method"] == "welch"


def _pad(folder: Path, header_rate: str | None = "50.0", n: int = 3001) -> Path:
    name = "2020_01_01_00_00_00.000-2020_01_01_00_01_00.000.121f02"
    a = _signal(n) / G0
    t = np.arange(n) / FS
    (folder / name).write_bytes(b"".join(struct.pack("<4f", t[i], *a[:, i]) for i in range(n)))
    rate = "" if header_rate is None else f"<SampleRate>{header_rate}</SampleRate>"
    (folder / f"{name}.header").write_text(
        f'<?xml version="1.0"?><sams2_accel><SensorID>121f02</SensorID>{rate}'
        "<CutoffFreq>20.0</CutoffFreq>"
        f'<GData file="{name}" format="binary 32 bit IEEE float little endian"/></sams2_accel>'
    )
    return folder / name


def test_pad_file(tmp_path: Path, capsys) -> None:
    path = _pad(tmp_path)
    rc, out, err = _run(capsys, ["assess", str(path), "--json"])
    assert rc == 0, err
    d = json.loads(out)
    assert set(d["observations"]) == {"121f02"}
    assert d["source"]["sample_rate_hz"] == 50.0 and d["source"]["cutoff_hz"] == 20.0
    # 60 s < the default 100 s: one interval, said so
    assert d["intervals"]["121f02"]["n_intervals"] == 1
    assert any("shorter than the default" in w for w in d["warnings"])


def _bad(tmp_path: Path, capsys, args: list[str], needle: str) -> str:
    out_dir = tmp_path / "never"
    rc, out, err = _run(capsys, ["assess", *args, "--out", str(out_dir)])
    assert rc == 2, (out, err)
    assert err.count("\n") == 1 and "Traceback" not in err and needle in err, err
    assert not out_dir.exists()  # nothing written
    return err


def test_bad_pad_input(tmp_path: Path, capsys) -> None:
    path = _pad(tmp_path, header_rate=None)
    err = _bad(tmp_path, capsys, [str(path)], "SampleRate")
    assert ".header: SampleRate" in err and "add <SampleRate>" in err
    path = _pad(tmp_path, n=1500)  # the name says 60 s, the data hold 30 s
    err = _bad(tmp_path, capsys, [str(path)], ": length")
    assert path.name in err and "truncated" in err


@pytest.mark.parametrize("named", ["/etc/passwd", "../x/data", "sub/data", ".."])
def test_a_pad_header_naming_a_path_is_refused(tmp_path: Path, capsys, named: str) -> None:
    # the header is given alone and its GData file names a path: the data are read beside
    # the header only, so that is one line naming GData.file (it was an internal error)
    path = _pad(tmp_path)
    header = path.with_name(path.name + ".header")
    header.write_text(header.read_text().replace(f'file="{path.name}"', f'file="{named}"'))
    path.rename(tmp_path / "elsewhere")
    err = _bad(tmp_path, capsys, [str(header)], "GData.file")
    assert named not in err


def test_bad_csv_input(tmp_path: Path, capsys) -> None:
    p = tmp_path / "nan.csv"
    rows = "\n".join(f"{i / FS},0,0,{'nan' if i == 40 else 0}" for i in range(200))
    p.write_text("time [s], x [g], y [g], z [g]\n" + rows + "\n")
    err = _bad(tmp_path, capsys, [str(p)], "line 42")
    assert "nan.csv" in err and "not a finite number" in err
    p = tmp_path / "gap.csv"
    times = [i / FS for i in range(100)] + [3.0 + i / FS for i in range(100)]
    p.write_text("time [s], x [g]\n" + "\n".join(f"{t},0" for t in times) + "\n")
    err = _bad(tmp_path, capsys, [str(p)], "line 102")
    assert "uniformly" in err
    p = tmp_path / "nounit.csv"
    p.write_text("time, x [g]\n" + "\n".join(f"{i / FS},0" for i in range(100)) + "\n")
    _bad(tmp_path, capsys, [str(p)], "line 1, column 1")
    p = tmp_path / "word.csv"
    p.write_text("time [s], x [g]\n0,0\n0.02,abc\n")
    _bad(tmp_path, capsys, [str(p)], "line 3")


def test_bad_options(tmp_path: Path, csv_file: Path, capsys) -> None:
    _bad(tmp_path, capsys, [str(csv_file), "--requirement", "nasa"], "--requirement")
    _bad(tmp_path, capsys, [str(csv_file), "--interval", "1000 s"], "--interval")
    _bad(tmp_path, capsys, [str(tmp_path / "missing.csv")], "no such file")


def test_out_checked_before_computing(tmp_path: Path, csv_file: Path, capsys) -> None:
    rc, out, err = _run(capsys, ["assess", str(csv_file), "--out", "/proc/x"])
    assert rc == 2 and err.count("\n") == 1 and "--out" in err


def test_uff58_file_gives_every_sensor(tmp_path: Path, csv_file: Path, capsys) -> None:
    from microg.dynamics.response import PointResponse
    from microg.models.uff import write_uff_time

    n = 12000
    t = np.arange(n) / FS
    a = _signal(n)
    resp = {
        "lab": PointResponse("lab", t, 0 * a, 0 * a, a),
        "node-2": PointResponse("node-2", t, 0 * a, 0 * a, 0.5 * a),
    }
    uff = write_uff_time(resp, tmp_path / "two.unv", precision="double")
    rc, out, err = _run(capsys, ["assess", str(uff), "--json"])
    assert rc == 0, err
    d = json.loads(out)
    assert set(d["observations"]) == set(d["intervals"]) == {"lab", "node-2"}
    assert d["source"]["format"] == "uff58" and set(d["source"]["sensors"]) == {"lab", "node-2"}
    rc, out2, _ = _run(capsys, ["assess", str(csv_file), "--json"])
    base = json.loads(out2)["observations"]["sensor"]
    # reference: the same accelerations read from the CSV (17 digits) by the CSV reader;
    # the UFF's E20.12 keeps 13 digits: the band RMS agree to 1e-9
    lab = d["observations"]["lab"]
    assert np.allclose(lab["third_octave"]["rms_g"], base["third_octave"]["rms_g"], rtol=1e-9)
    half = d["observations"]["node-2"]["third_octave"]["rms_g"]
    assert np.allclose(half, 0.5 * np.asarray(base["third_octave"]["rms_g"]), rtol=1e-9)
    assert d["complies"] is (lab["complies"] and d["observations"]["node-2"]["complies"])
    rc, out, err = _run(capsys, ["assess", str(uff)])
    assert rc == 0 and out.count("two.unv: ") == 2 and "lab (UFF58" in out
    # --sensor renames one record only
    err = _bad(tmp_path, capsys, [str(uff), "--sensor", "x"], "--sensor")
    assert "holds 2 sensors" in err


def test_bad_uff58_input(tmp_path: Path, capsys) -> None:
    from microg.dynamics.response import PointResponse
    from microg.models.uff import write_uff_time

    t = np.arange(200) / FS
    a = _signal(200)
    uff = write_uff_time(
        {"lab": PointResponse("lab", t, a, a, a)}, tmp_path / "v.unv", quantity="velocity"
    )
    err = _bad(tmp_path, capsys, [str(uff)], "dataset 58 #1")
    assert "v.unv" in err and "not acceleration" in err
    text = write_uff_time({"lab": PointResponse("lab", t, a, a, a)}, tmp_path / "a.unv").read_text()
    cut = tmp_path / "cut.unv"
    cut.write_text(text[: text.rindex("    -1\n    58")])  # the z record missing
    err = _bad(tmp_path, capsys, [str(cut)], "dataset 58 #1")
    assert "has no z axis" in err


def test_a_record_beyond_the_physical_limit_is_refused_with_its_value(tmp_path, capsys) -> None:
    # 1e300 micro-g (a unit or file error): the band powers would overflow to a verdict of
    # nulls and "inf"; it is one line naming the file, the sample and its value, exit 2, and
    # nothing is written
    path = tmp_path / "huge.csv"
    t = np.arange(0.0, 20.0, 0.02)
    a = 1e300 * np.sin(2 * np.pi * t)
    rows = "\n".join(f"{ti:.6g},{x:.6g},{x:.6g},{x:.6g}" for ti, x in zip(t, a, strict=True))
    path.write_text("time [s], x [ug], y [ug], z [ug]\n" + rows + "\n")
    out_dir = tmp_path / "out"
    rc, out, err = _run(capsys, ["assess", str(path), "--json", "--out", str(out_dir)])
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1
    assert "beyond the physical limit" in err and "sample 1 of axis x" in err
    assert not out_dir.exists()


def test_a_measured_tone_near_a_band_edge_keeps_its_whole_rms(tmp_path: Path, capsys) -> None:
    # the measured path: 2.4 micro-g RMS at 0.11333 Hz (a bin of a 300-s record at 10 Hz) in
    # the 0.1122-0.1413 Hz band (limit 2.25 micro-g); written with 17 digits, so the band RMS
    # is the tone's to 1e-9 (the CSV's rounding) and the band fails
    fs, n = 10.0, 3000
    t = np.arange(n) / fs
    x = 2.4e-6 * np.sqrt(2) * np.sin(2 * np.pi * (34 / 300) * t)
    path = tmp_path / "tone.csv"
    body = "\n".join(f"{ti:.10g},{v:.17g},0,0" for ti, v in zip(t, x, strict=True))
    path.write_text("time [s], x [g], y [g], z [g]\n" + body + "\n")
    rc, out, err = _run(capsys, ["assess", str(path), "--json"])
    assert rc == 0, err
    o = next(iter(json.loads(out)["observations"].values()))
    to = o["third_octave"]
    b = to["center_hz"].index(0.125)
    assert to["rms_g_axis"]["x"][b] == pytest.approx(2.4e-6, rel=1e-9)
    assert to["rms_g_axis"]["x"][b - 1] < 1e-6 * 2.4e-6
    assert to["resolved"][b] and to["margin_axis"]["x"][b] < 1.0
    assert o["complies"] is False


@pytest.fixture(scope="module")
def prediction(tmp_path_factory) -> Path:
    """results.json of `microg analyze` on the IOC model (one observed point, lab)."""
    out_dir = tmp_path_factory.mktemp("pred") / "run"
    assert main(["analyze", "--duration", "100 s", "--out", str(out_dir)]) == 0
    return out_dir / "results.json"


def test_predicted_overlays_the_prediction_band_by_band(
    tmp_path: Path, csv_file: Path, prediction: Path, capsys
) -> None:
    out_dir = tmp_path / "ov"
    args = ["assess", str(csv_file), "--predicted", str(prediction), "--out", str(out_dir)]
    rc, out, err = _run(capsys, args)
    assert rc == 0, err
    assert f"prediction {prediction} at lab: measured/predicted" in out
    d = json.loads((out_dir / "results.json").read_text())
    ov = d["prediction"]["sensor"]
    assert ov["point"] == "lab" and ov["requirement"] == "iss"
    pred = json.loads(prediction.read_text())["observations"]["lab"]["third_octave"]
    meas = d["observations"]["sensor"]["third_octave"]
    # the bands both tables hold (the measurement's stop at its 25-Hz Nyquist frequency): the
    # same numbers as each side's own results, copied, so equal to JSON's round trip
    assert ov["center_hz"] == meas["center_hz"] == pred["center_hz"][: len(meas["center_hz"])]
    assert ov["predicted_g"] == pred["rms_g"][: len(ov["center_hz"])]
    assert ov["measured_g"] == meas["rms_g"]
    i = ov["center_hz"].index(2.0)  # the record's 20 micro-g tone
    assert ov["ratio"][i] == pytest.approx(meas["rms_g"][i] / pred["rms_g"][i], rel=1e-12)
    assert ov["worst_ratio_band_hz"] == 2.0
    assert "sensor-prediction-overlay.png" in {p.name for p in out_dir.iterdir()}
    html = (out_dir / "report.html").read_text()
    assert "Prediction at lab beside the measurement" in html and "measured / predicted" in html


def test_bad_predicted(tmp_path: Path, csv_file: Path, prediction: Path, capsys) -> None:
    err = _bad(tmp_path, capsys, [str(csv_file), "--predicted", str(csv_file)], "--predicted")
    assert "not a microg result" in err
    measured = tmp_path / "measured.json"
    assert main(["assess", str(csv_file), "--out", str(tmp_path / "m")]) == 0
    capsys.readouterr()
    measured.write_text((tmp_path / "m" / "results.json").read_text())
    err = _bad(tmp_path, capsys, [str(csv_file), "--predicted", str(measured)], "--predicted")
    assert "microg assess result" in err
    ok = [str(csv_file), "--predicted", str(prediction)]
    err = _bad(tmp_path, capsys, [*ok, "--requirement", "ssp41000"], "--requirement")
    assert "'iss'" in err and "'ssp41000'" in err
    err = _bad(tmp_path, capsys, [*ok, "--observe", "crew"], "--observe")
    assert "no point 'crew'" in err and "lab" in err
    two = json.loads(prediction.read_text())
    two["observations"]["crew"] = two["observations"]["lab"]
    several = tmp_path / "two.json"
    several.write_text(json.dumps(two))
    err = _bad(tmp_path, capsys, [str(csv_file), "--predicted", str(several)], "--observe")
    assert "2 points (lab, crew)" in err
    rc, out, err = _run(
        capsys,
        ["assess", str(csv_file), "--predicted", str(several), "--observe", "crew", "--json"],
    )
    assert rc == 0 and json.loads(out)["prediction"]["sensor"]["point"] == "crew"
    _bad(tmp_path, capsys, [str(csv_file), "--observe", "lab"], "--observe")


@pytest.mark.parametrize("fast_tone_ug", [0.0, 500.0])
def test_undecided_is_neither_a_pass_nor_a_fail(tmp_path: Path, capsys, fast_tone_ug) -> None:
    # a 20-s record at 50 Hz: 50 micro-g RMS at 0.2 Hz, in a band the record cannot resolve
    # (undecided), and nothing else that a judged band sees: the verdict is "undecided" on the
    # console, in the JSON and on the page.  A 500 micro-g tone at 5 Hz (a resolved band whose
    # ISS limit is 5 x 18 = 90 micro-g) makes a judged band fail: then it is a fail, whatever
    # the undecided band would say
    fs, n = 50.0, 1000
    t = np.arange(n) / fs
    x = 50e-6 * np.sqrt(2) * np.sin(2 * np.pi * 0.2 * t)
    x = x + fast_tone_ug * 1e-6 * np.sqrt(2) * np.sin(2 * np.pi * 5.0 * t)
    path = tmp_path / "short.csv"
    body = "\n".join(f"{ti:.10g},{v:.17g},0,0" for ti, v in zip(t, x, strict=True))
    path.write_text("time [s], x [g], y [g], z [g]\n" + body + "\n")
    out_dir = tmp_path / "o"
    rc, out, err = _run(capsys, ["assess", str(path), "--out", str(out_dir)])
    assert rc == 0, err
    d = json.loads((out_dir / "results.json").read_text())
    o = next(iter(d["observations"].values()))
    kinds = {c["status"] for c in o["criteria"]}
    assert "undecided" in kinds
    judged_fail = any(c["status"] == "judged" and not c["complies"] for c in o["criteria"])
    assert judged_fail == (fast_tone_ug > 0)
    want = "fails" if judged_fail else "undecided"
    assert o["verdict"] == d["verdict"] == want and d["complies"] is False
    head = next(line for line in out.splitlines() if line.startswith("  verdict vs "))
    assert head.startswith(f"  verdict vs iss: {'DOES NOT COMPLY' if judged_fail else 'UNDECIDED'}")
    page = next(out_dir.glob("*.html")).read_text()
    said = "Verdict: does NOT comply" if judged_fail else "Verdict: undecided: no judged criterion"
    assert said in page and ("does NOT comply" in page) == judged_fail
