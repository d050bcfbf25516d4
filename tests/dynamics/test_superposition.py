"""The modal superposition of several loads (microg.dynamics.superposition.superpose).

References, each an independent path through the public entries:

* every load's own response (``modal_pwl_response``, ``response_at_points``: checked against
  solve_ivp and lsim in test_response.py), summed;
* the certified peak of the loads' summed force (``peak_response``: checked against an
  augmented matrix exponential in test_peak_refinement.py), which evaluates its samples from
  the combined force, not from the loads one by one;
* the modal accelerations at a peak, projected on the point's rows, give back the peak's own
  magnitude, including a peak that is the limit from the left at a force jump.
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.forces import ForceHistory, crew_pushoff
from microg.dynamics.response import modal_pwl_response, peak_response, response_at_points
from microg.dynamics.superposition import ModalLoad, superpose


def _case(seed: int = 2):
    """Two rigid and three damped modes, three points, two loads (one with a jump)."""
    rng = np.random.default_rng(seed)
    omega = np.r_[0.0, 0.0, 0.7, 2.3, 9.1]
    zeta = np.where(omega > 0, 0.02, 0.0)
    n = 7
    phi = rng.normal(size=(n, omega.size)) / np.sqrt(n)
    maps = {f"p{i}": rng.normal(size=(3, n)) for i in range(3)}
    f1 = crew_pushoff(60.0, 0.9, 4.31, 5.2)
    # ramps to 200 N over 1 s, then drops to 0: at some points the acceleration is largest
    # just before the drop, a limit from the left
    f2 = ForceHistory(np.array([1.0, 2.0, 2.0]), np.array([0.0, 200.0, 0.0]), "drop")
    b1 = maps["p0"].T @ np.array([1.0, 0.2, 0.0])
    b2 = maps["p2"].T @ np.array([0.0, -0.5, 1.0])
    t = np.arange(0.0, 12.0 + 1e-9, 0.01)
    return omega, zeta, phi, maps, [(f1, b1), (f2, b2)], t


def _superpose(omega, zeta, phi, maps, loads, t):
    names = list(maps)
    rows = np.concatenate([maps[n] @ phi for n in names])
    modal = [ModalLoad(f, phi.T @ b) for f, b in loads]
    return superpose(omega, zeta, modal, t, names, rows), rows


def test_superposed_response_is_the_sum_of_each_loads_own_response():
    omega, zeta, phi, maps, loads, t = _case()
    sup, _ = _superpose(omega, zeta, phi, maps, loads, t)
    acc = sum(
        modal_pwl_response(omega, zeta, f.timepts, np.outer(phi.T @ b, f.values), t).eta_ddot
        for f, b in loads
    )
    # the same closed form of each load, summed in the same order: rounding, 1e-12 of the
    # largest modal acceleration
    np.testing.assert_allclose(sup.modal_accel, acc, rtol=0, atol=1e-12 * np.abs(acc).max())
    per_load = [response_at_points(omega, zeta, phi, maps, f, b, t) for f, b in loads]
    for name in maps:
        got = sup.points[name]
        assert got.name == name and got.timepts is t
        for q in ("displacement", "velocity", "acceleration"):
            ref = sum(getattr(r[name], q) for r in per_load)
            # the acceleration is rows @ (summed modal acceleration), the reference the sum of
            # each load's projection: another summation order, rounding, 1e-12 of the largest
            scale = np.abs(ref).max()
            np.testing.assert_allclose(getattr(got, q), ref, rtol=0, atol=1e-12 * scale)


def test_superposed_peaks_equal_the_peaks_of_the_summed_force():
    omega, zeta, phi, maps, loads, t = _case()
    sup, rows = _superpose(omega, zeta, phi, maps, loads, t)
    ref = peak_response(omega, zeta, phi, maps, loads, t)
    assert list(sup.peaks) == list(maps)
    for name in maps:
        got, want = sup.peaks[name], ref[name]
        # one search on the same exact state; only the grid samples come from another
        # summation (each load's, not the combined force's): rounding, 1e-12 relative
        assert got.peak_accel_mps2 == pytest.approx(want.peak_accel_mps2, rel=1e-12)
        assert got.upper_bound_mps2 == pytest.approx(want.upper_bound_mps2, rel=1e-12)
        np.testing.assert_allclose(got.peak_accel_mps2_axis, want.peak_accel_mps2_axis, rtol=1e-12)
        assert got.peak_time_s == want.peak_time_s and got.peak_side == want.peak_side
        assert got.peak_accel_mps2 <= got.upper_bound_mps2 <= got.peak_accel_mps2 * (1 + 1e-9)


def test_modal_accelerations_at_the_peaks_give_back_each_peak():
    omega, zeta, phi, maps, loads, t = _case()
    sup, rows = _superpose(omega, zeta, phi, maps, loads, t)
    sides = {sup.peaks[n].peak_side for n in maps}
    assert sides == {"left", "right"}  # the case exercises both sides of a jump
    for j, name in enumerate(maps):
        pk = sup.peaks[name]
        a = rows[3 * j : 3 * j + 3] @ sup.modal_accel_at_peak[:, j]
        # the modal accelerations at the peak's time and side, projected: the peak itself
        # (the value just after the drop differs by the drop's 200 N through the modes);
        # the peak's own evaluation path differs: rounding, 1e-12 relative
        assert np.linalg.norm(a) == pytest.approx(pk.peak_accel_mps2, rel=1e-12)


def test_rows_that_repeat_a_value_change_neither_the_answer_nor_the_segments():
    # the same push written once with its 3 breakpoints and once as 20,001 sampled rows,
    # most of them zeros: the response is the same function (rounding, 1e-12 of the largest),
    # and the kernel sees the same pieces (what makes a million-row file cost what its pieces do)
    omega, zeta, phi, maps, _, t = _case()
    b = maps["p1"].T @ np.array([0.3, 0.0, 1.0])
    short = ForceHistory(np.array([0.0, 0.5, 1.0, 10.0]), np.array([0.0, 40.0, 0.0, 0.0]))
    rows = np.linspace(0.0, 10.0, 20001)
    long = ForceHistory(rows, short.at(rows))
    # kept: the rows of the push (0 <= t <= 1 s, each a new value) and the last row
    assert long.breakpoints[0].size == np.count_nonzero(rows <= 1.0) + 1
    ref, _ = _superpose(omega, zeta, phi, maps, [(short, b)], t)
    got, _ = _superpose(omega, zeta, phi, maps, [(long, b)], t)
    for name in maps:
        a_ref, a_got = ref.points[name].acceleration, got.points[name].acceleration
        np.testing.assert_allclose(a_got, a_ref, rtol=0, atol=1e-12 * np.abs(a_ref).max())
        # both peaks are certified to rtol 1e-9 of the same supremum
        assert got.peaks[name].peak_accel_mps2 == pytest.approx(
            ref.peaks[name].peak_accel_mps2, rel=3e-9
        )
