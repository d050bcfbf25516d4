"""Tests of microg.structure.fem: element kernels, assembly, rigid vectors, maps, samples."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.polynomial import polynomial as npoly

from microg.dynamics.modes import solve_modes
from microg.dynamics.rigid import rigid_basis
from microg.errors import InputError
from microg.models.station import Beam, NamedPoint, Orbit, PointMass, RigidBody, Station
from microg.structure.fem import (
    NodeSamples,
    build_fem,
    frame_mass_local,
    frame_rotation,
    frame_stiffness_local,
    point_mass_matrix,
    rigid_link,
)


def _pm(name, m, p, inertia=None):
    j = np.zeros((3, 3)) if inertia is None else np.asarray(inertia, float)
    return PointMass(name, m, np.asarray(p, float), j)


def small_station(extra_free_body: bool = False, symmetric: bool = False) -> Station:
    """A keel on a core body, a boom on the keel (gj = 0) and a pod riding on the boom."""
    if symmetric:
        core = RigidBody("core", (_pm("a", 2e4, [0, 0, -10], np.diag([1e4, 1e4, 5e3])),))
    else:
        core = RigidBody(
            "core",
            (
                _pm("a", 1e4, [1, 0, -5], [[1e3, 50, 0], [50, 2e3, 0], [0, 0, 3e3]]),
                _pm("b", 2e4, [0, 0.5, -20]),
            ),
        )
    keel = Beam(
        "keel",
        "core",
        np.zeros(3),
        np.array([0, 0, 1.0]),
        90.0,
        np.array([1.0, 0, 0]),
        5e8,
        6e8,
        3e8,
        None,
        100.0,
        (_pm("tip", 3e3, [0, 0, 90], np.diag([10, 20, 30])),),
    )
    boom_y = 30.0 if symmetric else 40.0
    boom = Beam(
        "boom",
        "keel",
        np.array([0, -boom_y / 2 if symmetric else 0, 50.0]),
        np.array([0, 1.0, 0]),
        boom_y,
        np.array([1.0, 0, 0]),
        4e8,
        4e8,
        0.0,
        2e9,
        30.0,
    )
    bodies = [core]
    if not symmetric:
        bodies.append(
            RigidBody(
                "pod", (_pm("c", 500, [2, 20, 50]),), parent="boom", attach=np.array([0, 20, 50.0])
            )
        )
    if extra_free_body:
        bodies.append(RigidBody("loose", (_pm("d", 100, [5, 5, 5], np.eye(3)),)))
    points = (
        NamedPoint("lab", "core", np.array([0, 0, -10.0]), "experiment"),
        NamedPoint("bp", "boom", np.array([0, 10, 50.0])),
    )
    return Station("t", tuple(bodies), (keel, boom), points, Orbit(6.87e6))


# ------------------------------------------------------------------ element kernels


def _hermite(L: float):
    """Cubic Hermite shape functions (v1, v1', v2, v2') as polynomial coefficients in x."""
    return [
        np.array([1, 0, -3 / L**2, 2 / L**3]),
        np.array([0, 1, -2 / L, 1 / L**2]),
        np.array([0, 0, 3 / L**2, -2 / L**3]),
        np.array([0, 0, -1 / L, 1 / L**2]),
    ]


def _integrate(c, L):
    return npoly.polyval(L, npoly.polyint(c))


def test_element_matrices_match_integrated_shape_functions():
    # Independent reference: K = int EI N'' N''^T, M = int rho A N N^T over the element,
    # integrated exactly with numpy polynomials; plane x-y directly, x-z with theta = -w'.
    L, ei_y, ei_z, ea, gj, mu, rj = 2.5, 3.0e6, 7.0e6, 4.0e8, 2.0e6, 12.0, 0.4
    k = frame_stiffness_local(np.array([L]), [ea], [ei_y], [ei_z], [gj])[0]
    m = frame_mass_local(np.array([L]), [mu], [rj])[0]
    N = _hermite(L)
    kb = np.array(
        [
            [_integrate(npoly.polymul(npoly.polyder(a, 2), npoly.polyder(b, 2)), L) for b in N]
            for a in N
        ]
    )
    mb = np.array([[_integrate(npoly.polymul(a, b), L) for b in N] for a in N])
    xy = [1, 5, 7, 11]
    np.testing.assert_allclose(k[np.ix_(xy, xy)], ei_z * kb, rtol=1e-12)
    np.testing.assert_allclose(m[np.ix_(xy, xy)], mu * mb, rtol=1e-12)
    s = np.diag([1, -1, 1, -1])  # theta_y = -dw/dx
    xz = [2, 4, 8, 10]
    np.testing.assert_allclose(k[np.ix_(xz, xz)], ei_y * s @ kb @ s, rtol=1e-12)
    np.testing.assert_allclose(m[np.ix_(xz, xz)], mu * s @ mb @ s, rtol=1e-12)
    lin = [np.array([1, -1 / L]), np.array([0, 1 / L])]  # linear axial / torsion
    kl = np.array(
        [
            [_integrate(npoly.polymul(npoly.polyder(a), npoly.polyder(b)), L) for b in lin]
            for a in lin
        ]
    )
    ml = np.array([[_integrate(npoly.polymul(a, b), L) for b in lin] for a in lin])
    np.testing.assert_allclose(k[np.ix_([0, 6], [0, 6])], ea * kl, rtol=1e-12)
    np.testing.assert_allclose(k[np.ix_([3, 9], [3, 9])], gj * kl, rtol=1e-12)
    np.testing.assert_allclose(m[np.ix_([0, 6], [0, 6])], mu * ml, rtol=1e-12)
    np.testing.assert_allclose(m[np.ix_([3, 9], [3, 9])], rj * ml, rtol=1e-12)


def test_frame_rotation_is_orthonormal_and_right_handed():
    rng = np.random.default_rng(1)
    d = rng.standard_normal((20, 3))
    o = rng.standard_normal((20, 3))
    R = frame_rotation(d, o)
    np.testing.assert_allclose(
        R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape), atol=1e-14
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0, rtol=1e-14)
    np.testing.assert_allclose(R[:, 0], d / np.linalg.norm(d, axis=1)[:, None], rtol=1e-14)


def test_point_mass_matrix_is_rigid_body_kinetic_energy():
    # T = 1/2 m |v + w x d|^2 + 1/2 w^T J w for node velocity v and angular velocity w
    rng = np.random.default_rng(2)
    m, d = 3.7, rng.standard_normal(3)
    a = rng.standard_normal((3, 3))
    J = a @ a.T
    m6 = point_mass_matrix(np.array([m]), J[None], d[None])[0]
    for _ in range(5):
        v, w = rng.standard_normal(3), rng.standard_normal(3)
        q = np.r_[v, w]
        vc = v + np.cross(w, d)
        np.testing.assert_allclose(q @ m6 @ q, m * vc @ vc + w @ J @ w, rtol=1e-12)
    t = rigid_link(d)
    np.testing.assert_allclose(t[:3] @ np.r_[np.zeros(3), [0, 0, 1.0]], np.cross([0, 0, 1.0], d))


# ------------------------------------------------------------------ assembled model


@pytest.fixture(scope="module")
def structure():
    return build_fem(small_station(), elements_per_beam=6)


def test_matrices_symmetric_and_mass_positive_definite(structure):
    m, k = structure.dense()
    assert structure.is_sparse and structure.method == "fem" and structure.plane is None
    np.testing.assert_array_equal(m, m.T)
    np.testing.assert_array_equal(k, k.T)
    sla.cholesky(m)  # raises if M is not positive definite
    assert np.min(np.linalg.eigvalsh(k)) > -1e-12 * np.max(np.abs(k))  # K semi-definite


def test_stiffness_annihilates_rigid_vectors(structure):
    k = structure.stiffness
    for name, r in structure.rigid_body.items():
        # row-wise: each row sums products of size |K||r|; exact rigid leaves only rounding
        ratio = np.abs(k @ r) / np.maximum(abs(k) @ np.abs(r), 1e-300)
        assert ratio.max() < 1e-13, name


def test_mass_properties_from_mass_matrix(structure):
    st = small_station()
    m = structure.mass
    rb = structure.rigid_body
    total, cm, inertia = st.mass_properties()
    # r_x^T M r_x = total mass (Station.mass_properties is the independent reference)
    for d in "xyz":
        np.testing.assert_allclose(rb[d] @ (m @ rb[d]), total, rtol=1e-12)
    # rigid rotations are about the centre of mass: no first moment, r_t^T M r_rot = 0
    for dt in "xyz":
        for dr in ("rx", "ry", "rz"):
            np.testing.assert_allclose(rb[dt] @ (m @ rb[dr]), 0.0, atol=1e-9 * total * 90)
    # inertia about the centre of mass, directly
    rot = np.column_stack([rb[d] for d in ("rx", "ry", "rz")])
    i_cm_fem = rot.T @ (m @ rot)
    # the FE adds the beams' polar mass moments rho J L d d^T, slender rods have none
    polar = np.zeros((3, 3))
    for bm in st.beams:
        rho_j = (
            bm.mass_per_length * (bm.ei_y + bm.ei_z) / bm.ea
            if bm.ea is not None
            else bm.mass_per_length * (0.02 * bm.length) ** 2
        )
        polar += rho_j * bm.length * np.outer(bm.direction, bm.direction)
    np.testing.assert_allclose(i_cm_fem, inertia + polar, rtol=1e-10, atol=1e-9 * inertia.max())
    np.testing.assert_allclose(structure.inertia_cm, inertia + polar, rtol=1e-12)
    np.testing.assert_allclose(structure.total_mass, total, rtol=1e-12)
    np.testing.assert_allclose(structure.center_of_mass, cm, rtol=1e-12)


def test_effective_masses_sum_to_total_mass_with_all_modes(structure):
    modes = solve_modes(structure, n_modes=structure.n_dof)
    assert modes.n_rigid == 6 and np.all(modes.omega[modes.rigid] == 0.0)
    phi = modes.phi
    np.testing.assert_allclose(phi.T @ (structure.mass @ phi), np.eye(phi.shape[1]), atol=1e-9)
    for d in "xyz":  # completeness: sum_j L_jd^2 = r_d^T M r_d
        np.testing.assert_allclose(modes.effective_mass[d].sum(), structure.total_mass, rtol=1e-9)
    assert np.all(modes.modal_mass > 0)


def test_named_points_and_samples_follow_rigid_motion(structure):
    rb = structure.rigid_body
    samples = structure.samples
    assert isinstance(samples, NodeSamples) and len(samples) == len(samples.labels)
    for j, d in enumerate(("rx", "ry", "rz")):
        axis = np.eye(3)[j]
        cm = structure.center_of_mass  # rigid rotations turn about the centre of mass
        for p in structure.points.values():
            np.testing.assert_allclose(
                p.translation @ rb[d], np.cross(axis, p.position - cm), atol=1e-12
            )
            np.testing.assert_allclose(p.rotation @ rb[d], axis, atol=1e-12)
        np.testing.assert_allclose(
            samples.displacement(rb[d]), np.cross(axis, samples.position - cm), atol=1e-12
        )
    both = np.column_stack([rb["x"], rb["rz"]])
    u = samples.displacement(both)
    assert u.shape == (len(samples), 3, 2)
    np.testing.assert_allclose(u[:, :, 1], samples.displacement(rb["rz"]), atol=1e-14)
    # body masses are sampled too, at their own positions
    assert "core/b" in samples.labels
    np.testing.assert_allclose(samples.position[samples.labels.index("core/b")], [0, 0.5, -20])


def test_nodes_at_masses_joints_and_points(structure):
    names = structure.meta["node_names"]
    pos = structure.meta["node_positions"]
    for target in ([0, 0, 50.0], [0, 0, 90.0], [0, 20, 50.0], [0, 10, 50.0]):
        assert np.min(np.linalg.norm(pos - target, axis=1)) < 1e-12, target
    assert names.count("core") == 1
    assert structure.dof_labels[:6] == tuple(
        f"core:{c}" for c in ("ux", "uy", "uz", "rx", "ry", "rz")
    )
    assert structure.meta["n_elements"] >= 12


def test_discretisation_options():
    st = small_station()
    coarse = build_fem(st, elements_per_beam=2)
    fine = build_fem(st, max_element_length=5.0)
    both = build_fem(st, elements_per_beam=2, max_element_length=5.0)
    assert coarse.n_dof < fine.n_dof == both.n_dof
    with pytest.raises(InputError, match="elements_per_beam"):
        build_fem(st, elements_per_beam=0)
    with pytest.raises(InputError, match="max_element_length"):
        build_fem(st, max_element_length=-1.0)


def test_disconnected_body_is_refused_as_a_named_mechanism():
    # a second parentless body is joined to nothing: six free motions, refused up front
    with pytest.raises(InputError, match="body 'loose'.*mechanism"):
        build_fem(small_station(extra_free_body=True), elements_per_beam=4)


def test_gravity_gradient_librations_eq_2_30():
    st = small_station(symmetric=True)  # principal axes along x, y, z
    s = build_fem(st, elements_per_beam=8, gravity_gradient=True)
    ix, iy, iz = np.diag(s.inertia_cm)
    assert np.allclose(s.inertia_cm, np.diag([ix, iy, iz]), atol=1e-9 * ix)
    cand = np.column_stack(list(s.rigid_body.values()))
    assert rigid_basis(s.mass, s.stiffness, cand).shape[1] == 4  # x, y, z, yaw
    modes = solve_modes(s, n_modes=12)
    assert modes.n_rigid == 4
    w0 = st.orbit.omega0
    expect = np.sort([w0 * np.sqrt(3 * (iy - iz) / ix), w0 * np.sqrt(3 * (ix - iz) / iy)])
    # Eq. 2.30; the elastic coupling shifts them by ~ w_lib^2 / w_el^2 ~ 1e-7, and the
    # round-off of the assembled K in the rigid span is ~1e-13 of |K| |r| (~1e-5 here)
    np.testing.assert_allclose(modes.omega[4:6], expect, rtol=1e-4)
    plain = solve_modes(build_fem(st, elements_per_beam=8), n_modes=12)
    # elastic modes barely change (first-order shift k phi_theta^2 / w^2 ~ 1e-6)
    np.testing.assert_allclose(modes.omega[6:], plain.omega[6:], rtol=1e-5)


def test_ioc_model_has_six_rigid_modes_and_librations():
    modelfile = pytest.importorskip("microg.models.toml")
    st = modelfile.load_station("ioc")
    s = build_fem(st, elements_per_beam=10)
    modes = solve_modes(s, n_modes=12)
    assert modes.n_rigid == 6 and np.all(modes.omega[:6] == 0.0)
    assert set(s.points) == {p.name for p in st.points}
    np.testing.assert_allclose(s.total_mass, st.mass_properties()[0], rtol=1e-12)
    g = solve_modes(build_fem(st, elements_per_beam=10, gravity_gradient=True), n_modes=12)
    assert g.n_rigid == 4  # gravity gradient restrains roll and pitch
    ix, iy, iz = np.diag(g.structure.inertia_cm)
    w0 = st.orbit.omega0
    expect = np.sort([w0 * np.sqrt(3 * (iy - iz) / ix), w0 * np.sqrt(3 * (ix - iz) / iy)])
    # Eq. 2.30 to the FE's round-off floor in the rigid span (~1e-9 of a stiffness scale
    # whose libration part is ~3e-6: measured 7e-4 in omega)
    np.testing.assert_allclose(g.omega[4:6], expect, rtol=3e-3)
