"""Reproduction of the seed report's Sections 2-3 and Appendix C, with an errata.

Everything printed is recomputed: Appendix C (w^2, phi, M_jj from the printed matrices;
the shipped model's matrices element by element), Table 4 (bending frequencies and
accelerations by Eq. 3.1 with the exact [A]max; libration by Eqs. 2.30 and 3.2) and the
curves of Figures 3 and 4.  Each printed value is compared with its recomputation within a
stated tolerance (:mod:`microg.seed.agreement`), each difference is explained in the errata
(:mod:`microg.seed.errata`), and the result names the report
(:data:`microg.seed.source.SEED_REPORT`) and the files it was made from (``meta``).
:func:`reproduce` returns a :class:`Reproduction`; the CLI and the HTML report only read it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from microg.dynamics.crew import CrewPushoff, accel_amax, acceleration_a, displacement_u
from microg.dynamics.dense import solve_dense
from microg.errors import InputError
from microg.models.station import Station
from microg.seed.agreement import (
    Agreement,
    Comparison,
    build_comparisons,
    case_solution,
    libration_route,
    summarize,
)
from microg.seed.condense import condensed_modes
from microg.seed.eq31 import MAIN_BODY_Z_RANGE_FT, eq31_accel
from microg.seed.errata import ErrataEntry, build_errata
from microg.seed.ioc import CASES, FT, LBF, SLUG, printed, report_matrices, report_stiffness_us
from microg.seed.libration import libration_accel_impulse, libration_frequencies, orbital_rate
from microg.seed.nomenclature import nomenclature
from microg.seed.source import SEED_REPORT, SeedReport, reproduction_meta
from microg.seed.tables import AppendixCCase, BendingRow, CurveSet, LibrationRow, Table4Case
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

    Both points must lie on the rigid main body, z in
    :data:`microg.seed.eq31.MAIN_BODY_Z_RANGE_FT` (-126.66 to 0 ft): Eq. 3.1 takes the
    admissible functions there as ``[1, z/l_k, 0, 0]``, which a point on the keel or the
    boom does not have.
    """

    crew: CrewPushoff
    z_e: float
    z_a: float

    def __post_init__(self) -> None:
        lo, hi = (v * FT for v in MAIN_BODY_Z_RANGE_FT)
        for name in ("z_e", "z_a"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
                raise InputError(f"must be a number, got {v!r}", where=name)
            if not np.isfinite(v):
                raise InputError(f"must be finite, got {v}", where=name)
            if not lo - 1e-9 <= v <= hi + 1e-9:
                raise InputError(
                    f"{v / FT:.6g} ft ({v:.6g} m) is not on the rigid main body "
                    f"({MAIN_BODY_Z_RANGE_FT[0]:g} ft <= z <= {MAIN_BODY_Z_RANGE_FT[1]:g} ft, "
                    "from the keel joint)",
                    where=name,
                    fix="Eq. 3.1 holds on the main body only, where the keel and boom "
                    "functions vanish; the report's laboratory is at -55 ft",
                )
            object.__setattr__(self, name, float(v))

    def is_report(self) -> bool:
        """Whether these are the report's own inputs (its printed accelerations are for them)."""
        r = ReproduceOptions.report()
        mine = (self.crew.f0, self.crew.t1, self.crew.t13, self.crew.t14, self.z_e, self.z_a)
        theirs = (r.crew.f0, r.crew.t1, r.crew.t13, r.crew.t14, r.z_e, r.z_a)
        return bool(np.allclose(mine, theirs, rtol=1e-12, atol=0.0))

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
class Reproduction:
    """Everything ``microg reproduce`` computes.

    Attributes
    ----------
    options : ReproduceOptions
    appendix_c, table4 : dict
        Per case (keys of :data:`microg.seed.ioc.CASES`).
    curves : CurveSet
        Figures 3 and 4.
    errata : list of ErrataEntry
        Every difference (ids ``E1``, ...), the OCR corrections and the errors of the text.
    model_mass : dict
        The shipped models' mass properties.
    point_response : dict
        Eq. 2.20b at the observation point per case.
    comparisons : list of Comparison
        Every printed value compared, with its tolerance and its erratum id.
    agreement : Agreement or None
        The comparisons counted per table and appendix.
    meta : dict
        Provenance: ``microg_version``, ``created_utc``, ``command``, the seed report's file
        and sha256, the printed-values file and its sha256, the models read and theirs.
    seed_report : SeedReport
    """

    options: ReproduceOptions
    appendix_c: dict[str, AppendixCCase]
    table4: dict[str, Table4Case]
    curves: CurveSet
    errata: list[ErrataEntry]
    model_mass: dict[str, dict[str, float]] = field(default_factory=dict)
    point_response: dict[str, ReportPointResponse] = field(default_factory=dict)
    comparisons: list[Comparison] = field(default_factory=list)
    agreement: Agreement | None = None
    meta: dict = field(default_factory=dict)
    seed_report: SeedReport = SEED_REPORT

    def to_dict(self) -> dict:
        """JSON-ready results (the same as :meth:`contract`)."""
        return self.contract()

    def contract(self) -> dict:
        """The ``--json`` contract.

        ``seed_report``, ``meta``, ``agreement``, ``comparisons``, ``nomenclature``, then
        ``appendix_c`` and ``table4`` keyed by case, ``options``, ``errata`` and
        ``model_mass_properties``.
        """
        out: dict = {
            "seed_report": self.seed_report.to_dict(),
            "meta": self.meta,
            "agreement": self.agreement.to_dict() if self.agreement is not None else None,
            "comparisons": [c.to_dict() for c in self.comparisons],
            "nomenclature": nomenclature(),
            "appendix_c": {},
            "table4": {},
        }
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
            "f0_N": self.options.crew.f0,
            "t1_s": self.options.crew.t1,
            "t13_s": self.options.crew.t13,
            "t14_s": self.options.crew.t14,
            "z_e_ft": self.options.z_e / FT,
            "z_e_m": self.options.z_e,
            "z_a_ft": self.options.z_a / FT,
            "z_a_m": self.options.z_a,
            "report_inputs": self.options.is_report(),
        }
        out["errata"] = [e.__dict__ for e in self.errata]
        out["model_mass_properties"] = self.model_mass
        return out


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


def reproduce(
    opts: ReproduceOptions | None = None,
    models: dict[bool, Station] | None = None,
    *,
    cases: tuple[str, ...] | list[str] | None = None,
    command: str | None = None,
    curve_omegas: tuple[float, ...] = (0.1, 0.2, 0.3, 0.4),
    curve_tmax: float = 60.0,
) -> Reproduction:
    """Recompute Appendix C, Table 4 and Figures 3-4 of the report, compare, and explain.

    Parameters
    ----------
    opts : ReproduceOptions, optional
        Crew force and points (the report's by default).  With other inputs the printed
        accelerations (which are for the report's) are shown but not compared.
    models : dict, optional
        ``{True: station with orbiter, False: without}`` (the shipped models by default).
    cases : sequence of str, optional
        Cases of :data:`microg.seed.ioc.CASES` (all four by default).
    command : str, optional
        The command line, for the provenance (``meta.command``).
    curve_omegas : tuple of float
        Frequencies of Figures 3-4, rad/s.
    curve_tmax : float
        Time span of Figures 3-4, s.
    """
    from microg.models.toml import load_station

    opts = opts or ReproduceOptions.report()
    chosen = list(CASES) if not cases else [c for c in CASES if c in cases]
    unknown = sorted(set(cases or ()) - set(CASES))
    if unknown or not chosen:
        raise InputError(
            f"unknown case(s) {unknown}", where="cases", fix=f"choose from {list(CASES)}"
        )
    if models is None:
        models = {True: load_station("ioc"), False: load_station("ioc-no-orbiter")}
    pr = printed()
    c = pr["constants"]
    l_k = c["l_k"] * FT
    k = report_stiffness_us(c["EI"], c["l_k"], c["l_s"])
    appendix: dict[str, AppendixCCase] = {}
    table4: dict[str, Table4Case] = {}
    model_mass: dict[str, dict[str, float]] = {}
    omega0: dict[bool, float] = {}
    for case in chosen:
        plane, orbiter = CASES[case]
        station = models[orbiter]
        ac, model_phi, model_mm = _appendix_case(case, station, opts)
        appendix[case] = ac
        sol = case_solution(
            ac.printed_mass_matrix, k[2, 2], k[3, 3], opts.crew, opts.z_e, opts.z_a, l_k
        )
        m_omega = np.sqrt(ac.model_omega2)
        m_acc = eq31_accel(
            model_phi, model_mm * SLUG, m_omega, opts.crew, opts.z_e, opts.z_a, l_k
        ).accel
        t4p = pr["table4"][case]
        rows = [
            BendingRow(
                omega=float(sol.omega[j]),
                accel_g=float(sol.accel_g[j]),
                printed_omega=float(t4p["bending_omega"][j]),
                printed_accel_g=float(t4p["bending_accel_g"][j]),
                amax=float(sol.amax[j]),
                participation=float(sol.participation[j]),
                model_omega=float(m_omega[j]),
                model_accel_g=float(m_acc[j] / G0),
            )
            for j in range(2)
        ]
        # libration: the report's route (Table 2 inertias and centre of mass)
        t2 = pr["table2"]["orbiter" if orbiter else "no_orbiter"]
        w0 = orbital_rate(station.orbit.radius, station.orbit.mu)
        omega0[orbiter] = w0
        route = libration_route(
            np.array(t2["inertia"], float),
            float(t2["cg_Z"]),
            plane,
            w0,
            opts.crew,
            opts.z_e,
            opts.z_a,
        )
        axis = "y" if plane == "xz" else "x"
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
            omega=route.omega,
            accel_g=route.accel_g,
            printed_omega=float(t4p["libration_omega"]),
            printed_accel_g=float(t4p["libration_accel_g"]),
            model_omega=mw,
            model_accel_g=m_lib / G0,
            exact_peak_accel_g=exact / G0,
            lever_e=route.lever_e,
            lever_a=route.lever_a,
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
    report_inputs = opts.is_report()
    comparisons = build_comparisons(
        chosen,
        opts.crew,
        opts.z_e,
        opts.z_a,
        {case: omega0[CASES[case][1]] for case in chosen},
        {case: appendix[case].model_mass_matrix for case in chosen},
        model_mass,
        report_inputs=report_inputs,
    )
    errata, comparisons = build_errata(comparisons, cases=list(appendix), table4=table4)
    meta = reproduction_meta(
        command, [(st.name, st.source) for o, st in models.items() if o in omega0]
    )
    return Reproduction(
        opts,
        appendix,
        table4,
        curves,
        errata,
        model_mass,
        point_response,
        comparisons,
        summarize(comparisons, report_inputs=report_inputs),
        meta,
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
