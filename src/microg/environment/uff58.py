"""Acceleration time histories of a UFF file (datasets 58, with dataset 164's units).

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

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from microg.environment.assessment import MAX_SAMPLES
from microg.environment.record import (
    CSV_STEP_TOLERANCE,
    MAX_SAMPLE_RATE_HZ,
    MeasuredRecord,
    accel_factor,
    nonuniform_step,
)
from microg.errors import InputError
from microg.units import parse_quantity

__all__ = ["UFF_SUFFIXES", "read_uff58"]


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
            label_factor = accel_factor(od_unit, where)
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
        bad = nonuniform_step(x) if np.all(np.isfinite(x)) else (1, float("nan"), float("nan"))
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
