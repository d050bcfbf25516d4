"""``load_model``'s dispatch by suffix: every deck suffix NASTRAN users write is read as a
deck, and NASTRAN output that is not a model is refused naming what to give instead."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from microg.cli import main
from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.bdf import load_bdf
from microg.models.file_units import parse_units
from microg.models.load import DECK_SUFFIXES, load_model
from microg.structure.discretize import discretize

DATA = Path(__file__).resolve().parents[1] / "data" / "nastran"
UNITS = "mm, mN, s"  # the outboard bulk data's own (tests/validation/test_nastran_bar_mass.py)


@pytest.mark.parametrize("suffix", DECK_SUFFIXES)
def test_every_deck_suffix_reads_the_same_deck(suffix, tmp_path):
    p = tmp_path / f"outboard{suffix}"
    shutil.copyfile(DATA / "cla_outboard.blk", p)
    got = load_model(p, units=UNITS, coupled_mass="consistent")
    want = load_bdf(DATA / "cla_outboard.blk", units=parse_units(UNITS), coupled_mass="consistent")
    a, b = (solve_modes(discretize(g)) for g in (got, want))
    np.testing.assert_array_equal(a.omega, b.omega)  # the same deck, the same solve: bit for bit


def test_a_blk_file_takes_units_on_the_command_line(capsys):
    # a .blk was once taken for a station name, and --units was refused for it
    assert main(["modes", str(DATA / "cla_outboard.blk"), "--units", UNITS, "--n-modes", "8"]) == 0
    assert "coupled" in capsys.readouterr().out  # the deck's PARAM,COUPMASS,1, stated


@pytest.mark.parametrize("suffix, what", [(".pch", "punch file"), (".f06", "F06")])
def test_nastran_output_that_is_not_a_model_is_refused(suffix, what, tmp_path, capsys):
    p = tmp_path / f"run{suffix}"
    p.write_text("$ not a model\n")
    with pytest.raises(InputError, match=what):
        load_model(p, units="in, lbf, s")
    assert main(["modes", str(p), "--units", "in, lbf, s"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ".op2" in err


def test_the_superelement_fix_names_the_option_once(capsys):
    assert main(["modes", str(DATA / "notall6_msc2017.op4"), "--units", "in, lbf, s"]) == 2
    err = capsys.readouterr().err
    assert err.count("--superelement") == 1 and "superelement=N" not in err
