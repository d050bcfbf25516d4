"""Units at the boundary: SI conversion, Hz against rad/s, non-finite values."""

from __future__ import annotations

import math

import pytest

from microg.errors import InputError
from microg.units import parse_quantity


@pytest.mark.parametrize(
    ("text", "dimension", "expected"),
    [
        ("296 ft", "length", 296 * 0.3048),  # exact foot
        ("25 lbf", "force", 25 * 0.45359237 * 9.80665),  # exact pound-force
        ("1 slug*ft^2", "rotary_inertia", 14.593902937206364 * 0.3048**2),
        ("1 Hz", "angular_frequency", 2 * math.pi),  # pint alone would give 1 rad/s
        ("1 rad/s", "angular_frequency", 1.0),
        ("60 rpm", "angular_frequency", 2 * math.pi),
        ("2 Hz", "frequency", 2.0),
        ("1 rad/s", "frequency", 1 / (2 * math.pi)),
        ("60 rpm", "frequency", 1.0),
    ],
)
def test_conversions(text: str, dimension: str, expected: float) -> None:
    assert parse_quantity(text, dimension, where="t") == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("text", ["nan s", "inf s", "-inf s", "1e400 s"])
def test_non_finite_rejected(text: str) -> None:
    with pytest.raises(InputError, match="finite"):
        parse_quantity(text, "time", where="--dt")


def test_wrong_dimension_names_the_field() -> None:
    with pytest.raises(InputError) as exc:
        parse_quantity("3 m", "force", where="--f0")
    assert str(exc.value).startswith("--f0:") and "not a force" in str(exc.value)


def test_bare_number_needs_default_unit() -> None:
    with pytest.raises(InputError, match="no unit"):
        parse_quantity(3.0, "length", where="beam.length")
    assert parse_quantity(3.0, "length", where="x", default_unit="ft") == pytest.approx(0.9144)
