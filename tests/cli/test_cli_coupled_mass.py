"""``--coupled-mass`` on every command that reads a model: it reaches the model and the output."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from microg.cli import main

DATA = Path(__file__).resolve().parents[1] / "data" / "nastran"
UNITS = "mm, mN, s"  # the deck's own (tests/validation/test_nastran_bar_mass.py)


@pytest.fixture
def deck(tmp_path: Path) -> Path:
    # Simcenter 2020.2's outboard bulk data, PARAM,COUPMASS,1, read as a deck
    p = tmp_path / "outboard.dat"
    p.write_text((DATA / "cla_outboard.blk").read_text())
    return p


@pytest.mark.parametrize("command", ["modes", "analyze", "locate"])
def test_every_model_command_takes_the_option(command, capsys):
    assert main([command, "--help"]) == 0
    assert "--coupled-mass" in capsys.readouterr().out


def test_analyze_and_locate_use_and_state_the_choice(deck, capsys):
    base = [str(deck), "--units", UNITS, "--at", "grid:1"]
    first = {}
    for form in ("coupled", "coupled-nx9"):
        rc = main(["analyze", *base, "--observe", "grid:3", "--no-progress", "--json",
                   "--coupled-mass", form])  # fmt: skip
        out, _ = capsys.readouterr()
        assert rc == 0
        doc = json.loads(out)
        assert doc["meta"]["mass_formulation"] == form
        first[form] = doc["modes"]["modes"][6]["freq_hz"]
        rc = main(["locate", *base, "--json", "--coupled-mass", form])
        out, _ = capsys.readouterr()
        assert rc == 0
        assert json.loads(out)["mass_formulation"].startswith(f"{form} (PARAM,COUPMASS,1")
    # the two forms differ in the ends' rotation coupling: the first elastic frequency moves
    # (1.7551 vs 1.7577 Hz measured), so the option did reach the model
    assert first["coupled-nx9"] / first["coupled"] - 1 > 1e-4
    rc = main(["locate", *base, "--coupled-mass", "coupled-nx9"])
    out, _ = capsys.readouterr()
    assert rc == 0 and out.splitlines()[1].startswith("mass: coupled-nx9 (PARAM,COUPMASS,1")
