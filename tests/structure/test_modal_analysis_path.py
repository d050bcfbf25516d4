"""The lean path of a large modal model through the main job equals the general computation.

Each fast path is checked against the computation it replaces, formed in full here: the
shape peaks in blocks of grids against ``max |phi_t|`` over the whole array, the modal mass
from the samples' peaks against ``1/p^2`` of the dense displacements, and the per-mode
contributions of :func:`microg.analyze` (shared modal peaks and band RMS scaled by the map
coefficients) against each mode's own series at the point, its norm and its periodogram.
"""

from __future__ import annotations

import numpy as np

import microg
from microg.dynamics.modes import _modal_mass_unit_peak, characteristic_length, solve_modes
from microg.environment.metrics import acceleration_psd, band_rms
from microg.environment.requirements import BandTable
from microg.models.modal import build_modal_model, parse_units, rigid_basis_at
from microg.structure.modal import _PEAK_BLOCK, modal_structure
from microg.units import G0


def _model(g: int, m: int, seed: int = 0):
    """Identity-mass stand-in: exact rigid modes (QR of the rigid motions) + orthogonal others."""
    rng = np.random.default_rng(seed)
    xyz = rng.uniform(-20, 20, (g, 3))
    q, _ = np.linalg.qr(rigid_basis_at(xyz).reshape(-1, 6))
    el = rng.standard_normal((6 * g, m - 6))
    el -= q @ (q.T @ el)
    phi = np.concatenate([q, el / np.linalg.norm(el, axis=0)], axis=1).reshape(g, 6, m)
    f = np.r_[np.zeros(6), np.sort(rng.uniform(0.1, 5.0, m - 6))]
    return build_modal_model(
        name="lean",
        grid_ids=np.arange(1, g + 1),
        xyz_m=xyz,
        freq_hz_signed=f,
        phi=phi,
        units=parse_units("m, N, s"),
        source="lean",
        replace_rigid=False,
    )


def test_shape_peaks_in_blocks_equal_the_whole_array_maximum():
    model = _model(2 * _PEAK_BLOCK + 17, 12)  # three blocks, the last one short
    smp = modal_structure(model).samples
    # reference: the maximum over the whole (g, 3, m) array at once; the maximum of the
    # block maxima is the same element (max is exact), so bit for bit
    ref = np.max(np.abs(model.phi[:, :3, :]), axis=(0, 1))
    np.testing.assert_array_equal(smp.shape_peaks(), ref)
    ref_rot = np.max(np.abs(model.phi[:, 3:6, :]), axis=(0, 1))
    np.testing.assert_array_equal(smp.shape_peaks("rotation"), ref_rot)


def test_modal_mass_from_sample_peaks_equals_the_dense_displacements():
    model = _model(3000, 20)
    st = modal_structure(model, ["grid:7"])
    modes = solve_modes(st)
    # reference: 1/p^2 with p the largest of the points' translations and rotations (times
    # L_c) and every grid's translation and rotation (times L_c: the Modes docstring), all
    # formed densely (einsum over all grids)
    lc = characteristic_length(st)
    p = st.point("grid:7")
    dense = np.einsum("gam,mk->gak", model.phi[:, :3, :], modes.phi)
    dense_rot = np.einsum("gam,mk->gak", model.phi[:, 3:6, :], modes.phi)
    peak = np.max(
        np.stack(
            [
                np.max(np.abs(p.translation @ modes.phi), axis=0),
                lc * np.max(np.abs(p.rotation @ modes.phi), axis=0),
                np.max(np.abs(dense), axis=(0, 1)),
                lc * np.max(np.abs(dense_rot), axis=(0, 1)),
            ]
        ),
        axis=0,
    )
    # single-entry (elastic) columns: the same scaled maximum; the rigid block's columns sum
    # six products in another order: rounding, 1e-13 relative on 1/p^2
    np.testing.assert_allclose(modes.modal_mass, 1.0 / peak**2, rtol=1e-13, atol=0)
    np.testing.assert_allclose(_modal_mass_unit_peak(st, modes.phi), modes.modal_mass, rtol=0)


def test_contributions_equal_each_modes_own_series():
    from microg.analysis.transient import modal_loads
    from microg.dynamics.response import modal_pwl_response

    model = _model(400, 16, seed=3)
    obs = ["grid:50", "grid:333"]
    res = microg.analyze(
        model,
        force="crew-pushoff",
        at="grid:1",
        observe=obs,
        duration=60.0,
        dt=0.01,
        isolation=False,
    )
    st, opts = res.structure, res.options
    idx = np.flatnonzero(res.used)
    m = res.modes.subset(idx)
    zeta = np.where(m.rigid, 0.0, opts.zeta)
    loads, _ = modal_loads(st, m, opts)
    t = res.timepts
    # reference: the full modal response of each load (modal_pwl_response), superposed
    eta = np.zeros((m.n_modes, t.size))
    acc = np.zeros_like(eta)
    for ld in loads:
        r = modal_pwl_response(
            m.omega, zeta, ld.force.timepts, np.outer(ld.gamma, ld.force.values), t
        )
        eta += r.eta
        acc += r.eta_ddot
    checked_band = 0
    for name in obs:
        c = res.observations[name].contributions
        a = res.observations[name].assessment
        tphi = st.point(name).translation @ m.phi
        # the point's response (all points' rows in one product) equals the point's own
        # product; another summation blocking of the same k terms: rounding, 1e-12
        ob = res.observations[name]
        for got, modal in ((ob.response.displacement, eta), (ob.response.acceleration, acc)):
            ref_pt = tphi @ modal
            np.testing.assert_allclose(got, ref_pt, rtol=0, atol=1e-12 * np.abs(ref_pt).max())
        series = tphi[:, :, None] * acc[None, :, :]  # (3, k, nt): each mode's own series
        # reference: the peak of each mode's own acceleration magnitude over the samples;
        # |c a(t)| = |c| |a(t)| up to one rounding per product: 1e-14 relative
        own = np.max(np.linalg.norm(series, axis=0), axis=1) / G0
        np.testing.assert_allclose(c.own_peak_g, own, rtol=1e-14, atol=0)
        wb = a.worst_band
        if wb is None or not np.isfinite(wb.margin):
            assert c.worst_band_rms_g is None
            continue
        ax = "xyz".index(wb.axis)
        to = a.third_octave
        i = int(np.argmin(np.abs(to.center_hz - wb.center_hz)))
        bands = BandTable(to.center_hz[i : i + 1], to.lower_hz[i : i + 1], to.upper_hz[i : i + 1])
        # reference: the periodogram of each mode's own series on the worst axis, its band
        # RMS; the PSD is quadratic in the series, so scaling after it differs by rounding
        # of the FFT of the scaled series (1e-12 relative covers a 6000-point FFT)
        ref = band_rms(acceleration_psd(t, series[ax]), bands).rms[:, 0] / G0
        assert c.worst_band_rms_g is not None
        np.testing.assert_allclose(c.worst_band_rms_g, ref, rtol=1e-12, atol=1e-15 * ref.max())
        checked_band += 1
    assert checked_band >= 1  # the band path was exercised


def test_modal_mass_of_an_imported_torsion_mode_counts_rotations():
    # the NASTRAN beam's 5th mode (2674.6 Hz... the first torsion, tests/data/nastran) barely
    # translates a grid: its modal mass is 1/p^2 with p = max(|u|, L_c |theta|) over the
    # grids (Modes docstring), computed here from the file's own shapes; before rotations
    # were counted it was 4e27 kg
    from pathlib import Path

    import microg
    from microg.dynamics.modes import characteristic_length, solve_modes
    from microg.structure.discretize import discretize

    data = Path(__file__).resolve().parents[1] / "data" / "nastran"
    path = data / "beam_modes" / "beam_modes_m2.op2"
    model = microg.load_model(path, units="in,lbf,s")
    s = discretize(model)
    m = solve_modes(s)
    lc = characteristic_length(s)
    shapes = model.phi  # (grids, 6, modes), mass-normalised, SI
    p = np.maximum(
        np.abs(shapes[:, :3]).max(axis=(0, 1)), lc * np.abs(shapes[:, 3:6]).max(axis=(0, 1))
    )
    np.testing.assert_allclose(m.modal_mass, 1.0 / p**2, rtol=1e-12)
    t = np.abs(shapes[:, :3]).max(axis=(0, 1))
    k = int(np.argmin(t / p))  # the mode that translates least: torsion
    assert t[k] < 1e-6 * p[k] and m.modal_mass[k] < 10.0 * np.median(m.modal_mass)
