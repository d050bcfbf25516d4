"""Force histories: the report's crew push-off, piecewise-linear breakpoints, CSV files, a library.

A :class:`ForceHistory` is a piecewise-linear function of time given by breakpoints.  Conventions
(shared with :func:`microg.dynamics.response.modal_pwl_response`):

* the force is zero before the first breakpoint;
* a repeated breakpoint time is a jump: the first value at that time is the limit from the left,
  the last value holds from that time on (right-continuous);
* after the last breakpoint the force holds its last value.

A history is either a scalar force along a direction (its own, or the one it is applied in),
or a vector force whose three components are given at each breakpoint (``vector``, a direction
that varies in time).  :meth:`ForceHistory.components` gives both as a (3, nb) array in N.

Everything inside is SI (s, N).  Units are parsed here, at the boundary, with
:mod:`microg.units`; magnitudes are bounded by :data:`microg.units.LIMITS`.
"""

from __future__ import annotations

import contextlib
import csv
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from microg import defaults
from microg._vectors import parse_direction
from microg.dynamics.crew import CrewPushoff
from microg.errors import InputError
from microg.units import LIMITS, parse_quantity, parse_unit

__all__ = [
    "ForceHistory",
    "Activity",
    "REPORT_F0_N",
    "MAX_CSV_BYTES",
    "MAX_CSV_LINE",
    "crew_pushoff",
    "piecewise_linear",
    "from_csv",
    "activity_library",
    "parse_force_spec",
    "crew_force",
    "known_force_specs",
]

#: the report's push-off magnitude, 25 lbf in newtons (1 lbf = 4.4482216152605 N exactly)
REPORT_F0_N = defaults.CREW_F0_N
#: largest force file read, bytes (a million rows of three forces is about 40 MB)
MAX_CSV_BYTES = 256 * 2**20
#: longest line of a force file, characters
MAX_CSV_LINE = 4096
#: longest force spec on the command line, characters
MAX_SPEC = 4096


def _readonly(a: np.ndarray, where: str) -> np.ndarray:
    """A read-only float copy of an array of numbers (InputError naming ``where`` otherwise)."""
    if isinstance(a, str | bytes) or a is None:
        raise InputError(f"must be an array of numbers, got {type(a).__name__}", where=where)
    try:
        out = np.array(a, dtype=float)
    except (TypeError, ValueError):
        raise InputError("must be an array of numbers", where=where) from None
    out.setflags(write=False)
    return out


def _first(mask: np.ndarray) -> int:
    return int(np.flatnonzero(mask)[0])


def _check_magnitudes(t: np.ndarray, f: np.ndarray, where: str) -> None:
    """Finite, and within the physical limits on times and forces (s, N)."""
    if not np.all(np.isfinite(t)):
        raise InputError(f"time[{_first(~np.isfinite(t))}] is not a finite number", where=where)
    if not np.all(np.isfinite(f)):
        bad = ~np.isfinite(f).reshape(-1, t.size).all(axis=0)
        raise InputError(f"force[{_first(bad)}] is not a finite number", where=where)
    if np.any(np.abs(t) > LIMITS["time"]):
        i = _first(np.abs(t) > LIMITS["time"])
        raise InputError(
            f"time[{i}] = {t[i]:.6g} s is beyond the limit of {LIMITS['time']:g} s", where=where
        )
    big = (np.abs(f) > LIMITS["force"]).reshape(-1, t.size).any(axis=0)
    if np.any(big):
        raise InputError(
            f"force[{_first(big)}] is beyond the limit of {LIMITS['force']:g} N", where=where
        )


@dataclass(frozen=True, eq=False)
class ForceHistory:
    """A piecewise-linear force history f(t), scalar along a direction or a 3-D vector.

    Attributes
    ----------
    timepts : (nb,) breakpoint times, s, non-decreasing; a repeated time is a jump
    force : (nb,) force at each breakpoint, N: the signed force along the direction, or, for a
        vector history, the magnitude of the force vector at each breakpoint
    name : label for output
    direction : optional (3,) unit vector of a scalar force in the model frame (its own
        direction, which wins over the direction it is applied in)
    vector : optional (3, nb) force vector at each breakpoint, N, model frame (a direction
        that varies in time); give ``force=None`` with it
    params : optional parameters that generated it, named with their units (``f0_N``,
        ``t1_s``, ...; the provenance in reports), or None

    Limits: times within +/- ``LIMITS["time"]`` (1e7 s), each force component within
    +/- ``LIMITS["force"]`` (1e7 N), all finite.
    """

    timepts: np.ndarray
    force: np.ndarray | None
    name: str = "force"
    direction: np.ndarray | None = field(default=None)
    vector: np.ndarray | None = field(default=None)
    params: dict[str, float] | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        where = f"force {self.name!r}"
        t = _readonly(self.timepts, f"{where}: timepts")
        if t.ndim != 1 or t.size < 1:
            raise InputError("timepts must be a 1-D array of length >= 1", where=where)
        if self.vector is not None:
            if self.force is not None or self.direction is not None:
                raise InputError("give either force (and direction) or vector", where=where)
            v = _readonly(self.vector, f"{where}: vector")
            if v.shape != (3, t.size):
                raise InputError(f"vector must have shape (3, {t.size})", where=where)
            _check_magnitudes(t, v, where)
            object.__setattr__(self, "vector", v)
            object.__setattr__(self, "force", _readonly(np.sqrt(np.sum(v * v, axis=0)), where))
        else:
            if self.force is None:
                raise InputError("give force (N) or vector (3, nb)", where=where)
            f = _readonly(self.force, f"{where}: force")
            if f.shape != t.shape:
                raise InputError(
                    "timepts and force must be 1-D arrays of equal length >= 1", where=where
                )
            _check_magnitudes(t, f, where)
            object.__setattr__(self, "force", f)
        if np.any(np.diff(t) < 0):
            i = _first(np.diff(t) < 0) + 1
            raise InputError(
                f"breakpoint times must not decrease (time[{i}] = {t[i]} < {t[i - 1]})",
                where=where,
            )
        object.__setattr__(self, "timepts", t)
        if self.direction is not None:
            d = parse_direction(np.asarray(self.direction, dtype=float), f"{where}: direction")
            object.__setattr__(self, "direction", _readonly(d, f"{where}: direction"))

    @property
    def values(self) -> np.ndarray:
        """The force at each breakpoint, (nb,), N: ``force``, never None after construction."""
        assert self.force is not None  # __post_init__ sets it (the magnitude for a vector)
        return self.force

    @property
    def is_vector(self) -> bool:
        """True when the direction varies in time (the history carries ``vector``)."""
        return self.vector is not None

    @property
    def duration(self) -> float:
        """Time from the first to the last breakpoint, s."""
        return float(self.timepts[-1] - self.timepts[0])

    @cached_property
    def breakpoints(self) -> tuple[np.ndarray, np.ndarray]:
        """Breakpoint times (s) and values (N; (3, k) for a vector history) that shape f(t).

        A breakpoint whose value equals both neighbours' lies inside a constant piece; leaving
        it out changes f(t) nowhere.  The response kernels read these, so their cost grows with
        the pieces of the force, not with rows that repeat a value (a long record of zeros).
        """
        raw = self.vector if self.vector is not None else self.values
        v = np.atleast_2d(raw)
        keep = np.ones(self.timepts.size, bool)
        if keep.size > 2:
            same = np.all(v[:, 1:] == v[:, :-1], axis=0)
            keep[1:-1] = ~(same[:-1] & same[1:])
        if keep.all():
            return self.timepts, raw
        t, vals = self.timepts[keep], raw[..., keep]
        t.setflags(write=False)
        vals.setflags(write=False)
        return t, vals

    def components(self, direction: np.ndarray | None = None) -> np.ndarray:
        """The force vector at each breakpoint, (3, nb), N, model frame.

        A vector history returns its ``vector``; a scalar history ``direction x force``, with
        its own direction if it has one (it wins), else ``direction``.  Between breakpoints
        each component is linear, so this is what a response computes from, component by
        component.

        Parameters
        ----------
        direction : (3,) direction of a scalar force without its own (dimensionless)
        """
        if self.vector is not None:
            return self.vector
        d = self.direction
        if d is None:
            if direction is None:
                raise InputError(
                    "the force has no direction of its own; give one", where="direction"
                )
            d = parse_direction(np.asarray(direction, dtype=float), "direction")
        assert self.force is not None
        out = np.outer(d, self.force)
        out.setflags(write=False)
        return out

    def at(self, t: np.ndarray | float) -> np.ndarray:
        """Force at times ``t`` (s), N: linear between breakpoints, right-continuous at jumps.

        Zero before the first breakpoint; the last value after the last breakpoint.  For a
        vector history: (3, ...) components.
        """
        t = np.asarray(t, dtype=float)
        raw = self.vector if self.vector is not None else self.force
        assert raw is not None
        values = np.atleast_2d(raw)  # (k, nb): k = 3 components or 1
        k = values.shape[0]
        tp = self.timepts
        i = np.searchsorted(tp, t, side="right") - 1
        last = tp.size - 1
        hold = values[:, -1].reshape(k, *([1] * t.ndim))
        if last == 0:
            value = np.broadcast_to(hold, (k, *t.shape))
        else:
            i_c = np.clip(i, 0, last - 1)
            t0, t1 = tp[i_c], tp[i_c + 1]
            with np.errstate(divide="ignore", invalid="ignore"):
                frac = np.where(t1 > t0, (t - t0) / (t1 - t0), 1.0)
            value = values[:, i_c] + (values[:, i_c + 1] - values[:, i_c]) * frac
            value = np.where(i >= last, hold, value)
        value = np.where(i < 0, 0.0, value)
        return value if self.vector is not None else value[0]

    def impulse(self) -> float:
        """Integral of the force from the first to the last breakpoint, N*s (trapezoids, exact).

        Signed along the direction for a scalar force; the magnitude of the impulse vector for
        a vector history.  A force that does not end at zero keeps acting after the last
        breakpoint; that part is not included.
        """
        dt = np.diff(self.timepts)
        if self.vector is not None:
            v = self.vector
            return float(np.linalg.norm(np.sum(0.5 * (v[:, 1:] + v[:, :-1]) * dt, axis=1)))
        assert self.force is not None
        return float(np.sum(0.5 * (self.force[1:] + self.force[:-1]) * dt))

    def with_direction(self, direction: np.ndarray) -> ForceHistory:
        """A copy of a scalar history applied along ``direction`` (normalised)."""
        if self.vector is not None:
            raise InputError("a vector force has its own direction at every time", where=self.name)
        return ForceHistory(self.timepts, self.force, self.name, np.asarray(direction, float))

    @classmethod
    def from_breakpoints(
        cls,
        timepts: np.ndarray,
        force: np.ndarray,
        name: str = "force",
        direction: np.ndarray | None = None,
    ) -> ForceHistory:
        """Validated constructor from breakpoint times (s) and forces (N); see the class doc."""
        return cls(np.asarray(timepts, float), np.asarray(force, float), name, direction)

    @classmethod
    def from_vectors(
        cls, timepts: np.ndarray, vector: np.ndarray, name: str = "force"
    ) -> ForceHistory:
        """A history from breakpoint times (s) and force vectors (3, nb), N.

        When every non-zero vector is parallel to one direction the result is the scalar form
        (signed force along that direction), which is exact and cheaper downstream.
        """
        t = np.asarray(timepts, float)
        v = np.asarray(vector, float)
        scalar = _as_scalar(v)
        if scalar is not None:
            d, f = scalar
            return cls(t, f, name, d)
        return cls(t, None, name, vector=v)


def _as_scalar(v: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(direction, signed force) when the columns of ``v`` (3, nb) are all parallel, else None."""
    if v.ndim != 2 or v.shape[0] != 3 or not np.all(np.isfinite(v)):
        return None
    mags = np.sqrt(np.sum(v * v, axis=0))
    if not np.any(mags > 0):
        return None
    k = int(np.argmax(mags))
    d = v[:, k] / mags[k]
    f = d @ v
    if np.max(np.abs(v - np.outer(d, f))) > 1e-12 * mags[k]:
        return None
    return d, f


def crew_pushoff(
    f0: float = REPORT_F0_N,
    t1: float = defaults.CREW_T1_S,
    t13: float = defaults.CREW_T13_S,
    t14: float = defaults.CREW_T14_S,
    *,
    name: str = "crew-pushoff",
) -> ForceHistory:
    """The report's crew push-off and landing force (Eq. 2.16) as a force history.

    A ramp from 0 to ``f0`` over (0, t1], then zero until ``t13``; at ``t13`` the force jumps to
    ``-f0`` and ramps back to zero at ``t14``; zero afterwards.  With the report's values
    (t14 - t13 = t1) this is Eq. 2.16 exactly (slope f0/t1 on both ramps) and the net impulse is
    zero.  When ``t14 - t13 != t1`` the landing still peaks at ``-f0`` (as the project reading of
    Eq. 2.16 states) and the net impulse is ``f0 (t1 - (t14 - t13)) / 2``.

    Validation is :class:`~microg.dynamics.crew.CrewPushoff`'s (the one crew-force type).

    Parameters
    ----------
    f0 : peak push-off force, N (report: 25 lbf = 111.2 N); > 0, the direction carries the sign
    t1 : end of the push-off ramp, s (report: 1 s)
    t13 : start of the landing, s (report: 13 s)
    t14 : end of the landing, s (report: 14 s); requires 0 < t1 <= t13 < t14
    name : label
    """
    t, f = CrewPushoff(f0, t1, t13, t14).breakpoints()  # Eq. 2.16, one implementation
    return ForceHistory(t, f, name)


def piecewise_linear(
    times: np.ndarray,
    values: np.ndarray,
    *,
    name: str = "piecewise-linear",
    direction: np.ndarray | None = None,
) -> ForceHistory:
    """A force history from breakpoints ``times`` (s, a repeat is a jump), ``values`` (N)."""
    return ForceHistory.from_breakpoints(times, values, name, direction)


# ---------------------------------------------------------------------------------------- CSV

#: header names of the columns (lower case) -> column key
_COLUMN_NAMES = {
    "time": "time",
    "t": "time",
    "force": "force",
    "f": "force",
    "fx": "fx",
    "fy": "fy",
    "fz": "fz",
    "direction": "direction",
    "dir": "direction",
}
_COLUMNS_FIX = (
    "columns are time and force (and optionally direction), or time, fx, fy, fz; units in "
    "brackets or after an underscore, e.g. 'time [s], force [N]' or 'time_s,force_N'"
)
_HEADER_CELL = re.compile(
    r"^(?P<key>[A-Za-z]+)\s*(?:\[(?P<u1>[^\]]*)\]|\((?P<u2>[^)]*)\)|_(?P<u3>\S.*))?$"
)
_BLANK_LINE = re.compile(r"(?:^|\n)[ \t\r]*(?:\n|$)")
_NUMBER_CHARS = str.maketrans("", "", "0123456789eE+-. \t")
_NUMBER_CHARS_AND_SEPARATORS = str.maketrans("", "", "0123456789eE+-. \t,\n")
_STRICT_NUMBER = re.compile(
    r"^[ \t]*[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?[ \t]*$"
)


def _decode(data: bytes, where: str) -> str:
    """UTF-8 text of a force file (a BOM is dropped); any other content is a one-line error.

    The message names the problem and a byte offset, never the content (a file given by
    mistake may hold secrets, e.g. /proc/self/environ).
    """
    for bom, enc in ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
                     (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16")):  # fmt: skip
        if data.startswith(bom):
            raise InputError(f"the file is {enc} text", where=where, fix="save it as UTF-8 CSV")
    nul = data.find(b"\x00")
    if nul >= 0:
        raise InputError(
            f"binary content (a NUL byte at offset {nul}), not a CSV text file",
            where=where,
            fix="give a CSV file with a header such as 'time [s], force [N]'",
        )
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"not UTF-8 text (byte {exc.start})",
            where=where,
            fix="save it as UTF-8 (e.g. from latin-1: iconv -f latin1 -t utf-8)",
        ) from None


def _read_text(path: Path, where: str) -> str:
    try:
        if not path.is_file():
            raise InputError("is not a regular file", where=where, fix="give a CSV file")
        with path.open("rb") as fh:
            data = fh.read(MAX_CSV_BYTES + 1)
    except OSError as exc:
        raise InputError(f"cannot read force file: {exc.strerror or exc}", where=where) from None
    if len(data) > MAX_CSV_BYTES:
        raise InputError(
            f"the file is larger than {MAX_CSV_BYTES // 2**20} MB", where=where, fix="thin it out"
        )
    return _decode(data, where)


def _split(line: str, lineno: int, where: str) -> list[str]:
    """Cells of one CSV line (quotes allowed); a csv error is one line naming the line."""
    try:
        return next(csv.reader([line]), [])
    except csv.Error:
        raise InputError("malformed CSV (quotes)", where=f"{where}, line {lineno}") from None


def _header(cells: list[str], where: str) -> tuple[dict[str, int], dict[str, str]]:
    """Column index and unit text by key, from the header's cells."""
    columns: dict[str, int] = {}
    units: dict[str, str] = {}
    for i, cell in enumerate(cells):
        m = _HEADER_CELL.match(cell.strip())
        key = _COLUMN_NAMES.get(m.group("key").lower()) if m else None
        if m is None or key is None:
            raise InputError(
                f"column {i + 1} of the header is not a known column", where=where, fix=_COLUMNS_FIX
            )
        if key in columns:
            raise InputError(f"column {key!r} appears twice", where=where)
        columns[key] = i
        units[key] = (m.group("u1") or m.group("u2") or m.group("u3") or "").strip()
    comps = [k for k in ("fx", "fy", "fz") if k in columns]
    if "time" not in columns:
        raise InputError(
            "missing column 'time'",
            where=where,
            fix="the header must name 'time [s]' and 'force [N]' (units of your choice)",
        )
    if comps and "force" in columns:
        raise InputError("give either force or fx, fy, fz, not both", where=where)
    if comps and len(comps) != 3:
        missing = ", ".join(k for k in ("fx", "fy", "fz") if k not in columns)
        raise InputError(f"missing column(s) {missing}", where=where, fix=_COLUMNS_FIX)
    if comps and "direction" in columns:
        raise InputError("a direction column goes with force, not with fx, fy, fz", where=where)
    if not comps and "force" not in columns:
        raise InputError(
            "missing column 'force'",
            where=where,
            fix="the header must name 'time [s]' and 'force [N]' (units of your choice)",
        )
    return columns, units


def _scale(unit: str, dimension: str, key: str, where: str) -> float:
    """SI factor of a header unit; the message names the column, not the file's text."""
    if not unit:
        raise InputError(
            f"no unit for the {key} column",
            where=where,
            fix="write the unit in the header, e.g. 'time [s], force [lbf]' or 'time_s,force_N'",
        )
    try:
        return parse_unit(unit, dimension, where=where)
    except InputError:
        raise InputError(
            f"the unit of the {key} column is not a unit of {dimension}",
            where=where,
            fix=f"use e.g. {'s, ms, min' if dimension == 'time' else 'N, kN, lbf'}",
        ) from None


def _column(cells: list[str], key: str, linenos: np.ndarray, where: str) -> np.ndarray:
    """The floats of one column; the first bad cell is reported by its line, not its text.

    Cells are plain numbers (sign, digits, point, exponent) with optional spaces or tabs
    around them: float() alone would also take ``1_0``, ``nan``, non-ASCII digits and
    non-ASCII spaces.
    """
    if not "".join(cells).translate(_NUMBER_CHARS):  # only characters a plain number has
        try:
            return np.array(cells, dtype=float)
        except ValueError:
            pass
    bad = next((i for i, c in enumerate(cells) if not _STRICT_NUMBER.match(c)), 0)
    cell = cells[bad].strip(" \t")
    what = "is empty" if not cell else "is not a number"
    if cell.lower().lstrip("+-") in ("nan", "inf", "infinity"):
        what = "is not a finite number"
    raise InputError(f"{key} {what}", where=f"{where}, line {linenos[bad]}")


def from_csv(path: str | Path, *, name: str | None = None) -> ForceHistory:
    """Read a force history from a CSV file (see docs/assessment.md, "Force files").

    Format: UTF-8 text; ``#`` starts a comment line; the first other line is the header.  It
    names the columns ``time`` and ``force`` (and optionally ``direction``), or ``time``,
    ``fx``, ``fy``, ``fz`` (a force whose direction varies), with units in brackets
    (``time [s], force [lbf]``), in parentheses, or after an underscore (``time_s,force_N``);
    or a header without units followed by a units line (``s, lbf``).  Times must increase
    strictly; values must be plain finite numbers within the limits of
    :data:`microg.units.LIMITS` (1e7 s, 1e7 N); ``direction`` (``x``, ``-z``, ``1 0 0``) must be
    the same on every row where it is given.  Rows are read vectorised (a million rows in
    about a second).

    Parameters
    ----------
    path : file name
    name : label (default: the file name)

    Raises
    ------
    InputError
        One line naming the file and line: not UTF-8 text, binary, too large, a missing or
        unknown column, a unit that is not a force/time, a value that is not a finite number
        or is beyond the limits, a time that does not increase.  Messages never quote the
        file's content.
    """
    path = Path(path)
    where = str(path)
    label = name or path.name
    text = _read_text(path, where)
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")  # any line ending
    if max(map(len, lines)) > MAX_CSV_LINE:
        longest = next(i for i, line in enumerate(lines) if len(line) > MAX_CSV_LINE)
        raise InputError(
            f"line {longest + 1} is longer than {MAX_CSV_LINE} characters", where=where
        )
    while lines and not lines[-1].strip():
        lines.pop()
    meaningful = (
        i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")
    )
    header_at = next(meaningful, None)
    if header_at is None:
        raise InputError("empty force file", where=where, fix="write 'time [s], force [N]'")
    where_h = f"{where}, line {header_at + 1}"
    columns, units = _header(_split(lines[header_at], header_at + 1, where), where_h)
    ncol = len(columns)
    data_start = header_at + 1
    # a units line: a header without units, then a line whose first cell is not a number
    second = next(meaningful, None)
    if second is not None and not any(units.values()):
        cells = _split(lines[second], second + 1, where)
        first = cells[columns["time"]] if columns["time"] < len(cells) else ""
        if not _STRICT_NUMBER.match(first):
            for key, i in columns.items():
                units[key] = cells[i].strip() if i < len(cells) else ""
            where_h = f"{where}, line {second + 1}"
            data_start = second + 1
    t_scale = _scale(units["time"], "time", "time", where_h)
    fkeys = ["fx", "fy", "fz"] if "fx" in columns else ["force"]
    f_scales = [_scale(units[k], "force", k, where_h) for k in fkeys]

    rows = lines[data_start:]
    body = "\n".join(rows)
    linenos = np.arange(data_start + 1, data_start + 1 + len(rows))
    blank = (
        (bool(rows) and not rows[0].strip())
        or "\n\n" in body
        or (("\n " in body or "\n\t" in body) and _BLANK_LINE.search(body) is not None)
    )
    if "#" in body or blank:  # comments or blank lines between the rows
        keep = [i for i, r in enumerate(rows) if r.strip() and not r.lstrip().startswith("#")]
        rows = [rows[i] for i in keep]
        linenos = linenos[keep]
        body = "\n".join(rows)
    if len(rows) < 2:
        raise InputError("need at least two rows of data", where=where)
    has_dir = "direction" in columns
    flat = None if '"' in body else body.replace("\n", ",").split(",")
    numeric: np.ndarray | None = None
    if flat is not None and len(flat) == len(rows) * ncol:
        if not has_dir and not body.translate(_NUMBER_CHARS_AND_SEPARATORS):
            with contextlib.suppress(ValueError):  # a bad cell is found column by column
                numeric = np.array(flat, dtype=float).reshape(len(rows), ncol)
        grid = np.array(flat, dtype=object).reshape(len(rows), ncol) if numeric is None else None

        def col(key: str) -> list[str]:
            assert grid is not None
            return grid[:, columns[key]].tolist()

    else:  # quotes, or rows of different lengths: cell by cell
        table = [_split(r, int(n), where) for r, n in zip(rows, linenos, strict=True)]
        counts = np.fromiter((len(c) for c in table), dtype=int, count=len(table))
        ok = (counts == ncol) | (
            (counts == ncol - 1) & has_dir & (columns.get("direction") == ncol - 1)
        )
        if not np.all(ok):
            r = _first(~ok)
            raise InputError(
                f"expected {ncol} values, found {counts[r]}", where=f"{where}, line {linenos[r]}"
            )

        def col(key: str) -> list[str]:
            i = columns[key]
            return [c[i] if i < len(c) else "" for c in table]

    with np.errstate(over="ignore"):  # a value that overflows in SI is caught just below
        if numeric is not None:  # every cell a plain number: one conversion for the file
            times = numeric[:, columns["time"]] * t_scale
            values = np.array(
                [numeric[:, columns[k]] * s for k, s in zip(fkeys, f_scales, strict=True)]
            )
        else:
            times = _column(col("time"), "time", linenos, where) * t_scale
            values = np.array(
                [
                    _column(col(k), k, linenos, where) * s
                    for k, s in zip(fkeys, f_scales, strict=True)
                ]
            )
    for arr, key, limit, unit in (
        (times[None, :], "time", LIMITS["time"], "s"),
        (values, "force", LIMITS["force"], "N"),
    ):
        bad = np.asarray(~(np.abs(arr) <= limit).all(axis=0))  # also catches inf after scaling
        if np.any(bad):
            r = _first(bad)
            raise InputError(
                f"{key} is beyond the limit of {limit:g} {unit} (or not finite after its unit)",
                where=f"{where}, line {linenos[r]}",
            )
    step = np.diff(times)
    if np.any(step <= 0):
        r = _first(step <= 0) + 1
        raise InputError(
            f"time {times[r]:g} s does not increase (previous row: {times[r - 1]:g} s)",
            where=f"{where}, line {linenos[r]}",
            fix="times must increase strictly from row to row",
        )
    if len(fkeys) == 3:
        return ForceHistory.from_vectors(times, values, label)

    direction: np.ndarray | None = None
    if has_dir:
        cells = [c.strip().lower() for c in col("direction")]
        seen: dict[str, np.ndarray] = {}
        for r, cell in enumerate(cells):
            if not cell or cell in seen:
                if (
                    cell
                    and direction is not None
                    and not np.allclose(seen[cell], direction, rtol=0, atol=1e-12)
                ):
                    raise InputError(
                        "direction changes; use fx, fy, fz columns for a direction that varies",
                        where=f"{where}, line {linenos[r]}",
                    )
                continue
            try:
                vec = parse_direction(cell, "direction")
            except InputError:
                raise InputError(
                    "cannot read the direction (x, -z, or three numbers '1 0 0')",
                    where=f"{where}, line {linenos[r]}",
                ) from None
            seen[cell] = vec
            if direction is None:
                direction = vec
            elif not np.allclose(vec, direction, rtol=0, atol=1e-12):
                raise InputError(
                    "direction changes; use fx, fy, fz columns for a direction that varies",
                    where=f"{where}, line {linenos[r]}",
                )
    return ForceHistory(times, values[0], label, direction)


# ------------------------------------------------------------------------------------ library


@dataclass(frozen=True)
class Activity:
    """A library crew activity: the report's pulse shape (Eq. 2.16) with a measured magnitude.

    Attributes
    ----------
    name : library key, e.g. ``foot-pushoff-max``
    description : one line
    f0 : peak force, N; t1, t13, t14 : times of the pulse, s
    source : citation of the magnitude; durations : where the times come from
    """

    name: str
    description: str
    f0: float
    t1: float
    t13: float
    t14: float
    source: str
    durations: str

    def pushoff(self, **overrides: float) -> CrewPushoff:
        """The validated crew force, with any of f0 (N), t1, t13, t14 (s) overridden."""
        params = {"f0": self.f0, "t1": self.t1, "t13": self.t13, "t14": self.t14}
        params.update(overrides)
        return CrewPushoff(**params)

    def history(self, name: str | None = None, **overrides: float) -> ForceHistory:
        """The force history, with any of f0 (N), t1, t13, t14 (s) overridden."""
        p = self.pushoff(**overrides)
        t, f = p.breakpoints()
        params = {"f0_N": p.f0, "t1_s": p.t1, "t13_s": p.t13, "t14_s": p.t14}
        return ForceHistory(
            t, f, name or self.name, params={k: float(v) for k, v in params.items()}
        )


@lru_cache(maxsize=1)
def activity_library() -> dict[str, Activity]:
    """The crew-activity library (``microg/data/crew_activities.toml``), keyed by name."""
    text = resources.files("microg").joinpath("data/crew_activities.toml").read_text("utf-8")
    raw = tomllib.loads(text)
    lib: dict[str, Activity] = {}
    for key, entry in raw.items():
        where = f"crew_activities.toml: {key}"
        lib[key] = Activity(
            name=key,
            description=entry["description"],
            f0=parse_quantity(entry["f0"], "force", where=f"{where}.f0"),
            t1=parse_quantity(entry["t1"], "time", where=f"{where}.t1"),
            t13=parse_quantity(entry["t13"], "time", where=f"{where}.t13"),
            t14=parse_quantity(entry["t14"], "time", where=f"{where}.t14"),
            source=entry["source"],
            durations=entry["durations"],
        )
    return lib


def known_force_specs() -> list[str]:
    """Names accepted by :func:`parse_force_spec` besides a CSV path."""
    return ["crew-pushoff", *activity_library()]


_PARAM_DIMENSION = {"f0": "force", "t1": "time", "t13": "time", "t14": "time"}
_PARAMS_FIX = (
    "parameters are f0=<force>, t1=<time>, t13=<time>, t14=<time>, each at most once, "
    "e.g. crew-pushoff:f0=40lbf,t1=0.5s"
)


def _parse_params(
    text: str, where: str, bare_units: Mapping[str, str] | None = None
) -> dict[str, float]:
    params: dict[str, float] = {}
    if not text.strip():  # "crew-pushoff:" is the spec without parameters
        return params
    if re.search(r"[0-9],[0-9]", text):  # t1=1,5s: a decimal comma, not two parameters
        raise InputError(
            "a comma between digits (a decimal comma?)",
            where=where,
            fix="write the decimal point as '.', e.g. t1=1.5s; commas separate parameters",
        )
    for item in (p.strip() for p in text.split(",")):
        if not item:
            raise InputError(
                "empty parameter (two commas, or a trailing comma)", where=where, fix=_PARAMS_FIX
            )
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or key not in _PARAM_DIMENSION:
            raise InputError(f"cannot read parameter {item!r}", where=where, fix=_PARAMS_FIX)
        if key in params:
            raise InputError(f"parameter {key} is given twice", where=where, fix=_PARAMS_FIX)
        dim = _PARAM_DIMENSION[key]
        params[key] = parse_quantity(
            value.strip(), dim, where=f"{where}: {key}", default_unit=(bare_units or {}).get(dim)
        )
    return params


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def parse_force_spec(
    spec: str, *, where: str = "force", bare_units: Mapping[str, str] | None = None
) -> ForceHistory:
    """A force history from a spec string.

    Accepted: ``crew-pushoff`` (the report's Eq. 2.16 values); ``crew-pushoff:f0=40lbf,t1=0.5s``
    (any of f0, t1, t13, t14 with units, each at most once); a library name
    (``foot-pushoff-max``, ``hand-pushoff-mean``, ...; parameters may follow a colon the same
    way); or the path of a CSV file (see :func:`from_csv`).

    Parameters
    ----------
    spec : the spec text
    where : parameter name for error messages
    bare_units : unit of a bare parameter value per dimension (``{"force": "lbf", "time":
        "s"}``: the model's unit system); None: a bare value is refused
    """
    if not isinstance(spec, str):
        raise InputError(f"expected a force spec string, got {type(spec).__name__}", where=where)
    if len(spec) > MAX_SPEC or "\x00" in spec:
        raise InputError(
            f"the spec is longer than {MAX_SPEC} characters or holds a NUL character", where=where
        )
    spec = spec.strip()
    lib = activity_library()
    head, sep, tail = spec.partition(":")
    key = head.strip().lower()
    path = Path(spec)
    if key in ("crew-pushoff", *lib) and not _is_file(path):
        params = _parse_params(tail, f"{where} {spec}", bare_units) if sep else {}
        try:
            if key == "crew-pushoff":
                return lib["report-pushoff"].history(name="crew-pushoff", **params)
            return lib[key].history(name=None, **params)
        except InputError as exc:
            raise InputError(exc.what, where=f"{where} {spec}: {exc.where}", fix=exc.fix) from None
    if _is_file(path) or path.suffix.lower() == ".csv":
        if not _is_file(path):
            raise InputError(f"force file {spec!r} not found", where=where)
        return from_csv(path)
    shown = spec if len(spec) <= 60 else spec[:57] + "..."
    raise InputError(
        f"unknown force {shown!r}",
        where=where,
        fix=f"use one of {', '.join(known_force_specs())}, or the path of a CSV file",
    )


def crew_force(
    spec: str | CrewPushoff | ForceHistory | None,
    *,
    where: str = "force",
    bare_units: Mapping[str, str] | None = None,
) -> CrewPushoff | ForceHistory:
    """The force of a spec, the push-off kept in its closed form.

    ``crew-pushoff`` and ``crew-pushoff:f0=...,t1=...,t13=...,t14=...`` give a
    :class:`~microg.dynamics.crew.CrewPushoff` (Eq. 2.16; its modal response is exact,
    Eqs. 2.17-2.18), every other spec the :class:`ForceHistory` of :func:`parse_force_spec`.
    The grammar is :func:`parse_force_spec`'s, the one of ``microg analyze --force``.

    Parameters
    ----------
    spec : str, CrewPushoff, ForceHistory or None
        A spec string (None: the report's push-off); a force object passes through.
    where : str
        Parameter name for error messages.
    bare_units : mapping, optional
        Unit of a bare parameter value per dimension (None: a bare value is refused).
    """
    if spec is None:
        return CrewPushoff()
    if isinstance(spec, CrewPushoff | ForceHistory):
        return spec
    if not isinstance(spec, str):
        raise InputError(
            f"expected a force spec string, got {type(spec).__name__}",
            where=where,
            fix="give e.g. crew-pushoff:f0=40lbf, a library activity or a CSV file",
        )
    head, sep, tail = spec.strip().partition(":")
    if head.strip().lower() != "crew-pushoff" or _is_file(Path(spec.strip())):
        return parse_force_spec(spec, where=where, bare_units=bare_units)
    params = _parse_params(tail, f"{where} {spec.strip()}", bare_units) if sep else {}
    try:
        return CrewPushoff(**params)
    except InputError as exc:
        shown = f"{where} {spec.strip()}: {exc.where}"
        raise InputError(exc.what, where=shown, fix=exc.fix) from None
