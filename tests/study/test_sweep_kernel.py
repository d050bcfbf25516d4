"""Every case of a sweep equals the per-case path (``microg.analyze``) run on it alone.

References (independent of the sweep's linear algebra):

* :func:`microg.analyze` on the case alone: its own modal solve, modal forces, modal
  response, point projection, assessment and certified exact peak;
* for an isolated case, :func:`microg.isolation.timedomain.package_response` on each axis of
  the analysis' record, then :func:`microg.environment.metrics.assess` (the isolation advice's
  time-domain check);
* :func:`microg.dynamics.response.peak_response` over the whole record, for the pruning of
  the exact-peak search.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from microg.dynamics.response import peak_response
from microg.environment.metrics import assess
from microg.errors import InputError
from microg.isolation.timedomain import package_response
from microg.study import CASE_DIMS, loads_study, sweep
from microg.units import G0

TEXT = """
[study]
model = "ioc"
[axes]
force = ["foot-pushoff-max", "hand-pushoff-mean"]
at = ["crew", "vertical-lab", "keel-mid"]
direction = ["x", "-y", [0.6, 0, 0.8]]
observe = ["lab", "keel-tip", "boom-tip"]
damping = [0.002, 0.02]
isolator = [{ name = "none" }, { name = "soft", f_n = "0.1 Hz", zeta1 = 0.1 }]
variant = [
  { name = "base" },
  { name = "dock-fwd", move = "main/Orbiter", to = ["0 ft", "0 ft", "-60 ft"] },
]
[record]
duration = "60 s"
dt = "0.1 s"
max_freq = "2 Hz"
peaks = "exact"
[[point]]
name = "keel-mid"
on = "keel"
s = "148 ft"
"""

# cases across every axis: (variant, isolator, damping, force, at, direction, observe)
CASES = [
    (0, 0, 0, 0, 0, 0, 0),
    (0, 0, 1, 1, 1, 1, 1),
    (0, 0, 0, 1, 2, 2, 2),
    (1, 0, 1, 0, 2, 1, 0),
    (1, 0, 0, 0, 1, 2, 1),
    (0, 1, 0, 0, 0, 1, 2),
    (1, 1, 1, 1, 2, 0, 1),
]


@pytest.fixture(scope="module")
def result():
    return sweep(loads_study(TEXT, filename="study.toml"))


@pytest.fixture(scope="module")
def data(result):
    return result.dataset.load()


def _close(x: np.ndarray, ref: np.ndarray, floor: float) -> None:
    """Equal to 1e-9 relative, except values at rounding level of the case's scale.

    ``floor`` is the case's own scale (its peak, or its largest band RMS) times 1e-12: an axis
    the force does not drive (a y push observed on the symmetry plane) carries only rounding,
    ~1e-16 of the scale, in both paths, and its relative difference means nothing.
    """
    np.testing.assert_allclose(x, ref, rtol=1e-9, atol=floor * 1e-12)


@pytest.mark.parametrize("case", CASES)
def test_a_case_equals_analyze_on_it_alone(result, data, case) -> None:
    index = (0, *case)
    labels = result.study.case(index)
    point = data.isel(dict(zip(CASE_DIMS, index, strict=True)))
    a = result.analyze_case(labels, isolation=False)
    ob = a.observations[labels["observe"]]
    mount = result.study.isolators[case[1]].mount
    if mount is None:
        ref = ob.assessment
    else:  # the package on its mount, driven by the analysis' record (base excitation)
        t = ob.response.timepts
        pkg = np.array([package_response(mount, t, row).package_accel for row in
                        ob.response.acceleration])  # fmt: skip
        ref = assess(t, pkg, a.requirement)
    scale = ref.peak_accel_g
    _close(point.peak_accel_g.values, ref.peak_accel_g, scale)
    _close(point.peak_accel_g_axis.values, ref.peak_accel_g_axis, scale)
    _close(point.rms_accel_g.values, ref.rms_accel_g, scale)
    _close(point.rms_accel_g_axis.values, ref.rms_accel_g_axis, scale)
    bands = ref.third_octave.rms_g
    _close(point.band_rms_g.values, bands, float(bands.max()))
    assert np.array_equal(point.band.values, ref.third_octave.center_hz)
    assert np.array_equal(point.limit_g.values, ref.third_octave.limit_g)
    assert np.array_equal(point.judged.values, ref.third_octave.resolved)
    _close(point.margin.values, ref.worst_band.margin, 1.0)
    assert bool(point.complies.values) == bool(ref.complies)
    assert bool(point.computed.values)


def test_exact_peaks_lie_in_the_analysis_certified_interval(result, data) -> None:
    for case in CASES:
        if result.study.isolators[case[1]].mount is not None:
            continue
        index = (0, *case)
        labels = result.study.case(index)
        pk = result.analyze_case(labels, isolation=False).observations[labels["observe"]].peak
        mine = float(data.peak_accel_g.values[index]) * G0
        # the analysis certifies the supremum in [peak, upper]; the sweep's search is tighter
        # (rtol 1e-10), so its value lies in that interval up to the last rounding
        assert pk.peak_accel_mps2 * (1 - 2e-10) <= mine <= pk.upper_bound_mps2 * (1 + 1e-15)
        assert mine >= pk.sampled_peak_accel_mps2 * (1 - 1e-15)


def test_the_pruned_exact_peak_equals_the_whole_record_search(result) -> None:
    """The windows searched miss no maximum: the same search over the whole record agrees."""
    from microg.study.kernel import (
        BlockWork,
        _coefficients,
        _exact_peaks,
        kernel_plan,
        modal_group,
        solve_basis,
    )
    from microg.study.run import _solve_args

    s = result.study
    plan = kernel_plan(s)
    model, kw = _solve_args(s, 0, 0)
    basis = solve_basis(model, **kw)
    blk = s.block(0)
    work = BlockWork(blk.id, blk.index, blk.at, blk.observe, s.block_mask(blk.index, blk.at,
                                                                        blk.observe))  # fmt: skip
    group = modal_group(basis, plan, 0, 0, 0)
    force = plan.forces[0]
    c, _ = _coefficients(basis, plan, group, work, force)
    got = _exact_peaks(c, group, force, plan.timepts)
    m = c.shape[2]
    maps = {str(i): c[i] for i in range(c.shape[0])}
    full = peak_response(group.omega, group.zeta, np.eye(m), maps, [(force, np.ones(m))],
                         plan.timepts, rtol=1e-12)  # fmt: skip
    ref = np.array([full[str(i)].peak_accel_mps2 for i in range(c.shape[0])])
    ref_ax = np.array([full[str(i)].peak_accel_mps2_axis for i in range(c.shape[0])])
    np.testing.assert_allclose(got["peak"], ref, rtol=2e-10)  # both certified to <= 1e-10
    np.testing.assert_allclose(got["peak_axis"], ref_ax, rtol=2e-10, atol=1e-12 * ref.max())


def test_the_default_rule_changes_no_verdict_and_certifies_only_near_a_limit(result, data):
    """``peaks = "verdict"`` (the default): every value but the peaks is the exact rule's, bit
    for bit; the peaks are the sampled record's (at most the certified exact peak) unless a
    verdict's limit lies between a sampled peak and its bound."""
    text = TEXT.replace('peaks = "exact"\n', "")
    fast = sweep(loads_study(text, filename="study.toml"))
    got = fast.dataset.load()
    for v in ("rms_accel_g", "rms_accel_g_axis", "band_rms_g", "margin", "complies", "computed"):
        assert np.array_equal(got[v].values, data[v].values, equal_nan=True), v
    # no limit of the iss set depends on the peak: no case is searched
    assert not got.peak_certified.values.any() and fast.summary().peaks_certified == 0
    assert int(data.peak_certified.sum()) == result.summary().peaks_certified > 0
    # a sampled maximum is at most the supremum it samples (the exact one, found to 1e-10)
    assert np.all(got.peak_accel_g.values <= data.peak_accel_g.values * (1 + 1e-15))
    assert np.all(got.peak_accel_g_axis.values <= data.peak_accel_g_axis.values * (1 + 1e-15))


def test_a_limit_between_the_sampled_peak_and_its_bound_is_certified(result) -> None:
    """The search runs exactly for the cases whose verdict the exact peak may change, and
    finds there the peaks of the search over every case (both certified to 1e-10)."""
    from microg.study.kernel import (
        BlockWork,
        _coefficients,
        _exact_peaks,
        kernel_plan,
        modal_group,
        solve_basis,
    )
    from microg.study.run import _solve_args

    s = result.study
    plan = kernel_plan(s)
    model, kw = _solve_args(s, 0, 0)
    basis = solve_basis(model, **kw)
    blk = s.block(0)
    work = BlockWork(blk.id, blk.index, blk.at, blk.observe, s.block_mask(blk.index, blk.at,
                                                                        blk.observe))  # fmt: skip
    group = modal_group(basis, plan, 0, 0, 0)
    force = plan.forces[0]
    c, _ = _coefficients(basis, plan, group, work, force)
    every = _exact_peaks(c, group, force, plan.timepts)
    none = _exact_peaks(c, group, force, plan.timepts, ([], []))
    assert every["certified"].all() and not none["certified"].any()
    sampled, exact = none["peak"], every["peak"]
    assert np.all(sampled <= exact * (1 + 1e-15))
    # a limit just above case k's exact peak: the sampled value is below it, the bound above
    k = int(np.argmax(exact / sampled))
    assert exact[k] > sampled[k] * (1 + 1e-6)  # the sampling misses this peak's top
    lim = exact[k] * (1 + 1e-8)
    got = _exact_peaks(c, group, force, plan.timepts, ([lim], []))
    assert got["certified"][k]
    # searched: only cases whose sampled peak is at most the limit; and every case whose
    # exact peak lies above it (its bound does too)
    assert np.all(sampled[got["certified"]] <= lim * (1 + 1e-9))
    assert np.all(got["certified"][(sampled <= lim) & (exact > lim)])
    np.testing.assert_allclose(got["peak"][k], exact[k], rtol=2e-10)  # both to 1e-10
    # a limit no case's bound reaches, and one below every sampled peak: nothing to search
    far = _exact_peaks(c, group, force, plan.timepts, ([10 * exact.max()], [0.5 * sampled.min()]))
    assert not far["certified"].any()
    assert np.array_equal(far["peak"], sampled)


def test_the_rigid_modes_share_one_row(result) -> None:
    from microg.study.kernel import kernel_plan, modal_group, solve_basis
    from microg.study.run import _solve_args

    s = result.study
    model, kw = _solve_args(s, 0, 0)
    basis = solve_basis(model, **kw)
    g = modal_group(basis, kernel_plan(s), 0, 0, 0)
    assert basis.rigid.sum() == 6
    assert g.rows.shape == (basis.omega.size - 5, basis.omega.size)
    # each mode goes to exactly one row; the rigid ones to the same row
    assert np.all(g.rows.sum(axis=0) == 1)
    assert np.count_nonzero(g.rows[:, basis.rigid].any(axis=1)) == 1


def test_every_case_of_the_plan_is_computed(data, result) -> None:
    assert int(data.computed.sum()) == result.study.n_cases
    assert np.all(np.isfinite(data.peak_accel_g.values))
    assert data.band_rms_g.dims == (*CASE_DIMS, "axis", "band")
    assert data.band_rms_g.attrs["units"] == "g"


CATALOGUE = """
[study]
model = "ioc"
[axes]
force = ["foot-pushoff-max", "sources:example"]
at = ["crew", "vertical-lab"]
direction = ["x", "y"]
observe = ["lab", "keel-tip"]
damping = [0.005, 0.02]
[record]
duration = "40 s"
dt = "0.1 s"
max_freq = "2 Hz"
peaks = "exact"
"""


def test_a_source_catalogue_case_equals_analyze_with_sources() -> None:
    """A catalogue is assessed in the frequency domain (microg.analyze(sources=...)); its
    sources carry their own points, so every at/direction holds the same values."""
    r = sweep(loads_study(CATALOGUE, filename="study.toml"))
    ds = r.dataset.load()
    cat = ds.sel(force="sources:example")
    assert bool(cat.computed.all()) and bool(np.isnan(cat.peak_accel_g).all())
    for iz, io in ((0, 0), (1, 1)):
        index = (0, 0, 0, iz, 1, 1, 0, io)
        labels = r.study.case(index)
        fd = r.analyze_case(labels).frequency_domain  # the per-case path, alone
        point = ds.isel(dict(zip(CASE_DIMS, index, strict=True)))
        nb = point.band.size
        assert np.array_equal(point.band.values, fd.center_hz[:nb])
        _close(point.band_rms_g.values, fd.rms_g[0][:, :nb], float(fd.rms_g.max()))
        _close(point.margin.values, np.min(fd.margin[0]), 1.0)
        assert bool(point.complies.values) == bool(fd.complies[0])
        same = ds.band_rms_g.isel(model=0, variant=0, isolator=0, damping=iz, force=1,
                                  observe=io).values  # fmt: skip
        assert np.all(same == same[0, 0])  # at and direction do not apply to a catalogue
    # the time-domain force of the same study still equals analyze (with the modes the
    # study's solve asked for: the analysis' count with sources)
    index = (0, 0, 0, 0, 0, 1, 1, 1)
    labels = r.study.case(index)
    a = r.analyze_case(labels, isolation=False).observations[labels["observe"]].assessment
    point = ds.isel(dict(zip(CASE_DIMS, index, strict=True)))
    _close(point.peak_accel_g.values, a.peak_accel_g, a.peak_accel_g)
    _close(point.band_rms_g.values, a.third_octave.rms_g, float(a.third_octave.rms_g.max()))
    from microg.study.summary import case_command

    cmd = case_command(r, r.study.case((0, 0, 0, 0, 1, 0, 0, 0)))
    assert cmd is not None and "--sources example" in cmd and "--force" not in cmd


def test_a_catalogue_is_refused_with_an_isolator_or_undamped_modes() -> None:
    from microg.errors import InputError

    iso = CATALOGUE.replace("[record]", '[[axes.isolator]]\nname = "soft"\nf_n = "0.1 Hz"\n'
                            "[record]")  # fmt: skip
    with pytest.raises(InputError) as info:
        loads_study(iso, filename="s.toml")
    assert info.value.where == "s.toml: axes.isolator"
    with pytest.raises(InputError) as info:
        loads_study(CATALOGUE.replace("[0.005, 0.02]", "[0.0, 0.02]"), filename="s.toml")
    assert info.value.where == "s.toml: axes.damping[0]"
    with pytest.raises(InputError) as info:
        loads_study(CATALOGUE.replace("sources:example", "sources:nope.toml"), filename="s.toml")
    assert info.value.where == "s.toml: axes.force[1]"


def test_an_imported_modal_models_grids_are_points_of_a_sweep(tmp_path) -> None:
    # grid:N of a NASTRAN OP2 (tests/data/nastran/cla_residual.op2) is a point, as in
    # microg.analyze; every case equals the analysis of it alone (result.analyze_case: the
    # per-case path), to the kernel's 1e-9 (see _close)
    op2 = Path(__file__).resolve().parents[1] / "data" / "nastran" / "cla_residual.op2"
    text = f"""
[study]
name = "modal"
model = {{ path = "{op2.as_posix()}", units = "in, lbf, s" }}
[axes]
force = ["crew-pushoff"]
at = ["grid:3"]
direction = ["x", "z"]
observe = ["grid:3", "grid:24"]
damping = [0.01]
[record]
duration = "60 s"
dt = "0.005 s"
peaks = "exact"
"""
    r = sweep(loads_study(text, filename="modal.toml"))
    ds = r.dataset.load()
    for idx in np.ndindex(*r.study.shape):
        labels = r.study.case(idx)
        ref = r.analyze_case(labels, isolation=False).observations[labels["observe"]]
        got = ds.isel(dict(zip(CASE_DIMS, idx, strict=True)))
        _close(got.peak_accel_g.values, ref.assessment.peak_accel_g, ref.assessment.peak_accel_g)
    bad = text.replace('"grid:24"', '"grid:10"')
    with pytest.raises(InputError, match="grid:N for a grid of the model"):
        loads_study(bad, filename="modal.toml")


def test_a_scatter_is_bounded_and_a_timed_out_one_is_tried_again(monkeypatch) -> None:
    # a scatter racing a worker's restart once waited without end in CI: every attempt
    # carries a timeout, and a timeout (an OSError) is tried again
    import microg.study.run as run

    monkeypatch.setattr("time.sleep", lambda s: None)
    calls: list[dict] = []

    class Client:
        def scatter(self, data, **kwargs):
            calls.append(kwargs)
            if len(calls) == 1:
                raise TimeoutError("scatter timed out")
            return "future"

    assert run._scatter(Client(), [1, 2], True) == "future"
    assert len(calls) == 2  # the timed-out attempt, then one that went
    assert all(c["timeout"] == run.SCATTER_TIMEOUT_S > 0 for c in calls)


def test_row_dft_keeps_small_high_bins_that_a_direct_fft_blurs() -> None:
    """Rows with a large slow content (a drift, a ramp) and a 1e-9 fast tone, combined as a
    case combines them, against an extended-precision FFT of the same rows."""
    from microg.study.kernel import _row_dft

    n = 20001
    t = np.arange(n) * 0.01
    h = np.array(
        [
            np.sin(2 * np.pi * (0.01 + 0.003 * j) * t + j) * (1 + t / 200)
            + 0.05 * (t > 13.0) * (t - 13.0)
            + 1e-9 * np.sin(2 * np.pi * (20 + 3 * j) * t)
            for j in range(8)
        ]
    )
    nk = n // 2 + 1
    xl = h.astype(np.longdouble)
    ref_rows = np.fft.rfft(xl - xl.mean(axis=1, keepdims=True), axis=1)
    c = np.random.default_rng(1).standard_normal((50, 8))
    ref = (c.astype(np.longdouble) @ ref_rows).astype(complex)
    got = c @ _row_dft(h, nk)
    direct = c @ np.fft.rfft(h - h.mean(axis=1, keepdims=True), axis=1)

    def band_error(x: np.ndarray, lo: int, hi: int) -> float:
        e = np.abs(x[:, lo:hi] - ref[:, lo:hi]) ** 2
        return float(np.sqrt(e.sum(axis=1) / (np.abs(ref[:, lo:hi]) ** 2).sum(axis=1)).max())

    fast = int(15.0 * n * 0.01)  # bins above 15 Hz: the tones, 1e-9 of the rows
    # measured 2.3e-14 above 15 Hz (the direct FFT: 2.8e-12, its rounding eps |x| over bins
    # 1e-9 of |x|); 1e-12 is the extended-precision agreement the sweep needs (its band RMS
    # against the analysis' own FFT of the combined record)
    assert band_error(got, fast, nk) < 1e-12 < band_error(direct, fast, nk)
    # below 1 Hz, where the slow content lives, no worse than the direct FFT (~1e-16)
    slow = int(1.0 * n * 0.01)
    assert band_error(got, 1, slow) <= max(2.0 * band_error(direct, 1, slow), 1e-15)
