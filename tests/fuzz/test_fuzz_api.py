"""Fuzzer of the library's public API: wrong types and ranges, one parameter at a time.

The generator draws a public entry point, one of its parameters and a value of a kind that
parameter does not take (None where a value is required, bool where a count is, bytes,
containers, non-finite floats, strings where a number is, arbitrary objects).  Invariant: an
:class:`~microg.errors.InputError` whose ``where`` names that parameter; never another
exception from inside microg, never past the hard time limit.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_fuzz_support import Hang, fuzz_settings, record, time_limit

import microg
from microg.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "examples" / "study.toml"

_STATION = microg.load_station("ioc")

NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])
JUNK = st.one_of(
    st.binary(min_size=1, max_size=4),
    st.lists(st.integers(0, 3), min_size=1, max_size=3),
    st.dictionaries(st.sampled_from("ab"), st.integers(), min_size=1, max_size=1),
    st.builds(object),
)
NOT_A_NUMBER = st.one_of(
    st.none(), st.booleans(), NON_FINITE, st.sampled_from(["10", "x", ""]), JUNK
)
NOT_A_COUNT = st.one_of(
    st.booleans(),
    NON_FINITE,
    st.floats(0.5, 1e3).filter(lambda x: x != int(x)),
    st.integers(-1000, 0),
    st.sampled_from(["10", "x"]),
    JUNK,
)
NOT_A_PATH = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(),
    st.floats(allow_nan=True),
    st.just(""),
    st.just("   "),
    JUNK,
)
NOT_A_FLAG = st.one_of(st.none(), st.integers(0, 5), st.sampled_from(["yes", "no", ""]), JUNK)

#: (call, parameter, strategy of wrong values)
CASES: list[tuple[str, str, Any]] = [
    ("load_station", "path_or_name", NOT_A_PATH),
    ("load_model", "path", NOT_A_PATH),
    ("load_study", "path", NOT_A_PATH),
    ("sweep", "study", NOT_A_PATH),
    ("solve_modes", "model", st.one_of(st.none(), st.booleans(), st.integers(), JUNK)),
    ("solve_modes", "n_modes", NOT_A_COUNT),
    ("discretize", "model", st.one_of(st.none(), st.integers(), JUNK)),
    ("discretize", "n", NOT_A_COUNT),
    ("analyze", "model", st.one_of(st.none(), st.integers(), JUNK)),
    ("analyze", "n_modes", NOT_A_COUNT),
    ("analyze", "n", NOT_A_COUNT),
    ("analyze", "damping", st.one_of(NOT_A_NUMBER, st.floats(1.0001, 1e9), st.floats(-1e9, -1e-9))),
    (
        "analyze",
        "absorber_mu",
        st.one_of(st.booleans(), NON_FINITE, st.sampled_from(["0.05"]), JUNK),
    ),
    ("analyze", "isolation", NOT_A_FLAG),
    ("analyze", "gravity_gradient", NOT_A_FLAG),
    (
        "analyze",
        "progress",
        st.one_of(st.integers(), st.sampled_from(["x"]), st.binary(max_size=2)),
    ),
    ("analyze", "sources", st.one_of(st.integers(), JUNK)),
    (
        "analyze",
        "direction",
        st.one_of(st.integers(), st.floats(allow_nan=True), st.binary(min_size=1, max_size=2)),
    ),
    (
        "sweep",
        "timeout_s",
        st.one_of(NOT_A_NUMBER.filter(lambda v: v is not None), st.floats(-1e6, 0.0)),
    ),
    ("sweep", "workers", NOT_A_COUNT),
    ("sweep", "threads", NOT_A_COUNT),
    ("sweep", "out", st.one_of(st.booleans(), st.integers(), st.just(""), JUNK)),
    ("sweep", "restart", NOT_A_FLAG.filter(lambda v: v is not None)),
]


def _call(name: str, param: str, value: Any) -> None:
    fn = getattr(microg, name)
    if name in ("load_station", "load_model", "load_study"):
        fn(value)
    elif name == "sweep":
        fn(value) if param == "study" else fn(STUDY, **{param: value})
    elif param == "model":
        fn(value)
    else:
        fn(_STATION, **{param: value})


@st.composite
def api_cases(draw: st.DrawFn) -> tuple[str, str, Any]:
    name, param, values = draw(st.sampled_from(CASES))
    return name, param, draw(values)


@given(api_cases())
@fuzz_settings(n_ci=400, n_long=5_000, deadline_s=10)
def test_fuzz_wrong_api_arguments(case: tuple[str, str, Any]) -> None:
    name, param, value = case
    try:
        with time_limit(30):
            _call(name, param, value)
    except InputError as exc:
        record("api arguments", "clean error")
        assert exc.where == param, (name, param, exc)
        return
    except Hang:
        record("api arguments", "hang")
        raise
    except Exception as exc:
        record("api arguments", "traceback")
        pytest.fail(f"{name}({param}={value!r}) raised {type(exc).__name__}: {exc}")
    record("api arguments", "misread")
    pytest.fail(f"{name}({param}={value!r}) was accepted")


def test_numpy_scalars_are_accepted_where_python_numbers_are() -> None:
    # the generator's complement: numpy integers and floats are numbers, not wrong types
    assert microg.solve_modes(_STATION, n_modes=np.int32(8)).n_modes == 8
    with pytest.raises(InputError) as e:
        microg.analyze(_STATION, damping=np.float64(1.5))
    assert e.value.where == "damping"
