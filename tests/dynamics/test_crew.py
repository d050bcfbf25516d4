"""Crew push-off force (Eq. 2.16) and the closed forms U(t), A(t) (Eqs. 2.17, 2.19)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from microg.dynamics.crew import CrewPushoff, accel_amax, acceleration_a, displacement_u, force
from microg.errors import InputError

REPORT = CrewPushoff(1.0, 1.0, 13.0, 14.0)


def _integrate(omega: float, p: CrewPushoff, t_eval: np.ndarray) -> np.ndarray:
    """eta'' + w^2 eta = f(t) from rest, integrated interval by interval (Eq. 2.15)."""
    edges = [0.0, p.t1, p.t13, p.t14, t_eval[-1]]
    state = np.zeros(2)
    out = np.empty((2, t_eval.size))
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        mid = 0.5 * (a + b)

        def rhs(t, y, mid=mid):
            # evaluate the force on this interval's own branch (no jump inside)
            return [y[1], _branch(p, t, mid) - omega**2 * y[0]]

        sel = (t_eval >= a) & (t_eval <= b)
        sol = solve_ivp(
            rhs, (a, b), state, t_eval=t_eval[sel], rtol=1e-12, atol=1e-14, method="DOP853"
        )
        out[:, sel] = sol.y
        state = solve_ivp(rhs, (a, b), state, rtol=1e-12, atol=1e-14, method="DOP853").y[:, -1]
    return out


def _branch(p: CrewPushoff, t: float, mid: float) -> float:
    """Force on the branch of Eq. 2.16 that contains ``mid`` (continuous inside an interval)."""
    if mid <= p.t1:
        return p.f0 / p.t1 * t
    if mid <= p.t13:
        return 0.0
    if mid <= p.t14:
        return p.f0 / (p.t14 - p.t13) * (t - p.t14)
    return 0.0


@pytest.mark.parametrize("omega", [0.1, 0.4, 1.021, 2.577])
def test_closed_form_matches_numerical_integration(omega: float) -> None:
    # reference: solve_ivp (DOP853, rtol 1e-12) of Eq. 2.15; the closed form must agree to
    # 1e-8 of the peak, which the integrator's tolerance leaves room for by ~3 decades
    p = REPORT
    t = np.linspace(0.0, 40.0, 801)
    y = _integrate(omega, p, t)
    u = displacement_u(omega, t, p) * p.f0 / (omega**3 * p.t1)
    a = acceleration_a(omega, t, p) * p.f0 / (omega * p.t1)
    acc_ref = np.array([_branch(p, ti, ti) for ti in t]) - omega**2 * y[0]
    assert np.max(np.abs(u - y[0])) <= 1e-8 * np.max(np.abs(y[0]))
    assert np.max(np.abs(a - acc_ref)) <= 1e-8 * np.max(np.abs(acc_ref))


@given(
    omega=st.floats(0.05, 5.0),
    t1=st.floats(0.2, 3.0),
    gap=st.floats(0.0, 20.0),
    dur=st.floats(0.2, 3.0),
)
@settings(max_examples=60, deadline=None)
def test_equation_of_motion_identity(omega: float, t1: float, gap: float, dur: float) -> None:
    # A = w t1 f/f0 - U is eta'' = f - w^2 eta in the report's scaling (Eqs. 2.15, 2.17, 2.18);
    # both sides are closed forms of O(1 + w t) size: 1e-9 absolute covers rounding
    p = CrewPushoff(1.0, t1, t1 + gap, t1 + gap + dur)
    t = np.linspace(0.0, p.t14 + 30.0, 997)
    lhs = acceleration_a(omega, t, p)
    rhs = omega * p.t1 * force(p, t) / p.f0 - displacement_u(omega, t, p)
    assert np.max(np.abs(lhs - rhs)) < 1e-9 * (1 + omega * t.max())


def test_displacement_and_velocity_continuous_at_breakpoints() -> None:
    # U and U' are continuous (the report, after Eq. 2.17d): one-sided limits agree to rounding
    p = REPORT
    w = 0.37
    for tb in (p.t1, p.t13, p.t14):
        eps = 1e-7
        left, right = displacement_u(w, np.array([tb - eps, tb + eps]), p)
        assert abs(right - left) < 1e-5  # |U'| = O(w t1): jump over 2 eps is ~1e-7
        du = (displacement_u(w, np.array([tb + 2 * eps]), p) - right) - (
            left - displacement_u(w, np.array([tb - 2 * eps]), p)
        )
        assert abs(du[0]) < 1e-9


def test_report_interval_forms() -> None:
    # Eq. 2.17b and 2.19b as printed, on (t1, t13]; Eq. 2.19c on (t13, t14]
    p = REPORT
    w = 0.3
    t = np.linspace(1.01, 13.0, 50)
    u_b = -np.sin(w * t) + np.sin(w * (t - 1)) + w * np.cos(w * (t - 1))
    assert np.allclose(displacement_u(w, t, p), u_b, atol=1e-13)
    t = np.linspace(13.01, 14.0, 20)
    a_c = (
        np.sin(w * t)
        - np.sin(w * (t - 1))
        + np.sin(w * (t - 13))
        - w * (np.cos(w * (t - 1)) + np.cos(w * (t - 13)))
    )
    assert np.allclose(acceleration_a(w, t, p), a_c, atol=1e-13)


@pytest.mark.parametrize("omega", [0.1, 0.2, 0.3, 0.4, 1.021, 2.577, 7.3])
def test_amax_is_the_maximum(omega: float) -> None:
    # reference: bounded scalar maximisation of |A| on each interval, its one-sided end
    # values, and the free-vibration amplitude after t14 (dense sampling of one period);
    # agreement to 1e-7 relative (sampling 2 pi/w / 2e4 leaves < 1e-7 of the crest)
    p = REPORT
    best = 0.0
    for a, b in ((0.0, 1.0), (1.0, 13.0), (13.0, 14.0)):
        grid = np.linspace(a, b, 400)
        k = int(np.argmax(np.abs(acceleration_a(omega, grid, p))))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        res = minimize_scalar(
            lambda x: -abs(acceleration_a(omega, np.array([x]), p)[0]),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-10},
        )
        # A jumps at t1, t13, t14 (the force does): the supremum includes the right limits
        ends = acceleration_a(omega, np.array([a + 1e-12, b]), p)
        best = max(best, -res.fun, *np.abs(ends))
    tail = np.linspace(14.0, 14.0 + 2 * np.pi / omega, 20001)
    best = max(best, np.max(np.abs(acceleration_a(omega, tail, p))))
    assert accel_amax(omega, p) == pytest.approx(best, rel=1e-7)
    assert accel_amax(omega, p) >= best - 1e-12


def test_amax_vectorised() -> None:
    w = np.array([0.1, 0.2, 0.3, 0.4])
    assert np.array_equal(accel_amax(w, REPORT), np.array([accel_amax(x, REPORT) for x in w]))


@pytest.mark.parametrize(
    ("args", "where"),
    [
        ((1.0, -1.0, 13.0, 14.0), "--t1"),
        ((1.0, 2.0, 1.0, 14.0), "--t13"),
        ((1.0, 1.0, 13.0, 13.0), "--t14"),
        ((0.0, 1.0, 13.0, 14.0), "--f0"),
        ((float("nan"), 1.0, 13.0, 14.0), "--f0"),
    ],
)
def test_checked_rejects_bad_times(args: tuple, where: str) -> None:
    with pytest.raises(InputError) as exc:
        CrewPushoff.checked(*args)
    assert exc.value.where == where


def test_breakpoints_reproduce_force() -> None:
    t_b, f_b = REPORT.breakpoints()
    t = np.linspace(0.001, 20.0, 3001)
    # interpolate right-continuously between breakpoints (repeated times are jumps)
    idx = np.searchsorted(t_b, t, side="left")
    idx = np.clip(idx, 1, t_b.size - 1)
    t0, t1_, f0, f1 = t_b[idx - 1], t_b[idx], f_b[idx - 1], f_b[idx]
    interp = np.where(t1_ > t0, f0 + (f1 - f0) * (t - t0) / np.where(t1_ > t0, t1_ - t0, 1), f1)
    interp = np.where(t > t_b[-1], f_b[-1], interp)
    assert np.allclose(interp, force(REPORT, t), atol=1e-12)


@given(
    omega=st.floats(0.05, 4.0),
    t1=st.floats(0.2, 3.0),
    gap=st.floats(0.0, 10.0),
    dur=st.floats(0.2, 3.0),
)
@settings(max_examples=40, deadline=None)
def test_amax_general_times(omega: float, t1: float, gap: float, dur: float) -> None:
    # [A]max for any t1 <= t13 < t14 (landing length d != t1, t13 = t1 allowed): it bounds
    # dense samples of A (including the right limits at the jumps) and is reached by them to
    # the sampling resolution (2e4 samples over the history plus one period: < 1e-6 relative)
    p = CrewPushoff(1.0, t1, t1 + gap, t1 + gap + dur)
    t = np.concatenate(
        [
            np.linspace(0.0, p.t14 + 2 * np.pi / omega, 20001),
            np.array([p.t1, p.t13, p.t14]),  # left values (A is closed on the right)
            np.array([p.t1, p.t13, p.t14]) + 1e-12,  # right limits
        ]
    )
    sampled = np.max(np.abs(acceleration_a(omega, t, p)))
    exact = float(accel_amax(omega, p))
    assert sampled <= exact * (1 + 1e-12)
    assert sampled >= exact * (1 - 2e-6)


# ------------------------------------------------------- one crew-force type, one rule


@pytest.mark.parametrize(
    ("args", "where"),
    [
        ((-25.0, 1.0, 13.0, 14.0), "f0"),  # f0 > 0 everywhere (forces accepted f0 != 0)
        ((0.0, 1.0, 13.0, 14.0), "f0"),
        ((1e300, 1.0, 13.0, 14.0), "f0"),  # beyond the 1e7 N limit
        ((1.0, 0.0, 13.0, 14.0), "t1"),
        ((1.0, 1e-9, 13.0, 14.0), "t1"),  # shorter than MIN_RAMP_S
        ((1.0, 2.0, 1.0, 14.0), "t13"),
        ((1.0, 1.0, 13.0, 13.0), "t14"),
        ((1.0, 1.0, 13.0, 2e7), "t14"),  # beyond the 1e7 s limit
        ((True, 1.0, 13.0, 14.0), "f0"),
    ],
)
def test_one_crew_force_type_one_validation(args: tuple, where: str) -> None:
    from microg.dynamics.forces import activity_library, crew_pushoff

    errors = []
    for make in (
        lambda: CrewPushoff(*args),
        lambda: crew_pushoff(*args),
        lambda: activity_library()["report-pushoff"].history(
            **dict(zip(("f0", "t1", "t13", "t14"), args, strict=True))
        ),
    ):
        with pytest.raises(InputError) as exc:
            make()
        errors.append((exc.value.where, exc.value.what))
    assert errors[0][0] == where  # the parameter, not a CLI flag
    assert errors[0] == errors[1] == errors[2]  # the same rule and the same words


def test_crew_pushoff_history_uses_the_type() -> None:
    from microg.dynamics.forces import crew_pushoff

    p = CrewPushoff(40.0, 0.5, 3.0, 3.5)
    t, f = p.breakpoints()
    h = crew_pushoff(40.0, 0.5, 3.0, 3.5)
    assert np.array_equal(h.timepts, t) and np.array_equal(h.force, f)
    assert isinstance(p.f0, float) and p.f0 == 40.0
