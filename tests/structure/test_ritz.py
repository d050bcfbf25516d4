"""Assumed-modes engine (Eqs. 2.5, 2.6, Appendix B) against direct integration and exact beams."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from microg.dynamics.dense import solve_dense
from microg.models.station import Beam, Orbit, PointMass, RigidBody, Station
from microg.structure.ritz import (
    Coordinate,
    assemble,
    build_ritz,
    cantilever_functions,
    planar_coordinates,
    report_cantilever_function,
)

EI, RHO, L = 2.0e7, 3.0, 10.0


def _cantilever_station(tip_mass: float = 0.0, tip_inertia: float = 0.0, rho: float = RHO):
    """A uniform beam along z from a heavy root body (the root body only carries mass)."""
    tip = (
        (PointMass("tip", tip_mass, np.array([0, 0, L]), np.diag([tip_inertia] * 3)),)
        if tip_mass or tip_inertia
        else ()
    )
    beam = Beam(
        "b",
        "root",
        np.zeros(3),
        np.array([0, 0, 1.0]),
        L,
        np.array([1.0, 0, 0]),
        EI,
        EI,
        1.0,
        None,
        rho,
        tip,
    )
    root = RigidBody("root", (PointMass("m0", 5.0, np.array([0, 0, -1.0])),))
    return Station("s", (root,), (beam,), (), Orbit(7.0e6), reference_length=L)


def _bending_only(station: Station, n: int, plane: str = "xz") -> list[Coordinate]:
    return [c for c in planar_coordinates(station, plane, n) if c.kind == "bending"]


def test_report_function_matrices_match_appendix_formulas() -> None:
    # Appendix A/B: m33 = 11/105 M_k for psi = xi^2 - xi^3/3, k33 = 4 EI/(3 l^3);
    # reference: scipy.integrate.quad of rho psi^2 and EI psi''^2 (quad error ~1e-14)
    st = _cantilever_station()
    m, k = assemble(st, _bending_only(st, 1), gravity_gradient=False)
    psi = report_cantilever_function()
    m_ref = quad(lambda s: RHO * psi(s / L) ** 2, 0, L)[0]
    k_ref = quad(lambda s: EI * (psi.deriv(2)(s / L) / L**2) ** 2, 0, L)[0]
    assert m[0, 0] == pytest.approx(m_ref, rel=1e-12)
    assert m[0, 0] == pytest.approx(11 / 105 * RHO * L, rel=1e-12)
    assert k[0, 0] == pytest.approx(k_ref, rel=1e-12)
    assert k[0, 0] == pytest.approx(4 * EI / (3 * L**3), rel=1e-12)


def test_symmetric_and_rigid_vectors_annihilated() -> None:
    # M, K symmetric; without gravity gradient K annihilates translation and rotation
    st = _cantilever_station(2.0, 0.5)
    s = build_ritz(st, "xz", 3, gravity_gradient=False)
    assert np.allclose(s.mass, s.mass.T, rtol=0, atol=1e-12 * np.abs(s.mass).max())
    assert np.allclose(s.stiffness, s.stiffness.T, rtol=0, atol=0)
    for r in s.rigid_body.values():
        assert np.linalg.norm(s.stiffness @ r) <= 1e-14 * np.linalg.norm(s.stiffness)
    # the rigid translation's kinetic energy is the total mass (Eq. 2.5 with psi1 = 1)
    r = s.rigid_body["x"]
    assert r @ s.mass @ r == pytest.approx(s.total_mass, rel=1e-12)


def _exact_cantilever_beta(alpha: float, jr: float, n: int) -> np.ndarray:
    """Roots beta L of the clamped beam with tip mass ratio alpha = M/(rho L) and tip
    rotary-inertia ratio jr = J/(rho L^3) (Blevins, Table 8-8 type; derived from the 4x4
    boundary determinant of w = A cos + B sin + C cosh + D sinh):

    1 + c ch + alpha b (c sh - s ch) - jr b^3 (s ch + c sh) + alpha jr b^4 (1 - c ch) = 0
    """

    def f(b: float) -> float:
        c, s, ch, sh = np.cos(b), np.sin(b), np.cosh(b), np.sinh(b)
        val = 1 + c * ch + alpha * b * (c * sh - s * ch) - jr * b**3 * (s * ch + c * sh)
        val += alpha * jr * b**4 * (1 - c * ch)
        return val / ch

    grid = np.linspace(0.05, 20.0, 40000)
    vals = np.array([f(b) for b in grid])
    roots = [
        brentq(f, grid[i], grid[i + 1], xtol=1e-14)
        for i in np.nonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]
    ]
    return np.array(roots[:n])


@pytest.mark.parametrize(("alpha", "jr"), [(0.0, 0.0), (0.5, 0.0), (0.5, 0.02)])
def test_converges_to_exact_cantilever(alpha: float, jr: float) -> None:
    # Rayleigh-Ritz bounds from above and converges to the exact clamped-free frequencies
    # (reference: the transcendental equation, brentq to 1e-14); 10 polynomial functions
    # give the first two frequencies to 1e-6 relative
    st = _cantilever_station(alpha * RHO * L, jr * RHO * L**3)
    beta = _exact_cantilever_beta(alpha, jr, 2)
    w_exact = (beta / L) ** 2 * np.sqrt(EI / RHO)
    errs = []
    for n in (1, 2, 4, 10):
        m, k = assemble(st, _bending_only(st, n), gravity_gradient=False)
        w, _, _ = solve_dense(m, k, np.zeros((n, 0)))
        errs.append((w[: min(2, n)] - w_exact[: min(2, n)]) / w_exact[: min(2, n)])
        assert np.all(errs[-1] > -1e-9)  # upper bound property of Rayleigh-Ritz
    assert abs(errs[-1][0]) < 1e-6 and abs(errs[-1][1]) < 1e-6
    assert abs(errs[1][0]) < abs(errs[0][0])  # refinement improves


def test_report_function_first_frequency_error() -> None:
    # the report's single function overestimates the bare cantilever's first frequency by
    # sqrt((4/3)/(11/105)) / 1.8751^2 - 1 = 1.5% (a property of psi = xi^2 - xi^3/3)
    st = _cantilever_station()
    m, k = assemble(st, _bending_only(st, 1), gravity_gradient=False)
    w = np.sqrt(k[0, 0] / m[0, 0])
    w_exact = (1.8751040687 / L) ** 2 * np.sqrt(EI / RHO)
    assert w / w_exact - 1 == pytest.approx(np.sqrt(140 / 11) / 1.8751040687**2 - 1, rel=1e-8)


def test_cantilever_functions_are_admissible() -> None:
    for f in cantilever_functions(6):
        assert f(0.0) == pytest.approx(0.0, abs=1e-15)
        assert f.deriv()(0.0) == pytest.approx(0.0, abs=1e-15)


def test_gravity_gradient_term_gives_libration_frequency() -> None:
    # Appendix B-2 with 1/l_k^2: a rigid station (no beams' flexibility relevant) librates
    # at w0 sqrt(3 (Ix - Iz)/Iy) (Eq. 2.30b); reference: the formula with the station's own
    # inertia about its centre of mass. Elastic coupling shifts it by O(w_lib^2/w_el^2) ~ 1e-7
    st = _cantilever_station(2.0, 0.0)
    stiff = Station(st.name, st.bodies, st.beams, st.points, Orbit(6.87e6), st.reference_length)
    s = build_ritz(stiff, "xz", 1, gravity_gradient=True)
    w, _, rigid = solve_dense(s.mass, s.stiffness, np.column_stack(list(s.rigid_body.values())))
    assert rigid.sum() == 1  # only the translation is a zero mode; rotation is restrained
    _, _, inertia = stiff.mass_properties()
    w0 = stiff.orbit.omega0
    w_lib = w0 * np.sqrt(3 * (inertia[0, 0] - inertia[2, 2]) / inertia[1, 1])
    assert w[1] == pytest.approx(w_lib, rel=1e-5)
