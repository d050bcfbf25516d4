"""The factored exponential tables of the response kernel (microg.dynamics.oscillator.exp_table).

Reference: numpy's direct complex exponential of the same arguments, exp(lam (t0 + i step)).
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from microg.dynamics import oscillator

EPS = np.finfo(float).eps


@settings(max_examples=60, deadline=None)
@given(
    sigma=st.floats(0.0, 10.0),
    omega_d=st.floats(0.0, 300.0),
    t0=st.floats(0.0, 300.0),
    step=st.floats(1e-4, 2.0),
    count=st.integers(1, 400),
)
def test_exp_table_equals_direct_exponentials(sigma, omega_d, t0, step, count):
    lam = np.array([[-sigma + 1j * omega_d], [-0.5 * sigma + 0.3j * omega_d], [0.0 + 0j]])
    got = oscillator.exp_table(lam, t0, step, count)
    times = t0 + np.arange(count) * step
    arg = lam * times
    ref = np.exp(arg)
    decayed = arg.real < -oscillator.DECAYED
    # set to exactly 0 below exp(-600) (the kernel's convention: 1e-261 of the start)
    assert np.all(got[decayed] == 0.0)
    # never a subnormal number (they make the kernel's arithmetic ~100x slower)
    mag = np.abs(got)
    assert np.all((mag == 0.0) | (mag >= np.finfo(float).tiny))
    # elsewhere: a product of two exponentials whose arguments split the time t0 + i1 q step +
    # i2 step differently from the direct t0 + i step: a few roundings of the value (8 eps) plus
    # the rounding of the time in the phase and decay, |lam| ulp(t) (4 ulps of the sum)
    keep = ~decayed
    tol = (8 * EPS + 4 * np.abs(lam) * EPS * np.maximum(times, 1.0)) * np.abs(ref)
    assert np.all(np.abs(got - ref)[keep] <= tol[keep] + 1e-300)
