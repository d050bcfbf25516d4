"""Every isolation-advice status follows from the assessment's fields beside it.

One synthetic record per status that needs no mount search (not-needed, undecided, peak-only,
transient-only), built so that the deciding criterion is known by construction; each test
checks the status against the JSON fields (``complies``, ``peak_limit_g``, the worst judged
band's margin, the criteria) rather than against the note's wording.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from microg.environment.criteria import verdict_complies
from microg.environment.metrics import assess
from microg.environment.requirements import iss_requirement
from microg.isolation.advise import STATUSES, IsolationAdvice, advise_isolation
from microg.units import G0

DT = 0.01


def _record(seconds: float) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(int(round(seconds / DT))) * DT
    return t, np.zeros((3, t.size))


def _advice(t, a, requirement=None, transient="iss"):
    req = requirement or iss_requirement()
    res = assess(t, a, req, transient=transient)
    # the band path (the mount search) is not reached by these records: no response needed
    adv = advise_isolation("p", res, None, req, package_mass=100.0)  # type: ignore[arg-type]
    assert adv.status in STATUSES
    assert res.complies == verdict_complies(res.criteria)  # the verdict is its criteria's
    return res, adv, res.to_dict()


def test_not_needed_names_a_reported_only_exceedance():
    # a constant 2 micro-g (no vibration: the mean is in no band) integrates to 20 micro-g s
    # over 10 s, above the unverified 10 micro-g s: reported, not judged
    t, a = _record(200.0)
    a[0] = 2e-6 * G0
    res, adv, d = _advice(t, a)
    assert d["complies"] is True and adv.status == "not-needed" and not adv.needed
    rep = [c for c in d["criteria"] if c["status"] == "reported" and c["complies"] is False]
    assert [c["name"] for c in rep] == ["integrated-10ug-s-per-axis-10s"]
    assert rep[0]["value_ug_s"] == pytest.approx(20.0, rel=1e-9)  # 2 micro-g x 10 s
    assert "integrated-10ug-s-per-axis-10s" in adv.note and "not in the verdict" in adv.note


def test_undecided_when_only_unresolved_bands_exceed():
    # a 20-s record with a 0.2 Hz tone of 10 micro-g RMS: the 0.2 Hz band (limit 3.6 micro-g)
    # is not resolved (< 5 bins) and its estimate exceeds; every resolved band passes
    t, a = _record(20.0)
    a[0] = 10e-6 * G0 * np.sqrt(2) * np.sin(2 * np.pi * 0.2 * t)
    res, adv, d = _advice(t, a, transient=None)
    assert d["complies"] is False and d["peak_limit_g"] is None
    assert d["worst_band"]["margin"] == "inf" or d["worst_band"]["margin"] >= 1.0
    assert adv.status == "undecided" and adv.needed and adv.mount is None
    und = [c for c in d["criteria"] if c["status"] == "undecided"]
    assert len(und) == 1 and "0.2" in und[0]["why"]
    assert "peak" not in adv.note.split("(")[0]


def test_peak_only_when_the_requirements_peak_limit_is_exceeded():
    # one sample of 5 micro-g in 200 s against a peak limit of 1 micro-g: the band RMS of the
    # spike (5 / sqrt(20000) micro-g spread over 50 Hz) is far below every band limit
    t, a = _record(200.0)
    a[0, 1000] = 5e-6 * G0
    req = replace(iss_requirement(), name="iss+peak", peak_limit_g=1e-6)
    res, adv, d = _advice(t, a, requirement=req, transient=None)
    assert d["complies"] is False and d["peak_limit_g"] == 1e-6
    assert d["peak_accel_g"] > d["peak_limit_g"] and d["worst_band"]["margin"] >= 1.0
    assert adv.status == "peak-only"
    peak = next(c for c in d["criteria"] if c["name"] == "iss+peak peak")
    assert peak["status"] == "judged" and peak["margin"] == pytest.approx(0.2, rel=1e-12)


def test_transient_only_when_a_verified_transient_criterion_is_exceeded():
    # the same spike at 20 micro-g against the seed report's verified 1e-5 g peak criterion
    t, a = _record(200.0)
    a[0, 1000] = 20e-6 * G0
    res, adv, d = _advice(t, a, transient="report-1e-5g")
    assert d["complies"] is False and d["peak_limit_g"] is None
    assert d["worst_band"]["margin"] >= 1.0
    assert adv.status == "transient-only"
    c = next(c for c in d["criteria"] if c["name"] == "peak-1e-5g")
    assert c["status"] == "judged" and c["margin"] == pytest.approx(0.5, rel=1e-12)
    assert "peak-1e-5g" in adv.note


def test_not_assessed_placeholder():
    adv = IsolationAdvice.not_assessed("p")
    assert adv.status == "not-assessed" and not adv.needed
