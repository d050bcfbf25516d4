"""Eq. 3.1 of the seed report: the peak acceleration of each elastic mode at the laboratory.

``a_e = |(phi_1j + phi_2j z_e/l_k)(phi_1j + phi_2j z_a/l_k)| f0 [A_j]max / (M_jj w_j t1)``
(Eq. 2.20b per mode, with the exact [A_j]max of :func:`microg.dynamics.crew.accel_amax`).
The admissible functions at a point of the rigid main body are ``[1, z/l_k, 0, 0]``, so the
formula holds for points on the main body only (z <= 0, see
:data:`MAIN_BODY_Z_RANGE_FT`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from microg.dynamics.crew import CrewPushoff, accel_amax

__all__ = ["MAIN_BODY_Z_RANGE_FT", "Eq31", "eq31_accel"]

#: z range (ft, from the keel joint) of the report's rigid main body: its masses lie at
#: -5.5 to -126.66 ft (the orbiter, Table 3) and the keel starts at z = 0
MAIN_BODY_Z_RANGE_FT: tuple[float, float] = (-126.66, 0.0)


@dataclass(frozen=True)
class Eq31:
    """Eq. 3.1 for each elastic mode.

    Attributes
    ----------
    accel : ndarray (nm,)
        Peak acceleration per mode, m/s^2.
    amax : ndarray (nm,)
        Exact [A_j]max (dimensionless).
    participation : ndarray (nm,)
        (phi_1j + phi_2j z_e/l_k)(phi_1j + phi_2j z_a/l_k) (dimensionless in the report's
        scaling of phi).
    """

    accel: np.ndarray
    amax: np.ndarray
    participation: np.ndarray


def eq31_accel(
    phi: np.ndarray,
    modal_mass: np.ndarray,
    omega: np.ndarray,
    crew: CrewPushoff,
    z_e: float,
    z_a: float,
    l_k: float,
) -> Eq31:
    """Peak acceleration of each elastic mode at ``z_e`` from the crew force at ``z_a`` (Eq. 3.1).

    Parameters
    ----------
    phi : ndarray (4, nm)
        Eigenvectors in the report's coordinates (q1 translation, q2 = theta l_k, q3, q4),
        one per column, any scaling.
    modal_mass : ndarray (nm,)
        M_jj = phi_j^T m phi_j, kg (in the scaling of ``phi``).
    omega : ndarray (nm,)
        Elastic circular frequencies, rad/s (> 0).
    crew : CrewPushoff
        The force history (N, s).
    z_e, z_a : float
        Observation and force points on the rigid main body, m from the keel joint.
    l_k : float
        Keel length, m: psi_2 = z/l_k (Eq. 2.21b).
    """
    pe = phi[0] + phi[1] * z_e / l_k
    pa = phi[0] + phi[1] * z_a / l_k
    amax = np.atleast_1d(accel_amax(omega, crew))
    acc = np.abs(pe * pa) * crew.f0 * amax / (modal_mass * omega * crew.t1)
    return Eq31(acc, amax, pe * pa)
