"""The symbols of the reproduction page, each with its meaning and unit (US customary and SI).

The reproduction shows the report's quantities in the report's units (slug, ft, lbf, s) and
accelerations in g; the SI unit and the factor from the US unit to it stand beside each.
Factors come from :mod:`microg.units` (exact definitions), not typed here.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from microg.units import FT, G0, G0_US, LBF, SLUG

__all__ = ["Symbol", "NOMENCLATURE", "nomenclature"]


@dataclass(frozen=True)
class Symbol:
    """One symbol of the page.

    Attributes
    ----------
    symbol : str
        As written on the page (plain text: ``w`` for omega, ``phi`` for phi).
    meaning : str
    unit_us : str
        Unit on the page (the report's US customary unit; ``-`` for dimensionless).
    unit_si : str
        The SI unit.
    si_per_us : float or None
        One ``unit_us`` in ``unit_si`` (None when dimensionless or the same unit).
    source : str
        Where the report defines it.
    """

    symbol: str
    meaning: str
    unit_us: str
    unit_si: str
    si_per_us: float | None
    source: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready entry."""
        return asdict(self)


_D = "-"  # dimensionless

NOMENCLATURE: tuple[Symbol, ...] = (
    # the station model
    Symbol(
        "z",
        "coordinate along the keel axis, from the joint of keel and keel extension; "
        "the rigid main body is at z <= 0",
        "ft",
        "m",
        FT,
        "Table 3 note",
    ),
    Symbol(
        "Z",
        "coordinate from the bottom end of the keel extension, Z = z + 100 ft",
        "ft",
        "m",
        FT,
        "Table 3 note",
    ),
    Symbol("y", "coordinate along the solar boom from the keel", "ft", "m", FT, "Table 3"),
    Symbol("z_e", "z of the observation point (the experiment), P_e", "ft", "m", FT, "Section 3"),
    Symbol("z_a", "z of the point where the crew force acts, P_a", "ft", "m", FT, "Section 3"),
    Symbol(
        "z_s",
        "z of the solar boom's attachment on the keel (165.5 ft)",
        "ft",
        "m",
        FT,
        "Section 2.4",
    ),
    Symbol("l_k", "length of the keel (296 ft)", "ft", "m", FT, "Eq. 2.21"),
    Symbol("l_s", "length of one half of the solar boom (132 ft)", "ft", "m", FT, "Eq. 2.21"),
    Symbol(
        "EI",
        "bending stiffness of booms and keel (1.31e9 lbf ft^2)",
        "lbf ft^2",
        "N m^2",
        LBF * FT**2,
        "Table 1",
    ),
    Symbol(
        "M_s, M_k",
        "mass of the solar boom frame, of the keel frame",
        "slug",
        "kg",
        SLUG,
        "Appendix A",
    ),
    Symbol(
        "I_x, I_y, I_z",
        "moments of inertia of the station about its principal axes "
        "through the centre of mass (x, y across the keel, z along it)",
        "slug ft^2",
        "kg m^2",
        SLUG * FT**2,
        "Eqs. 2.27-2.30, Table 2",
    ),
    Symbol(
        "I_sx, I_sy, I_UB, I_LB",
        "rotary inertias of a solar array, of the upper and the lower boom",
        "slug ft^2",
        "kg m^2",
        SLUG * FT**2,
        "Appendix A",
    ),
    Symbol("CG", "centre of mass (its Z coordinate)", "ft", "m", FT, "Table 2, Section 3"),
    Symbol(
        "W",
        "weight (the report converts weight to mass with g = 32.2 ft/s^2)",
        "lbf",
        "N",
        LBF,
        "Tables 2-3",
    ),
    Symbol(
        "g",
        f"the report's weight-to-mass conversion, {G0_US} ft/s^2; as a unit of "
        f"acceleration (a_e in g) microg uses standard gravity, {G0} m/s^2",
        "ft/s^2",
        "m/s^2",
        FT,
        "Section 3",
    ),
    # the four-coordinate model (Sections 2.1-2.5)
    Symbol(
        "q_1..q_4",
        "generalized coordinates: rigid translation, rigid rotation times l_k "
        "(q_2 = theta l_k), keel tip bending, boom tip bending",
        "ft",
        "m",
        FT,
        "Eqs. 2.1, 2.21",
    ),
    Symbol(
        "psi_i",
        "admissible functions: 1, z/l_k, (z/l_k)^2 - (z/l_k)^3/3, the same in y/l_s",
        _D,
        _D,
        None,
        "Eq. 2.21",
    ),
    Symbol(
        "m_ij",
        "generalized mass matrix (every q_i is a length, so every m_ij is a mass)",
        "slug",
        "kg",
        SLUG,
        "Eq. 2.5, Appendix A",
    ),
    Symbol(
        "k_ij",
        "generalized stiffness matrix: k33 = 4 EI/(3 l_k^3), k44 = 4 EI/(3 l_s^3); "
        "k22 is the gravity-gradient term (dropped in Eqs. 2.23-2.26)",
        "lbf/ft",
        "N/m",
        LBF / FT,
        "Eq. 2.6, Appendix B",
    ),
    Symbol(
        "T, mbar",
        "condensation of the rigid coordinates: [q1, q2] = T [q3, q4], and the "
        "condensed 2x2 mass mbar",
        "- ; slug",
        "- ; kg",
        SLUG,
        "Eqs. 2.23-2.24",
    ),
    Symbol("w", "circular frequency (the report's omega)", "rad/s", "rad/s", None, "Eq. 2.9"),
    Symbol(
        "w_j, w_j^2",
        "elastic circular frequency of mode j and its square",
        "rad/s, (rad/s)^2",
        "rad/s, (rad/s)^2",
        None,
        "Eq. 2.25, Appendix C",
    ),
    Symbol(
        "phi_j, phi_ij",
        "eigenvector of mode j and its i-th element, in the report's "
        "scaling (Eq. 2.26 times a power of ten; only ratios within a vector and phi^2/M_jj "
        "are physical)",
        _D,
        _D,
        None,
        "Eq. 2.26, Appendix C",
    ),
    Symbol(
        "M_jj",
        "modal (generalized) mass phi_j^T m phi_j, in the scaling of phi_j",
        "slug",
        "kg",
        SLUG,
        "Eq. 2.12a, Appendix C",
    ),
    Symbol("eta_j", "normal coordinate of mode j: q = Phi eta", "ft", "m", FT, "Eq. 2.11"),
    # crew force and response (Sections 2.2-2.3, 3)
    Symbol("f_a(t), f0", "crew force history and its peak (25 lbf)", "lbf", "N", LBF, "Eq. 2.16"),
    Symbol(
        "t1, t13, t14",
        "end of the push-off ramp, start and end of the landing (1, 13, 14 s)",
        "s",
        "s",
        None,
        "Eq. 2.16",
    ),
    Symbol(
        "d",
        "landing duration t14 - t13 (Eq. 2.19d as derived)",
        "s",
        "s",
        None,
        "Eq. 2.16",
    ),
    Symbol(
        "U(t)",
        "dimensionless displacement: eta = f0 U(t)/(w^3 t1)",
        _D,
        _D,
        None,
        "Eq. 2.17, Figure 3",
    ),
    Symbol(
        "A(t)",
        "dimensionless acceleration: eta'' = f0 A(t)/(w t1)",
        _D,
        _D,
        None,
        "Eq. 2.19, Figure 4",
    ),
    Symbol(
        "[A]max",
        "maximum over t of |A(t)| (exact here; the report estimates it from Figure 4)",
        _D,
        _D,
        None,
        "Eq. 3.1",
    ),
    Symbol(
        "a_e",
        "peak acceleration at the experiment, per mode (Eq. 3.1) or librational "
        "(Eq. 3.2); shown in g = 9.80665 m/s^2",
        "g",
        "m/s^2",
        G0,
        "Eqs. 3.1-3.2, Table 4",
    ),
    Symbol(
        "a(P_e, t)",
        "acceleration history at the observation point (modal sum)",
        "g",
        "m/s^2",
        G0,
        "Eq. 2.20b",
    ),
    # libration (Section 2.6-2.7, Appendix B-2)
    Symbol(
        "mu (Eq. 2.29)",
        "Earth's gravitational parameter, 1.407e16 ft^3/s^2",
        "ft^3/s^2",
        "m^3/s^2",
        FT**3,
        "Eq. 2.29, Appendix B-2",
    ),
    Symbol(
        "R",
        "orbit radius (not printed; 6,870 km reproduces the printed 1.89e-3 rad/s)",
        "ft",
        "m",
        FT,
        "Eq. 2.29",
    ),
    Symbol("w0", "orbital rate sqrt(mu/R^3)", "rad/s", "rad/s", None, "Eq. 2.29"),
    Symbol(
        "theta, theta_x, theta_y",
        "libration angle (roll about x, pitch about y)",
        "rad",
        "rad",
        None,
        "Eqs. 2.27-2.28",
    ),
    Symbol("w_x, w_y", "libration frequencies (roll, pitch)", "rad/s", "rad/s", None, "Eq. 2.30"),
    Symbol(
        "M_x, M_y, H",
        "disturbing torque, and H its impulse",
        "lbf ft; lbf ft s",
        "N m; N m s",
        LBF * FT,
        "Eqs. 2.31-2.33",
    ),
    # suspension (Section 4; named in the errata)
    Symbol("m1, m2", "main (package) mass and absorber mass", "slug", "kg", SLUG, "Eq. 4.1"),
    Symbol("W1", "package weight (1,000 lb)", "lbf", "N", LBF, "Section 4.2"),
    Symbol(
        "k1, k2",
        "main (suspension) spring and absorber spring",
        "lbf/ft",
        "N/m",
        LBF / FT,
        "Eq. 4.1",
    ),
    Symbol("c", "absorber damping coefficient", "lbf s/ft", "N s/m", LBF / FT, "Eq. 4.1"),
    Symbol(
        "U0, U1, A1",
        "amplitudes: support displacement, package displacement, package acceleration",
        "ft; ft; ft/s^2",
        "m; m; m/s^2",
        FT,
        "Eqs. 4.2-4.4",
    ),
    Symbol("M_a", "acceleration magnification factor |A1|/(w^2 U0)", _D, _D, None, "Eq. 4.5"),
    Symbol("D", "denominator of Eq. 4.7", _D, _D, None, "Eq. 4.7"),
    Symbol("k (Section 4)", "spring ratio k1/k2", _D, _D, None, "Eq. 4.6"),
    Symbol("mu (Section 4)", "absorber mass ratio m2/m1", _D, _D, None, "Eq. 4.6"),
    Symbol("zeta", "absorber damping factor c/(2 sqrt(m2 k2))", _D, _D, None, "Eq. 4.6"),
    Symbol(
        "r",
        "frequency ratio w/w_n (station frequency over the suspension's)",
        _D,
        _D,
        None,
        "Eq. 4.6",
    ),
    Symbol(
        "w_n",
        "natural frequency of the main mass-spring, sqrt(k1/m1)",
        "rad/s",
        "rad/s",
        None,
        "Eq. 4.6",
    ),
)


def nomenclature() -> list[dict[str, Any]]:
    """The nomenclature as JSON-ready entries."""
    return [s.to_dict() for s in NOMENCLATURE]
