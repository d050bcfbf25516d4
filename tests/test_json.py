"""microg._json: the two JSON conventions for non-finite floats, element by element.

Reference: the values written out by hand (the conventions are definitions, so the check is
exact equality), and ``json.dumps(..., allow_nan=False)`` accepting every output.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from microg._json import (
    finite_list,
    finite_or_none,
    json_by_name,
    json_nested,
    json_number,
    json_numbers,
)

VALUES = np.array([[1.5, np.inf, -np.inf], [np.nan, 0.0, -2.0]])


def test_json_number_keeps_infinity_as_a_string_and_nan_as_none():
    assert json_number(np.float32(1.5)) == 1.5 and type(json_number(np.int64(3))) is float
    assert [json_number(v) for v in (np.inf, -np.inf, np.nan)] == ["inf", "-inf", None]
    assert json_numbers(VALUES) == [1.5, "inf", "-inf", None, 0.0, -2.0]  # C order
    assert json_nested(VALUES) == [[1.5, "inf", "-inf"], [None, 0.0, -2.0]]
    assert json_nested(np.float64(np.inf)) == "inf" and json_nested(np.zeros((0, 2))) == []
    by = json_by_name(("x", "y"), VALUES)
    assert by == {"x": [1.5, "inf", "-inf"], "y": [None, 0.0, -2.0]}
    assert json_by_name(("x",), VALUES[1]) == {"x": [None, 0.0, -2.0]}  # one row
    json.dumps([by, json_numbers(VALUES)], allow_nan=False)  # strict JSON: no exception


def test_finite_or_none_drops_every_non_finite_value():
    assert finite_or_none(2) == 2.0 and type(finite_or_none(np.float32(2))) is float
    assert [finite_or_none(v) for v in (np.inf, -np.inf, np.nan)] == [None, None, None]
    assert finite_list(VALUES) == [1.5, None, None, None, 0.0, -2.0]
    assert finite_list([]) == []
    json.dumps(finite_list(VALUES), allow_nan=False)


def test_a_name_count_that_differs_from_the_rows_is_refused():
    # zip(..., strict=True): a mislabelled table is a defect, never silently truncated
    with pytest.raises(ValueError):
        json_by_name(("x",), VALUES)
