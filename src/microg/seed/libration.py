"""Rigid-body librational (gravity-gradient) motion of the station (Eqs. 2.27-2.35).

Pitch (rotation about y, the X-Z plane) and roll (about x, the Y-Z plane) in the report's
form ``I_y theta'' + 3 w0^2 (I_x - I_z) theta = M_y`` (Eq. 2.28) and Eq. 2.27.  (The full
linearised roll equation also carries an orbital-rate term, 4 w0^2 instead of 3 w0^2, and
couples with yaw; microg follows the report and says so in the errata.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from microg.dynamics.crew import CrewPushoff, accel_amax, acceleration_a

__all__ = [
    "orbital_rate",
    "libration_frequencies",
    "LibrationResponse",
    "libration_response",
    "libration_accel_impulse",
]


def orbital_rate(radius: float, mu: float = 3.986004418e14) -> float:
    """Circular orbital rate sqrt(mu / R^3), rad/s (Eq. 2.29).

    Parameters
    ----------
    radius : float
        Orbit radius, m.
    mu : float
        Gravitational parameter, m^3/s^2.
    """
    return float(np.sqrt(mu / radius**3))


def libration_frequencies(omega0: float, inertia: np.ndarray) -> dict[str, float]:
    """Roll and pitch libration frequencies, rad/s (Eqs. 2.30a-b).

    Parameters
    ----------
    omega0 : float
        Orbital rate, rad/s.
    inertia : ndarray (3,) or (3, 3)
        Principal moments (I_x, I_y, I_z) about the centre of mass, kg m^2.

    Returns
    -------
    dict
        ``{"x": w_x, "y": w_y}`` (NaN where the gravity gradient destabilises).
    """
    i = np.asarray(inertia, float)
    ix, iy, iz = np.diag(i) if i.ndim == 2 else i
    with np.errstate(invalid="ignore"):
        wx = omega0 * np.sqrt(3.0 * (iy - iz) / ix)
        wy = omega0 * np.sqrt(3.0 * (ix - iz) / iy)
    return {"x": float(wx), "y": float(wy)}


def libration_accel_impulse(
    z_e: float, z_a: float, f0: float, t1: float, omega: float, inertia: float
) -> float:
    """Peak librational acceleration from the push-off impulse alone, m/s^2 (Eqs. 2.35, 3.2).

    ``a = Z_e Z_a f0 w t1 / (2 I)``: the push-off's angular impulse ``Z_a f0 t1 / 2`` sets
    the station librating with amplitude ``H/(I w)`` (Eq. 2.33 corrected); at distance
    ``Z_e`` from the centre of mass the acceleration amplitude is ``Z_e H w / I``.

    Parameters
    ----------
    z_e, z_a : float
        Distances of the observation point and the crew force from the centre of mass, m.
    f0 : float
        Crew force, N.
    t1 : float
        Push-off duration, s.
    omega : float
        Libration frequency, rad/s.
    inertia : float
        Moment of inertia about the libration axis through the centre of mass, kg m^2.
    """
    return abs(z_e * z_a) * f0 * omega * t1 / (2.0 * inertia)


@dataclass(frozen=True)
class LibrationResponse:
    """Exact librational response to the full crew force history.

    Attributes
    ----------
    omega : float
        Libration frequency, rad/s.
    timepts : ndarray
        s.
    theta : ndarray
        Libration angle, rad.
    accel : ndarray
        Acceleration at the observation point, m/s^2.
    peak_accel : float
        Exact max over all t of |accel|, m/s^2 (push-off and landing both included).
    peak_accel_impulse : float
        The report's impulse estimate (push-off only, Eq. 3.2), m/s^2.
    """

    omega: float
    timepts: np.ndarray
    theta: np.ndarray
    accel: np.ndarray
    peak_accel: float
    peak_accel_impulse: float


def libration_response(
    crew: CrewPushoff,
    omega: float,
    inertia: float,
    z_e: float,
    z_a: float,
    timepts: np.ndarray,
) -> LibrationResponse:
    """Libration from the crew force f(t) applied at lever arm ``z_a`` (Eqs. 2.28, 2.31).

    The torque ``z_a f(t)`` has the shape of Eq. 2.16, so ``theta`` is the closed form
    ``z_a/I f0/(w^3 t1) U(t)`` and the acceleration at ``z_e`` is ``z_e theta''``.

    Parameters
    ----------
    crew : CrewPushoff
    omega : float
        Libration frequency, rad/s.
    inertia : float
        kg m^2.
    z_e, z_a : float
        Lever arms of the observation point and the force about the centre of mass, m.
    timepts : ndarray
        s.
    """
    from microg.dynamics.crew import displacement_u

    scale_u = z_a / inertia * crew.f0 / (omega**3 * crew.t1)
    scale_a = z_a / inertia * crew.f0 / (omega * crew.t1)
    theta = scale_u * displacement_u(omega, timepts, crew)
    accel = z_e * scale_a * acceleration_a(omega, timepts, crew)
    peak = abs(z_e * scale_a) * float(accel_amax(omega, crew))
    return LibrationResponse(
        omega=omega,
        timepts=np.asarray(timepts, float),
        theta=theta,
        accel=accel,
        peak_accel=peak,
        peak_accel_impulse=libration_accel_impulse(z_e, z_a, crew.f0, crew.t1, omega, inertia),
    )
