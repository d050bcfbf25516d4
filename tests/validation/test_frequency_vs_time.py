"""The frequency-domain path against the exact time-domain solver.

References
----------
* microg.dynamics.response.response_at_points: the exact modal response to piecewise-linear
  forces (closed form per segment, tested against solve_ivp and lsim in
  tests/dynamics/test_response.py).
* The first-order hold: the piecewise-linear interpolant of samples of ``e^{i w t}`` taken
  every ``dt`` has, at ``w``, the amplitude ``sinc^2(w dt / 2)`` (``sinc x = sin x / x``; e.g.
  Oppenheim & Schafer, *Discrete-Time Signal Processing*, 3rd ed., Sec. 4.6.3); the sampled
  sine the time solver sees is corrected by that exact factor, everything else at ``w + 2 pi k
  / dt`` is orthogonal to the fundamental over whole periods.
* microg.environment.metrics.assess: the time-domain band RMS (periodogram + Parseval).
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics import frequency as fq
from microg.dynamics.forces import piecewise_linear
from microg.dynamics.modes import solve_modes
from microg.dynamics.response import generalized_force_vector, response_at_points
from microg.environment.metrics import assess
from microg.environment.sources import Source
from microg.environment.vibratory import assess_sources
from microg.models.toml import load_station
from microg.structure.ritz import build_ritz

#: heavy damping so that transients die quickly: the lowest elastic mode (0.14 Hz) decays as
#: exp(-zeta w t), time constant 1 / (0.2 * 0.9 rad/s) = 5.6 s
ZETA = 0.2


@pytest.fixture(scope="module")
def model():
    s = build_ritz(load_station("ioc"), None, 2, gravity_gradient=False)
    return s, solve_modes(s)


def _sine_response(s, m, at, direction, amp, f_hz, phase, per_period, t_end, tout):
    """Acceleration at 'lab' (3, nt) from the exact solver, force A sin-started PWL sine."""
    dt = 1.0 / (f_hz * per_period)
    tb = np.arange(0.0, t_end + dt / 2, dt)
    force = piecewise_linear(tb, amp * np.cos(2 * np.pi * f_hz * tb + phase))
    b = generalized_force_vector(s.point(at).translation, np.asarray(direction, float))
    zeta = np.where(m.rigid, 0.0, ZETA)
    maps = {"lab": s.point("lab").translation}
    r = response_at_points(m.omega, zeta, m.phi, maps, force, b, tout)
    return r["lab"].acceleration, dt


def _hold(f_hz: float, dt: float) -> float:
    """Amplitude of the first-order-hold interpolant of a sampled sine at its own frequency."""
    x = np.pi * f_hz * dt
    return float((np.sin(x) / x) ** 2)


def test_harmonic_steady_state_equals_frf_amplitude(model):
    """Steady state of a long harmonic force (exact PWL solver) = H(w) F, to 1e-6."""
    s, m = model
    f_hz, amp, phase = 0.7, 3.0, -np.pi / 2  # sin start: no jump at t = 0
    direction = np.array([0.3, 0.2, -0.9])
    periods, ns = 10, 97  # analysis window: 10 whole periods, 97 samples per period
    t0 = 130.0  # 23 time constants of the slowest elastic mode: transients below 1e-10
    t0 = np.ceil(t0 * f_hz) / f_hz
    tout = t0 + np.arange(periods * ns) / (ns * f_hz)
    acc, dt = _sine_response(
        s, m, "boom-tip", direction, amp, f_hz, phase, 400, t0 + 11 / f_hz, tout
    )
    # fundamental phasor of the record: DFT over whole periods (with 400 force points and 97
    # output samples per period, the first PWL alias folded onto f is k = 16: below 3e-8)
    A_time = 2.0 / tout.size * (acc @ np.exp(-2j * np.pi * f_hz * tout))
    h = fq.frf(m, ZETA, ["lab"], "boom-tip", direction, [f_hz]).accel_per_n[0, :, 0]
    A_freq = h * amp * np.exp(1j * phase) * _hold(f_hz, dt)
    # tolerance 1e-6 of the largest axis: transients (< 1e-10) and folded aliases (< 3e-8)
    # are far below it
    assert np.max(np.abs(A_time - A_freq)) <= 1e-6 * np.max(np.abs(A_freq))


def test_rss_of_two_independent_sources_equals_time_rms_of_incommensurate_sines(model):
    """Two sines at f1 = 1 Hz and f2 = 2^(1/12) Hz (irrational ratio) at two points, in one
    1/3-octave band: the band mean square is the sum of the two (RSS), as the time average of
    the summed response shows."""
    s, m = model
    f1, f2 = 1.0, 2.0 ** (1.0 / 12.0)
    a1, a2 = 2.0, 1.5
    dw, sw = 2 * np.pi * (f2 - f1), 2 * np.pi * (f2 + f1)
    t0 = 80.0  # 14 time constants: transient amplitudes below 1e-6 (the tolerance is ~1e-3)
    beats = 6  # window: a whole number of beat periods, so the difference-frequency term
    T = beats * 2 * np.pi / dw  # of the cross product averages to 0 exactly (~101 s)
    fs_out = 37.0  # output rate: PWL aliases near 400 f do not fold onto f1 or f2
    n_out = int(fs_out * T)
    dto = T / n_out
    tout = t0 + np.arange(n_out) * dto
    per = 400  # force points per period: PWL aliases at (400 k +- 1) f, amplitude < 7e-6
    t_end = t0 + T + 1
    d1, d2 = np.array([1.0, 0.0, 1.0]), np.array([1.0, 1.0, 1.0])  # both excite every axis
    acc1, dt1 = _sine_response(s, m, "crew", d1, a1, f1, -np.pi / 2, per, t_end, tout)
    acc2, dt2 = _sine_response(s, m, "boom-tip", d2, a2, f2, -np.pi / 2, per, t_end, tout)
    ms_time = np.mean((acc1 + acc2) ** 2, axis=1)  # discrete mean over the window
    # the frequency-domain band mean square, with the hold factor of each sampled sine
    band_lo, band_hi = np.array([0.8913]), np.array([1.122])
    loads = [
        fq.Load("one", "crew", d1, fq.HarmonicLines([a1 * _hold(f1, dt1)], [f1])),
        fq.Load("two", "boom-tip", d2, fq.HarmonicLines([a2 * _hold(f2, dt2)], [f2])),
    ]
    r = fq.band_response(m, ZETA, ["lab"], loads, band_lo, band_hi)
    ms_freq = r.rms_mps2[0, :, 0] ** 2
    c1 = r.source_rms_mps2[0, :, 0, 0] * np.sqrt(2)  # amplitude of each line at each axis
    c2 = r.source_rms_mps2[0, :, 0, 1] * np.sqrt(2)

    # what the discrete window mean still holds besides the two mean squares (Dirichlet
    # kernel bound |mean_k cos(x k + p)| <= 1 / (n |sin(x/2)|)): the sum-frequency cross term
    # c1 c2 cos((w1 + w2) t), each c^2/2 cos(2 w t), and the difference-frequency term, which
    # is 0 over whole beat periods (rounding only); the PWL aliases add their own mean square,
    # (1/400)^4 ~ 4e-11 of a line's per alias pair times |H(400 f) / H(f)|^2 (< 1e4 here)
    def dirichlet(w: float) -> float:
        return 1.0 / (n_out * abs(np.sin(w * dto / 2)))

    tol = (
        c1 * c2 * dirichlet(sw)
        + (c1**2 / 2) * dirichlet(4 * np.pi * f1)
        + (c2**2 / 2) * dirichlet(4 * np.pi * f2)
        + 1e-6 * ms_freq
    )
    assert np.all(np.abs(ms_time - ms_freq) <= tol)
    # and, on the axes both sources reach, the bound rejects a coherent (in-phase) sum by far
    both = np.minimum(c1, c2) > 0.1 * np.maximum(c1, c2)
    coherent = (c1 + c2) ** 2 / 2
    assert np.count_nonzero(both) >= 2
    assert np.all(np.abs(coherent - ms_freq)[both] > 10 * tol[both])


def test_frequency_domain_assessment_equals_time_domain_assessment(model):
    """assess_sources (g RMS per band) = metrics.assess of the steady-state time record of the
    same harmonic source, on whole periods (the line falls on one periodogram bin)."""
    s, m = model
    f_hz, amp = 2.0, 1.0
    per = 100  # PWL aliases at (100 k +- 1) f; sampled at 64 f only k = 64 folds onto the band
    t0 = 130.0
    periods = 40
    fs = 64 * f_hz
    tout = t0 + np.arange(periods * 64) / fs
    acc, dt = _sine_response(
        s, m, "vertical-lab", [0, 1, 0], amp, f_hz, -np.pi / 2, per, t0 + periods / f_hz + 1, tout
    )
    td = assess(tout, acc)
    src = Source("line", "vertical-lab", "y", fq.HarmonicLines([amp * _hold(f_hz, dt)], [f_hz]))
    fd = assess_sources(m, [src], ["lab"], zeta=ZETA)
    k = int(np.flatnonzero((fd.lower_hz <= f_hz) & (fd.upper_hz > f_hz))[0])
    kt = int(np.flatnonzero(np.isclose(td.third_octave.center_hz, fd.center_hz[k]))[0])
    # Parseval on whole periods: the periodogram puts the line's power in one bin; the PWL
    # aliases fold into other bands (the first into this one, k = 64, has 2e-8 of the line's
    # amplitude); transients are below 1e-10: 1e-6
    assert np.allclose(td.third_octave.rms_g[:, kt], fd.rms_g[0, :, k], rtol=1e-6)
