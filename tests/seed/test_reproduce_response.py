"""Eqs. 2.20a-b (closed-form modal superposition) against the independent piecewise-linear
modal kernel (microg.dynamics.response) and Eq. 3.1 against the time history's own peak."""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff
from microg.dynamics.response import modal_pwl_response
from microg.seed.ioc import FT, LBF, SLUG
from microg.seed.reproduce import report_point_response, reproduce


@pytest.fixture(scope="module")
def c1():
    return reproduce().appendix_c["xz_orbiter"]


def test_eq_2_20_matches_pwl_kernel(c1) -> None:
    # reference: microg.dynamics.response propagates eta_j'' + w_j^2 eta_j = gamma_j f(t) exactly
    # segment by segment, with gamma_j = phi_j.psi(P_a)/M_jj; the physical response at P_e is
    # sum_j phi_j.psi(P_e) eta_j. Two exact routes: agreement to 1e-10 of the peak
    crew = CrewPushoff(25 * LBF, 1.0, 13.0, 14.0)
    psi = np.array([1.0, -55.0 / 296.0, 0.0, 0.0])
    omega = np.sqrt(c1.omega2)
    mm = c1.modal_mass * SLUG
    t = np.linspace(0.0, 80.0, 4001) + 1e-6  # off the jump instants
    rr = report_point_response(c1.phi, mm, omega, psi, psi, crew, t)
    t_b, f_b = crew.breakpoints()
    gamma = (c1.phi.T @ psi) / mm
    res = modal_pwl_response(omega, np.zeros(2), t_b, np.outer(gamma, f_b), t)
    disp = (c1.phi.T @ psi) @ res.eta
    acc = (c1.phi.T @ psi) @ res.eta_ddot
    assert np.max(np.abs(rr.displacement - disp)) <= 1e-10 * np.max(np.abs(disp))
    assert np.max(np.abs(rr.accel - acc)) <= 1e-10 * np.max(np.abs(acc))


def test_eq_3_1_is_the_peak_of_each_mode(c1) -> None:
    # Eq. 3.1 (exact [A]max) bounds each mode's sampled history and is attained to within
    # the sampling (1e-3 relative at 400 samples per period)
    crew = CrewPushoff(25 * LBF, 1.0, 13.0, 14.0)
    psi = np.array([1.0, -55.0 / 296.0, 0.0, 0.0])
    omega = np.sqrt(c1.omega2)
    t = np.linspace(0.0, 14.0 + 2 * np.pi / omega.min(), 40001)
    rr = report_point_response(c1.phi, c1.modal_mass * SLUG, omega, psi, psi, crew, t)
    sampled = np.max(np.abs(rr.accel_modes), axis=1)
    assert np.all(sampled <= rr.peak_accel_modes * (1 + 1e-12))
    assert np.allclose(sampled, rr.peak_accel_modes, rtol=1e-3)


def test_table4_uses_eq_3_1(c1) -> None:
    rep = reproduce()
    b = rep.table4["xz_orbiter"].bending
    crew = rep.options.crew
    psi = np.array([1.0, rep.options.z_e / (296 * FT), 0.0, 0.0])
    rr = report_point_response(
        c1.phi, c1.modal_mass * SLUG, np.sqrt(c1.omega2), psi, psi, crew, np.array([0.0])
    )
    assert np.allclose(rr.peak_accel_modes / 9.80665, [b[0].accel_g, b[1].accel_g], rtol=1e-12)


@pytest.mark.parametrize(("z_e", "z_a", "where"), [(10.0, -55.0, "z_e"), (-55.0, -130.0, "z_a")])
def test_points_off_the_main_body_are_refused(z_e: float, z_a: float, where: str) -> None:
    # Eq. 3.1 uses psi = [1, z/l_k, 0, 0], true on the rigid main body only (-126.66..0 ft):
    # a point on the keel (z > 0) or below the orbiter is refused, naming the parameter
    from microg.errors import InputError
    from microg.seed.reproduce import ReproduceOptions

    with pytest.raises(InputError) as exc:
        ReproduceOptions(CrewPushoff(25 * LBF), z_e * FT, z_a * FT)
    assert exc.value.where == where and "main body" in str(exc.value)
    ReproduceOptions(CrewPushoff(25 * LBF), 0.0, -126.66 * FT)  # the ends are accepted


def test_main_body_range_is_the_models() -> None:
    # the range's ends are the main body of the shipped model: its lowest mass (the orbiter)
    # and the keel joint, where the keel begins
    from microg.models.toml import load_station
    from microg.seed.eq31 import MAIN_BODY_Z_RANGE_FT

    st = load_station("ioc")
    main = next(b for b in st.bodies if b.name == "main")
    zs = [m.position[2] / FT for m in main.masses]
    assert min(zs) == pytest.approx(MAIN_BODY_Z_RANGE_FT[0], abs=1e-9)
    assert max(zs) <= MAIN_BODY_Z_RANGE_FT[1]


def test_unknown_case_is_refused() -> None:
    from microg.errors import InputError

    with pytest.raises(InputError) as exc:
        reproduce(cases=["xy_orbiter"])
    assert exc.value.where == "cases"
