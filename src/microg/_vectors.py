"""The one direction parser: axis names and 3-vectors -> unit vectors in the station frame.

Accepted forms, everywhere a direction is read (CLI options, model files, force files,
study files, the Python API):

* an axis name with at most one sign: ``"x"``, ``"+y"``, ``"-z"`` (case-insensitive);
* three finite numbers, not all zero: ``"1 0 0"``, ``"1, 0, 0"``, ``[0, 0.6, 0.8]``, or
  a numpy array of shape (3,).

Anything else is an :class:`~microg.errors.InputError` naming ``where`` (``"+-x"``, ``"x y"``,
``"1,5 0 0"``, booleans, bytes, text longer than :data:`MAX_TEXT` characters, numbers beyond
the floating-point range).  The vector is returned normalised; its norm is computed with
scaling so that components as large as 1e308 neither overflow nor warn.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = ["AXES", "AXIS_NAMES", "DIRECTION_FIX", "MAX_TEXT", "axis_name", "parse_direction"]

#: unit vectors of the station axes
AXES: dict[str, np.ndarray] = {
    "x": np.array([1.0, 0.0, 0.0]),
    "y": np.array([0.0, 1.0, 0.0]),
    "z": np.array([0.0, 0.0, 1.0]),
}
AXIS_NAMES = ("x", "y", "z")
#: the accepted forms, for error messages
DIRECTION_FIX = "write x, y, z, -x, ... or three numbers such as '1 0 0'"
#: longest direction text accepted, characters
MAX_TEXT = 200

_AXIS = re.compile(r"^([+-]?)([xyz])$")
_NUMBER = re.compile(r"^[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?$")


def _fail(text: Any, where: str, why: str = "") -> InputError:
    shown = " ".join(repr(text).split())
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    return InputError(f"cannot read direction {shown}{why}", where=where, fix=DIRECTION_FIX)


def _unit(vec: np.ndarray, text: Any, where: str) -> np.ndarray:
    if vec.shape != (3,) or not np.all(np.isfinite(vec)):
        raise _fail(text, where)
    if not np.any(vec):
        raise _fail(text, where, ": it is the zero vector")
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
        if len(value) > MAX_TEXT:
            raise _fail(value, where, f": longer than {MAX_TEXT} characters")
        token = value.strip().lower()
        m = _AXIS.match(token.replace(" ", ""))
        if m:
            axis = np.zeros(3)
            axis[AXIS_NAMES.index(m.group(2))] = -1.0 if m.group(1) == "-" else 1.0
            return axis
        # one kind of separator: "1 0 0", "1, 0, 0" or "1; 0; 0" ("1,5 0" is not 1, 5, 0)
        sep = "," if "," in token else ";" if ";" in token else None
        parts = [p.strip() for p in token.split(sep)] if sep else token.split()
        if len(parts) != 3 or not all(_NUMBER.match(p) for p in parts):
            raise _fail(value, where)
        vec = np.array([float(p) for p in parts])
        if not np.all(np.isfinite(vec)):
            raise _fail(value, where, ": a component is beyond the floating-point range")
        return _unit(vec, value, where)
    if isinstance(value, bool | bytes | bytearray | dict) or value is None:
        raise _fail(value, where)
    if isinstance(value, np.ndarray) and value.shape != (3,):
        raise _fail(value, where)
    try:
        items = list(value)
    except TypeError:
        raise _fail(value, where) from None
    if len(items) != 3 or any(
        isinstance(c, bool | np.bool_) or not isinstance(c, int | float | np.integer | np.floating)
        for c in items
    ):
        raise _fail(value, where)
    try:
        vec = np.array([float(c) for c in items])
    except OverflowError:
        raise _fail(value, where, ": a component is beyond the floating-point range") from None
    return _unit(vec, value, where)


def axis_name(direction: np.ndarray, tol: float = 1e-12) -> str | None:
    """``"x"``, ``"-y"``, ... when ``direction`` is a signed station axis, else None."""
    d = np.asarray(direction, float)
    for name, a in AXES.items():
        for sign, prefix in ((1.0, ""), (-1.0, "-")):
            if np.max(np.abs(d - sign * a)) <= tol:
                return prefix + name
    return None
