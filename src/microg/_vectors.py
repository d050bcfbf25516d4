"""The one direction parser: axis names and 3-vectors -> unit vectors in the station frame.

Accepted forms, everywhere a direction is read (CLI options, model files, force files,
study files, the Python API):

* an axis name with at most one sign: ``"x"``, ``"+y"``, ``"-z"`` (case-insensitive);
* three finite numbers, not all zero: ``"1 0 0"``, ``"1, 0, 0"``, ``[0, 0.6, 0.8]``, or
  a numpy array of shape (3,).

Anything else is an :class:`~microg.errors.InputError` naming ``where``.  The vector is
returned normalised; its norm is computed with scaling so that components as large as
1e308 neither overflow nor warn.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = ["AXES", "AXIS_NAMES", "DIRECTION_FIX", "axis_name", "parse_direction"]

#: unit vectors of the station axes
AXES: dict[str, np.ndarray] = {
    "x": np.array([1.0, 0.0, 0.0]),
    "y": np.array([0.0, 1.0, 0.0]),
    "z": np.array([0.0, 0.0, 1.0]),
}
AXIS_NAMES = ("x", "y", "z")
#: the accepted forms, for error messages
DIRECTION_FIX = "write x, y, z, -x, ... or three numbers such as '1 0 0'"

_AXIS = re.compile(r"^([+-]?)([xyz])$")
_NUMBER = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?$")


def _unit(vec: np.ndarray, text: Any, where: str) -> np.ndarray:
    if vec.shape != (3,) or not np.all(np.isfinite(vec)) or not np.any(vec):
        raise InputError(f"cannot read direction {text!r}", where=where, fix=DIRECTION_FIX)
    scale = float(np.max(np.abs(vec)))
    v = vec / scale  # largest component 1: no overflow in the norm
    return v / math.sqrt(float(v @ v))


def parse_direction(value: str | Sequence[float] | np.ndarray, where: str) -> np.ndarray:
    """Unit vector of a direction given as an axis name or three numbers.

    Parameters
    ----------
    value : str, sequence of 3 floats, or ndarray (3,)
        ``"x"``, ``"-z"``, ``"1 0 0"``, ``"0.6, 0, 0.8"``, ``[0, 1, 0]`` (dimensionless).
    where : str
        Where the value came from (parameter, option or ``file: field``), for the error.

    Returns
    -------
    ndarray (3,)
        The unit vector, station frame.
    """
    if isinstance(value, str):
        token = value.strip().lower()
        m = _AXIS.match(token.replace(" ", ""))
        if m:
            return (-1.0 if m.group(1) == "-" else 1.0) * AXES[m.group(2)].copy()
        parts = [p for p in re.split(r"[\s,;]+", token) if p]
        if len(parts) != 3 or not all(_NUMBER.match(p) for p in parts):
            raise InputError(f"cannot read direction {value!r}", where=where, fix=DIRECTION_FIX)
        return _unit(np.array([float(p) for p in parts]), value, where)
    if isinstance(value, bool):
        raise InputError(f"cannot read direction {value!r}", where=where, fix=DIRECTION_FIX)
    try:
        items = list(value)  # type: ignore[arg-type]
    except TypeError:
        raise InputError(
            f"cannot read direction {value!r}", where=where, fix=DIRECTION_FIX
        ) from None
    if len(items) != 3 or any(
        isinstance(c, bool) or not isinstance(c, int | float | np.integer | np.floating)
        for c in items
    ):
        raise InputError(f"cannot read direction {value!r}", where=where, fix=DIRECTION_FIX)
    return _unit(np.array(items, dtype=float), value, where)


def axis_name(direction: np.ndarray, tol: float = 1e-12) -> str | None:
    """``"x"``, ``"-y"``, ... when ``direction`` is a signed station axis, else None."""
    d = np.asarray(direction, float)
    for name, a in AXES.items():
        for sign, prefix in ((1.0, ""), (-1.0, "-")):
            if np.max(np.abs(d - sign * a)) <= tol:
                return prefix + name
    return None
