"""Tests of microg.location.sampling: sample lines, nodes of the fundamental, in-plane energy."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff
from microg.dynamics.forces import REPORT_F0_N
from microg.dynamics.modes import solve_modes
from microg.location.amap import acceleration_map
from microg.location.sampling import (
    BODY_LINE_SAMPLES,
    element_lines,
    find_nodes,
    sample_lines,
    sample_shapes,
)
from microg.models.station import NamedPoint
from microg.models.toml import load_station
from microg.structure.discretize import discretize

CREW = CrewPushoff(REPORT_F0_N)


@pytest.fixture(scope="module")
def ioc():
    station = load_station("ioc")
    structure = discretize(station, "ritz", plane="xz", n=1)
    modes = solve_modes(structure)
    return station, structure, modes, acceleration_map(structure, modes, "crew", "x", CREW)


def _station_with_point(station, name, on, position):
    pts = (*station.points, NamedPoint(name, on, np.asarray(position, float)))
    return dataclasses.replace(station, points=pts)


def test_nodes_are_zeros_of_the_fundamental(ioc):
    station, _, modes, ioc_map = ioc
    assert ioc_map.nodes, "the IOC fundamental has nodes"
    j = ioc_map.fundamental
    assert modes.omega[j] == pytest.approx(1.0175, rel=1e-3)  # the lowest excited mode
    scale = np.max(np.abs(ioc_map.fundamental_shape))
    for node in ioc_map.nodes:
        # reference: a named point placed at the node, its map built by the Ritz engine
        st = _station_with_point(station, "probe", node.component, node.position)
        s = discretize(st, "ritz", plane="xz", n=1)
        value = (s.point("probe").translation @ modes.phi[:, j])[0]
        carrier = st.component(node.component)
        if hasattr(carrier, "length"):
            # beam: linear interpolation of a cubic between samples 1/40 of the beam apart,
            # error <= (h/L)^2 max|psi''|/8 ~ 2e-4 of the peak; 2e-3 leaves margin
            assert abs(value) < 2e-3 * scale
        else:
            # rigid body: the displacement is affine, interpolation is exact to rounding
            assert abs(value) < 1e-10 * scale


def test_rigid_body_line_is_densified_exactly(ioc):
    # the main body's samples are collinear and every shape is affine along them: the line
    # is rigid and filled to BODY_LINE_SAMPLES samples by the affine law, which must agree
    # with the Ritz engine's own map at a point placed between two masses
    station, structure, modes, _ = ioc
    pos, comp, shapes = sample_shapes(structure, modes.phi)
    pos2, comp2, shapes2, lines = sample_lines(pos, comp, shapes)
    (main,) = [ln for ln in lines if ln.component == "main"]
    assert main.rigid and main.index.size >= BODY_LINE_SAMPLES
    beams = [ln for ln in lines if ln.component != "main"]
    assert beams and not any(ln.rigid for ln in beams)
    k = main.index[main.index >= pos.shape[0]][7]  # a densified sample
    st = _station_with_point(station, "probe", "main", pos2[k])
    ref = discretize(st, "ritz", plane="xz", n=1).point("probe").translation @ modes.phi
    # affine interpolation of affine data: rounding only
    np.testing.assert_allclose(shapes2[k], ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())


def test_find_nodes_on_a_straight_line():
    # exact reference: a linear displacement y = t - 0.3 on a line of 11 samples has its zero
    # at t = 0.3; linear interpolation of a linear function is exact
    from microg.location.sampling import SampleLine

    t = np.linspace(0.0, 1.0, 11)
    positions = np.column_stack([np.zeros(11), np.zeros(11), t])
    line = SampleLine("rod", np.arange(11), positions[0], np.array([0.0, 0.0, 1.0]), True)
    (node,) = find_nodes([line], positions, t - 0.3)
    assert node.distance == pytest.approx(0.3, abs=1e-14)
    assert node.to_dict()["position_m"][2] == pytest.approx(0.3, abs=1e-14)
    assert find_nodes([line], positions, t + 1.0) == ()


def test_element_lines_are_the_straight_chains_of_elements():
    # a chain 0-1-2-3 along x (element 1-2 given twice, once reversed, and a zero-length
    # element 3-4), a branch 1-5 perpendicular at node 1, and a bent pair 5-6 / 6-7
    pos = np.array(
        [[0, 0, 0], [1, 0, 0], [2, 0, 0], [4, 0, 0], [4, 0, 0], [1, 1, 0], [1, 2, 0], [2, 3, 0]],
        float,
    )
    seg = np.array([[0, 1], [1, 2], [2, 1], [2, 3], [3, 4], [1, 5], [5, 6], [6, 7]])
    labels = [f"g{i}" for i in range(8)]
    lines = {ln.component: ln for ln in element_lines(pos, seg, labels=labels)}
    # reference: the chains by hand (a T joint keeps the straight chain; a bend ends a line)
    assert set(lines) == {"g0..g3", "g1..g6", "g6..g7"}
    chain = lines["g0..g3"]
    assert chain.index.tolist() == [0, 1, 2, 3] and not chain.rigid
    np.testing.assert_array_equal(chain.axis, [1.0, 0.0, 0.0])
    np.testing.assert_array_equal(chain.origin, pos[0])
    assert lines["g1..g6"].index.tolist() == [1, 5, 6]
    # three collinear elements at one node (0-1, 1-2 and an overlapping 1-3): no line
    # continues through node 1, each element is its own line
    three = element_lines(pos, np.array([[0, 1], [1, 2], [1, 3]]))
    assert sorted(ln.index.tolist() for ln in three) == [[0, 1], [1, 2], [1, 3]]
    # elements whose both ends are already on a line are left out
    covered = np.zeros(8, bool)
    covered[[0, 1, 2, 3]] = True
    rest = element_lines(pos, seg, labels=labels, covered=covered)
    assert {ln.component for ln in rest} == {"g1..g6", "g6..g7"}
    assert element_lines(pos, np.zeros((0, 2), int)) == []
