"""ModalModel -> Structure in modal coordinates: exact rigid vectors, offset points, lazy maps."""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.forces import ForceHistory
from microg.dynamics.modes import solve_modes
from microg.dynamics.response import generalized_force_vector, response_at_points
from microg.errors import InputError
from microg.models.modal import ModalPoint, build_modal_model, parse_units
from microg.models.toml import load_station
from microg.structure.discretize import discretize
from microg.structure.modal import modal_structure

pytestmark = pytest.mark.nastran


@pytest.fixture(scope="module")
def fe():
    s = discretize(load_station("ioc"))
    md = solve_modes(s, 30)
    n = len(s.meta["node_names"])
    samp = s.samples
    phi = np.concatenate(
        [samp.displacement(md.phi)[:n], md.phi[np.asarray(samp.rot_index)[:n]]], axis=1
    )
    model = build_modal_model(
        name="ioc",
        grid_ids=np.arange(1, n + 1),
        xyz_m=np.asarray(samp.position)[:n],
        freq_hz_signed=md.freq_hz,
        phi=phi,
        units=parse_units("m, N, s"),
        source="ioc-fe",
    )
    return s, md, model


def test_matrices_and_exact_rigid_modes(fe):
    s, md, model = fe
    st = discretize(model)  # the hook: modal_structure(ModalModel)
    assert st.method == "modal"
    assert np.array_equal(st.mass, np.eye(30))
    assert np.array_equal(np.diag(st.stiffness), model.omega**2)
    # K annihilates every rigid-body vector exactly (zeros on the rigid diagonal)
    for d, v in st.rigid_body.items():
        assert np.all(st.stiffness @ v == 0.0), d
    m2 = solve_modes(st)
    assert m2.n_rigid == 6 and np.all(m2.omega[:6] == 0.0)
    # elastic frequencies equal the FE model's (diagonal K: rounding only)
    assert np.allclose(m2.omega[6:], md.omega[6:30], rtol=1e-13)


def test_mass_properties_equal_the_fe_model(fe):
    s, _, model = fe
    st = modal_structure(model)
    # reference: the FE model's own mass properties (independent assembly)
    assert st.total_mass == pytest.approx(s.total_mass, rel=1e-10)
    assert np.allclose(st.center_of_mass, s.center_of_mass, atol=1e-9 * 100)
    assert np.allclose(
        st.inertia_cm, s.inertia_cm, rtol=1e-9, atol=1e-9 * np.abs(s.inertia_cm).max()
    )


def test_offset_point_includes_rotation(fe):
    """A point at an offset from a grid moves as u + theta x d: same map as the FE rigid link."""
    s, md, model = fe
    lab = s.point("lab")  # FE point, rigidly offset from its node
    node = int(np.argmin(np.linalg.norm(model.xyz_m - lab.position, axis=1)))
    nodes = np.flatnonzero(np.abs(s.points["lab"].rotation).sum(axis=0))[:3] // 6
    node = int(nodes[0])
    off = lab.position - model.xyz_m[node]
    m = model.with_points([ModalPoint("lab", int(model.grid_ids[node]), off)])
    st = modal_structure(m)
    # reference: FE translation map of the point applied to the FE modes
    assert np.allclose(
        st.point("lab").translation,
        lab.translation @ md.phi,
        atol=1e-12 * np.abs(lab.translation @ md.phi).max(),
    )


def test_response_equals_fe_response(fe):
    s, md, model = fe
    g_crew = 1 + int(np.flatnonzero(np.abs(s.point("crew").translation).sum(axis=0))[0] // 6)
    g_obs = 1 + int(np.flatnonzero(np.abs(s.point("keel-tip").translation).sum(axis=0))[0] // 6)
    st = modal_structure(model, [f"grid:{g_crew}", f"grid:{g_obs}"], samples=False)
    m2 = solve_modes(st)
    f = ForceHistory(np.array([0.0, 0.5, 1.0, 1.5]), np.array([0.0, 100.0, 100.0, 0.0]))
    t = np.arange(0.0, 20.0, 0.01)

    def resp(struct, modes, at, obs):
        b = generalized_force_vector(struct.point(at).translation, np.array([1.0, 0.0, 0.0]))
        z = np.where(modes.rigid, 0.0, 0.005)
        maps = {"o": struct.point(obs).translation}
        return response_at_points(modes.omega, z, modes.phi, maps, f, b, t)["o"].acceleration

    # FE reference at the same nodes: node translation maps (exact nodal DOFs)
    n = s.n_dof

    def node_map(g):
        tm = np.zeros((3, n))
        tm[:, 6 * (g - 1) : 6 * (g - 1) + 3] = np.eye(3)
        return tm

    b = generalized_force_vector(node_map(g_crew), np.array([1.0, 0.0, 0.0]))
    z = np.where(md.rigid, 0.0, 0.005)
    ref = response_at_points(md.omega, z, md.phi, {"o": node_map(g_obs)}, f, b, t)["o"].acceleration
    got = resp(st, m2, f"grid:{g_crew}", f"grid:{g_obs}")
    # same 30 modes, same exact integrator: rounding of the modal transformation only
    assert np.max(np.abs(got - ref)) <= 1e-10 * np.max(np.abs(ref))


def test_maps_only_for_points_used_and_unknown_grid(fe):
    _, _, model = fe
    st = modal_structure(model, ["grid:3"], samples=False)
    assert list(st.points) == ["grid:3"] and st.samples is None
    assert st.point("grid:5").translation.shape == (3, 30)  # on demand
    with pytest.raises(InputError, match="nearest grids"):
        st.point("grid:100000")


def test_samples_are_views_and_products_equal_the_dense_ones(fe):
    _, _, model = fe
    st = modal_structure(model)
    smp = st.samples
    assert np.shares_memory(smp.phi_t, model.phi) and smp.position is model.xyz_m
    assert smp.labels[:2] == ("grid:1", "grid:2") and len(smp) == model.n_grids
    assert set(smp.component) == {"grids"}
    m2 = solve_modes(st)
    dense = np.einsum("gam,mk->gak", model.phi[:, :3, :], m2.phi)  # reference: dense product
    got = smp.displacement(m2.phi)
    single = np.count_nonzero(m2.phi, axis=0) == 1
    assert single.sum() == 30 - 6  # elastic modes: one entry each; the rigid block mixes
    # single-entry columns: the same one product per value (bit for bit); the rest: the
    # same sums over the nonzero rows, in another order (rounding)
    np.testing.assert_array_equal(got[:, :, single], dense[:, :, single])
    np.testing.assert_allclose(got, dense, rtol=0, atol=1e-13 * np.abs(dense).max())
    # a general (dense) coordinate matrix and a vector take the general path
    rng = np.random.default_rng(1)
    q = rng.standard_normal((30, 4))
    np.testing.assert_allclose(
        smp.displacement(q), np.einsum("gam,mk->gak", model.phi[:, :3, :], q), rtol=1e-12
    )
    np.testing.assert_allclose(smp.displacement(q[:, 0]), model.phi[:, :3, :] @ q[:, 0])
    # the peak per mode without forming the displacements: exactly the dense maximum
    np.testing.assert_array_equal(
        smp.peak_translation(m2.phi)[single], np.max(np.abs(dense), axis=(0, 1))[single]
    )
    np.testing.assert_allclose(
        smp.peak_translation(m2.phi), np.max(np.abs(dense), axis=(0, 1)), rtol=1e-13
    )
    # rotations likewise, against the dense rotational motion (reference: einsum)
    rot = np.einsum("gam,mk->gak", model.phi[:, 3:6, :], m2.phi)
    np.testing.assert_allclose(
        smp.peak_rotation(m2.phi), np.max(np.abs(rot), axis=(0, 1)), rtol=1e-13
    )
    # a general coordinate matrix (every column mixing, rows not consecutive) after it
    q2 = np.zeros((30, 3))
    q2[[2, 7, 11], :] = rng.standard_normal((3, 3))
    np.testing.assert_allclose(
        smp.peak_rotation(q2),
        np.max(np.abs(np.einsum("gam,mk->gak", model.phi[:, 3:6, :], q2)), axis=(0, 1)),
        rtol=1e-13,
    )


def _random_model(g: int, m: int, seed: int = 0):
    """Identity-mass stand-in: exact rigid modes (QR of the rigid motions) + random others."""
    from microg.models.modal import rigid_basis_at

    rng = np.random.default_rng(seed)
    xyz = rng.uniform(-20, 20, (g, 3))
    q, _ = np.linalg.qr(rigid_basis_at(xyz).reshape(-1, 6))
    el = rng.standard_normal((6 * g, m - 6))
    el -= q @ (q.T @ el)
    phi = np.concatenate([q, el / np.linalg.norm(el, axis=0)], axis=1).reshape(g, 6, m)
    f = np.r_[np.zeros(6), np.sort(rng.uniform(0.1, 10.0, m - 6))]
    return build_modal_model(
        name="random",
        grid_ids=np.arange(1, g + 1),
        xyz_m=xyz,
        freq_hz_signed=f,
        phi=phi,
        units=parse_units("m, N, s"),
        source="random",
        replace_rigid=False,
    )


def test_rigid_coefficients_from_a_few_grids_equal_the_full_fit():
    from dataclasses import replace

    from microg.errors import ModelError
    from microg.models.modal import rigid_basis_at
    from microg.structure.modal import RIGID_FIT_GRIDS, _fit_grids, rigid_coefficients

    model = _random_model(2000, 12)
    assert model.n_grids > RIGID_FIT_GRIDS and np.count_nonzero(model.rigid) == 6
    a = rigid_coefficients(model)
    # reference: least squares over every grid
    r0 = rigid_basis_at(model.xyz_m).reshape(-1, 6)
    ref, *_ = np.linalg.lstsq(r0, model.phi[:, :, :6].reshape(-1, 6), rcond=None)
    # the rigid shapes are exact rigid motions to rounding: both fits give A to rounding
    np.testing.assert_allclose(a, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    # the fit grids are a few; the check is at every grid: spoil one grid outside them
    used = set(_fit_grids(model.xyz_m).tolist())
    k = next(i for i in range(model.n_grids) if i not in used)
    phi = model.phi.copy()
    phi[k, 0, 2] += 1e-3 * np.abs(phi[:, :, 2]).max()  # residual ~1e-5 > 1e-8
    with pytest.raises(ModelError, match="not rigid-body motions"):
        rigid_coefficients(replace(model, phi=phi))
    # mass properties from A: identity mass per DOF, 2000 grids -> 2000 kg
    st = modal_structure(model, ["grid:1"], samples=False)
    assert st.total_mass == pytest.approx(2000.0, rel=1e-12)
    assert np.allclose(st.center_of_mass, model.xyz_m.mean(axis=0), atol=1e-9 * 20)
