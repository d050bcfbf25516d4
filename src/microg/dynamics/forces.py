"""Force histories: the report's crew push-off, piecewise-linear breakpoints, CSV files, a library.

A :class:`ForceHistory` is a piecewise-linear function of time given by breakpoints.  Conventions
(shared with :func:`microg.dynamics.response.modal_pwl_response`):

* the force is zero before the first breakpoint;
* a repeated breakpoint time is a jump: the first value at that time is the limit from the left,
  the last value holds from that time on (right-continuous);
* after the last breakpoint the force holds its last value.

Everything inside is SI (s, N).  Units are parsed here, at the boundary, with
:func:`microg.units.parse_quantity`.
"""

from __future__ import annotations

import csv
import math
import re
import tomllib
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from microg._vectors import parse_direction
from microg.dynamics.crew import CrewPushoff
from microg.errors import InputError
from microg.units import LBF, parse_quantity

__all__ = [
    "ForceHistory",
    "Activity",
    "REPORT_F0_N",
    "crew_pushoff",
    "piecewise_linear",
    "from_csv",
    "activity_library",
    "parse_force_spec",
    "known_force_specs",
]

#: the report's push-off magnitude, 25 lbf in newtons (1 lbf = 4.4482216152605 N exactly)
REPORT_F0_N = 25.0 * LBF


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class ForceHistory:
    """A piecewise-linear force history f(t) applied along an optional fixed direction.

    Attributes
    ----------
    timepts : (nb,) breakpoint times, s, non-decreasing; a repeated time is a jump
    force : (nb,) force at each breakpoint, N
    name : label for output
    direction : optional (3,) unit vector of the force in the model frame
    """

    timepts: np.ndarray
    force: np.ndarray
    name: str = "force"
    direction: np.ndarray | None = field(default=None)

    def __post_init__(self) -> None:
        t = _readonly(self.timepts)
        f = _readonly(self.force)
        where = f"force {self.name!r}"
        if t.ndim != 1 or f.shape != t.shape or t.size < 1:
            raise InputError(
                "timepts and force must be 1-D arrays of equal length >= 1", where=where
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
            raise InputError("times and forces must be finite numbers", where=where)
        if np.any(np.diff(t) < 0):
            i = int(np.flatnonzero(np.diff(t) < 0)[0]) + 1
            raise InputError(
                f"breakpoint times must not decrease (time[{i}] = {t[i]} < {t[i - 1]})",
                where=where,
            )
        object.__setattr__(self, "timepts", t)
        object.__setattr__(self, "force", f)
        if self.direction is not None:
            d = np.asarray(self.direction, dtype=float)
            norm = float(np.linalg.norm(d)) if d.shape == (3,) else 0.0
            if not (np.isfinite(norm) and norm > 0):
                raise InputError("direction must be a non-zero 3-vector", where=where)
            object.__setattr__(self, "direction", _readonly(d / norm))

    @property
    def duration(self) -> float:
        """Time from the first to the last breakpoint, s."""
        return float(self.timepts[-1] - self.timepts[0])

    def at(self, t: np.ndarray | float) -> np.ndarray:
        """Force at times ``t`` (s), N: linear between breakpoints, right-continuous at jumps.

        Zero before the first breakpoint; the last value after the last breakpoint.
        """
        t = np.asarray(t, dtype=float)
        tp, fp = self.timepts, self.force
        i = np.searchsorted(tp, t, side="right") - 1
        last = tp.size - 1
        i_c = np.clip(i, 0, max(last - 1, 0))
        if last == 0:
            value = np.full(t.shape, fp[0])
        else:
            t0, t1 = tp[i_c], tp[i_c + 1]
            with np.errstate(divide="ignore", invalid="ignore"):
                frac = np.where(t1 > t0, (t - t0) / (t1 - t0), 1.0)
            value = fp[i_c] + (fp[i_c + 1] - fp[i_c]) * frac
        value = np.where(i >= last, fp[-1], value)
        return np.where(i < 0, 0.0, value)

    def impulse(self) -> float:
        """Integral of the force from the first to the last breakpoint, N*s (trapezoids, exact).

        A force that does not end at zero keeps acting after the last breakpoint; that part is
        not included.
        """
        dt = np.diff(self.timepts)
        return float(np.sum(0.5 * (self.force[1:] + self.force[:-1]) * dt))

    def with_direction(self, direction: np.ndarray) -> ForceHistory:
        """A copy applied along ``direction`` (normalised)."""
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


def crew_pushoff(
    f0: float = REPORT_F0_N,
    t1: float = 1.0,
    t13: float = 13.0,
    t14: float = 14.0,
    *,
    name: str = "crew-pushoff",
) -> ForceHistory:
    """The report's crew push-off and landing force (Eq. 2.16).

    A ramp from 0 to ``f0`` over (0, t1], then zero until ``t13``; at ``t13`` the force jumps to
    ``-f0`` and ramps back to zero at ``t14``; zero afterwards.  With the report's values
    (t14 - t13 = t1) this is Eq. 2.16 exactly (slope f0/t1 on both ramps) and the net impulse is
    zero.  When ``t14 - t13 != t1`` the landing still peaks at ``-f0`` (as the project reading of
    Eq. 2.16 states) and the net impulse is ``f0 (t1 - (t14 - t13)) / 2``.

    Parameters
    ----------
    f0 : peak push-off force, N (report: 25 lbf = 111.2 N); non-zero
    t1 : end of the push-off ramp, s (report: 1 s)
    t13 : start of the landing, s (report: 13 s)
    t14 : end of the landing, s (report: 14 s); requires 0 < t1 <= t13 < t14
    name : label
    """
    values = {"f0": f0, "t1": t1, "t13": t13, "t14": t14}
    for key, val in values.items():
        if not math.isfinite(val):
            raise InputError(f"{key} must be a finite number, got {val}", where=name)
    if f0 == 0:
        raise InputError("f0 must be non-zero", where=name, fix="give e.g. f0=25lbf")
    if not (0 < t1 <= t13 < t14):
        raise InputError(
            f"times must satisfy 0 < t1 <= t13 < t14, got t1={t1}, t13={t13}, t14={t14} s",
            where=name,
        )
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

_UNIT_IN_HEADER = re.compile(r"^\s*([A-Za-z_]+)\s*(?:\[(.*)\]|\((.*)\))?\s*$")


def _unit_scale(unit: str, dimension: str, where: str) -> float:
    unit = unit.strip()
    if not unit:
        raise InputError(
            f"no unit for the {dimension} column",
            where=where,
            fix="write the unit in the header, e.g. 'time [s], force [lbf]'",
        )
    return parse_quantity(f"1 {unit}", dimension, where=where)


def from_csv(path: str | Path, *, name: str | None = None) -> ForceHistory:
    """Read a force history from a CSV file (see docs/assessment.md, "Force files").

    Format: ``#`` starts a comment line; the first other line is the header, naming the columns
    ``time`` and ``force`` (and optionally ``direction``) with units in brackets, e.g.
    ``time [s], force [lbf]``; or a header without units followed by a units line (``s, lbf``).
    Times must increase strictly; values must be finite; ``direction`` (``x``, ``-z``, ``1 0 0``)
    must be the same on every row where it is given.

    Parameters
    ----------
    path : file name
    name : label (default: the file name)

    Raises
    ------
    InputError
        Naming the file and line for a missing column, a unit that is not a force/time, a value
        that is not a finite number, or a time that does not increase.
    """
    path = Path(path)
    label = name or path.name
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise InputError(f"cannot read force file: {exc.strerror}", where=str(path)) from None
    rows: list[tuple[int, list[str]]] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        rows.append((lineno, next(csv.reader([line]))))
    if not rows:
        raise InputError("empty force file", where=str(path), fix="write 'time [s], force [N]'")

    header_line, header = rows[0]
    where_h = f"{path}, line {header_line}"
    columns: dict[str, int] = {}
    units: dict[str, str] = {}
    for i, cell in enumerate(header):
        m = _UNIT_IN_HEADER.match(cell)
        key = m.group(1).lower() if m else cell.strip().lower()
        key = {"t": "time", "f": "force", "dir": "direction"}.get(key, key)
        if key not in ("time", "force", "direction"):
            raise InputError(
                f"unknown column {cell.strip()!r}",
                where=where_h,
                fix="columns are time, force and optionally direction",
            )
        if key in columns:
            raise InputError(f"column {key!r} appears twice", where=where_h)
        columns[key] = i
        unit = (m.group(2) or m.group(3) or "") if m else ""
        units[key] = unit
    for key in ("time", "force"):
        if key not in columns:
            raise InputError(
                f"missing column {key!r}",
                where=where_h,
                fix="the header must name 'time [s]' and 'force [N]' (units of your choice)",
            )
    data = rows[1:]
    # a units line: first cell of the next line is not a number
    if data and not units["time"] and not units["force"]:
        lineno, cells = data[0]
        try:
            float(cells[columns["time"]])
        except (ValueError, IndexError):
            for key, i in columns.items():
                units[key] = cells[i] if i < len(cells) else ""
            data = data[1:]
            where_h = f"{path}, line {lineno}"
    t_scale = _unit_scale(units["time"], "time", f"{where_h}: time")
    f_scale = _unit_scale(units["force"], "force", f"{where_h}: force")
    if len(data) < 2:
        raise InputError("need at least two rows of data", where=str(path))

    ncol = len(header)
    times = np.empty(len(data))
    forces = np.empty(len(data))
    direction: np.ndarray | None = None
    for r, (lineno, cells) in enumerate(data):
        where = f"{path}, line {lineno}"
        if len(cells) != ncol and not (len(cells) == ncol - 1 and "direction" in columns):
            raise InputError(f"expected {ncol} values, found {len(cells)}", where=where)
        for key, store in (("time", times), ("force", forces)):
            cell = cells[columns[key]].strip()
            try:
                value = float(cell)
            except ValueError:
                raise InputError(f"{key} {cell!r} is not a number", where=where) from None
            if not math.isfinite(value):
                raise InputError(f"{key} is {cell!r}; a finite number is required", where=where)
            store[r] = value
        if r and times[r] <= times[r - 1]:
            raise InputError(
                f"time {times[r]:g} does not increase (previous row: {times[r - 1]:g})",
                where=where,
                fix="times must increase strictly from row to row",
            )
        if "direction" in columns and columns["direction"] < len(cells):
            cell = cells[columns["direction"]].strip()
            if cell:
                vec = parse_direction(cell, f"{where}: direction")
                if direction is None:
                    direction = vec
                elif not np.allclose(vec, direction, rtol=0, atol=1e-12):
                    raise InputError(
                        "direction changes; a time-varying direction is not supported",
                        where=where,
                        fix="use one file per direction",
                    )
    return ForceHistory(times * t_scale, forces * f_scale, label, direction)


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

    def history(self, name: str | None = None, **overrides: float) -> ForceHistory:
        """The force history, with any of f0 (N), t1, t13, t14 (s) overridden."""
        params = {"f0": self.f0, "t1": self.t1, "t13": self.t13, "t14": self.t14}
        params.update(overrides)
        return crew_pushoff(name=name or self.name, **params)


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


def _parse_params(text: str, where: str) -> dict[str, float]:
    params: dict[str, float] = {}
    for item in filter(None, (p.strip() for p in text.split(","))):
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or key not in _PARAM_DIMENSION:
            raise InputError(
                f"cannot read parameter {item!r}",
                where=where,
                fix="parameters are f0=<force>, t1=<time>, t13=<time>, t14=<time>, "
                "e.g. crew-pushoff:f0=40lbf,t1=0.5s",
            )
        params[key] = parse_quantity(value.strip(), _PARAM_DIMENSION[key], where=f"{where}: {key}")
    return params


def parse_force_spec(spec: str, *, where: str = "--force") -> ForceHistory:
    """A force history from a CLI spec.

    Accepted: ``crew-pushoff`` (the report's Eq. 2.16 values); ``crew-pushoff:f0=40lbf,t1=0.5s``
    (any of f0, t1, t13, t14 with units); a library name (``foot-pushoff-max``,
    ``hand-pushoff-mean``, ...; parameters may follow a colon the same way); or the path of a CSV
    file (see :func:`from_csv`).

    Parameters
    ----------
    spec : the spec text
    where : option name for error messages
    """
    spec = spec.strip()
    lib = activity_library()
    head, sep, tail = spec.partition(":")
    key = head.strip().lower()
    if key in ("crew-pushoff", *lib) and not Path(spec).is_file():
        params = _parse_params(tail, f"{where} {spec}") if sep else {}
        if key == "crew-pushoff":
            return lib["report-pushoff"].history(name="crew-pushoff", **params)
        return lib[key].history(name=None, **params)
    path = Path(spec)
    if path.is_file() or path.suffix.lower() == ".csv":
        if not path.is_file():
            raise InputError(f"force file {spec!r} not found", where=where)
        return from_csv(path)
    raise InputError(
        f"unknown force {spec!r}",
        where=where,
        fix=f"use one of {', '.join(known_force_specs())}, or the path of a CSV file",
    )
