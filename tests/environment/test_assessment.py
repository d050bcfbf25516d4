"""Tests of microg.environment.assessment: assess (PSD, 1/3-octave bands, resolution, DC).

References: Parseval's theorem (mean square of a sum of sinusoids = sum of A^2/2), the RMS of a
sinusoid (A/sqrt 2), the boxcar window's spectral leakage (the integral of sinc^2, from
scipy.special.sici), analytic integrals of constant and sinusoidal accelerations.  The
names are imported from microg.environment.metrics, the path users import them by.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.figure import Figure

from microg.environment.metrics import (
    acceleration_psd,
    assess,
    band_rms,
    json_number,
)
from microg.environment.requirements import (
    BandTable,
    iss_requirement,
    report_flat_requirement,
    ssp41000_limit_g,
    third_octave_bands,
)
from microg.errors import InputError
from microg.plotting.environment import (
    plot_integrated_acceleration,
    plot_psd,
    plot_third_octave,
    plot_time_history,
)
from microg.units import G0

FS, T = 200.0, 100.0  # sampling rate Hz, record length s
TIME = np.arange(int(FS * T)) / FS  # periodogram bins at multiples of 1/T = 0.01 Hz


def test_parseval_band_mean_squares_sum_to_total():
    rng = np.random.default_rng(0)
    # sinusoids on exact bins between 0.2 and 60 Hz (inside the band range 0.1-80 Hz)
    freqs = rng.choice(np.arange(20, 6000), size=40, replace=False) / T
    amps = rng.uniform(0.1, 1.0, size=40)
    phases = rng.uniform(0, 2 * np.pi, size=40)
    a = np.sum(amps[:, None] * np.sin(2 * np.pi * freqs[:, None] * TIME + phases[:, None]), axis=0)
    spec = acceleration_psd(TIME, a)
    bands = third_octave_bands(0.1, 80.0)
    br = band_rms(spec, bands)
    # contiguous bands and the bin-splitting rule make this exact; reference: sum A^2/2
    assert np.sum(br.rms**2) == pytest.approx(np.sum(amps**2) / 2, rel=1e-12)
    assert np.all(br.coverage == 1.0)


@settings(max_examples=30)
@given(
    seed=st.integers(0, 2**31),
    n=st.integers(16, 4000),
    mean=st.floats(-1e3, 1e3),
    cuts=st.lists(st.floats(0.01, 0.99), min_size=0, max_size=8),
)
def test_bands_covering_0_to_nyquist_hold_the_variance(seed, n, mean, cuts):
    # invariant: contiguous bands from 0 Hz to Nyquist hold exactly the variance (Parseval with
    # the mean removed: the DC is the quasi-steady part, in no band); 1e-9 relative plus the
    # rounding of mean**2 against the variance
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.01
    a = mean + rng.standard_normal(n)
    spec = acceleration_psd(t, a)
    edges = np.unique(np.r_[0.0, np.sort(cuts) * spec.nyquist_hz, spec.nyquist_hz])
    bands = BandTable(0.5 * (edges[:-1] + edges[1:]), edges[:-1], edges[1:])
    br = band_rms(spec, bands)
    var = np.var(a)
    assert np.sum(br.rms**2) == pytest.approx(var, rel=1e-9, abs=1e-12 * (mean**2 + var))


@pytest.mark.parametrize("f0", [0.5, 1.0, 6.3, 40.0])
def test_sinusoid_lands_in_its_band(f0):
    amp = 3e-4
    a = amp * np.sin(2 * np.pi * f0 * TIME)
    bands = third_octave_bands(0.01, 100.0)
    br = band_rms(acceleration_psd(TIME, a), bands)
    i = np.argmin(np.abs(bands.center_hz - f0))
    # integer number of cycles: the periodogram puts all power in one bin (exact)
    assert br.rms[0, i] == pytest.approx(amp / np.sqrt(2), rel=1e-12)
    others = np.delete(br.rms[0], i)
    assert np.all(others <= 1e-10 * amp)  # leakage-free: rounding only


def test_welch_sinusoid_band_within_leakage():
    amp, f0 = 1e-3, 5.0
    a = amp * np.sin(2 * np.pi * f0 * TIME)
    spec = acceleration_psd(TIME, a, method="welch", segment_s=20.0)
    br = band_rms(spec, third_octave_bands(1.0, 50.0))
    i = np.argmin(np.abs(br.bands.center_hz - f0))
    # Hann window: main lobe +-2 bins (0.1 Hz) stays inside the 5 Hz band (4.47-5.62 Hz);
    # Welch's density scaling preserves the power of a tone to within ~1 %
    assert br.rms[0, i] == pytest.approx(amp / np.sqrt(2), rel=1e-2)


# ----------------------------------------------------------------------- resolution and DC


def test_band_resolution_rule():
    req = iss_requirement()
    b = int(np.argmin(np.abs(req.bands.center_hz - 1.0)))  # 0.8913-1.122 Hz, B = 0.2307 Hz
    width = req.bands.upper_hz[b] - req.bands.lower_hz[b]
    for record, resolved in ((20.0, False), (25.0, True)):  # B T = 4.61 and 5.77 bins
        t = np.arange(int(record * FS)) / FS
        res = assess(t, np.zeros((3, t.size)))
        assert res.third_octave.n_bins[b] == pytest.approx(width * record, rel=1e-12)
        assert bool(res.third_octave.resolved[b]) is resolved
    # 20 s: the 1 Hz band's reason says how long a record it needs (5 / B = 21.7 s)
    t = np.arange(int(20 * FS)) / FS
    res = assess(t, np.zeros((3, t.size)))
    reason = res.third_octave.reasons[b]
    assert "frequency bins" in reason and f"{5 / width:.4g} s" in reason
    # a band reaching past Nyquist (100 Hz) is unresolved; the one wholly above is dropped
    top = res.third_octave
    assert top.upper_hz[-1] > 100.0 > top.lower_hz[-1] and not top.resolved[-1]
    assert "Nyquist" in top.reasons[-1]
    # Welch: the segment sets the bins, the reason says so
    res = assess(TIME, np.zeros((3, TIME.size)), psd_method="welch", segment_s=10.0)
    assert not res.third_octave.resolved[b] and "Welch" in res.third_octave.reasons[b]


def _sinc2_fraction(nb_lo: float, nb_hi: float, off: float) -> float:
    """Power fraction of a tone in a band, from the boxcar kernel written out bin by bin.

    A tone ``off`` bins above bin 0 spreads its periodogram power as sinc^2(k - off) over bins
    k (the Dirichlet kernel of a long record); the band [nb_lo, nb_hi) in bin units holds
    the bins k that lie in it (PIMS's band sum).
    """
    return float(sum(np.sinc(k - off) ** 2 for k in range(-200, 201) if nb_lo <= k < nb_hi))


def test_five_bins_keep_a_centred_tone_in_its_band():
    # the rule's justification (docs/assessment.md): a tone at a band's centre, anywhere on the
    # bin grid, keeps >= 92 % of its power (96 % of its RMS) in a band of >= 5 bins; in a band
    # of ~1 bin it can keep as little as 50-75 %.  Reference: the boxcar leakage kernel
    # sinc^2 written out bin by bin; 1e-2: the Dirichlet kernel of 2500 samples against sinc,
    # and the tone's negative-frequency image 25 bins away (~1/(pi^2 25) = 4e-3).
    fs, n = 100.0, 2500  # 25 s, df = 0.04 Hz; the 1 Hz band holds 5.77 bins
    df = fs / n
    t = np.arange(n) / fs
    req = iss_requirement()
    b = int(np.argmin(np.abs(req.bands.center_hz - 1.0)))
    lo, hi = req.bands.lower_hz[b], req.bands.upper_hz[b]
    worst = 1.0
    for off in np.linspace(0.0, 1.0, 9):  # the tone from on-bin to one bin higher
        k0 = np.round(0.5 * (lo + hi) / df) - 0.5
        f0 = (k0 + off) * df
        a = np.sqrt(2) * np.sin(2 * np.pi * f0 * t)  # unit RMS
        res = assess(t, a[None, :], transient=None)
        frac = res.third_octave.rms_g[0, b] ** 2 * G0**2
        ref = _sinc2_fraction(lo / df, hi / df, k0 + off)
        assert frac == pytest.approx(ref, abs=1e-2)
        worst = min(worst, ref)
    assert (hi - lo) / df >= 5 and worst >= 0.92
    # one bin (a 5-s record): the same tone keeps much less
    assert min(_sinc2_fraction(-0.577, 0.577, o) for o in np.linspace(0, 0.5, 6)) < 0.8


def test_constant_5ug_on_20s_gives_no_band_rms_and_complies():
    # a constant 5 micro-g (quasi-steady, no vibration) gave 1.5-2.1 micro-g in the
    # 0.0098-0.025 Hz bands and complies = false on a 20-s record
    t = np.arange(2000) * 0.01
    a = np.zeros((3, t.size))
    a[0] = 5e-6 * G0
    res = assess(t, a)
    assert res.mean_accel_g_axis[0] == pytest.approx(5e-6, rel=1e-12)  # reported, not lost
    # no band RMS from DC: only the rounding of (a - mean), ~1e-16 of 5 ug
    assert np.max(res.third_octave.rms_g) <= 1e-15
    assert res.complies is True
    # the lowest bands are listed as unresolved, with the reason; the verdict says what it covers
    d = res.to_dict()
    un = d["third_octave"]["unresolved_bands"]
    assert un[0]["center_hz"] == 0.0098 and "bins" in un[0]["reason"]
    lo, hi = d["third_octave"]["verdict_range_hz"]
    assert lo == pytest.approx(1.122) and hi <= 50.0  # from the 1.25 Hz band to below Nyquist
    assert set(d["third_octave"]["verdict_bands_hz"]) <= set(d["third_octave"]["center_hz"])


def test_dc_bin_excluded_from_every_band_without_demeaning():
    # even a spectrum of the raw record (no demeaning) gives the 0-Hz bin's power to no band
    t = np.arange(2000) * 0.01
    spec = acceleration_psd(t, np.full(t.size, 5e-6 * G0), demean=False)
    assert spec.psd[0, 0] > 0  # the DC power is there ...
    br = band_rms(spec, iss_requirement().bands)
    assert np.max(br.rms) <= 1e-15 * 5e-6 * G0  # ... and in no band (FFT rounding only)


def test_no_resolved_band_is_not_a_pass():
    t = np.arange(10) * 0.1  # 1 s at 10 Hz: no band below Nyquist (5 Hz) holds 5 bins of 1 Hz
    res = assess(t, np.zeros((3, t.size)))
    assert not np.any(res.third_octave.resolved)
    assert res.complies is False and res.worst_band is None
    assert any("cannot be judged" in w for w in res.warnings)


def test_unresolved_exceedance_is_not_a_pass():
    # 100 ug at 0.02 Hz on a 100-s record: far above 1.8 ug, in a band of 0.08 bins.  Every
    # resolved band is clean, but compliance cannot be shown in the unresolved one: not a pass
    a = 100e-6 * G0 * np.sqrt(2) * np.sin(2 * np.pi * 0.02 * TIME)
    res = assess(TIME, a[None, :], transient=None)
    assert res.complies is False
    assert any("not resolved" in w and "0.0197" in w for w in res.warnings)
    # a tone well inside the resolved range, below its limit, still passes
    ok = 2e-6 * G0 * np.sqrt(2) * np.sin(2 * np.pi * 1.0 * TIME)
    assert assess(TIME, ok[None, :], transient=None).complies is True
    # the 0.02 Hz bin lies in the 0.0197 Hz band (0.0176-0.0223 Hz; df = 0.01 Hz) only
    assert res.to_dict()["third_octave"]["unresolved_exceeding_hz"] == [0.0197]


def test_unresolved_exceedances_are_one_warning_listing_the_bands():
    # tones in four unresolved bands of a 20-s record: one warning for the kind, naming each
    t = np.arange(2000) * 0.01
    a = sum(50e-6 * G0 * np.sin(2 * np.pi * f * t) for f in (0.05, 0.1, 0.15, 0.2)) * np.ones(
        (1, 1)
    )
    res = assess(t, a, transient=None)
    over = res.to_dict()["third_octave"]["unresolved_exceeding_hz"]
    assert len(over) >= 4
    lines = [w for w in res.warnings if "not resolved" in w]
    assert len(lines) == 1 and lines[0].startswith(f"{len(over)} bands are not resolved")
    assert all(f"{c:.4g} Hz (" in lines[0] for c in over)


def test_pims_steps_are_the_ssp_curve_near_the_upper_edge():
    # PIMS's steps derive from the SSP 41000 curve evaluated near each band's upper
    # edge.  For the sloped part (bands 12-40) 18 f_c against 16 f_upper: within 1.5 % (the
    # base-10 ratio 10^0.05 = 1.122, and nominal centres rounded by up to 1 %: 0.16 for
    # 10^-0.8 = 0.1585); the flat parts are exactly 1.125 x the curve at the centre.
    req = iss_requirement()
    c, hi, lim = req.bands.center_hz, req.bands.upper_hz, req.limit_g
    sloped = (c >= 0.125) & (c <= 81.0)
    assert np.allclose(lim[sloped], ssp41000_limit_g(hi[sloped]), rtol=1.5e-2)
    assert np.allclose(lim[~sloped], 1.125 * ssp41000_limit_g(c[~sloped]), rtol=1e-12)


def test_margin_and_pass_fail():
    limit_1hz = 18e-6 * G0  # m/s^2 RMS limit of the 1 Hz band
    for factor, expected in ((0.5, True), (2.0, False)):
        a = np.sqrt(2) * factor * limit_1hz * np.sin(2 * np.pi * 1.0 * TIME)
        res = assess(TIME, np.vstack([a, 0 * a, 0 * a]))
        assert res.complies is expected
        assert res.worst_band.center_hz == pytest.approx(1.0)
        assert res.worst_band.axis == "x"
        assert res.worst_band.margin == pytest.approx(1 / factor, rel=1e-10)
        assert res.rms_accel_g == pytest.approx(factor * 18e-6, rel=1e-9)


def test_report_flat_requirement_peak():
    a = 2e-5 * G0 * np.exp(-(((TIME - 50) / 0.2) ** 2))  # short pulse of 2e-5 g
    res = assess(TIME, a, report_flat_requirement(), axes=("z",))
    assert res.peak_accel_g == pytest.approx(2e-5, rel=1e-6)
    assert res.peak_limit_g == 1e-5
    assert res.complies is False


def test_requirement_by_name():
    a = np.zeros((3, TIME.size))
    assert assess(TIME, a, "ssp41000").requirement == "ssp41000"
    with pytest.raises(InputError, match="unknown requirement"):
        assess(TIME, a, "nope")


# ----------------------------------------------------------------------------- integrals


def test_integrated_both_named_in_output():
    a = np.vstack([1e-4 * np.sin(2 * np.pi * TIME / 20), 0 * TIME, 0 * TIME])
    d = assess(TIME, a).to_dict()
    assert "integrated_accel" not in d  # the old, misnamed key
    sl, pb = d["integrated_accel_sliding"], d["integrated_accel_pims"]
    assert sl["window_s"] == 10.0 and pb["window_s"] == 10.0
    assert pb["block_samples"] == 2000 and pb["n_blocks"] == 10
    # sliding over every start is the worst window: at least PIMS's block maximum
    assert sl["max_mps_axis"]["x"] >= pb["max_mps_axis"]["x"]
    short = assess(TIME[:1000], a[:, :1000]).to_dict()
    assert short["integrated_accel_pims"] is None  # 5 s: no complete block, said so
    assert any("no PIMS integrated" in w for w in short["warnings"])


# ----------------------------------------------------------------------- transient criteria


def test_transient_criteria_verdict():
    from microg.environment.transient import (
        TransientCriteria,
        TransientCriterion,
        transient_criteria,
    )

    # a 1-s push of 400 ug: peak within 1000 ug, integral 400 ug s >> 10 ug s
    a = np.zeros((3, TIME.size))
    a[0, (TIME >= 10) & (TIME < 11)] = 400e-6 * G0
    lax = report_flat_requirement(level_g=1.0)  # no band or peak limit in the way
    res = assess(TIME, a, lax, transient="iss")
    tr = res.to_dict()["transient"]
    assert tr["criteria"] == "iss" and tr["verified"] is False
    peak, integ = tr["checks"]
    assert peak["value_g"] == pytest.approx(400e-6, rel=1e-12) and peak["complies"] is True
    # reference: 400 ug x 1 s (exact for a rectangle on the grid, trapezoid edges: +-1 dt/2)
    assert integ["value_ug_s"] == pytest.approx(400.0, rel=1e-2) and integ["complies"] is False
    assert integ["verified"] is False and integ["enters_verdict"] is False
    assert "unverified" in integ["source"]
    # unverified: reported once, as its criterion (not repeated in warnings), not in complies
    rep = [c for c in res.criteria if c.name == "integrated-10ug-s-per-axis-10s"]
    assert len(rep) == 1 and rep[0].status == "reported" and rep[0].complies is False
    assert not any("integrated-10ug-s" in w for w in res.warnings)
    assert res.transient.complies is False and res.transient.complies_verified is True
    # the same limit, verified (a user's sourced criterion), decides the verdict
    ok = assess(TIME, a, lax, transient=None).complies
    crit = transient_criteria("iss").criteria[1]
    mine = TransientCriteria(
        "mine", "", (TransientCriterion(crit.name, crit.quantity, crit.limit, 10.0, "doc", True),)
    )
    assert assess(TIME, a, lax, transient=mine).complies is False and ok is True


def test_transient_criteria_file_errors(tmp_path):
    from microg.environment.transient import load_transient_criteria

    p = tmp_path / "c.toml"
    p.write_text('[[set]]\nname = "a"\n[[set.criterion]]\nname = "p"\nquantity = "peak_axis"\n')
    with pytest.raises(InputError, match=r"criterion\[0\]\.limit_ug"):
        load_transient_criteria(p)
    p.write_text(
        '[[set]]\nname = "a"\n[[set.criterion]]\nname = "p"\nquantity = "peak_axis"\n'
        'limit_ug = 5.0\nsource = "x"\nverified = true\n'
    )
    assert load_transient_criteria(p).criteria[0].limit == pytest.approx(5e-6 * G0)


# ------------------------------------------------------------------------ outputs and units


def test_to_dict_units_inf_and_json():
    a = np.vstack([1e-5 * np.sin(2 * np.pi * 2.0 * TIME), 0 * TIME, 0 * TIME])
    res = assess(TIME, a)
    d = res.to_dict()
    text = json.dumps(d, allow_nan=False)  # strictly JSON: no NaN or Infinity tokens
    assert "Infinity" not in text
    to = d["third_octave"]
    assert {"center_hz", "lower_hz", "upper_hz", "rms_g", "limit_g", "margin", "complies"} - set(
        to
    ) == {"complies"}
    assert len(to["lower_hz"]) == len(to["center_hz"]) == len(to["upper_hz"])
    # y and z carry no power: their margins are infinite, written "inf" (documented)
    assert set(to["margin_axis"]["y"]) == {"inf"}
    assert json_number(np.inf) == "inf" and json_number(np.nan) is None
    # every dimensional key says its unit (suffix rule of the developers' guide)
    units = ("_g", "_hz", "_s", "_mps", "_g_axis", "_mps_axis", "_ug_s")
    plain = {
        "third_octave", "requirement", "requirement_source", "complies", "worst_band", "record",
        "integrated_accel_sliding", "integrated_accel_pims", "transient", "warnings",
        "criteria", "verdict",
    }  # fmt: skip
    for k in d:
        assert k in plain or k.endswith(units), k
    for k in d["record"]:
        assert k.endswith(("_s", "_hz")) or k in ("samples", "psd_method", "demeaned"), k


def test_to_xarray_dims_and_units():
    a = np.vstack([1e-5 * np.sin(2 * np.pi * 2.0 * TIME), 0 * TIME, 0 * TIME])
    res = assess(TIME, a)
    ds = res.to_xarray()
    assert ds["rms_g"].dims == ("axis", "center_hz") and ds["rms_g"].attrs["units"] == "g"
    assert ds["psd_g2_per_hz"].dims == ("axis", "freq_hz")
    assert ds["center_hz"].attrs["units"] == "Hz"
    assert np.array_equal(ds["rms_g"].values, res.third_octave.rms_g)
    assert ds.attrs["requirement"] == "iss"


def test_nonfinite_and_nonuniform_rejected():
    t = np.sort(np.random.default_rng(1).uniform(0, 10, 100))
    with pytest.raises(InputError, match="uniformly"):
        acceleration_psd(t, np.sin(t))
    a = np.zeros((3, TIME.size))
    a[1, 7] = np.nan
    with pytest.raises(InputError, match="not finite"):
        assess(TIME, a)


def test_plots_return_figures_and_steps_on_band_edges():
    a = np.vstack([np.sin(TIME), np.cos(TIME), 0 * TIME]) * 1e-5
    res = assess(TIME, a)
    figs = [
        plot_time_history(TIME, a),
        plot_psd(res.spectrum),
        plot_third_octave(res),
        plot_integrated_acceleration(TIME, a),
        res.plot(),
    ]
    for fig in figs:
        assert isinstance(fig, Figure)
        assert len(fig.axes[0].lines) >= 3
    # the limit is drawn as steps from each band's lower to its upper edge
    line = next(ln for ln in figs[2].axes[0].lines if ln.get_label() == "limit")
    x, y = line.get_xdata(), line.get_ydata()
    to = res.third_octave
    assert np.allclose(x[0::2], to.lower_hz) and np.allclose(x[1::2], to.upper_hz)
    assert np.allclose(y[0::2], to.limit_g * 1e6) and np.allclose(y[1::2], to.limit_g * 1e6)


def test_overlay_of_a_prediction_and_a_measurement():
    from microg.plotting.environment import plot_overlay

    pred = assess(TIME, np.vstack([1e-5 * np.sin(2 * np.pi * 2.0 * TIME), 0 * TIME, 0 * TIME]))
    rng = np.random.default_rng(2)
    meas = assess(TIME, 1e-6 * rng.standard_normal((3, TIME.size)), transient_basis="pims")
    fig = plot_overlay(pred, meas, labels=("IOC lab", "SAMS 121f03"))
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    labels = [ln.get_label() for ln in fig.axes[0].lines]
    assert {"IOC lab x", "SAMS 121f03 x", "limit"} <= set(labels)
    assert len(fig.axes[1].lines) == 2  # one PSD each, the worst axis by RMS
    assert isinstance(pred.plot("psd"), Figure)
