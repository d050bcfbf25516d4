"""Exact FOH time response against solve_ivp, scipy.signal.lsim and the steady-state M_a."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate, signal

from microg.errors import InputError
from microg.isolation.timedomain import IsolatorModel, package_response, state_space
from microg.isolation.transmissibility import accel_magnification

WITH_ABSORBER = IsolatorModel.from_dimensionless(450.0, 135.0, k=10.0, mu=0.05, zeta=0.2)
NO_ABSORBER = IsolatorModel(m1=450.0, k1=135.0)
DAMPED_MOUNT = IsolatorModel(m1=450.0, k1=135.0, c1=30.0)


def reference_ivp(model: IsolatorModel, t: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Integrate x' = A x + B a0(t) step by step with a0 linear on each step (DOP853)."""
    A, B, C = state_space(model)
    x = np.zeros(A.shape[0])
    out = [C[0] @ x]
    for j in range(t.size - 1):  # a loop over samples is fine in a reference
        s = (a[j + 1] - a[j]) / (t[j + 1] - t[j])

        def rhs(tt, xx, j=j, s=s):  # type: ignore[no-untyped-def]
            return A @ xx + B[:, 0] * (a[j] + s * (tt - t[j]))

        sol = integrate.solve_ivp(rhs, (t[j], t[j + 1]), x, method="DOP853", rtol=1e-13, atol=1e-16)
        x = sol.y[:, -1]
        out.append(C[0] @ x)
    return np.array(out)


@pytest.mark.parametrize(
    "model", [WITH_ABSORBER, NO_ABSORBER, DAMPED_MOUNT], ids=["abs", "bare", "c1"]
)
def test_non_uniform_steps_against_solve_ivp(model: IsolatorModel) -> None:
    rng = np.random.default_rng(7)
    t = np.cumsum(np.r_[0.0, rng.uniform(0.02, 0.5, 300)])
    a = rng.normal(size=t.size) * 1e-4
    res = package_response(model, t, a)
    ref = reference_ivp(model, t, a)
    # DOP853 at rtol 1e-13 on each exact-linear segment: agreement to ~1e-10 of the peak
    np.testing.assert_allclose(res.package_accel, ref, rtol=0, atol=1e-10 * np.abs(ref).max())


def test_uniform_steps_against_lsim() -> None:
    t = np.linspace(0.0, 60.0, 6001)
    a = np.sin(1.02 * t) * np.exp(-0.03 * t) + 0.3 * np.sign(np.sin(0.2 * t))
    A, B, C = state_space(WITH_ABSORBER)
    _, y, _ = signal.lsim((A, B, C, np.zeros((1, 1))), a, t, interp=True)
    res = package_response(WITH_ABSORBER, t, a)
    # lsim is exact FOH on a uniform grid too (its own expm): agreement to rounding, 1e-11
    np.testing.assert_allclose(res.package_accel, y, rtol=0, atol=1e-11 * np.abs(y).max())


def test_steady_state_amplitude_is_M_a() -> None:
    # harmonic mount acceleration, finely sampled; after the transient has decayed the package
    # amplitude over mount amplitude is M_a(r) of Eq. 4.3 (frequency-domain check)
    model = IsolatorModel(m1=1.0, k1=1.0, c1=0.4)  # damped so the transient dies
    w = 1.7
    t = np.linspace(0.0, 200.0, 200_001)
    res = package_response(model, t, np.sin(w * t))
    tail = res.package_accel[t > 150]
    # mount damper c1 is outside the report model: compare with the exact SDOF value
    s = 1j * w
    expected = abs((0.4 * s + 1.0) / (s * s + 0.4 * s + 1.0))
    # sampling at dt = 1e-3 resolves the peak to cos(w dt/2) ~ 1 - 4e-7
    assert tail.max() == pytest.approx(expected, rel=1e-5)
    # and with an absorber (zeta > 0 damps everything), against accel_magnification
    # (lightly damped modes: run 500 s so the transient, ~exp(-0.03 t), is below 1e-6)
    m = IsolatorModel.from_dimensionless(1.0, 1.0, k=20.0, mu=0.05, zeta=0.2)
    t2 = np.linspace(0.0, 500.0, 250_001)  # dt = 2e-3: peak sampling error ~ 1.5e-6
    res2 = package_response(m, t2, np.sin(w * t2))
    assert res2.package_accel[t2 > 450].max() == pytest.approx(
        float(accel_magnification(20.0, 0.05, 0.2, w)), rel=1e-5
    )


def test_oversample_and_summary_fields() -> None:
    t = np.array([0.0, 1.0, 3.0, 3.5, 8.0, 20.0])
    a = np.array([0.0, 1.0, -1.0, 0.5, 0.0, 0.0])
    coarse = package_response(WITH_ABSORBER, t, a)
    fine = package_response(WITH_ABSORBER, t, a, oversample=8)
    # same piecewise-linear input: the fine result at the original samples equals the coarse one
    np.testing.assert_allclose(fine.package_accel[::8], coarse.package_accel, atol=1e-14)
    assert fine.peak_package >= coarse.peak_package
    assert fine.peak_mount == 1.0
    assert fine.peak_ratio == pytest.approx(fine.peak_package / fine.peak_mount)
    assert fine.rms_ratio == pytest.approx(fine.rms_package / fine.rms_mount)
    # rest relative to the mount at t0
    assert coarse.stroke[0] == 0.0 and coarse.package_accel[0] == 0.0


def test_validation() -> None:
    with pytest.raises(InputError, match="timepts"):
        package_response(NO_ABSORBER, [0.0, 1.0, 1.0], [0.0, 1.0, 2.0])
    with pytest.raises(InputError, match="mount_accel"):
        package_response(NO_ABSORBER, [0.0, 1.0], [0.0])
    with pytest.raises(InputError, match="m1"):
        IsolatorModel(m1=0.0, k1=1.0)
    with pytest.raises(InputError, match="m2"):
        IsolatorModel(m1=1.0, k1=1.0, m2=1.0)


def _sequential(M: np.ndarray, c: np.ndarray, x0: np.ndarray, index=None) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Reference: the recurrence x_{k+1} = M_k x_k + c_k as a plain loop (batch axes leading)."""
    K = c.shape[-2]
    X = np.empty((*c.shape[:-2], K + 1, c.shape[-1]))
    X[..., 0, :] = x0
    x = x0
    for k in range(K):  # a loop over steps is fine in a reference
        Mk = M[..., k if index is None else index[k], :, :]
        x = np.einsum("...ij,...j->...i", Mk, x) + c[..., k, :]
        X[..., k + 1, :] = x
    return X


@pytest.mark.parametrize("K", [1, 7, 64, 65, 1000, 1237])
def test_affine_scan_equals_sequential_loop(K: int) -> None:
    """The one blocked scan (microg._scan) against the sequential recurrence it replaces."""
    from microg._scan import affine_scan, lti_scan

    rng = np.random.default_rng(K)
    for n in (2, 4):
        # contractive-to-neutral maps, like the exact step maps of damped oscillators
        M = rng.normal(size=(3, K, n, n)) * 0.2 + 0.8 * np.eye(n)
        c = rng.normal(size=(3, K, n))
        x0 = rng.normal(size=(3, n))
        ref = _sequential(M, c, x0)
        got = affine_scan(M, c, x0=x0)
        # a few roundings per block start (products in another order): 1e-12 of the states
        assert np.max(np.abs(got - ref)) <= 1e-12 * np.max(np.abs(ref))
        idx = rng.integers(0, 5, K)
        Mu = rng.normal(size=(5, n, n)) * 0.2 + 0.8 * np.eye(n)
        ref_i = _sequential(Mu, c[0], x0[0], idx)
        got_i = affine_scan(Mu, c[0], index=idx, x0=x0[0])
        assert np.max(np.abs(got_i - ref_i)) <= 1e-12 * np.max(np.abs(ref_i))
        # one shared map with inputs and outputs (the uniform first-order-hold case)
        G = rng.normal(size=(2, n))
        u = rng.normal(size=(K, 2))
        Cm = rng.normal(size=(3, n))
        ref_l = _sequential(Mu[:1], u @ G, x0[0], np.zeros(K, int)) @ Cm.T
        got_l = lti_scan(Mu[0], G, u, Cm, x0=x0[0])
        assert np.max(np.abs(got_l - ref_l)) <= 1e-12 * np.max(np.abs(ref_l))


def test_long_uniform_record_equals_sequential_foh_loop() -> None:
    """50,001 uniform samples (the O(N) shared-map path) against the plain FOH recurrence."""
    from microg.isolation.timedomain import foh_discretize

    t = np.linspace(0.0, 500.0, 50_001)
    a = np.sin(1.02 * t) + 0.2 * np.sin(7.3 * t)
    res = package_response(WITH_ABSORBER, t, a)
    A, B, C = state_space(WITH_ABSORBER)
    Phi, G1, G2 = foh_discretize(A, B, [(t[-1] - t[0]) / (t.size - 1)])
    slope = np.diff(a) / np.diff(t)
    X = _sequential(
        Phi[:1],
        G1[0] * a[:-1, None] + G2[0] * slope[:, None],
        np.zeros(4),
        np.zeros(t.size - 1, int),
    )
    ref = X @ C[0]
    # the same recurrence, block starts composed in another order: rounding over 5e4 steps
    np.testing.assert_allclose(res.package_accel, ref, rtol=0, atol=1e-11 * np.abs(ref).max())
    np.testing.assert_allclose(res.stroke, X[:, 0], rtol=0, atol=1e-11 * np.abs(X[:, 0]).max())
