"""Reproduction of the seed report's Sections 2-3 and Appendix C, with an errata.

Everything printed is recomputed: Appendix C (w^2, phi, M_jj from the printed matrices;
the shipped model's matrices element by element), Table 4 (bending frequencies and
accelerations by Eq. 3.1 with the exact [A]max; libration by Eqs. 2.30 and 3.2) and the
curves of Figures 3 and 4.  :func:`reproduce` returns a :class:`Reproduction`; the CLI and
the HTML report only read it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from microg.dynamics.crew import CrewPushoff, accel_amax, acceleration_a, displacement_u
from microg.dynamics.dense import solve_dense
from microg.models.station import Station
from microg.seed.condense import condensed_modes
from microg.seed.errata import ErrataEntry, build_errata
from microg.seed.ioc import CASES, FT, LBF, SLUG, printed, report_matrices, report_stiffness_us
from microg.seed.libration import libration_accel_impulse, libration_frequencies, orbital_rate
from microg.units import G0

__all__ = [
    "ReproduceOptions",
    "ErrataEntry",
    "AppendixCCase",
    "BendingRow",
    "LibrationRow",
    "Table4Case",
    "CurveSet",
    "Reproduction",
    "ReportPointResponse",
    "report_point_response",
    "reproduce",
]

#: relative bound within which a model element counts as matching Appendix C
MATRIX_BOUND = 0.02


@dataclass(frozen=True)
class ReproduceOptions:
    """Inputs of the reproduction (SI).

    Attributes
    ----------
    crew : CrewPushoff
        The crew force (the report's: 25 lbf, 1, 13, 14 s).
    z_e : float
        Observation point z (from the keel joint), m (the report: -55 ft).
    z_a : float
        Crew force z, m (the report: -55 ft).
    """

    crew: CrewPushoff
    z_e: float
    z_a: float

    @classmethod
    def report(cls) -> ReproduceOptions:
        """The report's own inputs (Section 2.3 and Section 3)."""
        c = printed()["constants"]
        return cls(
            CrewPushoff(c["crew_f0"] * LBF, c["crew_t1"], c["crew_t13"], c["crew_t14"]),
            c["z_lab"] * FT,
            c["z_lab"] * FT,
        )


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


@dataclass(frozen=True)
class Reproduction:
    """Everything ``microg reproduce`` computes."""

    options: ReproduceOptions
    appendix_c: dict[str, AppendixCCase]
    table4: dict[str, Table4Case]
    curves: CurveSet
    errata: list[ErrataEntry]
    model_mass: dict[str, dict[str, float]] = field(default_factory=dict)
    point_response: dict[str, ReportPointResponse] = field(default_factory=dict)

    def contract(self) -> dict:
        """The ``--json`` contract: ``appendix_c`` and ``table4`` keyed by case."""
        out: dict = {"appendix_c": {}, "table4": {}}
        for case, ac in self.appendix_c.items():
            out["appendix_c"][case] = {
                "label": ac.label,
                "printed_mass_matrix": ac.printed_mass_matrix,
                "model_mass_matrix": ac.model_mass_matrix,
                "element_rel_diff": ac.element_rel_diff,
                "omega2": ac.omega2,
                "omega2_full_eigenproblem": ac.omega2_full,
                "printed_omega2": ac.printed_omega2,
                "phi": ac.phi.T,
                "printed_phi": ac.printed_phi.T,
                "modal_mass": ac.modal_mass,
                "modal_mass_of_printed_phi": ac.modal_mass_of_printed_phi,
                "printed_modal_mass": ac.printed_modal_mass,
                "model_omega2": ac.model_omega2,
            }
        for case, t4 in self.table4.items():
            out["table4"][case] = {
                "bending": [
                    {
                        "omega": b.omega,
                        "accel_g": b.accel_g,
                        "printed_omega": b.printed_omega,
                        "printed_accel_g": b.printed_accel_g,
                        "amax": b.amax,
                        "participation": b.participation,
                        "model_omega": b.model_omega,
                        "model_accel_g": b.model_accel_g,
                    }
                    for b in t4.bending
                ],
                "libration": {
                    "omega": t4.libration.omega,
                    "accel_g": t4.libration.accel_g,
                    "printed_omega": t4.libration.printed_omega,
                    "printed_accel_g": t4.libration.printed_accel_g,
                    "model_omega": t4.libration.model_omega,
                    "model_accel_g": t4.libration.model_accel_g,
                    "exact_peak_accel_g": t4.libration.exact_peak_accel_g,
                },
                "rigid_translation_accel_g": t4.rigid_translation_accel_g,
            }
        out["options"] = {
            "f0_lbf": self.options.crew.f0 / LBF,
            "t1_s": self.options.crew.t1,
            "t13_s": self.options.crew.t13,
            "t14_s": self.options.crew.t14,
            "z_e_ft": self.options.z_e / FT,
            "z_a_ft": self.options.z_a / FT,
        }
        out["errata"] = [e.__dict__ for e in self.errata]
        out["model_mass_properties"] = self.model_mass
        return out


def _rel(a: float, b: float) -> float | None:
    return None if b == 0 else (a - b) / abs(b)


def _accel_eq31(
    phi: np.ndarray,
    modal_mass_kg: np.ndarray,
    omega: np.ndarray,
    opts: ReproduceOptions,
    l_k: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eq. 3.1 (Eq. 2.20b per mode): |psi(e) psi(a)| f0 [A]max / (M_jj w t1), m/s^2."""
    pe = phi[0] + phi[1] * opts.z_e / l_k
    pa = phi[0] + phi[1] * opts.z_a / l_k
    amax = accel_amax(omega, opts.crew)
    acc = np.abs(pe * pa) * opts.crew.f0 * amax / (modal_mass_kg * omega * opts.crew.t1)
    return acc, amax, pe * pa


def _appendix_case(
    case: str, model: Station, opts: ReproduceOptions
) -> tuple[AppendixCCase, np.ndarray, np.ndarray]:
    pr = printed()
    c = pr["constants"]
    entry = pr["appendix_c"][case]
    plane, _ = CASES[case]
    m = np.array(entry["mass"], float)
    k = report_stiffness_us(c["EI"], c["l_k"], c["l_s"])
    cm = condensed_modes(m, k[2, 2], k[3, 3])
    omega_full, _, _ = solve_dense(m, k, np.eye(4)[:, :2])
    printed_phi = np.array(entry["phi"], float).T
    mm_printed_phi = np.einsum("ij,ik,kj->j", printed_phi, m, printed_phi)
    rm = report_matrices(model, plane)
    model_m = rm.mass_us
    rel = np.where(m != 0, (model_m - m) / np.where(m != 0, np.abs(m), 1.0), 0.0)
    cm_model = condensed_modes(model_m, k[2, 2], k[3, 3])
    ac = AppendixCCase(
        case=case,
        label=entry["label"],
        printed_mass_matrix=m,
        model_mass_matrix=model_m,
        element_rel_diff=rel,
        omega2=cm.omega2,
        omega2_full=omega_full[2:] ** 2,
        printed_omega2=np.array(entry["omega2"], float),
        phi=cm.phi,
        printed_phi=printed_phi,
        modal_mass=cm.modal_mass,
        modal_mass_of_printed_phi=mm_printed_phi,
        printed_modal_mass=np.array(entry["modal_mass"], float),
        model_omega2=cm_model.omega2,
    )
    return ac, cm_model.phi, cm_model.modal_mass


def _table2_lever(case: str, z: float) -> float:
    """Distance from Table 2's centre of mass to station z (m); Z = z + 100 ft."""
    key = "orbiter" if CASES[case][1] else "no_orbiter"
    cg_z = printed()["table2"][key]["cg_Z"] * FT - 100.0 * FT
    return cg_z - z


def reproduce(
    opts: ReproduceOptions | None = None,
    models: dict[bool, Station] | None = None,
    *,
    curve_omegas: tuple[float, ...] = (0.1, 0.2, 0.3, 0.4),
    curve_tmax: float = 60.0,
) -> Reproduction:
    """Recompute Appendix C, Table 4 and Figures 3-4 of the report.

    Parameters
    ----------
    opts : ReproduceOptions, optional
        Crew force and points (the report's by default).
    models : dict, optional
        ``{True: station with orbiter, False: without}`` (the shipped models by default).
    curve_omegas : tuple of float
        Frequencies of Figures 3-4, rad/s.
    curve_tmax : float
        Time span of Figures 3-4, s.
    """
    from microg.models.toml import load_station

    opts = opts or ReproduceOptions.report()
    if models is None:
        models = {True: load_station("ioc"), False: load_station("ioc-no-orbiter")}
    pr = printed()
    l_k = pr["constants"]["l_k"] * FT
    appendix: dict[str, AppendixCCase] = {}
    table4: dict[str, Table4Case] = {}
    model_mass: dict[str, dict[str, float]] = {}
    for case, (plane, orbiter) in CASES.items():
        station = models[orbiter]
        ac, model_phi, model_mm = _appendix_case(case, station, opts)
        appendix[case] = ac
        omega = np.sqrt(ac.omega2)
        acc, amax, part = _accel_eq31(ac.phi, ac.modal_mass * SLUG, omega, opts, l_k)
        m_omega = np.sqrt(ac.model_omega2)
        m_acc, _, _ = _accel_eq31(model_phi, model_mm * SLUG, m_omega, opts, l_k)
        t4p = pr["table4"][case]
        rows = [
            BendingRow(
                omega=float(omega[j]),
                accel_g=float(acc[j] / G0),
                printed_omega=float(t4p["bending_omega"][j]),
                printed_accel_g=float(t4p["bending_accel_g"][j]),
                amax=float(amax[j]),
                participation=float(part[j]),
                model_omega=float(m_omega[j]),
                model_accel_g=float(m_acc[j] / G0),
            )
            for j in range(2)
        ]
        # libration: the report's route (Table 2 inertias and centre of mass)
        t2 = pr["table2"]["orbiter" if orbiter else "no_orbiter"]
        i_t2 = np.array(t2["inertia"], float) * SLUG * FT**2
        w0 = orbital_rate(station.orbit.radius, station.orbit.mu)
        axis = "y" if plane == "xz" else "x"
        i_axis = i_t2[1] if plane == "xz" else i_t2[0]
        w_lib = libration_frequencies(w0, i_t2)[axis]
        lever_e, lever_a = _table2_lever(case, opts.z_e), _table2_lever(case, opts.z_a)
        a_lib = libration_accel_impulse(lever_e, lever_a, opts.crew.f0, opts.crew.t1, w_lib, i_axis)
        total, cm, inertia = station.mass_properties()
        mw = libration_frequencies(w0, inertia)[axis]
        mi = inertia[1, 1] if plane == "xz" else inertia[0, 0]
        me, ma = cm[2] - opts.z_e, cm[2] - opts.z_a
        m_lib = libration_accel_impulse(me, ma, opts.crew.f0, opts.crew.t1, mw, mi)
        # exact rigid rotational acceleration over the whole history: z_e z_a f0/I A(t)/(w t1)
        exact = (
            abs(me * ma)
            * opts.crew.f0
            / (mi * mw * opts.crew.t1)
            * float(accel_amax(mw, opts.crew))
        )
        lib = LibrationRow(
            omega=w_lib,
            accel_g=a_lib / G0,
            printed_omega=float(t4p["libration_omega"]),
            printed_accel_g=float(t4p["libration_accel_g"]),
            model_omega=mw,
            model_accel_g=m_lib / G0,
            exact_peak_accel_g=exact / G0,
            lever_e=lever_e,
            lever_a=lever_a,
        )
        table4[case] = Table4Case(case, rows, lib, opts.crew.f0 / total / G0)
        model_mass["orbiter" if orbiter else "no_orbiter"] = {
            "total_mass_kg": total,
            "weight_lbf": total * 32.2 * FT / LBF,
            "cg_Z_ft": cm[2] / FT + 100.0,
            "table2_cg_Z_ft": float(t2["cg_Z"]),
            "Ix_slug_ft2": inertia[0, 0] / (SLUG * FT**2),
            "Iy_slug_ft2": inertia[1, 1] / (SLUG * FT**2),
            "Iz_slug_ft2": inertia[2, 2] / (SLUG * FT**2),
        }
    timepts = np.linspace(0.0, curve_tmax, 1201)
    w = np.asarray(curve_omegas, float)[:, None]
    curves = CurveSet(
        timepts,
        w[:, 0],
        displacement_u(w, timepts, opts.crew),
        acceleration_a(w, timepts, opts.crew),
        accel_amax(w[:, 0], opts.crew),
    )

    t_resp = np.linspace(0.0, 100.0, 2001)
    point_response = {}
    for case, ac in appendix.items():
        psi_e = np.array([1.0, opts.z_e / l_k, 0.0, 0.0])  # points on the rigid main body
        psi_a = np.array([1.0, opts.z_a / l_k, 0.0, 0.0])
        point_response[case] = report_point_response(
            ac.phi, ac.modal_mass * SLUG, np.sqrt(ac.omega2), psi_e, psi_a, opts.crew, t_resp
        )
    rep = Reproduction(opts, appendix, table4, curves, [], model_mass, point_response)
    return Reproduction(
        opts, appendix, table4, curves, build_errata(rep), model_mass, point_response
    )


@dataclass(frozen=True)
class ReportPointResponse:
    """Response at an observation point to the crew force at another (Eqs. 2.20a-b).

    Attributes
    ----------
    timepts : ndarray (nt,)
        s.
    displacement_modes, accel_modes : ndarray (nm, nt)
        Each elastic mode's contribution, m and m/s^2.
    displacement, accel : ndarray (nt,)
        Their sums (the report's modal superposition), m and m/s^2.
    peak_accel_modes : ndarray (nm,)
        Exact peak of each mode's contribution (Eq. 3.1), m/s^2.
    """

    timepts: np.ndarray
    displacement_modes: np.ndarray
    accel_modes: np.ndarray
    displacement: np.ndarray
    accel: np.ndarray
    peak_accel_modes: np.ndarray


def report_point_response(
    phi: np.ndarray,
    modal_mass: np.ndarray,
    omega: np.ndarray,
    psi_e: np.ndarray,
    psi_a: np.ndarray,
    crew: CrewPushoff,
    timepts: np.ndarray,
) -> ReportPointResponse:
    """Closed-form response at P_e to the crew force at P_a (Eqs. 2.20a, 2.20b, 3.1).

    ``u = sum_j (phi_j . psi(P_e)) (phi_j . psi(P_a)) U_j(t) f0/(w_j^3 t1 M_jj)`` and the
    same with ``A_j(t) f0/(w_j t1 M_jj)`` for the acceleration.

    Parameters
    ----------
    phi : ndarray (n, nm)
        Elastic eigenvectors, one per column (any scaling).
    modal_mass : ndarray (nm,)
        ``phi_j^T m phi_j``, kg (consistent with ``phi``).
    omega : ndarray (nm,)
        rad/s (> 0).
    psi_e, psi_a : ndarray (n,)
        Admissible functions at the observation and force points (Eq. 2.1); for the report's
        model ``[1, z/l_k, psi3(z), psi4(y)]`` (psi3 = psi4 = 0 on the rigid main body).
    crew : CrewPushoff
    timepts : ndarray (nt,)
        s.
    """
    part = (phi.T @ psi_e) * (phi.T @ psi_a)  # (nm,)
    w = omega[:, None]
    u = displacement_u(w, timepts, crew) * (crew.f0 / (w**3 * crew.t1 * modal_mass[:, None]))
    a = acceleration_a(w, timepts, crew) * (crew.f0 / (w * crew.t1 * modal_mass[:, None]))
    u = part[:, None] * u
    a = part[:, None] * a
    peak = np.abs(part) * crew.f0 * accel_amax(omega, crew) / (omega * crew.t1 * modal_mass)
    return ReportPointResponse(timepts, u, a, u.sum(axis=0), a.sum(axis=0), peak)
