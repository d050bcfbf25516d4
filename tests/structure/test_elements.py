"""Tests of microg.structure.elements: the frame element kernels.

References: textbook closed forms (Timoshenko cantilever under end load, pinned-fixed beam),
numerical integration of the Friedman-Kosmatka shape functions, NASTRAN's translational
lumping, and hand averages of the RBE3 fit.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from microg.errors import InputError
from microg.structure.elements import (
    beam_mass_consistent_local,
    beam_mass_lumped_local,
    beam_stiffness_local,
    bush_matrix,
    frame_mass_local,
    frame_stiffness_local,
    interpolation_matrix,
    release_ends,
    rigid_link,
    rod_mass_local,
    shear_parameter,
)

RNG = np.random.default_rng(7)


def test_timoshenko_stiffness_reduces_to_euler_bernoulli():
    L = np.array([0.7, 2.0])
    args = (L, [1e8, 2e8], [3e5, 1e5], [4e5, 2e5], [1e5, 3e5])
    # phi = 0 is the fem kernel exactly (one definition of the Euler-Bernoulli element)
    np.testing.assert_array_equal(beam_stiffness_local(*args), frame_stiffness_local(*args))


def test_timoshenko_cantilever_end_load_is_exact():
    # One element, clamped at a: tip deflection P L^3/(3 EI) + P L/(k G A) and tip rotation
    # P L^2/(2 EI) are the exact Timoshenko static solution (Przemieniecki sec. 5.6), which
    # the shear-deformable element reproduces for any phi; 1e-12 is rounding.
    L, ei, ks = 1.3, 2e5, 7e5
    phi = shear_parameter(np.array([L]), np.array([ei]), np.array([ks]))
    k = beam_stiffness_local(np.array([L]), [1e8], [ei], [ei], [1e5], phi, phi)[0]
    kb = k[6:, 6:]
    for plane, (iv, it, sgn) in {"v": (1, 5, 1.0), "w": (2, 4, -1.0)}.items():
        load = np.zeros(6)
        load[iv] = 1.0
        u = np.linalg.solve(kb, load)
        assert u[iv] == pytest.approx(L**3 / (3 * ei) + L / ks, rel=1e-12), plane
        assert u[it] == pytest.approx(sgn * L**2 / (2 * ei), rel=1e-12), plane


def test_consistent_mass_is_fem_kernel_without_shear_and_rotary_inertia():
    L = np.array([0.5, 1.5])
    m = np.array([3.0, 7.0])
    j = np.array([0.1, 0.2])
    np.testing.assert_allclose(
        beam_mass_consistent_local(L, m, j), frame_mass_local(L, m, j), rtol=1e-14, atol=1e-15
    )


def test_consistent_mass_integrates_friedman_kosmatka_shape_functions():
    # M = int (rho A N_v^T N_v + rho I N_t^T N_t) dx with the interdependent shape functions
    # of Friedman & Kosmatka (1993), integrated by 8-point Gauss-Legendre (exact for these
    # degree-6 polynomials): agreement to rounding (1e-13).
    L, phi, m, r = 1.7, 0.37, 2.3, 0.11
    xg, wg = np.polynomial.legendre.leggauss(8)
    xi = 0.5 * (xg + 1)
    w = 0.5 * wg * L
    f = 1 / (1 + phi)
    Nv = np.stack(
        [
            f * (2 * xi**3 - 3 * xi**2 - phi * xi + 1 + phi),
            f * L * (xi**3 - (2 + phi / 2) * xi**2 + (1 + phi / 2) * xi),
            f * (-2 * xi**3 + 3 * xi**2 + phi * xi),
            f * L * (xi**3 - (1 - phi / 2) * xi**2 - (phi / 2) * xi),
        ]
    )
    Nt = np.stack(
        [
            6 * f / L * (xi**2 - xi),
            f * (3 * xi**2 - (4 + phi) * xi + 1 + phi),
            -6 * f / L * (xi**2 - xi),
            f * (3 * xi**2 - (2 - phi) * xi),
        ]
    )
    ref = m * (Nv * w) @ Nv.T + r * (Nt * w) @ Nt.T
    full = beam_mass_consistent_local(
        np.array([L]), [m], [0.0], np.array([phi]), np.array([phi]), [r], [r]
    )[0]
    idx_v = [1, 5, 7, 11]
    np.testing.assert_allclose(full[np.ix_(idx_v, idx_v)], ref, rtol=1e-13, atol=1e-15)
    # x-z plane: theta_y = -dw/dx flips the signs of the rotation rows and columns
    s = np.diag([1.0, -1.0, 1.0, -1.0])
    idx_w = [2, 4, 8, 10]
    np.testing.assert_allclose(full[np.ix_(idx_w, idx_w)], s @ ref @ s, rtol=1e-13, atol=1e-15)


def test_lumped_mass_is_nastran_translational_lumping():
    L = np.array([2.0, 2.0])
    m = beam_mass_lumped_local(L, [3.0, 3.0], [0.5, 0.5], np.array([True, False]))
    # half of m' L = 3 kg on every end translation, nothing on bending rotations; the CBEAM
    # (True) lumps half of rho J L = 0.5 kg m^2 on the axial rotations, the CBAR does not
    for e in range(2):
        assert np.count_nonzero(m[e] - np.diag(np.diag(m[e]))) == 0
        np.testing.assert_array_equal(np.diag(m[e])[[0, 1, 2, 6, 7, 8]], 3.0)
        np.testing.assert_array_equal(np.diag(m[e])[[4, 5, 10, 11]], 0.0)
    assert m[0, 3, 3] == m[0, 9, 9] == 0.5
    assert m[1, 3, 3] == m[1, 9, 9] == 0.0


def test_rod_mass_forms_conserve_mass():
    L = np.array([1.5])
    for lumped in (True, False):
        m = rod_mass_local(L, [2.0], lumped)[0]
        # a unit translation in each direction carries the rod's whole mass, 3 kg
        for d in range(3):
            u = np.zeros(12)
            u[[d, d + 6]] = 1.0
            assert u @ m @ u == pytest.approx(3.0, rel=1e-15)


def test_pin_release_gives_pinned_fixed_beam_stiffness():
    # Released rotation about z at end b: the lateral stiffness at b with end a clamped is
    # the propped-cantilever value 3 EI / L^3 (Przemieniecki Table 5.1), exact to rounding.
    L, ei = 2.0, 4e5
    k = beam_stiffness_local(np.array([L]), [1e8], [ei], [ei], [1e5])
    m = frame_mass_local(np.array([L]), [1.0], [0.0])
    rel = np.zeros((1, 12), bool)
    rel[0, 11] = True  # theta_z at end b
    kr, mr = release_ends(k, m, rel)
    assert np.all(kr[0, 11] == 0) and np.all(mr[0, :, 11] == 0)
    assert kr[0, 7, 7] == pytest.approx(3 * ei / L**3, rel=1e-12)
    np.testing.assert_allclose(kr[0], kr[0].T, atol=1e-9)


def test_bush_matrix_is_free_of_rigid_body_forces_and_diagonal_at_its_point():
    k6 = np.diag([1e5, 2e5, 3e5, 10.0, 20.0, 30.0])
    axes = sla.qr(RNG.standard_normal((3, 3)))[0]
    axes *= np.sign(np.linalg.det(axes))
    a, b = np.array([0.0, 0, 0]), np.array([1.0, 0.5, 0.2])
    loc = np.array([0.3, 0.9, -0.4])
    K = bush_matrix(k6, axes, a, b, loc)
    # rigid motion: every node moves as u = t + r x p: the spring force must vanish (1e-9 of
    # the largest term times the motion: rounding)
    for col in range(6):
        ua = np.zeros(6)
        ua[col] = 1.0
        ra = rigid_link(a) @ ua
        rb = rigid_link(b) @ ua
        assert np.abs(K @ np.concatenate([ra, rb])).max() <= 1e-10 * np.abs(K).max()
    # coincident nodes at the spring point, basic axes: K = [[k, -k], [-k, k]] exactly
    Kc = bush_matrix(k6, np.eye(3), a, a, a)
    np.testing.assert_allclose(Kc, np.block([[k6, -k6], [-k6, k6]]), rtol=1e-15)


def test_interpolation_matches_hand_average_and_moves_rigidly():
    # four sources at (+-1, 0, 0), (0, +-1, 0), equal weights, reference at the origin: by
    # hand, the translation is the mean, theta_z = sum(x u_y - y u_x) / sum(x^2 + y^2),
    # theta_x = sum(y u_z) / sum(y^2), theta_y = -sum(x u_z) / sum(x^2); exact to rounding
    pos = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, -1.0, 0]])
    u = RNG.standard_normal((4, 3))
    dirs = np.tile(np.eye(3), (4, 1))
    W = interpolation_matrix(np.zeros(3), np.repeat(pos, 3, axis=0), dirs, np.ones(12))
    q = W @ u.ravel()
    np.testing.assert_allclose(q[:3], u.mean(axis=0), atol=1e-14)
    x, y = pos[:, 0], pos[:, 1]
    assert q[5] == pytest.approx(np.sum(x * u[:, 1] - y * u[:, 0]) / np.sum(x**2 + y**2), abs=1e-14)
    assert q[3] == pytest.approx(np.sum(y * u[:, 2]) / np.sum(y**2), abs=1e-14)
    assert q[4] == pytest.approx(-np.sum(x * u[:, 2]) / np.sum(x**2), abs=1e-14)
    # a rigid motion of irregular, unequally weighted sources is returned exactly
    pos2 = RNG.standard_normal((5, 3))
    ref = np.array([0.2, -0.1, 0.3])
    t, r = RNG.standard_normal(3), RNG.standard_normal(3)
    us = t + np.cross(r, pos2 - ref)
    W2 = interpolation_matrix(
        ref, np.repeat(pos2, 3, axis=0), np.tile(np.eye(3), (5, 1)), np.arange(1.0, 16.0)
    )
    np.testing.assert_allclose(W2 @ us.ravel(), np.concatenate([t, r]), atol=1e-12)
    with pytest.raises(InputError, match="do not determine"):
        interpolation_matrix(ref, np.repeat(pos2[:1], 3, axis=0), np.eye(3), np.ones(3))
