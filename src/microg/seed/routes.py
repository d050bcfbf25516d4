"""The report's routes from printed data: Appendix C and Table 4 of a case, and libration.

:func:`case_solution` (Eqs. 2.23-2.26 and 3.1 from a 4x4 mass matrix with the report's
stiffness), :func:`libration_route` (Eqs. 2.30 and 3.2 from printed mass properties), and
:func:`printed_case`: one case recomputed from its printed matrix with the first-order
bound of the rounding of every printed element (what the Appendix C and Table 4 comparisons
judge, :mod:`microg.seed.agree_appendix_c`, :mod:`microg.seed.agree_table4`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from microg.dynamics.crew import CrewPushoff
from microg.seed.comparison import (
    CASE_NAMES,
    CAUSE_INCONSISTENT,
    Comparison,
    compare,
    rounding_bound,
)
from microg.seed.condense import condensed_modes
from microg.seed.eq31 import eq31_accel
from microg.seed.ioc import CASES, FT, SLUG, half_unit, printed, printed_literals
from microg.seed.libration import libration_accel_impulse, libration_frequencies
from microg.units import G0

__all__ = [
    "IU",
    "JU",
    "CaseSolution",
    "LibrationSolution",
    "PrintedCase",
    "case_solution",
    "libration_route",
    "power_of_ten",
    "printed_case",
    "sym4",
]

#: row and column of each element of a 4x4 upper triangle, row by row
IU, JU = np.triu_indices(4)


@dataclass(frozen=True)
class CaseSolution:
    """Appendix C and Table 4 of one case from a 4x4 mass matrix (report stiffness).

    Attributes
    ----------
    omega2 : ndarray (2,)
        Elastic w^2, (rad/s)^2 (Eq. 2.25).
    phi : ndarray (4, 2)
        Eigenvectors in Eq. 2.26's scaling, one per column.
    modal_mass : ndarray (2,)
        M_jj of ``phi``, slug.
    omega : ndarray (2,)
        rad/s.
    accel_g : ndarray (2,)
        Eq. 3.1 with the exact [A]max, g.
    amax : ndarray (2,)
        Exact [A_j]max.
    participation : ndarray (2,)
        (phi_1j + phi_2j z_e/l_k)(phi_1j + phi_2j z_a/l_k).
    """

    omega2: np.ndarray
    phi: np.ndarray
    modal_mass: np.ndarray
    omega: np.ndarray
    accel_g: np.ndarray
    amax: np.ndarray
    participation: np.ndarray


def case_solution(
    mass_slug: np.ndarray,
    k33: float,
    k44: float,
    crew: CrewPushoff,
    z_e: float,
    z_a: float,
    l_k: float,
) -> CaseSolution:
    """Elastic modes (Eqs. 2.23-2.26) and Eq. 3.1 of one case.

    Parameters
    ----------
    mass_slug : ndarray (4, 4)
        Generalized mass, slug.
    k33, k44 : float
        Report stiffness, lbf/ft.
    crew : CrewPushoff
        N, s.
    z_e, z_a : float
        Observation and force points on the main body, m from the keel joint.
    l_k : float
        Keel length, m.
    """
    cm = condensed_modes(mass_slug, k33, k44)
    omega = np.sqrt(cm.omega2)
    e = eq31_accel(cm.phi, cm.modal_mass * SLUG, omega, crew, z_e, z_a, l_k)
    return CaseSolution(
        cm.omega2, cm.phi, cm.modal_mass, omega, e.accel / G0, e.amax, e.participation
    )


@dataclass(frozen=True)
class LibrationSolution:
    """The report's librational line of Table 4 (Eqs. 2.30, 3.2).

    Attributes
    ----------
    omega : float
        rad/s.
    accel_g : float
        g.
    lever_e, lever_a : float
        Distances of observation point and force from the centre of mass, m.
    inertia : float
        Moment of inertia about the libration axis, kg m^2.
    """

    omega: float
    accel_g: float
    lever_e: float
    lever_a: float
    inertia: float


def libration_route(
    inertia_slug_ft2: np.ndarray,
    cg_z_ft: float,
    plane: str,
    omega0: float,
    crew: CrewPushoff,
    z_e: float,
    z_a: float,
) -> LibrationSolution:
    """Libration frequency (Eq. 2.30) and acceleration (Eq. 3.2) from printed mass properties.

    Parameters
    ----------
    inertia_slug_ft2 : ndarray (3,)
        I_x, I_y, I_z about the centre of mass, slug ft^2 (Table 2).
    cg_z_ft : float
        Centre of mass Z (from the bottom of the keel extension), ft; z = Z - 100 ft.
    plane : {"xz", "yz"}
        Pitch (about y) or roll (about x).
    omega0 : float
        Orbital rate, rad/s.
    crew : CrewPushoff
    z_e, z_a : float
        m from the keel joint.
    """
    i = np.asarray(inertia_slug_ft2, float) * SLUG * FT**2
    axis = "y" if plane == "xz" else "x"
    w = libration_frequencies(omega0, i)[axis]
    i_axis = float(i[1] if plane == "xz" else i[0])
    cg_z = cg_z_ft * FT - 100.0 * FT
    lever_e, lever_a = cg_z - z_e, cg_z - z_a
    a = libration_accel_impulse(lever_e, lever_a, crew.f0, crew.t1, w, i_axis)
    return LibrationSolution(w, a / G0, lever_e, lever_a, i_axis)


def sym4(values: np.ndarray) -> np.ndarray:
    """Symmetric 4x4 matrix from its upper triangle (row by row).

    Parameters
    ----------
    values : ndarray (10,)
        The upper triangle, in the unit of the matrix.
    """
    m = np.zeros((4, 4))
    i, j = IU, JU
    m[i, j] = values
    m[j, i] = values
    return m


def power_of_ten(ratio: float) -> float:
    """The signed power of ten nearest a ratio.

    Parameters
    ----------
    ratio : float
        Nonzero, dimensionless.
    """
    return float(np.sign(ratio) * 10.0 ** np.round(np.log10(abs(ratio))))


@dataclass(frozen=True)
class PrintedCase:
    """One case of Appendix C recomputed from its printed matrix, with the rounding bounds.

    Attributes
    ----------
    case, label : str
        Key of :data:`microg.seed.ioc.CASES` and the appendix's name (``C-1``...).
    plane : str
    orbiter : bool
    crew : CrewPushoff
        N, s.
    z_e, z_a : float
        Observation and force points, m from the keel joint.
    mass : ndarray (4, 4)
        The printed matrix, slug.
    x, h : ndarray (10,)
        Its upper triangle and half a unit in the last printed digit of each element.
    k33, k44 : float
        Report stiffness, lbf/ft.
    l_k : float
        Keel length, m.
    base : CaseSolution
        The modes and Eq. 3.1 of the printed matrix.
    printed_phi : ndarray (4, 2)
    printed_mm : ndarray (2,)
        Printed eigenvectors and modal masses (slug).
    phi_scale, mm_scale : ndarray (2,)
        The powers of ten of the report's scaling of each vector and modal mass.
    b_w2, b_mm, b_w, b_acc : ndarray (2,)
        Rounding bounds of w^2 ((rad/s)^2), M_jj (slug), w (rad/s), a_e (g).
    b_phi : ndarray (4, 2)
        Rounding bounds of the eigenvector elements.
    w2 : list of Comparison
        The w^2 comparisons (whether the printed matrix gives the printed frequencies).
    """

    case: str
    label: str
    plane: str
    orbiter: bool
    crew: CrewPushoff
    z_e: float
    z_a: float
    mass: np.ndarray
    x: np.ndarray
    h: np.ndarray
    k33: float
    k44: float
    l_k: float
    base: CaseSolution
    printed_phi: np.ndarray
    printed_mm: np.ndarray
    phi_scale: np.ndarray
    mm_scale: np.ndarray
    b_w2: np.ndarray
    b_phi: np.ndarray
    b_mm: np.ndarray
    b_w: np.ndarray
    b_acc: np.ndarray
    w2: list[Comparison]

    @property
    def inconsistent(self) -> bool:
        """True when the printed matrix does not give the printed frequencies."""
        return not all(cmp.agrees for cmp in self.w2)

    @property
    def cause_inconsistent(self) -> str:
        """The cause of every difference of an inconsistent case."""
        return CAUSE_INCONSISTENT.format(cn=self.label)


def printed_case(case: str, crew: CrewPushoff, z_e: float, z_a: float) -> PrintedCase:
    """Appendix C of ``case`` recomputed from its printed matrix, with the rounding bounds.

    Parameters
    ----------
    case : str
        Key of :data:`microg.seed.ioc.CASES`.
    crew : CrewPushoff
        N, s.
    z_e, z_a : float
        Observation and force points, m from the keel joint.
    """
    pr, lit = printed(), printed_literals()
    c = pr["constants"]
    cn = CASE_NAMES[case]
    plane, orbiter = CASES[case]
    entry, ltext = pr["appendix_c"][case], lit["appendix_c"][case]
    m = np.array(entry["mass"], float)
    x = m[IU, JU]
    cells = zip(x, IU, JU, strict=True)
    h = np.array([0.0 if v == 0 else half_unit(ltext["mass"][i][j]) for v, i, j in cells])
    k33 = 4 * c["EI"] / (3 * c["l_k"] ** 3)
    k44 = 4 * c["EI"] / (3 * c["l_s"] ** 3)
    l_k = c["l_k"] * FT
    base = case_solution(m, k33, k44, crew, z_e, z_a, l_k)
    printed_phi = np.array(entry["phi"], float).T
    phi_scale = np.array(
        [power_of_ten(float(np.median(printed_phi[:, j] / base.phi[:, j]))) for j in range(2)]
    )
    printed_mm = np.array(entry["modal_mass"], float)
    mm_scale = 10.0 ** (2 * np.round(0.5 * np.log10(printed_mm / base.modal_mass)))

    def values(xv: np.ndarray) -> np.ndarray:
        s = case_solution(sym4(xv), k33, k44, crew, z_e, z_a, l_k)
        return np.concatenate(
            [
                s.omega2,
                (s.phi * phi_scale).ravel(order="F"),
                s.modal_mass * mm_scale,
                s.omega,
                s.accel_g,
            ]
        )

    bound = rounding_bound(values, x, h)
    b_w2, b_phi, b_mm = bound[0:2], bound[2:10].reshape(4, 2, order="F"), bound[10:12]
    b_w, b_acc = bound[12:14], bound[14:16]
    # w^2 -- and whether this case's printed matrix and frequencies agree at all
    where = f"Appendix {cn}"
    w2 = [
        compare(
            "appendix_c_omega2",
            where,
            f"w_{j + 1}^2 (rad/s)^2",
            ltext["omega2"][j],
            base.omega2[j],
            b_w2[j],
        )
        for j in range(2)
    ]
    return PrintedCase(
        case, cn, plane, orbiter, crew, z_e, z_a, m, x, h, k33, k44, l_k, base, printed_phi,
        printed_mm, phi_scale, mm_scale, b_w2, b_phi, b_mm, b_w, b_acc, w2,
    )  # fmt: skip
