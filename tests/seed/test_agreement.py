"""The agreement of the printed values: tolerances from the printed digits, counts computed
from the comparisons, every difference linked to its erratum.

References: the printed literals of ``microg/data/_seed_printed.toml`` (read independently
here with ``tomllib``), brute-force corner sampling of the input rounding (for the
first-order bound), and the reproduction's own tables (for the recomputed values).
"""

from __future__ import annotations

import itertools
import re
import tomllib
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff
from microg.seed.agreement import summarize
from microg.seed.comparison import (
    CAUSE_HALF,
    CAUSE_UNEXPLAINED,
    GROUPS,
    MODEL_BOUND,
    rounding_bound,
)
from microg.seed.ioc import FT, LBF, half_unit, printed, printed_literals
from microg.seed.reproduce import ReproduceOptions, reproduce
from microg.seed.routes import case_solution

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def rep():
    return reproduce()


# ----------------------------------------------------------------- printed digits


@pytest.mark.parametrize(
    ("text", "half"),
    [
        ("1.0431", 5e-5),
        ("2.730", 5e-4),  # the trailing zero is printed, hence significant
        ("0.254e-8", 5e-12),
        ("1.89e-3", 5e-6),
        ("-2758", 0.5),
        ("96.0", 0.05),
        ("1.31e9", 5e6),
        ("11590", 5.0),  # four significant digits
        ("608600", 50.0),  # an integer's trailing zeros: significant up to four digits
    ],
)
def test_half_unit_of_printed_literals(text: str, half: float) -> None:
    # definition: half a unit in the last printed (significant) digit; exact up to rounding
    assert half_unit(text) == pytest.approx(half, rel=1e-12)


def test_half_unit_of_m11_covers_its_exact_value() -> None:
    # m11 is the total mass 608,600 lb / 32.2 = 18,900.6 slug (Table 2); the printed "18900"
    # must stand for it: the four-digit reading (+-5) does, a five-digit one (+-0.5) would not
    exact = 608600 / 32.2
    assert abs(exact - 18900) <= half_unit("18900")
    assert abs(exact - 18900) > 0.5


def test_literals_are_the_printed_values() -> None:
    # reference: tomllib's own parse of the same file; every leaf equal as a number
    text = resources.files("microg").joinpath("data/_seed_printed.toml").read_text("utf-8")
    ref = tomllib.loads(text)
    lit = printed_literals()
    count = 0

    def walk(a, b) -> None:
        nonlocal count
        if isinstance(a, dict):
            assert set(a) == set(b)
            for k in a:
                walk(a[k], b[k])
        elif isinstance(a, list):
            assert len(a) == len(b)
            for x, y in zip(a, b, strict=True):
                walk(x, y)
        elif isinstance(a, int | float) and not isinstance(a, bool):
            assert isinstance(b, str) and float(b) == a
            count += 1
        else:
            assert a == b

    walk(ref, lit)
    assert count > 150  # all matrices, vectors, Table 2 and Table 4 entries


# ----------------------------------------------------------------- the rounding bound


def test_rounding_bound_of_a_linear_map_is_exact() -> None:
    # f(x) = A x: sum_i |f(x + h_i e_i) - f(x)| = |A| h exactly (reference: the algebra)
    a = np.array([[1.0, -2.0, 0.5], [3.0, 0.0, -1.0]])
    h = np.array([0.1, 0.0, 0.02])
    bound = rounding_bound(lambda x: a @ x, np.array([1.0, 2.0, 3.0]), h)
    np.testing.assert_allclose(bound, np.abs(a) @ h, rtol=1e-12)


def test_omega2_bound_is_the_worst_corner_of_the_rounding_box() -> None:
    # reference: brute force over corners of the box printed +- half a unit (C-3, 9 inputs):
    # no corner moves w^2 further than the first-order bound (2% slack for second order) and
    # the corner that follows the signs of the slopes reaches it (within 2%)
    pr, lit = printed(), printed_literals()
    c = pr["constants"]
    m = np.array(pr["appendix_c"]["yz_orbiter"]["mass"], float)
    text = lit["appendix_c"]["yz_orbiter"]["mass"]
    k33 = 4 * c["EI"] / (3 * c["l_k"] ** 3)
    k44 = 4 * c["EI"] / (3 * c["l_s"] ** 3)
    crew = CrewPushoff(25 * LBF)
    iu, ju = np.triu_indices(4)
    keep = m[iu, ju] != 0
    iu, ju = iu[keep], ju[keep]
    h = np.array([half_unit(text[i][j]) for i, j in zip(iu, ju, strict=True)])

    def w2(x: np.ndarray) -> np.ndarray:
        mm = np.zeros((4, 4))
        mm[iu, ju] = x
        mm[ju, iu] = x
        return case_solution(mm, k33, k44, crew, -55 * FT, -55 * FT, 296 * FT).omega2

    x0 = m[iu, ju]
    base = w2(x0)
    bound = rounding_bound(w2, x0, h)
    worst = np.zeros(2)
    for signs in itertools.product((-1.0, 1.0), repeat=x0.size):
        worst = np.maximum(worst, np.abs(w2(x0 + np.array(signs) * h) - base))
    assert np.all(worst <= bound * 1.02)
    assert np.all(worst >= bound * 0.98)


# ----------------------------------------------------------------- the comparisons


def test_recomputed_values_are_the_reproductions(rep) -> None:
    # the summary counts the reproduction's own numbers, not a second computation
    got = {(c.where, c.quantity): c.recomputed for c in rep.comparisons}
    names = {"xz_orbiter": "C-1", "xz_no_orbiter": "C-2", "yz_orbiter": "C-3"}
    names["yz_no_orbiter"] = "C-4"
    for case, t4 in rep.table4.items():
        ac = rep.appendix_c[case]
        for j, b in enumerate(t4.bending):
            assert got[(f"Table 4 {case}", f"bending w_{j + 1} (rad/s)")] == b.omega
            assert got[(f"Table 4 {case}", f"bending a_e mode {j + 1} (g)")] == b.accel_g
            assert got[(f"Appendix {names[case]}", f"w_{j + 1}^2 (rad/s)^2")] == ac.omega2[j]
        assert got[(f"Table 4 {case}", "libration w (rad/s)")] == t4.libration.omega
        assert got[(f"Table 4 {case}", "libration a_e (g)")] == t4.libration.accel_g
        for i in range(4):
            for j in range(i, 4):
                key = (f"Appendix {names[case]} vs model", f"m{i + 1}{j + 1} (slug)")
                if ac.printed_mass_matrix[i, j] != 0:
                    assert got[key] == ac.model_mass_matrix[i, j]


def test_every_printed_value_is_compared_once(rep) -> None:
    # Appendix C (2 w^2, 8 phi, 2 M_jj per case), Table 4 (2 w, 2 a_e, libration w and a_e)
    # and the model's nonzero m_ij, Section 3 CG (2), Table 2 (5 per case): counted from the
    # printed-values file, independently of the comparisons
    pr = printed()
    n_matrix = sum(
        int(np.count_nonzero(np.triu(np.array(e["mass"], float))))
        for e in pr["appendix_c"].values()
    )
    keys = [(c.where, c.quantity) for c in rep.comparisons]
    assert len(keys) == len(set(keys))
    assert rep.agreement.compared == 4 * (2 + 8 + 2 + 2 + 2 + 1 + 1)
    assert rep.agreement.model_compared == n_matrix + 2 + 2 * 5


def test_tolerance_is_half_a_unit_plus_the_propagated_rounding(rep) -> None:
    # every reproduction tolerance includes the value's own rounding; model ones are 2%
    for c in rep.comparisons:
        kind = next(g.kind for g in GROUPS if g.key == c.group)
        if kind == "reproduction":
            assert c.tolerance >= half_unit(c.printed_text)
            assert c.agrees == (abs(c.recomputed - c.printed) <= c.tolerance)
        else:
            assert c.tolerance == pytest.approx(MODEL_BOUND * abs(c.printed), rel=1e-15)


def test_summary_is_counted_from_the_comparisons(rep) -> None:
    a = rep.agreement
    for g in a.groups:
        mine = [c for c in rep.comparisons if c.group == g.key]
        assert g.compared == len(mine) and g.agree + g.differ == g.compared
        assert g.agree == sum(c.agrees for c in mine)
        ids = sorted(i for cc in g.causes for i in cc.errata)
        assert ids == sorted(c.erratum for c in mine if not c.agrees)
        assert g.tolerance and g.justification
    assert a.compared == sum(g.compared for g in a.groups if g.kind == "reproduction")
    assert a.agree + a.differ == a.compared
    assert f"Of {a.compared} printed values" in a.headline and f", {a.agree} agree" in a.headline
    # a comparison that changes changes the count: the summary is computed, not typed
    flipped = [replace(rep.comparisons[0], agrees=not rep.comparisons[0].agrees)]
    flipped += rep.comparisons[1:]
    other = summarize(flipped)
    assert other.agree == a.agree + (-1 if rep.comparisons[0].agrees else 1)


def test_every_difference_links_its_erratum(rep) -> None:
    by_id = {e.id: e for e in rep.errata}
    assert len(by_id) == len(rep.errata)  # ids unique
    for c in rep.comparisons:
        if c.agrees:
            assert c.erratum is None and c.cause == ""
            continue
        e = by_id[c.erratum]
        assert (e.where, e.quantity, e.printed, e.recomputed) == (
            c.where,
            c.quantity,
            c.printed,
            c.recomputed,
        )
        assert e.reason == c.reason and e.cause == c.cause and e.reason
    assert rep.agreement.unexplained == 0  # every difference has a cause
    assert all(c.cause != CAUSE_UNEXPLAINED for c in rep.comparisons if not c.agrees)


def test_findings_of_the_seed_review(rep) -> None:
    # seed review: C-1 and C-3 reproduce from their printed matrices, C-2 and C-4 do not;
    # every printed libration acceleration is twice Eq. 3.2; libration frequencies reproduce
    by = {(c.where, c.quantity): c for c in rep.comparisons}
    for cn in ("C-1", "C-3"):
        assert all(by[(f"Appendix {cn}", f"w_{j}^2 (rad/s)^2")].agrees for j in (1, 2))
    for cn in ("C-2", "C-4"):
        assert not any(by[(f"Appendix {cn}", f"w_{j}^2 (rad/s)^2")].agrees for j in (1, 2))
    for case in rep.table4:
        assert by[(f"Table 4 {case}", "libration w (rad/s)")].agrees
        lib = by[(f"Table 4 {case}", "libration a_e (g)")]
        assert not lib.agrees and lib.cause == CAUSE_HALF
    # C-3 is fully self-consistent: every eigenvector element and modal mass agrees
    c3 = [c for c in rep.comparisons if c.where == "Appendix C-3"]
    assert len(c3) == 12 and all(c.agrees for c in c3)
    # C-1's phi_1: only the second element is wrong (0.9546; the eigenvector has 3.61)
    c1 = [by[("Appendix C-1", f"phi_1[{i}] (Eq. 2.26 vector x 1e0)")] for i in (1, 2, 3, 4)]
    assert [c.agrees for c in c1] == [True, False, True, True]
    assert c1[1].recomputed == pytest.approx(3.61, abs=5e-3)


def test_other_inputs_compare_frequencies_only() -> None:
    # the printed accelerations are for 25 lbf at -55 ft: with other inputs they are not
    # compared, and the summary says why
    r = reproduce(ReproduceOptions(CrewPushoff(40 * LBF), -55 * FT, -55 * FT))
    assert not ReproduceOptions(CrewPushoff(40 * LBF), -55 * FT, -55 * FT).is_report()
    assert ReproduceOptions.report().is_report()
    groups = {g.key: g for g in r.agreement.groups}
    for key in ("table4_bending_accel", "table4_libration_accel"):
        assert groups[key].compared == 0 and "not compared" in groups[key].note
    assert groups["table4_bending_omega"].compared == 8
    assert r.agreement.compared == 4 * (2 + 8 + 2 + 2 + 1)


def test_errata_doc_counts_are_the_computed_ones(rep) -> None:
    # docs/errata.md's agreement table must carry the counts the reproduction computes
    text = (ROOT / "docs" / "errata.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| ([^|]+) \| ([^|]+) \| (\d+) \| (\d+) \| (\d+) \|", text, re.M)
    documented = [(s.strip(), int(n), int(a), int(d)) for s, _, n, a, d in rows]
    computed = [(g.source, g.compared, g.agree, g.differ) for g in rep.agreement.groups]
    assert documented == computed
