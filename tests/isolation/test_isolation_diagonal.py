"""The diagonal (eigen-coordinate) FOH path and its scalar scan, against sequential references.

References: the plain sequential recurrence ``z_{k+1} = a_k z_k + b_k`` (a Python loop), and a
per-step first-order-hold loop whose every step is its own matrix exponential of the augmented
matrix (``scipy.linalg.expm``, no shared maps, no eigen-decomposition).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import linalg

from microg._scan import scalar_scan
from microg.isolation import timedomain as td
from microg.isolation.timedomain import (
    IsolatorModel,
    package_response,
    package_responses,
    state_space,
)

EPS = np.finfo(float).eps


def _loop(a: np.ndarray, b: np.ndarray, x0: np.ndarray, index: np.ndarray | None) -> np.ndarray:
    """Reference: the scalar recurrences one step at a time."""
    m, K = b.shape
    Z = np.empty((m, K + 1), complex)
    Z[:, 0] = x0
    z = x0.astype(complex)
    for k in range(K):  # a loop over steps is fine in a reference
        z = a[:, 0 if index is None else index[k]] * z + b[:, k]
        Z[:, k + 1] = z
    return Z


@pytest.mark.parametrize("K", [1, 15, 64, 65, 999, 4097])
def test_scalar_scan_equals_sequential_loop(K: int) -> None:
    rng = np.random.default_rng(K)
    lam = np.array([-0.02 + 1.3j, -3.0 + 0.5j, 0.0 + 2.0j, -0.7 + 0j])
    h = np.array([0.01, 0.013, 0.021])
    a = np.exp(lam[:, None] * h[None, :])
    b = rng.normal(size=(4, K)) + 1j * rng.normal(size=(4, K))
    x0 = rng.normal(size=4) + 1j * rng.normal(size=4)
    idx = rng.integers(0, 3, K)
    for index, aa in ((idx, a), (None, a[:, :1])):
        ref = _loop(aa, b, x0, index)
        got = scalar_scan(aa, b, index=index, x0=x0)
        assert got is not None
        # the running sums round as the loop does (|P_r / P_j| <= 1): a few eps per step
        # relative to the largest state, times the ~sqrt(K) steps that accumulate
        tol = 50 * np.sqrt(K + 1) * EPS * np.abs(ref).max()
        np.testing.assert_allclose(got, ref, rtol=0, atol=tol)
        w = rng.normal(size=(2, 4)) + 1j * rng.normal(size=(2, 4))
        y = scalar_scan(aa, b, index=index, x0=x0, weights=w)
        assert y is not None
        np.testing.assert_allclose(y, (w @ ref).real, rtol=0, atol=10 * tol * np.abs(w).max())


def test_scalar_scan_declines_a_coordinate_that_decays_too_fast_per_step() -> None:
    # |a| = e^-30 per step: blocks of SCALAR_SPAN / 30 < 16 steps: None, the caller falls back
    a = np.array([[np.exp(-30.0 + 1j)]])
    assert scalar_scan(a, np.ones((1, 1000), complex)) is None


def _expm_loop(model: IsolatorModel, t: np.ndarray, a0: np.ndarray) -> np.ndarray:
    """Reference FOH: every step its own expm of [[A, B, 0], [0, 0, 1], [0, 0, 0]] h."""
    A, B, C = state_space(model)
    n = A.shape[0]
    M = np.zeros((n + 2, n + 2))
    M[:n, :n], M[:n, n], M[n, n + 1] = A, B[:, 0], 1.0
    x = np.zeros(n)
    out = np.empty((2, t.size))
    out[:, 0] = [C[0] @ x, x[0]]
    for j in range(t.size - 1):  # a loop over samples is fine in a reference
        h = t[j + 1] - t[j]
        E = linalg.expm(h * M)
        x = E[:n, :n] @ x + E[:n, n] * a0[j] + E[:n, n + 1] * (a0[j + 1] - a0[j]) / h
        out[:, j + 1] = [C[0] @ x, x[0]]
    return out


MODELS = {
    "bare-undamped": IsolatorModel(m1=450.0, k1=135.0),
    "bare-damped": IsolatorModel(m1=450.0, k1=135.0, c1=40.0),
    "absorber": IsolatorModel.from_dimensionless(450.0, 135.0, k=10.0, mu=0.05, zeta=0.2),
    "overdamped": IsolatorModel(m1=450.0, k1=135.0, c1=3000.0),
}


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("grid", ["uniform", "random"])
def test_diagonal_path_against_per_step_expm_loop(name: str, grid: str) -> None:
    model = MODELS[name]
    rng = np.random.default_rng(4)
    steps = np.full(400, 0.02) if grid == "uniform" else rng.uniform(0.005, 0.05, 400)
    t = np.r_[0.0, np.cumsum(steps)]
    a0 = np.sin(1.3 * t) + 0.3 * rng.normal(size=t.size)
    A, B, C = state_space(model)
    d = td._diagonalize(A, B, np.vstack([C, np.eye(A.shape[0])[:1]]))
    assert d is not None  # well separated eigenvalues: the diagonal path is the one tested
    res = package_response(model, t, a0)
    ref = _expm_loop(model, t, a0)
    # both exact for piecewise-linear input: rounding only, amplified by the eigenvectors'
    # condition (< 1e2 here) over 400 steps: 1e-12 of the peak
    for got, r in ((res.package_accel, ref[0]), (res.stroke, ref[1])):
        np.testing.assert_allclose(got, r, rtol=0, atol=1e-12 * np.abs(r).max())


def test_critically_damped_mount_falls_back_to_the_scans() -> None:
    # zeta = 1: a double eigenvalue with one eigenvector (defective): the diagonal form is
    # refused and the matrix scans give the same exact response
    m1, k1 = 450.0, 135.0
    model = IsolatorModel(m1=m1, k1=k1, c1=2.0 * np.sqrt(k1 * m1))
    A, B, C = state_space(model)
    assert td._diagonalize(A, B, np.vstack([C, np.eye(2)[:1]])) is None
    rng = np.random.default_rng(5)
    t = np.r_[0.0, np.cumsum(rng.uniform(0.005, 0.05, 300))]
    a0 = np.cos(0.7 * t) + 0.2 * rng.normal(size=t.size)
    res = package_response(model, t, a0)
    ref = _expm_loop(model, t, a0)
    np.testing.assert_allclose(res.package_accel, ref[0], rtol=0, atol=1e-12 * np.abs(ref[0]).max())


def test_package_responses_equal_one_call_per_row() -> None:
    model = MODELS["absorber"]
    t = np.linspace(0.0, 50.0, 5001)
    rows = np.random.default_rng(6).normal(size=(3, t.size))
    many = package_responses(model, t, rows)
    for r, res in zip(rows, many, strict=True):
        one = package_response(model, t, r)
        # the same arithmetic row by row: identical
        np.testing.assert_array_equal(res.package_accel, one.package_accel)
        np.testing.assert_array_equal(res.stroke, one.stroke)
        assert res.peak_stroke == one.peak_stroke


def test_phi_functions_against_augmented_expm() -> None:
    # reference: expm([[z, 1, 0], [0, 0, 1], [0, 0, 0]]) holds phi1(z), phi2(z) in its first row
    z = np.array([1e-9 + 1e-7j, 0.3 - 0.2j, 0.49j, 0.51, -3 + 4j, -40 + 0j, 1e-3j, -0.5 - 0.1j])
    p1, p2 = td._phi12(z)
    for zi, a, b in zip(z, p1, p2, strict=True):
        E = linalg.expm(np.array([[zi, 1, 0], [0, 0, 1], [0, 0, 0]], complex))
        # series below |z| = 1/2, closed form above: a few roundings (expm's own ~1e-15)
        assert abs(a - E[0, 1]) <= 4e-15 * abs(E[0, 1])
        assert abs(b - E[0, 2]) <= 4e-15 * abs(E[0, 2])
