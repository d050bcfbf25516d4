"""The tables of the seed report as microg recomputes them: Appendix C, Table 4, Figures 3-4.

Rows and cases of :class:`~microg.seed.reproduce.Reproduction` (SI unless a field names its
unit; the report's slug where it prints slug), filled by :func:`microg.seed.reproduce.reproduce`
and read by the errata (:mod:`microg.seed.errata`), the CLI and the HTML report.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["AppendixCCase", "BendingRow", "CurveSet", "LibrationRow", "Table4Case"]


@dataclass(frozen=True)
class AppendixCCase:
    """Appendix C for one case, recomputed.

    Attributes
    ----------
    case, label : str
    printed_mass_matrix : ndarray (4, 4)
        As printed (slug), with the OCR corrections listed in the errata.
    model_mass_matrix : ndarray (4, 4)
        From the shipped model (slug).
    element_rel_diff : ndarray (4, 4)
        (model - printed) / |printed| (0 where printed is 0).
    omega2 : ndarray (2,)
        Elastic w^2 from the printed matrix, closed form (Eq. 2.25), (rad/s)^2.
    omega2_full : ndarray (2,)
        The same from the full 4x4 eigenproblem (Eq. 2.9), rigid modes at zero.
    printed_omega2 : ndarray (2,)
    phi : ndarray (4, 2)
        Eigenvectors of Eq. 2.26 (report scaling) from the printed matrix.
    printed_phi : ndarray (4, 2)
    modal_mass : ndarray (2,)
        M_jj of ``phi`` (slug).
    modal_mass_of_printed_phi : ndarray (2,)
        M_jj computed from the printed eigenvectors (slug).
    printed_modal_mass : ndarray (2,)
    model_omega2 : ndarray (2,)
        Elastic w^2 of the model's matrices with the report's stiffness (rad/s)^2.
    """

    case: str
    label: str
    printed_mass_matrix: np.ndarray
    model_mass_matrix: np.ndarray
    element_rel_diff: np.ndarray
    omega2: np.ndarray
    omega2_full: np.ndarray
    printed_omega2: np.ndarray
    phi: np.ndarray
    printed_phi: np.ndarray
    modal_mass: np.ndarray
    modal_mass_of_printed_phi: np.ndarray
    printed_modal_mass: np.ndarray
    model_omega2: np.ndarray


@dataclass(frozen=True)
class BendingRow:
    """One bending mode of Table 4.

    Attributes
    ----------
    omega : float
        rad/s, from the printed matrix (Eq. 2.25).
    accel_g : float
        Eq. 3.1 with the exact [A]max, g.
    printed_omega, printed_accel_g : float
    amax : float
        Exact [A_j]max.
    participation : float
        (phi_1j + phi_2j z_e/l_k)(phi_1j + phi_2j z_a/l_k).
    model_omega, model_accel_g : float
        The same from the shipped model's mass matrix (report stiffness).
    """

    omega: float
    accel_g: float
    printed_omega: float
    printed_accel_g: float
    amax: float
    participation: float
    model_omega: float
    model_accel_g: float


@dataclass(frozen=True)
class LibrationRow:
    """The librational line of Table 4.

    Attributes
    ----------
    omega : float
        rad/s, Eq. 2.30 with Table 2's inertias and the model's orbit radius.
    accel_g : float
        Eq. 3.2 (impulse of the push-off, Table 2 centre of mass and inertia), g.
    printed_omega, printed_accel_g : float
    model_omega, model_accel_g : float
        The same with the shipped model's own centre of mass and inertias.
    exact_peak_accel_g : float
        Exact max of the rigid rotational acceleration over the whole force history
        (push-off and landing, the model's inertia), g.
    lever_e, lever_a : float
        Distances of observation point and force from the centre of mass (Table 2), m.
    """

    omega: float
    accel_g: float
    printed_omega: float
    printed_accel_g: float
    model_omega: float
    model_accel_g: float
    exact_peak_accel_g: float
    lever_e: float
    lever_a: float


@dataclass(frozen=True)
class Table4Case:
    """Table 4 for one case."""

    case: str
    bending: list[BendingRow]
    libration: LibrationRow
    rigid_translation_accel_g: float


@dataclass(frozen=True)
class CurveSet:
    """Figures 3 and 4: U(t) and A(t) for several w.

    Attributes
    ----------
    timepts : ndarray (nt,)
        s.
    omega : ndarray (nw,)
        rad/s.
    u : ndarray (nw, nt)
    a : ndarray (nw, nt)
    amax : ndarray (nw,)
        Exact max |A| over all t.
    """

    timepts: np.ndarray
    omega: np.ndarray
    u: np.ndarray
    a: np.ndarray
    amax: np.ndarray
