"""The samples of a record as the metrics take them: rows of axes, uniform times.

The checks every record-based quantity shares (spectra, band RMS, integrals, intervals):
the shape of the samples, the sampling rate of the times, finiteness, the names of the axes,
and the ``xarray.Dataset`` the results build (xarray imported on first use).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = ["as_axes", "axis_names", "check_finite", "sample_rate", "xr_dataset"]


def as_axes(accel: np.ndarray) -> np.ndarray:
    """The samples as a float array (naxes, nt); one axis (nt,) becomes (1, nt).

    Parameters
    ----------
    accel : array_like (naxes, nt) or (nt,)
        Acceleration, m/s^2 (any unit: only the shape is checked).
    """
    a = np.asarray(accel, dtype=float)
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2:
        raise InputError("acceleration must have shape (naxes, nt) or (nt,)", where="accel")
    return a


def sample_rate(timepts: np.ndarray) -> float:
    """Sampling rate of uniformly spaced times, Hz (steps within 1e-6 of their mean).

    Parameters
    ----------
    timepts : ndarray (nt,)
        Times, s (at least 4).
    """
    t = np.asarray(timepts, dtype=float)
    if t.ndim != 1 or t.size < 4:
        raise InputError("need at least 4 uniformly spaced samples", where="timepts")
    mean = float(t[-1] - t[0]) / (t.size - 1)
    dev = np.diff(t)
    dev -= mean
    # written so that a NaN anywhere fails it (a NaN compares false); max |dev| without |dev|
    if not (mean > 0 and max(float(dev.max()), -float(dev.min())) <= 1e-6 * mean):
        if not np.all(np.isfinite(t)):
            raise InputError(
                "times are not all finite", where="timepts", fix="remove NaN/inf times"
            )
        raise InputError(
            "a spectrum needs uniformly spaced output times",
            where="timepts",
            fix="evaluate the response on a uniform grid (np.linspace)",
        )
    return 1.0 / mean


def check_finite(a: np.ndarray) -> None:
    """InputError naming the first non-finite sample (row, index), if there is one.

    Parameters
    ----------
    a : ndarray (naxes, nt)
        Acceleration, m/s^2.
    """
    bad = ~np.isfinite(a)
    if np.any(bad):
        ax, i = np.unravel_index(int(np.argmax(bad)), a.shape)
        raise InputError(
            f"acceleration is not finite (row {ax}, sample {i})",
            where="accel",
            fix="remove or fill the NaN/inf samples before assessing",
        )


def axis_names(n: int, axes: tuple[str, ...] | None = None) -> tuple[str, ...]:
    """Names of ``n`` axes: ``axes`` when given (checked), ``x, y, z`` for 3, else ``a0, a1``.

    Parameters
    ----------
    n : int
        Number of axes (rows of the record).
    axes : tuple of str, optional
        Their names; must be ``n`` of them.
    """
    if axes is not None:
        if len(axes) != n:
            raise InputError(f"{len(axes)} axis names for {n} axes", where="axes")
        return tuple(axes)
    return ("x", "y", "z")[:n] if n <= 3 else tuple(f"a{i}" for i in range(n))


def xr_dataset(data: dict[str, Any], coords: dict[str, Any], attrs: dict[str, Any]) -> Any:
    """``xarray.Dataset(data, coords=coords, attrs=attrs)``, xarray imported here.

    Parameters
    ----------
    data, coords, attrs : dict
        As ``xarray.Dataset`` takes them (units in each variable's attributes).
    """
    import xarray as xr

    return xr.Dataset(data, coords=coords, attrs=attrs)
