"""How many of the seed report's printed values microg reproduces, and within which tolerance.

Every printed number that microg recomputes becomes one :class:`Comparison`: the literal as
printed (``data/_seed_printed.toml``), the recomputed value, the tolerance, whether they agree
and, when they do not, why (computed, not asserted).  :func:`summarize` counts them per table
and appendix (:class:`Agreement`); the errata (:mod:`microg.seed.errata`) carry one entry per
difference, and each comparison links to its entry.

:mod:`~microg.seed.comparison` (a comparison and its tolerance rules),
:mod:`~microg.seed.routes` (the report's routes from printed data),
:mod:`~microg.seed.agree_appendix_c`, :mod:`~microg.seed.agree_table4` and
:mod:`~microg.seed.agree_model` (the comparisons of each table) make the comparisons; this
module puts them in order and counts them (their names are importable from here).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from microg.dynamics.crew import CrewPushoff
from microg.seed.agree_appendix_c import appendix_c_comparisons
from microg.seed.agree_model import model_comparisons
from microg.seed.agree_table4 import table4_comparisons
from microg.seed.comparison import (
    CASE_NAMES,
    CAUSE_UNEXPLAINED,
    GROUPS,
    MODEL_BOUND,
    Comparison,
    Group,
    rounding_bound,
)
from microg.seed.routes import (
    CaseSolution,
    LibrationSolution,
    case_solution,
    libration_route,
    printed_case,
)

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
        pc = printed_case(case, crew, z_e, z_a)
        out.extend(appendix_c_comparisons(pc))
        out.extend(table4_comparisons(pc, omega0[case], report_inputs))
    out.extend(model_comparisons({k: model_matrices[k] for k in cases}, model_mass))
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
