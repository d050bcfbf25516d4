"""The gravity gradient (tidal) specific force at points offset from the centre of mass.

The full 3-D two-body difference ``g(R_cm) - g(R_cm + rho)`` with ``g(r) = -mu r / |r|^3``,
not its linearisation, evaluated without cancellation.  To first order in ``rho/R`` it is
``-n^2 (3 r_hat (r_hat . rho) - rho)``, ``n = sqrt(mu / R^3)`` the mean motion (see
:mod:`microg.environment.quasisteady`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["gravity_gradient_accel"]


def gravity_gradient_accel(rho_m: np.ndarray, r_cm_m: np.ndarray, mu: float) -> np.ndarray:
    """Tidal specific force ``g(R) - g(R + rho)`` at offsets ``rho`` from the CM, m/s^2.

    The full two-body difference (no linearisation), written without cancellation: with
    ``s = R + rho``, ``g(R) - g(s) = mu [rho / S^3 + R (1/S^3 - 1/R^3)]`` and
    ``1/S^3 - 1/R^3 = (R - S)(R^2 + R S + S^2) / (R^3 S^3)``,
    ``R - S = -(2 R . rho + rho . rho) / (R + S)``.

    Parameters
    ----------
    rho_m : (..., 3) offsets of the points from the centre of mass, m
    r_cm_m : (..., 3) position of the centre of mass from the Earth's centre, m (broadcasts)
    mu : gravitational parameter, m^3/s^2

    Returns
    -------
    (..., 3) m/s^2, in the frame of the inputs.
    """
    rho = np.asarray(rho_m, dtype=float)
    rc = np.asarray(r_cm_m, dtype=float)
    s = rc + rho
    R2 = np.einsum("...i,...i->...", rc, rc)[..., None]
    S2 = np.einsum("...i,...i->...", s, s)[..., None]
    R, S = np.sqrt(R2), np.sqrt(S2)
    two_r_rho = 2.0 * np.einsum("...i,...i->...", rho, rc)[..., None]
    r_minus_s = -(two_r_rho + np.einsum("...i,...i->...", rho, rho)[..., None]) / (R + S)
    S3 = S2 * S
    inv_diff = r_minus_s * (R2 + R * S + S2) / (R2 * R * S3)
    return mu * (rho / S3 + rc * inv_diff)
