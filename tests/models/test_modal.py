"""ModalModel, unit declarations, points files, the own file format, rigid-mode replacement."""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.modal import (
    ModalPoint,
    build_modal_model,
    load_modal_model,
    parse_units,
    read_options,
    replace_rigid_modes,
    rigid_basis_at,
    save_modal_model,
)
from microg.models.toml import load_station
from microg.structure.discretize import discretize

pytestmark = pytest.mark.nastran


@pytest.fixture(scope="module")
def ioc_fe():
    """microg's own FE model of the IOC station, its modes and grid-like node shapes."""
    s = discretize(load_station("ioc"))
    md = solve_modes(s, 30)
    samp = s.samples
    xyz = np.asarray(samp.position)[: len(s.meta["node_names"])]
    n = xyz.shape[0]
    phi = np.concatenate(
        [samp.displacement(md.phi)[:n], md.phi[np.asarray(samp.rot_index)[:n]]], axis=1
    )
    return s, md, xyz, phi


def test_units_in_lbf_s_give_the_slinch():
    u = parse_units("in, lbf, s")
    # reference: exact definitions, lbf = 0.45359237 kg * 9.80665 m/s^2, in = 0.0254 m
    slinch = 0.45359237 * 9.80665 / 0.0254
    assert u.mass_kg == pytest.approx(slinch, rel=1e-12)  # same exact constants: rounding
    assert u.length_m == 0.0254 and u.time_s == 1.0


@pytest.mark.parametrize(
    "text, what",
    [
        ("", "no unit declaration"),
        ("in, lbf", "is not 'LENGTH, FORCE, TIME'"),
        ("in, kg, s", "mass unit cannot be derived"),
        ("in, lbf, s, kg", "inconsistent units"),
    ],
)
def test_bad_unit_declarations_are_errors(text, what):
    with pytest.raises(InputError, match=what):
        parse_units(text)


def test_consistent_fourth_unit_is_accepted():
    assert parse_units("mm, N, s, tonne").mass_kg == pytest.approx(1000.0, rel=1e-12)


def test_points_file(tmp_path):
    f = tmp_path / "points.toml"
    f.write_text(
        'units = "in, lbf, s"\nwtmass = 0.00259\n[points]\nlab = "grid:2001"\n'
        'crew = { grid = "grid:55", kind = "crew", offset = ["0 in", "0 in", "12 in"] }\n'
    )
    opts = read_options(f)
    assert opts.units == "in, lbf, s" and opts.wtmass == 0.00259
    lab, crew = opts.points
    assert (lab.name, lab.grid, lab.kind) == ("lab", 2001, "point")
    assert crew.kind == "crew" and crew.offset_m == pytest.approx([0, 0, 12 * 0.0254])


def test_points_file_bad_kind(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text('[points]\nlab = { grid = "grid:1", kind = "bogus" }\n')
    with pytest.raises(InputError, match="unknown kind"):
        read_options(f)


def _model(ioc_fe, **kw):
    s, md, xyz, phi = ioc_fe
    return build_modal_model(
        name="ioc",
        grid_ids=np.arange(1, xyz.shape[0] + 1) * 10,
        xyz_m=xyz,
        freq_hz_signed=md.freq_hz,
        phi=phi,
        units=parse_units("m, N, s"),
        source="test",
        **kw,
    )


def test_grid_not_in_model_lists_nearest_ids(ioc_fe):
    m = _model(ioc_fe)
    with pytest.raises(InputError, match=r"nearest grids: grid:10, grid:20, grid:30"):
        m.point("grid:7")


def test_own_file_round_trip_is_exact(ioc_fe, tmp_path):
    m = _model(ioc_fe, points=[ModalPoint("lab", 50, np.array([0.1, 0, 0]), "experiment")])
    f = save_modal_model(m, tmp_path / "ioc.npz")
    back = load_modal_model(f)
    # lossless binary format: every array equal bit for bit
    for attr in ("grid_ids", "xyz_m", "omega", "phi", "rigid"):
        assert np.array_equal(getattr(back, attr), getattr(m, attr))
    assert back.points[0].kind == "experiment" and back.points[0].offset_m[0] == 0.1
    assert back.replaced_rigid.count == m.replaced_rigid.count


def test_own_file_truncated_is_one_line_error(ioc_fe, tmp_path):
    f = save_modal_model(_model(ioc_fe), tmp_path / "ioc.npz")
    data = f.read_bytes()
    f.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError) as exc:
        load_modal_model(f)
    assert exc.value.where == str(f) and "\n" not in str(exc.value)


def test_noisy_mixed_rigid_modes_are_replaced_exactly(ioc_fe):
    """A free-free run's rigid modes at noisy frequencies, mixed and contaminated."""
    s, md, xyz, phi = ioc_fe
    rng = np.random.default_rng(1)
    q, _ = np.linalg.qr(rng.standard_normal((6, 6)))  # mix the six rigid modes
    noisy = phi.copy()
    noisy[:, :, :6] = np.einsum("gak,kl->gal", phi[:, :, :6], q)
    noisy[:, :, :6] += 1e-4 * phi[:, :, 6:12]  # elastic contamination (solver noise)
    f = md.freq_hz.copy()
    f[:6] = [-3e-3, 1e-4, 2e-3, 5e-3, 8e-3, 1e-2]
    # exact rigid-body mass of the FE model about the origin (R^T M R): the reference
    r = np.column_stack([s.rigid_body[d] for d in ("x", "y", "z", "rx", "ry", "rz")])
    mrr = r.T @ (s.mass @ r)
    om, ph, rigid, rep, warn = replace_rigid_modes(f, noisy, xyz, rigid_mass=mrr)
    assert rep.count == 6 and rep.max_file_freq_hz == pytest.approx(1e-2)
    assert np.all(om[:6] == 0.0) and rigid[:6].all()
    # replaced modes are exact rigid motions of the grids, mass-orthonormal with M_rr
    R0 = rigid_basis_at(xyz).reshape(-1, 6)
    a, *_ = np.linalg.lstsq(R0, ph[:, :, :6].reshape(-1, 6), rcond=None)
    assert np.linalg.norm(R0 @ a - ph[:, :, :6].reshape(-1, 6)) < 1e-12 * np.linalg.norm(a)
    # A^T M_rr A = I to rounding (exact normalisation from the mass)
    assert np.allclose(a.T @ mrr @ a, np.eye(6), atol=1e-12)
    # and they span the FE model's exact rigid modes: projection of those is complete
    fe_r = phi[:, :, :6].reshape(-1, 6)
    proj = (
        ph[:, :, :6].reshape(-1, 6)
        @ np.linalg.lstsq(ph[:, :, :6].reshape(-1, 6), fe_r, rcond=None)[0]
    )
    assert np.linalg.norm(proj - fe_r) < 1e-10 * np.linalg.norm(fe_r)


def test_rigid_modes_too_close_to_elastic_are_kept_with_a_warning(ioc_fe):
    s, md, xyz, phi = ioc_fe
    f = md.freq_hz.copy()
    f[:6] = 0.008  # below the 0.01 Hz limit, but the first elastic is 0.05 Hz: not 10x apart
    f[6] = 0.05
    _, _, rigid, rep, warn = replace_rigid_modes(f, phi, xyz)
    assert rep is None and not rigid.any()
    assert "not 10x below" in warn[0]


def test_rigid_shapes_above_the_frequency_limit_stay_elastic_with_a_warning(ioc_fe):
    # exact rigid shapes on 200+ grids, but the file says 0.05 Hz: the frequency is the
    # primary evidence, so they are kept as elastic modes and a warning names the limit
    s, md, xyz, phi = ioc_fe
    f = md.freq_hz.copy()
    f[:6] = 0.05
    om, _, rigid, rep, warn = replace_rigid_modes(f, phi, xyz)
    assert rep is None and not rigid.any() and np.all(om[:6] > 0)
    assert "above the 0.01 Hz limit" in warn[0]


def test_rigid_fit_on_two_grids_is_not_trusted_without_a_mass(ioc_fe):
    # the six rigid modes at 1e-5 Hz, but seen on 2 grids only: a rigid-body fit of 12
    # numbers with 6 unknowns proves nothing, so without a mass they stay as given; the
    # exact 6x6 rigid-body mass confirms them.  Reference mass: the FE model's rigid modes
    # are exact rigid motions R C of all 40 grids, mass-normalised, so M_rr = C^-T C^-1
    s, md, xyz, phi = ioc_fe
    f = md.freq_hz.copy()
    f[:6] = 1e-5
    sub = phi[[0, 5]]
    _, _, rigid, rep, warn = replace_rigid_modes(f, sub, xyz[[0, 5]])
    assert rep is None and not rigid.any() and "cannot confirm" in warn[0]
    r_all, p_all = rigid_basis_at(xyz).reshape(-1, 6), phi[:, :, :6].reshape(-1, 6)
    c, *_ = np.linalg.lstsq(r_all, p_all, rcond=None)
    ci = np.linalg.inv(c)
    mrr = ci.T @ ci
    om, _, rigid, rep, _ = replace_rigid_modes(f, sub, xyz[[0, 5]], rigid_mass=mrr)
    assert rep.count == 6 and "confirmed by the rigid-body mass" in rep.rule
    assert np.all(om[:6] == 0.0)
