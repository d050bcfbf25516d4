"""Fuzzer of values that are only extreme: the isolation designer's frequencies, bands and
mass ratios at the edges of double precision (1e-320, 1e-300, 1e300) and of their documented
ranges.

Invariant (``microg.cli.main``): exit 0 with a result whose JSON is strict, or exit 2 with one
line on stderr; never an internal error (exit 3), a traceback, a warning, or a hang.  An
adversarial campaign found ``isolate design --freq "1e-300 Hz"``, ``--freq-band 1e-320:1``,
``--mu 1e-320`` and ``--mu 1e300`` failing with internal errors.
"""

from __future__ import annotations

import contextlib
import io
import json
import warnings

from hypothesis import given
from hypothesis import strategies as st
from test_fuzz_support import Hang, fuzz_settings, one_line, record, time_limit

from microg.cli import main

EDGES = ["1e-320", "1e-300", "1e-12", "1e-9", "1e-6", "0.5", "1", "3.7", "1e6", "1e9", "1e300",
         "0", "-1", "1e400", "nan"]  # fmt: skip
NUM = st.one_of(st.sampled_from(EDGES), st.floats(1e-12, 1e12).map(lambda x: f"{x:.6g}"))


@st.composite
def isolate_lines(draw: st.DrawFn) -> list[str]:
    cmd = draw(st.sampled_from(["design", "tune", "claims"]))
    argv = ["isolate", cmd]
    if cmd == "design":
        argv += draw(
            st.sampled_from(
                [
                    ["--freq", f"{draw(NUM)} Hz"],
                    ["--omega", f"{draw(NUM)} rad/s"],
                    ["--freq-band", f"{draw(NUM)}:{draw(NUM)}"],
                    ["--omega-band", f"{draw(NUM)}:{draw(NUM)}"],
                    ["--freq-band", f"{draw(NUM)}:{draw(NUM)}", "--mu", draw(NUM)],
                ]
            )
        )
        mass = draw(st.sampled_from(["450", "450", "450", draw(NUM)]))
        argv += ["--mass", f"{mass} kg"]  # the design needs the package's mass
        if draw(st.booleans()):
            argv += ["--target", draw(NUM)]
    elif cmd == "tune":
        argv += ["--mu", draw(NUM)]
        if draw(st.booleans()):
            argv += ["--band", f"{draw(NUM)}:{draw(NUM)}"]
        if draw(st.booleans()):
            argv += ["--zeta", draw(NUM)]
    else:
        argv += ["--mu-max", draw(NUM)]
    return [*argv, "--json"]


@given(isolate_lines())
@fuzz_settings(n_ci=200, n_long=3_000, deadline_s=20)
def test_fuzz_extreme_isolation_values(argv: list[str]) -> None:
    out, err = io.StringIO(), io.StringIO()
    try:
        with time_limit(30), warnings.catch_warnings():
            warnings.simplefilter("error")
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                rc = main(argv)
    except Hang:
        record("extreme values", "hang")
        raise
    except Exception:
        record("extreme values", "traceback")
        raise
    if rc == 0:
        json.loads(out.getvalue(), parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
        record("extreme values", "valid result")
    else:
        assert rc == 2, (argv, rc, err.getvalue())
        assert one_line(err.getvalue()) and out.getvalue() == "", (argv, err.getvalue())
        record("extreme values", "clean error")
