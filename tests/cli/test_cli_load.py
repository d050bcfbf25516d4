"""The ``microg`` process reads a station in a forked child (microg.cli._load): the same model.

References: :func:`microg.load_model` in a plain interpreter (no start-up changes, no fork),
compared through the pickled bytes of the model; ``microg modes --json`` run through
:func:`microg.cli.main` with an argument list (a library caller: nothing forked), compared
with the command's output as a process, text for text.
"""

from __future__ import annotations

import json
import subprocess
import sys

from microg.models.load import loads_station

PROCESS = r"""
import json, pickle, sys
from microg.cli._startup import install
install()
from microg.cli import _load
import microg._fork as fork
seen = {}
start = fork.Forked.start
def spy(*a, **k):
    p = start(*a, **k)
    seen["forked"] = p.forked
    return p
fork.Forked.start = spy
model = _load.load_model("ioc")
print(json.dumps({"model": pickle.dumps(model, protocol=5).hex(), "forked": seen.get("forked"),
                  "pydantic": "pydantic" in sys.modules, "scipy": "scipy" in sys.modules}))
"""

PLAIN = r"""
import json, pickle, microg
print(json.dumps({"model": pickle.dumps(microg.load_model("ioc"), protocol=5).hex()}))
"""

LIBRARY_MODES = r"""
import contextlib, io, sys
from microg.cli import main
buf = io.StringIO()
with contextlib.redirect_stdout(buf):
    code = main(["modes", "ioc", "--json"])
sys.stdout.write(buf.getvalue())
sys.exit(code)
"""


def _run(code: str) -> dict:
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=300
    )
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_the_process_reads_the_station_in_a_child_and_gets_the_same_model():
    forked, plain = _run(PROCESS), _run(PLAIN)
    assert forked["forked"] is True  # read by the child
    assert forked["model"] == plain["model"]  # the same object, bit for bit
    assert forked["pydantic"] is False  # the validation ran in the child only
    assert forked["scipy"] is True  # the frame FE's modules were imported meanwhile


def test_microg_modes_prints_what_the_library_call_prints():
    as_process = subprocess.run(
        [sys.executable, "-m", "microg", "modes", "ioc", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    as_library = subprocess.run(
        [sys.executable, "-c", LIBRARY_MODES],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    assert as_process.stdout == as_library.stdout
    assert json.loads(as_process.stdout)["modes"][6]["freq_hz"] > 0  # the first elastic mode


def test_a_bad_model_is_the_same_one_line_error():
    proc = subprocess.run(
        [sys.executable, "-m", "microg", "modes", "no-such-model", "--json"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 2 and proc.stdout == ""
    assert len(proc.stderr.strip().splitlines()) == 1 and "no-such-model" in proc.stderr


def test_which_models_are_stations():
    assert loads_station("ioc") and loads_station("station.toml")  # shipped name, TOML
    assert not loads_station("modes.npz") and not loads_station("run.op2")
    assert not loads_station("ioc", points="points.toml")  # a points file: a modal model's
