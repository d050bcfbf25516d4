"""The report's closed-form path to the elastic modes (Eqs. 2.23-2.26).

Eliminate the rigid translation q1 and rotation q2 (their stiffness is zero once the
gravity-gradient coupling is dropped), leaving a 2x2 problem in q3, q4 with the condensed
mass ``mbar = m_ee + m_er T``, ``T = -m_rr^-1 m_re`` (Eq. 2.23-2.24), whose two
frequencies have the closed form of Eq. 2.25 and eigenvectors Eq. 2.26.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["CondensedModes", "condensed_modes"]


@dataclass(frozen=True)
class CondensedModes:
    """Elastic modes of a 4-coordinate model by static condensation of the rigid ones.

    Attributes
    ----------
    omega2 : ndarray (2,)
        Elastic w^2, ascending, (rad/s)^2 (Eq. 2.25).
    phi : ndarray (4, 2)
        Eigenvectors in the report's scaling (Eq. 2.26), one per column.
    modal_mass : ndarray (2,)
        M_jj = phi_j^T m phi_j (Eq. 2.12a), in the mass unit of ``m``.
    transform : ndarray (2, 2)
        T of Eq. 2.23: [q1, q2] = T [q3, q4].
    mbar : ndarray (2, 2)
        Condensed mass of Eq. 2.24.
    """

    omega2: np.ndarray
    phi: np.ndarray
    modal_mass: np.ndarray
    transform: np.ndarray
    mbar: np.ndarray

    @property
    def omega(self) -> np.ndarray:
        """Elastic circular frequencies, rad/s."""
        return np.sqrt(self.omega2)


def condensed_modes(mass: np.ndarray, k33: float, k44: float) -> CondensedModes:
    """Closed-form elastic modes of the report's 4x4 model (Eqs. 2.23-2.26).

    Parameters
    ----------
    mass : ndarray (4, 4)
        Generalized mass (any consistent unit, e.g. slug).
    k33, k44 : float
        Bending stiffnesses of keel and boom (unit consistent with ``mass``: lbf/ft with
        slug gives (rad/s)^2).

    Notes
    -----
    Eq. 2.26 prints the third element as ``mbar33 w^2``; the second row of Eq. 2.24 gives
    ``q3 : q4 = mbar34 w^2 : (k33 - mbar33 w^2)``, which is what the first two rows (the
    T-transformed ones) also use.  This function uses ``mbar34 w^2``.
    """
    m = np.asarray(mass, float)
    t = -np.linalg.solve(m[:2, :2], m[:2, 2:])
    mbar = m[2:, 2:] + m[2:, :2] @ t
    m33, m34, m43, m44 = mbar[0, 0], mbar[0, 1], mbar[1, 0], mbar[1, 1]
    disc = np.sqrt((m33 * k44 - m44 * k33) ** 2 + 4 * m34 * m43 * k33 * k44)
    den = 2 * (m33 * m44 - m34 * m43)
    omega2 = np.array([(m33 * k44 + m44 * k33 - disc) / den, (m33 * k44 + m44 * k33 + disc) / den])
    q3 = m34 * omega2
    q4 = k33 - m33 * omega2
    qe = np.vstack([q3, q4])
    phi = np.vstack([t @ qe, qe])
    modal_mass = np.einsum("ij,ik,kj->j", phi, m, phi)
    return CondensedModes(omega2, phi, modal_mass, t, mbar)
