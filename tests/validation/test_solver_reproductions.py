"""Reproductions of solver defects once found, each by name.

Every model is under tests/data/models/ (``solver_*.toml``) or shipped.  Each test states the
defect as it was found and checks the fixed behaviour against an independent reference.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.modes import DEFAULT_N_MODES, solve_modes
from microg.errors import InputError
from microg.models.station import Beam, Orbit, RigidBody, Station
from microg.models.toml import load_station
from microg.structure.discretize import discretize
from microg.structure.fem import MAX_STIFFNESS_RATIO, build_fem
from microg.structure.ritz import build_ritz

DATA = Path(__file__).resolve().parents[1] / "data" / "models"


def _model(name: str) -> Station:
    return load_station(DATA / f"solver_{name}.toml")


# ------------------------------------------------------------ solver models and chains


def test_fine_mesh_2000_elements_is_not_a_mechanism():
    # `microg modes ioc --method fem --elements 2000` was refused: "9 zero-frequency mode(s)
    # beyond the 6 rigid-body modes".  Reference: the 40-element mesh, converged to ~1e-9 for
    # these modes (Hermite elements converge as h^4: test_beam_exact)
    st = load_station("ioc")
    fine = solve_modes(discretize(st, "fem", n=2000), 16)
    ref = solve_modes(discretize(st, "fem", n=40), 16)
    assert fine.n_rigid == 6 and np.all(fine.omega[:6] == 0.0)
    np.testing.assert_allclose(fine.omega[6:], ref.omega[6:], rtol=1e-7)


def test_fine_mesh_cli_2000_elements_exits_0(capsys):
    from microg.cli import main

    rc = main(["modes", "ioc", "--method", "fem", "--elements", "2000", "--json"])
    out = capsys.readouterr().out
    assert rc == 0
    assert sum(m["rigid"] for m in json.loads(out)["modes"]) == 6


def test_free_beam_10000_elements_matches_the_exact_solution():
    # the assembled K loses the lowest modes of fine meshes (4e-3 at 10,000 elements: eps
    # (L/h)^4); the tree flexibility keeps them.  Reference: the free-free Euler-Bernoulli
    # beam, beta L = 4.730040744862704, 7.853204624095838 (Meirovitch, Fundamentals of
    # Vibrations, Table 8.1); discretisation error (beta h)^4 / 720 ~ 1e-16 at h = L/10^4
    length, ei, mpl = 10.0, 1e5, 0.5
    beam = Beam(
        "b",
        "core",
        np.zeros(3),
        np.array([0, 0, 1.0]),
        length,
        np.array([1.0, 0, 0]),
        ei,
        ei,
        1e6,
        1e8,
        mpl,
    )
    st = Station("free", (RigidBody("core", ()),), (beam,), (), Orbit(6.8e6), length)
    m = solve_modes(build_fem(st, elements_per_beam=10000), 10)
    bending = np.sort(m.omega[~m.rigid])[[0, 2]]  # each bending frequency twice (x and y)
    exact = (np.array([4.730040744862704, 7.853204624095838]) / length) ** 2 * np.sqrt(ei / mpl)
    np.testing.assert_allclose(bending, exact, rtol=1e-9)


def test_single_free_beam_away_from_the_origin_has_six_rigid_modes():
    # "dense solver found 5 rigid modes, expected 6" for the beam at root [8.895, -50, -4.112]
    st = _model("single_beam")
    for s in (build_fem(st), build_ritz(st, None, 2, gravity_gradient=False)):
        m = solve_modes(s)
        assert m.n_rigid == 6 and np.all(m.omega[m.rigid] == 0.0)
        # reference: the same beam at the origin (physics does not depend on the frame)
        b = st.beams[0]
        at0 = Station(
            st.name,
            st.bodies,
            (
                Beam(
                    b.name,
                    b.parent,
                    np.zeros(3),
                    b.direction,
                    b.length,
                    b.orientation,
                    b.ei_y,
                    b.ei_z,
                    b.gj,
                    b.ea,
                    b.mass_per_length,
                ),
            ),
            (),
            st.orbit,
            st.reference_length,
        )
        m0 = solve_modes(
            build_fem(at0)
            if s.method == "fem"
            else build_ritz(at0, None, 2, gravity_gradient=False)
        )
        # frame elements to 1e-9; the assumed-modes rotation coordinates turn about the
        # origin (the report's convention), 50 m away: conditioned by (50 m / 1.2 m)^2
        rtol = 1e-9 if s.method == "fem" else 1e-9 * (1 + (50.8 / b.length) ** 2)
        np.testing.assert_allclose(m.omega[~m.rigid], m0.omega[~m0.rigid], rtol=rtol)


def test_massless_coordinates_are_condensed_and_mapped():
    # beams without ea, a massless beam carrying point masses, collinear body masses: were
    # refused with "... carry no mass".  Reference: the same model with a negligible mass
    # per length on the massless beam (1e-9 kg/m: frequencies move by ~1e-10 of it)
    st = _model("massless")
    arm = next(b for b in st.beams if b.name == "arm")
    light = Beam(
        arm.name,
        arm.parent,
        arm.root,
        arm.direction,
        arm.length,
        arm.orientation,
        arm.ei_y,
        arm.ei_z,
        arm.gj,
        arm.ea,
        1e-9,
        arm.masses,
    )
    st2 = Station(
        st.name,
        st.bodies,
        tuple(light if b.name == "arm" else b for b in st.beams),
        st.points,
        st.orbit,
        st.reference_length,
    )
    for build in (lambda s: build_fem(s), lambda s: build_ritz(s, None, 3, gravity_gradient=False)):
        s = build(st)
        m = solve_modes(s, 20)
        m2 = solve_modes(build(st2), 20)
        assert m.n_rigid == 6
        # the light model has one more (near-massless, ~1e7 rad/s) mode per condensed one
        np.testing.assert_allclose(m.omega[6:], m2.omega[6 : m.n_modes], rtol=1e-7)
        # shapes on every coordinate, massless ones included: M-orthonormal, samples defined
        np.testing.assert_allclose(m.phi.T @ (s.mass @ m.phi), np.eye(m.n_modes), atol=1e-9)
        assert np.all(np.isfinite(m.modal_mass)) and np.all(m.modal_mass > 0)


def test_gj_tiny_behaves_like_gj_zero():
    # gj = "1e-30 lbf*ft^2" failed with SolverError while gj = 0 is a penalty: the rule
    # gj <= 1e-12 max(EI) is numerically zero and treated like 0 (docs/model-format.md)
    for build in (lambda s: build_fem(s), lambda s: build_ritz(s, None, 4, gravity_gradient=False)):
        a = solve_modes(build(_model("gj_tiny")), 20)
        b = solve_modes(build(_model("gj_zero")), 20)
        np.testing.assert_array_equal(a.omega, b.omega)  # the very same structure


def test_stiffness_contrast_beyond_the_limit_is_refused_up_front():
    # EI 1e16 beside 1e-24 N m^2 (a ratio of 1e40) failed with SolverError: now refused with
    # the documented limit, naming the soft beam
    st = _model("ei_contrast")
    for method in ("fem", "ritz"):
        with pytest.raises(
            InputError, match=f"beam 'soft'.*{re.escape(f'{MAX_STIFFNESS_RATIO:g}')}"
        ):
            discretize(st, method)


def test_chain_of_300_beams_is_one_straight_beam():
    # a chain of 300 short beams failed with SolverError.  Reference: the same station with
    # one 150 m beam and the same 0.05 m elements (identical physics and mesh)
    st = _model("chain300")
    m = solve_modes(build_fem(st), 16)
    b0 = st.beams[0]
    one = Station(
        st.name,
        st.bodies,
        (
            Beam(
                "keel",
                "core",
                b0.root,
                b0.direction,
                150.0,
                b0.orientation,
                b0.ei_y,
                b0.ei_z,
                b0.gj,
                b0.ea,
                b0.mass_per_length,
            ),
        ),
        (),
        st.orbit,
        st.reference_length,
    )
    ref = solve_modes(build_fem(one, elements_per_beam=3000), 16)
    assert m.n_rigid == 6
    # the two meshes place their nodes by different sums (0.5 i against s / 3000), so the
    # models differ by rounding; ARPACK's Ritz values of the 10th mode then agree to ~2e-9
    np.testing.assert_allclose(m.omega[6:], ref.omega[6:], rtol=1e-8)
    with pytest.raises(InputError, match="at most 40 beams"):
        build_ritz(st, None, 1)  # the assumed-modes limit, documented in ritz.MAX_RITZ_BEAMS


def test_500_stub_beams_on_one_body():
    # 500 stub beams failed with SolverError.  Reference: a cantilever clamped to a rigid
    # base, beta1 = 1.875104068711961; the heavy core (20 t against 0.4 t of stubs) moves
    # only for the few stub combinations that have a net force, so most of the cluster sits
    # at the clamped value (to its discretisation error, ~1e-6 at 10 elements)
    st = _model("stubs500")
    m = solve_modes(build_fem(st), 24)
    assert m.n_rigid == 6
    b = st.beams[0]
    clamped = (1.875104068711961 / b.length) ** 2 * np.sqrt(b.ei_y / b.mass_per_length)
    stub = m.omega[~m.rigid]
    stub = stub[np.abs(stub / clamped - 1) < 0.01]
    assert stub.size >= 12
    assert np.median(stub) == pytest.approx(clamped, rel=1e-5)


# ------------------------------------------------------------ peaks and unit systems


def test_libration_same_in_si_and_us_files_at_16_functions():
    # `--functions 16` gave librations 1-5 % off and SI/US files 4 % apart (cond(M) 1.3e16,
    # eigh(K, M) directly).  The SI file is the IOC converted to 10 significant digits, so
    # the two stations differ by ~1e-10: every frequency must agree to 1e-9
    us = solve_modes(build_ritz(load_station("ioc"), None, 16, gravity_gradient=True))
    si = solve_modes(build_ritz(_model("ioc_si"), None, 16, gravity_gradient=True))
    assert us.n_rigid == si.n_rigid == 4  # x, y, z, yaw: roll and pitch are restrained
    np.testing.assert_allclose(si.omega, us.omega, rtol=1e-9)
    # independent reference: the rigid station's roll libration w0 sqrt(3 (I_y - I_z) / I_x)
    # with I_x = r^T M r of the model's rotation about the centre of mass; the elastic
    # coupling lowers it by ~ (w_lib / w_el)^2 ~ 5e-6 (Eq. 2.30)
    s = us.structure
    rx = np.asarray(s.rigid_body["rx"])
    ix = float(rx @ s.mass @ rx)
    _, _, inertia = load_station("ioc").mass_properties()
    w0 = load_station("ioc").orbit.omega0
    roll = w0 * np.sqrt(3 * (inertia[1, 1] - inertia[2, 2]) / ix)
    assert us.omega[4] == pytest.approx(roll, rel=2e-5)
    assert us.omega[4] == pytest.approx(1.83475e-3, rel=1e-5)


def test_modal_masses_are_bounded_by_the_station_mass():
    # `microg modes ioc --plane 3d --functions 8` showed a torsion mode of 5.65e26 kg.  With
    # each shape scaled to a largest generalized point motion max(|u|, L_c |theta|) of 1, the
    # modal mass sum m u^2 + J theta^2 is at most m_total + trace(I)/L_c^2 = 3 m_total at the
    # sampled points (L_c^2 = trace(I) / 2 m); sampling between points allows a little more
    s = build_ritz(load_station("ioc"), None, 8, gravity_gradient=True)
    m = solve_modes(s)
    assert np.all(m.modal_mass > 0) and np.max(m.modal_mass) <= 4.0 * s.total_mass
    f = build_fem(load_station("ioc"))
    mf = solve_modes(f, 40)
    assert np.max(mf.modal_mass) <= 4.0 * f.total_mass


def test_effective_masses_of_elastic_modes_are_exact_zeros():
    # elastic modes of a free-free structure are M-orthogonal to every rigid motion: their
    # effective masses are 0, not 1e-35 (the round-off of an exact zero)
    for s in (
        build_ritz(load_station("ioc"), None, 8, gravity_gradient=False),
        build_fem(load_station("ioc")),
    ):
        m = solve_modes(s, 40 if s.is_sparse else None)
        for d, v in m.effective_mass.items():
            assert np.all(v[m.elastic] == 0.0), d
        frac = m.effective_mass_fraction
        if not s.is_sparse:  # all modes: completeness, the fractions sum to 1
            for d, v in frac.items():
                assert v.sum() == pytest.approx(1.0, rel=1e-10), d


def test_unstable_libration_is_reported_not_raised():
    # `microg modes FILE --plane yz` raised "SolverError: negative eigenvalue" for I_y < I_z,
    # and --plane 3d showed omega = 0, "rigid: no".  Reference: the rigid station's growth
    # rate w0 sqrt(3 (I_z - I_y) / I_x), I_x the model's own rotational mass about the centre
    # of mass (the planar model moves points laterally only); elastic coupling ~1e-5
    st = _model("unstable")
    w0 = st.orbit.omega0
    for method, plane in (("ritz", "yz"), ("ritz", "3d"), ("fem", "3d")):
        s = discretize(st, method, plane=plane, gravity_gradient=True)
        m = solve_modes(s, 12 if s.is_sparse else None)
        assert np.count_nonzero(m.unstable) == 1 and not np.any(m.rigid & m.unstable)
        j = int(np.flatnonzero(m.unstable)[0])
        assert m.omega[j] == 0.0 and not m.elastic[j]
        rx = np.asarray(s.rigid_body["rx"])
        iy, iz = np.diag(s.inertia_cm)[1:]
        rate = w0 * np.sqrt(3 * (iz - iy) / float(rx @ s.mass @ rx))
        assert m.growth_rate[j] == pytest.approx(rate, rel=1e-4)
        assert any("I_y" in n and "I_z" in n for n in m.notes)
        d = m.to_dict()["modes"][j]
        assert d["unstable"] is True and d["growth_rate_rad_s"] == pytest.approx(rate, rel=1e-4)


def test_unstable_libration_cli_exits_0(capsys):
    from microg.cli import main

    rc = main(
        [
            "modes",
            str(DATA / "solver_unstable.toml"),
            "--method",
            "ritz",
            "--plane",
            "yz",
            "--gravity-gradient",
            "--json",
        ]
    )
    out, err = capsys.readouterr()
    assert rc == 0, err
    assert any(m.get("unstable") for m in json.loads(out)["modes"])


def test_default_number_of_modes_for_sparse_models():
    m = solve_modes(build_fem(load_station("ioc")))
    assert m.n_modes == DEFAULT_N_MODES
