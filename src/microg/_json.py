"""Floats for strict JSON: the two conventions the results use, in one place.

JSON has no NaN or infinity (``json.dumps(..., allow_nan=False)`` refuses them), so every
``to_dict()`` turns non-finite floats into something JSON holds:

* :func:`json_number` (and :func:`json_numbers`, :func:`json_nested`, :func:`json_by_name`):
  +-inf as the strings ``"inf"``/``"-inf"`` and NaN as None.  ``"inf"`` is the documented
  form of an infinite margin (a band with no power); None means "not computed"
  (docs/architecture.md).
* :func:`finite_or_none` (and :func:`finite_list`): every non-finite value as None, for
  quantities where an infinity carries no meaning of its own (a band's edges, an FRF).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = [
    "finite_list",
    "finite_or_none",
    "json_by_name",
    "json_nested",
    "json_number",
    "json_numbers",
]


def json_number(value: float) -> float | str | None:
    """A float for JSON: finite as is, +-inf as ``"inf"``/``"-inf"``, NaN as None.

    Parameters
    ----------
    value : float
        Any real number (numpy scalars included), in its own unit.
    """
    v = float(value)
    if math.isfinite(v):
        return v
    if math.isnan(v):
        return None
    return "inf" if v > 0 else "-inf"


def json_numbers(values: Any) -> list[float | str | None]:
    """:func:`json_number` of every element of ``values``, flattened (C order) to a list.

    Parameters
    ----------
    values : array_like
        Real numbers, any shape, in their own unit.
    """
    return [json_number(v) for v in np.ravel(values)]


def json_nested(values: Any) -> Any:
    """:func:`json_number` of every element, keeping the shape as nested lists.

    Parameters
    ----------
    values : array_like
        Real numbers, any shape, in their own unit (a 0-d array gives a scalar).
    """
    return np.vectorize(json_number, otypes=[object])(np.asarray(values, float)).tolist()


def finite_or_none(value: float) -> float | None:
    """A float for JSON: finite as is, any non-finite value (NaN, +-inf) as None.

    Parameters
    ----------
    value : float
        Any real number, in its own unit.
    """
    v = float(value)
    return v if math.isfinite(v) else None


def finite_list(values: Any) -> list[float | None]:
    """:func:`finite_or_none` of every element of ``values``, flattened (C order) to a list.

    Parameters
    ----------
    values : array_like
        Real numbers, any shape, in their own unit.
    """
    return [finite_or_none(v) for v in np.ravel(np.asarray(values, float))]


def json_by_name(names: Any, values: Any) -> dict[str, Any]:
    """``{name: json_nested(row)}`` over the first dimension of ``values`` (one row per name).

    Parameters
    ----------
    names : sequence of str
        One name per row (for example the axes ``x``, ``y``, ``z``).
    values : array_like
        Real numbers, shape (len(names), ...) (a 1-D array is one row), in their own unit.
    """
    return {n: json_nested(r) for n, r in zip(names, np.atleast_2d(values), strict=True)}
