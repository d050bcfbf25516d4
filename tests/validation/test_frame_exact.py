"""Validation: frame elements against exact solutions.

* Timoshenko cantilever (shear and rotary inertia): the exact frequencies of the Timoshenko
  beam equations, found here from their characteristic exponents (Huang, J. Appl. Mech. 28
  (1961) 579, written out below) by root finding: no discretisation.
* Rod axial modes: the exact dispersion of the discrete chain (lumped and consistent) and
  the continuum ``omega_n = (2n - 1) pi c / (2 L)``.
* CBUSH spring-mass: the closed-form roots of the 2-DOF system of a mass with rotary inertia
  on a spring offset from its centre.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from microg.dynamics.modes import solve_modes
from microg.models.graph import (
    BeamElement,
    BeamSection,
    ConcentratedMass,
    Constraint,
    GraphModel,
    Node,
    RodElement,
    Spring,
)
from microg.structure.frame import build_frame

# a stubby aluminium bar, L/h = 10: shear and rotary inertia move the modes by 1-10 %
E, NU, RHO = 70e9, 0.3, 2700.0
G = E / (2 * (1 + NU))
B = H = 0.2
A, I, K_SHEAR, L = B * H, B * H**3 / 12, 5.0 / 6.0, 2.0
EI, KGA, RA, RI = E * I, K_SHEAR * G * A, RHO * A, RHO * I


def _timoshenko_det(w: float) -> float:
    """Clamped-free determinant of the Timoshenko equations at circular frequency ``w``.

    ``kGA (v'' - psi') + rho A w^2 v = 0`` and ``EI psi'' + kGA (v' - psi) + rho I w^2 psi = 0``;
    ``v ~ e^(lambda x)`` gives ``EI kGA mu^2 + w^2 (EI rho A + kGA rho I) mu
    + rho A w^2 (rho I w^2 - kGA) = 0`` in ``mu = lambda^2``; below the cut-off
    ``sqrt(kGA / rho I)`` one root ``alpha^2 > 0`` and one ``-beta^2 < 0``.  Basis
    ``v = cosh, sinh (alpha x), cos, sin (beta x)`` with ``psi = p sinh, p cosh, -q sin,
    q cos`` (``p = alpha + rho A w^2/(kGA alpha)``, ``q = beta - rho A w^2/(kGA beta)``);
    rows: v(0) = 0, psi(0) = 0, EI psi'(L) = 0, kGA (v'(L) - psi(L)) = 0.
    """
    a2 = EI * KGA
    b2 = w**2 * (EI * RA + KGA * RI)
    c2 = RA * w**2 * (RI * w**2 - KGA)
    disc = np.sqrt(b2**2 - 4 * a2 * c2)
    al = np.sqrt((-b2 + disc) / (2 * a2))
    be = np.sqrt((b2 + disc) / (2 * a2))
    p = al + RA * w**2 / (KGA * al)
    q = be - RA * w**2 / (KGA * be)
    ch, sh, c, s = np.cosh(al * L), np.sinh(al * L), np.cos(be * L), np.sin(be * L)
    rows = np.array(
        [
            [1.0, 0.0, 1.0, 0.0],
            [0.0, p, 0.0, q],
            [p * al * ch, p * al * sh, -q * be * c, -q * be * s],
            [al * sh - p * sh, al * ch - p * ch, -be * s + q * s, be * c - q * c],
        ]
    )
    return float(np.linalg.det(rows))


def _exact_timoshenko(n: int) -> np.ndarray:
    ws = np.linspace(1.0, 0.5 * np.sqrt(KGA / RI), 20000)
    d = np.array([_timoshenko_det(w) for w in ws])
    cross = np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))
    return np.array(
        [brentq(_timoshenko_det, ws[i], ws[i + 1], xtol=1e-12, rtol=1e-15) for i in cross[:n]]
    )


def _cantilever(ne: int, shear: bool = True) -> np.ndarray:
    sec = BeamSection(
        "bar",
        E * A,
        E * I,
        E * I * 4.0,  # stiffer about z: the y-plane modes are apart from the z-plane ones
        G * 0.141 * B**4,
        RA,
        RHO * 2 * I,
        4.0 * KGA if shear else None,
        KGA if shear else None,
        RI,
        RI * 4.0,
    )
    nodes = tuple(Node(f"n{i}", np.array([L * i / ne, 0.0, 0.0])) for i in range(ne + 1))
    beams = tuple(
        BeamElement(f"e{i}", (f"n{i}", f"n{i + 1}"), sec, np.array([0.0, 1.0, 0.0]))
        for i in range(ne)
    )
    g = GraphModel("cantilever", nodes, beams=beams, constraints=(Constraint("n0", "123456"),))
    s = build_frame(g, constrained=True)
    m = solve_modes(s)
    # the x-z plane (bending about local y, EI): modes whose kinetic energy is in uz and ry
    energy = np.asarray(m.phi * (s.mass @ m.phi))
    plane = np.array([lab.endswith((":uz", ":ry")) for lab in s.dof_labels])
    return m.omega[energy[plane].sum(axis=0) > 0.99]


def test_timoshenko_cantilever_converges_to_exact_solution():
    exact = _exact_timoshenko(4)
    w20, w40 = _cantilever(20)[:4], _cantilever(40)[:4]
    err20, err40 = w20 / exact - 1, w40 / exact - 1
    # consistent interdependent-interpolation elements converge from above at second order
    # in h for shear-deformable beams (the shear strain is constant per element): halving
    # h divides the error by ~4; 40 elements are within 7e-4 for the 4th mode, 1e-6 for the 1st
    assert np.all(err40 > 0) and np.all(err20 > err40)
    np.testing.assert_allclose(err20 / err40, 4.0, rtol=0.06)
    assert np.all(np.abs(err40) < [2e-6, 5e-5, 3e-4, 1e-3])
    # Richardson's extrapolation of the two meshes removes the h^2 term: the exact values to
    # 1e-5, over 100 times closer than either mesh (what is left is the h^4 term, 5e-6 on
    # the 4th mode): the meshes converge to the exact solution, not near it
    rich = (4 * w40 - w20) / 3
    np.testing.assert_allclose(rich, exact, rtol=1e-5)
    assert np.all(np.abs(rich / exact - 1) < 0.02 * np.abs(err40))
    # without shear flexibility the elements are 0.6 % (1st) to 15 % (4th) high: the test
    # tells a shear-deformable element from an Euler-Bernoulli one
    eb = _cantilever(40, shear=False)[:4]
    assert np.all(eb / exact - 1 > 0.005) and eb[3] / exact[3] - 1 > 0.1


@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_rod_axial_modes_exact_discrete_and_continuum(mass):
    # fixed-free rod of N linear elements: the discrete chain's modes are exactly
    # w^2 = (2 c^2/h^2)(1 - cos kh) (lumped) or (6 c^2/h^2)(1 - cos kh)/(2 + cos kh)
    # (consistent) with kh = (2n - 1) pi / (2N) (1e-10: the dense solver's rounding); they
    # approach the continuum (2n - 1) pi c / (2 L) as O(h^2)
    n_el, length, ea, mpl = 40, 3.0, 2e7, 5.0
    nodes = tuple(Node(f"n{i}", np.array([length * i / n_el, 0.0, 0.0])) for i in range(n_el + 1))
    rods = tuple(RodElement(f"r{i}", (f"n{i}", f"n{i + 1}"), ea, 1e3, mpl) for i in range(n_el))
    # transverse motion is left free of stiffness: pin it with constraints on every node
    cons = tuple(Constraint(f"n{i}", "23456") for i in range(1, n_el + 1)) + (
        Constraint("n0", "123456"),
    )
    g = GraphModel("rod", nodes, rods=rods, constraints=cons, mass_formulation=mass)
    s = build_frame(g, constrained=True)
    w = np.sort(solve_modes(s).omega)[:5]
    c2, h = ea / mpl, length / n_el
    kh = (2 * np.arange(1, 6) - 1) * np.pi / (2 * n_el)
    if mass == "lumped":
        exact_discrete = np.sqrt(2 * c2 / h**2 * (1 - np.cos(kh)))
    else:
        exact_discrete = np.sqrt(6 * c2 / h**2 * (1 - np.cos(kh)) / (2 + np.cos(kh)))
    np.testing.assert_allclose(w, exact_discrete, rtol=1e-10)
    continuum = (2 * np.arange(1, 6) - 1) * np.pi * np.sqrt(c2) / (2 * length)
    # dispersion error (kh)^2/24 at most: 3e-3 for the 5th mode at 40 elements
    np.testing.assert_allclose(w, continuum, rtol=(kh[-1]) ** 2 / 24 * 1.05)


def test_cbush_spring_mass_closed_form():
    # a rigid mass m with inertia J about z, carried by a CBUSH whose point is offset by d
    # along x from the mass's node, grounded: in (y, theta_z) the stiffness is
    # k_y [[1, d], [d, d^2]] + diag(0, k_rz) and the mass diag(m, J); the roots of
    # det(K - w^2 M) = 0 in closed form.  Other directions: w^2 = k_x/m, k_z/m, ...
    m, J, d = 40.0, 3.0, 0.25
    kx, ky, kz, krx, kry, krz = 1e5, 2e5, 3e5, 4e3, 5e3, 6e3
    k6 = np.diag([kx, ky, kz, krx, kry, krz])
    node = Node("m", np.zeros(3))
    bush = Spring("bush", ("m", None), k6, np.zeros((6, 6)), np.eye(3), np.array([d, 0.0, 0.0]))
    mass = ConcentratedMass("mass", "m", m, np.zeros(3), np.diag([J, J, J]))
    s = build_frame(GraphModel("sdof", (node,), springs=(bush,), masses=(mass,)))
    w2 = np.sort(solve_modes(s).omega ** 2)
    # y-theta_z: (m J) w^4 - (m (ky d^2 + krz) + J ky) w^2 + ky krz = 0
    a, b, c = m * J, -(m * (ky * d**2 + krz) + J * ky), ky * krz
    yz = np.sort(
        [(-b - np.sqrt(b * b - 4 * a * c)) / (2 * a), (-b + np.sqrt(b * b - 4 * a * c)) / (2 * a)]
    )
    # z-theta_y likewise (displacement z of the point = w - d theta_y)
    a2, b2, c2 = m * J, -(m * (kz * d**2 + kry) + J * kz), kz * kry
    zy = np.sort(
        [
            (-b2 - np.sqrt(b2 * b2 - 4 * a2 * c2)) / (2 * a2),
            (-b2 + np.sqrt(b2 * b2 - 4 * a2 * c2)) / (2 * a2),
        ]
    )
    expect = np.sort(np.r_[kx / m, krx / J, yz, zy])
    np.testing.assert_allclose(w2, expect, rtol=1e-12)
