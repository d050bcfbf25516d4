"""Tests of microg.location.peaks: Eq. 3.1 factors, the rigid part, time grid, elastic rule."""

from __future__ import annotations

import types

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff, acceleration_a
from microg.dynamics.forces import REPORT_F0_N, ForceHistory
from microg.errors import InputError
from microg.location.peaks import (
    POINTS_PER_PERIOD,
    elastic_mask,
    elastic_modes,
    force_breakpoints,
    max_force,
    mode_peak_factors,
    peak_over_time,
    rigid_part,
    time_grid,
)

CREW = CrewPushoff(REPORT_F0_N)


def test_peak_factors_are_eq_3_1_with_exact_amax():
    # reference: the maximum of the closed-form A(t) (Eq. 2.19) over a dense grid that also
    # holds the instants just after each force jump
    omega = np.array([0.0, 0.3, 1.0175, 3.64])
    peaks, exact = mode_peak_factors(omega, CREW)
    assert exact
    assert peaks[0] == CREW.f0  # a rigid mode follows the force
    t = np.sort(np.r_[np.linspace(0.0, 300.0, 600_001), np.array([1.0, 13.0, 14.0]) + 1e-12])
    for w, p in zip(omega[1:], peaks[1:], strict=True):
        direct = CREW.f0 / (w * CREW.t1) * np.max(np.abs(acceleration_a(w, t, CREW)))
        # grid crest error (w dt)^2/8 <= 3e-7 at dt = 5e-4 s, w <= 3.64 rad/s
        assert p == pytest.approx(direct, rel=1e-6)


def test_peak_factors_of_a_force_history_match_the_push_off():
    # the same push-off as a ForceHistory takes the time-grid path: within the grid's crest
    # error 1 - cos(pi/32) = 0.48 %, from below
    tb, fb = CREW.breakpoints()
    hist = ForceHistory(tb, fb, name="push")
    omega = np.array([0.0, 1.0175, 3.64])
    exact, _ = mode_peak_factors(omega, CREW)
    grid, is_exact = mode_peak_factors(omega, hist)
    assert not is_exact
    assert np.all(grid <= exact * (1 + 1e-9)) and np.all(grid >= exact * (1 - 4.9e-3))
    assert max_force(hist) == max_force(CREW) == CREW.f0
    with pytest.raises(InputError) as exc:
        force_breakpoints("push")
    assert exc.value.where == "force"


def test_rigid_part_does_not_depend_on_the_rigid_basis():
    # two rigid modes rotated into each other (any orthogonal 2x2 Q): c = sum resp_j gamma_j
    # is invariant, so the rigid part is too; the per-mode products are not
    rng = np.random.default_rng(3)
    resp = rng.normal(size=(5, 3))
    gamma = rng.normal(size=3)
    rigid = np.array([True, True, False])
    q, _ = np.linalg.qr(rng.normal(size=(2, 2)))
    resp2 = resp.copy()
    resp2[:, :2] = resp[:, :2] @ q
    gamma2 = gamma.copy()
    gamma2[:2] = q.T @ gamma[:2]
    a = rigid_part(resp, gamma, rigid, CREW)
    b = rigid_part(resp2, gamma2, rigid, CREW)
    np.testing.assert_allclose(a, b, rtol=1e-12)
    np.testing.assert_allclose(a, np.abs(resp[:, :2] @ gamma[:2]) * CREW.f0, rtol=1e-14)


def test_time_grid_resolves_the_fastest_mode_and_both_sides_of_jumps():
    tb, _ = CREW.breakpoints()
    omega = np.array([0.0, 1.0, 40.0])
    grid = time_grid(tb, omega, omega > 0, None)
    assert np.max(np.diff(grid)) <= 2 * np.pi / 40.0 / POINTS_PER_PERIOD * (1 + 1e-9)
    for t in (1.0, 13.0, 14.0):
        assert t in grid and np.nextafter(t, -np.inf) in grid
    # the window: last breakpoint plus three periods of the slowest elastic mode
    assert grid[-1] == pytest.approx(14.0 + 3 * 2 * np.pi / 1.0)


def test_peak_over_time_is_the_max_of_the_modal_sum():
    rng = np.random.default_rng(4)
    r = rng.normal(size=(7, 3))
    eta = rng.normal(size=(3, 50))
    np.testing.assert_allclose(peak_over_time(r, eta), np.max(np.abs(r @ eta), axis=1))
    assert np.all(peak_over_time(np.zeros((4, 0)), np.zeros((0, 9))) == 0)


def test_elastic_rule_is_the_modes_own():
    # Modes.elastic, when the modes define it, is the one rule; else every non-rigid mode
    # (never a frequency threshold: a 1e-3 rad/s non-rigid mode is elastic by the fallback)
    rigid = np.array([True, False, False])
    plain = types.SimpleNamespace(omega=np.array([0.0, 1e-3, 2.0]), rigid=rigid)
    np.testing.assert_array_equal(elastic_modes(plain), [False, True, True])
    ruled = types.SimpleNamespace(
        omega=plain.omega, rigid=rigid, elastic=np.array([False, False, True])
    )
    np.testing.assert_array_equal(elastic_modes(ruled), [False, False, True])
    np.testing.assert_array_equal(elastic_mask(ruled), [False, False, True])
    np.testing.assert_array_equal(elastic_mask(plain.omega, rigid), [False, True, True])
    with pytest.raises(InputError):
        elastic_mask(plain.omega)
