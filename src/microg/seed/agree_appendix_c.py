"""Appendix C's printed values against their recomputation: w^2, eigenvectors, modal masses.

Each case's printed frequencies, eigenvector elements (in the report's scaling: Eq. 2.26
times the power of ten nearest the printed vector) and modal masses, each within half a unit
of its last digit plus the rounding of the printed matrix it is recomputed from; every
difference with its computed cause (see :mod:`microg.seed.comparison`).
"""

from __future__ import annotations

import numpy as np

from microg.seed.comparison import (
    CAUSE_M_OF_PRINTED,
    CAUSE_NOT_EIGEN,
    CAUSE_ONE_ELEMENT,
    CAUSE_UNEXPLAINED,
    Comparison,
    compare,
    rounding_bound,
    with_cause,
)
from microg.seed.ioc import half_unit, printed, printed_literals
from microg.seed.routes import PrintedCase, sym4

__all__ = ["appendix_c_comparisons"]


def _sci(x: float) -> str:
    return f"1e{int(round(np.log10(abs(x))))}" if x > 0 else f"-1e{int(round(np.log10(-x)))}"


def appendix_c_comparisons(pc: PrintedCase) -> list[Comparison]:
    """The Appendix C comparisons of one case (reproduction groups), with their causes.

    Parameters
    ----------
    pc : PrintedCase
        The case recomputed from its printed matrix (:func:`microg.seed.routes.printed_case`).
    """
    pr, lit = printed(), printed_literals()
    case, cn = pc.case, pc.label
    entry, ltext = pr["appendix_c"][case], lit["appendix_c"][case]
    m, x, h, base = pc.mass, pc.x, pc.h, pc.base
    printed_phi, phi_scale, mm_scale = pc.printed_phi, pc.phi_scale, pc.mm_scale
    b_phi, b_mm = pc.b_phi, pc.b_mm
    inconsistent, cause_inc = pc.inconsistent, pc.cause_inconsistent
    w2 = pc.w2
    out: list[Comparison] = []
    where = f"Appendix {cn}"
    stiff = np.diag([0.0, 0.0, pc.k33, pc.k44])
    rayleigh = np.einsum("ij,ik,kj->j", printed_phi, stiff, printed_phi) / np.einsum(
        "ij,ik,kj->j", printed_phi, m, printed_phi
    )
    for j, cmp in enumerate(w2):
        out.append(
            with_cause(
                cmp,
                cause_inc,
                f"w^2 from the printed matrix is {base.omega2[j]:.5g}, beyond the "
                f"{cmp.tolerance:.2g} its digits allow; the Rayleigh quotient of the printed "
                f"phi_{j + 1} (Eq. 2.12b) is {rayleigh[j]:.5g}: the printed matrix, eigenvectors "
                f"and frequencies of {cn} disagree with each other",
            )
        )

    # eigenvector elements
    vec_agree = np.zeros((4, 2), bool)
    phis: list[list[Comparison]] = [[], []]
    for j in range(2):
        for i in range(4):
            cmp = compare(
                "appendix_c_phi",
                where,
                f"phi_{j + 1}[{i + 1}] (Eq. 2.26 vector x {_sci(phi_scale[j])})",
                ltext["phi"][j][i],
                base.phi[i, j] * phi_scale[j],
                b_phi[i, j],
            )
            vec_agree[i, j] = cmp.agrees
            phis[j].append(cmp)
    w2p = np.array(entry["omega2"], float)
    resid = np.zeros(2)
    for j in range(2):
        r = stiff @ printed_phi[:, j] - w2p[j] * m @ printed_phi[:, j]
        resid[j] = np.linalg.norm(r) / (
            np.linalg.norm(stiff @ printed_phi[:, j])
            + w2p[j] * np.linalg.norm(m @ printed_phi[:, j])
        )
        for i, cmp in enumerate(phis[j]):
            others = np.delete(vec_agree[:, j], i)
            if inconsistent:
                cause = cause_inc
                reason = (
                    f"the printed matrix of {cn} does not give its printed frequencies (see its "
                    "w^2 entries); the eigenvector recomputed from it differs"
                )
            elif others.all():
                cause = CAUSE_ONE_ELEMENT
                reason = (
                    f"the other elements of phi_{j + 1} agree; the eigenvector of the printed "
                    f"matrix has {cmp.recomputed:.4g} here"
                )
            else:
                cause = CAUSE_NOT_EIGEN
                reason = (
                    f"the printed phi_{j + 1} is not an eigenvector of the printed matrix: "
                    f"|(k - w^2 m) phi| is {resid[j]:.2g} of |k phi| + w^2 |m phi| with the "
                    "printed w^2"
                )
            out.append(with_cause(cmp, cause, reason))

    # modal masses; is the printed M_jj phi^T m phi of the printed vector?
    for j in range(2):
        cmp = compare(
            "appendix_c_modal_mass",
            where,
            f"M_{j + 1}{j + 1} (slug, Eq. 2.26 vector x {_sci(np.sqrt(mm_scale[j]))})",
            ltext["modal_mass"][j],
            base.modal_mass[j] * mm_scale[j],
            b_mm[j],
        )
        pv = printed_phi[:, j]
        hp = np.array([half_unit(t) for t in ltext["phi"][j]])

        def of_printed(v: np.ndarray) -> np.ndarray:
            return np.array([v[:4] @ sym4(v[4:]) @ v[:4]])

        xin = np.concatenate([pv, x])
        own = float(of_printed(xin)[0])
        own_tol = half_unit(ltext["modal_mass"][j]) + float(
            rounding_bound(of_printed, xin, np.concatenate([hp, h]))[0]
        )
        follows = abs(own - cmp.printed) <= own_tol
        text = f"phi^T m phi of the printed phi_{j + 1} is {own:.5g}"
        if inconsistent:
            cause = cause_inc
            reason = (
                text + f" ({'it follows from' if follows else 'it does not follow from'} the "
                f"printed vector); the printed matrix of {cn} does not give its printed frequencies"
            )
        elif follows and not vec_agree[:, j].all():
            cause = CAUSE_M_OF_PRINTED
            reason = text + ": the printed M_jj follows from the printed vector, which is wrong"
        else:
            cause = CAUSE_UNEXPLAINED
            reason = text + (
                ": the printed M_jj follows from the printed phi"
                if follows
                else ": the printed M_jj does not follow from the printed phi either"
            )
        out.append(with_cause(cmp, cause, reason))

    return out
