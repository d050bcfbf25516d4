"""Tests of microg.environment.bands: the band integration as a linear map, its fast path.

References: a plain loop over bins and bands (the overlap of each band with each bin), the
definition ``band_rms(acceleration_psd(...))``, and the exact mean square of a bin-centred
sine (A^2 / 2).
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.environment.bands import _band_weights, band_mean_square, band_rms, band_weights
from microg.environment.requirements import BandTable, third_octave_bands
from microg.environment.spectrum import Spectrum, acceleration_psd


def test_band_weights_sum_the_bins_whose_frequency_lies_in_the_band():
    # independent reference: a plain loop over bins and bands adding psd_k df of each bin k
    # >= 1 with lo <= f_k < hi (PIMS's band sum; a band reaching Nyquist also holds the
    # Nyquist bin, a band from Nyquist up holds nothing); rounding of a sum of a few thousand
    # terms: 1e-12 relative
    rng = np.random.default_rng(7)
    for nf, df in ((513, 0.05), (1000, 0.013)):
        f = np.arange(nf) * df
        nyq = f[-1] if nf % 2 else f[-1] + df / 2
        psd = rng.random((3, nf))
        lo = np.r_[0.0, 0.5 * df, rng.uniform(0, nyq, 8), nyq - df / 3, nyq]
        hi = lo + np.r_[df / 4, 3 * df, rng.uniform(0.01, 3.0, 8), df, 1.0]
        bands = BandTable(np.sqrt(lo * hi + 1e-9), lo, hi)
        ref = np.zeros((3, lo.size))
        for b in range(lo.size):
            for k in range(1, nf):
                inside = lo[b] <= f[k] < hi[b] or (hi[b] >= nyq and lo[b] <= f[k] <= nyq)
                if inside and lo[b] < nyq:
                    ref[:, b] += psd[:, k] * df
        got = np.asarray(band_weights(f, df, nyq, bands) @ psd.T).T
        np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-15 * ref.max())
        spec = Spectrum(f, psd, df, nyq, "periodogram")
        keep = lo < nyq
        np.testing.assert_allclose(
            band_rms(spec, bands).rms, np.sqrt(ref[:, keep]), rtol=1e-12, atol=1e-15
        )


@pytest.mark.parametrize(
    "where",
    [
        "on the lower edge",
        "beside the lower edge",
        "mid-band",
        "beside the upper edge",
        "between two edges",
    ],
)
def test_a_tone_on_a_bin_keeps_its_whole_rms_in_one_band(where):
    """A bin-centred tone's band RMS is its RMS, wherever the band edges fall.

    Reference: the tone's RMS A / sqrt(2) (a sine on a bin of a boxcar record has no leakage,
    so its whole power is in that one bin).  Edges put on the tone's bin, one bin beside it, or
    through the bin's interval (0.3 bin above the tone); the neighbouring band gets nothing.
    Tolerance 1e-12: rounding of the DFT of 30,000 samples.
    """
    fs, n, amp = 100.0, 30000, 2.0  # 300 s
    df = fs / n
    t = np.arange(n) / fs
    k = 34  # 0.11333 Hz
    f0 = k * df
    shift = {
        "on the lower edge": 0.0,
        "beside the lower edge": 1.0,
        "mid-band": 3.0,
        "beside the upper edge": 5.0,
        "between two edges": 0.5,
    }[where]
    edges = (k - shift + np.array([-6.0, 0.0, 6.0])) * df  # two bands of 6 bins
    if where == "between two edges":
        edges = (k + np.array([-6.0, 0.3, 6.3])) * df  # an edge through the tone's bin
    bands = BandTable(np.sqrt(edges[:-1] * edges[1:]), edges[:-1], edges[1:])
    x = amp * np.sin(2 * np.pi * f0 * t)
    ms = band_mean_square(t, x, bands)[0]
    br = band_rms(acceleration_psd(t, x), bands).rms[0]
    hold = int(np.searchsorted(edges, f0, side="right") - 1)
    assert ms[hold] == pytest.approx(amp**2 / 2, rel=1e-12)
    assert br[hold] == pytest.approx(amp / np.sqrt(2), rel=1e-12)
    assert ms[1 - hold] <= 1e-20 * amp**2


def test_a_band_edge_tone_fails_the_band_it_lies_in():
    """2.4 micro-g RMS at 0.11333 Hz (a bin of a 300-s record) in the 0.1122-0.1413 Hz band
    (limit 2.25 micro-g): the band holds all 2.4 micro-g and fails (margin 0.94), and the
    0.1 Hz band holds none of it.  Reference: the tone's RMS; 1e-9 for the FFT's rounding.
    """
    from microg.environment.metrics import assess
    from microg.units import G0

    fs, n = 100.0, 30000
    t = np.arange(n) / fs
    f0 = 34 * fs / n
    x = np.zeros((3, n))
    x[0] = 2.4e-6 * G0 * np.sqrt(2) * np.sin(2 * np.pi * f0 * t)
    res = assess(t, x, transient=None)
    to = res.third_octave
    b = int(np.argmin(np.abs(to.center_hz - 0.125)))
    assert to.lower_hz[b] < f0 < to.upper_hz[b]
    assert to.rms_g[0, b] == pytest.approx(2.4e-6, rel=1e-9)
    assert to.margin[0, b] == pytest.approx(to.limit_g[b] / 2.4e-6, rel=1e-9)
    assert to.margin[0, b] < 1
    assert to.rms_g[0, b - 1] < 1e-6 * 2.4e-6
    assert res.complies is False


@pytest.mark.parametrize("n", [20001, 4096, 1000, 17])
@pytest.mark.parametrize("wide", [False, True])
def test_band_mean_square_equals_the_periodogram_band_sum(n, wide):
    """Both paths (direct DFT of a few bins; the whole FFT) give W @ periodogram.

    Reference: ``band_rms(acceleration_psd(...))`` (numpy's FFT), the definition itself.
    Tolerance 1e-11 relative to the largest band: the direct sums of n terms round to
    ~sqrt(n) eps of |x|^2 n.
    """
    rng = np.random.default_rng(n)
    fs = 100.0
    t = np.arange(n) / fs
    x = rng.standard_normal((7, n)) + 3.0  # a mean, which neither path counts
    df = fs / n
    if wide:
        bands = third_octave_bands(0.01, 50.0)  # many bins: the whole-FFT path
    else:  # three narrow bands, a few bins each, edges between bins: the direct path
        lo = np.array([3.3, 11.1, 20.05]) * df + 0.1
        bands = BandTable(lo, lo, lo + np.array([4.6, 2.3, 9.9]) * df)
    got = band_mean_square(t, x, bands)
    ref = band_rms(acceleration_psd(t, x), bands).rms ** 2
    keep = bands.lower_hz < fs / 2
    assert got.shape == (7, bands.center_hz.size)
    np.testing.assert_allclose(got[:, keep], ref, rtol=0, atol=1e-11 * ref.max())
    assert np.all(got[:, ~keep] == 0.0)


def test_band_mean_square_of_a_bin_centred_sine_is_half_its_square():
    """Exact: a sine of amplitude A on bin k of a boxcar record has mean square A^2 / 2.

    All of it falls in bin k (no leakage), so any band holding the whole bin returns
    A^2 / 2 to rounding (1e-12).
    """
    n, fs, k, amp = 20001, 100.0, 40, 3.0
    t = np.arange(n) / fs
    f0 = k * fs / n
    x = amp * np.sin(2 * np.pi * f0 * t)
    bands = BandTable(np.array([f0]), np.array([f0 * 0.9]), np.array([f0 * 1.1]))
    got = band_mean_square(t, x, bands)
    assert got[0, 0] == pytest.approx(amp**2 / 2, rel=1e-12)


def test_band_weights_are_kept_read_only_and_equal_a_fresh_computation():
    """The kept map is the computed one (reference: the uncached kernel) and cannot change."""
    f = np.fft.rfftfreq(2001, 0.01)
    bands = third_octave_bands(0.1, 40.0)
    w1 = band_weights(f, f[1], 50.0, bands)
    w2 = band_weights(f.copy(), f[1], 50.0, bands)
    assert w2 is w1  # the same inputs: the kept map
    ref = _band_weights(f, f[1], 50.0, bands.lower_hz, bands.upper_hz)
    assert (w1 != ref).nnz == 0
    with pytest.raises(ValueError):
        w1.data[0] = 1.0
    other = band_weights(f, f[1], 50.0, third_octave_bands(0.2, 40.0))
    assert other is not w1 and other.shape[0] < w1.shape[0]
