"""Table 4's printed values against their recomputation: bending and libration lines.

Each case's bending frequencies and accelerations (Eq. 3.1 with the exact [A]max) from the
printed Appendix C matrix, and its libration frequency and acceleration (Eqs. 2.30 and 3.2
with Table 2's inertias and centre of mass); every difference with its computed cause (see
:mod:`microg.seed.comparison`).  The printed accelerations are for the report's inputs only.
"""

from __future__ import annotations

import numpy as np

from microg.seed.comparison import (
    CAUSE_AMAX,
    CAUSE_HALF,
    CAUSE_TABLE4_VS_APPENDIX,
    CAUSE_UNEXPLAINED,
    Comparison,
    compare,
    rounding_bound,
    with_cause,
)
from microg.seed.ioc import SLUG, half_unit, printed, printed_literals
from microg.seed.routes import PrintedCase, libration_route
from microg.units import G0

__all__ = ["table4_comparisons"]


def table4_comparisons(pc: PrintedCase, omega0: float, report_inputs: bool) -> list[Comparison]:
    """The Table 4 comparisons of one case (reproduction groups), with their causes.

    Parameters
    ----------
    pc : PrintedCase
        The case recomputed from its printed matrix (:func:`microg.seed.routes.printed_case`).
    omega0 : float
        Orbital rate of the case's model, rad/s (Eq. 2.29).
    report_inputs : bool
        Whether crew force and points are the report's (else the printed accelerations,
        which are for those, are not compared).
    """
    pr, lit = printed(), printed_literals()
    case, cn = pc.case, pc.label
    plane, orbiter = pc.plane, pc.orbiter
    crew, z_e, z_a, l_k = pc.crew, pc.z_e, pc.z_a, pc.l_k
    ltext = lit["appendix_c"][case]
    base, printed_phi, printed_mm = pc.base, pc.printed_phi, pc.printed_mm
    b_w, b_acc = pc.b_w, pc.b_acc
    inconsistent, cause_inc = pc.inconsistent, pc.cause_inconsistent
    w2p = np.array(pr["appendix_c"][case]["omega2"], float)
    out: list[Comparison] = []

    # Table 4: bending frequencies and accelerations
    t4, t4t = pr["table4"][case], lit["table4"][case]
    where4 = f"Table 4 {case}"
    for j in range(2):
        cmp = compare(
            "table4_bending_omega",
            where4,
            f"bending w_{j + 1} (rad/s)",
            t4t["bending_omega"][j],
            base.omega[j],
            b_w[j],
        )
        root = float(np.sqrt(w2p[j]))
        h_root = half_unit(ltext["omega2"][j]) / (2 * root)  # rounding of the printed w^2
        from_printed = abs(root - cmp.printed) <= half_unit(t4t["bending_omega"][j]) + h_root
        said = f"the square root of Appendix {cn}'s printed w_{j + 1}^2 is {root:.4g}" + (
            ": Table 4 follows it" if from_printed else ": Table 4 does not follow it"
        )
        if inconsistent:
            cause = cause_inc
            reason = said + f"; {cn}'s printed matrix gives {base.omega[j]:.4g}"
        elif not from_printed and abs(root - cmp.recomputed) <= b_w[j] + h_root:
            cause = CAUSE_TABLE4_VS_APPENDIX
            reason = said + (
                f", and the printed matrix gives {base.omega[j]:.4g}, in agreement with it: "
                f"Table 4's {cmp.printed_text} is a slip"
            )
        else:
            cause, reason = CAUSE_UNEXPLAINED, said
        out.append(with_cause(cmp, cause, reason))
    if report_inputs:
        for j in range(2):
            cmp = compare(
                "table4_bending_accel",
                where4,
                f"bending a_e mode {j + 1} (g)",
                t4t["bending_accel_g"][j],
                base.accel_g[j],
                b_acc[j],
            )
            implied = cmp.printed / base.accel_g[j] * base.amax[j]
            pe = printed_phi[0, j] + printed_phi[1, j] * z_e / l_k
            pa = printed_phi[0, j] + printed_phi[1, j] * z_a / l_k
            unit_a = (
                abs(pe * pa) * crew.f0 / (printed_mm[j] * SLUG * t4["bending_omega"][j] * crew.t1)
            )
            implied_p = cmp.printed * G0 / unit_a
            reason = (
                f"Eq. 3.1 with the exact [A]max = {base.amax[j]:.4g}; the printed value implies "
                f"[A]max = {implied:.3g} with the recomputed phi and M_jj ({implied_p:.3g} with "
                "the printed ones); the report estimates [A]max from Figure 4, whose curves "
                "are drawn for w = 0.1-0.4 rad/s"
            )
            cause = CAUSE_AMAX + (f"; {cause_inc}" if inconsistent else "")
            out.append(with_cause(cmp, cause, reason))

    # Table 4: libration (Table 2's inertias and centre of mass)
    key = "orbiter" if orbiter else "no_orbiter"
    t2, t2t = pr["table2"][key], lit["table2"][key]
    xl = np.array([*t2["inertia"], t2["cg_Z"]], float)
    hl = np.array([half_unit(t) for t in [*t2t["inertia"], t2t["cg_Z"]]])

    def lib(v: np.ndarray) -> np.ndarray:
        s = libration_route(v[:3], float(v[3]), plane, omega0, crew, z_e, z_a)
        return np.array([s.omega, s.accel_g])

    lb = rounding_bound(lib, xl, hl)
    lsol = libration_route(xl[:3], float(xl[3]), plane, omega0, crew, z_e, z_a)
    cmp = compare(
        "table4_libration_omega",
        where4,
        "libration w (rad/s)",
        t4t["libration_omega"],
        lsol.omega,
        lb[0],
    )
    out.append(with_cause(cmp, CAUSE_UNEXPLAINED, "Eq. 2.30 with Table 2's inertias, R = 6,870 km"))
    if report_inputs:
        cmp = compare(
            "table4_libration_accel",
            where4,
            "libration a_e (g)",
            t4t["libration_accel_g"],
            lsol.accel_g,
            lb[1],
        )
        ratio = cmp.printed / lsol.accel_g
        twice = (
            abs(cmp.printed - 2 * lsol.accel_g) <= half_unit(t4t["libration_accel_g"]) + 2 * lb[1]
        )
        if twice:
            cause = CAUSE_HALF
            reason = (
                f"printed/recomputed = {ratio:.3f}, twice Eq. 3.2 within the tolerance: the "
                "printed value omits the 1/2 of Eq. 3.2 (the push-off impulse is f0 t1/2)"
            )
        else:
            cause, reason = CAUSE_UNEXPLAINED, f"printed/recomputed = {ratio:.3f}"
        out.append(with_cause(cmp, cause, reason))
    return out
