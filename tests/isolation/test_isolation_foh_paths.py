"""The FOH package response's fast paths against independent references.

``package_response`` takes the diagonal (eigen-coordinate) recurrence on any grid when the state
matrix diagonalises well; otherwise the shared-map O(N) scan on a uniform grid, and on a grid whose
steps are whole multiples of one fine step (it refines the grid and picks the samples), otherwise
the general scan.  Every test runs twice: on the diagonal path and with it switched off (the
matrix scans).  References: a closed form (undamped mount, ramp input), solve_ivp (DOP853) step by
step, and the general scan of :func:`microg._scan.affine_scan` itself.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from microg.isolation import timedomain as td
from microg.isolation.timedomain import IsolatorModel, package_response, state_space

WITH_ABSORBER = IsolatorModel.from_dimensionless(450.0, 135.0, k=10.0, mu=0.05, zeta=0.2)
BARE = IsolatorModel(m1=450.0, k1=135.0)


@pytest.fixture(autouse=True, params=[True, False], ids=["diagonal", "scans"])
def _path(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every test on the diagonal path and on the matrix scans."""
    monkeypatch.setattr(td, "_DIAGONAL", request.param)


def _commensurate_grid(n: int, base_s: float, seed: int) -> np.ndarray:
    """Times that are exact integer multiples of ``base_s`` (steps of 1, 2 or 4 base steps)."""
    rng = np.random.default_rng(seed)
    return np.r_[0, np.cumsum(rng.choice([1, 2, 4], n - 1))] * base_s


def _ivp(model: IsolatorModel, t: np.ndarray, a: np.ndarray) -> np.ndarray:
    """x' = A x + B a0(t), a0 linear on each step, DOP853 step by step (rtol 1e-13)."""
    A, B, C = state_space(model)
    x = np.zeros(A.shape[0])
    out = [C[0] @ x]
    for j in range(t.size - 1):  # a loop over samples is fine in a reference
        s = (a[j + 1] - a[j]) / (t[j + 1] - t[j])

        def rhs(tt: float, xx: np.ndarray, j: int = j, s: float = s) -> np.ndarray:
            return A @ xx + B[:, 0] * (a[j] + s * (tt - t[j]))

        sol = integrate.solve_ivp(rhs, (t[j], t[j + 1]), x, method="DOP853", rtol=1e-13, atol=1e-16)
        x = sol.y[:, -1]
        out.append(C[0] @ x)
    return np.array(out)


def test_commensurate_grid_takes_the_refined_path() -> None:
    t = _commensurate_grid(500, 0.01, 1)
    h = np.diff(t)
    hu, index = td._group_steps(h, float(t.max()), float(t[-1] - t[0]))
    fine = td._commensurate(t, hu, index)
    assert fine is not None
    counts, h_fine = fine
    assert counts.sum() == round((t[-1] - t[0]) / 0.01)
    assert h_fine == pytest.approx(0.01, rel=1e-14)  # span / count: one rounding
    # not commensurate (0.01 and 0.0137 s): the general path
    t2 = np.r_[0, np.cumsum(np.where(np.arange(499) % 3 == 0, 0.0137, 0.01))]
    hu2, index2 = td._group_steps(np.diff(t2), float(t2.max()), float(t2[-1] - t2[0]))
    assert td._commensurate(t2, hu2, index2) is None


@pytest.mark.parametrize("model", [WITH_ABSORBER, BARE], ids=["abs", "bare"])
def test_refined_path_against_solve_ivp(model: IsolatorModel) -> None:
    t = _commensurate_grid(300, 0.05, 2)
    rng = np.random.default_rng(3)
    a = rng.normal(size=t.size) * 1e-4
    res = package_response(model, t, a)
    ref = _ivp(model, t, a)
    # DOP853 at rtol 1e-13 on each exact-linear step: agreement to ~1e-10 of the peak
    np.testing.assert_allclose(res.package_accel, ref, rtol=0, atol=1e-10 * np.abs(ref).max())


def test_refined_path_against_closed_form_ramp() -> None:
    """Undamped bare mount, a0 = s t: u1'' = s (t - sin(omega t) / omega), exactly."""
    t = _commensurate_grid(20_000, 0.01, 4)  # ~47,000 fine steps
    s = 1e-3
    res = package_response(BARE, t, s * t)
    w = BARE.omega_n
    exact = s * (t - np.sin(w * t) / w)
    # the exact recurrence over 5e4 steps of an undamped map: rounding grows with the step count
    # (a phase error of ~N eps), 1e-11 of the peak leaves a factor ~10 over what it reaches
    np.testing.assert_allclose(res.package_accel, exact, rtol=0, atol=1e-11 * np.abs(exact).max())
    stroke = -s * (t - np.sin(w * t) / w) / w**2  # z1 = u1 - u0 from z1'' + w^2 z1 = -s t
    np.testing.assert_allclose(res.stroke, stroke, rtol=0, atol=1e-11 * np.abs(stroke).max())


def test_refined_path_equals_general_scan(monkeypatch: pytest.MonkeyPatch) -> None:
    t = _commensurate_grid(30_000, 0.002, 5)
    a = np.sin(1.02 * t) + 0.1 * np.sin(17.0 * t)
    fast = package_response(WITH_ABSORBER, t, a)
    monkeypatch.setattr(td, "_REFINE_AT_MOST", 0)  # refinement refused: the general scan
    monkeypatch.setattr(td, "_DIAGONAL", False)
    general = package_response(WITH_ABSORBER, t, a)
    for key in ("package_accel", "stroke"):
        ref = getattr(general, key)
        # the same exact FOH steps (a step of m fine steps is Phi(h)^m in exact arithmetic):
        # rounding accumulated over N = 7e4 fine steps, bounded by ~N eps = 1.6e-11 of the peak
        tol = 1.5 * 7e4 * np.finfo(float).eps * np.abs(ref).max()
        np.testing.assert_allclose(getattr(fast, key), ref, rtol=0, atol=tol)


def test_group_steps_linear_pass_equals_sort() -> None:
    rng = np.random.default_rng(6)
    for n_distinct in (1, 3, 8, 12):  # 12 > _PEEL_AT_MOST: the sort
        choices = rng.uniform(1e-3, 1e-2, n_distinct)
        h = rng.choice(choices, 5000) * (1.0 + 1e-16 * rng.normal(size=5000))
        hu, index = td._group_steps(h, 10.0, float(h.sum()))
        assert np.all(index >= 0)
        # every step is within the grouping tolerance of its representative
        assert np.max(np.abs(h - hu[index])) <= 8.0 * np.finfo(float).eps * 10.0
        assert hu.size >= np.unique(np.round(choices, 12)).size


def _piecewise_grid() -> np.ndarray:
    """Uniform pieces of incommensurate steps (0.01 s, 0.0137 s) with irregular steps between."""
    rng = np.random.default_rng(8)
    steps = np.r_[
        np.full(3000, 0.01), np.full(2000, 0.0137), rng.uniform(0.005, 0.02, 50), np.full(999, 0.01)
    ]
    return np.r_[0.0, np.cumsum(steps)]


def test_piecewise_uniform_grid_against_closed_form_ramp() -> None:
    """Undamped bare mount, a0 = s t, on uniform pieces joined by irregular steps (exact form)."""
    t = _piecewise_grid()
    hu, index = td._group_steps(np.diff(t), float(t.max()), float(t[-1] - t[0]))
    assert td._commensurate(t, hu, index) is None  # so the per-run path is the one tested
    s = 1e-3
    res = package_response(BARE, t, s * t)
    w = BARE.omega_n
    exact = s * (t - np.sin(w * t) / w)
    # ~6e3 exact steps, the state carried between pieces: rounding only, 1e-12 of the peak
    # (an error of one step length in a carried state would show ~1e-4)
    np.testing.assert_allclose(res.package_accel, exact, rtol=0, atol=1e-12 * np.abs(exact).max())
    stroke = -s * (t - np.sin(w * t) / w) / w**2
    np.testing.assert_allclose(res.stroke, stroke, rtol=0, atol=1e-12 * np.abs(stroke).max())


def test_piecewise_uniform_grid_equals_general_scan(monkeypatch: pytest.MonkeyPatch) -> None:
    t = _piecewise_grid()
    a = np.sin(1.02 * t) + 0.1 * np.sin(17.0 * t)
    fast = package_response(WITH_ABSORBER, t, a)
    monkeypatch.setattr(td, "_RUN_AT_LEAST", 10**9)  # no runs: one general scan
    monkeypatch.setattr(td, "_DIAGONAL", False)
    general = package_response(WITH_ABSORBER, t, a)
    for key in ("package_accel", "stroke"):
        ref = getattr(general, key)
        # the same exact step maps, composed in another order: rounding over N = 6e3 steps,
        # bounded by ~N eps = 1.3e-12 of the peak
        tol = 1.5 * 6e3 * np.finfo(float).eps * np.abs(ref).max()
        np.testing.assert_allclose(getattr(fast, key), ref, rtol=0, atol=tol)
