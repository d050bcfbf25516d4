"""Rigid-body librational (gravity-gradient) motion of the station (Eqs. 2.27-2.35).

Pitch (rotation about y, the X-Z plane) and roll (about x, the Y-Z plane) in the report's
form ``I_y theta'' + 3 w0^2 (I_x - I_z) theta = M_y`` (Eq. 2.28) and Eq. 2.27.  (The full
linearised roll equation also carries an orbital-rate term, 4 w0^2 instead of 3 w0^2, and
couples with yaw; microg follows the report and says so in the errata.)
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "orbital_rate",
    "libration_frequencies",
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
