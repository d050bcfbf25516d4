"""Measured acceleration in CSV, with the unit of every column in the header.

CSV: one header line with a unit per column, ``time [s], x [m/s^2], y [m/s^2], z [m/s^2]``
(any time unit; accelerations in ``m/s^2``, ``g``, ``mg``, ``ug``, ``ft/s^2`` ...), units in
brackets, parentheses or after an underscore (``time_s``); ``#`` comments, of which
``# sensor: NAME`` names the sensor and ``# cutoff: 6 Hz`` gives the anti-alias cutoff.

Every problem raises :class:`~microg.errors.InputError` naming the file and the line, record
or field, and the fix.
"""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np

from microg.environment.assessment import MAX_SAMPLES
from microg.environment.record import (
    MAX_SAMPLE_RATE_HZ,
    MeasuredRecord,
    accel_factor,
    nonuniform_step,
)
from microg.errors import InputError
from microg.units import parse_quantity

__all__ = ["MAX_CSV_BYTES", "read_accel_csv"]

#: largest CSV read, bytes
MAX_CSV_BYTES = 1_000_000_000
_AXIS_NAMES = {
    "x": "x", "ax": "x", "a_x": "x", "accel_x": "x", "xaccel": "x",
    "y": "y", "ay": "y", "a_y": "y", "accel_y": "y", "yaccel": "y",
    "z": "z", "az": "z", "a_z": "z", "accel_z": "z", "zaccel": "z",
}  # fmt: skip
_TIME_NAMES = {"time", "t", "timepts", "time_rel", "seconds"}
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
            axis_cols[ax] = (j, accel_factor(unit, where))
        else:
            raise InputError(  # never quoted: a file named by mistake must not leak
                "not a known column",
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
    bad_step = nonuniform_step(t)
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
