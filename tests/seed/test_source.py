"""The seed report's record and the provenance of a reproduction.

References: the OCR'd copy of the report (``tests/data/seed/``), the shipped files read
directly from the package directory, and hashlib.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import re
from pathlib import Path

import microg
from microg.models.toml import load_station
from microg.seed.source import SEED_REPORT, reproduction_meta, station_record

ROOT = Path(__file__).resolve().parents[2]
SEED = ROOT / "tests" / "data" / "seed" / SEED_REPORT.file_name
DATA = Path(microg.__file__).resolve().parent / "data"


def test_title_is_the_reports_first_line() -> None:
    # the OCR'd copy opens with the title in capitals: the record's title, word for word
    first = SEED.read_text(encoding="utf-8").strip().splitlines()[0].strip()
    assert first == SEED_REPORT.title.upper()
    assert SEED_REPORT.title == (
        "Analytical determination of space station response to crew motion and design of "
        "suspension system for microgravity experiments"
    )


def test_recorded_sha256_is_the_files() -> None:
    assert hashlib.sha256(SEED.read_bytes()).hexdigest() == SEED_REPORT.file_sha256


def test_no_year_later_than_1984_is_cited() -> None:
    # the year note says: not printed, the latest cited work is of August 1984
    text = SEED.read_text(encoding="utf-8")
    years = [int(y) for y in re.findall(r"\b(19[5-9]\d)\b", text)]
    assert max(years) == 1984 and "August, 1984" in text
    assert SEED_REPORT.year is None and "1984" in SEED_REPORT.year_note
    assert SEED_REPORT.authors is None and "not legible" in SEED_REPORT.authors_note


def test_meta_hashes_the_shipped_files() -> None:
    meta = reproduction_meta("microg reproduce", [("ioc", "microg/data/ioc.toml"), ("x", "")])
    assert meta["microg_version"] == microg.__version__
    assert meta["command"] == "microg reproduce"
    t = dt.datetime.strptime(meta["created_utc"], "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=dt.UTC)
    assert abs((dt.datetime.now(dt.UTC) - t).total_seconds()) < 120
    assert meta["seed_report_file"] == SEED_REPORT.file_name
    assert meta["seed_report_sha256"] == SEED_REPORT.file_sha256
    printed = hashlib.sha256((DATA / "_seed_printed.toml").read_bytes()).hexdigest()
    assert meta["printed_values_path"] == "microg/data/_seed_printed.toml"
    assert meta["printed_values_sha256"] == printed
    ioc = hashlib.sha256((DATA / "ioc.toml").read_bytes()).hexdigest()
    assert meta["models"][0] == {"name": "ioc", "path": "microg/data/ioc.toml", "sha256": ioc}
    assert meta["models"][1] == {"name": "x", "path": None, "sha256": None}  # in memory


def test_station_record_of_a_users_file(tmp_path: Path) -> None:
    src = (DATA / "ioc.toml").read_text(encoding="utf-8")
    f = tmp_path / "mine.toml"
    f.write_text(src, encoding="utf-8")
    st = load_station(str(f))
    rec = station_record(st.name, st.source)
    assert rec["path"] == str(f.resolve())
    assert rec["sha256"] == hashlib.sha256(f.read_bytes()).hexdigest()
    assert station_record("gone", str(tmp_path / "gone.toml"))["sha256"] is None
