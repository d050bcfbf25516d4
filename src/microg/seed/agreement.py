"""How many of the seed report's printed values microg reproduces, and within which tolerance.

Every printed number that microg recomputes becomes one :class:`Comparison`: the literal as
printed (``data/_seed_printed.toml``), the recomputed value, the tolerance, whether they agree
and, when they do not, why (computed, not asserted).  :func:`summarize` counts them per table
and appendix (:class:`Agreement`); the errata (:mod:`microg.seed.errata`) carry one entry per
difference, and each comparison links to its entry.

Tolerances
----------
*Reproduction* groups (values recomputed from the report's own printed data): a printed
literal stands for every value within half a unit of its last digit
(:func:`microg.seed.ioc.half_unit`).  The author computed each result from unrounded
intermediate values and printed both rounded, so a recomputation from the printed inputs
``x_i`` may differ from the printed result by up to ::

    tol = h(result) + sum_i |f(x + h_i e_i) - f(x)|

(half a unit of the result, plus the first-order worst case of the rounding of every printed
input it is recomputed from).  A larger difference cannot be rounding.  Data the author used
as given (EI, l_k, l_s, f0, t1, t13, t14, z_e, z_a) are exact.

*Model* groups (the shipped model against printed matrices and mass properties): the model's
keel masses are fitted to C-1 and C-3 (the OCR lost their positions), and the model is held
to ``MODEL_BOUND`` = 2% of the printed value.  For C-1 and C-3 agreement is the fit's, not
independent evidence.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np

from microg.dynamics.crew import CrewPushoff
from microg.seed.condense import condensed_modes
from microg.seed.eq31 import eq31_accel
from microg.seed.ioc import CASES, FT, SLUG, half_unit, printed, printed_literals
from microg.seed.libration import libration_accel_impulse, libration_frequencies
from microg.units import G0

__all__ = [
    "MODEL_BOUND",
    "CASE_NAMES",
    "Group",
    "GROUPS",
    "Comparison",
    "CauseCount",
    "GroupSummary",
    "Agreement",
    "CaseSolution",
    "case_solution",
    "LibrationSolution",
    "libration_route",
    "rounding_bound",
    "build_comparisons",
    "summarize",
]

#: relative bound within which a model quantity counts as matching the printed value
MODEL_BOUND = 0.02

#: Appendix C's name of each case
CASE_NAMES: dict[str, str] = {
    "xz_orbiter": "C-1",
    "xz_no_orbiter": "C-2",
    "yz_orbiter": "C-3",
    "yz_no_orbiter": "C-4",
}

_ROUNDING = (
    "half a unit in the last printed digit of the value, plus the first-order change that "
    "half a unit in the last printed digit of each input makes ({inputs}), summed"
)
_ROUNDING_WHY = (
    "the author computed from unrounded intermediates and printed inputs and result rounded: "
    "a recomputation from the printed inputs can differ from the printed result by this much "
    "and no more (to first order); {given}"
)
_MATRIX_GIVEN = "EI, l_k and l_s are data the author used as given (exact)"
_MODEL_TOL = f"{100 * MODEL_BOUND:g}% of the printed value"
_MODEL_WHY = (
    "the shipped model's acceptance bound: the OCR lost the keel masses' positions and about "
    "20,000 lb of Table 3, so the keel masses are fitted to C-1 and C-3 (non-negative least "
    "squares); agreement with C-1 and C-3 is the fit's, not an independent check"
)


@dataclass(frozen=True)
class Group:
    """One row of the agreement summary: a kind of printed value in one table or appendix."""

    key: str
    source: str
    quantity: str
    kind: str  # "reproduction" or "model"
    tolerance: str
    justification: str


GROUPS: tuple[Group, ...] = (
    Group(
        "appendix_c_omega2",
        "Appendix C",
        "elastic w_j^2 from the printed m_ij (Eqs. 2.23-2.25)",
        "reproduction",
        _ROUNDING.format(inputs="the case's printed m_ij"),
        _ROUNDING_WHY.format(given=_MATRIX_GIVEN),
    ),
    Group(
        "appendix_c_phi",
        "Appendix C",
        "eigenvector elements phi_ij (Eq. 2.26 times the power of ten nearest the printed "
        "vector: the report's scaling)",
        "reproduction",
        _ROUNDING.format(inputs="the case's printed m_ij"),
        _ROUNDING_WHY.format(given=_MATRIX_GIVEN),
    ),
    Group(
        "appendix_c_modal_mass",
        "Appendix C",
        "modal masses M_jj (of the Eq. 2.26 vector times the power of ten nearest the printed "
        "M_jj)",
        "reproduction",
        _ROUNDING.format(inputs="the case's printed m_ij"),
        _ROUNDING_WHY.format(given=_MATRIX_GIVEN),
    ),
    Group(
        "table4_bending_omega",
        "Table 4",
        "bending frequencies w_j (square roots of the recomputed w_j^2)",
        "reproduction",
        _ROUNDING.format(inputs="the case's printed m_ij"),
        _ROUNDING_WHY.format(given=_MATRIX_GIVEN),
    ),
    Group(
        "table4_bending_accel",
        "Table 4",
        "bending accelerations a_e (Eq. 3.1 with the exact [A]max)",
        "reproduction",
        _ROUNDING.format(inputs="the case's printed m_ij"),
        _ROUNDING_WHY.format(
            given=_MATRIX_GIVEN + "; so are f0 = 25 lbf, t1, t13, t14 = 1, 13, 14 s and "
            "z_e = z_a = -55 ft"
        ),
    ),
    Group(
        "table4_libration_omega",
        "Table 4",
        "libration frequencies (Eq. 2.30 with Table 2's inertias)",
        "reproduction",
        _ROUNDING.format(inputs="Table 2's I_x, I_y, I_z"),
        _ROUNDING_WHY.format(
            given="the orbit radius R = 6,870 km is not printed: it is inferred from the "
            "printed 1.89e-3 rad/s (X-Z, orbiter), so only the other three cases test Eq. 2.30 "
            "independently; mu is exact"
        ),
    ),
    Group(
        "table4_libration_accel",
        "Table 4",
        "librational accelerations a_e (Eq. 3.2 with Table 2's inertias and centre of mass)",
        "reproduction",
        _ROUNDING.format(inputs="Table 2's I_x, I_y, I_z and CG Z"),
        _ROUNDING_WHY.format(given="f0, t1, z_e and z_a are the report's exact inputs"),
    ),
    Group(
        "model_appendix_c",
        "Appendix C",
        "printed m_ij against the shipped model's (one assumed function per beam)",
        "model",
        _MODEL_TOL,
        _MODEL_WHY,
    ),
    Group(
        "model_section3_cg",
        "Section 3",
        "the 'present model' centre of mass (Z) against the shipped model's",
        "model",
        _MODEL_TOL + " (Z from the bottom of the keel extension, the report's origin)",
        _MODEL_WHY,
    ),
    Group(
        "model_table2",
        "Table 2",
        "weight, centre of mass (Z) and moments of inertia against the shipped model's",
        "model",
        _MODEL_TOL,
        _MODEL_WHY,
    ),
)

# causes of a difference (the summary groups the errata by them)
CAUSE_INCONSISTENT = "{cn}'s printed matrix and printed frequencies disagree"
CAUSE_ONE_ELEMENT = "one element of a printed vector wrong (its other elements agree)"
CAUSE_NOT_EIGEN = "printed vector is not an eigenvector of the printed matrix"
CAUSE_M_OF_PRINTED = "M_jj computed from the printed (wrong) vector"
CAUSE_TABLE4_VS_APPENDIX = "Table 4 does not follow from the report's own Appendix C"
CAUSE_AMAX = "[A]max estimated (from Figure 4), not the exact maximum of A(t)"
CAUSE_HALF = "printed value is twice Eq. 3.2 (the 1/2 of the push-off impulse dropped)"
CAUSE_FITTED = "keel-dependent element: keel masses fitted"
CAUSE_13_30 = "Appendix A-2 integrates the boom's mass with 13/30 for 11/60"
CAUSE_NOT_FROM_ORBITER = "no-orbiter element does not follow from the orbiter case"
CAUSE_PRESENT_MODEL = "the report's own model cannot be rebuilt (keel masses fitted)"
CAUSE_NOT_TABLE2 = "Table 2 is JSC's analytical model, not the report's"
CAUSE_UNEXPLAINED = "not explained: beyond the rounding, no cause found"


@dataclass(frozen=True)
class Comparison:
    """One printed value beside its recomputation.

    Attributes
    ----------
    group : str
        Key of its :data:`GROUPS` row.
    where, quantity : str
        Table/appendix and case; the quantity with its unit.
    printed : float
    printed_text : str
        The literal as printed (its digits set the rounding).
    recomputed : float
        In the unit of ``printed``.
    tolerance : float
        Absolute, in the unit of ``printed`` (see the module docstring).
    agrees : bool
        ``|recomputed - printed| <= tolerance``.
    cause, reason : str
        Why they differ (empty when they agree).
    erratum : str or None
        Id of the errata entry of a difference (set by :func:`microg.seed.errata.build_errata`).
    """

    group: str
    where: str
    quantity: str
    printed: float
    printed_text: str
    recomputed: float
    tolerance: float
    agrees: bool
    cause: str = ""
    reason: str = ""
    erratum: str | None = None

    @property
    def rel_diff(self) -> float | None:
        """(recomputed - printed) / |printed| (None for a printed 0)."""
        return None if self.printed == 0 else (self.recomputed - self.printed) / abs(self.printed)

    @property
    def rel_tolerance(self) -> float | None:
        """Relative tolerance, ``tolerance / |printed|`` (None for a printed 0)."""
        return None if self.printed == 0 else self.tolerance / abs(self.printed)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready values (with ``rel_diff`` and ``rel_tolerance``)."""
        d = asdict(self)
        d["rel_diff"] = self.rel_diff
        d["rel_tolerance"] = self.rel_tolerance
        return d


@dataclass(frozen=True)
class CauseCount:
    """How many differences of a summary row one cause explains, and their errata ids."""

    cause: str
    count: int
    errata: list[str]


@dataclass(frozen=True)
class GroupSummary:
    """One row of the agreement summary (computed from the comparisons)."""

    key: str
    source: str
    quantity: str
    kind: str
    compared: int
    agree: int
    differ: int
    tolerance: str
    justification: str
    causes: list[CauseCount]
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready row."""
        return asdict(self)


@dataclass(frozen=True)
class Agreement:
    """The agreement summary: per group, and totals per kind.

    Attributes
    ----------
    groups : list of GroupSummary
    compared, agree, differ : int
        Totals over the reproduction groups (values recomputed from the report's own data).
    model_compared, model_agree, model_differ : int
        Totals over the model groups.
    unexplained : int
        Differences (of either kind) for which no cause was found.
    """

    groups: list[GroupSummary]
    compared: int
    agree: int
    differ: int
    model_compared: int
    model_agree: int
    model_differ: int
    unexplained: int = 0

    @property
    def headline(self) -> str:
        """One sentence: how many printed values agree within tolerance."""
        why = (
            "each explained in the errata"
            if self.unexplained == 0
            else f"{self.unexplained} of all differences without an explanation"
        )
        return (
            f"Of {self.compared} printed values recomputed from the report's own data, "
            f"{self.agree} agree within the tolerance their printed digits allow and "
            f"{self.differ} differ; of {self.model_compared} printed values compared with the "
            f"shipped model, {self.model_agree} agree within {100 * MODEL_BOUND:g}% and "
            f"{self.model_differ} differ ({why})."
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {
            "headline": self.headline,
            "reproduction": {
                "compared": self.compared,
                "agree": self.agree,
                "differ": self.differ,
            },
            "model": {
                "compared": self.model_compared,
                "agree": self.model_agree,
                "differ": self.model_differ,
                "bound_rel": MODEL_BOUND,
            },
            "unexplained": self.unexplained,
            "groups": [g.to_dict() for g in self.groups],
        }


# --------------------------------------------------------------------------- kernels


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


def rounding_bound(
    f: Callable[[np.ndarray], np.ndarray], x: np.ndarray, h: np.ndarray
) -> np.ndarray:
    """First-order worst case of input rounding: ``sum_i |f(x + h_i e_i) - f(x)|``.

    Parameters
    ----------
    f : callable
        Inputs (n,) -> outputs (m,).
    x : ndarray (n,)
        Inputs as printed.
    h : ndarray (n,)
        Half a unit in the last printed digit of each input (0: exact).
    """
    x = np.asarray(x, float)
    base = np.asarray(f(x), float)
    bound = np.zeros_like(base)
    for i in np.flatnonzero(h):  # one solve per printed input (at most ten)
        xp = x.copy()
        xp[i] += h[i]
        bound += np.abs(np.asarray(f(xp), float) - base)
    return bound


# --------------------------------------------------------------------------- comparisons


_IU, _JU = np.triu_indices(4)


def _sym(values: np.ndarray) -> np.ndarray:
    """Symmetric 4x4 matrix from its upper triangle (row by row)."""
    m = np.zeros((4, 4))
    i, j = _IU, _JU
    m[i, j] = values
    m[j, i] = values
    return m


def _power_of_ten(ratio: float) -> float:
    """The signed power of ten nearest a ratio."""
    return float(np.sign(ratio) * 10.0 ** np.round(np.log10(abs(ratio))))


def _sci(x: float) -> str:
    return f"1e{int(round(np.log10(abs(x))))}" if x > 0 else f"-1e{int(round(np.log10(-x)))}"


def _compare(
    group: str, where: str, qty: str, text: str, recomputed: float, bound: float
) -> Comparison:
    """A reproduction comparison: tolerance = half a unit of the printed text + ``bound``."""
    p = float(text)
    tol = half_unit(text) + float(bound)
    r = float(recomputed)
    return Comparison(group, where, qty, p, text, r, tol, bool(abs(r - p) <= tol))


def _why(c: Comparison, cause: str, reason: str) -> Comparison:
    """The comparison with its cause and reason, if it differs."""
    return c if c.agrees else replace(c, cause=cause, reason=reason)


def _appendix_and_table4(
    case: str,
    crew: CrewPushoff,
    z_e: float,
    z_a: float,
    omega0: float,
    report_inputs: bool,
) -> list[Comparison]:
    """Comparisons of Appendix C and Table 4 for one case (reproduction groups)."""
    pr, lit = printed(), printed_literals()
    c = pr["constants"]
    cn = CASE_NAMES[case]
    plane, orbiter = CASES[case]
    entry, ltext = pr["appendix_c"][case], lit["appendix_c"][case]
    m = np.array(entry["mass"], float)
    x = m[_IU, _JU]
    cells = zip(x, _IU, _JU, strict=True)
    h = np.array([0.0 if v == 0 else half_unit(ltext["mass"][i][j]) for v, i, j in cells])
    k33 = 4 * c["EI"] / (3 * c["l_k"] ** 3)
    k44 = 4 * c["EI"] / (3 * c["l_s"] ** 3)
    l_k = c["l_k"] * FT
    base = case_solution(m, k33, k44, crew, z_e, z_a, l_k)
    printed_phi = np.array(entry["phi"], float).T
    phi_scale = np.array(
        [_power_of_ten(float(np.median(printed_phi[:, j] / base.phi[:, j]))) for j in range(2)]
    )
    printed_mm = np.array(entry["modal_mass"], float)
    mm_scale = 10.0 ** (2 * np.round(0.5 * np.log10(printed_mm / base.modal_mass)))

    def values(xv: np.ndarray) -> np.ndarray:
        s = case_solution(_sym(xv), k33, k44, crew, z_e, z_a, l_k)
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
    out: list[Comparison] = []
    where = f"Appendix {cn}"

    # w^2 -- and whether this case's printed matrix and frequencies agree at all
    stiff = np.diag([0.0, 0.0, k33, k44])
    rayleigh = np.einsum("ij,ik,kj->j", printed_phi, stiff, printed_phi) / np.einsum(
        "ij,ik,kj->j", printed_phi, m, printed_phi
    )
    w2 = [
        _compare(
            "appendix_c_omega2",
            where,
            f"w_{j + 1}^2 (rad/s)^2",
            ltext["omega2"][j],
            base.omega2[j],
            b_w2[j],
        )
        for j in range(2)
    ]
    inconsistent = not all(cmp.agrees for cmp in w2)
    cause_inc = CAUSE_INCONSISTENT.format(cn=cn)
    for j, cmp in enumerate(w2):
        out.append(
            _why(
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
            cmp = _compare(
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
            out.append(_why(cmp, cause, reason))

    # modal masses; is the printed M_jj phi^T m phi of the printed vector?
    for j in range(2):
        cmp = _compare(
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
            return np.array([v[:4] @ _sym(v[4:]) @ v[:4]])

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
        out.append(_why(cmp, cause, reason))

    # Table 4: bending frequencies and accelerations
    t4, t4t = pr["table4"][case], lit["table4"][case]
    where4 = f"Table 4 {case}"
    for j in range(2):
        cmp = _compare(
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
        out.append(_why(cmp, cause, reason))
    if report_inputs:
        for j in range(2):
            cmp = _compare(
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
            out.append(_why(cmp, cause, reason))

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
    cmp = _compare(
        "table4_libration_omega",
        where4,
        "libration w (rad/s)",
        t4t["libration_omega"],
        lsol.omega,
        lb[0],
    )
    out.append(_why(cmp, CAUSE_UNEXPLAINED, "Eq. 2.30 with Table 2's inertias, R = 6,870 km"))
    if report_inputs:
        cmp = _compare(
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
        out.append(_why(cmp, cause, reason))
    return out


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


def _model_comparisons(
    model_matrices: dict[str, np.ndarray], model_mass: dict[str, dict[str, float]]
) -> list[Comparison]:
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
                out.append(_why(cmp, *_element_cause(case, i, j, mm)))
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
            _why(
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
                _why(
                    cmp,
                    CAUSE_NOT_TABLE2,
                    why_t2.format(own=cg[key]["present_model_Z"], t2=cg[key]["table2_Z"]),
                )
            )
    return out


def build_comparisons(
    cases: list[str],
    crew: CrewPushoff,
    z_e: float,
    z_a: float,
    omega0: dict[str, float],
    model_matrices: dict[str, np.ndarray],
    model_mass: dict[str, dict[str, float]],
    *,
    report_inputs: bool = True,
) -> list[Comparison]:
    """Every printed value microg recomputes, beside its recomputation and tolerance.

    Parameters
    ----------
    cases : list of str
        Cases of :data:`microg.seed.ioc.CASES` to compare.
    crew : CrewPushoff
        The crew force (N, s).
    z_e, z_a : float
        Observation and force points, m from the keel joint.
    omega0 : dict
        Case -> orbital rate of its model, rad/s (Eq. 2.29).
    model_matrices : dict
        Case -> the shipped model's 4x4 mass matrix, slug.
    model_mass : dict
        ``"orbiter"``/``"no_orbiter"`` -> the model's mass properties (``weight_lbf``,
        ``cg_Z_ft``, ``Ix_slug_ft2``, ``Iy_slug_ft2``, ``Iz_slug_ft2``).
    report_inputs : bool
        Whether crew force and points are the report's; if not, the printed accelerations
        (which are for the report's inputs) are not compared.
    """
    out: list[Comparison] = []
    for case in cases:
        out.extend(_appendix_and_table4(case, crew, z_e, z_a, omega0[case], report_inputs))
    out.extend(_model_comparisons({k: model_matrices[k] for k in cases}, model_mass))
    order = {g.key: n for n, g in enumerate(GROUPS)}
    return sorted(out, key=lambda c: order[c.group])  # stable: case order within a group


def summarize(comparisons: list[Comparison], *, report_inputs: bool = True) -> Agreement:
    """Count the comparisons per :data:`GROUPS` row, with the causes of the differences.

    Parameters
    ----------
    comparisons : list of Comparison
        With their errata ids set.
    report_inputs : bool
        False when the printed accelerations were not compared (other crew inputs).
    """
    rows: list[GroupSummary] = []
    for g in GROUPS:
        mine = [c for c in comparisons if c.group == g.key]
        causes: dict[str, list[str]] = {}
        for c in mine:
            if not c.agrees:
                causes.setdefault(c.cause, []).append(c.erratum or "")
        note = ""
        if not mine and g.key in ("table4_bending_accel", "table4_libration_accel"):
            note = (
                "not compared: the crew force or the points differ from the report's "
                "(25 lbf; 1, 13, 14 s; -55 ft), and the printed accelerations are for those"
                if not report_inputs
                else ""
            )
        rows.append(
            GroupSummary(
                key=g.key,
                source=g.source,
                quantity=g.quantity,
                kind=g.kind,
                compared=len(mine),
                agree=sum(c.agrees for c in mine),
                differ=sum(not c.agrees for c in mine),
                tolerance=g.tolerance,
                justification=g.justification,
                causes=[CauseCount(k, len(v), v) for k, v in causes.items()],
                note=note,
            )
        )

    def total(kind: str, attr: str) -> int:
        return sum(getattr(r, attr) for r in rows if r.kind == kind)

    return Agreement(
        rows,
        total("reproduction", "compared"),
        total("reproduction", "agree"),
        total("reproduction", "differ"),
        total("model", "compared"),
        total("model", "agree"),
        total("model", "differ"),
        sum(not c.agrees and c.cause == CAUSE_UNEXPLAINED for c in comparisons),
    )
