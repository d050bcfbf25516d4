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
