"""Modal and effective masses of an imported NASTRAN residual model (cla_residual.op2).

The file is a Craig-Bampton residual structure: 26 grids and 22 scalar points (the component
modes' coordinates), which have no position and are dropped.  Its mode 12 (6.88 Hz) moves the
scalar points by 1 (generalized-mass-normalised, file units) and the grids by at most 1e-5 in:
scaled to a largest point motion of 1 m its generalized mass is 1.5e11 kg, which is the
definition at work, not a physical mass; the table says so.  The effective masses are not
affected: they sum to the model's mass.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import microg
from microg.cli import main
from microg.models.op2 import read_op2_modes
from microg.structure.discretize import discretize

OP2 = Path(__file__).parents[1] / "data" / "nastran" / "cla_residual.op2"
#: 1 lbf s^2/in in kg (exact by the definitions of the pound, g0 and the inch)
SLINCH_KG = 0.45359237 * 9.80665 / 0.0254


@pytest.fixture(scope="module")
def modes():
    s = discretize(microg.load_model(OP2, units="in, lbf, s"), "fem")
    return s, microg.solve_modes(s)


def test_effective_masses_sum_to_the_grid_point_weight_generators_mass(modes):
    # reference: the file's OGPWG 6x6 rigid-body mass (WTMASS 1), converted here; 1e-12:
    # the rounding of a sum of 66 terms and of the exact rigid modes' construction
    s, m = modes
    ref = read_op2_modes(OP2).rigid_mass[0, 0] * SLINCH_KG
    assert s.total_mass == pytest.approx(ref, rel=1e-12)
    for d in ("x", "y", "z"):
        assert np.sum(m.effective_mass[d]) == pytest.approx(ref, rel=1e-12)


def test_a_mode_on_dropped_scalar_points_is_flagged_not_a_physical_mass(modes, tmp_path, capsys):
    s, m = modes
    assert m.modal_mass[11] > 1e8 * s.total_mass  # mode 12: ~1.5e11 kg
    assert m.modal_mass_exceeds_model[11]
    assert not np.any(m.modal_mass_exceeds_model[m.rigid])
    d = m.to_dict()
    assert "largest point motion of 1 m" in d["modal_mass_normalised_to"]
    assert d["modes"][11]["modal_mass_exceeds_model_mass"] is True
    assert main(["modes", str(OP2), "--units", "in, lbf, s"]) == 0
    out = capsys.readouterr().out
    note = next(line for line in out.splitlines() if "above the model's" in line)
    assert " 12," in note and "not a physical mass" in note
    assert "modal mass: shape scaled to a largest point motion of 1 m" in out


def test_no_mode_of_the_shipped_frame_model_is_flagged():
    s = discretize(microg.load_station("ioc"), "fem")
    m = microg.solve_modes(s, n_modes=30)
    assert not m.modal_mass_exceeds_model.any()
    json.dumps(m.to_dict())  # JSON-ready
