"""PIMS-style interval products (microg.environment.intervals) against an independent reference.

The reference is written out straightforwardly here: a loop over the intervals, scipy.signal's
periodogram (or Welch) on each interval and axis, the bin-sharing band integral as an explicit
loop over bins, hand-made percentiles (sorted values, linear interpolation between ranks), and
explicit min/max/mean.  Both sides do the same arithmetic in another order: 1e-10 relative.
"""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure
from scipy import signal

from microg.environment.intervals import PIMS_PERCENTILES, interval_products
from microg.environment.requirements import iss_requirement
from microg.errors import InputError
from microg.units import G0

FS = 20.0
RNG = np.random.default_rng(12)
N = int(1037 * FS)  # 10 intervals of 100 s and an incomplete 37 s
TIME = np.arange(N) / FS
ACCEL = 1e-5 * G0 * RNG.standard_normal((3, N)) + np.array([[2e-6], [0.0], [-1e-6]]) * G0


def _band_power_loop(freq: np.ndarray, psd: np.ndarray, lo: float, hi: float) -> float:
    """Bin k's power psd_k df where lo <= f_k < hi (every bin up to Nyquist when hi reaches
    it); no 0 Hz."""
    df = freq[1] - freq[0]
    nyq = FS / 2
    total = 0.0
    for k in range(1, freq.size):
        if lo <= freq[k] < hi or (hi >= nyq and lo <= freq[k]):
            total += psd[k] * df
    return total


def _percentile_by_hand(values: np.ndarray, p: float) -> float:
    v = np.sort(values)
    rank = p / 100 * (v.size - 1)
    i = int(np.floor(rank))
    j = min(i + 1, v.size - 1)
    return float(v[i] + (rank - i) * (v[j] - v[i]))


def _reference(interval_s: float, method: str, segment_s: float | None = None):
    per = int(round(interval_s * FS))
    ni = N // per
    req = iss_requirement()
    keep = req.bands.lower_hz < FS / 2
    lo, hi = req.bands.lower_hz[keep], req.bands.upper_hz[keep]
    nyq = FS / 2
    rms = np.zeros((ni, 3, lo.size))
    stats = np.zeros((ni, 3, 3))  # min, max, mean
    for i in range(ni):
        chunk = ACCEL[:, i * per : (i + 1) * per]
        for ax in range(3):
            x = chunk[ax]
            stats[i, ax] = x.min(), x.max(), x.mean()
            if method == "periodogram":
                f, p = signal.periodogram(x - x.mean(), fs=FS, window="boxcar", detrend=False)
            else:
                nseg = int(round(segment_s * FS))
                f, p = signal.welch(
                    x, fs=FS, window="hann", nperseg=nseg, noverlap=nseg // 2, detrend="constant"
                )
            for b in range(lo.size):
                rms[i, ax, b] = np.sqrt(_band_power_loop(f, p, lo[b], min(hi[b], nyq))) / G0
    return rms, stats, ni


def test_interval_band_rms_percentiles_and_stats_against_reference():
    res = interval_products(TIME, ACCEL, "iss", interval_s=100.0)
    ref, stats, ni = _reference(100.0, "periodogram")
    b = res.bands
    assert b.rms_g.shape == ref.shape and ni == 10
    assert np.allclose(b.rms_g, ref, rtol=1e-10, atol=0)
    rss = np.sqrt(ref[:, 0] ** 2 + ref[:, 1] ** 2 + ref[:, 2] ** 2)
    assert np.allclose(b.rss_g, rss, rtol=1e-10)
    assert b.percentiles == PIMS_PERCENTILES
    for k, p in enumerate(PIMS_PERCENTILES):
        for ax in range(3):
            for band in range(ref.shape[2]):
                want = _percentile_by_hand(ref[:, ax, band], p)
                assert b.percentile_rms_g[k, ax, band] == pytest.approx(want, rel=1e-10)
        for band in range(ref.shape[2]):
            assert b.percentile_rms_g[k, 3, band] == pytest.approx(
                _percentile_by_hand(rss[:, band], p), rel=1e-10
            )
    # fraction of intervals over the limit, counted by hand
    lim = iss_requirement().limit_g[: ref.shape[2]]
    assert np.array_equal(b.exceed_fraction, np.mean(ref > lim, axis=0))
    # interval min / max / mean of the raw acceleration
    assert np.allclose(res.stats.min_g, stats[:, :, 0] / G0, rtol=1e-12)
    assert np.allclose(res.stats.max_g, stats[:, :, 1] / G0, rtol=1e-12)
    assert np.allclose(res.stats.mean_g, stats[:, :, 2] / G0, rtol=1e-10)
    assert res.dropped_s == pytest.approx(37.0)
    assert np.allclose(b.t_start_s, np.arange(10) * 100.0)


def test_welch_option_against_reference():
    res = interval_products(
        TIME, ACCEL, "iss", interval_s=200.0, psd_method="welch", segment_s=50.0
    )
    ref, _, _ = _reference(200.0, "welch", 50.0)
    assert np.allclose(res.bands.rms_g, ref, rtol=1e-10)
    assert res.to_dict()["psd_method"] == "welch"


def test_resolution_per_interval():
    # a 100-s interval resolves bands from B >= 5 / 100 s = 0.05 Hz (0.25 Hz band, B = 0.058)
    res = interval_products(TIME, ACCEL, interval_s=100.0)
    c = res.bands.bands.center_hz
    assert not res.bands.resolved[c == 0.2][0] and res.bands.resolved[c == 0.25][0]


def test_band_limited_rms_and_cumulative_against_loop():
    res = interval_products(TIME, ACCEL, interval_s=100.0, band_hz=(0.5, 2.0))
    per = 2000
    for i in (0, 7):
        for ax in range(3):
            x = ACCEL[ax, i * per : (i + 1) * per]
            f, p = signal.periodogram(x - x.mean(), fs=FS, window="boxcar", detrend=False)
            want = np.sqrt(_band_power_loop(f, p, 0.5, 2.0)) / G0
            assert res.band_limited.rms_g[i, ax] == pytest.approx(want, rel=1e-10)
    # cumulative RMS at Nyquist is the RMS of the demeaned record (Parseval); at f, the loop
    cum = res.cumulative
    var = np.var(ACCEL, axis=1)
    assert np.allclose(cum.rms_g[:, -1], np.sqrt(var) / G0, rtol=1e-10)
    f, p = signal.periodogram(ACCEL[1] - ACCEL[1].mean(), fs=FS, window="boxcar", detrend=False)
    k = 5000
    assert cum.rms_g[1, k] == pytest.approx(np.sqrt(np.sum(p[1 : k + 1]) * (f[1] - f[0])) / G0)
    assert np.allclose(cum.rss_g, np.sqrt(np.sum(cum.rms_g**2, axis=0)), rtol=1e-12)


def test_spectrogram_finds_a_tone():
    t = np.arange(int(400 * FS)) / FS
    a = np.zeros((3, t.size))
    a[2] = np.sqrt(2) * 1e-5 * G0 * np.sin(2 * np.pi * 3.0 * t)  # 10 ug RMS at 3 Hz
    res = interval_products(t, a, interval_s=100.0, spectrogram_segment_s=10.0)  # df = 0.1 Hz
    sp = res.spectrogram
    assert sp.psd_g2_per_hz.shape == (3, sp.freq_hz.size, sp.time_s.size)
    z = sp.psd_g2_per_hz[2]
    assert np.all(sp.freq_hz[np.argmax(z, axis=0)] == pytest.approx(3.0))
    # density scaling: the PSD integrates to the tone's mean square in every segment (Hann
    # main lobe inside the range; 1e-3: the Hann sidelobes' share beyond +-4 bins)
    df = sp.freq_hz[1] - sp.freq_hz[0]
    ms = np.sum(z, axis=0) * df
    assert np.allclose(ms, 1e-10, rtol=1e-3)


def test_outputs_xarray_dict_plots():
    res = interval_products(TIME, ACCEL, interval_s=100.0)
    d = res.to_dict()
    assert d["n_intervals"] == 10 and d["interval_s"] == 100.0
    to = d["third_octave"]
    assert set(to["percentile_rms_g"]) == {"x", "y", "z", "rss"}
    assert len(to["percentile_rms_g"]["rss"]) == 5
    assert len(d["cumulative_rms"]["freq_hz"]) == len(to["center_hz"])
    ds = res.to_xarray()
    assert ds["rms_g"].dims == ("interval", "axis", "center_hz")
    assert ds["rms_g"].attrs["units"] == "g" and ds["interval"].attrs["units"] == "s"
    assert ds["spectrogram_g2_per_hz"].dims == ("axis", "spec_freq_hz", "spec_time_s")
    for fig in (
        res.plot(),
        res.bands.plot(row="x"),
        res.stats.plot(),
        res.band_limited.plot(),
        res.spectrogram.plot(),
        res.cumulative.plot(),
    ):
        assert isinstance(fig, Figure) and fig.axes


def test_bad_interval():
    with pytest.raises(InputError, match="shorter than one interval"):
        interval_products(TIME[:100], ACCEL[:, :100], interval_s=100.0)
    with pytest.raises(InputError, match="not positive"):
        interval_products(TIME, ACCEL, interval_s=-1.0)
