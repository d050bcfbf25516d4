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

UFF 58 (``.unv``/``.uff``, the Universal File Format's "function at nodal DOF", as written by
microg's :func:`~microg.models.uff.write_uff_time`, pyuff and test-data systems): one dataset
per node and direction.  Datasets are grouped by the response entity and node of record 6;
each group must hold the three translations (directions +-1, +-2, +-3; a negative direction
flips the sign) of one uniformly sampled acceleration time history:

* record 6: function type 1 (time response) or 0 (general);
* record 7: real data (ordinate type 2 or 4), even spacing (``t = min + i * increment``) or
  uneven ``x, y`` pairs whose abscissa is uniform to :data:`CSV_STEP_TOLERANCE` of the step;
* record 8: the abscissa is time (specific data type 17, or 0/1 in a time response), s;
* record 9: the ordinate is acceleration (specific data type 12, or 0/1 with an acceleration
  units label).  Units: the record's units label (``m/s^2``, ``g``, ``in/s^2``...) when it
  names an acceleration unit, else dataset 164's length factor (SI = file / factor; the
  acceleration's length exponent is 1); a label that contradicts dataset 164 is refused,
  and a file with neither has no units;
* the sensor name: ID line 1 when the group's records share it (microg writes the point
  name there), else ``ENTITY:NODE`` (``node:NODE`` without an entity name).  ID line 3 (the
  creation date) is the record's ``start``.

Binary UFF (58b) is not read.

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
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.environment.metrics import MAX_SAMPLES
from microg.errors import InputError
from microg.units import G0, parse_quantity

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "MAX_HEADER_BYTES",
    "MAX_CSV_BYTES",
    "MeasuredRecord",
    "PadHeader",
    "read_pad_header",
    "read_pad",
    "read_accel_csv",
    "read_measured",
    "read_measured_all",
    "read_uff58",
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

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready header (SI values; the other fields as text)."""
        return {
            "path": self.path,
            "data_type": self.data_type,
            "sensor": self.sensor,
            "sample_rate_hz": self.sample_rate_hz,
            "cutoff_hz": self.cutoff_hz,
            "time_zero": self.time_zero,
            "data_format": self.data_format,
            "data_file": self.data_file,
            "fields": dict(self.fields),
        }


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
    start : start time as the file gives it (PAD ``TimeZero``, UFF ID line 3), or None
    metadata : further header fields (text)
    warnings : what a reader of the verdict must know about the file's data
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
    warnings: tuple[str, ...] = ()

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
            "warnings": list(self.warnings),
        }

    def to_xarray(self) -> Any:
        """The samples as an ``xarray.DataArray`` ``accel_mps2``, the header in the attributes.

        Dims ``axis``, ``time``; m/s^2, times in s.
        """
        import xarray as xr

        return xr.DataArray(
            self.accel,
            dims=("axis", "time"),
            coords={"axis": list(self.axes), "time": ("time", self.timepts, {"units": "s"})},
            name="accel_mps2",
            attrs={
                "units": "m/s^2",
                "long_name": "measured acceleration",
                "sensor": self.sensor or "",
                "path": self.path,
                "format": self.format,
                "sample_rate_hz": self.sample_rate_hz,
                **({} if self.cutoff_hz is None else {"cutoff_hz": self.cutoff_hz}),
                **({} if self.start is None else {"start": self.start}),
            },
        )

    def plot(self, *, title: str = "", ax: Any = None) -> Figure:
        """The record against time, micro-g (``plotting.environment.plot_time_history``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_time_history

        return plot_time_history(
            self.timepts,
            self.accel,
            axes=self.axes,
            title=title or f"Acceleration at {self.key}",
            ax=ax,
        )


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


def _nonuniform_step(t: np.ndarray) -> tuple[int, float, float] | None:
    """``(i, step, typical)`` of the first time step off the typical one, else None.

    Off: by more than :data:`CSV_STEP_TOLERANCE`; ``i`` is the 0-based index of the sample
    after it.
    """
    steps = np.diff(t)
    typical = float(np.median(steps))  # robust: a single gap does not move it
    off = np.abs(steps - typical) > CSV_STEP_TOLERANCE * abs(typical)
    if typical > 0 and not np.any(off):
        return None
    r = int(np.argmax(off)) + 1 if np.any(off) else 1
    return r, float(steps[r - 1]), typical


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
    bad_step = _nonuniform_step(t)
    if bad_step is not None:
        r, step, typical = bad_step
        raise InputError(
            f"time step {step:.6g} s differs from the record's step {typical:.6g} s "
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


def read_measured_all(path: str | Path) -> tuple[MeasuredRecord, ...]:
    """Every record of a measured file: the sensors of a UFF 58 file, else the one record.

    Parameters
    ----------
    path : the file (``.csv``/``.txt``, ``.unv``/``.uff``, a PAD data file or its ``.header``)
    """
    p = Path(path)
    if not p.exists():
        raise InputError("no such file", where=str(p), fix="give the path of a measured record")
    if p.is_dir():
        raise InputError("is a directory", where=str(p), fix="give a PAD, CSV or UFF file")
    if p.suffix.lower() in (".csv", ".txt"):
        return (read_accel_csv(p),)
    if p.suffix.lower() in UFF_SUFFIXES:
        return read_uff58(p)
    if p.name.endswith(".header") or p.with_name(p.name + ".header").is_file():
        return (read_pad(p),)
    raise InputError(
        "unknown kind of file",
        where=str(p),
        fix="give a .csv with units in its header, a UFF .unv with datasets 58, or a PAD data "
        "file with its .header beside it",
    )


def read_measured(path: str | Path, sensor: str | None = None) -> MeasuredRecord:
    """Read a measured record: a CSV, a UFF 58 sensor, or a PAD file (data or ``.header``).

    Parameters
    ----------
    path : the file
    sensor : the record's sensor name, to pick one of a UFF file's sensors (needed when the
        file holds several)
    """
    records = read_measured_all(path)
    if sensor is not None:
        for r in records:
            if r.key == sensor:
                return r
        raise InputError(
            f"no sensor {sensor!r}",
            where=f"{path}: sensor",
            fix=f"sensors in the file: {', '.join(r.key for r in records)}",
        )
    if len(records) > 1:
        raise InputError(
            f"holds {len(records)} sensors",
            where=f"{path}: sensor",
            fix=f"name one of {', '.join(r.key for r in records)} (or read them all with "
            "read_measured_all)",
        )
    return records[0]


# --------------------------------------------------------------------------------- UFF 58

#: suffixes of UFF files
UFF_SUFFIXES = (".unv", ".uff")
#: UFF specific data types (record 8-11, field 1) named in messages
_UFF_TYPES = {
    0: "unknown", 1: "general", 2: "stress", 3: "strain", 5: "temperature", 6: "heat flux",
    8: "displacement", 9: "reaction force", 11: "velocity", 12: "acceleration",
    13: "excitation force", 15: "pressure", 16: "mass", 17: "time", 18: "frequency", 19: "rpm",
    20: "order",
}  # fmt: skip
_UFF_FUNCTIONS = {
    0: "general", 1: "time response", 2: "auto spectrum", 3: "cross spectrum",
    4: "frequency response function", 5: "transmissibility", 6: "coherence",
    9: "power spectral density", 12: "spectrum",
}  # fmt: skip


def _none(text: str) -> bool:
    t = text.strip()
    return not t or t.upper() == "NONE"


@dataclass(frozen=True)
class _Uff58:
    """One dataset 58 as read (SI), before grouping by node."""

    index: int
    where: str
    id1: str
    id3: str
    entity: str
    node: int
    direction: int
    t0: float
    dt: float
    values: np.ndarray
    unit: str
    note: str | None = None


def _uff_ints(text: str, widths: tuple[int, ...], where: str, what: str) -> list[int]:
    """Fixed-width integer fields (``I10`` ...), or whitespace-separated as a fallback."""
    out, pos = [], 0
    try:
        for w in widths:
            out.append(int(text[pos : pos + w]))
            pos += w
        return out
    except ValueError:
        pass
    try:
        vals = [int(v) for v in text.split()[: len(widths)]]
    except ValueError:
        vals = []
    if len(vals) != len(widths):
        raise InputError(f"{what} is not {len(widths)} integers: {text.strip()!r}", where=where)
    return vals


def _uff_characteristics(line: str, where: str, what: str) -> tuple[list[int], str, str]:
    """Records 8-11: (type, length/force/temperature exponents), axis label, units label."""
    nums = _uff_ints(line[:25], (10, 5, 5, 5), where, what)
    return nums, line[26:46].strip(), line[47:67].strip()


def _uff_record(ds: Any, k: int, path: str, length_factor: float | None) -> _Uff58:
    """Dataset 58 number ``k`` (1-based) of ``path``, validated (see the module doc)."""
    from microg.models.uff import data_values

    where = f"{path}: dataset 58 #{k} (line {ds.start_line})"
    ln = ds.lines
    if len(ln) < 11:
        raise InputError("the header (records 1-11) is cut", where=where)
    r6 = ln[5]
    func, _fid, _ver, _lc = _uff_ints(r6[:30], (5, 10, 5, 10), where, "record 6")
    entity = r6[31:41].strip()
    node_dir = _uff_ints(r6[41:55], (10, 4), where, "record 6 (response node, direction)")
    node, direction = node_dir
    r7 = ln[6].split()
    try:
        ord_type, n, even = int(r7[0]), int(r7[1]), int(r7[2])
        xmin, dx = float(r7[3].replace("D", "E")), float(r7[4].replace("D", "E"))
    except (IndexError, ValueError):
        raise InputError(f"record 7 is not read: {ln[6].strip()!r}", where=where) from None
    ab, _ab_label, ab_unit = _uff_characteristics(ln[7], where, "record 8")
    od, od_label, od_unit = _uff_characteristics(ln[8], where, "record 9")
    if func not in (0, 1):
        name = _UFF_FUNCTIONS.get(func, f"type {func}")
        raise InputError(
            f"function type {func} ({name}) is not a time history",
            where=where,
            fix="give time responses (record 6 function type 1)",
        )
    if not (ab[0] == 17 or (ab[0] in (0, 1) and func == 1)):
        raise InputError(
            f"the abscissa is {_UFF_TYPES.get(ab[0], f'type {ab[0]}')}, not time",
            where=where,
            fix="give time histories (record 8 specific data type 17)",
        )
    if not _none(ab_unit):
        try:
            t_factor = parse_quantity(f"1 {ab_unit}", "time", where=where)
        except InputError:
            t_factor = 1.0
        if abs(t_factor - 1.0) > 1e-12:
            raise InputError(
                f"the abscissa units label is {ab_unit!r}: UFF time is in seconds",
                where=where,
                fix="write the abscissa in s",
            )
    if ord_type not in (2, 4):
        kind = "complex" if ord_type in (5, 6) else f"type {ord_type}"
        raise InputError(
            f"ordinate data are {kind}: not an acceleration time history",
            where=where,
            fix="give real data (record 7 ordinate data type 2 or 4)",
        )
    label_factor = None
    if not _none(od_unit):
        try:
            label_factor = _accel_factor(od_unit, where)
        except InputError:
            label_factor = None
    if not (od[0] == 12 or (od[0] in (0, 1) and label_factor is not None)):
        raise InputError(
            f"the ordinate is {_UFF_TYPES.get(od[0], f'type {od[0]}')}"
            + (f" ({od_label})" if not _none(od_label) else "")
            + ", not acceleration",
            where=where,
            fix="give acceleration records (record 9 specific data type 12)",
        )
    if direction not in (1, 2, 3, -1, -2, -3):
        what = "a rotation" if abs(direction) in (4, 5, 6) else "a scalar or unknown direction"
        raise InputError(
            f"response direction {direction} is {what}, not a translation x, y or z",
            where=where,
            fix="give translational accelerations (record 6 direction 1, 2, 3 or -1, -2, -3)",
        )
    file_factor = None
    if length_factor is not None:
        lexp = od[1] if od[0] == 1 else 1  # acceleration: length^1 (UFF Addendum A)
        file_factor = (1.0 / length_factor) ** lexp
    if (
        label_factor is not None
        and file_factor is not None
        and abs(label_factor - file_factor) > 1e-6 * file_factor
    ):
        raise InputError(
            f"the units label {od_unit!r} ({label_factor:.6g} m/s^2) contradicts dataset "
            f"164 (file unit {file_factor:.6g} m/s^2)",
            where=where,
            fix="correct the record's units label or the file's dataset 164",
        )
    factor = label_factor if label_factor is not None else file_factor
    if factor is None:
        raise InputError(
            "no units: no dataset 164 and no acceleration units label in record 9",
            where=where,
            fix="add a dataset 164 or label the ordinate's units (e.g. 'm/s^2', 'g')",
        )
    if n < 16:
        raise InputError(f"only {n} samples", where=where, fix="need at least 16")
    if n > MAX_SAMPLES:
        raise InputError(f"{n:,} samples is more than {MAX_SAMPLES:,}", where=where)
    body = ln[11:]
    vals = data_values(body, where, width=13 if ord_type == 2 else 20)
    want = n if even == 1 else 2 * n
    if vals.size != want:
        raise InputError(
            f"{vals.size} data values where record 7 gives {n}"
            + ("" if even == 1 else " (x, y) pairs"),
            where=where,
            fix="the dataset is truncated or its record 7 is wrong",
        )
    note = None
    if even == 1:
        if not (np.isfinite(dx) and dx > 0 and np.isfinite(xmin)):
            raise InputError(f"abscissa increment {dx:g} s is not > 0", where=where)
        t0, y = xmin, vals
    else:
        x, y = vals[0::2], vals[1::2]
        bad = _nonuniform_step(x) if np.all(np.isfinite(x)) else (1, float("nan"), float("nan"))
        if bad is not None:
            i, step, typical = bad
            raise InputError(
                f"non-uniform abscissa: step {step:.6g} s before sample {i + 1} differs from "
                f"the record's step {typical:.6g} s",
                where=where,
                fix="give uniformly sampled data (resample it, or split the record at the gap)",
            )
        t0, dx = float(x[0]), float((x[-1] - x[0]) / (n - 1))
        note = (
            f"dataset 58 #{k}: uneven abscissa within {CSV_STEP_TOLERANCE:.0%} of a uniform "
            f"step, taken as t0 + i * {dx:.6g} s"
        )
    if not np.all(np.isfinite(y)):
        i = int(np.argmax(~np.isfinite(y)))
        raise InputError(f"sample {i + 1} is {y[i]} (not finite)", where=where)
    if 1.0 / dx > MAX_SAMPLE_RATE_HZ:
        raise InputError(
            f"sampling rate {1 / dx:g} Hz is above {MAX_SAMPLE_RATE_HZ:g}", where=where
        )
    unit = od_unit if label_factor is not None else "dataset 164"
    return _Uff58(
        k, where, ln[0].strip(), ln[2].strip(), entity, node, direction, t0, dx,
        np.sign(direction) * y * factor, unit, note,
    )  # fmt: skip


def _uff_name(group: list[_Uff58]) -> str:
    ids = {r.id1 for r in group}
    if len(ids) == 1 and not _none(next(iter(ids))):
        return next(iter(ids))
    head = group[0]
    return f"{head.entity}:{head.node}" if not _none(head.entity) else f"node:{head.node}"


def read_uff58(path: str | Path) -> tuple[MeasuredRecord, ...]:
    """Read the acceleration time histories of a UFF file (datasets 58, 164), one per sensor.

    See the module docstring for the grouping, units and checks.

    Parameters
    ----------
    path : the ``.unv``/``.uff`` file

    Returns
    -------
    tuple of MeasuredRecord
        In the order of each sensor's first dataset; ``accel`` rows x, y, z in m/s^2.
    """
    from microg.models.uff import dataset_units, read_uff

    p = Path(path)
    label = str(p)
    sets = read_uff(p)
    u164 = [d for d in sets if d.number == 164]
    length_factor = None
    if u164:  # SI length = file length / factor
        length_factor = 1.0 / dataset_units(u164[0], f"{label}: dataset 164").length_m
    found = [d for d in sets if d.number == 58]
    if not found:
        have = ", ".join(sorted({str(d.number) for d in sets})) or "none"
        raise InputError(
            f"no time histories (dataset 58; datasets present: {have})",
            where=label,
            fix="give a UFF file of acceleration time histories (dataset 58)",
        )
    recs = [_uff_record(d, k + 1, label, length_factor) for k, d in enumerate(found)]
    groups: dict[tuple[str, int], list[_Uff58]] = {}
    for r in recs:
        groups.setdefault((r.entity, r.node), []).append(r)
    names = {key: _uff_name(g) for key, g in groups.items()}
    clash = {n for n in names.values() if list(names.values()).count(n) > 1}
    for key, g in groups.items():
        if names[key] in clash:  # two nodes with one ID line 1: name them by node
            names[key] = (
                f"{g[0].entity}:{g[0].node}" if not _none(g[0].entity) else f"node:{g[0].node}"
            )
    out = []
    for key, g in groups.items():
        name = names[key]
        by_axis: dict[int, _Uff58] = {}
        for r in g:
            ax = abs(r.direction)
            if ax in by_axis:
                raise InputError(
                    f"sensor {name!r} has axis {'xyz'[ax - 1]} twice (datasets 58 "
                    f"#{by_axis[ax].index} and #{r.index})",
                    where=r.where,
                    fix="give one record per node and direction",
                )
            by_axis[ax] = r
        missing = [a for a in "xyz" if "xyz".index(a) + 1 not in by_axis]
        if missing:
            raise InputError(
                f"sensor {name!r} (node {g[0].node}, datasets 58 "
                f"{', '.join(f'#{r.index}' for r in g)}) has no {', '.join(missing)} axis",
                where=g[0].where,
                fix="give the three translations x, y, z of each sensor",
            )
        x, y, z = by_axis[1], by_axis[2], by_axis[3]
        for r in (y, z):
            same = r.values.size == x.values.size and abs(r.dt - x.dt) <= 1e-5 * x.dt
            if not same or abs(r.t0 - x.t0) > 0.5 * x.dt:
                raise InputError(
                    f"sensor {name!r}: axis {'xyz'[abs(r.direction) - 1]} is sampled otherwise "
                    f"({r.values.size} samples from {r.t0:g} s every {r.dt:g} s) than x "
                    f"({x.values.size} from {x.t0:g} s every {x.dt:g} s)",
                    where=r.where,
                    fix="give the three axes of a sensor on one time base",
                )
        nt = x.values.size
        warnings = tuple(r.note for r in (x, y, z) if r.note)
        units = sorted({r.unit for r in (x, y, z)})
        out.append(
            MeasuredRecord(
                path=label,
                format="uff58",
                sensor=name,
                timepts=x.t0 + np.arange(nt) * x.dt,
                accel=np.vstack([x.values, y.values, z.values]),
                sample_rate_hz=1.0 / x.dt,
                axes=("x", "y", "z"),
                cutoff_hz=None,
                start=None if _none(x.id3) else x.id3,
                metadata={
                    "node": str(x.node),
                    "entity": x.entity,
                    "datasets_58": ", ".join(f"#{r.index}" for r in (x, y, z)),
                    "units": ", ".join(units),
                },
                warnings=warnings,
            )
        )
    return tuple(out)
