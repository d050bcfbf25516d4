"""Gain and phase margins of a SISO loop from its frequency response, by python-control.

:func:`control.stability_margins` reads the crossings from an interpolating FRD (a cubic
spline through the response, :class:`control.FrequencyResponseData` with ``smooth=True``):
it finds where ``|L| - 1`` and the phase about -180 deg change sign between grid points and
refines each crossing by root finding on the spline, and it also minimises ``|1 + L|`` at
every local minimum of the grid (the stability margin, not used here).  Evaluating the spline
costs one call per point and per iteration, which made the margins of the isolator's twelve
loops the bulk of a design.

:func:`margins_from_response` therefore hands :func:`control.stability_margins` only the
grid's neighbourhood of each crossing: ``WINDOW`` points either side of every sign change,
one FRD per window (a window never spans a gap, so no crossing is invented between windows).
The spline through a window matches the spline through the whole grid at the crossing to the
decay of a cubic spline's end condition over ``WINDOW`` knots (about ``0.27 ** WINDOW``
relative to the interpolation error, far below the margins' printed digits); the test suite
checks the margins of the designed isolator's loops against the whole-grid reading.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["WINDOW", "loop_margin_values", "margins_from_response", "pick_margins"]

#: grid points kept either side of a crossing for the interpolating FRD
WINDOW = 8


def _crossing_windows(resp: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges ``[lo, hi)`` around every grid interval where a crossing can lie.

    The same sign tests as :func:`control.stability_margins`: ``|L| - 1`` (gain crossover)
    and ``angle(-L)`` where ``Re L <= 0`` at the interval's start (phase crossover; the wrap
    where ``L`` crosses the positive real axis is discarded by the same test inside
    stability_margins).  Overlapping windows are merged.
    """
    n = resp.size
    mod = np.abs(resp) - 1.0
    arg = np.angle(-resp)
    phase = np.where(np.diff(np.sign(arg)))[0]
    phase = phase[np.real(resp[phase]) <= 0]  # stability_margins keeps only these
    idx = np.union1d(np.where(np.diff(np.sign(mod)))[0], phase)
    out: list[tuple[int, int]] = []
    for i in idx:
        lo, hi = max(0, int(i) - WINDOW), min(n, int(i) + 2 + WINDOW)
        if out and lo <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], hi))
        else:
            out.append((lo, hi))
    return out


def pick_margins(
    gms: np.ndarray, pms: np.ndarray, wpcs: np.ndarray, wgcs: np.ndarray
) -> tuple[float, float, float | None, float | None]:
    """The reported margins from every crossing found (see :func:`loop_margin_values`)."""
    gms, pms = np.atleast_1d(np.asarray(gms, float)), np.atleast_1d(np.asarray(pms, float))
    wpcs, wgcs = np.atleast_1d(np.asarray(wpcs, float)), np.atleast_1d(np.asarray(wgcs, float))
    gm, wpc = math.inf, None
    ok = np.isfinite(gms) & (gms > 0)
    if ok.any():
        j = int(np.argmin(np.abs(np.log(gms[ok]))))
        gm, wpc = float(gms[ok][j]), float(wpcs[ok][j])
    pm, wgc = math.inf, None
    okp = np.isfinite(pms)
    if okp.any():
        dist = np.abs((pms[okp] + 180.0) % 360.0 - 180.0)
        j = int(np.argmin(dist))
        pm, wgc = float(dist[j]), float(wgcs[okp][j])
    return gm, pm, wgc, wpc


def margins_from_response(
    resp: np.ndarray, omega: np.ndarray
) -> tuple[float, float, float | None, float | None]:
    """(gain margin, phase margin in degrees, gain- and phase-crossover in rad/s) of a loop.

    Parameters
    ----------
    resp : (n,) the loop's complex frequency response ``L(i omega)``
    omega : (n,) increasing frequencies, rad/s

    Read by :func:`control.stability_margins` (``returnall``) on the windows of the module
    docstring; the choice among several crossings is :func:`loop_margin_values`'.
    """
    import control as ct

    resp = np.asarray(resp, complex).reshape(-1)
    omega = np.asarray(omega, float).reshape(-1)
    parts: list[list[np.ndarray]] = [[], [], [], []]
    for lo, hi in _crossing_windows(resp):
        gms, pms, _, wpcs, wgcs, _ = ct.stability_margins(
            ct.frd(resp[lo:hi], omega[lo:hi], smooth=True), returnall=True
        )
        for store, v in zip(parts, (gms, pms, wpcs, wgcs), strict=True):
            store.append(np.atleast_1d(np.asarray(v, float)))
    gms, pms, wpcs, wgcs = (np.concatenate(p) if p else np.zeros(0) for p in parts)
    return pick_margins(gms, pms, wpcs, wgcs)


def loop_margin_values(
    loop: Any, omega: np.ndarray
) -> tuple[float, float, float | None, float | None]:
    """(gain margin, phase margin in degrees, gain- and phase-crossover in rad/s) of a SISO loop.

    Read by :func:`control.stability_margins` (``returnall``) from the loop's frequency
    response at ``omega`` (rad/s), interpolated (:func:`margins_from_response`).  A loop may
    cross |L| = 1 and -180 deg more than once: the phase margin is the least angular distance
    from -180 deg over the gain crossovers (a phase of -258 deg is 78 deg from it), the gain
    margin the crossing factor nearest to 1 on a log scale (a factor below 1 means that
    *reducing* the gain by it destabilises: a conditionally stable loop); inf where there is
    no crossover.

    Parameters
    ----------
    loop : SISO ``control`` system (the loop transfer)
    omega : frequencies, rad/s
    """
    from microg.isolation.active.fresp import freq_response

    w = np.asarray(omega, float)
    return margins_from_response(freq_response(loop, w / (2 * math.pi))[0, 0], w)
