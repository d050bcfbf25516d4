"""Tests of microg.environment.integrated: the sliding and the PIMS integrated accelerations.

References: analytic integrals of constant and sinusoidal accelerations, and an explicit
block-by-block implementation of PIMS's ``file_trapz`` (baluneboy/pims, transient/main.py).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from microg.environment.integrated import integrated_acceleration, integrated_acceleration_pims


def test_integrated_acceleration_sliding():
    t = np.linspace(0, 30, 3001)
    ia = integrated_acceleration(t, np.full(t.size, 0.2))
    assert ia.max_mps[0] == pytest.approx(2.0, rel=1e-12)  # 0.2 m/s^2 * 10 s, exact
    # sinusoid of period 20 s: the 10-s window over half a period gives 2 A / w
    w, amp = 2 * np.pi / 20, 1e-4
    ia = integrated_acceleration(t, amp * np.sin(w * t))
    # trapezoid error (w dt)^2 / 12 = 8e-7 relative on a 0.01 s grid
    assert ia.max_mps[0] == pytest.approx(2 * amp / w, rel=2e-6)
    short = integrated_acceleration(t[:501], np.ones(501))
    assert short.window_s == pytest.approx(5.0) and short.max_mps[0] == pytest.approx(5.0)


def _pims_file_trapz_reference(a: np.ndarray, fs: float, sec: float) -> np.ndarray:
    """PIMS's file_trapz written out block by block (transient/main.py of baluneboy/pims)."""
    b = a - a.mean(axis=1, keepdims=True)  # "demean signal" over the whole file
    dt = 1.0 / fs
    nt = int(np.ceil(sec / dt))
    out = []
    start = 0
    while start + nt <= b.shape[1]:  # the incomplete last block is deleted
        out.append([integrate.trapezoid(row[start : start + nt], dx=dt) for row in b])
        start += nt
    return np.array(out).T


def test_integrated_acceleration_pims_matches_block_reference():
    rng = np.random.default_rng(3)
    fs = 142.0  # the sample rate of a SAMS 121f03 PAD file
    t = np.arange(int(47.3 * fs)) / fs  # 4 complete 10-s blocks and a partial one
    a = 1e-5 * rng.standard_normal((3, t.size)) + np.array([[3e-4], [0.0], [-1e-4]])
    got = integrated_acceleration_pims(t, a, 10.0, sample_rate_hz=fs)
    ref = _pims_file_trapz_reference(a, fs, 10.0)
    assert got.block_samples == 1420 and got.n_blocks == 4
    # same arithmetic in another order: 1e-12 of the block integrals' scale
    scale = np.max(np.abs(ref))
    assert np.allclose(got.delta_v, ref, rtol=0, atol=1e-12 * scale)
    assert np.allclose(got.max_mps, np.max(np.abs(ref), axis=1), rtol=1e-12)
    # a constant is the quasi-steady part: demeaned, it integrates to nothing in PIMS's
    # definition, while microg's sliding window keeps it (conservative)
    c = np.full((1, t.size), 3e-4)
    assert integrated_acceleration_pims(t, c, 10.0).max_mps[0] == pytest.approx(0.0, abs=1e-18)
    assert integrated_acceleration(t, c, 10.0).max_mps[0] == pytest.approx(3e-3, rel=1e-9)
