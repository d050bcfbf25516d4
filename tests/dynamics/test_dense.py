"""Tests of microg.dynamics.dense: graded inverse solve, unstable modes, legacy unpacking."""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.dense import graded_eigh, solve_dense
from microg.dynamics.modes import solve_modes
from microg.errors import InputError


def test_graded_eigh_keeps_relative_accuracy_over_twenty_decades() -> None:
    # a diagonal stiffness spanning 1e-12..1e8 with a well-conditioned dense mass (the shape
    # of a Ritz model with a gravity-gradient coordinate).  References, each exact where it
    # is used: the lowest eigenvalues from the standard problem S = K^-1/2 M K^-1/2 (exact
    # diagonal scaling; its largest eigenvalues 1/lambda carry relative error eps), the
    # highest from scipy's eigh(K, M) (absolute error eps lambda_max)
    import scipy.linalg as sla

    rng = np.random.default_rng(3)
    n = 40
    a = rng.standard_normal((n, n))
    m = a @ a.T / n + np.eye(n)
    k = np.logspace(-12, 8, n)
    lam, y = graded_eigh(np.diag(k), m)
    d = 1.0 / np.sqrt(k)
    low = np.sort(1.0 / np.linalg.eigvalsh(d[:, None] * m * d[None, :]))[:10]
    high = sla.eigh(np.diag(k), m, eigvals_only=True)[-10:]
    np.testing.assert_allclose(lam[:10], low, rtol=1e-10)
    np.testing.assert_allclose(lam[-10:], high, rtol=1e-10)
    # the direct solve loses the lowest one entirely (absolute error 1e-8 >> 1e-12)
    direct = sla.eigh(np.diag(k), m, eigvals_only=True)
    assert abs(direct[0] / low[0] - 1) > 1e-3
    np.testing.assert_allclose(y.T @ m @ y, np.eye(n), atol=1e-9)


def test_unstable_mode_reported_with_growth_rate() -> None:
    # a mass on a negative spring -k next to a free one: lambda = -k/m, growth sqrt(k/m)
    mass = np.diag([2.0, 3.0])
    stiff = np.array([[-8.0, 0.0], [0.0, 27.0]])
    sol = solve_dense(mass, stiff, np.zeros((2, 0)))
    assert sol.unstable.tolist() == [True, False]
    assert sol.growth_rate[0] == pytest.approx(2.0, rel=1e-13) and sol.omega[0] == 0.0
    assert sol.omega[1] == pytest.approx(3.0, rel=1e-13)
    with pytest.raises(InputError, match="unstable"):
        omega, phi, rigid = solve_dense(mass, stiff, np.zeros((2, 0)))  # cannot say so


def test_tuple_unpacking_still_works_for_stable_problems() -> None:
    omega, phi, rigid = solve_dense(np.eye(2), np.array([[1.0, -1.0], [-1.0, 1.0]]))
    assert rigid.tolist() == [True, False] and omega[1] == pytest.approx(np.sqrt(2.0))


def _ioc_with_keel_ei(ei: str):
    from importlib import resources

    from microg.models.toml import loads_station

    text = resources.files("microg.data").joinpath("ioc.toml").read_text()
    keel = text.index('name = "keel"')
    at = text.index("ei = ", keel)
    end = text.index("\n", at)
    return loads_station(text[:at] + f'ei = "{ei}"' + text[end:])


def test_a_near_rigid_keel_is_refused_with_its_reason_not_an_internal_error():
    # a keel EI of 1e16 N m^2 (inside the documented EI limit) beside the IOC's 5.4e8: the
    # coordinates' K_ii / M_ii span 6e15, and 29 low modes could not reach the backward-error
    # check (a SolverError, "internal error").  It is a modelling limit: one InputError
    # naming the stiffest coordinate and the way out
    from microg.structure.fem import build_fem

    with pytest.raises(InputError, match=r"span 6\.3e\+15.*keel:") as e:
        solve_modes(build_fem(_ioc_with_keel_ei("1e16 N*m^2")))
    assert "ritz" in e.value.fix
    # 1e12 N m^2 (spread 6e11) is inside what double precision resolves: solved, every mode
    # through the backward-error check
    m = solve_modes(build_fem(_ioc_with_keel_ei("1e12 N*m^2")))
    assert m.n_rigid == 6 and np.all(np.diff(m.omega) >= 0)
    # the assumed-modes model of the stiff keel solves too (the fix the message offers)
    from microg.structure.ritz import build_ritz

    r = solve_modes(build_ritz(_ioc_with_keel_ei("1e16 N*m^2"), None, 2, gravity_gradient=False))
    assert r.n_rigid == 6
