"""Checks of the quasi-steady inputs: finite numbers and 3-vectors, named in every error."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = ["finite_number", "points3", "vector3"]


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


def points3(value: Any, where: str) -> np.ndarray:
    """``value`` as (p, 3) finite floats (one point may be given as (3,)), or InputError.

    Parameters
    ----------
    value : array_like (p, 3) or (3,)
        The points, in their own unit.
    where : str
        The parameter's name in the error.
    """
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(
            "must be points as rows of three finite numbers (p x 3), got values that are not "
            "numbers",
            where=where,
        ) from None
    if v.shape == (3,):
        v = v[None, :]
    if v.ndim != 2 or v.shape[1] != 3 or not np.all(np.isfinite(v)):
        got = "a non-finite value" if v.ndim == 2 and v.shape[1] == 3 else f"shape {v.shape}"
        raise InputError(
            f"must be points as rows of three finite numbers (p x 3), got {got}", where=where
        )
    return v
