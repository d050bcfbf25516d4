"""Checks of the public API's arguments, raising InputError naming the parameter.

Each returns the value in its one form or raises :class:`~microg.errors.InputError` whose
``where`` is the parameter (never a TypeError from deep inside).  The public entry points
(``microg.load_model``, ``solve_modes``, ``analyze``, ``sweep``, the force constructors, ...)
call these once, at the boundary; the kernels behind them trust their inputs.  ``bool`` is
never taken for a number (``True`` is not 1 mode); numbers are Python or numpy numbers, never
strings (a string with a unit goes through :mod:`microg.units`).
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from microg.errors import InputError

__all__ = ["boolean", "function", "integer", "number", "path", "text"]


def _kind(value: Any) -> str:
    """The type of a rejected value, never its content (it may be a foreign file's)."""
    return type(value).__name__


def path(value: Any, name: str) -> Path:
    """A file-system path from a str or ``os.PathLike`` (not empty; the reader judges the rest)."""
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str):
        raise InputError(
            f"must be a file path (str or pathlib.Path), got {_kind(value)}", where=name
        )
    if not value.strip():
        raise InputError("must be a file path, got an empty string", where=name)
    return Path(value)


def integer(value: Any, name: str, *, lo: int | None = None, hi: int | None = None) -> int:
    """An integer (Python or numpy; not bool, not a float) within ``[lo, hi]``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise InputError(f"must be an integer, got {_kind(value)}", where=name)
    v = int(value)
    if lo is not None and v < lo:
        raise InputError(f"must be >= {lo}, got {v}", where=name)
    if hi is not None and v > hi:
        raise InputError(f"must be <= {hi}, got {v}", where=name)
    return v


def number(
    value: Any,
    name: str,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    unit: str = "",
) -> float:
    """A finite real number (Python or numpy; not bool, not a string) within its range.

    ``lo_open``: the lower end is excluded (``> lo``); ``unit`` is named in the message.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        what = f"a number of {unit}" if unit else "a number"
        raise InputError(f"must be {what}, got {_kind(value)}", where=name)
    v = float(value)
    u = f" {unit}" if unit else ""
    if not math.isfinite(v):
        raise InputError(f"must be a finite number, got {v}", where=name)
    if lo is not None and (v <= lo if lo_open else v < lo):
        raise InputError(f"must be {'>' if lo_open else '>='} {lo:g}{u}, got {v:g}{u}", where=name)
    if hi is not None and v > hi:
        raise InputError(f"must be <= {hi:g}{u}, got {v:g}{u}", where=name)
    return v


def boolean(value: Any, name: str) -> bool:
    """``True`` or ``False`` (Python or numpy bool; not 0/1, not a string)."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return bool(value)
    raise InputError(f"must be True or False, got {_kind(value)}", where=name)


def text(value: Any, name: str) -> str:
    """A string."""
    if not isinstance(value, str):
        raise InputError(f"must be a string, got {_kind(value)}", where=name)
    return value


def function(value: Any, name: str) -> Callable[..., Any]:
    """A callable."""
    if not callable(value):
        raise InputError(f"must be a function, got {_kind(value)}", where=name)
    return value
