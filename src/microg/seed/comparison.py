"""One printed value beside its recomputation, and the tolerance rules that judge it.

Every printed number that microg recomputes becomes one :class:`Comparison`: the literal as
printed (``data/_seed_printed.toml``), the recomputed value, the tolerance, whether they agree
and, when they do not, why (computed, not asserted).  :data:`GROUPS` lists the kinds of
printed value with their tolerance and its justification; the ``CAUSE_*`` strings name the
causes of a difference (the agreement summary groups the errata by them).

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

from microg.seed.ioc import half_unit

__all__ = [
    "CASE_NAMES",
    "GROUPS",
    "MODEL_BOUND",
    "Comparison",
    "Group",
    "compare",
    "rounding_bound",
    "with_cause",
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


def compare(
    group: str, where: str, qty: str, text: str, recomputed: float, bound: float
) -> Comparison:
    """A reproduction comparison: tolerance = half a unit of the printed text + ``bound``.

    Parameters
    ----------
    group : str
        Key of its :data:`GROUPS` row.
    where, qty : str
        Table/appendix and case; the quantity with its unit.
    text : str
        The literal as printed.
    recomputed : float
        In the unit of the printed value.
    bound : float
        The first-order bound of the rounding of the inputs (:func:`rounding_bound`), same
        unit.
    """
    p = float(text)
    tol = half_unit(text) + float(bound)
    r = float(recomputed)
    return Comparison(group, where, qty, p, text, r, tol, bool(abs(r - p) <= tol))


def with_cause(c: Comparison, cause: str, reason: str) -> Comparison:
    """The comparison with its cause and reason, if it differs (as it is, if it agrees).

    Parameters
    ----------
    c : Comparison
    cause, reason : str
        The short cause (a ``CAUSE_*``) and the computed reason.
    """
    return c if c.agrees else replace(c, cause=cause, reason=reason)
