"""Tests of microg.models.coords: coordinate frames and the CORD2R/C/S chaining.

References: hand values of cylindrical and spherical coordinates and axes; NASTRAN's
CORD2R/C/S definition (QRG: A the origin, B on the z axis, C in the x-z plane, given in the
reference system RID) worked by hand for a chain of systems.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from microg.errors import InputError
from microg.models.coords import (
    BASIC,
    CoordinateFrame,
    Cord2,
    chain_cord2,
    frame_from_points,
    nastran_coordinates,
)


def test_cylindrical_and_spherical_frames_by_hand():
    cyl = frame_from_points("c", "cylindrical", [1, 2, 3], [1, 2, 4], [2, 2, 3], where="t")
    # (r, theta, z) = (2, 90 deg, 1) from origin (1, 2, 3): basic (1, 4, 4)
    np.testing.assert_allclose(cyl.to_basic([2, math.pi / 2, 1]), [1, 4, 4], atol=1e-14)
    np.testing.assert_allclose(
        cyl.axes_at([1, 4, 4]), [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], atol=1e-15
    )
    sph = CoordinateFrame("s", "spherical", np.zeros(3), np.eye(3))
    # (r, theta, phi) = (2, 60 deg, 30 deg): r (sin t cos p, sin t sin p, cos t)
    t, p = math.radians(60), math.radians(30)
    np.testing.assert_allclose(
        sph.to_basic([2, t, p]),
        2 * np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]),
    )
    ax = sph.axes_at(sph.to_basic([2, t, p]))
    np.testing.assert_allclose(ax @ ax.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(ax) == pytest.approx(1.0)
    np.testing.assert_allclose(BASIC.axes_at([5.0, 6, 7]), np.eye(3))
    with pytest.raises(InputError, match="C lies on the z axis"):
        frame_from_points("x", "rectangular", [0, 0, 0], [0, 0, 1], [0, 0, 2], where="t")


def test_nastran_coordinates_convert_degrees_and_scale_lengths():
    # cylindrical (r, theta deg, z) and spherical (r, theta deg, phi deg): only lengths scale
    np.testing.assert_allclose(
        nastran_coordinates("cylindrical", [2.0, 90.0, 3.0], 0.5), [1.0, math.pi / 2, 1.5]
    )
    np.testing.assert_allclose(
        nastran_coordinates("spherical", [[2.0, 90.0, 180.0]], 2.0), [[4.0, math.pi / 2, math.pi]]
    )
    np.testing.assert_allclose(nastran_coordinates("rectangular", [1.0, 2.0, 3.0], 2.0), [2, 4, 6])


def _cord(cid, kind, rid, a, b, c):
    return Cord2(cid, kind, rid, np.array([a, b, c], float), f"deck.bdf: CORD2 {cid}")


def test_chained_systems_by_hand_in_any_order():
    # length unit 0.5 m.  CS 1 (cylindrical): A = (2, 4, 6) units = basic (1, 2, 3) m, z along
    # basic z, x along basic x.  CS 2 (rectangular) in CS 1: A = (r 1, theta 0, z 0) = basic
    # (1.5, 2, 3); B = (1, 0, 1): z' = +z; C = (1, 90 deg, 0) = basic (1, 2.5, 3): x' =
    # (-1, 1, 0)/sqrt 2 and y' = z' x x' = (-1, -1, 0)/sqrt 2.  The child is listed first:
    # the chain is resolved by reference, not by order.
    defs = [
        _cord(2, "rectangular", 1, [1, 0, 0], [1, 0, 1], [1, 90, 0]),
        _cord(1, "cylindrical", 0, [2, 4, 6], [2, 4, 8], [4, 4, 6]),
    ]
    frames = chain_cord2(defs, length=0.5)
    assert set(frames) == {0, 1, 2} and frames[0] is BASIC and frames[2].name == "cs:2"
    np.testing.assert_allclose(frames[1].origin, [1, 2, 3], atol=1e-15)
    np.testing.assert_allclose(frames[2].origin, [1.5, 2, 3], atol=1e-15)  # r = 1 unit = 0.5 m
    s = 1 / math.sqrt(2)
    np.testing.assert_allclose(frames[2].rotation, [[-s, s, 0], [-s, -s, 0], [0, 0, 1]], atol=1e-15)


@pytest.mark.parametrize(
    ("defs", "what", "at"),
    [
        ([_cord(3, "rectangular", 9, [0, 0, 0], [0, 0, 1], [1, 0, 0])], "reference system 9", 3),
        (
            [
                _cord(4, "rectangular", 5, [0, 0, 0], [0, 0, 1], [1, 0, 0]),
                _cord(5, "rectangular", 4, [0, 0, 0], [0, 0, 1], [1, 0, 0]),
            ],
            "cycle",
            4,
        ),
        ([_cord(0, "rectangular", 0, [0, 0, 0], [0, 0, 1], [1, 0, 0])], "basic system", 0),
        ([_cord(6, "spherical", 0, [0, 0, 0], [0, 0, 0], [1, 0, 0])], "A and B coincide", 6),
        ([_cord(7, "rectangular", 0, [0, 0, 0], [0, 0, 1], [0, 0, 2])], "on the z axis", 7),
    ],
)
def test_bad_chains_name_the_definition(defs, what, at):
    with pytest.raises(InputError, match=what) as exc:
        chain_cord2(defs)
    assert str(exc.value).startswith(f"deck.bdf: CORD2 {at}: ")
