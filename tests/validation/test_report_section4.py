"""Section 4 of the report (Eqs. 4.3-4.7, Section 4.2 claims, Figure 8, conclusion 5).

Source: the seed report, Section 4 "Design Characteristics of Suspension System" and
conclusion (5).  Printed numbers are compared with recomputations made here from first
principles (the report's own g = 32.2 ft/s^2), not with values tuned to match.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from microg.isolation import accel_magnification, check_section42_claims
from microg.plotting.isolation import figure8

G_REPORT = 32.2  # ft/s^2, the report's weight-to-mass conversion


@pytest.fixture(scope="module")
def claims():  # type: ignore[no-untyped-def]
    return check_section42_claims()


@pytest.mark.parametrize(("k", "mu"), [(5, 0.01), (10, 0.025), (20, 0.05), (15, 0.01)])
def test_eq_4_3_solved_by_direct_complex_solve(k: float, mu: float) -> None:
    """Eq. 4.3 in physical units (m1 = 1000 lb / 32.2, omega_n = 0.6 rad/s) vs the kernel."""
    zeta = 0.2
    m1 = 1000 / G_REPORT
    k1 = m1 * 0.6**2
    k2, m2 = k1 / k, mu * m1
    c = 2 * zeta * math.sqrt(m2 * k2)
    for r2 in (0.3, 0.7, 1.5, 2.0, 4.0):
        w = math.sqrt(r2) * 0.6
        mat = np.array(
            [
                [k1 + k2 - m1 * w**2 + 1j * c * w, -(k2 + 1j * c * w)],
                [-(k2 + 1j * c * w), k2 - m2 * w**2 + 1j * c * w],
            ]
        )
        u1 = np.linalg.solve(mat, [k1 * 1.0, 0.0])[0]
        # Eq. 4.5: M_a = |A1|/(w^2 U0) = |w^2 U1|/(w^2 U0); 1e-12: well-conditioned points
        assert float(accel_magnification(k, mu, zeta, math.sqrt(r2))) == pytest.approx(
            abs(u1), rel=1e-12
        )


def test_claim_a_r2_above_2(claims) -> None:  # type: ignore[no-untyped-def]
    a = claims.by_id("a")
    assert a.holds
    # Figure 8 curves cross M_a = 1 near r^2 = 2 (within 10%); independent dense sweep here
    r2 = np.linspace(2.2, 12.0, 5000)
    for mu in (0.01, 0.025, 0.05):
        for k in (5, 10, 15, 20):
            assert np.all(accel_magnification(k, mu, 0.2, np.sqrt(r2)) < 1.0)
    assert 1.8 < a.values["figure8_crossing_r2_min"] <= a.values["figure8_crossing_r2_max"] < 2.1


def test_claims_b_c_spring_bound(claims) -> None:  # type: ignore[no-untyped-def]
    b, c = claims.by_id("b"), claims.by_id("c")
    assert not b.holds and not c.holds
    m1 = 1000 / G_REPORT  # slug
    # r^2 = m1 w^2/k1 > 2  <=>  k1 < m1 w^2/2 (lb/ft), /12 for lb/in
    assert c.values["k1_max_lbf_per_in_at_omega"] == pytest.approx(m1 * 1.0 / 2 / 12, rel=1e-14)
    assert c.values["k1_max_lbf_per_in_at_fundamental"] == pytest.approx(
        m1 * 1.021**2 / 2 / 12, rel=1e-14
    )
    assert c.values["k1_max_lbf_per_in_at_omega"] == pytest.approx(1.294, abs=5e-4)  # vs printed 5
    # the printed 5 lb/in is 2W/g = 62.1 lb/ft = 5.18 lb/in: the inverted inequality of (b)
    two_w_g = c.values["two_w_over_g_lbf_per_in"]
    assert two_w_g == pytest.approx(2 * 1000 / G_REPORT / 12, rel=1e-14)
    assert round(two_w_g) == 5  # the printed value, explained
    assert b.values["ratio_printed_to_correct"] == pytest.approx(4.0, rel=1e-14)
    # a 5 lb/in spring amplifies at 1 rad/s: r^2 = 0.518, M_a = 1/(1 - r^2) = 2.07
    r2 = m1 / 60.0
    assert c.values["Ma_with_5_lbf_per_in"] == pytest.approx(1 / (1 - r2), rel=1e-14)
    assert c.values["Ma_with_5_lbf_per_in"] > 2


def test_claim_d_band_half_to_two(claims) -> None:  # type: ignore[no-untyped-def]
    d = claims.by_id("d")
    assert not d.holds
    # independent brute force at mu = 0.25 over a (k, zeta) grid: the best largest M_a over
    # 0.5 < r^2 < 2 stays above Den Hartog's fixed-point height sqrt(1 + 2/mu) = 3
    r = np.sqrt(np.linspace(0.5, 2.0, 3001))
    ks = np.geomspace(1.0, 40.0, 120)[:, None, None]
    zs = np.geomspace(0.02, 1.5, 60)[None, :, None]
    worst = accel_magnification(ks, 0.25, zs, r).max(axis=-1)
    assert worst.min() > 3.0 - 1e-9
    assert d.values["best_peak_Ma_mu_max_zeta_free"] == pytest.approx(worst.min(), rel=2e-2)
    assert d.values["best_peak_Ma_mu_max_zeta_free"] > 0.5


def test_conclusion_5_quarter_is_not_a_limit(claims) -> None:  # type: ignore[no-untyped-def]
    e = claims.by_id("e")
    assert not e.holds
    # M_a = 1/(r^2 - 1): 1/4 at r^2 = 5, 1/10 at r^2 = 11 (no lower limit)
    assert float(accel_magnification(1.0, 1e-12, 0.0, math.sqrt(11.0))) == pytest.approx(
        0.1, rel=1e-9
    )
    m1 = 1000 / G_REPORT
    assert e.values["k1_lbf_per_in_for_Ma_0.1_at_omega"] == pytest.approx(m1 / 11 / 12, rel=1e-14)


def test_figure8_six_panels() -> None:
    fig = figure8()
    axes = fig.get_axes()
    assert len(axes) == 6
    titles = [ax.get_title() for ax in axes]
    assert titles[:3] == [
        "mu = 0.01, zeta = 0.2",
        "mu = 0.025, zeta = 0.2",
        "mu = 0.05, zeta = 0.2",
    ]
    assert titles[3:] == ["k = 10, zeta = 0.2", "k = 15, zeta = 0.2", "k = 20, zeta = 0.2"]
    # each plotted absorber curve is M_a of its label (checked at its own samples)
    line = [ln for ln in axes[1].get_lines() if ln.get_label() == "k = 10"][0]
    x, y = line.get_data()
    np.testing.assert_allclose(y, accel_magnification(10, 0.025, 0.2, np.sqrt(x)), rtol=1e-15)
    assert axes[0].get_yscale() == "log"
