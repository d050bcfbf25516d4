"""The shipped model against the printed matrices and mass properties (the model groups).

Appendix C's printed m_ij, Section 3's "present model" centre of mass and Table 2's weight,
centre of mass and inertias, each held to ``MODEL_BOUND`` (2%) of the printed value; every
difference with its computed cause (see :mod:`microg.seed.comparison`).
"""

from __future__ import annotations

import numpy as np

from microg.seed.comparison import (
    CASE_NAMES,
    CAUSE_13_30,
    CAUSE_FITTED,
    CAUSE_NOT_FROM_ORBITER,
    CAUSE_NOT_TABLE2,
    CAUSE_PRESENT_MODEL,
    CAUSE_UNEXPLAINED,
    MODEL_BOUND,
    Comparison,
    with_cause,
)
from microg.seed.ioc import CASES, printed, printed_literals

__all__ = ["model_comparisons"]


def _orbiter_increments() -> dict[tuple[int, int], float]:
    """Orbiter's increments to m11, m12, m22 in the X-Z plane (slug): m_o, m_o zbar, m_o zbar^2."""
    c = printed()["constants"]
    m_o = 235400.0 / c["g"]
    zbar = -126.66 / c["l_k"]
    return {(0, 0): m_o, (0, 1): m_o * zbar, (1, 1): m_o * zbar**2}


def _element_cause(case: str, i: int, j: int, model: np.ndarray) -> tuple[str, str]:
    """Cause and reason of a model element outside the bound."""
    plane, orbiter = CASES[case]
    pr = printed()["appendix_c"]
    c = printed()["constants"]
    if plane == "yz" and (i, j) in ((1, 3), (2, 3)):
        zs = c["z_s"] / c["l_k"]
        slope = 1.0 if i == 1 else 2 * zs - zs**2
        ms = 2345.0 / c["g"]
        delta = (13 / 30 - 11 / 60) * ms * c["l_s"] * slope / c["l_k"]
        return CAUSE_13_30, (
            "Appendix A-2 writes the boom's distributed term as 13/30 M_s l_s; the integral "
            "of y psi4(y/l_s) over the boom is 11/60 M_s l_s. With 13/30 the model gives "
            f"{model[i, j] - delta:.1f}; no non-negative array inertia matches m24, m34 and m44 "
            "together"
        )
    if not orbiter:
        inc = _orbiter_increments()
        src = "xz_orbiter" if plane == "xz" else "yz_orbiter"
        with_orb = np.array(pr[src]["mass"], float)
        if (i, j) in inc:
            implied = with_orb[i, j] - inc[(i, j)]
            return CAUSE_NOT_FROM_ORBITER, (
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
            return CAUSE_NOT_FROM_ORBITER, (
                "m44 does not depend on the orbiter; C-1 and C-3 print 122.9"
            )
    if (i, j) in ((0, 1), (0, 2), (1, 2), (1, 1), (2, 2)):
        return CAUSE_FITTED, (
            "keel-dependent element: the keel masses are fitted (non-negative least squares "
            "to C-1/C-3); the printed moments are not all attainable by masses on the keel"
        )
    return CAUSE_UNEXPLAINED, "beyond the model's bound"


def model_comparisons(
    model_matrices: dict[str, np.ndarray], model_mass: dict[str, dict[str, float]]
) -> list[Comparison]:
    """The model comparisons (Appendix C elements, Section 3, Table 2), with their causes.

    Parameters
    ----------
    model_matrices : dict
        Case -> the shipped model's 4x4 mass matrix, slug.
    model_mass : dict
        ``"orbiter"``/``"no_orbiter"`` -> the model's mass properties (``weight_lbf``,
        ``cg_Z_ft``, ``Ix_slug_ft2``, ``Iy_slug_ft2``, ``Iz_slug_ft2``).
    """
    pr, lit = printed(), printed_literals()
    out: list[Comparison] = []

    def model_cmp(group: str, where: str, qty: str, text: str, value: float) -> Comparison:
        p = float(text)
        tol = MODEL_BOUND * abs(p)
        v = float(value)
        return Comparison(group, where, qty, p, text, v, tol, bool(abs(v - p) <= tol))

    for case, mm in model_matrices.items():
        cn = CASE_NAMES[case]
        ltext = lit["appendix_c"][case]["mass"]
        for i in range(4):
            for j in range(i, 4):
                if float(ltext[i][j]) == 0:
                    continue
                cmp = model_cmp(
                    "model_appendix_c",
                    f"Appendix {cn} vs model",
                    f"m{i + 1}{j + 1} (slug)",
                    ltext[i][j],
                    mm[i, j],
                )
                out.append(with_cause(cmp, *_element_cause(case, i, j, mm)))
    cg = pr["cg_table"]
    labels = {"orbiter": "with orbiter", "no_orbiter": "without orbiter"}
    for key, props in model_mass.items():
        label = labels[key]
        cmp = model_cmp(
            "model_section3_cg",
            "Section 3, centre-of-mass table",
            f"CG Z {label}, report's 'present model' (ft)",
            lit["cg_table"][key]["present_model_Z"],
            props["cg_Z_ft"],
        )
        out.append(
            with_cause(
                cmp,
                CAUSE_PRESENT_MODEL,
                "the report's own model vs the shipped model (keel masses fitted to Appendix "
                "C); the printed table has the 'present model' rows swapped (59.5 belongs to "
                "the orbiter case: 68.3 - 59.5 = 8.8, its printed difference); Table 2 gives "
                f"{cg[key]['table2_Z']} ft",
            )
        )
    why_t2 = (
        "Table 2 is JSC's analytical model (reference 1, Table 4.3.3.3-2); the report's own "
        "model already differs from it (Section 3: CG Z {own} ft against {t2} ft), and the "
        "shipped model follows the report's Appendix C"
    )
    for key, props in model_mass.items():
        label = labels[key]
        t2t = lit["table2"][key]
        rows = [
            (f"weight {label} (lbf)", t2t["weight"], props["weight_lbf"]),
            (f"CG Z {label} (ft)", t2t["cg_Z"], props["cg_Z_ft"]),
            (f"I_x {label} (slug ft^2)", t2t["inertia"][0], props["Ix_slug_ft2"]),
            (f"I_y {label} (slug ft^2)", t2t["inertia"][1], props["Iy_slug_ft2"]),
            (f"I_z {label} (slug ft^2)", t2t["inertia"][2], props["Iz_slug_ft2"]),
        ]
        for qty, text, value in rows:
            cmp = model_cmp("model_table2", "Table 2 vs model", qty, text, value)
            out.append(
                with_cause(
                    cmp,
                    CAUSE_NOT_TABLE2,
                    why_t2.format(own=cg[key]["present_model_Z"], t2=cg[key]["table2_Z"]),
                )
            )
    return out
