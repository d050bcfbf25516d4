"""NASA PIMS/SAMS PAD acceleration files: the XML header and the 32-bit float records.

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

Every problem raises :class:`~microg.errors.InputError` naming the file and the line, record
or field, and the fix.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

import numpy as np

from microg.environment.assessment import MAX_SAMPLES
from microg.environment.record import MAX_SAMPLE_RATE_HZ, MeasuredRecord
from microg.errors import InputError
from microg.units import G0

__all__ = ["MAX_HEADER_BYTES", "PadHeader", "read_pad", "read_pad_header"]

#: largest PAD header read, bytes
MAX_HEADER_BYTES = 1_000_000
#: elements per record of the PIMS sensors that are not x, y, z acceleration
_OTHER_LAYOUTS = {"ossraw": 6, "radgse": 14}
_PAD_NAME = re.compile(
    r"(?P<start>\d{4}_\d{2}_\d{2}_\d{2}_\d{2}_\d{2}\.\d{3})[-+]"
    r"(?P<stop>\d{4}_\d{2}_\d{2}_\d{2}_\d{2}_\d{2}\.\d{3})"
)


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
        name = hdr.data_file.strip()
        if not name or name in (".", "..") or "/" in name or "\\" in name or "\0" in name:
            # the data is read beside its header only: a path in the header is not followed
            raise InputError(
                "the header's GData file names a path, not a file beside the header",
                where=f"{hp}: GData.file",
                fix=f"put the data file beside its header as {dp.name}",
            )
        alt = hp.with_name(name)
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
