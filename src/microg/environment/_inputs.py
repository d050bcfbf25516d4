"""Checks of the quasi-steady inputs: finite numbers and 3-vectors, named in every error."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = ["finite_number", "vector3"]


def finite_number(
    value: float, where: str, *, positive: bool = False, nonneg: bool = False
) -> float:
    """``value`` as a float, refused (InputError naming ``where``) unless finite (and > 0, >= 0).

    Parameters
    ----------
    value : float
        The input, in its own unit.
    where : str
        The parameter's name in the error.
    positive, nonneg : bool
        Also require ``value > 0`` or ``value >= 0``.
    """
    v = float(value)
    if not math.isfinite(v):
        raise InputError(f"must be a finite number, got {value!r}", where=where)
    if positive and not v > 0:
        raise InputError(f"must be > 0, got {value!r}", where=where)
    if nonneg and v < 0:
        raise InputError(f"must be >= 0, got {value!r}", where=where)
    return v


def vector3(value: Any, where: str) -> np.ndarray:
    """``value`` as three finite floats, refused (InputError naming ``where``) otherwise.

    Parameters
    ----------
    value : array_like (3,)
        The input, in its own unit.
    where : str
        The parameter's name in the error.
    """
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InputError(f"must be three finite numbers, got {value!r}", where=where)
    return v
