"""The three-way verdict from the criteria: a judged fail fails, else undecided, else complies.

Reference: the rule of :mod:`microg.environment.criteria` applied by hand to every combination
of criterion kinds and outcomes.
"""

from __future__ import annotations

import itertools

import pytest

from microg.environment.criteria import (
    CriterionVerdict,
    combine_verdicts,
    overall_verdict,
    verdict_complies,
)


def _c(status: str, complies: bool | None) -> CriterionVerdict:
    margin = float("nan") if complies is None else (2.0 if complies else 0.5)
    return CriterionVerdict("c", status, complies, margin, 1.0, 1.0, "g", "src", "why")


KINDS = [("judged", True), ("judged", False), ("reported", True), ("reported", False),
         ("undecided", None)]  # fmt: skip


@pytest.mark.parametrize("n", [1, 2, 3])
def test_overall_verdict_by_hand_over_every_combination(n):
    for combo in itertools.product(KINDS, repeat=n):
        vs = tuple(_c(*k) for k in combo)
        judged_fail = any(s == "judged" and c is False for s, c in combo)
        undecided = any(s == "undecided" for s, _ in combo)
        want = "fails" if judged_fail else "undecided" if undecided else "complies"
        assert overall_verdict(vs) == want, combo
        # complies (the boolean of the JSON) is exactly the verdict "complies"
        assert verdict_complies(vs) == (want == "complies")


def test_combining_points_a_fail_anywhere_fails():
    assert combine_verdicts(["complies", "undecided", "fails"]) == "fails"
    assert combine_verdicts(["complies", "undecided"]) == "undecided"
    assert combine_verdicts(["complies", "complies"]) == "complies"
    with pytest.raises(ValueError, match="not a verdict"):
        combine_verdicts(["complies", "ok"])


def test_a_reported_line_names_its_source_and_a_judged_one_its_basis():
    assert _c("reported", False).line().endswith("(limit from src)")
    assert _c("judged", False).line() == ("c: FAILS (margin 0.5; 1 g against 1 g); why")
