"""Readers of measured acceleration: one entry for PAD, CSV and UFF 58 files.

:func:`read_measured` and :func:`read_measured_all` pick the reader by the file: a ``.csv``
or ``.txt`` (:mod:`~microg.environment.accel_csv`: units in the header), a ``.unv``/``.uff``
(:mod:`~microg.environment.uff58`: one record per sensor), a PIMS/SAMS PAD data file or its
``.header`` (:mod:`~microg.environment.pad`).  Every reader returns
:class:`~microg.environment.record.MeasuredRecord` (SI, uniformly sampled); the readers' names
are importable from here.

Every problem raises :class:`~microg.errors.InputError` naming the file and the line, record
or field, and the fix.
"""

from __future__ import annotations

from pathlib import Path

from microg.environment.accel_csv import MAX_CSV_BYTES, read_accel_csv
from microg.environment.pad import MAX_HEADER_BYTES, PadHeader, read_pad, read_pad_header
from microg.environment.record import CSV_STEP_TOLERANCE, MAX_SAMPLE_RATE_HZ, MeasuredRecord
from microg.environment.uff58 import UFF_SUFFIXES, read_uff58
from microg.errors import InputError

__all__ = [
    "CSV_STEP_TOLERANCE",
    "MAX_HEADER_BYTES",
    "MAX_CSV_BYTES",
    "MAX_SAMPLE_RATE_HZ",
    "UFF_SUFFIXES",
    "MeasuredRecord",
    "PadHeader",
    "read_pad_header",
    "read_pad",
    "read_accel_csv",
    "read_measured",
    "read_measured_all",
    "read_uff58",
]


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
