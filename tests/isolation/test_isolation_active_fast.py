"""The active check's fast paths against the straightforward python-control computations.

* the vectorised frequency response (Schur form) against a dense solve at every frequency;
* the loops broken one at a time from one response of ``H = K P_yu`` against
  ``control.feedback`` of the state spaces;
* the margins read on windows around the crossings against the whole-grid reading;
* the acceleration-loop search cached per plant;
* the closed loop's time response by the blocked scan against ``control.forced_response``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

ct = pytest.importorskip("control")

from microg.isolation.active import verify  # noqa: E402
from microg.isolation.active.controller import (  # noqa: E402
    _DESIGN_OMEGA,
    OMEGA_P_MIN,
    _channel_loop,
    accel_loop_gains,
    design_feedback,
)
from microg.isolation.active.fresp import freq_response  # noqa: E402
from microg.isolation.active.margins import (  # noqa: E402
    loop_margin_values,
    margins_from_response,
    pick_margins,
)  # noqa: E402
from microg.isolation.active.plant import DOF_NAMES, gain  # noqa: E402
from microg.isolation.active.presets import load_preset  # noqa: E402
from microg.isolation.active.target import target_by_name  # noqa: E402


@pytest.fixture(scope="module")
def aris():
    plant, name = load_preset("aris")
    return plant, design_feedback(plant, target_by_name(name))


def _normwise(ref: np.ndarray, got: np.ndarray) -> float:
    num = np.linalg.norm(ref - got, axis=(0, 1))
    return float(np.max(num / np.linalg.norm(ref, axis=(0, 1))))


@pytest.mark.parametrize("discrete", [False, True])
def test_vectorised_response_matches_a_dense_solve(aris, discrete) -> None:
    plant, ctrl = aris
    cl = verify.closed_loop(plant, ctrl, discrete=discrete)
    sub = verify._select(18, range(6)) * cl * verify._inputs(21, range(9))
    f = np.geomspace(1e-4, 0.49 * plant.sample_rate_hz, 60)[::-1]  # any order
    got = freq_response(sub, f)
    n = sub.nstates
    z = np.exp(2j * np.pi * f * sub.dt) if discrete else 2j * np.pi * f
    ref = np.stack(
        [sub.C @ np.linalg.solve(zi * np.eye(n) - sub.A, sub.B) + sub.D for zi in z], axis=-1
    )
    # tolerance: a backward-stable solve's forward error is about eps * cond; cond(A) is ~1e9
    # (continuous: Pade poles at ~1e4 1/s beside umbilical poles at ~1e-2 1/s) and ~1e11
    # (sampled); python-control's own per-point response differs from the dense solve by the
    # same order (5e-9 and 1.5e-6 here)
    tol = 10 * np.finfo(float).eps * np.linalg.cond(sub.A)
    assert _normwise(ref, got) < tol
    # the diagonal transmissibility pointwise, where the checks read it
    for i in range(3):
        assert np.max(np.abs(got[i, i] - ref[i, i]) / np.abs(ref[i, i])) < tol


def test_loops_at_a_time_match_control_feedback(aris) -> None:
    plant, ctrl = aris
    gen = plant.generalized(3)
    p_yu = verify._select(30, range(18, 30)) * gen * verify._inputs(27, range(21, 27))
    h = ctrl.system * p_yu
    f = np.geomspace(1e-3, 100.0, 40)
    fast = verify.loops_at_a_time(freq_response(h, f))
    for i in range(len(DOF_NAMES)):
        e = np.eye(6)
        e[i, i] = 0.0
        closed = ct.feedback(h, gain(e), sign=1)
        li = -(verify._select(6, [i]) * closed * verify._inputs(6, [i]))
        ref = freq_response(li, f)[0, 0]
        # 1e-6: two algebraically equal forms of the same loop (a 6x6 complex solve per
        # frequency against the state-space feedback), both within the closed loop's
        # conditioning (above)
        assert np.max(np.abs(fast[i] - ref) / np.abs(ref)) < 1e-6


def _whole_grid(loop, omega):
    gms, pms, _, wpcs, wgcs, _ = ct.stability_margins(
        ct.frd(loop, omega, smooth=True), returnall=True
    )
    return pick_margins(gms, pms, wpcs, wgcs)


@pytest.mark.parametrize("wa_hz", [0.3, 3.0, 30.0])
@pytest.mark.parametrize("channel", [0, 3])
def test_windowed_margins_equal_the_whole_grid(channel, wa_hz) -> None:
    plant, _ = load_preset("aris")
    loop = _channel_loop(plant, channel, 2 * math.pi * wa_hz, OMEGA_P_MIN, 3)
    resp = freq_response(loop, _DESIGN_OMEGA / (2 * math.pi))[0, 0]
    # the windows alone: the same response read on the whole grid and on the windows
    whole = ct.frd(resp, _DESIGN_OMEGA, smooth=True)
    gms, pms, _, wpcs, wgcs, _ = ct.stability_margins(whole, returnall=True)
    ref = pick_margins(gms, pms, wpcs, wgcs)
    got = margins_from_response(resp, _DESIGN_OMEGA)
    for r, g in zip(ref, got, strict=True):
        if r is None or not math.isfinite(r):
            assert g == r
        else:
            # 1e-10: a cubic spline's end condition decays ~0.27 per knot, WINDOW = 8 knots
            # from the crossing; measured ~1e-12
            assert abs(g - r) <= 1e-10 * abs(r)
    # end to end against python-control's own response on the whole grid
    end_to_end = zip(
        _whole_grid(loop, _DESIGN_OMEGA), loop_margin_values(loop, _DESIGN_OMEGA), strict=True
    )
    for r, g in end_to_end:
        if r is None or not math.isfinite(r):
            assert g == r
        else:
            # 1e-6: the two responses differ by up to ~1e-7 at the loop's low-frequency
            # crossings (|L| ~ 20 there: the per-point solves' conditioning, test above)
            assert abs(g - r) <= 1e-6 * abs(r)


def test_margins_of_the_design_match_the_whole_grid(aris) -> None:
    plant, ctrl = aris
    fast, _ = verify.loop_margins(plant, ctrl)
    gen = plant.generalized(3)
    p_yu = verify._select(30, range(18, 30)) * gen * verify._inputs(27, range(21, 27))
    h = ctrl.system * p_yu
    omega = (
        2
        * math.pi
        * np.geomspace(verify.MARGIN_F_LO_HZ, 20.0 * plant.sample_rate_hz, verify.MARGIN_POINTS)
    )
    for i, m in enumerate(fast):
        e = np.eye(6)
        e[i, i] = 0.0
        li = -(verify._select(6, [i]) * ct.feedback(h, gain(e), sign=1) * verify._inputs(6, [i]))
        gm, pm, _, _ = _whole_grid(li, omega)
        # 1e-6: as above, through the coupled loop's conditioning
        assert abs(m.phase_margin_deg - pm) <= 1e-6 * pm
        assert abs(m.gain_margin - gm) <= 1e-6 * gm


def test_acceleration_gains_are_cached_per_plant() -> None:
    plant, _ = load_preset("aris")
    first = accel_loop_gains(plant)
    again = accel_loop_gains(load_preset("aris")[0])
    assert np.array_equal(first, again)
    again[0] = -1.0  # a copy: the cache is not changed through it
    assert accel_loop_gains(plant)[0] == first[0]
    other = accel_loop_gains(plant.with_(max_loop_hz=1.0))
    assert other.max() <= 2 * math.pi * 1.0 * (1 + 1e-12)


def test_time_response_matches_control_forced_response(aris) -> None:
    plant, ctrl = aris
    cl = verify.closed_loop(plant, ctrl)
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 60.0, 6001)
    # a station-like base motion: lines at 0.1, 1.3 and 7 Hz, a step and broadband noise
    a0 = 1e-5 * (
        np.sin(2 * np.pi * np.outer([0.1, 1.3, 7.0], t))
        + (t > 20.0)[None, :]
        + 0.3 * rng.standard_normal((3, t.size))
    )
    plat, q, force = verify.time_response(cl, t, a0)
    rows = list(range(3)) + list(range(6, 12)) + list(range(12, 18))
    sub = verify._select(18, rows) * cl * verify._inputs(21, range(3))
    ref = np.asarray(ct.forced_response(sub, t, a0).outputs).reshape(len(rows), t.size)
    got = np.concatenate([plat, q, force])
    # the same discretisation (one expm of the same block matrix) and recurrence; the blocked
    # scan only reorders the products of the block start states (module doc of microg._scan):
    # a few roundings per block amplified by the step map's conditioning.  Measured 4e-12 of
    # each output's peak (60 s and 200 s records); 1e-9 still separates a wrong map or a
    # shifted sample (order 1)
    scale = np.max(np.abs(ref), axis=1, keepdims=True)
    live = scale[:, 0] > 0.0  # rows the base motion cannot reach are zero in both
    assert live.sum() >= 9
    assert np.max(np.abs(got - ref)[live] / scale[live]) < 1e-9
    assert not np.any(got[~live])
    # at rest with a zero input
    assert not np.any(verify.foh_response(sub, t, np.zeros((3, t.size))))


def _forget() -> None:
    """Empty every result microg keeps for the isolator (the next call computes afresh)."""
    from microg.isolation.active import controller, fresp

    fresp.clear_kept()
    for kept in (
        verify._MARGINS_CACHE,
        verify._LOOPS_CACHE,
        verify._CL_CACHE,
        verify._PYU_CACHE,
        controller._CHANNEL_CACHE,
        controller._GAINS_CACHE,
        verify._POLES_CACHE,
    ):
        kept.clear()


def test_kept_frequency_responses_are_each_systems_own_and_read_only() -> None:
    rng = np.random.default_rng(5)
    f = np.geomspace(0.01, 100.0, 50)
    a = -np.diag(rng.uniform(1.0, 10.0, 4))
    b, c = rng.standard_normal((4, 2)), rng.standard_normal((3, 4))
    one = ct.ss(a, b, c, np.zeros((3, 2)))
    two = ct.ss(a, b, 2.0 * c, np.zeros((3, 2)))  # same shapes, other values
    r1 = freq_response(one, f)
    r2 = freq_response(two, f)
    assert np.array_equal(r2, 2.0 * r1)  # not the first one's kept response
    assert freq_response(one, f) is r1  # kept
    with pytest.raises(ValueError):
        r1[0, 0, 0] = 0.0  # a kept response cannot be changed by a caller
    assert not np.array_equal(freq_response(one, f[::2]), r1)  # other frequencies: computed
    assert freq_response(ct.ss(a, b, c, np.zeros((3, 2)), 0.01), f).shape == r1.shape
    assert not np.array_equal(freq_response(ct.ss(a, b, c, np.zeros((3, 2)), 0.01), f), r1)


def test_kept_margins_and_loops_equal_a_fresh_computation(aris) -> None:
    plant, ctrl = aris
    f = np.geomspace(0.01, 100.0, 40)
    slow = design_feedback(plant.with_(max_loop_hz=2.0), target_by_name("g-limit"))
    _forget()
    fresh = [verify.loop_margins(p, k, freq_hz=f) for p, k in ((plant, ctrl), (plant, slow))]
    fresh_d = verify.loop_margins(plant, ctrl, discrete=True)
    kept = [verify.loop_margins(p, k, freq_hz=f) for p, k in ((plant, ctrl), (plant, slow))]
    # bit for bit: the same numbers, whether computed or kept, and each controller its own
    for (m0, l0), (m1, l1) in zip(fresh, kept, strict=True):
        assert m0 == m1 and np.array_equal(l0, l1)
    assert fresh[0][0] != fresh[1][0]
    assert verify.loop_margins(plant, ctrl, discrete=True)[0] == fresh_d[0]
    # kept margins with frequencies not seen before: the loops computed, the margins kept
    g = np.geomspace(0.02, 50.0, 30)
    _, at_g = verify.loop_margins(plant, ctrl, freq_hz=g)
    _forget()
    assert np.array_equal(verify.loop_margins(plant, ctrl, freq_hz=g)[1], at_g)
    # and both are the loops of H = K P_yu at those frequencies (computed here on their own)
    h = np.einsum("ijf,jkf->ikf", freq_response(ctrl.system, g), verify.plant_yu_response(plant, g))
    assert np.array_equal(verify.loops_at_a_time(h), at_g)
    assert verify.closed_loop(plant, ctrl) is verify.closed_loop(plant, ctrl)
    assert verify.closed_loop(plant, slow) is not verify.closed_loop(plant, ctrl)


def test_a_design_is_the_same_whether_computed_or_kept() -> None:
    from dataclasses import fields as dc_fields

    from microg.isolation.active.design import design_active

    t = np.arange(0.0, 20.0, 0.01)
    a0 = 1e-5 * np.sin(2 * np.pi * np.outer([0.3, 1.1, 4.0], t))
    _forget()
    first = design_active("aris", target={1.0: 30.0}, timepts=t, base_accel=a0)
    again = design_active("aris", target={1.0: 30.0}, timepts=t, base_accel=a0)
    other = design_active("aris", target={2.0: 30.0}, timepts=t, base_accel=2 * a0)
    _forget()
    cold = design_active("aris", target={2.0: 30.0}, timepts=t, base_accel=2 * a0)
    assert first.to_dict() == again.to_dict()
    assert other.to_dict() == cold.to_dict()
    for fld in dc_fields(cold):
        v, w = getattr(other, fld.name), getattr(cold, fld.name)
        if isinstance(v, np.ndarray):
            assert np.array_equal(v, w, equal_nan=True), fld.name


@pytest.mark.parametrize("discrete", [False, True])
def test_a_sub_system_is_the_selection_by_gains_bit_for_bit(aris, discrete) -> None:
    plant, ctrl = aris
    cl = verify.closed_loop(plant, ctrl, discrete=discrete)
    dt = cl.dt if discrete else None
    for rows, cols in (
        (range(3), range(3)),
        (range(6), range(3, 9)),
        (range(3), range(9, 21)),
        ([0, 1, 2, *range(6, 18)], range(3)),
    ):
        by_gains = verify._select(18, rows, dt) * cl * verify._inputs(21, cols, dt)
        direct = verify._sub(cl, rows, cols)
        for name in "ABCD":
            assert np.array_equal(getattr(direct, name), getattr(by_gains, name)), name
        assert direct.dt == by_gains.dt
