"""Exact modal response to piecewise-linear forces: the public entries and their results.

Each modal coordinate obeys (report Eq. 2.15, with modal damping added)::

    eta'' + 2 zeta omega eta' + omega^2 eta = p(t),      eta(t0) = eta'(t0) = 0,

where ``p = phi^T f / modal_mass`` is piecewise linear between breakpoints; the response is
exact to rounding, by the closed form of each linear segment (:mod:`microg.dynamics.pwl`, with
the oscillator functions of :mod:`microg.dynamics.oscillator`).  Rigid-body modes
(``omega = 0``) need no special case.

* :func:`modal_pwl_response`, :func:`modal_pwl_evaluate`: modal coordinates (selected
  derivatives, optionally projected on rows ``T phi`` block by block);
* :func:`response_at_points`: displacement, velocity and acceleration of named points;
* :func:`peak_response`: the certified true peak of the acceleration over a window, both
  one-sided limits at the force's jumps and the stationary points between samples included
  (:mod:`microg.dynamics.peaks`).

These entries check their inputs once (``InputError`` naming the argument); the kernels they
call trust them.  The superposition of several loads for the main job is
:mod:`microg.dynamics.superposition`.

Conventions: the force is zero before the first breakpoint; a repeated breakpoint time is a jump
(the last value at that time holds from it on, i.e. the force is right-continuous; times closer than
4 roundings of max(|t|, 1 s) count as repeated); after the last breakpoint the force holds its last
value.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.dynamics.oscillator import oscillator_functions
from microg.dynamics.peaks import PeakResponse, certified_peaks
from microg.dynamics.pwl import check_inputs, evaluate, prepare, superposed_force
from microg.errors import InputError
from microg.units import G0

if TYPE_CHECKING:
    from microg.dynamics.forces import ForceHistory

__all__ = [
    "ModalResponse",
    "PeakResponse",
    "PointResponse",
    "combined_modal_force",
    "generalized_force_vector",
    "modal_pwl_evaluate",
    "modal_pwl_response",
    "oscillator_functions",
    "peak_response",
    "response_at_points",
]


@dataclass(frozen=True)
class ModalResponse:
    """Modal coordinates and their rates at the output times.

    Attributes
    ----------
    timepts : (nt,) output times, s
    eta : (m, nt) modal displacements (units of p / omega^2, e.g. m * sqrt(kg) for
        mass-normalised modes)
    eta_dot : (m, nt) modal velocities
    eta_ddot : (m, nt) modal accelerations, right-continuous at jumps of the force
    """

    timepts: np.ndarray
    eta: np.ndarray
    eta_dot: np.ndarray
    eta_ddot: np.ndarray

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary: the record and each mode's largest sampled |value|.

        The histories themselves are in :meth:`to_xarray` (a record of 200 modes x 20,001
        samples is 32 MB a series, too much for JSON).
        """
        t = np.asarray(self.timepts, float)
        return {
            "n_modes": int(self.eta.shape[0]),
            "n_samples": int(t.size),
            "t_start_s": float(t[0]) if t.size else None,
            "t_end_s": float(t[-1]) if t.size else None,
            "peak_eta": _row_peaks(self.eta),
            "peak_eta_dot": _row_peaks(self.eta_dot),
            "peak_eta_ddot": _row_peaks(self.eta_ddot),
        }

    def to_xarray(self) -> Any:
        """``eta``, ``eta_dot``, ``eta_ddot`` as an ``xarray.Dataset`` over (mode, time).

        Modal units: for mass-normalised modes ``eta`` is m sqrt(kg), its rates per s and
        per s^2 (attribute ``units``); ``mode`` counts from 1.
        """
        import xarray as xr

        dims = ("mode", "time")
        return xr.Dataset(
            {
                "eta": (dims, self.eta, {"units": "m kg^0.5"}),
                "eta_dot": (dims, self.eta_dot, {"units": "m kg^0.5 / s"}),
                "eta_ddot": (dims, self.eta_ddot, {"units": "m kg^0.5 / s^2"}),
            },
            coords={
                "mode": ("mode", np.arange(1, self.eta.shape[0] + 1), {"units": "1"}),
                "time": ("time", np.asarray(self.timepts, float), {"units": "s"}),
            },
        )

    def plot(self, n_show: int = 6, ax: Any = None) -> Any:
        """The modal accelerations of the ``n_show`` modes with the largest peak (a Figure).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.modes import plot_modal_response

        return plot_modal_response(self, n_show=n_show, ax=ax)


def _row_peaks(a: np.ndarray) -> list[float]:
    """Largest |value| of each row (an empty row: 0)."""
    a = np.atleast_2d(np.asarray(a, float))
    return np.max(np.abs(a), axis=1, initial=0.0).tolist()


@dataclass(frozen=True)
class PointResponse:
    """Translational response of one named point (three axes of the model frame).

    Attributes
    ----------
    name : point name
    timepts : (nt,) output times, s
    displacement : (3, nt) m
    velocity : (3, nt) m/s
    acceleration : (3, nt) m/s^2
    """

    name: str
    timepts: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray

    def acceleration_g(self) -> np.ndarray:
        """Acceleration in units of standard gravity (G0 = 9.80665 m/s^2), shape (3, nt)."""
        return self.acceleration / G0

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary: the record and the largest sampled values per axis (SI).

        ``peak_accel_g`` is the largest sampled |a| (vector magnitude); the certified
        maximum between samples is :class:`PeakResponse`'s.  The histories are in
        :meth:`to_xarray`.
        """
        t = np.asarray(self.timepts, float)
        mag = np.linalg.norm(np.asarray(self.acceleration, float), axis=0)
        return {
            "name": self.name,
            "n_samples": int(t.size),
            "t_start_s": float(t[0]) if t.size else None,
            "t_end_s": float(t[-1]) if t.size else None,
            "peak_displacement_m_axis": _row_peaks(self.displacement),
            "peak_velocity_mps_axis": _row_peaks(self.velocity),
            "peak_accel_mps2_axis": _row_peaks(self.acceleration),
            "sampled_peak_accel_g": float(np.max(mag, initial=0.0)) / G0,
        }

    def to_xarray(self) -> Any:
        """Displacement, velocity and acceleration as an ``xarray.Dataset`` over (axis, time)."""
        import xarray as xr

        dims = ("axis", "time")
        return xr.Dataset(
            {
                "displacement_m": (dims, self.displacement, {"units": "m"}),
                "velocity_mps": (dims, self.velocity, {"units": "m/s"}),
                "accel_mps2": (dims, self.acceleration, {"units": "m/s^2"}),
            },
            coords={
                "axis": ("axis", ["x", "y", "z"][: np.shape(self.acceleration)[0]]),
                "time": ("time", np.asarray(self.timepts, float), {"units": "s"}),
            },
            attrs={"point": self.name},
        )

    def plot(self, ax: Any = None) -> Any:
        """The acceleration history, micro-g against s (a Figure).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_time_history

        return plot_time_history(
            self.timepts, self.acceleration, title=f"Acceleration at {self.name}", ax=ax
        )


def modal_pwl_response(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    timepts_force: np.ndarray,
    modal_force: np.ndarray,
    timepts_out: np.ndarray,
) -> ModalResponse:
    """Exact response of damped/undamped/rigid modal equations to a piecewise-linear force.

    Solves eta'' + 2 zeta omega eta' + omega^2 eta = p(t) (report Eq. 2.15 with modal damping)
    with zero initial state at ``timepts_force[0]``, exactly to rounding, by the closed form of each
    linear segment of ``p`` (see the module docstring).  The force is zero before the first
    breakpoint and holds its last value after the last one; a repeated time is a jump.

    Parameters
    ----------
    omega : (m,) natural frequencies, rad/s; 0 for rigid-body modes
    zeta : (m,) or scalar modal damping ratios, 0 <= zeta < 1
    timepts_force : (nb,) breakpoint times, s, non-decreasing (a repeated time is a jump)
    modal_force : (m, nb) modal force p at each breakpoint, already divided by the modal mass
        (N/kg-like units, m/s^2 per unit modal coordinate); at a repeated time the first column is
        the value just before the jump, the last the value from the jump on
    timepts_out : (nt,) sorted output times, s; any spacing (each uniformly spaced run inside a
        force segment takes the fast table path); times before the first breakpoint give zero
        response

    Returns
    -------
    ModalResponse
        ``eta``, ``eta_dot``, ``eta_ddot`` of shape (m, nt); accelerations are right-continuous.
    """
    omega, zeta, timepts_force, modal_force, timepts_out = check_inputs(
        omega, zeta, timepts_force, modal_force, timepts_out
    )
    st = prepare(omega, zeta, timepts_force, modal_force)
    eta, eta_dot, eta_ddot = evaluate(st, timepts_out, (0, 1, 2))
    return ModalResponse(timepts=timepts_out, eta=eta, eta_dot=eta_dot, eta_ddot=eta_ddot)


def modal_pwl_evaluate(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    timepts_force: np.ndarray,
    modal_force: np.ndarray,
    timepts_out: np.ndarray,
    *,
    derivatives: Sequence[int] = (0, 1, 2),
    project: np.ndarray | None = None,
) -> np.ndarray:
    """Selected derivatives of :func:`modal_pwl_response`'s exact response, optionally projected.

    ``project @ eta^(d)`` is contracted block by block, so the modal array is never built.

    Parameters
    ----------
    omega, zeta, timepts_force, modal_force, timepts_out
        As :func:`modal_pwl_response` (rad/s, -, s, modal force, s).
    derivatives : sequence of int
        Time derivatives wanted, each 0 (eta), 1 (eta') or 2 (eta''), in any order (each is
        evaluated once).
    project : ndarray (r, m), optional
        Rows to contract the modes with (e.g. points' ``T phi``, m per modal unit).

    Returns
    -------
    ndarray (len(derivatives), m or r, nt)
        In the modal unit times the projection's unit, per s^d.
    """
    qs = tuple(int(d) for d in derivatives)
    if not qs or any(d not in (0, 1, 2) for d in qs):
        raise InputError(f"derivatives must be among 0, 1, 2, got {qs}", where="derivatives")
    omega, zeta, timepts_force, modal_force, timepts_out = check_inputs(
        omega, zeta, timepts_force, modal_force, timepts_out
    )
    if project is not None:
        project = np.asarray(project, float)
        if project.ndim != 2 or project.shape[1] != omega.size:
            raise InputError(
                f"project must have shape (r, {omega.size}), got {project.shape}", where="project"
            )
    st = prepare(omega, zeta, timepts_force, modal_force)
    wanted = tuple(sorted(set(qs)))  # the kernel takes distinct derivatives in increasing order
    out = evaluate(st, timepts_out, wanted, project)
    return out if wanted == qs else out[[wanted.index(d) for d in qs]]


def generalized_force_vector(translation_map: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Generalized force per newton applied at a point in a direction: ``T^T d``.

    Parameters
    ----------
    translation_map : (3, n) map from the n generalized coordinates to the point's translation, m
        per unit coordinate
    direction : (3,) direction of the force (normalised here)

    Returns
    -------
    (n,) generalized force per newton of applied force.
    """
    d = np.asarray(direction, dtype=float)
    norm = np.linalg.norm(d)
    if d.shape != (3,) or not np.isfinite(norm) or norm == 0:
        raise InputError("a force direction must be a non-zero 3-vector", where="direction")
    return np.asarray(translation_map, dtype=float).T @ (d / norm)


def _point_projection(
    phi: np.ndarray, point_maps: Mapping[str, np.ndarray], where: str
) -> tuple[list[str], np.ndarray]:
    """Names and the stacked (3 P, m) projection ``T_point phi`` of every point."""
    names = list(point_maps)
    blocks = []
    for name in names:
        tmap = np.asarray(point_maps[name], dtype=float)
        if tmap.shape != (3, phi.shape[0]):
            raise InputError(
                f"translation map must have shape (3, {phi.shape[0]}), got {tmap.shape}",
                where=f"{where}: point {name!r}",
            )
        blocks.append(tmap @ phi)
    proj = np.concatenate(blocks) if blocks else np.zeros((0, phi.shape[1]))
    return names, proj


def _check_phi(phi: np.ndarray, omega: np.ndarray, b: np.ndarray, where: str) -> None:
    if phi.ndim != 2 or phi.shape[1] != omega.size:
        raise InputError(f"phi must have shape (n, {omega.size})", where=f"{where}: phi")
    if b.shape != (phi.shape[0],):
        raise InputError(f"force_dof_vector must have shape ({phi.shape[0]},)", where=where)


def response_at_points(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    phi: np.ndarray,
    point_maps: Mapping[str, np.ndarray],
    force_history: ForceHistory,
    force_dof_vector: np.ndarray,
    timepts_out: np.ndarray,
) -> dict[str, PointResponse]:
    """Translational response at named points to one force history applied through a dof vector.

    The modal force is ``p_j(t) = phi[:, j] . force_dof_vector * f(t)`` (mass-normalised modes,
    report Eqs. 2.13-2.14), the modal response is that of :func:`modal_pwl_response`, and each
    point moves by ``T_point @ phi @ eta`` (rigid-body rotation at offset points is in
    ``T_point``).  ``T_point phi`` is formed first and contracted with the modal response block
    by block, so the (3, modes, times) modal array is never built.

    Parameters
    ----------
    omega : (m,) natural frequencies, rad/s (0 for rigid-body modes)
    zeta : (m,) or scalar modal damping ratios
    phi : (n, m) mass-normalised mode shapes, one per column (phi^T M phi = I)
    point_maps : name -> (3, n) translation map of the point, m per unit generalized coordinate
    force_history : a :class:`~microg.dynamics.forces.ForceHistory` (``timepts`` s, ``force`` N)
    force_dof_vector : (n,) generalized force per newton of applied force (see
        :func:`generalized_force_vector`)
    timepts_out : (nt,) sorted output times, s

    Returns
    -------
    dict name -> PointResponse (displacement m, velocity m/s, acceleration m/s^2, shape (3, nt)).
    """
    phi = np.asarray(phi, dtype=float)
    omega = np.asarray(omega, dtype=float)
    b = np.asarray(force_dof_vector, dtype=float)
    _check_phi(phi, omega, b, "response_at_points")
    timepts_force, force = force_history.breakpoints
    gamma = phi.T @ b  # (m,) modal participation per newton
    omega, zeta_a, timepts_force, modal_force, timepts_out = check_inputs(
        omega, zeta, timepts_force, np.outer(gamma, force), timepts_out
    )
    names, proj = _point_projection(phi, point_maps, "response_at_points")
    st = prepare(omega, zeta_a, timepts_force, modal_force)
    vals = evaluate(st, timepts_out, (0, 1, 2), proj)  # (3, 3 P, nt)
    out: dict[str, PointResponse] = {}
    for i, name in enumerate(names):
        rows = slice(3 * i, 3 * i + 3)
        out[name] = PointResponse(
            name=name,
            timepts=timepts_out,
            displacement=vals[0, rows],
            velocity=vals[1, rows],
            acceleration=vals[2, rows],
        )
    return out


def combined_modal_force(
    phi: np.ndarray, loads: Sequence[tuple[ForceHistory, np.ndarray]]
) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoints and modal force of the sum of several loads, for :func:`modal_pwl_response`.

    The sum of piecewise-linear forces is piecewise linear on the union of their breakpoints.
    Every union time appears twice: first with the limit from the left, then with the value from
    that time on (a jump where they differ; the kernel merges equal times).

    Parameters
    ----------
    phi : (n, m) mass-normalised mode shapes
    loads : sequence of (force history, (n,) generalized force per newton); force in N

    Returns
    -------
    timepts_force : (2 U,) s
    modal_force : (m, 2 U) modal force p_j per unit modal mass, m/s^2 per unit coordinate
    """
    phi = np.asarray(phi, dtype=float)
    if not loads:
        raise InputError("need at least one load", where="loads")
    modal = []
    for force, b in loads:
        b = np.asarray(b, dtype=float)
        if b.shape != (phi.shape[0],):
            raise InputError(
                f"a generalized force vector must have shape ({phi.shape[0]},)", where="loads"
            )
        modal.append((force, phi.T @ b))
    return superposed_force(modal)


def peak_response(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    phi: np.ndarray,
    point_maps: Mapping[str, np.ndarray],
    loads: Sequence[tuple[ForceHistory, np.ndarray]],
    timepts_out: np.ndarray,
    *,
    rtol: float = 1e-9,
    max_rounds: int = 30,
) -> dict[str, PeakResponse]:
    """True maximum of the exact acceleration at named points, with a certified bound.

    The acceleration is that of :func:`response_at_points` summed over ``loads``.  It is
    evaluated exactly (closed form) at the output times, at every force breakpoint inside the
    window with both one-sided limits at a jump (the limit from the left is the end of the
    previous segment), then refined between samples with certified bounds of its first and
    second derivatives until no interval may exceed the best value by more than ``rtol``
    (the algorithm: :func:`microg.dynamics.peaks.certified_peaks`).

    Guarantee: the true supremum over the window [timepts_out[0], timepts_out[-1]] lies in
    ``[peak, upper_bound]``, and ``upper_bound <= peak (1 + rtol)`` unless ``max_rounds`` ran out
    (then ``upper_bound`` still holds and says how far off the peak may be).

    Parameters
    ----------
    omega : (m,) natural frequencies, rad/s (0 for rigid-body modes)
    zeta : (m,) or scalar modal damping ratios, 0 <= zeta < 1
    phi : (n, m) mass-normalised mode shapes (phi^T M phi = I)
    point_maps : name -> (3, n) translation map of the point, m per unit generalized coordinate
    loads : sequence of (ForceHistory, (n,) generalized force per newton), forces in N; the
        responses add (see :func:`combined_modal_force`)
    timepts_out : (nt,) sorted output times, s; their span is the window searched
    rtol : relative tolerance of the certified bound (> 0)
    max_rounds : largest number of refinement rounds (>= 0)

    Returns
    -------
    dict name -> PeakResponse (m/s^2, s)
    """
    phi = np.asarray(phi, dtype=float)
    omega = np.asarray(omega, dtype=float)
    if not (np.isfinite(rtol) and rtol > 0):
        raise InputError(f"must be a number > 0, got {rtol!r}", where="rtol")
    if not (isinstance(max_rounds, int | np.integer) and max_rounds >= 0):
        raise InputError(f"must be an integer >= 0, got {max_rounds!r}", where="max_rounds")
    if phi.ndim != 2 or phi.shape[1] != omega.size:
        raise InputError(f"phi must have shape (n, {omega.size})", where="peak_response: phi")
    tb, pf = combined_modal_force(phi, loads)
    omega, zeta_a, tb, pf, t = check_inputs(omega, zeta, tb, pf, timepts_out)
    if t.size == 0:
        raise InputError("need at least one output time", where="timepts_out")
    names, proj = _point_projection(phi, point_maps, "peak_response")
    st = prepare(omega, zeta_a, tb, pf)
    return certified_peaks(st, names, proj, t, rtol=rtol, max_rounds=int(max_rounds))
