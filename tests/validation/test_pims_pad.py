"""PIMS/SAMS PAD files as PIMS's own code reads them (github.com/baluneboy/pims).

References, commit 5a07e02588b1b7c8ebf7458b10e81b8ecf84ad13 of baluneboy/pims:

* ``pad/binaryToAscii.py``: data are 32-bit little-endian floats (``struct.unpack('<f')``),
  4 columns per record for acceleration files;
* ``pad/padquarantine.py`` (``array_fromfile``) and baluneboy/ugaudio ``load.py`` (``padread``):
  ``np.fromfile(f, dtype=np.float32).reshape(-1, 4)``; the header is ``datafile + '.header'``;
* ``transient/main.py``: column 0 is time ("toss out time column"), the rest is in g
  (``ug = b / 1.0e-06  # convert to ug``);
* ``pad/create_header_dict.py`` (``parse_header``): XML elements ``SampleRate``,
  ``CutoffFreq``, ``SensorID``, ``TimeZero``, ``GData`` (``format``, ``file``); the header
  below follows the layout of PIMS's sample header ``sandbox/data/*.121f03006.header``.

The data file is written here record by record with ``struct.pack('<4f', ...)``, the format
PIMS's binaryToAscii unpacks: an independent writer for the reader under test.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from microg.environment.measured import read_accel_csv, read_measured, read_pad_header
from microg.environment.metrics import assess
from microg.errors import InputError
from microg.units import G0

NAME = "2014_10_22_09_36_36.324-2014_10_22_09_37_35.317.121f03006"

HEADER = """<?xml version="1.0" encoding="US-ASCII"?><sams2_accel>
\t<SensorID>121f03006</SensorID>
\t<TimeZero>2014_10_22_09_36_36.324</TimeZero>
\t<Gain>10.0</Gain>
\t<SampleRate>{fs}</SampleRate>
\t<CutoffFreq>6.00</CutoffFreq>
\t<GData file="{name}" format="binary 32 bit IEEE float little endian"/>
\t<SensorCoordinateSystem comment="LAB1O1, ER2, Lower Z Panel" name="121f03" p="30.0" r="0.0" \
time="2001_05_17_15_11_43.000" w="-90.0" x="191.54" y="-40.54" z="135.25"/>
\t<DataCoordinateSystem comment="S0, Geom. Ctr. ITA" name="SSAnalysis" p="0.0" r="0.0" \
time="2001_05_01_00_00_00.000" w="0.0" x="0.0" y="0.0" z="0.0"/>
\t<DataQualityMeasure>temperature+gain+axial-mis-alignment, Valid</DataQualityMeasure>
\t<ISSConfiguration>Increment:  28, Flight: ULF7</ISSConfiguration>
</sams2_accel>
"""


def signal_g(n: int, fs: float) -> np.ndarray:
    """x: 20 ug RMS at 2 Hz; y: -250 ug bias; z: 5 ug RMS noise (g)."""
    t = np.arange(n) / fs
    rng = np.random.default_rng(4)
    return np.vstack(
        [
            20e-6 * np.sqrt(2) * np.sin(2 * np.pi * 2.0 * t),
            np.full(n, -250e-6),
            5e-6 * rng.standard_normal(n),
        ]
    )


def write_pad(
    folder: Path,
    fs: float = 142.0,
    seconds: float = 58.993,
    header: str | None = None,
    name: str = NAME,
    times: np.ndarray | None = None,
) -> Path:
    n = int(round(seconds * fs)) + 1
    a = signal_g(n, fs)
    t = np.arange(n) / fs if times is None else times
    data = b"".join(struct.pack("<4f", t[i], a[0, i], a[1, i], a[2, i]) for i in range(n))
    path = folder / name
    path.write_bytes(data)
    hdr = HEADER.format(fs=f"{fs:.2f}", name=name) if header is None else header
    (folder / f"{name}.header").write_text(hdr, encoding="ascii")
    return path


def test_pad_reader(tmp_path: Path) -> None:
    path = write_pad(tmp_path)
    rec = read_measured(path)
    assert rec.format == "pad" and rec.sensor == "121f03006" and rec.key == "121f03006"
    assert rec.sample_rate_hz == 142.0 and rec.cutoff_hz == 6.0
    assert rec.start == "2014_10_22_09_36_36.324"
    n = int(round(58.993 * 142.0)) + 1
    assert rec.accel.shape == (3, n)
    # g -> m/s^2 of the float32 samples, exactly (the reference: the same numbers packed '<f')
    want = signal_g(n, 142.0).astype(np.float32).astype(float) * G0
    assert np.array_equal(rec.accel, want)
    assert np.allclose(np.diff(rec.timepts), 1 / 142.0, rtol=1e-12)
    assert rec.metadata["SensorCoordinateSystem.comment"] == "LAB1O1, ER2, Lower Z Panel"
    # the header file itself may be given
    assert read_measured(tmp_path / f"{NAME}.header").accel.shape == (3, n)


def test_pad_and_csv_give_the_same_assessment(tmp_path: Path) -> None:
    path = write_pad(tmp_path)
    rec = read_measured(path)
    # the same samples written as CSV in micro-g
    csv = tmp_path / "same.csv"
    ug = rec.accel / G0 * 1e6
    rows = "\n".join(
        f"{t:.17g},{x:.17g},{y:.17g},{z:.17g}" for t, x, y, z in zip(rec.timepts, *ug, strict=True)
    )
    csv.write_text("# sensor: 121f03006\ntime [s], x [ug], y [ug], z [ug]\n" + rows + "\n")
    rc = read_accel_csv(csv)
    assert rc.sensor == "121f03006"
    assert np.allclose(rc.accel, rec.accel, rtol=1e-12, atol=1e-18)
    a1 = assess(rec.timepts, rec.accel, cutoff_hz=rec.cutoff_hz, transient_basis="pims")
    a2 = assess(rc.timepts, rc.accel, cutoff_hz=6.0, transient_basis="pims")
    assert np.allclose(a1.third_octave.rms_g, a2.third_octave.rms_g, rtol=1e-9)
    # the mean (a sensor bias here) is reported and kept out of the bands
    assert a1.mean_accel_g_axis[1] == pytest.approx(-250e-6, rel=1e-6)
    # the 2 Hz tone: 20 ug RMS in the 2 Hz band (1.778-2.239 Hz); 59 s holds 118 cycles, so
    # leakage is below 1e-3 of the tone's power
    i = int(np.argmin(np.abs(a1.third_octave.center_hz - 2.0)))
    assert a1.third_octave.rms_g[0, i] == pytest.approx(20e-6, rel=1e-3)
    # bands above the 6 Hz cutoff are not judged, and say why
    top = a1.third_octave.upper_hz > 6.0
    assert not np.any(a1.third_octave.resolved[top])
    assert all("cutoff" in a1.third_octave.reasons[j] for j in np.nonzero(top)[0])


def test_header_without_sample_rate(tmp_path: Path) -> None:
    bad = HEADER.replace("\t<SampleRate>{fs}</SampleRate>\n", "").format(name=NAME)
    path = write_pad(tmp_path, header=bad)
    with pytest.raises(InputError) as err:
        read_measured(path)
    assert err.value.where.endswith(".header: SampleRate")
    assert "SampleRate" in (err.value.fix or "")
    assert read_pad_header.__doc__


def test_length_not_matching_header(tmp_path: Path) -> None:
    # truncated to 30 s while the name (and the header's GData) say 59 s
    path = write_pad(tmp_path, seconds=30.0)
    with pytest.raises(InputError, match="span") as err:
        read_measured(path)
    assert err.value.where.endswith(": length")
    # a partial last record
    path.write_bytes(path.read_bytes()[:-6])
    with pytest.raises(InputError, match="16-byte records"):
        read_measured(path)
    # a header whose SampleRate disagrees with the data's time column
    path = write_pad(tmp_path, header=HEADER.format(fs="500.0", name=NAME))
    with pytest.raises(InputError, match="500-Hz grid") as err:
        read_measured(path)
    assert err.value.where.endswith("record 2")


def test_gap_in_time_column(tmp_path: Path) -> None:
    fs = 142.0
    n = int(round(58.993 * fs)) + 1
    t = np.arange(n) / fs
    t[4000:] += 0.5  # half a second missing
    path = write_pad(tmp_path, times=t, name="gap.121f03006")
    with pytest.raises(InputError, match="gap") as err:
        read_measured(path)
    assert err.value.where.endswith("record 4001")


def test_other_layouts_refused(tmp_path: Path) -> None:
    hdr = HEADER.format(fs="142.00", name=NAME).replace("121f03006</SensorID>", "ossraw</SensorID>")
    path = write_pad(tmp_path, header=hdr)
    with pytest.raises(InputError, match="not\\s+t, x, y, z"):
        read_measured(path)
    hdr = HEADER.format(fs="142.00", name=NAME).replace("little endian", "big endian")
    path = write_pad(tmp_path, header=hdr)
    with pytest.raises(InputError, match="GData.format|data format"):
        read_measured(path)
