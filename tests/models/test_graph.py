"""Tests of microg.models.graph: validation, the graph TOML reader and writer.

References: the format's own
specification (``docs/model-format.md``, "Graph models", whose example is loaded here),
and the round trip through :func:`dump_graph`.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.errors import InputError, ModelError
from microg.models.graph import (
    GraphModel,
    dump_graph,
    load_graph,
    loads_graph,
    parse_components,
)
from microg.structure.frame import build_frame
from microg.units import FT, LBF, SLUG

DOC = Path(__file__).resolve().parents[2] / "docs" / "model-format.md"

SMALL = """
[graph]
name = "frame"
units = "SI"
mass = "consistent"

[[frame]]
name = "cyl"
kind = "cylindrical"
origin = [0, 0, 0]
z_axis = "+z"
xz_point = [1, 0, 0]

[[node]]
name = "a"
at = [0, 0, 0]
[[node]]
name = "b"
at = [2, 0, 0]
frame = "cyl"
[[node]]
name = "c"
at = [2, 2, 0]
[[node]]
name = "p"
at = [2, 2, 0]

[[section]]
name = "tube"
ea = "2e8 N"
ei = 5e5
gj = "3e5 N*m^2"
mass_per_length = "4 kg/m"
shear_y = "1e8 N"
shear_z = "1e8 N"
rotary_inertia = true

[[beam]]
name = "ab"
nodes = ["a", "b"]
section = "tube"
[[beam]]
name = "bc"
nodes = ["b", "c"]
section = "tube"
orientation = [1, 0, 0]
kind = "bar"
[[rod]]
name = "ca"
nodes = ["c", "a"]
ea = "1e7 N"
mass_per_length = "1 kg/m"

[[spring]]
name = "iso"
nodes = ["c", "p"]
axes = "basic"
stiffness.x = "1e4 N/m"
stiffness.y = "1e4 N/m"
stiffness.z = "2e4 N/m"
stiffness.rx = "50 N*m/rad"
stiffness.ry = 50
stiffness.rz = "60 N*m/rad"
damping = { z = "20 N*s/m" }

[[mass]]
name = "payload"
node = "p"
mass = "20 kg"
at = [2, 2, 0.1]
inertia = { xx = "1 kg*m^2", yy = 2, zz = 3, xy = 0.1 }

[[rigid]]
name = "tie"
independent = "a"
dependents = ["a2"]

[[node]]
name = "a2"
at = [0, 0, 0.5]

[[mass]]
name = "m2"
node = "a2"
mass = 5

[[point]]
name = "crew"
node = "c"
at = [2, 2.2, 0]
kind = "crew"
"""


# --------------------------------------------------------------------------- components


def test_components_parsing():
    assert parse_components(123456, where="w") == "123456"
    assert parse_components("31", where="w") == "13"
    for bad in ("127", "11", "", 0, True):
        with pytest.raises(InputError):
            parse_components(bad, where="w")


# --------------------------------------------------------------------------- reader


def test_small_graph_reads_in_si():
    g = loads_graph(SMALL, filename="frame.toml")
    assert g.mass_formulation == "consistent" and len(g.nodes) == 5
    sec = g.beams[0].section
    assert sec.ei_y_N_m2 == sec.ei_z_N_m2 == 5e5 and sec.shear_y_N == 1e8
    # homogeneous-section defaults: rho J = m' (EI_y + EI_z)/EA, rotary rho I = m' EI/EA
    assert sec.polar_mass_kg_m == pytest.approx(4 * 1e6 / 2e8)
    assert sec.rotary_y_kg_m == pytest.approx(4 * 5e5 / 2e8)
    # node b's displacement axes are the cylinder's at (2, 0, 0): radial +x, tangential +y
    np.testing.assert_allclose(g.node("b").axes, np.eye(3), atol=1e-15)
    # default orientation of ab (along x): the least aligned axis, y
    np.testing.assert_allclose(g.beams[0].orientation, [0, 1, 0])
    m = {x.name: x for x in g.masses}
    np.testing.assert_allclose(m["payload"].offset_m, [0, 0, 0.1])
    assert m["payload"].inertia_kg_m2[0, 1] == 0.1
    assert g.springs[0].stiffness[4, 4] == 50.0 and g.springs[0].damping[2, 2] == 20.0
    s = build_frame(g)
    modes = solve_modes(s)
    assert modes.n_rigid == 6 and s.point("crew").position[1] == 2.2


def test_us_units_and_rotational_spring_units():
    text = SMALL.replace('units = "SI"', 'units = "US"')
    g = loads_graph(text)
    # bare numbers take US units: ei 5e5 lbf ft^2, ry 50 lbf ft/rad, mass 5 slug
    assert g.beams[0].section.ei_y_N_m2 == pytest.approx(5e5 * LBF * FT**2, rel=1e-14)
    assert g.springs[0].stiffness[4, 4] == pytest.approx(50 * LBF * FT, rel=1e-14)
    assert g.springs[0].stiffness[3, 3] == pytest.approx(50.0, rel=1e-14)  # "50 N*m/rad"
    assert {m.name: m.mass_kg for m in g.masses}["m2"] == pytest.approx(5 * SLUG, rel=1e-14)
    with pytest.raises(ModelError, match="is not a rotational stiffness"):
        loads_graph(SMALL.replace('rx = "50 N*m/rad"', 'rx = "50 N/m"'))


def test_dump_and_reload_reproduce_the_model():
    g = loads_graph(SMALL, filename="frame.toml")
    text = dump_graph(g)
    g2 = loads_graph(text, filename="dump.toml")
    s1, s2 = build_frame(g), build_frame(g2)
    m1, k1 = s1.dense() if not s1.is_sparse else (s1.mass.toarray(), s1.stiffness.toarray())
    m2, k2 = s2.dense() if not s2.is_sparse else (s2.mass.toarray(), s2.stiffness.toarray())
    # 17 significant digits written: the matrices agree to rounding (1e-14 of the largest)
    np.testing.assert_allclose(k2, k1, rtol=0, atol=1e-14 * np.abs(k1).max())
    np.testing.assert_allclose(m2, m1, rtol=0, atol=1e-14 * np.abs(m1).max())
    for a, b in zip(g.nodes, g2.nodes, strict=True):
        assert a.name == b.name and np.allclose(a.position, b.position, rtol=1e-15)
        np.testing.assert_allclose(a.axes, b.axes, atol=1e-15)
    assert [p.name for p in g2.points] == ["crew"]


@pytest.mark.parametrize(
    ("edit", "where", "what"),
    [
        (("[graph]\n", "[graph]\nbogus = 1\n"), "graph.bogus", "unknown key"),
        (('name = "ab"\n', 'name = "ab"\nlenght = 1\n'), "beam[0].lenght", "unknown key"),
        (('nodes = ["a", "b"]\nsection', 'nodes = ["a", "zz"]\nsection'), "ab", "does not exist"),
        (
            ('section = "tube"\n[[beam]]', 'section = "pipe"\n[[beam]]'),
            "beam[0].section",
            "unknown section",
        ),
        (('ea = "2e8 N"', 'ea = "2e8 kg"'), "section[0].ea", "not"),
        (('ea = "2e8 N"', "ea = 2e8\nei_y = 1"), "section[0].ei", "either ei"),
        (('at = [2, 0, 0]\nframe = "cyl"', 'at = [0, 0, 0]\nframe = "cyl"'), "ab", "zero length"),
        (
            ('orientation = [1, 0, 0]\nkind = "bar"', 'orientation = [0, 1, 0]\nkind = "bar"'),
            "bc",
            "parallel",
        ),
        (('axes = "basic"\n', ""), "spring[0]", "coordinate system"),
        (("xy = 0.1", "xy = 3"), "payload", "positive semidefinite"),
        (
            ('mass = "consistent"', 'mass = "diagonal"'),
            "graph.mass",
            "'lumped', 'consistent', 'coupled' or",
        ),
        # the structure (pydantic, as for station files): tables, kinds of value, counts
        (("[[rod]]", "[[bogus]]\n[[rod]]"), "frame.toml: bogus", "unknown key"),
        (('nodes = ["c", "a"]', 'nodes = ["c"]'), "rod[0].nodes", "expected two node names"),
        (('dependents = ["a2"]', "dependents = []"), "rigid[0].dependents", "non-empty array"),
        (
            ('axes = "basic"', "axes = [[1, 0, 0], [0, 1, 0], [0, 0, 2]]"),
            "spring[0].axes",
            "orthonormal",
        ),
        (("damping = { z", "damping = { q"), "spring[0].damping.q", "allowed keys here: x, y"),
        (('kind = "crew"', 'kind = "pilot"'), "point[0].kind", "'crew', 'experiment' or 'point'"),
        (("at = [2, 2.2, 0]", "at = [2, 2.2]"), "point[0].at", "three lengths"),
        (
            ("rotary_inertia = true", 'rotary_inertia = "yes"'),
            "section[0].rotary_inertia",
            "true or false",
        ),
    ],
)
def test_bad_graph_files_are_one_line_errors(edit, where, what):
    text = SMALL.replace(*edit)
    assert text != SMALL
    with pytest.raises(InputError) as exc:
        loads_graph(text, filename="frame.toml")
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("frame.toml") and where in msg and what in msg, msg


def test_syntax_error_and_missing_file(tmp_path):
    with pytest.raises(ModelError, match="invalid TOML"):
        loads_graph("[graph\nname=1", filename="x.toml")
    with pytest.raises(ModelError, match=r"x.toml: graph: required table is missing \(add it"):
        loads_graph("[[node]]\nname='a'\nat=[0,0,0]\n", filename="x.toml")
    with pytest.raises(InputError, match="cannot read"):
        load_graph(tmp_path / "none.toml")


def test_unknown_node_lists_nearest_grids():
    g = GraphModel("g", tuple(loads_graph(SMALL).nodes))
    with pytest.raises(InputError, match="unknown node 'x'"):
        g.node("x")


# --------------------------------------------------------------------------- docs


def test_documented_example_loads_and_solves():
    # the "Graph models" section's example is valid and free-free (6 exact rigid modes)
    text = DOC.read_text()
    section = text[text.index("## Graph models") :]
    block = re.search(r"```toml\n(.*?)```", section, re.S)
    assert block is not None
    g = loads_graph(block.group(1), filename="example.toml")
    modes = solve_modes(build_frame(g))
    assert modes.n_rigid == 6 and np.all(modes.omega[:6] == 0.0)
