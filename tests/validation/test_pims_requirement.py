"""The ISS vibratory requirement exactly as NASA's PIMS group codes it.

Reference: ``get_oto_iss_req_steps()`` in ``otorunhist/main.py`` of the public repository
baluneboy/pims (commit 5a07e02588b1b7c8ebf7458b10e81b8ecf84ad13, the newest snapshot; the
function is unchanged since commit da2be21bfce704a0e0a15f8ac06a2158019692ca, 2019-01-11;
``transient/main.py`` holds an identical copy).  The rows below are typed from that code
(lower edge Hz, centre Hz, upper edge Hz, limit g RMS), not regenerated from a formula.
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.environment.metrics import assess
from microg.environment.requirements import (
    iss_requirement,
    requirement,
    ssp41000_limit_g,
    ssp41000_requirement,
)
from microg.errors import InputError
from microg.units import G0

# get_oto_iss_req_steps(), baluneboy/pims otorunhist/main.py, as typed from the code
PIMS_MOTO = np.array(
    [
        [0.0088, 0.0098, 0.0110, 1.8000e-006],
        [0.0110, 0.0124, 0.0139, 1.8000e-006],
        [0.0139, 0.0156, 0.0175, 1.8000e-006],
        [0.0175, 0.0197, 0.0221, 1.8000e-006],
        [0.0221, 0.0248, 0.0278, 1.8000e-006],
        [0.0278, 0.0313, 0.0351, 1.8000e-006],
        [0.0351, 0.0394, 0.0442, 1.8000e-006],
        [0.0442, 0.0496, 0.0557, 1.8000e-006],
        [0.0557, 0.0625, 0.0702, 1.8000e-006],
        [0.0702, 0.0787, 0.0891, 1.8000e-006],
        [0.0891, 0.1000, 0.1122, 1.8000e-006],
        [0.1122, 0.1250, 0.1413, 2.2500e-006],
        [0.1413, 0.1600, 0.1778, 2.8800e-006],
        [0.1778, 0.2000, 0.2239, 3.6000e-006],
        [0.2239, 0.2500, 0.2818, 4.5000e-006],
        [0.2818, 0.3150, 0.3548, 5.6700e-006],
        [0.3548, 0.4000, 0.4467, 7.2000e-006],
        [0.4467, 0.5000, 0.5623, 9.0000e-006],
        [0.5623, 0.6300, 0.7079, 1.1340e-005],
        [0.7079, 0.8000, 0.8913, 1.4400e-005],
        [0.8913, 1.0000, 1.1220, 1.8000e-005],
        [1.1220, 1.2500, 1.4130, 2.2500e-005],
        [1.4130, 1.6000, 1.7780, 2.8800e-005],
        [1.7780, 2.0000, 2.2390, 3.6000e-005],
        [2.2390, 2.5000, 2.8180, 4.5000e-005],
        [2.8180, 3.1500, 3.5480, 5.6700e-005],
        [3.5480, 4.0000, 4.4670, 7.2000e-005],
        [4.4670, 5.0000, 5.6230, 9.0000e-005],
        [5.6230, 6.3000, 7.0790, 1.1340e-004],
        [7.0790, 8.0000, 8.9130, 1.4400e-004],
        [8.9130, 10.0000, 11.2200, 1.8000e-004],
        [11.2200, 12.5000, 14.1300, 2.2500e-004],
        [14.1300, 16.0000, 17.7800, 2.8800e-004],
        [17.7800, 20.0000, 22.3900, 3.6000e-004],
        [22.3900, 25.0000, 28.1800, 4.5000e-004],
        [28.1800, 31.5000, 35.4800, 5.6700e-004],
        [35.4800, 40.0000, 44.6700, 7.2000e-004],
        [44.6700, 50.0000, 56.2300, 9.0000e-004],
        [56.2300, 64.0000, 71.8380, 1.1520e-003],
        [71.8380, 80.6350, 90.5100, 1.4514e-003],
        [90.5100, 101.5900, 114.0400, 1.8000e-003],
        [114.0400, 128.0000, 143.6800, 1.8000e-003],
        [143.6800, 161.2700, 181.0200, 1.8000e-003],
        [181.0200, 203.1900, 228.0700, 1.8000e-003],
        [228.0700, 256.0000, 287.3500, 1.8000e-003],
        [287.3500, 322.5400, 362.0400, 1.8000e-003],
    ]
)


def test_iss_is_pims_table_exactly() -> None:
    req = iss_requirement()
    got = np.column_stack([req.bands.lower_hz, req.bands.center_hz, req.bands.upper_hz])
    # the shipped CSV carries PIMS's printed digits: equal to the last bit of the decimal parse
    assert got.shape == (46, 3)
    assert np.array_equal(got, PIMS_MOTO[:, :3])
    assert np.array_equal(req.limit_g, PIMS_MOTO[:, 3])
    assert req.name == "iss"
    assert "baluneboy/pims" in req.source and "get_oto_iss_req_steps" in req.source


def test_pims_table_structure() -> None:
    # provenance checks on PIMS's own numbers (independent of microg's CSV):
    lo, c, hi, lim = PIMS_MOTO.T
    # contiguous bands: each upper edge is the next lower edge
    assert np.array_equal(hi[:-1], lo[1:])
    # bands 11-38: IEC 61260 base-10 edges 10^((n -+ 1/2)/10), n = -10..17, to PIMS's 4 digits
    n = np.arange(-10, 18)
    iec_lo, iec_hi = 10.0 ** ((n - 0.5) / 10), 10.0 ** ((n + 0.5) / 10)
    assert np.allclose(lo[10:38], iec_lo, rtol=6e-4) and np.allclose(hi[10:38], iec_hi, rtol=6e-4)
    # bands 1-10 and 39-46: base-2 centres 2^(k/3), k = -20..-11 and 18..25, rounded by PIMS to
    # 4 decimals (half a unit, 5e-5: 0.03125 -> 0.0313 is exactly half) and to 2-3 decimals
    # above 60 Hz (5e-3)
    assert np.allclose(c[:10], 2.0 ** (np.arange(-20, -10) / 3), rtol=0, atol=5.000001e-5)
    assert np.allclose(c[38:], 2.0 ** (np.arange(18, 26) / 3), rtol=0, atol=5e-3)
    # limits: 1.8 ug to the 0.1 Hz band, 18 x nominal centre ug from 0.125 Hz to 80.6 Hz,
    # 1.8 mg from 101.6 Hz (PIMS's get_oto_iss_req_steps); PIMS rounds 18 x 80.635 = 1451.43
    # to 1451.4
    assert np.all(lim[:11] == 1.8e-6) and np.all(lim[40:] == 1.8e-3)
    assert np.allclose(lim[11:40], 18e-6 * c[11:40], rtol=1e-4)


def _tone(fs: float, n: int, f0: float, rms_g: float) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) / fs
    a = np.sqrt(2) * rms_g * G0 * np.sin(2 * np.pi * f0 * t)
    return t, np.vstack([a, 0 * a, 0 * a])


def test_verdict_flips_named_in_issue_9() -> None:
    # 250 ug RMS at 14.20 Hz: PIMS band 33 (14.13-17.78 Hz, 288 ug) -> passes; the old base-2
    # table put it in 11.31-14.25 Hz (228.6 ug) -> failed.  fs = 100 Hz, 20 s: 14.20 Hz is bin
    # 284 exactly (no leakage) and its bin [14.175, 14.225] lies inside band 33.
    t, a = _tone(100.0, 2000, 14.20, 250e-6)
    res = assess(t, a)
    i = int(np.argmin(np.abs(res.third_octave.center_hz - 16.0)))
    assert res.third_octave.rms_g[0, i] == pytest.approx(250e-6, rel=1e-9)  # Parseval, exact bin
    assert res.third_octave.resolved[i]
    assert res.complies is True
    # 2.5 ug RMS at 0.1408 Hz: PIMS band 12 (0.1122-0.1413 Hz, 2.25 ug) -> fails; the old table
    # put it in 0.1403-0.1768 Hz (2.83 ug) -> passed.  fs = 2 Hz, 1250 s: bin 176 exactly, its
    # interval [0.1404, 0.1412] inside band 12.
    t, a = _tone(2.0, 2500, 0.1408, 2.5e-6)
    res = assess(t, a)
    i = int(np.argmin(np.abs(res.third_octave.center_hz - 0.125)))
    assert res.third_octave.rms_g[0, i] == pytest.approx(2.5e-6, rel=1e-9)
    assert res.third_octave.resolved[i]
    assert res.complies is False
    assert res.worst_band.center_hz == 0.125


def test_ssp41000_is_separate_and_continuous() -> None:
    # SSP 41000 curve (domain.md): 1.6 ug for 0.01-0.1 Hz, 16 f ug for 0.1-100 Hz, 1600 ug above
    f = np.array([0.01, 0.05, 0.1, 0.2, 1.0, 50.0, 100.0, 200.0])
    expect = np.array([1.6, 1.6, 1.6, 3.2, 16.0, 800.0, 1600.0, 1600.0]) * 1e-6
    assert np.allclose(ssp41000_limit_g(f), expect, rtol=1e-12)
    req = ssp41000_requirement()
    assert req.name == "ssp41000"
    iss = iss_requirement()
    # judged on the same bands as PIMS, the curve evaluated at each band's centre
    assert np.array_equal(req.bands.center_hz, iss.bands.center_hz)
    assert np.allclose(req.limit_g, ssp41000_limit_g(iss.bands.center_hz), rtol=1e-12)


def test_requirement_lookup_by_name() -> None:
    assert requirement("iss") is iss_requirement()
    assert requirement("ssp41000").name == "ssp41000"
    assert requirement("flat").peak_limit_g == pytest.approx(1e-5)
    with pytest.raises(InputError, match="ssp41000"):
        requirement("nasa")
