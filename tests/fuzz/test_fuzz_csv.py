"""Fuzzer of CSV force files.

Two strategies:

* valid by construction: a header in one of the accepted forms (brackets, parentheses,
  underscore suffix, a units line; scalar force with or without direction, or fx, fy, fz),
  units from a table of exact factors, strictly increasing times, comments, blank lines, CRLF;
  the reader must return exactly the values an independent parse gives (else a misreading);
* mutated: the same files broken at the byte, cell, header or row level (encodings, NUL,
  long cells, non-numbers, decreasing times, huge values, changing directions, missing
  cells); the reader must give a one-line error naming the file, or a history that is
  finite, increasing and within the limits.

Errors must never quote the file's content: every file carries a secret token in a place
that breaks it, and no message may contain the token.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_fuzz_support import Hang, fuzz_settings, one_line, record, time_limit

from microg.dynamics.forces import ForceHistory, parse_force_spec
from microg.errors import InputError
from microg.units import LIMITS

LBF = 0.45359237 * 9.80665
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0}
FORCE_UNITS = {"N": 1.0, "kN": 1e3, "lbf": LBF, "mN": 1e-3}
SECRET = "tok3n-S3CRET"
DIRECTIONS = {"x": [1, 0, 0], "-y": [0, -1, 0], "+z": [0, 0, 1], "0 0.6 0.8": [0, 0.6, 0.8]}

_DIR = Path(tempfile.mkdtemp(prefix="microg-fuzz-csv-"))


def _header_cell(name: str, unit: str, style: str) -> str:
    if style == "brackets":
        return f"{name} [{unit}]"
    if style == "parens":
        return f"{name} ({unit})"
    if style == "underscore":
        return f"{name}_{unit}"
    return name  # "line": units on the next line


@st.composite
def valid_files(draw: st.DrawFn) -> dict[str, Any]:
    """A valid force file and the values it must give (times s, forces N, direction)."""
    style = draw(st.sampled_from(["brackets", "parens", "underscore", "line"]))
    vector = draw(st.booleans())
    t_unit = draw(st.sampled_from(sorted(TIME_UNITS)))
    f_unit = draw(st.sampled_from(sorted(FORCE_UNITS)))
    n = draw(st.integers(2, 40))
    steps = draw(st.lists(st.floats(1e-3, 10.0), min_size=n, max_size=n))
    start = draw(st.floats(-10.0, 10.0))  # 410 h at most: within the 1e7 s limit
    t_text = [repr(float(x)) for x in np.cumsum([start, *steps[1:]])]
    if len({float(x) for x in t_text}) != n or any(np.diff([float(x) for x in t_text]) <= 0):
        t_text = [str(i) for i in range(n)]
    fmax = LIMITS["force"] / FORCE_UNITS[f_unit] / 2
    comps = ["fx", "fy", "fz"] if vector else ["force"]
    f_text = []
    for _ in comps:  # one format per column: fewer choices, less memory in long runs
        fmt = draw(st.sampled_from(["{!r}", "{:.6e}", "{:g}", "{:.3f}"]))
        col = draw(st.lists(st.floats(-fmax, fmax, allow_nan=False), min_size=n, max_size=n))
        f_text.append([fmt.format(v) for v in col])
    direction = None if vector else draw(st.sampled_from([None, *sorted(DIRECTIONS)]))
    names = [draw(st.sampled_from(["time", "t", "Time", "T"]))]
    names += [c if draw(st.booleans()) else c.upper() for c in comps]
    cells = [_header_cell(names[0], t_unit, style)]
    cells += [_header_cell(c, f_unit, style) for c in names[1:]]
    if direction is not None:
        cells.append("direction")
    extra = draw(
        st.dictionaries(st.integers(-1, n - 1), st.sampled_from(["", "# note", "   "]), max_size=3)
    )
    lines = []
    if draw(st.booleans()):
        lines.append("# a comment, with commas, and [brackets]")
    lines.append(",".join(cells))
    if style == "line":
        lines.append(",".join([t_unit] + [f_unit] * len(comps) + ([""] if direction else [])))
    if -1 in extra:  # a blank or comment line before the first row
        lines.append(extra[-1])
    for i in range(n):
        row = [t_text[i]] + [col[i] for col in f_text]
        if direction is not None:
            row.append(direction if " " not in direction else f'"{direction}"')
        lines.append(",".join(row))
        if i in extra:
            lines.append(extra[i])
    eol = draw(st.sampled_from(["\n", "\r\n"]))
    text = eol.join(lines) + draw(st.sampled_from(["", eol, eol + eol]))
    data = text.encode("utf-8")
    if draw(st.booleans()):
        data = b"\xef\xbb\xbf" + data
    times = np.array([float(x) for x in t_text]) * TIME_UNITS[t_unit]
    values = np.array([[float(x) for x in col] for col in f_text]) * FORCE_UNITS[f_unit]
    return {"data": data, "times": times, "values": values, "direction": direction}


def _write(data: bytes, name: str = "f.csv") -> Path:
    path = _DIR / name
    path.write_bytes(data)
    return path


def _check(data: bytes) -> tuple[str, ForceHistory | None, str]:
    path = _write(data)
    try:
        with time_limit(30):
            history = parse_force_spec(str(path))
    except Hang:
        record("csv", "hang")
        raise
    except InputError as exc:
        msg = str(exc)
        assert one_line(msg) and str(path) in msg, msg
        assert SECRET not in msg, f"a message quotes the file: {msg}"
        return "clean error", None, msg
    except Exception:
        record("csv", "traceback")
        raise
    t = history.timepts
    comps = history.components(np.array([1.0, 0.0, 0.0]))
    assert np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)
    assert np.all(np.isfinite(comps)) and np.all(np.abs(comps) <= LIMITS["force"])
    assert np.all(np.abs(t) <= LIMITS["time"])
    return "valid result", history, ""


@given(valid_files())
@fuzz_settings(n_ci=300, n_long=5_000, deadline_s=10)
def test_fuzz_valid_force_files_read_exactly(case: dict[str, Any]) -> None:
    category, history, msg = _check(case["data"])
    if history is None:
        record("csv", "misread")
        raise AssertionError(f"a valid file was refused: {msg}")
    # independent reference: Python's float() of each cell times the exact unit factor
    # (1e-15: pint's lbf factor differs from the exact one in the last digit)
    try:
        np.testing.assert_allclose(history.timepts, case["times"], rtol=1e-15, atol=0)
        comps = case["values"]
        if case["direction"] is not None:
            d = np.array(DIRECTIONS[case["direction"]], float)
            np.testing.assert_allclose(history.direction, d / np.linalg.norm(d), rtol=1e-15)
            np.testing.assert_allclose(history.force, comps[0], rtol=1e-15, atol=0)
        elif comps.shape[0] == 1:
            assert history.direction is None
            np.testing.assert_allclose(history.force, comps[0], rtol=1e-15, atol=0)
        else:
            scale = np.max(np.abs(comps)) + 1e-300
            got = history.components()
            np.testing.assert_allclose(got, comps, rtol=1e-12, atol=1e-12 * scale)
    except AssertionError:
        record("csv", "misread")
        raise
    record("csv", category)


@st.composite
def broken_files(draw: st.DrawFn) -> bytes:
    """A valid file broken in one to three places; the secret sits where it breaks it."""
    data = draw(valid_files())["data"].decode("utf-8-sig")
    lines = data.split("\n")
    for _ in range(draw(st.integers(1, 3))):
        op = draw(
            st.sampled_from(
                [
                    "cell",
                    "header",
                    "order",
                    "huge",
                    "cut",
                    "extra",
                    "direction",
                    "secret-line",
                    "nul",
                    "long",
                ]
            )
        )
        i = draw(st.integers(0, len(lines) - 1))
        if op == "cell":
            bad = draw(
                st.sampled_from(
                    ["nan", "inf", "-inf", "abc", "1_0", "\u0663", "", '"1,5"', "0x10", "1e999"]
                    + [SECRET, f"{SECRET}=1"]
                )
            )
            cells = lines[i].split(",")
            cells[draw(st.integers(0, len(cells) - 1))] = bad
            lines[i] = ",".join(cells)
        elif op == "header":
            lines[0] = draw(
                st.sampled_from(
                    [
                        f"{SECRET},force [N]",
                        "time [s],force",
                        "time [parsec],force [N]",
                        f"time [{SECRET}],force [N]",
                        "time [s],force [kg]",
                        "time [s],time [s]",
                        "time [s],fx [N],fy [N]",
                        "force [N]",
                        "",
                        "time [s],force [N],force [N]",
                        "time [9**9**9 s],force [N]",
                    ]
                )
            )
        elif op == "order" and len(lines) > 2:
            j = draw(st.integers(1, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "huge":
            cells = lines[i].split(",")
            cells[-1] = draw(st.sampled_from(["1.7e308", "-1.7e308", "1e300", "2e7"]))
            lines[i] = ",".join(cells)
        elif op == "cut":
            lines = lines[: max(1, i)]
        elif op == "extra":
            lines[i] = lines[i] + ",1"
        elif op == "direction":
            lines[i] = lines[i] + draw(st.sampled_from([",y", ",+-x", ",0 0 0", ",1e400 0 0"]))
        elif op == "secret-line":
            lines.insert(i, f"{SECRET}={SECRET}")
        elif op == "nul":
            lines[i] = lines[i] + "\x00"
        elif op == "long":
            lines[i] = lines[i] + "9" * draw(st.sampled_from([5000, 10_000_000 // 8]))
    text = "\n".join(lines)
    encoding = draw(st.sampled_from(["utf-8", "utf-8", "utf-8", "utf-16", "latin-1", "cp1252"]))
    if encoding == "latin-1":
        text = text.replace("time", "tim\u00e9", 1)
    return text.encode(encoding, "replace")


@given(broken_files())
@fuzz_settings(n_ci=300, n_long=5_000, deadline_s=15)
def test_fuzz_broken_force_files(data: bytes) -> None:
    category, _, _ = _check(data)
    record("csv", category)


@pytest.mark.parametrize("path", ["/proc/self/environ", "/proc/self/cmdline", "/dev/null"])
def test_system_files_as_force_files(path: str) -> None:
    # `--force /proc/self/environ` printed the first line of the process environment
    if not Path(path).exists():
        pytest.skip(f"{path} does not exist here")
    with pytest.raises(InputError) as exc:
        parse_force_spec(path)
    msg = str(exc.value)
    assert one_line(msg) and "PATH=" not in msg and "HOME=" not in msg
    assert math.isfinite(len(msg))
