"""Readers of measured acceleration: NASA PIMS/SAMS PAD files and CSV with units in the header.

PAD files (PIMS's "Principal Investigator Microgravity Services Acceleration Data"), as PIMS's
own code reads and writes them (github.com/baluneboy/pims, commit
5a07e02588b1b7c8ebf7458b10e81b8ecf84ad13):

* the data file holds 32-bit little-endian IEEE floats, records of 4 columns ``t, x, y, z``:
  ``t`` in seconds from the header's ``TimeZero``, accelerations in g.  PIMS reads it with
  ``np.fromfile(f, dtype=np.float32).reshape(-1, 4)`` (``padread`` in baluneboy/ugaudio
  ``load.py``; ``array_fromfile`` in ``pad/padquarantine.py``; ``pad/binaryToAscii.py``
  unpacks ``'<f'``), drops column 0 as time (``transient/main.py``: "toss out time column")
  and treats the rest as g (``ug = b / 1.0e-06  # convert to ug``);
* the header file is the data file's name plus ``.header`` (``pad/padquarantine.py``), XML
  with the data type as root tag (e.g. ``sams2_accel``) and the elements ``SensorID``,
  ``TimeZero``, ``SampleRate`` (samples per second), ``CutoffFreq`` (Hz),
  ``GData format="binary 32 bit IEEE float little endian" file=...``,
  ``SensorCoordinateSystem``, ``DataCoordinateSystem``, ``DataQualityMeasure``,
  ``ISSConfiguration`` (``parse_header`` in ``pad/create_header_dict.py``).  PIMS uses 4
  elements per record except for the ``ossraw`` (6) and ``radgse`` (14) sensors, which are
  not acceleration triads and are refused here.

CSV: one header line with a unit per column, ``time [s], x [m/s^2], y [m/s^2], z [m/s^2]``
(any time unit; accelerations in ``m/s^2``, ``g``, ``mg``, ``ug``, ``ft/s^2`` ...), units in
brackets, parentheses or after an underscore (``time_s``); ``#`` comments, of which
``# sensor: NAME`` names the sensor and ``# cutoff: 6 Hz`` gives the anti-alias cutoff.

Every problem raises :class:`~microg.errors.InputError` naming the file and the line, record
or field, and the fix.
"""

from __future__ import annotations

import io
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

import numpy as np

from microg.environment.metrics import MAX_SAMPLES
from microg.errors import InputError
from microg.units import G0, parse_quantity

__all__ = [
    "MAX_HEADER_BYTES",
    "MAX_CSV_BYTES",
    "MeasuredRecord",
    "PadHeader",
    "read_pad_header",
    "read_pad",
    "read_accel_csv",
    "read_measured",
]

#: largest PAD header read, bytes
MAX_HEADER_BYTES = 1_000_000
#: largest CSV read, bytes
MAX_CSV_BYTES = 1_000_000_000
#: highest sampling rate accepted, Hz
MAX_SAMPLE_RATE_HZ = 1e6
#: jitter of a CSV time step tolerated, fraction of the step (rounding of printed times)
CSV_STEP_TOLERANCE = 0.01
#: elements per record of the PIMS sensors that are not x, y, z acceleration
_OTHER_LAYOUTS = {"ossraw": 6, "radgse": 14}
_PAD_NAME = re.compile(
    r"(?P<start>\d{4}_\d{2}_\d{2}_\d{2}_\d{2}_\d{2}\.\d{3})[-+]"
    r"(?P<stop>\d{4}_\d{2}_\d{2}_\d{2}_\d{2}_\d{2}\.\d{3})"
)
#: acceleration unit names that pint would read otherwise (g = gram, mg = milligram)
_ACCEL_ALIASES = {
    "g": "standard_gravity",
    "g0": "standard_gravity",
    "gee": "standard_gravity",
    "mg": "milli_g",
    "milli-g": "milli_g",
    "ug": "micro_g",
    "µg": "micro_g",
    "μg": "micro_g",
    "micro-g": "micro_g",
    "mps2": "m/s^2",
    "m/s2": "m/s^2",
    "m/s/s": "m/s^2",
}
_AXIS_NAMES = {
    "x": "x", "ax": "x", "a_x": "x", "accel_x": "x", "xaccel": "x",
    "y": "y", "ay": "y", "a_y": "y", "accel_y": "y", "yaccel": "y",
    "z": "z", "az": "z", "a_z": "z", "accel_z": "z", "zaccel": "z",
}  # fmt: skip
_TIME_NAMES = {"time", "t", "timepts", "time_rel", "seconds"}


@dataclass(frozen=True)
class PadHeader:
    """The fields of a PAD header microg uses (SI), and the rest as text."""

    path: str
    data_type: str
    sensor: str | None
    sample_rate_hz: float
    cutoff_hz: float | None
    time_zero: str | None
    data_format: str | None
    data_file: str | None
    fields: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class MeasuredRecord:
    """A measured acceleration record, SI, uniformly sampled.

    Attributes
    ----------
    path : the data file
    format : ``pad`` or ``csv``
    sensor : the sensor's name (PAD ``SensorID``, CSV ``# sensor:``), or None
    timepts : (n,) times, s, ``t0 + i / sample_rate_hz``
    accel : (naxes, n) acceleration, m/s^2
    sample_rate_hz : samples per second
    axes : axis names of the rows of ``accel``
    cutoff_hz : anti-alias cutoff of the data, Hz, or None
    start : start time as the file gives it (PAD ``TimeZero``), or None
    metadata : further header fields (text)
    """

    path: str
    format: str
    sensor: str | None
    timepts: np.ndarray
    accel: np.ndarray
    sample_rate_hz: float
    axes: tuple[str, ...] = ("x", "y", "z")
    cutoff_hz: float | None = None
    start: str | None = None
    metadata: dict[str, str] = field(default_factory=dict)

    @property
    def duration_s(self) -> float:
        """Record length ``n / fs``, s."""
        return self.accel.shape[1] / self.sample_rate_hz

    @property
    def key(self) -> str:
        """The key of this record in the ``observations`` contract (``sensor`` if unnamed)."""
        return self.sensor or "sensor"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description of the record (no samples)."""
        return {
            "path": self.path,
            "format": self.format,
            "sensor": self.sensor,
            "axes": list(self.axes),
            "samples": int(self.accel.shape[1]),
            "sample_rate_hz": self.sample_rate_hz,
            "duration_s": self.duration_s,
            "cutoff_hz": self.cutoff_hz,
            "start": self.start,
            "metadata": dict(self.metadata),
        }


# ------------------------------------------------------------------------------- PAD files


def _positive(text: str | None, where: str, what: str, fix: str) -> float:
    try:
        v = float(str(text).strip())
    except (TypeError, ValueError):
        raise InputError(f"{what} {text!r} is not a number", where=where, fix=fix) from None
    if not (math.isfinite(v) and v > 0):
        raise InputError(f"{what} {text!r} is not a positive finite number", where=where, fix=fix)
    return v


def read_pad_header(path: str | Path) -> PadHeader:
    """Read a PAD header (XML; see the module doc).

    Parameters
    ----------
    path : the ``.header`` file
    """
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > MAX_HEADER_BYTES:
            raise InputError(
                f"{size} bytes is too large for a PAD header (limit {MAX_HEADER_BYTES})",
                where=str(p),
            )
        text = p.read_bytes().decode("utf-8", errors="replace")
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", where=str(p)) from None
    if re.search(r"<!(DOCTYPE|ENTITY)", text, re.IGNORECASE):
        raise InputError(
            "has a DOCTYPE or ENTITY declaration", where=str(p), fix="a PAD header has none"
        )
    try:
        root = ET.fromstring(text.lstrip())
    except ET.ParseError as exc:
        line = exc.position[0] if hasattr(exc, "position") else "?"
        raise InputError(
            f"is not valid XML ({exc})", where=f"{p}: line {line}", fix="give a PAD .header file"
        ) from None

    def text_of(tag: str) -> str | None:
        el = root.find(tag)
        if el is None or el.text is None or not el.text.strip():
            return None
        return el.text.strip()

    rate_text = text_of("SampleRate")
    if rate_text is None:
        raise InputError(
            "the sampling rate is missing",
            where=f"{p}: SampleRate",
            fix="add <SampleRate>samples per second</SampleRate> to the header",
        )
    fs = _positive(rate_text, f"{p}: SampleRate", "SampleRate", "give samples per second")
    if fs > MAX_SAMPLE_RATE_HZ:
        raise InputError(
            f"SampleRate {fs:g} Hz is above {MAX_SAMPLE_RATE_HZ:g} Hz", where=f"{p}: SampleRate"
        )
    cut_text = text_of("CutoffFreq")
    cutoff = (
        None
        if cut_text is None
        else _positive(cut_text, f"{p}: CutoffFreq", "CutoffFreq", "give the cutoff in Hz")
    )
    gdata = root.find("GData")
    fmt = gdata.get("format") if gdata is not None else None
    data_file = gdata.get("file") if gdata is not None else None
    fields = {}
    for el in root:
        if el.text and el.text.strip():
            fields[el.tag] = el.text.strip()
        for k, v in el.attrib.items():
            fields[f"{el.tag}.{k}"] = v
    return PadHeader(
        path=str(p),
        data_type=root.tag,
        sensor=text_of("SensorID"),
        sample_rate_hz=fs,
        cutoff_hz=cutoff,
        time_zero=text_of("TimeZero"),
        data_format=fmt,
        data_file=data_file,
        fields=fields,
    )


def _pad_span_s(name: str) -> float | None:
    """Seconds from start to stop in a PAD file name (``START-STOP.SENSOR``), or None."""
    m = _PAD_NAME.search(name)
    if m is None:
        return None
    fmt = "%Y_%m_%d_%H_%M_%S.%f"
    try:
        t0 = datetime.strptime(m.group("start"), fmt)
        t1 = datetime.strptime(m.group("stop"), fmt)
    except ValueError:
        return None
    return (t1 - t0).total_seconds()


def read_pad(path: str | Path) -> MeasuredRecord:
    """Read a PIMS/SAMS PAD acceleration file and its header.

    Parameters
    ----------
    path : the data file (its header is ``path + ".header"``) or the ``.header`` file
    """
    p = Path(path)
    if p.name.endswith(".header"):
        hp, dp = p, p.with_name(p.name[: -len(".header")])
    else:
        dp, hp = p, p.with_name(p.name + ".header")
    if not hp.is_file():
        raise InputError(
            "no header file beside the data",
            where=str(hp),
            fix="a PAD data file needs its .header (XML with SampleRate)",
        )
    hdr = read_pad_header(hp)
    if not dp.is_file() and hdr.data_file:
        alt = hp.with_name(hdr.data_file)
        dp = alt if alt.is_file() else dp
    if not dp.is_file():
        raise InputError(
            "the data file named by the header is missing",
            where=str(dp),
            fix="put the PAD data file beside its header",
        )
    if hdr.data_format is not None:
        f = hdr.data_format.lower()
        if not ("32" in f and "float" in f and "little" in f):
            raise InputError(
                f"data format {hdr.data_format!r} is not read by microg",
                where=f"{hp}: GData.format",
                fix="microg reads 'binary 32 bit IEEE float little endian' PAD data",
            )
    if hdr.sensor and hdr.sensor.lower() in _OTHER_LAYOUTS:
        raise InputError(
            f"sensor {hdr.sensor!r} records {_OTHER_LAYOUTS[hdr.sensor.lower()]} values, not "
            "t, x, y, z acceleration",
            where=f"{hp}: SensorID",
            fix="give an acceleration PAD file (4 columns)",
        )
    size = dp.stat().st_size
    rec = 16  # 4 x float32
    if size == 0 or size % rec:
        raise InputError(
            f"{size} bytes is not a whole number of 16-byte records (t, x, y, z as 32-bit floats)",
            where=f"{dp}: length",
            fix="the file is truncated or not a PAD acceleration file; check it against its header",
        )
    n = size // rec
    if n > MAX_SAMPLES:
        raise InputError(f"{n:,} records is more than {MAX_SAMPLES:,}", where=f"{dp}: length")
    if n < 16:
        raise InputError(f"only {n} records", where=f"{dp}: length", fix="need at least 16")
    raw = np.fromfile(dp, dtype="<f4").reshape(n, 4).astype(float)
    bad = ~np.isfinite(raw)
    if np.any(bad):
        bi, bj = (int(v) for v in np.unravel_index(int(np.argmax(bad)), raw.shape))
        raise InputError(
            f"value {raw[bi, bj]} is not finite",
            where=f"{dp}: record {bi + 1}, column {'txyz'[bj]}",
            fix="remove or repair the bad records (PIMS data are finite)",
        )
    fs = hdr.sample_rate_hz
    t = raw[:, 0]
    expected = t[0] + np.arange(n) / fs
    ulp = np.spacing(np.abs(expected).astype(np.float32)).astype(float)
    off = np.abs(t - expected)
    tol = 0.25 / fs + 4 * ulp
    if np.any(off > tol):
        i = int(np.argmax(off > tol))
        raise InputError(
            f"time {t[i]:.7g} s is not on the header's {fs:g}-Hz grid (expected "
            f"{expected[i]:.7g} s): a gap, a repeated record or a wrong SampleRate",
            where=f"{dp}: record {i + 1}",
            fix="split the file at the gap, or correct SampleRate in the header",
        )
    span = (n - 1) / fs
    named = _pad_span_s(dp.name)
    if named is None and hdr.data_file:
        named = _pad_span_s(hdr.data_file)
    if named is not None and abs(named - span) > 2.0 / fs + 2e-3:
        raise InputError(
            f"{n} records span {span:.6g} s at the header's SampleRate {fs:g} Hz, but the file "
            f"name spans {named:.6g} s",
            where=f"{dp}: length",
            fix="the file is truncated or the header's SampleRate is wrong",
        )
    meta = {k: v for k, v in hdr.fields.items() if k not in ("SampleRate", "CutoffFreq")}
    meta["DataType"] = hdr.data_type
    meta["header"] = str(hp)
    return MeasuredRecord(
        path=str(dp),
        format="pad",
        sensor=hdr.sensor,
        timepts=expected,
        accel=raw[:, 1:].T * G0,
        sample_rate_hz=fs,
        axes=("x", "y", "z"),
        cutoff_hz=hdr.cutoff_hz,
        start=hdr.time_zero,
        metadata=meta,
    )


# ------------------------------------------------------------------------------------ CSV

_UNIT_IN = re.compile(r"^\s*(?P<name>[^\[\(]*?)\s*[\[\(]\s*(?P<unit>[^\]\)]*?)\s*[\]\)]\s*$")


def _split_header_cell(cell: str) -> tuple[str, str | None]:
    """``"x [m/s^2]"`` -> ("x", "m/s^2"); ``"time_s"`` -> ("time", "s"); ``"x"`` -> ("x", None)."""
    m = _UNIT_IN.match(cell)
    if m:
        return m.group("name").strip().lower(), m.group("unit").strip()
    name = cell.strip()
    low = name.lower()
    if low in _TIME_NAMES or low in _AXIS_NAMES:
        return low, None
    if "_" in name:
        base, unit = name.rsplit("_", 1)
        return base.strip().lower(), unit.strip()
    return low, None


def _accel_factor(unit: str, where: str) -> float:
    u = _ACCEL_ALIASES.get(unit.strip().lower(), unit.strip())
    u = _ACCEL_ALIASES.get(u, u)
    if u in ("micro_g", "milli_g", "standard_gravity"):
        return {"micro_g": 1e-6 * G0, "milli_g": 1e-3 * G0, "standard_gravity": G0}[u]
    return parse_quantity(f"1 {u}", "acceleration", where=where)


def _scan_bad_line(lines: list[str], start: int, ncol: int, path: str) -> InputError:
    """The first data line after ``start`` that is not ``ncol`` numbers (error path only)."""
    for i in range(start, len(lines)):
        s = lines[i].split("#", 1)[0].strip()
        if not s:
            continue
        cells = s.split(",")
        if len(cells) != ncol:
            return InputError(
                f"{len(cells)} cells where the header has {ncol}",
                where=f"{path}: line {i + 1}",
                fix="give one value per header column",
            )
        for j, c in enumerate(cells):
            try:
                float(c)
            except ValueError:
                return InputError(
                    f"cell {j + 1} {c.strip()!r} is not a number",
                    where=f"{path}: line {i + 1}",
                    fix="write plain numbers (the units belong in the header)",
                )
    return InputError("cannot read the data", where=path, fix="check the file's format")


def _data_line_number(lines: list[str], start: int, row: int) -> int:
    """1-based file line of data row ``row`` (0-based) after the header (error path only)."""
    k = -1
    for i in range(start, len(lines)):
        if lines[i].split("#", 1)[0].strip():
            k += 1
            if k == row:
                return i + 1
    return len(lines)


def read_accel_csv(path: str | Path) -> MeasuredRecord:
    """Read measured acceleration from a CSV file with units in its header (see module doc).

    Parameters
    ----------
    path : the CSV file
    """
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > MAX_CSV_BYTES:
            raise InputError(f"{size:,} bytes is more than {MAX_CSV_BYTES:,}", where=str(p))
        text = p.read_text("utf-8")
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", where=str(p)) from None
    except UnicodeDecodeError:
        raise InputError("is not UTF-8 text", where=str(p), fix="give a CSV text file") from None
    lines = text.splitlines()
    sensor: str | None = None
    cutoff: float | None = None
    h = None
    for i, ln in enumerate(lines):
        s = ln.strip()
        if not s:
            continue
        if s.startswith("#"):
            m = re.match(r"#\s*(sensor|cutoff)\s*[:=]\s*(.+?)\s*$", s, re.IGNORECASE)
            if m and m.group(1).lower() == "sensor":
                sensor = m.group(2).strip().strip("\"'") or None
            elif m:
                cutoff = parse_quantity(
                    m.group(2), "frequency", where=f"{p}: line {i + 1} (cutoff)"
                )
            continue
        h = i
        break
    if h is None:
        raise InputError("no header line", where=str(p), fix="start with 'time [s], x [g], ...'")
    cells = lines[h].split(",")
    time_col = None
    axis_cols: dict[str, tuple[int, float]] = {}
    time_factor = 1.0
    for j, cell in enumerate(cells):
        name, unit = _split_header_cell(cell)
        where = f"{p}: line {h + 1}, column {j + 1}"
        if name in _TIME_NAMES:
            if unit is None:
                raise InputError(
                    f"column {cell.strip()!r} has no unit", where=where, fix="write 'time [s]'"
                )
            time_factor = parse_quantity(f"1 {unit}", "time", where=where)
            time_col = j
        elif name in _AXIS_NAMES:
            ax = _AXIS_NAMES[name]
            if unit is None:
                raise InputError(
                    f"column {cell.strip()!r} has no unit",
                    where=where,
                    fix=f"write '{ax} [m/s^2]', '{ax} [g]' or '{ax} [ug]'",
                )
            if ax in axis_cols:
                raise InputError(f"axis {ax} given twice", where=where)
            axis_cols[ax] = (j, _accel_factor(unit, where))
        else:
            raise InputError(
                f"unknown column {cell.strip()!r}",
                where=where,
                fix="columns: time, x, y, z, each with its unit, e.g. 'time [s], x [m/s^2]'",
            )
    if time_col is None or not axis_cols:
        raise InputError(
            "the header needs a time column and at least one of x, y, z",
            where=f"{p}: line {h + 1}",
            fix="write 'time [s], x [m/s^2], y [m/s^2], z [m/s^2]'",
        )
    ncol = len(cells)
    body = "\n".join(lines[h + 1 :])
    try:
        data = np.loadtxt(io.StringIO(body), delimiter=",", comments="#", ndmin=2, dtype=float)
    except ValueError:
        raise _scan_bad_line(lines, h + 1, ncol, str(p)) from None
    if data.shape[1] != ncol:
        raise _scan_bad_line(lines, h + 1, ncol, str(p))
    n = data.shape[0]
    if n < 16:
        raise InputError(f"only {n} data rows", where=str(p), fix="need at least 16 samples")
    if n > MAX_SAMPLES:
        raise InputError(f"{n:,} rows is more than {MAX_SAMPLES:,}", where=str(p))
    bad = ~np.isfinite(data)
    if np.any(bad):
        br, bc = (int(v) for v in np.unravel_index(int(np.argmax(bad)), data.shape))
        raise InputError(
            f"cell {bc + 1} is {data[br, bc]} (not a finite number)",
            where=f"{p}: line {_data_line_number(lines, h + 1, br)}",
            fix="remove or fill the missing samples before assessing",
        )
    t = data[:, time_col] * time_factor
    steps = np.diff(t)
    typical = float(np.median(steps))  # robust: a single gap does not move it
    off = np.abs(steps - typical) > CSV_STEP_TOLERANCE * abs(typical)
    if not typical > 0 or np.any(off):
        r = int(np.argmax(off)) + 1 if np.any(off) else 1
        raise InputError(
            f"time step {steps[r - 1]:.6g} s differs from the record's step {typical:.6g} s "
            "(the time column must increase uniformly: a gap, a repeated or unsorted time)",
            where=f"{p}: line {_data_line_number(lines, h + 1, r)}",
            fix="give uniformly sampled data (resample it, or split the file at the gap)",
        )
    dt = (t[-1] - t[0]) / (n - 1)  # every step within 1 % of the typical one: their mean
    fs = 1.0 / dt
    if fs > MAX_SAMPLE_RATE_HZ:
        raise InputError(f"sampling rate {fs:g} Hz is above {MAX_SAMPLE_RATE_HZ:g}", where=str(p))
    axes = tuple(ax for ax in ("x", "y", "z") if ax in axis_cols)
    accel = np.array([data[:, axis_cols[ax][0]] * axis_cols[ax][1] for ax in axes])
    return MeasuredRecord(
        path=str(p),
        format="csv",
        sensor=sensor,
        timepts=t[0] + np.arange(n) * dt,
        accel=accel,
        sample_rate_hz=fs,
        axes=axes,
        cutoff_hz=cutoff,
        start=None,
        metadata={},
    )


def read_measured(path: str | Path) -> MeasuredRecord:
    """Read a measured record: a CSV (``.csv``) or a PAD file (data or ``.header``).

    Parameters
    ----------
    path : the file
    """
    p = Path(path)
    if not p.exists():
        raise InputError("no such file", where=str(p), fix="give the path of a measured record")
    if p.is_dir():
        raise InputError("is a directory", where=str(p), fix="give a PAD or CSV file")
    if p.suffix.lower() in (".csv", ".txt"):
        return read_accel_csv(p)
    if p.name.endswith(".header") or p.with_name(p.name + ".header").is_file():
        return read_pad(p)
    raise InputError(
        "unknown kind of file",
        where=str(p),
        fix="give a .csv with units in its header, or a PAD data file with its .header beside it",
    )
