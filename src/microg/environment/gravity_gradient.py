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
    # S^2 - R^2 = 2 R . rho + rho . rho, formed from the small terms (no |R + rho| to round)
    q = 2.0 * (rho @ rc if rc.ndim == 1 else np.einsum("...i,...i->...", rho, rc))
    q += np.einsum("...i,...i->...", rho, rho)
    R2 = np.einsum("...i,...i->...", rc, rc)
    S2 = R2 + q
    R, S = np.sqrt(R2), np.sqrt(S2)
    S3 = S2 * S
    # g(R) - g(s) = (mu / S^3) rho + mu (1/S^3 - 1/R^3) R, with R - S = -q / (R + S)
    inv_diff = (-mu * q / (R + S)) * (R2 + R * S + S2) / (R2 * R * S3)
    out = rho * (mu / S3)[..., None]
    # rc * inv_diff[..., None] broadcasts a length-3 inner loop; the outer product is one call
    out += inv_diff[..., None] @ rc[None, :] if rc.ndim == 1 else rc * inv_diff[..., None]
    return out
