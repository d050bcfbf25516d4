"""Tests of microg.environment.spectrum: the periodogram and the record's sampling checks.

Reference: scipy.signal.periodogram (the same definition: boxcar window, density scaling,
one-sided).
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.environment.spectrum import acceleration_psd, periodogram
from microg.errors import InputError


@pytest.mark.parametrize("n", [1000, 1001, 4])
def test_periodogram_is_scipys(n):
    # reference: scipy.signal.periodogram with the same definition (boxcar, density, one-sided);
    # both are one FFT, so they agree to rounding (1e-12 of the largest bin)
    from scipy import signal

    rng = np.random.default_rng(n)
    x = rng.standard_normal((3, n))
    f_ref, p_ref = signal.periodogram(x, fs=50.0, window="boxcar", detrend=False, axis=-1)
    f, p = periodogram(x, 50.0)
    assert np.array_equal(f, f_ref)
    assert np.allclose(p, p_ref, rtol=0, atol=1e-12 * p_ref.max())


@pytest.mark.parametrize(
    "bad, message",
    [(np.nan, "not all finite"), (np.inf, "not all finite"), (0.0105, "uniformly spaced")],
)
def test_sample_rate_refuses_nonfinite_and_uneven_times(bad, message):
    """A NaN or inf time anywhere (also mid-record) or an uneven step is refused by name."""
    t = np.arange(100) * 0.01
    t[50] = t[50] + bad if np.isfinite(bad) else bad
    with pytest.raises(InputError, match=message):
        acceleration_psd(t, np.ones(100))
