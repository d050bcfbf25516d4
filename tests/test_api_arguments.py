"""The public API refuses a wrong argument with microg's InputError naming the parameter.

Every entry point of ``microg`` (and the force constructors) is called with values of the wrong
type or out of range, one parameter at a time: a library caller gets ``InputError`` whose
``where`` names that parameter, never a TypeError, AttributeError or ValueError from inside
microg (the defects an adversarial campaign found: ``solve_modes(5)``, ``analyze(direction=5)``,
``sweep(timeout_s="10")``, ``ForceHistory(force=["a", "b"])``, ...).  A property test draws
the wrong values with hypothesis.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import microg
from microg import _args
from microg.errors import InputError

STUDY = Path(__file__).resolve().parents[1] / "examples" / "study.toml"


@pytest.fixture(scope="module")
def ioc():
    return microg.load_station("ioc")


#: values that are no file path
NOT_PATHS = [None, 5, 1.5, True, b"ioc", ["ioc"], {"a": 1}, "", "  "]


@pytest.mark.parametrize("bad", NOT_PATHS)
@pytest.mark.parametrize(
    ("call", "param"),
    [
        (microg.load_station, "path_or_name"),
        (microg.load_model, "path"),
        (microg.load_study, "path"),
        (microg.sweep, "study"),
    ],
)
def test_loaders_refuse_what_is_not_a_path(call, param, bad):
    with pytest.raises(InputError) as e:
        call(bad)
    assert e.value.where == param


@pytest.mark.parametrize("bad", [None, 5, 1.5, True, b"x", ["a"], {"a": 1}, object()])
def test_model_arguments_name_the_model(bad):
    for call in (microg.solve_modes, microg.discretize, microg.analyze):
        with pytest.raises(InputError) as e:
            call(bad)
        assert e.value.where == "model"


def test_solve_modes_takes_a_path_like_a_name(tmp_path):
    # a Path is a model file: a missing one is a one-line model error naming it
    with pytest.raises(InputError, match="x.toml"):
        microg.solve_modes(tmp_path / "x.toml")


@pytest.mark.parametrize("bad", ["10", math.nan, 2.5, True, [1], 0, -1])
def test_mode_and_element_counts_are_positive_integers(ioc, bad):
    with pytest.raises(InputError) as e:
        microg.solve_modes(ioc, n_modes=bad)
    assert e.value.where == "n_modes"
    for param in ("n", "n_modes"):
        with pytest.raises(InputError) as e:
            microg.analyze(ioc, **{param: bad})
        assert e.value.where == param


def test_numpy_integers_are_integers(ioc):
    # a count taken from an array is an integer, not a type error
    assert microg.solve_modes(ioc, n_modes=np.int64(12)).n_modes == 12


@pytest.mark.parametrize(
    ("param", "bad"),
    [
        ("direction", 5),
        ("direction", b"x"),
        ("absorber_mu", "0.05"),
        ("absorber_mu", math.nan),
        ("absorber_mu", True),
        ("absorber_mu", -1.0),
        ("damping", "x"),
        ("damping", None),
        ("damping", math.nan),
        ("damping", 2.0),
        ("progress", 5),
        ("progress", "x"),
        ("sources", 5),
        ("sources", b"x"),
        ("sources", []),
        ("sources", {}),
        ("isolation", "no"),
        ("isolation", 5),
        ("gravity_gradient", "x"),
        ("command", 5),
        ("method", 5),
        ("plane", 5),
    ],
)
def test_analyze_names_the_wrong_parameter(ioc, param, bad):
    with pytest.raises(InputError) as e:
        microg.analyze(ioc, **{param: bad})
    assert e.value.where == param


@pytest.mark.parametrize(
    ("param", "bad"),
    [
        ("timeout_s", "10"),
        ("timeout_s", -1.0),
        ("timeout_s", math.inf),
        ("workers", True),
        ("workers", 0),
        ("workers", "2"),
        ("workers", 2.5),
        ("threads", 0),
        ("threads", -1),
        ("threads", "1"),
        ("out", 5),
        ("out", b"x"),
        ("scheduler", 5),
        ("restart", "yes"),
        ("progress", 5),
    ],
)
def test_sweep_names_the_wrong_parameter(param, bad, tmp_path):
    with pytest.raises(InputError) as e:
        microg.sweep(STUDY, **{param: bad})
    assert e.value.where == param
    assert not any(tmp_path.iterdir())  # refused before anything is written


@pytest.mark.parametrize(
    ("args", "where"),
    [
        ((np.array([0.0, 1.0]), ["a", "b"]), "force 'force': force"),
        (("x", [1.0]), "force 'force': timepts"),
        ((None, [1.0]), "force 'force': timepts"),
        ((np.array([0.0, 1.0]), b"ab"), "force 'force': force"),
    ],
)
def test_force_history_names_the_array(args, where):
    with pytest.raises(InputError) as e:
        microg.ForceHistory(*args)
    assert e.value.where == where


# ----------------------------------------------------------------------------- property test

WRONG = st.one_of(
    st.none(),
    st.booleans(),
    st.binary(max_size=4),
    st.text(max_size=4).filter(lambda s: not s.strip() or not s.isdigit()),
    st.lists(st.integers(), max_size=2),
    st.dictionaries(st.text(max_size=2), st.integers(), max_size=1),
    st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not math.isfinite(x)),
    st.builds(object),
)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    bad=WRONG,
    param=st.sampled_from(["n", "n_modes", "damping", "absorber_mu", "isolation", "progress"]),
)
def test_analyze_refuses_any_wrong_type(ioc, bad, param):
    # a few values of the right kind are fine for some parameters (None means default for n,
    # n_modes, absorber_mu, progress); everything else is an InputError naming the parameter
    if bad is None and param in ("n", "n_modes", "absorber_mu", "progress"):
        return
    if isinstance(bad, bool) and param == "isolation":
        return
    with pytest.raises(InputError) as e:
        microg.analyze(ioc, **{param: bad})
    assert e.value.where == param


@settings(max_examples=80, deadline=None)
@given(bad=WRONG)
def test_checkers_refuse_any_wrong_type(bad):
    # the checkers themselves: a wrong value never passes and never raises anything else
    for check in (_args.integer, _args.number, _args.boolean, _args.function):
        if check is _args.boolean and isinstance(bad, bool):
            continue
        if check is _args.function and callable(bad):
            continue
        with pytest.raises(InputError) as e:
            check(bad, "p")
        assert e.value.where == "p"
