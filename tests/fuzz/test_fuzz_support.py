"""Shared machinery of the input fuzzers, with tests of its own.

* Profiles: the CI profile (default) is derandomized and fast; ``HYPOTHESIS_PROFILE=fuzz-long``
  runs many more, random examples locally.  Every fuzz test uses :func:`fuzz_settings`.
* A per-example hard time limit (:func:`time_limit`, SIGALRM): a hang fails the example
  even if it never returns (hypothesis's own deadline only reports slow examples that end).
* Outcome counts per category (clean error, valid result, traceback, hang, misread, known
  solver failure), written as JSON to ``$MICROG_FUZZ_REPORT`` when it is set.
* A small TOML writer for mutated model documents.
"""

from __future__ import annotations

import atexit
import contextlib
import json
import math
import os
import re
import signal
import time
from collections import Counter
from collections.abc import Iterator
from datetime import timedelta
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

LONG = os.environ.get("HYPOTHESIS_PROFILE") == "fuzz-long"
CATEGORIES = ("clean error", "valid result", "traceback", "hang", "misread", "known solver")

settings.register_profile("fuzz-ci", derandomize=True, database=None, print_blob=True)
settings.register_profile("fuzz-long", derandomize=False, print_blob=True)

COUNTS: dict[str, Counter[str]] = {}


def fuzz_settings(n_ci: int, n_long: int, deadline_s: float) -> settings:
    """Settings of one fuzz test: ``n_ci`` derandomized examples, or ``n_long`` random ones."""
    return settings(
        settings.get_profile("fuzz-long" if LONG else "fuzz-ci"),
        max_examples=n_long if LONG else n_ci,
        deadline=timedelta(seconds=deadline_s),
        suppress_health_check=[
            HealthCheck.too_slow,
            HealthCheck.data_too_large,
            HealthCheck.filter_too_much,
        ],
    )


def record(group: str, category: str) -> None:
    """Count one example's outcome."""
    assert category in CATEGORIES, category
    COUNTS.setdefault(group, Counter())[category] += 1


@atexit.register
def _write_report() -> None:  # pragma: no cover - only with MICROG_FUZZ_REPORT
    path = os.environ.get("MICROG_FUZZ_REPORT")
    if not path or not COUNTS:
        return
    old: dict[str, dict[str, int]] = {}
    with contextlib.suppress(OSError, ValueError), open(path, encoding="utf-8") as fh:
        old = json.load(fh)
    for group, counts in COUNTS.items():
        merged = Counter(old.get(group, {}))
        merged.update(counts)
        old[group] = dict(merged)
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(old, fh, indent=2, sort_keys=True)


class Hang(BaseException):
    """An example ran past its hard time limit (BaseException: no ``except Exception`` eats it)."""


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`Hang` in the block after ``seconds`` of wall time (main thread, POSIX)."""

    def fire(signum: int, frame: Any) -> None:
        raise Hang(f"no answer after {seconds} s")

    previous = signal.signal(signal.SIGALRM, fire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def one_line(message: str) -> bool:
    """A clean message: one non-empty line without a traceback."""
    return bool(message.strip()) and "\n" not in message.strip() and "Traceback" not in message


# ------------------------------------------------------------------------------ TOML writer

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")
_ESC = {'"': '\\"', "\\": "\\\\", "\n": "\\n", "\t": "\\t", "\r": "\\r", "\b": "\\b", "\f": "\\f"}


def toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else toml_value(key)


def toml_value(value: Any) -> str:
    """An inline TOML value."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        out = []
        for ch in value:
            if ch in _ESC:
                out.append(_ESC[ch])
            elif ord(ch) < 0x20 or ord(ch) == 0x7F:
                out.append(f"\\u{ord(ch):04X}")
            elif 0xD800 <= ord(ch) <= 0xDFFF:  # a lone surrogate cannot be encoded
                out.append("?")
            else:
                out.append(ch)
        return '"' + "".join(out) + '"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{toml_key(k)} = {toml_value(v)}" for k, v in value.items()) + " }"
    raise TypeError(type(value))


def _is_table_array(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def dump_toml(doc: dict[str, Any]) -> str:
    """TOML text of a document (tables as headers, arrays of tables as [[...]])."""
    lines: list[str] = []

    def table(path: list[str], d: dict[str, Any], header: str | None) -> None:
        if header is not None:
            lines.append(header)
        subs = []
        for k, v in d.items():
            if (isinstance(v, dict) and (v or not path)) or _is_table_array(v):
                subs.append((k, v))
            else:
                lines.append(f"{toml_key(k)} = {toml_value(v)}")
        for k, v in subs:
            sub = [*path, toml_key(k)]
            if isinstance(v, dict):
                table(sub, v, f"[{'.'.join(sub)}]")
            else:
                for item in v:
                    table(sub, item, f"[[{'.'.join(sub)}]]")

    table([], doc, None)
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------ tests of the above


def test_time_limit_stops_a_hang() -> None:
    start = time.perf_counter()
    with pytest.raises(Hang), time_limit(0.2):
        while True:
            time.sleep(0.01)
    assert time.perf_counter() - start < 2.0


@given(
    st.recursive(
        st.none().map(lambda _: 1)
        | st.booleans()
        | st.integers(-(2**63), 2**63 - 1)
        | st.floats(allow_nan=False)
        | st.text(max_size=8),
        lambda children: (
            st.lists(children, max_size=3)
            | st.dictionaries(st.text(min_size=1, max_size=5), children, max_size=3)
        ),
        max_leaves=10,
    ).filter(lambda v: not isinstance(v, list) or not _is_table_array(v))
)
@settings(max_examples=100, deadline=None, derandomize=True, database=None)
def test_dump_toml_round_trips(value: Any) -> None:
    import tomllib

    doc = {"a": value, "t": {"k": value}, "arr": [{"x": value}, {"y": 2}]}
    text = dump_toml(doc)
    back = tomllib.loads(text)
    assert back["t"]["k"] == value or (
        isinstance(value, dict) and not value and back["t"]["k"] == {}
    )
    assert back["arr"][1] == {"y": 2}
