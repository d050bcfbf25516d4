"""Fuzzer of command-line option strings: quantities, directions, force
specs, point names, output paths, with the issue's reproductions as named tests.

Each generator builds an option string from parts whose meaning it knows (a number text, a
unit from a table of exact factors, junk, a suffix), so an independent oracle says whether
the string is valid and, if so, its SI value.  Invariant: a valid string gives exactly the
oracle's value; an invalid one a clean error (click's BadParameter or an InputError, one
line); never anything else, never past the hard time limit.  The full command line
(``microg.cli.main``) must exit 0, or 2 with one line on stderr, nothing on stdout and
nothing written.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import click
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_fuzz_support import Hang, fuzz_settings, one_line, record, time_limit

from microg._vectors import parse_direction
from microg.cli import main
from microg.cli.params import MassOrWeightType, QuantityType
from microg.dynamics.crew import MIN_RAMP_S
from microg.dynamics.forces import activity_library, parse_force_spec
from microg.errors import InputError
from microg.units import LIMITS, SMALLEST

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "station.toml"
FT, LB, G0 = 0.3048, 0.45359237, 9.80665
LBF = LB * G0
SLUG = LBF / FT

#: exact SI factors of the units the generators use, by dimension
UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "ft": FT, "in": 0.0254, "km": 1e3, "mm": 1e-3},
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0},
    "force": {"N": 1.0, "lbf": LBF, "kN": 1e3},
    "mass": {"kg": 1.0, "lb": LB, "slug": SLUG, "t": 1e3},
    "frequency": {"Hz": 1.0, "kHz": 1e3, "rpm": 1 / 60},
    "angular_frequency": {"rad/s": 1.0, "Hz": 2 * math.pi, "rpm": 2 * math.pi / 60},
}
DEFAULT = {"length": "ft", "time": "s", "force": "lbf", "mass": "kg", "frequency": "Hz"}
DEFAULT["angular_frequency"] = "rad/s"
#: texts that are not numbers, with reproductions of strings that once broke the parser
BAD_NUMBERS = ["9**9**9", "2**1000", "(296", "2,96", "1,5", "nan", "inf", "-inf", "", "+-1",
               "1e400", "0x10", "__import__('os')", "1.2.3", "1_0", "\u0663", "."]  # fmt: skip
#: unit texts that are not a unit of any dimension here
BAD_UNITS = ["foo", "m/m", "percent", "kg/lb", "(m", "m^99", "m^2^3", "N m", "**2", "é"]
BAD_SUFFIXES = [" 2", " x", "**2", ",5", "*2"]  # (not ")": "(m" + ")" is a unit)
#: cross-dimension units: (unit, dimensions it belongs to)
OTHER_UNITS = {
    "m": {"length"},
    "s": {"time"},
    "kg": {"mass"},
    "N": {"force"},
    "Hz": {"frequency", "angular_frequency"},
}


def _run_cli(argv: list[str], cwd: Path) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    old = Path.cwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(argv)
    finally:
        os.chdir(old)
    return rc, out.getvalue(), err.getvalue()


def _guard(group: str, fn: Any) -> Any:
    """Run ``fn`` under the hard time limit, counting hangs and tracebacks."""
    try:
        with time_limit(30), warnings.catch_warnings():
            warnings.simplefilter("error")  # a RuntimeWarning is a defect too
            return fn()
    except Hang:
        record(group, "hang")
        raise
    except (InputError, click.BadParameter, AssertionError):
        raise
    except Exception:
        record(group, "traceback")
        raise


# -------------------------------------------------------------------------------- quantities


@st.composite
def quantity_cases(draw: st.DrawFn, dim: str | None = None) -> dict[str, Any]:
    """(dimension, text, kind, expected SI value or None when the text is invalid)."""
    dim = dim or draw(st.sampled_from(sorted(UNITS)))
    valid = True
    if draw(st.integers(0, 5)):
        x = draw(st.floats(-1e6, 1e6, allow_nan=False) | st.sampled_from([0.0, 1e-300, 1e300]))
        number = draw(st.sampled_from(["{!r}", "{:.6e}", "{:g}", "{:.3f}", "{:+.2f}"])).format(x)
        x = float(number)
    else:
        number, x, valid = draw(st.sampled_from(BAD_NUMBERS)), math.nan, False
    kind = draw(st.sampled_from(["unit", "unit", "bare", "other", "bad"]))
    factor = 1.0
    if kind == "unit":
        unit = draw(st.sampled_from(sorted(UNITS[dim])))
        factor = UNITS[dim][unit]
    elif kind == "bare":
        unit = ""
        factor = UNITS[dim][DEFAULT[dim]]
    elif kind == "other":
        unit = draw(st.sampled_from(sorted(OTHER_UNITS)))
        if dim in OTHER_UNITS[unit]:
            factor = UNITS[dim][unit]
        else:
            valid = False
    else:
        unit, valid = draw(st.sampled_from(BAD_UNITS)), False
    space = draw(st.sampled_from([" ", "", "  "])) if unit else ""
    if unit and unit[0] in "*(0123456789" and not space:
        space = " "  # "5**2" is a bad number, not the bad unit under test
    suffix = draw(st.sampled_from(["", "", "", *BAD_SUFFIXES])) if number else ""  # " 2" is 2
    if suffix:
        valid = False
    text = f"{number}{space}{unit}{suffix}"
    if valid:
        value = x * factor
        valid = math.isfinite(value) and abs(value) <= LIMITS[dim]
        valid = valid and not (0 < abs(value) < SMALLEST.get(dim, 0.0))
    return {"dim": dim, "text": text, "kind": kind, "expected": (x * factor) if valid else None}


@given(quantity_cases())
@fuzz_settings(n_ci=500, n_long=5_000, deadline_s=5)
def test_fuzz_quantity_options(case: dict[str, Any]) -> None:
    param = QuantityType(case["dim"], DEFAULT[case["dim"]])

    def convert() -> float:
        return param.convert(case["text"], None, None)

    try:
        value = _guard("cli", convert)
    except click.BadParameter as exc:
        assert one_line(exc.message), exc.message
        if case["expected"] is not None:
            record("cli", "misread")
            raise AssertionError(f"{case['text']!r} refused: {exc.message}") from None
        record("cli", "clean error")
        return
    if case["expected"] is None or value != pytest.approx(case["expected"], rel=1e-12):
        record("cli", "misread")
        raise AssertionError(f"{case['text']!r} read as {value}, expected {case['expected']}")
    record("cli", "valid result")


# -------------------------------------------------------------------------------- directions


@st.composite
def direction_cases(draw: st.DrawFn) -> dict[str, Any]:
    if draw(st.booleans()):
        sign = draw(st.sampled_from(["", "+", "-", "+-", "--", "++", "-+"]))
        axis = draw(st.sampled_from(["x", "y", "z", "X", "Z", "w", "xy", ""]))
        pad = draw(st.sampled_from(["", " ", "  "]))
        text = f"{pad}{sign}{pad if draw(st.booleans()) else ''}{axis}{pad}"
        valid = sign in ("", "+", "-") and axis.lower() in ("x", "y", "z")
        vec = None
        if valid:
            vec = np.zeros(3)
            vec["xyz".index(axis.lower())] = -1.0 if sign == "-" else 1.0
        return {"text": text, "expected": vec}
    n = draw(st.sampled_from([3, 3, 3, 2, 4]))
    comps = draw(
        st.lists(
            st.floats(-1e308, 1e308, allow_nan=False)
            | st.sampled_from([0.0, 1.0, -1.0, 1e308, 1e-308]),
            min_size=n,
            max_size=n,
        )
    )
    texts = [draw(st.sampled_from(["{!r}", "{:g}", "{:.3e}"])).format(c) for c in comps]
    bad = draw(st.integers(0, 6)) == 0
    if bad:
        texts[0] = draw(st.sampled_from(["nan", "inf", "1e400", "a", "", "0x1", "1_0"]))
    sep = draw(st.sampled_from([" ", ",", ", ", ";", "  ", "mixed"]))
    text = (texts[0] + "," + " ".join(texts[1:])) if sep == "mixed" else sep.join(texts)
    numbers = texts
    if sep.strip() == "" and texts[0] == "":  # runs of spaces are one separator
        numbers, bad = texts[1:], False
    valid = len(numbers) == 3 and not bad and sep != "mixed"
    vec = np.array([float(t) for t in numbers]) if valid else None
    if vec is not None and (not np.all(np.isfinite(vec)) or not np.any(vec)):
        vec = None
    if vec is not None:
        scale = np.max(np.abs(vec))
        vec = (vec / scale) / np.sqrt(np.sum((vec / scale) ** 2))
    return {"text": text, "expected": vec}


@given(direction_cases())
@fuzz_settings(n_ci=300, n_long=5_000, deadline_s=5)
def test_fuzz_direction_options(case: dict[str, Any]) -> None:
    try:
        vec = _guard("cli", lambda: parse_direction(case["text"], "direction"))
    except InputError as exc:
        assert one_line(str(exc)) and exc.where == "direction"
        if case["expected"] is not None:
            record("cli", "misread")
            raise AssertionError(f"{case['text']!r} refused: {exc}") from None
        record("cli", "clean error")
        return
    expected = case["expected"]
    if expected is None or not np.allclose(vec, expected, rtol=1e-12, atol=1e-15):
        record("cli", "misread")
        raise AssertionError(f"{case['text']!r} read as {vec}, expected {expected}")
    record("cli", "valid result")


# ------------------------------------------------------------------------------- force specs

_PARAMS = {"f0": "force", "t1": "time", "t13": "time", "t14": "time"}


@st.composite
def spec_cases(draw: st.DrawFn) -> dict[str, Any]:
    lib = activity_library()
    name = draw(st.sampled_from(["crew-pushoff", *sorted(lib), "Crew-Pushoff", "teleport"]))
    key_name = name.lower()
    base = lib.get("report-pushoff" if key_name == "crew-pushoff" else key_name)
    valid = base is not None
    items: list[str] = []
    values: dict[str, float] = {}
    for _ in range(draw(st.integers(0, 4))):
        key = draw(st.sampled_from([*_PARAMS, *_PARAMS, "g", "F0", "", "f0 "]))
        dim = _PARAMS.get(key.strip())
        if dim is not None and draw(st.integers(0, 6)):
            q = draw(quantity_cases(dim))
            ok = q["expected"] is not None and q["kind"] != "bare"  # no default unit in specs
        else:  # a quantity of a dimension that shares no unit with time or force
            q = draw(quantity_cases(draw(st.sampled_from(["length", "mass", "frequency"]))))
            ok = False
        if dim is None or not ok or key.strip() in values:
            valid = False
        elif ok:
            values[key.strip()] = q["expected"]
        items.append(f"{key}={q['text']}")
    spec = name + (":" + ",".join(items) if items or draw(st.booleans()) else "")
    p: dict[str, float] = {}
    if base is not None and valid:
        p = {"f0": base.f0, "t1": base.t1, "t13": base.t13, "t14": base.t14, **values}
        valid = (
            0 < p["f0"] <= LIMITS["force"]
            and p["t1"] >= MIN_RAMP_S
            and p["t13"] >= p["t1"]
            and p["t14"] - p["t13"] >= MIN_RAMP_S
            and p["t14"] <= LIMITS["time"]
        )
    return {"spec": spec, "expected": p if valid else None}


@given(spec_cases())
@fuzz_settings(n_ci=300, n_long=5_000, deadline_s=5)
def test_fuzz_force_specs(case: dict[str, Any]) -> None:
    try:
        h = _guard("cli", lambda: parse_force_spec(case["spec"]))
    except InputError as exc:
        assert one_line(str(exc)), str(exc)
        if case["expected"] is not None:
            record("cli", "misread")
            raise AssertionError(f"{case['spec']!r} refused: {exc}") from None
        record("cli", "clean error")
        return
    p = case["expected"]
    if p is None:
        record("cli", "misread")
        raise AssertionError(f"{case['spec']!r} accepted: {h.force.max()} N")
    # Eq. 2.16's breakpoints written out (the report's convention: jumps at t1 and t13)
    t = np.array([0, p["t1"], p["t1"], p["t13"], p["t13"], p["t14"]])
    f = np.array([0, p["f0"], 0, 0, -p["f0"], 0])
    try:
        np.testing.assert_allclose(h.timepts, t, rtol=1e-12)
        np.testing.assert_allclose(h.force, f, rtol=1e-12)
    except AssertionError:
        record("cli", "misread")
        raise
    record("cli", "valid result")


# ------------------------------------------------------------------------- whole commands


_SCRATCH = Path(tempfile.mkdtemp(prefix="microg-fuzz-cli-"))
_NAMES = ["hatch", "rack3", "Hatch", "rack 3", "nowhere", "", "a/b", "é", "hatch,rack3", "-x"]


@st.composite
def command_cases(draw: st.DrawFn) -> dict[str, Any]:
    """A command line that is cheap to run, and whether it must succeed."""
    kind = draw(st.sampled_from(["design", "design", "analyze", "modes", "out"]))
    if kind == "design":

        def sane(c: dict[str, Any]) -> bool:  # the mount design itself has its own limits
            return c["expected"] is None or c["expected"] <= 0 or 1e-3 <= c["expected"] <= 1e6

        m = draw(quantity_cases(draw(st.sampled_from(["mass", "force"]))).filter(sane))
        fdim = draw(st.sampled_from(["frequency", "angular_frequency"]))
        f = draw(quantity_cases(fdim).filter(sane))
        flag_m = "--mass" if m["dim"] == "mass" else "--weight"
        flag_f = "--freq" if f["dim"] == "frequency" else "--omega"
        ok = m["expected"] is not None and f["expected"] is not None
        ok = ok and m["expected"] > 0 and f["expected"] > 0
        mass = None if not ok else (m["expected"] if flag_m == "--mass" else m["expected"] / G0)
        omega = None
        if ok:
            omega = f["expected"] if flag_f == "--omega" else 2 * math.pi * f["expected"]
        argv = ["isolate", "design", flag_m, m["text"], flag_f, f["text"], "--json"]
        return {"argv": argv, "ok": ok, "mass": mass, "omega": omega, "out": None}
    if kind == "analyze":
        # at least one option is bad, so the run must stop at once with one line
        at = draw(st.sampled_from(_NAMES))
        direction = draw(direction_cases())
        duration = draw(quantity_cases())
        bad_at = at not in ("hatch", "rack3")
        bad = bad_at or direction["expected"] is None or duration["dim"] != "time"
        if not bad:
            at = "nowhere"
        argv = ["analyze", str(EXAMPLE), "--at", at, "--direction", direction["text"]]
        if duration["dim"] == "time":
            argv += ["--duration", duration["text"]]
        else:
            argv += ["--observe", draw(st.sampled_from(_NAMES[2:]))]
        out = _SCRATCH / "analyze-out"
        argv += ["--out", str(out), "--json", "--no-progress"]
        return {"argv": argv, "ok": False, "out": out}
    if kind == "modes":
        target = draw(
            st.sampled_from(
                [
                    str(EXAMPLE),
                    "ioc",
                    "IOC",
                    "no-such-model",
                    str(ROOT / "examples" / "pushes.csv"),
                    str(ROOT / "examples"),
                    "/proc/self/environ",
                    "a" * 5000,
                    "",
                ]
            )
        )
        ok = target in (str(EXAMPLE), "ioc")
        return {"argv": ["modes", target, "--json"], "ok": ok, "out": None}
    out_text = draw(st.sampled_from(["", "/proc/x", str(EXAMPLE), str(ROOT / "examples"), "."]))
    argv = draw(
        st.sampled_from(
            [["reproduce", "--out", out_text], ["isolate", "figure8", "--out", out_text]]
        )
    )
    return {"argv": argv, "ok": False, "out": None}


@given(command_cases())
@fuzz_settings(n_ci=250, n_long=3_000, deadline_s=20)
def test_fuzz_command_lines(case: dict[str, Any]) -> None:
    before = set(_SCRATCH.iterdir())
    rc, out, err = _guard("cli", lambda: _run_cli(case["argv"], _SCRATCH))
    assert "Traceback" not in err, err
    if rc == 2:
        assert one_line(err) and err.startswith("microg: error: ") and out == "", (rc, err)
        assert set(_SCRATCH.iterdir()) == before, "an error left files behind"
        if case["ok"] and any(flag in err for flag in ("--mass", "--weight", "--freq", "--omega")):
            record("cli", "misread")  # a valid option refused
            raise AssertionError(f"{case['argv']} refused: {err}")
        record("cli", "clean error")  # (or the library refusing a valid but extreme design)
        return
    if rc != 0 or not case["ok"]:
        record("cli", "misread" if rc == 0 else "traceback")
        raise AssertionError(f"{case['argv']}: exit {rc}, stderr {err!r}")
    data = json.loads(out)
    if case["argv"][0] == "isolate":
        assert data["mass_kg"] == pytest.approx(case["mass"], rel=1e-12)
        assert data["omega_band"][0] == pytest.approx(case["omega"], rel=1e-12)
        assert math.isfinite(data["k1_N_per_m"]) and data["k1_N_per_m"] > 0
    record("cli", "valid result")


# --------------------------------------------------------- the reproductions, one test each


def test_direction_1e308_1e308_0_does_not_warn() -> None:
    # printed numpy RuntimeWarnings, then called it [0, 0, 0] (pytest runs warnings as errors)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = parse_direction("1e308 1e308 0", "direction")
    np.testing.assert_allclose(d, [2**-0.5, 2**-0.5, 0.0], rtol=1e-15)


def test_direction_plus_minus_x_is_refused() -> None:
    with pytest.raises(InputError, match="cannot read direction"):
        parse_direction("+-x", "direction")


def test_out_empty_string_is_an_error(tmp_path: Path) -> None:
    # `--out ''` wrote into the current directory
    for argv in (["reproduce", "--out", ""], ["isolate", "figure8", "--out", ""]):
        rc, out, err = _run_cli(argv, tmp_path)
        assert rc == 2 and one_line(err) and "--out" in err and out == ""
    assert list(tmp_path.iterdir()) == []


def test_out_proc_x_fails_before_computing(tmp_path: Path) -> None:
    # `--out /proc/x` failed only after a 10-s run
    start = time.perf_counter()
    rc, _, err = _run_cli(["reproduce", "--out", "/proc/x"], tmp_path)
    assert rc == 2 and "--out" in err and one_line(err)
    assert time.perf_counter() - start < 5  # the reproduction itself takes longer; no compute


def test_isolate_figure8_message_is_not_blank(tmp_path: Path) -> None:
    # printed "microg: error: --out: " (a required option without a message)
    rc, out, err = _run_cli(["isolate", "figure8"], tmp_path)
    assert rc == 0 and err == "" and (tmp_path / "figure8.png").read_bytes()[:4] == b"\x89PNG"
    rc, _, err = _run_cli(["isolate", "figure8", "--out", "x.txt"], tmp_path)
    assert rc == 2 and err.strip() != "microg: error: --out:" and "png" in err


def test_package_mass_accepts_a_mass_or_a_weight() -> None:
    # --package-weight "200 kg" failed with "'200 kg' is not a force"
    t = MassOrWeightType("lbf")
    assert t.convert("200 kg", None, None) == 200.0
    assert t.convert("441 lbf", None, None) == pytest.approx(441 * LBF / G0, rel=1e-12)
    assert t.convert("1000", None, None) == pytest.approx(1000 * LB, rel=1e-12)  # bare: lbf
    assert t.convert("14 slug", None, None) == pytest.approx(14 * SLUG, rel=1e-12)
    for bad, needle in (("200 m", "neither a mass"), ("-5 kg", "> 0"), ("1e300 kg", "limit")):
        with pytest.raises(click.BadParameter, match=needle):
            t.convert(bad, None, None)


@pytest.mark.slow  # a full analysis with its report (about 8 s; run in CI too)
def test_example_station_runs_as_in_the_readme(tmp_path: Path) -> None:
    # microg analyze examples/station.toml --force examples/pushes.csv
    #                 --at hatch --observe rack3
    argv = ["analyze", str(EXAMPLE), "--force", str(ROOT / "examples" / "pushes.csv")]
    argv += ["--at", "hatch", "--observe", "rack3", "--out", "run", "--json", "--no-progress"]
    rc, out, err = _run_cli(argv, tmp_path)
    assert rc == 0, err
    data = json.loads(out)
    assert "rack3" in json.dumps(data) and (tmp_path / "run" / "report.html").exists()
