"""The seed report itself and the provenance of a reproduction.

The report: its title, what the OCR'd copy shows of its origin.  The provenance: version, time,
command, the files the numbers come from, with sha256.

The report is not shipped with microg.  The values microg compares against were read from its
OCR'd copy into
``microg/data/_seed_printed.toml``, which is shipped and hashed at run time, as are the model
files the reproduction reads.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import hashlib
from dataclasses import asdict, dataclass
from importlib import resources
from pathlib import Path
from typing import Any

__all__ = [
    "SeedReport",
    "SEED_REPORT",
    "PRINTED_VALUES_RESOURCE",
    "file_record",
    "station_record",
    "reproduction_meta",
]

#: the shipped file of printed values (package-relative)
PRINTED_VALUES_RESOURCE = "data/_seed_printed.toml"


@dataclass(frozen=True)
class SeedReport:
    """Bibliographic record of the seed report, as far as the OCR'd copy shows it.

    Attributes
    ----------
    title : str
        As printed on its first page (there in capitals).
    authors : str or None
        None: not legible in the OCR'd copy (see ``authors_note``).
    year : int or None
        None: not printed (see ``year_note``).
    program : str
        The programme it was written under.
    file_name, file_sha256 : str
        The OCR'd copy the printed values were read from (not shipped).
    """

    title: str
    authors: str | None
    authors_note: str
    year: int | None
    year_note: str
    program: str
    program_note: str
    file_name: str
    file_sha256: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready record."""
        return asdict(self)


SEED_REPORT = SeedReport(
    title=(
        "Analytical determination of space station response to crew motion and design of "
        "suspension system for microgravity experiments"
    ),
    authors=None,
    authors_note=(
        "not legible: the OCR'd copy's first page carries the title and the abstract only, "
        "and its acknowledgement page (XXVII-ii) did not survive the OCR"
    ),
    year=None,
    year_note=(
        "not printed; the latest work it cites is dated August 1984 (its reference 1, the "
        "Space Station Configuration Description of the Space Station Program Office, "
        "L.B.J. Space Center), so 1984 or later"
    ),
    program="NASA/ASEE",
    program_note=(
        "as the project's seed review reads it; the OCR'd text does not name the programme. "
        "Its pages are numbered XXVII-i, XXVII-1, ...: chapter XXVII of a compiled volume"
    ),
    file_name="000_21c0b08f89afe689.txt",
    file_sha256="0b3ce08d184b2dbf5668161766dcccf8054dadc56a384aa2aee27c908bd02232",
)


def file_record(resource: str) -> dict[str, str]:
    """Package-relative path and sha256 of a shipped file of ``microg``.

    Parameters
    ----------
    resource : str
        Path inside the package, e.g. ``"data/ioc.toml"``.
    """
    data = resources.files("microg").joinpath(resource).read_bytes()
    return {"path": f"microg/{resource}", "sha256": hashlib.sha256(data).hexdigest()}


def station_record(name: str, source: str) -> dict[str, str | None]:
    """Path and sha256 of the file a station was read from (``Station.source``).

    A shipped model's source is package-relative (``microg/data/ioc.toml``); a user's file
    is hashed where it lies; a station built in memory has neither (None).

    Parameters
    ----------
    name : str
        The station's name.
    source : str
        Its ``Station.source``.
    """
    out: dict[str, str | None] = {"name": name, "path": source or None, "sha256": None}
    if source.startswith("microg/"):
        with contextlib.suppress(OSError, ValueError):
            out.update(file_record(source.removeprefix("microg/")))
    elif source and Path(source).is_file():
        path = Path(source).resolve()
        out.update(path=str(path), sha256=hashlib.sha256(path.read_bytes()).hexdigest())
    return out


def reproduction_meta(
    command: str | None, stations: list[tuple[str, str]], created_utc: str | None = None
) -> dict[str, Any]:
    """The ``meta`` block of a reproduction: what made it, when, and from which files.

    Parameters
    ----------
    command : str or None
        The command line (None from the Python API).
    stations : list of (name, source)
        The models read (``Station.name``, ``Station.source``).
    created_utc : str, optional
        ISO 8601 UTC time stamp; now by default.
    """
    from microg import __version__

    printed = file_record(PRINTED_VALUES_RESOURCE)
    return {
        "microg_version": __version__,
        "created_utc": created_utc or _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "command": command,
        "seed_report_file": SEED_REPORT.file_name,
        "seed_report_sha256": SEED_REPORT.file_sha256,
        "printed_values_path": printed["path"],
        "printed_values_sha256": printed["sha256"],
        "models": [station_record(n, s) for n, s in stations],
    }
