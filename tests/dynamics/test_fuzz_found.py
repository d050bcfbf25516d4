"""The solver-stage failures the model fuzzer found (``tests/data/fuzz_found/``), now fixed.

Each file is a valid model on which ``solve_modes(discretize(station, "fem", n=2))`` once
broke an invariant of a free 3-D model (second line of the file).  The invariant is the
fuzzer's own (``tests/fuzz/test_fuzz_models._physics_problem``: exactly 6 rigid modes,
shapes M- and K-orthogonal to 1e-9); a model that is a mechanism is refused with one line
naming the body and the fix instead.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FOUND = ROOT / "tests" / "data" / "fuzz_found"
sys.path.insert(0, str(ROOT / "tests" / "fuzz"))

from test_fuzz_models import _physics_problem  # noqa: E402

from microg.dynamics.modes import solve_modes  # noqa: E402
from microg.errors import InputError  # noqa: E402
from microg.models.toml import loads_station  # noqa: E402
from microg.structure.discretize import discretize  # noqa: E402

#: mechanisms: the rotation has neither inertia nor stiffness, so no free-free solve exists
MECHANISMS = {
    "model-59f7998c33.toml": "masses lie on one line",
    "model-dafd9c303a.toml": "all its mass is at one point",
}


@pytest.mark.parametrize("path", sorted(FOUND.glob("model-*.toml")), ids=lambda p: p.name)
def test_fuzz_found_model_solves_or_is_refused_by_name(path: Path) -> None:
    station = loads_station(path.read_text(encoding="utf-8"), filename=path.name)
    if path.name in MECHANISMS:
        with pytest.raises(InputError) as err:
            solve_modes(discretize(station, "fem", n=2))
        msg = str(err.value)
        assert "\n" not in msg and MECHANISMS[path.name] in msg and "body main" in msg
        return
    structure = discretize(station, "fem", n=2)
    modes = solve_modes(structure)
    assert _physics_problem(structure, modes) is None
