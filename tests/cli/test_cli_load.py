"""``microg modes`` loads its model as the library does.

Reference: ``microg modes --json`` run through :func:`microg.cli.main` with an argument list
(a library caller), compared with the command's output as a process, text for text.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from microg.models.load import loads_station

LIBRARY_MODES = r"""
import contextlib, io, sys
from microg.cli import main
buf = io.StringIO()
with contextlib.redirect_stdout(buf):
    code = main(["modes", "ioc", "--json"])
sys.stdout.write(buf.getvalue())
sys.exit(code)
"""


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


def test_op4_superelement_and_its_dof_map_in_the_output(capsys):
    """An OP4 of three superelements: refused without --superelement (one line, exit 2),
    read with it, the DOF map's source said (truth of the numbers:
    tests/validation/test_nastran_op4_real.py)."""
    pytest.importorskip("pyyeti")
    from microg.cli import main

    op4 = Path(__file__).resolve().parents[1] / "data" / "nastran" / "extseout_nas2cam.op4"
    rc = main(["modes", str(op4), "--units", "mm,N,s"])
    out, err = capsys.readouterr()
    assert rc == 2 and err.count("\n") == 1
    assert "matrices of superelements 101, 102, 0" in err and "--superelement" in err
    rc = main(["modes", str(op4), "--units", "mm,N,s", "--superelement", "102", "--n-modes", "8"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    assert "DOF map from" in out and "USETTAB, EQEXINS, CSTMS, BGPDTS of superelement 102" in out
    assert "8 scalar point(s) (SPOINT, first 2995001)" in out
    rc = main(["locate", str(op4), "--units", "mm,N,s", "--superelement", "0", "--at", "grid:3"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    assert "DOF map from" in out
