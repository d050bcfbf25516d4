"""A call computed in a forked child (microg._fork) gives the call's own result, or its error.

Reference: the same call made in the caller, whose value, exception and warning the forked
path must reproduce on every path (a child that succeeds, raises, warns, dies, returns what
does not pickle; no fork with threads running).  The forks run in a fresh interpreter: a
pytest process may run other threads, where :class:`~microg._fork.Forked` rightly refuses.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

SCRIPT = r"""
import json, os, sys, threading, time, warnings
from microg._fork import Forked

def square(x):
    return {"value": x * x, "pid": os.getpid()}

def fails(x):
    raise ValueError(f"bad {x}")

def warns(x):
    warnings.warn(f"careful with {x}", UserWarning)
    return x

def dies(x):
    if os.getpid() != PARENT:
        os._exit(3)  # the child dies without a word
    return x + 1

def unpicklable(x):
    return lambda: x

PARENT = os.getpid()
out = {}
with Forked.start(square, 7) as p:
    r = p.result()
    out["square"] = [r["value"], r["pid"] != PARENT, p.forked, p.computed_here]
with Forked.start(fails, 3) as p:
    try:
        p.result()
    except ValueError as exc:
        out["fails"] = [str(exc), p.computed_here]
with Forked.start(warns, 5) as p:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out["warns"] = [p.result(), [str(w.message) for w in caught], p.computed_here]
with Forked.start(dies, 1) as p:
    out["dies"] = [p.result(), p.computed_here]
with Forked.start(unpicklable, 2) as p:
    out["unpicklable"] = [p.result()(), p.computed_here]
with Forked.start(time.sleep, 30) as p:  # a child outliving its timeout: computed here
    t = time.monotonic()
    p._call = (square, (4,), {})  # what the caller computes instead (the same call, quickly)
    out["timeout"] = [p.result(timeout_s=0.2)["value"], p.computed_here,
                      time.monotonic() - t < 5]
stop = threading.Event()
th = threading.Thread(target=stop.wait)
th.start()
with Forked.start(square, 3) as p:  # another thread runs: no fork
    r = p.result()
    out["threads"] = [r["value"], r["pid"] == PARENT, p.forked]
stop.set()
th.join()
try:
    os.waitpid(-1, os.WNOHANG)
    out["children_left"] = True
except ChildProcessError:
    out["children_left"] = False
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def forked() -> dict:
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, check=True, timeout=300
    )
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_the_childs_result_is_the_calls(forked):
    assert forked["square"] == [49, True, True, False]  # computed by the child, 7 * 7


def test_an_error_is_raised_by_the_call_itself(forked):
    assert forked["fails"] == ["bad 3", True]  # the caller's own call raised it


def test_a_warning_is_shown_once_by_the_caller(forked):
    assert forked["warns"] == [5, ["careful with 5"], True]


def test_a_dead_child_or_an_unpicklable_result_is_computed_here(forked):
    assert forked["dies"] == [2, True]
    assert forked["unpicklable"] == [2, True]


def test_a_slow_child_is_stopped_and_the_call_computed_here(forked):
    assert forked["timeout"] == [16, True, True]


def test_no_fork_with_other_threads_and_no_child_left(forked):
    assert forked["threads"] == [9, True, False]
    assert forked["children_left"] is False
