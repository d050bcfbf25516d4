"""Modal superposition of several loads: the exact transient response of the main job.

Each load is a piecewise-linear force history ``f(t)`` (N) acting through its modal
participation ``gamma = phi^T b`` (``b`` the generalized force per newton, report Eqs.
2.13-2.14); its modal force is ``p_j(t) = gamma_j f(t)`` and its exact modal response that of
:mod:`microg.dynamics.pwl`.  The loads' responses add (the equations are linear):

* modal accelerations ``eta''(t) = sum_loads eta''_load(t)`` at the output times;
* the rows ``T phi`` of the observed points, contracted block by block: displacement, velocity
  and acceleration of every point;
* the certified true peak of every point's acceleration (:mod:`microg.dynamics.peaks`) of the
  summed force (piecewise linear on the union of the breakpoints);
* the modal accelerations at each peak (the limit from the left at a jump on the peak's left).

:func:`superpose` is a pure kernel of SI arrays: it trusts its inputs (the damping ratio, the
times and the loads are checked once by the caller, :func:`microg.analyze`).  The state of each
load's modes at its force breakpoints is computed once and evaluated for every quantity.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from microg.dynamics.forces import ForceHistory
from microg.dynamics.peaks import PeakResponse, certified_peaks
from microg.dynamics.pwl import ModalState, evaluate, prepare, superposed_force
from microg.dynamics.response import PointResponse

__all__ = ["ModalLoad", "Superposition", "superpose"]


@dataclass(frozen=True)
class ModalLoad:
    """One scalar load of the response: a force history (N) through its modal participation.

    Attributes
    ----------
    force : ForceHistory
        Breakpoints (s) and force (N).
    gamma : ndarray (k,)
        Modal participation ``phi^T b`` per newton (``b`` the generalized force per newton),
        m per modal unit for mass-normalised modes.
    """

    force: ForceHistory
    gamma: np.ndarray


@dataclass(frozen=True)
class Superposition:
    """The superposed exact response of several loads (the arrays of :func:`superpose`).

    Attributes
    ----------
    timepts : ndarray (nt,)
        Output times, s.
    modal_accel : ndarray (k, nt)
        Modal accelerations, m/s^2 per modal unit (right-continuous at force jumps).
    points : dict of str to PointResponse
        Displacement (m), velocity (m/s) and acceleration (m/s^2) of every point, (3, nt).
    peaks : dict of str to PeakResponse
        The certified true peak of every point's acceleration over the record.
    modal_accel_at_peak : ndarray (k, P)
        Modal accelerations at each point's peak (in ``points`` order), m/s^2 per modal unit.
    """

    timepts: np.ndarray
    modal_accel: np.ndarray
    points: dict[str, PointResponse]
    peaks: dict[str, PeakResponse]
    modal_accel_at_peak: np.ndarray


def _summed(
    states: Sequence[ModalState],
    t: np.ndarray,
    derivatives: tuple[int, ...],
    project: np.ndarray | None = None,
) -> np.ndarray:
    """``derivatives`` of every load's response at ``t``, summed: (len, k or r, nt)."""
    rows = states[0].omega.size if project is None else project.shape[0]
    out = np.zeros((len(derivatives), rows, t.size))
    for st in states:
        out += evaluate(st, t, derivatives, project)
    return out


def superpose(
    omega: np.ndarray,
    zeta: np.ndarray,
    loads: Sequence[ModalLoad],
    timepts_out: np.ndarray,
    names: Sequence[str],
    rows: np.ndarray,
    *,
    rtol: float = 1e-9,
    max_rounds: int = 30,
) -> Superposition:
    """The exact response of several loads superposed, at named points, with exact peaks.

    Parameters
    ----------
    omega : ndarray (k,)
        Natural frequencies of the modes in the response, rad/s (0 for rigid-body modes).
    zeta : ndarray (k,)
        Their modal damping ratios, 0 <= zeta < 1 (0 for rigid-body modes).
    loads : sequence of ModalLoad
        At least one; force histories in N, participations per newton.
    timepts_out : ndarray (nt,)
        Sorted output times, s (nt >= 1); their span is the window of the peaks.
    names : sequence of str
        The P observed points, in the order of ``rows``.
    rows : ndarray (3 P, k)
        ``T phi`` of every point (x, y, z of each), m per modal unit.
    rtol, max_rounds
        Relative tolerance and largest number of refinement rounds of the certified peaks
        (:func:`microg.dynamics.peaks.certified_peaks`).

    Returns
    -------
    Superposition
    """
    t = timepts_out
    states = [
        prepare(omega, zeta, ld.force.breakpoints[0], np.outer(ld.gamma, ld.force.breakpoints[1]))
        for ld in loads
    ]
    acc = _summed(states, t, (2,))[0]
    # displacements and velocities at the points only (the modal ones are never stored)
    d_all, v_all = _summed(states, t, (0, 1), rows)
    a_all = rows @ acc
    if len(loads) == 1:
        summed = states[0]  # one load: its own states are those of the sum
    else:
        tb, pf = superposed_force([(ld.force, ld.gamma) for ld in loads])
        summed = prepare(omega, zeta, tb, pf)
    peaks = certified_peaks(
        summed,
        list(names),
        rows,
        t,
        rtol=rtol,
        max_rounds=max_rounds,
        grid_vals=a_all,
    )
    points = {
        name: PointResponse(name, t, d_all[r], v_all[r], a_all[r])
        for name, r in ((n, slice(3 * j, 3 * j + 3)) for j, n in enumerate(names))
    }
    return Superposition(
        timepts=t,
        modal_accel=acc,
        points=points,
        peaks=peaks,
        modal_accel_at_peak=_accel_at_peaks(states, [peaks[n] for n in names]),
    )


def _accel_at_peaks(states: Sequence[ModalState], peaks: Sequence[PeakResponse]) -> np.ndarray:
    """Modal accelerations (k, len(peaks)) at the exact peaks, in one evaluation.

    At a jump on the peak's left side, the limit from the left (the time just before it).
    """
    tp = np.array([float(pk.peak_time_s) for pk in peaks])
    left = np.array([pk.peak_side == "left" for pk in peaks], bool)
    tp = np.where(left, np.nextafter(tp, -np.inf), tp)
    order = np.argsort(tp, kind="stable")
    acc = np.empty((states[0].omega.size, tp.size))
    if tp.size:
        acc[:, order] = _summed(states, tp[order], (2,))[0]
    return acc
