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


def test_band_weights_integrate_the_piecewise_constant_psd_exactly():
    # independent reference: a plain loop over bins and bands of the overlap length of each
    # band with each bin [f_k - df/2, f_k + df/2] (clipped to [0, Nyquist]), the DC bin left
    # out; rounding of a sum of a few thousand terms: 1e-12 relative
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
            lo_b, hi_b = min(lo[b], nyq), min(hi[b], nyq)
            for k in range(1, nf):
                a, c = max(f[k] - df / 2, 0.0), min(f[k] + df / 2, nyq)
                ov = max(0.0, min(c, hi_b) - max(a, lo_b))
                if c > a:
                    ref[:, b] += psd[:, k] * df * ov / (c - a)
        got = np.asarray(band_weights(f, df, nyq, bands) @ psd.T).T
        np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-15 * ref.max())
        spec = Spectrum(f, psd, df, nyq, "periodogram")
        keep = lo < nyq
        np.testing.assert_allclose(
            band_rms(spec, bands).rms, np.sqrt(ref[:, keep]), rtol=1e-12, atol=1e-15
        )


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
