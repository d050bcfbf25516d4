"""The errata of the seed report: each printed value beside microg's, and the reason.

Built from a :class:`~microg.seed.reproduce.Reproduction`; every number here is computed, the
reasons are the findings of the seed review re-checked by the computation (for example a
printed libration acceleration is called "twice Eq. 3.2" only when the ratio is within 5%
of 2).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from microg.seed.ioc import CASES, printed

if TYPE_CHECKING:
    from microg.seed.reproduce import Reproduction

__all__ = ["ErrataEntry", "build_errata"]


@dataclass(frozen=True)
class ErrataEntry:
    """One printed value beside its recomputation, and why they differ."""

    where: str
    quantity: str
    printed: float | None
    recomputed: float | None
    rel_diff: float | None
    reason: str


def _rel(a: float, b: float) -> float | None:
    return None if b == 0 else float((a - b) / abs(b))


def _orbiter_increments() -> dict[tuple[int, int], float]:
    """Orbiter's increments to m11, m12, m22 in the X-Z plane (slug): m_o, m_o zbar, m_o zbar^2."""
    c = printed()["constants"]
    m_o = 235400.0 / c["g"]
    zbar = -126.66 / c["l_k"]
    return {(0, 0): m_o, (0, 1): m_o * zbar, (1, 1): m_o * zbar**2}


def _element_reason(case: str, i: int, j: int, rep: Reproduction) -> str:
    plane, orbiter = CASES[case]
    pr = printed()["appendix_c"]
    c = printed()["constants"]
    if plane == "yz" and (i, j) in ((1, 3), (2, 3)):
        zs = c["z_s"] / c["l_k"]
        slope = 1.0 if i == 1 else 2 * zs - zs**2
        ms = 2345.0 / c["g"]
        delta = (13 / 30 - 11 / 60) * ms * c["l_s"] * slope / c["l_k"]
        model = rep.appendix_c[case].model_mass_matrix[i, j]
        return (
            "Appendix A-2 writes the boom's distributed term as 13/30 M_s l_s; the integral "
            "of y psi4(y/l_s) over the boom is 11/60 M_s l_s. With 13/30 the model gives "
            f"{model - delta:.1f}; no non-negative array inertia matches m24, m34 and m44 together"
        )
    if not orbiter:
        inc = _orbiter_increments()
        src = "xz_orbiter" if plane == "xz" else "yz_orbiter"
        with_orb = np.array(pr[src]["mass"], float)
        if (i, j) in inc:
            implied = with_orb[i, j] - inc[(i, j)]
            return (
                f"C-{'1' if plane == 'xz' else '3'} minus the orbiter's own increment "
                f"({inc[(i, j)]:.1f}) gives {implied:.1f}; the printed no-orbiter value "
                "does not follow from the printed with-orbiter matrix"
                + (
                    " (C-4's m22 repeats C-3's 3298)"
                    if (case, i, j) == ("yz_no_orbiter", 1, 1)
                    else ""
                )
            )
        if (i, j) == (3, 3):
            return "m44 does not depend on the orbiter; C-1 and C-3 print 122.9"
    if (i, j) in ((0, 1), (0, 2), (1, 2), (1, 1), (2, 2)):
        return (
            "keel-dependent element: the keel masses are fitted (non-negative least squares "
            "to C-1/C-3); the printed moments are not all attainable by masses on the keel"
        )
    return "rounding of the printed matrix and of the fitted model values"


def build_errata(rep: Reproduction) -> list[ErrataEntry]:
    """Every discrepancy between the printed report and microg's recomputation."""
    out: list[ErrataEntry] = []
    c = printed()["constants"]

    def add(where: str, qty: str, p: float | None, r: float | None, reason: str) -> None:
        rel = None if p is None or r is None else _rel(r, p)
        out.append(ErrataEntry(where, qty, p, r, rel, reason))

    names = {
        "xz_orbiter": "C-1",
        "xz_no_orbiter": "C-2",
        "yz_orbiter": "C-3",
        "yz_no_orbiter": "C-4",
    }
    for case, ac in rep.appendix_c.items():
        cn = names[case]
        consistent = case in ("xz_orbiter", "yz_orbiter")
        for j in range(2):
            reason = (
                "agrees: printed matrix rounded to 4 digits"
                if consistent
                else "the printed matrix, eigenvectors and frequencies of "
                f"{cn} disagree with each other (seed review); recomputed from the printed matrix"
            )
            add(
                f"Appendix {cn}",
                f"w_{j + 1}^2 (rad/s)^2",
                ac.printed_omega2[j],
                ac.omega2[j],
                reason,
            )
        for j in range(2):
            # the report scales its vectors by powers of ten; use the nearest one
            power = np.round(0.5 * np.log10(ac.printed_modal_mass[j] / ac.modal_mass[j]))
            mm = ac.modal_mass[j] * 10.0 ** (2 * power)
            of_printed = ac.modal_mass_of_printed_phi[j]
            close = abs(of_printed - ac.printed_modal_mass[j]) < 0.01 * ac.printed_modal_mass[j]
            add(
                f"Appendix {cn}",
                f"M_{j + 1}{j + 1} (slug, Eq. 2.26 vector x 1e{int(power)})",
                ac.printed_modal_mass[j],
                mm,
                f"phi^T m phi of the printed eigenvector is {of_printed:.4g}"
                + (
                    ": the printed M_jj follows from the printed phi"
                    if close
                    else ": the printed M_jj does not follow from the printed phi"
                ),
            )
        # eigenvector elements that disagree beyond 2% after a common scale
        for j in range(2):
            pp = ac.printed_phi[:, j]
            rp = ac.phi[:, j]
            scale = float(np.median(pp / rp))  # robust to one misprinted element
            rs = rp * scale
            for i in range(4):
                if abs(rs[i] - pp[i]) > 0.02 * max(abs(pp[i]), 1e-12):
                    add(
                        f"Appendix {cn}",
                        f"phi_{j + 1}[{i + 1}] (scaled to the printed vector)",
                        float(pp[i]),
                        float(rs[i]),
                        "misprint or a vector that is not an eigenvector of the printed matrix",
                    )
        for (i, j), ocr in _ocr(case).items():
            add(
                f"Appendix {cn}",
                f"m{i + 1}{j + 1} as read",
                ocr[0],
                ocr[1],
                "OCR damage: value used",
            )
        for i in range(4):
            for j in range(i, 4):
                p = ac.printed_mass_matrix[i, j]
                r = ac.model_mass_matrix[i, j]
                if p != 0 and abs(r - p) > 0.02 * abs(p):
                    add(
                        f"Appendix {cn} vs model",
                        f"m{i + 1}{j + 1} (slug)",
                        float(p),
                        float(r),
                        _element_reason(case, i, j, rep),
                    )
    for case, t4 in rep.table4.items():
        for j, b in enumerate(t4.bending):
            add(
                f"Table 4 {case}",
                f"bending w_{j + 1} (rad/s)",
                b.printed_omega,
                b.omega,
                "sqrt of the Appendix C w^2 recomputed from the printed matrix",
            )
            implied = b.printed_accel_g / b.accel_g * b.amax if b.accel_g else float("nan")
            add(
                f"Table 4 {case}",
                f"bending a_e mode {j + 1} (g)",
                b.printed_accel_g,
                b.accel_g,
                f"Eq. 3.1 with exact [A]max = {b.amax:.4g}; the printed value implies "
                f"[A]max = {implied:.3g} (read by eye from Figure 4) with the recomputed "
                "phi and M_jj",
            )
        lib = t4.libration
        add(
            f"Table 4 {case}",
            "libration w (rad/s)",
            lib.printed_omega,
            lib.omega,
            "Eq. 2.30 with Table 2's inertias and an orbit radius of 6,870 km",
        )
        ratio = lib.printed_accel_g / lib.accel_g if lib.accel_g else float("nan")
        if abs(ratio - 2.0) < 0.1:
            why = (
                f"printed/recomputed = {ratio:.3f}: the printed value omits the 1/2 of Eq. 3.2 "
                "(the push-off impulse is f0 t1/2)"
            )
        else:
            why = f"printed/recomputed = {ratio:.3f}"
        add(f"Table 4 {case}", "libration a_e (g)", lib.printed_accel_g, lib.accel_g, why)
    xo = rep.table4.get("xz_orbiter") or next(iter(rep.table4.values()))
    out.append(
        ErrataEntry(
            "Eq. 3.1 / Table 4",
            "rigid translation acceleration during the push (g)",
            None,
            xo.rigid_translation_accel_g,
            None,
            "Eq. 3.1 sums the elastic modes only; the whole station accelerates at f0/m11 "
            "while the crew pushes, more than either bending mode, and rigid rotation adds "
            f"{xo.libration.exact_peak_accel_g:.3g} g at the lab (vs the libration "
            f"{xo.libration.accel_g:.3g} g of Eq. 3.2)",
        )
    )
    mm = rep.model_mass
    cg = printed()["cg_table"]
    for key, label in (("orbiter", "with orbiter"), ("no_orbiter", "without orbiter")):
        add(
            "Section 3, centre-of-mass table",
            f"CG Z {label}, report's 'present model' (ft)",
            float(cg[key]["present_model_Z"]),
            mm[key]["cg_Z_ft"],
            "the report's own model vs the shipped model (keel masses fitted to Appendix C); "
            "the printed table has the 'present model' rows swapped (59.5 belongs to the "
            f"orbiter case: 68.3 - 59.5 = 8.8, its printed difference); Table 2 gives "
            f"{cg[key]['table2_Z']} ft",
        )
    ek = 4 * c["EI"] / (3 * c["l_s"] ** 3)
    out.append(
        ErrataEntry(
            "Appendix B-1",
            "k44 (lbf/ft)",
            ek,
            2 * ek,
            1.0,
            "k44 = 4EI/(3 l_s^3) is one cantilever, but m44 counts the mass of both boom halves; "
            "two half-booms bending together have twice the stiffness. The reproduction uses the "
            "report's k44; the model-based analyses use the physical two-sided boom",
        )
    )
    for where, text in _TEXT_ERRATA:
        out.append(ErrataEntry(where, text[0], None, None, None, text[1]))
    return out


def _ocr(case: str) -> dict[tuple[int, int], tuple[float, float]]:
    fixes = printed()["appendix_c"][case].get("ocr_corrections", [])
    return {(int(i), int(j)): (float(a), float(b)) for i, j, a, b in fixes}


_TEXT_ERRATA: list[tuple[str, tuple[str, str]]] = [
    ("Eq. 2.15", ("equation", "reads eta'' + w^2 eta = f_a(t), zero initial conditions")),
    ("Eq. 2.17c", ("missing", "derived by superposing ramps and steps (microg.dynamics.crew)")),
    ("Eq. 2.17d", ("cos w(t2 - t13)", "cos w(t - t13)")),
    (
        "Eq. 2.16",
        (
            "landing (f0/t1)(t - t14)",
            "read as a jump to -f0 ramping to 0 at t14 (seed "
            "review); identical to the printed slope when t14 - t13 = t1",
        ),
    ),
    (
        "Eq. 2.19d",
        (
            "missing",
            "derived (microg.dynamics.crew): A = sin wt - sin w(t-t1) + (t1/d) [sin w(t-t13) "
            "- sin w(t-t14)] - w t1 [cos w(t-t1) + cos w(t-t13)], d = t14 - t13",
        ),
    ),
    ("Eq. 2.20b", ("f0/(w^3 t1 M_jj)", "the acceleration scale is f0/(w_j t1 M_jj), as Eq. 3.1")),
    ("Eq. 2.26", ("third element mbar33 w^2", "mbar34 w^2 (from the second row of Eq. 2.24)")),
    ("Eq. 2.33", ("(M/w) sin wt", "theta = H/(I_y w_y) sin w_y t, H the torque impulse")),
    (
        "Eq. 2.27",
        (
            "3 w0^2 (I_y - I_z)",
            "the report's form is used; the complete linearised roll "
            "equation has 4 w0^2 and couples with yaw",
        ),
    ),
    (
        "Appendix B-2",
        (
            "k22 = 3 (mu/R^3)(I_x - I_z)",
            "with psi2 = z/l_k the generalized stiffness needs 1/l_k^2 "
            "(microg.structure.ritz includes it)",
        ),
    ),
    ("Conclusion 7", ("Eq. (4.1)", "Eq. (3.1)")),
    ("Section 3 note 2", ("Table 5", "Table 4")),
]
