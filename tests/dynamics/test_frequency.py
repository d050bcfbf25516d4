"""Tests of microg.dynamics.frequency: FRFs, harmonic lines, band integration, combination.

References: a dense complex solve of (K - w^2 M + i w C) x = F with the modal damping matrix
C = M Phi diag(2 zeta omega) Phi^T M (all modes kept); scipy.integrate.quad with break points
at every resonance for band integrals of |H|^2 S; closed forms (the single-mode factor at
resonance, the power of flat bands and power-law PSDs); Maxwell-Betti reciprocity; and
invariants (shares sum to 1, linearity, coherent sums of identical sources).
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from microg._io import dumps
from microg.dynamics import bandquad
from microg.dynamics import frequency as fq
from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.toml import load_station
from microg.structure.fem import build_fem
from microg.structure.ritz import build_ritz

ZETA = 0.02


@pytest.fixture(scope="module")
def ritz():
    s = build_ritz(load_station("ioc"), None, 2, gravity_gradient=False)
    return s, solve_modes(s)


@pytest.fixture(scope="module")
def fem():
    s = build_fem(load_station("ioc"), elements_per_beam=3)
    return s, solve_modes(s, 40)


def _dense_frf(s, m, zeta, observe, at, direction, freq_hz):
    """Reference: direct complex solve of the full equations at each frequency.

    Returns the FRFs (npt, 3, nf) and the 2-norm condition number of the dynamic stiffness
    ``K - w^2 M + i w C`` at each frequency (it bounds the solve's relative error by
    about cond * eps: LU with partial pivoting is backward stable).
    """
    M, K = s.dense()
    z = fq.damping_ratios(m, zeta)
    Mphi = M @ m.phi
    C = Mphi @ np.diag(2.0 * z * m.omega) @ Mphi.T  # exact when all modes are kept
    b = s.point(at).translation.T @ (np.asarray(direction, float) / np.linalg.norm(direction))
    out = np.concatenate([s.point(p).translation for p in observe])
    h, cond = [], []
    for f in freq_hz:
        w = 2 * np.pi * f
        Z = K - w * w * M + 1j * w * C
        x = np.linalg.solve(Z, b)
        h.append(-w * w * (out @ x))
        cond.append(np.linalg.cond(Z))
    return np.array(h).T.reshape(len(observe), 3, -1), np.array(cond)


# --------------------------------------------------------------------------- kernels


def test_modal_factor_limits_and_resonance():
    wj = np.array([0.0, 2.0, 5.0])
    z = np.array([0.0, 0.01, 0.3])
    r = fq.modal_frf_factor(wj, z, np.array([0.0, 2.0, 1e6]))
    # rigid mode: the mass line, 1 at every frequency including the w -> 0 limit
    assert np.allclose(r[0], 1.0, rtol=0, atol=1e-15)
    # elastic mode: 0 at w = 0 (no static acceleration), i/(2 zeta) at w = w_j (closed form),
    # -> 1 far above resonance (residual mass line)
    assert r[1, 0] == 0 and r[2, 0] == 0
    assert abs(r[1, 1] - 1j / (2 * 0.01)) <= 1e-12 * 50
    # far above resonance r = 1 - i 2 zeta w_j / w + O(1/w^2)
    assert abs(r[2, 2] - 1.0) == pytest.approx(2 * 0.3 * 5.0 / 1e6, rel=1e-5)


@pytest.mark.parametrize("which", ["ritz", "fem"])
def test_modal_frf_equals_dense_complex_solve(which, request):
    """All modes kept, modal damping: the modal FRF is the exact solution of the full system."""
    s, _ = request.getfixturevalue(which)
    M, K = s.dense()
    s = dataclasses.replace(s, mass=M, stiffness=K)  # dense: every mode
    m = solve_modes(s)
    assert m.n_modes == s.n_dof
    f = np.r_[np.geomspace(0.003, 80.0, 60), m.freq_hz[~m.rigid][:8]]  # incl. resonances
    got = fq.frf(m, ZETA, ["lab", "boom-tip"], "keel-tip", [0.3, -0.5, 0.8], f)
    ref, cond = _dense_frf(s, m, ZETA, ["lab", "boom-tip"], "keel-tip", [0.3, -0.5, 0.8], f)
    # the dense solve is backward stable: relative error ~ cond(K - w^2 M + i w C) * eps, which
    # is large at low w on a free-free structure (K singular); allow 100 cond eps, and at least
    # 1e-12 (the modal sum's own rounding), of the largest response at each frequency
    scale = np.max(np.abs(ref), axis=(0, 1))
    err = np.max(np.abs(got.accel_per_n - ref), axis=(0, 1)) / scale
    bound = np.maximum(100 * cond * np.finfo(float).eps, 1e-12)
    assert np.all(err <= bound)
    assert np.all(err[f > 1.0] < 1e-7)  # where the dense solve is well conditioned, tight


def test_frf_reciprocity(fem):
    """Maxwell-Betti: H(a <- b along d) . e = H(b <- a along e) . d (symmetric M, K, C)."""
    _, m = fem
    f = np.geomspace(0.01, 40, 200)
    d = np.array([0.2, 0.9, -0.4])
    e = np.array([-0.7, 0.1, 0.7])
    h_ab = np.einsum(
        "k,kf->f", e / np.linalg.norm(e), fq.frf(m, ZETA, ["lab"], "boom-tip", d, f).accel_per_n[0]
    )
    h_ba = np.einsum(
        "k,kf->f", d / np.linalg.norm(d), fq.frf(m, ZETA, ["boom-tip"], "lab", e, f).accel_per_n[0]
    )
    # same modal sum in a different order: rounding only
    assert np.max(np.abs(h_ab - h_ba)) <= 1e-12 * np.max(np.abs(h_ab))


def test_harmonic_response_is_frf_times_phasor(ritz):
    _, m = ritz
    lines = fq.HarmonicLines([2.0, 1.0, 0.5], [0.3, 1.7, 1.7], [0.0, 0.4, -1.0])
    hr = fq.harmonic_response(m, ZETA, ["lab"], "boom-tip", "z", lines)
    h = fq.frf(m, ZETA, ["lab"], "boom-tip", "z", lines.freq_hz).accel_per_n[0]
    phasor = lines.amplitude_n * np.exp(1j * lines.phase_rad)
    assert np.allclose(hr.accel_mps2[0], h * phasor, rtol=1e-14, atol=0)
    # the two 1.7 Hz lines add as phasors, the 0.3 Hz line in mean square (definition)
    ms = np.abs(h[:, 0] * phasor[0]) ** 2 / 2 + np.abs(h[:, 1] * (phasor[1] + phasor[2])) ** 2 / 2
    assert np.allclose(hr.rms_mps2[0] ** 2, ms, rtol=1e-13)
    assert dumps(hr.to_dict()) and hr.to_xarray().rms_mps2.shape == (1, 3)
    assert hr.plot("lab").axes


# ------------------------------------------------------------------------- spectra


def test_psd_power_is_exact_integral_of_loglog_interpolant():
    psd = fq.ForcePSD([0.5, 1.0, 3.0, 3.5, 10.0], [0.2, 0.2, 1e-3, 0.0, 0.05])
    lo = np.array([0.4, 0.7, 2.0, 3.2, 0.1])
    hi = np.array([0.9, 2.5, 3.4, 12.0, 20.0])
    got = psd.power_n2(lo, hi)
    for a, b, g in zip(lo, hi, got, strict=True):
        ref, err = quad(
            lambda f: psd.psd_at(np.array([f]))[0],
            a,
            b,
            points=[1.0, 3.0, 3.5],
            limit=200,
            epsabs=0,
            epsrel=1e-13,
        )
        # adaptive quadrature of the same interpolant to 1e-13: closed form must agree
        assert g == pytest.approx(ref, rel=1e-11, abs=1e-15)
    # log-log between points: the value at the geometric mean is the geometric mean
    assert psd.psd_at(np.array([np.sqrt(1.0 * 3.0)]))[0] == pytest.approx(np.sqrt(0.2 * 1e-3))


def test_band_spectrum_is_flat_and_its_power_exact():
    bs = fq.BandForceSpectrum([1.0, 1.25], [1.25, 1.6], [0.3, 0.4])
    assert bs.psd_at(np.array([1.1]))[0] == pytest.approx(0.09 / 0.25)
    assert bs.psd_at(np.array([0.99, 1.6]))[0] == 0  # outside: zero (upper edge open)
    assert bs.power_n2(np.array([0.0]), np.array([10.0]))[0] == pytest.approx(0.25)
    assert bs.mean_square_n2 == pytest.approx(0.25)


@pytest.mark.parametrize(
    "make",
    [
        lambda: fq.ForcePSD([1.0, 2.0], [0.1, -1.0]),
        lambda: fq.ForcePSD([1.0, 2.0], [0.1, np.nan]),
        lambda: fq.ForcePSD([2.0, 1.0], [0.1, 0.1]),
        lambda: fq.BandForceSpectrum([1.0], [1.2], [-0.1]),
        lambda: fq.BandForceSpectrum([1.0, 1.1], [1.2, 1.3], [0.1, 0.1]),
        lambda: fq.HarmonicLines([1.0], [0.0]),
        lambda: fq.HarmonicLines([np.nan], [1.0]),
    ],
)
def test_bad_spectra_are_refused(make):
    with pytest.raises(InputError):
        make()


# ------------------------------------------------------------------ band integration


def _quad_band(m, zeta, observe_row, at, direction, spec, lo, hi):
    """Reference: adaptive quadrature of |H|^2 S with break points at the resonances."""
    z = fq.damping_ratios(m, zeta)
    out = fq.output_modal(m, [observe_row[0]])[observe_row[1]]
    inp = fq.input_modal(m, at, direction)

    def g(f):
        h = fq.acceleration_frf(m.omega, z, out[None], inp[None], np.array([2 * np.pi * f]))
        return abs(h[0, 0, 0]) ** 2 * spec.psd_at(np.array([f]))[0]

    pts = [x for x in np.r_[m.freq_hz, spec.breakpoints_hz] if lo < x < hi]
    val, _ = quad(g, lo, hi, points=pts or None, limit=1000, epsabs=0, epsrel=1e-12)
    return val


@pytest.mark.parametrize("zeta", [0.02, 1e-4])
def test_band_rms_matches_quad_with_resonances_inside(fem, zeta):
    """Band mean square of a band spectrum and of a PSD against scipy quad (resonances in)."""
    _, m = fem
    f_el = m.freq_hz[~m.rigid]
    # bands centred on resonances (and one between), as the requirement's 1/3 octaves would be
    c = np.array([f_el[0], f_el[3], 0.5 * (f_el[5] + f_el[6]), f_el[10]])
    lo, hi = c / 2 ** (1 / 6), c * 2 ** (1 / 6)
    bands = fq.BandForceSpectrum(np.r_[lo[:2]], np.r_[hi[:2]], [0.7, 1.3])
    psd = fq.ForcePSD([0.05, 0.5, 4.0, 30.0], [0.02, 1.0, 0.1, 1e-3])
    loads = [fq.Load("b", "vertical-lab", "x", bands), fq.Load("p", "boom-tip", "1 0 1", psd)]
    order = np.argsort(lo)
    lo, hi = lo[order], hi[order]
    r = fq.band_response(m, zeta, ["lab"], loads, lo, hi)
    for k, (a, b) in enumerate(zip(lo, hi, strict=True)):
        for j, (ld, spec) in enumerate(((loads[0], bands), (loads[1], psd))):
            for ax in range(3):
                ref = _quad_band(m, zeta, ("lab", ax), ld.at, ld.direction, spec, a, b)
                got = r.source_rms_mps2[0, ax, k, j] ** 2
                # quad at epsrel 1e-12 vs the convergence-checked rule (rtol 1e-9): 1e-8 of
                # the larger of the two sources' band mean squares at this point and axis
                scale = np.max(r.source_rms_mps2[0, ax, k] ** 2)
                assert abs(got - ref) <= 1e-8 * max(ref, 1e-6 * scale), (k, j, ax, got, ref)
    assert r.refinements >= 0 and np.all(r.quad_error <= 1e-9)


def test_a_loose_tolerance_takes_fewer_nodes_and_still_meets_it(fem):
    """rtol 1e-3 integrates with 6 Gauss points an interval (not 8) and stays within 1e-3."""
    _, m = fem
    f_el = m.freq_hz[~m.rigid]
    c = np.array([f_el[0], f_el[3], f_el[10]])
    lo, hi = c / 2 ** (1 / 6), c * 2 ** (1 / 6)
    psd = fq.ForcePSD([0.05, 0.5, 4.0, 30.0], [0.02, 1.0, 0.1, 1e-3])
    loads = [fq.Load("p", "boom-tip", "1 0 1", psd)]
    tight = fq.band_response(m, 0.005, ["lab"], loads, lo, hi)
    loose = fq.band_response(m, 0.005, ["lab"], loads, lo, hi, rtol=1e-3)
    assert bandquad.default_order(1e-3) == 6 and bandquad.default_order(1e-9) == 8
    six = fq.band_response(m, 0.005, ["lab"], loads, lo, hi, rtol=1e-3, order=6)
    assert loose.quad_nodes == six.quad_nodes < tight.quad_nodes  # the 6-point rule is used
    for k, (a, b) in enumerate(zip(lo, hi, strict=True)):
        for ax in range(3):
            ref = _quad_band(m, 0.005, ("lab", ax), "boom-tip", loads[0].direction, psd, a, b)
            got = loose.rms_mps2[0, ax, k] ** 2
            # the tolerance asked, on the largest axis's band mean square (quad: 1e-12)
            scale = np.max(tight.rms_mps2[0, :, k] ** 2)
            assert abs(got - ref) <= 1e-3 * max(ref, 1e-6 * scale), (k, ax, got, ref)


def test_near_far_split_equals_the_full_modal_sum_on_the_same_nodes(fem):
    """The Chebyshev interpolant of the far modes changes nothing: the band mean squares equal
    the full modal sum of |H|^2 S evaluated at the same quadrature nodes (rounding only)."""
    _, m = fem
    req_lo = 0.01 * 2.0 ** (np.arange(0, 40) / 3)
    lo, hi = req_lo / 2 ** (1 / 6), req_lo * 2 ** (1 / 6)
    specs = [
        fq.ForcePSD([0.005, 1.0, 80.0], [1e-3, 1.0, 1e-2]),
        fq.BandForceSpectrum(lo, hi, np.linspace(0.1, 1.0, lo.size)),
    ]
    loads = [fq.Load("p", "keel-tip", "1 1 0", specs[0]), fq.Load("b", "lab", "z", specs[1])]
    r = fq.band_response(m, ZETA, ["lab", "boom-tip"], loads, lo, hi)
    z = fq.damping_ratios(m, ZETA)
    out = fq.output_modal(m, ["lab", "boom-tip"])
    inp = np.array([fq.input_modal(m, ld.at, ld.direction) for ld in loads])
    scale = np.max(np.abs(out), axis=0) * np.max(np.abs(inp), axis=0)
    quad_, _, _, _ = bandquad.converged_quadrature(lo, hi, m.omega, z, scale, specs, 8, 1e-9)
    h = fq.acceleration_frf(m.omega, z, out, inp, 2 * np.pi * quad_.freq_hz)  # all modes
    S = np.array([sp.psd_at(quad_.freq_hz) for sp in specs])
    ref = bandquad.per_band(np.abs(h) ** 2 * S[None] * quad_.weight_hz, quad_.start)  # (p, s, nb)
    got = np.moveaxis(r.source_rms_mps2.reshape(6, lo.size, 2), 2, 1) ** 2
    assert np.any(r.near_modes < m.n_modes)  # the far-mode path is exercised
    # far-mode interpolants are checked to 1e-14 of each mode: 1e-11 relative
    assert np.allclose(got, ref, rtol=1e-11, atol=0)


def test_coarse_sampling_would_miss_the_resonance(fem):
    """The converged rule gets a narrow resonance that a 50-point uniform grid misses."""
    _, m = fem
    zeta = 1e-4
    z = fq.damping_ratios(m, zeta)
    out = fq.output_modal(m, ["boom-tip"])
    inp = fq.input_modal(m, "boom-tip", "z")
    # the elastic mode with the largest resonant response |c_j| / (2 zeta) at some axis
    el = np.flatnonzero(~m.rigid)[:12]
    c = np.abs(out[:, el] * inp[el])
    ax, k = np.unravel_index(np.argmax(c), c.shape)
    fj = m.freq_hz[el[k]]
    lo, hi = np.array([fj / 1.1]), np.array([fj * 1.12])
    spec = fq.BandForceSpectrum(lo, hi, [1.0])
    r = fq.band_response(m, zeta, ["boom-tip"], [fq.Load("s", "boom-tip", "z", spec)], lo, hi)
    ref = _quad_band(m, zeta, ("boom-tip", ax), "boom-tip", "z", spec, lo[0], hi[0])
    assert r.rms_mps2[0, ax, 0] ** 2 == pytest.approx(ref, rel=1e-8)
    # a uniform 50-point grid with the resonance halfway between two points
    step = (hi[0] - lo[0]) / 49
    grid = fj + step * (np.arange(50) - 24.5)
    h = fq.acceleration_frf(m.omega, z, out[ax][None], inp[None], 2 * np.pi * grid)[0, 0]
    naive = np.trapezoid(np.abs(h) ** 2 * spec.psd_at(grid), grid)
    assert naive < 0.5 * ref  # the trap the kernel must avoid: the peak falls between samples


def test_lines_fall_in_their_band_and_outside_lines_warn(ritz):
    _, m = ritz
    lo = np.array([0.9, 1.12])
    hi = np.array([1.12, 1.4])
    lines = fq.HarmonicLines([1.0, 1.0, 1.0], [1.0, 1.12, 5.0])
    r = fq.band_response(m, ZETA, ["lab"], [fq.Load("h", "crew", "x", lines)], lo, hi)
    hr = fq.harmonic_response(m, ZETA, ["lab"], "crew", "x", lines)
    ms = np.abs(hr.accel_mps2[0]) ** 2 / 2  # (3, 3 lines)
    # band [lower, upper): the 1.12 Hz line belongs to the second band only
    assert np.allclose(r.rms_mps2[0, :, 0] ** 2, ms[:, 0], rtol=1e-13)
    assert np.allclose(r.rms_mps2[0, :, 1] ** 2, ms[:, 1], rtol=1e-13)
    assert any("outside every band" in w for w in r.warnings)


# ----------------------------------------------------------------------- combination


def _two(spec_a, spec_b, group):
    return [
        fq.Load("a", "crew", "x", spec_a, group=group),
        fq.Load("b", "crew", "x", spec_b, group=group),
    ]


@pytest.mark.parametrize("kind", ["harmonic", "psd"])
def test_coherent_and_independent_sums(ritz, kind):
    """Two identical sources at one point: independent -> 2 MS, coherent in phase -> 4 MS,
    coherent in antiphase (harmonic) -> 0 (definitions of RSS and coherent sum)."""
    _, m = ritz
    lo, hi = np.array([0.2, 0.9]), np.array([0.9, 3.0])
    if kind == "harmonic":
        a = fq.HarmonicLines([1.0, 0.5], [0.5, 1.3])
        anti = fq.HarmonicLines([1.0, 0.5], [0.5, 1.3], [np.pi, np.pi])
    else:
        a = fq.ForcePSD([0.2, 1.0, 3.0], [0.1, 1.0, 0.01])
        anti = None
    one = fq.band_response(m, ZETA, ["lab"], [fq.Load("a", "crew", "x", a)], lo, hi)
    ind = fq.band_response(m, ZETA, ["lab"], _two(a, a, None), lo, hi)
    coh = fq.band_response(m, ZETA, ["lab"], _two(a, a, "machine"), lo, hi)
    ms1 = one.rms_mps2**2
    assert np.allclose(ind.rms_mps2**2, 2 * ms1, rtol=1e-12)
    assert np.allclose(coh.rms_mps2**2, 4 * ms1, rtol=1e-12)
    assert np.allclose(coh.source_share, 0.5, atol=1e-12)  # symmetric members
    assert coh.group_names == ("machine",)
    if anti is not None:
        off = fq.band_response(m, ZETA, ["lab"], _two(a, anti, "machine"), lo, hi)
        assert np.max(off.rms_mps2) <= 1e-7 * np.max(one.rms_mps2)
        # each member alone is still the single source's level
        assert np.allclose(off.source_rms_mps2[..., 0], one.rms_mps2, rtol=1e-12)


@st.composite
def _case(draw):
    ns = draw(st.integers(1, 4))
    specs = []
    for _ in range(ns):
        k = draw(st.sampled_from(["h", "b", "p"]))
        if k == "h":
            specs.append(
                fq.HarmonicLines(
                    [draw(st.floats(0.1, 2))], [draw(st.floats(0.05, 20))], [draw(st.floats(-3, 3))]
                )
            )
        elif k == "b":
            specs.append(
                fq.BandForceSpectrum(
                    [0.1, 1.0], [0.5, 8.0], [draw(st.floats(0.01, 1)), draw(st.floats(0, 1))]
                )
            )
        else:
            specs.append(
                fq.ForcePSD(
                    [0.05, 1.0, 30.0], [draw(st.floats(1e-3, 1)), 0.1, draw(st.floats(1e-4, 1e-2))]
                )
            )
    groups = [draw(st.sampled_from([None, "g1", "g2"])) for _ in range(ns)]
    pts = [
        draw(st.sampled_from(["lab", "crew", "vertical-lab", "keel-tip", "boom-tip"]))
        for _ in range(ns)
    ]
    return specs, groups, pts


@functools.lru_cache(maxsize=1)
def _ritz_modes():  # a plain cache, not a fixture: hypothesis prints its arguments on failure
    return solve_modes(build_ritz(load_station("ioc"), None, 2, gravity_gradient=False))


@settings(max_examples=20, deadline=None)
@given(case=_case())
def test_shares_sum_to_one_and_response_is_linear(case):
    m = _ritz_modes()
    specs, groups, pts = case
    loads = [
        fq.Load(f"s{i}", p, "1 1 0", sp, group=g)
        for i, (sp, p, g) in enumerate(zip(specs, pts, groups, strict=True))
    ]
    lo = np.array([0.04, 0.3, 2.0])
    hi = np.array([0.3, 2.0, 25.0])
    r = fq.band_response(m, ZETA, ["lab", "boom-tip"], loads, lo, hi)
    top = float(np.max(r.rms_mps2))
    live = r.rms_mps2 > 1e-9 * top  # bands with a physical response, not rounding noise
    # shares are a decomposition of the band mean square: they sum to 1 (rounding, and the
    # far-mode interpolant at 1e-14 for the mode shares)
    assert np.allclose(r.source_share.sum(-1)[live], 1.0, atol=1e-9)
    assert np.allclose(r.mode_share.sum(-1)[live], 1.0, atol=1e-8)
    # groups are independent: their mean squares add up to the total
    assert np.allclose(
        (r.group_rms_mps2**2).sum(-1), r.rms_mps2**2, rtol=1e-10, atol=1e-24 * top**2
    )

    # linearity: forces x 3 -> accelerations x 3
    def scaled(sp):
        if isinstance(sp, fq.HarmonicLines):
            return fq.HarmonicLines(3 * sp.amplitude_n, sp.freq_hz, sp.phase_rad)
        if isinstance(sp, fq.BandForceSpectrum):
            return fq.BandForceSpectrum(sp.lower_hz, sp.upper_hz, 3 * sp.rms_n)
        return fq.ForcePSD(sp.freq_hz, 9 * sp.value_n2_per_hz)

    loads3 = [fq.Load(ld.name, ld.at, ld.direction, scaled(ld.spectrum), ld.group) for ld in loads]
    r3 = fq.band_response(m, ZETA, ["lab", "boom-tip"], loads3, lo, hi)
    assert np.allclose(r3.rms_mps2, 3 * r.rms_mps2, rtol=1e-10, atol=1e-12 * top)


def test_without_contributions_the_bands_are_the_same_and_the_modes_zero(fem):
    """contributions=False leaves the band and source values bit for bit, mode terms zero."""
    _, m = fem
    f_el = m.freq_hz[~m.rigid]
    c = np.array([f_el[0], f_el[3]])
    lo, hi = c / 2 ** (1 / 6), c * 2 ** (1 / 6)
    loads = [
        fq.Load("p", "boom-tip", "1 0 1", fq.ForcePSD([0.05, 4.0, 30.0], [0.02, 1.0, 1e-3])),
        fq.Load("b", "vertical-lab", "x", fq.BandForceSpectrum(lo, hi, [0.7, 1.3])),
        fq.Load("h", "lab", "y", fq.HarmonicLines([0.4], [float(c[1])], [0.0])),
    ]
    full = fq.band_response(m, 0.01, ["lab"], loads, lo, hi)
    bare = fq.band_response(m, 0.01, ["lab"], loads, lo, hi, contributions=False)
    assert np.any(full.mode_rms_mps2 > 0) and np.any(full.mode_share != 0)
    np.testing.assert_array_equal(bare.rms_mps2, full.rms_mps2)
    np.testing.assert_array_equal(bare.source_rms_mps2, full.source_rms_mps2)
    assert not np.any(bare.mode_rms_mps2) and not np.any(bare.mode_share)


def test_mode_alone_is_exact_for_a_single_mode(ritz):
    """With one elastic mode kept, that mode alone is the whole response."""
    _, m = ritz
    one = m.subset(np.array([int(np.flatnonzero(~m.rigid)[0])]))
    spec = fq.ForcePSD([0.01, 1.0], [1.0, 1.0])
    lo, hi = np.array([0.05, 0.2]), np.array([0.2, 0.8])
    r = fq.band_response(one, ZETA, ["boom-tip"], [fq.Load("s", "lab", "x", spec)], lo, hi)
    assert np.allclose(r.mode_rms_mps2[..., 0], r.rms_mps2, rtol=1e-12)
    assert np.allclose(r.mode_share[..., 0][r.rms_mps2 > 0], 1.0, rtol=1e-12)


# ----------------------------------------------------------------------- bad input


def test_bad_input(ritz):
    _, m = ritz
    spec = fq.ForcePSD([0.1, 1.0], [1.0, 1.0])
    load = fq.Load("s", "lab", "x", spec)
    lo, hi = np.array([0.1]), np.array([0.2])
    with pytest.raises(InputError, match="0 < zeta < 1"):
        fq.band_response(m, 0.0, ["lab"], [load], lo, hi)
    with pytest.raises(InputError, match="unknown point 'nowhere'") as exc:
        fq.band_response(m, ZETA, ["nowhere"], [load], lo, hi)
    assert exc.value.where == "observe[0]"
    with pytest.raises(InputError, match="unknown point"):
        fq.band_response(m, ZETA, ["lab"], [fq.Load("s", "nowhere", "x", spec)], lo, hi)
    with pytest.raises(InputError, match="used twice"):
        fq.band_response(m, ZETA, ["lab"], [load, load], lo, hi)
    with pytest.raises(InputError):
        fq.frf(m, ZETA, ["lab"], "lab", "x", [-1.0])
    with pytest.raises(InputError):
        fq.Load("s", "lab", "sideways", spec)


def test_result_objects(ritz):
    _, m = ritz
    loads = [fq.Load("s", "lab", "x", fq.ForcePSD([0.1, 10.0], [1.0, 1.0]))]
    r = fq.band_response(
        m, ZETA, ["lab", "boom-tip"], loads, np.array([0.2, 1.0]), np.array([1.0, 5.0])
    )
    d = r.to_dict()
    assert dumps(d) and set(d["points"]) == {"lab", "boom-tip"}
    ds = r.to_xarray()
    assert ds.mode_rms_mps2.dims == ("point", "axis", "band", "mode")
    assert ds.source_rms_mps2.dims == ("point", "axis", "band", "source")
    assert ds.rms_mps2.attrs["units"] == "m/s^2"
    fig = r.plot("boom-tip")
    assert fig.axes
    fr = fq.frf(m, ZETA, ["lab"], "boom-tip", "z", np.geomspace(0.01, 10, 50))
    assert (
        fr.plot().axes and dumps(fr.to_dict()) and fr.to_xarray().dims == ("point", "axis", "freq")
    )


def test_truncated_modes_are_flagged(ritz):
    """Bands far above the highest kept mode: the modal sum misses the modes above, say so."""
    _, m = ritz
    spec = fq.ForcePSD([1.0, 200.0], [1.0, 1.0])
    lo, hi = np.array([1.0, 90.0]), np.array([1.2, 110.0])
    r = fq.band_response(m, ZETA, ["lab"], [fq.Load("s", "lab", "x", spec)], lo, hi)
    assert m.freq_hz[-1] < 1.5 * 110.0
    assert any("modal truncation" in w for w in r.warnings)


def test_unstable_modes_are_flagged():
    """A gravity-gradient-unstable attitude has no steady state: the result says so."""
    from pathlib import Path

    from microg.structure.discretize import discretize

    path = Path(__file__).parents[1] / "data" / "models" / "solver_unstable.toml"
    s = discretize(load_station(path), "ritz", plane="yz", gravity_gradient=True)
    m = solve_modes(s)
    assert np.any(m.unstable)
    spec = fq.ForcePSD([0.01, 1.0], [1.0, 1.0])
    r = fq.band_response(
        m, ZETA, ["lab"], [fq.Load("s", "lab", "y", spec)], np.array([0.01]), np.array([0.02])
    )
    assert any("unstable mode" in w for w in r.warnings)


# ------------------------------------------------------------------ weighted band integrals


def _lorentz_weight(f0_hz, zeta):
    """A 1-DOF |T|^2 per row, resonant at ``f0_hz[p]`` (the shape of an isolator's umbilical)."""
    f0 = np.asarray(f0_hz, float)

    def w(f):
        r = np.asarray(f, float)[None, :] / f0[:, None]
        return np.abs((1 + 2j * zeta * r) / (1 - r**2 + 2j * zeta * r)) ** 2

    return w


def test_weighted_band_rms_matches_quad(fem):
    """int w_p |H_p|^2 S df against scipy quad, with a sharp weight resonant inside bands."""
    _, m = fem
    f_el = m.freq_hz[~m.rigid]
    c = np.array([f_el[0], f_el[3], 0.5 * (f_el[5] + f_el[6])])
    lo, hi = c / 2 ** (1 / 6), c * 2 ** (1 / 6)
    order = np.argsort(lo)
    lo, hi = lo[order], hi[order]
    f_w = np.array([c[0] * 1.05, c[1] / 1.07, c[2] * 1.02])  # one resonance per axis
    weight = _lorentz_weight(f_w, 0.01)
    psd = fq.ForcePSD([0.05, 0.5, 4.0, 30.0], [0.02, 1.0, 0.1, 1e-3])
    load = fq.Load("p", "boom-tip", "1 0 1", psd)
    r = fq.band_response(m, ZETA, ["lab"], [load], lo, hi, weight=weight, weight_breakpoints_hz=f_w)
    z = fq.damping_ratios(m, ZETA)
    out = fq.output_modal(m, ["lab"])
    inp = fq.input_modal(m, load.at, load.direction)
    for k, (a, b) in enumerate(zip(lo, hi, strict=True)):
        for ax in range(3):

            def g(f, ax=ax):
                h = fq.acceleration_frf(
                    m.omega, z, out[ax][None], inp[None], np.array([2 * np.pi * f])
                )
                return (
                    weight(np.array([f]))[ax, 0]
                    * abs(h[0, 0, 0]) ** 2
                    * psd.psd_at(np.array([f]))[0]
                )

            pts = [x for x in np.r_[m.freq_hz, psd.breakpoints_hz, f_w] if a < x < b]
            ref, _ = quad(g, a, b, points=pts or None, limit=2000, epsabs=0, epsrel=1e-12)
            got = r.rms_mps2[0, ax, k] ** 2
            # quad at 1e-12 vs the rule converged to 1e-9 on the weighted integrand: 1e-8
            scale = np.max(r.rms_mps2[0, :, k] ** 2)
            assert abs(got - ref) <= 1e-8 * max(ref, 1e-6 * scale), (k, ax, got, ref)
    assert np.all(r.quad_error <= 1e-9)
    plain = fq.band_response(m, ZETA, ["lab"], [load], lo, hi)
    assert np.max(r.rms_mps2 / np.maximum(plain.rms_mps2, 1e-300)) > 3.0  # the weight matters
    # without the weight's breakpoints the check on the weighted integrand refines the bands
    # to 1e-9 (7.5e-10 measured; the check on the unweighted integrand alone stops at 2.6e-7)
    r2 = fq.band_response(m, ZETA, ["lab"], [load], lo, hi, weight=weight)
    assert r2.refinements > 0
    assert np.allclose(r2.rms_mps2**2, r.rms_mps2**2, rtol=1e-8, atol=0)


def test_weighted_lines_are_weighted_at_their_frequency(ritz):
    _, m = ritz
    lo, hi = np.array([0.2, 0.9]), np.array([0.9, 3.0])
    lines = fq.HarmonicLines([1.0, 0.5, 0.7], [0.5, 1.3, 0.61], [0.0, 1.0, 2.0])
    weight = _lorentz_weight([0.55, 1.2, 2.0], 0.05)
    loads = [fq.Load("h", "crew", "x", lines)]
    plain = fq.band_response(m, ZETA, ["lab"], loads, lo, hi)
    wtd = fq.band_response(m, ZETA, ["lab"], loads, lo, hi, weight=weight)
    hr = fq.harmonic_response(m, ZETA, ["lab"], "crew", "x", lines)
    ms = np.abs(hr.accel_mps2[0]) ** 2 / 2 * weight(lines.freq_hz)  # (3, lines)
    # one line per frequency, orthogonal: band 0 holds 0.5 and 0.61 Hz, band 1 holds 1.3 Hz
    assert np.allclose(wtd.rms_mps2[0, :, 0] ** 2, ms[:, 0] + ms[:, 2], rtol=1e-12)
    assert np.allclose(wtd.rms_mps2[0, :, 1] ** 2, ms[:, 1], rtol=1e-12)
    assert not np.allclose(wtd.rms_mps2, plain.rms_mps2)


def test_constant_weight_scales_every_mean_square(ritz):
    """A constant weight c_p per row multiplies every mean square of row p by c_p; shares keep."""
    _, m = ritz
    lo, hi = np.array([0.2, 0.9]), np.array([0.9, 3.0])
    psd = fq.ForcePSD([0.2, 1.0, 3.0], [0.1, 1.0, 0.01])
    lines = fq.HarmonicLines([1.0, 0.5], [0.5, 1.3], [0.0, 2.0])
    loads = [
        fq.Load("a", "crew", "x", psd, group="m"),
        fq.Load("b", "lab", "1 1 0", psd, group="m"),
        fq.Load("c", "crew", "z", lines, group="m"),
        fq.Load("d", "boom-tip", "y", lines),
    ]
    cw = np.array([0.3, 2.0, 7.0])
    weight = lambda f: np.repeat(cw[:, None], np.size(f), axis=1)  # noqa: E731
    plain = fq.band_response(m, ZETA, ["lab"], loads, lo, hi)
    wtd = fq.band_response(m, ZETA, ["lab"], loads, lo, hi, weight=weight)
    c3 = cw[None, :, None]
    # 1e-9: both converge to rtol 1e-9 (the weighted check may refine differently)
    assert np.allclose(wtd.rms_mps2**2, c3 * plain.rms_mps2**2, rtol=1e-9, atol=0)
    for name in ("source_rms_mps2", "group_rms_mps2", "mode_rms_mps2"):
        a, b = getattr(wtd, name) ** 2, getattr(plain, name) ** 2
        assert np.allclose(a, c3[..., None] * b, rtol=1e-9, atol=1e-30), name
    for name in ("source_share", "mode_share"):
        assert np.allclose(getattr(wtd, name), getattr(plain, name), rtol=1e-8, atol=1e-12)


def test_weighted_shares_sum_to_one(fem):
    _, m = fem
    req_lo = 0.05 * 2.0 ** (np.arange(0, 12) / 3)
    lo, hi = req_lo / 2 ** (1 / 6), req_lo * 2 ** (1 / 6)
    loads = [
        fq.Load("p", "keel-tip", "1 1 0", fq.ForcePSD([0.03, 1.0, 10.0], [1e-3, 1.0, 1e-2])),
        fq.Load("q", "lab", "z", fq.ForcePSD([0.03, 10.0], [1.0, 1.0]), group="g"),
        fq.Load("h", "lab", "x", fq.HarmonicLines([1.0], [0.4]), group="g"),
    ]
    weight = _lorentz_weight([0.1, 0.3, 1.0], 0.02)
    r = fq.band_response(
        m, ZETA, ["lab", "boom-tip"], loads, lo, hi, weight=lambda f: np.tile(weight(f), (2, 1))
    )
    live = r.rms_mps2 > 0
    # the signed shares are projections on the (weighted) total: they sum to 1 (rounding)
    assert np.allclose(r.mode_share.sum(axis=-1)[live], 1.0, atol=1e-9)
    assert np.allclose(r.source_share.sum(axis=-1)[live], 1.0, atol=1e-12)


def test_a_bad_weight_is_refused(ritz):
    _, m = ritz
    load = fq.Load("s", "lab", "x", fq.ForcePSD([0.1, 1.0], [1.0, 1.0]))
    lo, hi = np.array([0.1]), np.array([0.2])
    for bad in (lambda f: np.ones((2, np.size(f))), lambda f: -np.ones((3, np.size(f)))):
        with pytest.raises(InputError) as exc:
            fq.band_response(m, ZETA, ["lab"], [load], lo, hi, weight=bad)
        assert exc.value.where == "weight"
