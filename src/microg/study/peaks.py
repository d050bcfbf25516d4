"""The peaks of a block's records: sampled, and exact (certified) where they are needed.

The records of a block's cases are ``c @ h`` (:mod:`microg.study.kernel`): ``h`` the modal
accelerations of one modal group under the unit modal force, ``c`` (cells, 3, m') the cases'
coefficients.  Their sampled maxima come from the products in blocks of cases and of time
(:func:`_time_stats`).  The exact maximum between samples is found, where it is needed, by the
analysis' certified search (:func:`~microg.dynamics.peaks.certified_peaks`) on the windows
whose bounds may exceed the sampled maximum (:func:`_candidates`), with the group's modal state
prepared once (:func:`~microg.dynamics.pwl.prepare`); :func:`_peak_upper` bounds the exact
peak over the whole record from the samples, so that a verdict's limit below the sampled peak
or above the bound needs no search.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from microg.dynamics.forces import ForceHistory
from microg.dynamics.peaks import certified_peaks
from microg.dynamics.pwl import ModalState
from microg.dynamics.response import modal_pwl_response

__all__ = ["PEAK_RTOL", "Rows"]

#: cases per product ``C @ H`` and samples per time chunk (about 12 MB of work array)
_CELLS = 512
_TIME = 1024
#: cases per call of the exact-peak search on one window
_PEAK_CELLS = 8
#: candidate runs closer than this many samples are searched as one window
_MERGE = 200
#: longest window of one batch of cases, samples
_SPAN = 2000
#: relative tolerance of the exact peaks: well inside the analysis' own certified 1e-9
PEAK_RTOL = 1e-10
#: refinement rounds of the exact-peak search (peak_response's default)
_PEAK_ROUNDS = 30


class Rows(Protocol):
    """What the peaks need of a modal group (:class:`microg.study.kernel.ModalGroup`)."""

    @property
    def h(self) -> np.ndarray:
        """(m', nt) modal accelerations under the unit modal force, m/s^2 per unit gamma."""

    @property
    def omega(self) -> np.ndarray:
        """(m',) rad/s."""

    @property
    def zeta(self) -> np.ndarray:
        """(m',) damping ratios."""

    @property
    def state(self) -> ModalState | None:
        """The rows' modal state at the force segments' starts (None: no exact search)."""


def _time_stats(c: np.ndarray, h: np.ndarray) -> dict[str, np.ndarray]:
    """Sampled peaks (magnitude and per axis) of the records ``c @ h``, m/s^2.

    In blocks of cases and of time, so the (cases, 3, samples) array is never held whole.
    Also the largest squared magnitude and squared axis value in each time chunk of
    :data:`_TIME` samples (``chunk_f2`` (n, nc), ``chunk_a2`` (n, 3, nc)), m^2/s^4.
    """
    n, nt = c.shape[0], h.shape[1]
    nc = -(-nt // _TIME)
    chunk_f2 = np.zeros((n, nc))
    chunk_a2 = np.zeros((n, 3, nc))
    for c0 in range(0, n, _CELLS):
        cc = c[c0 : c0 + _CELLS]
        k = cc.shape[0]
        flat = cc.reshape(3 * k, -1)
        buf = np.empty((3 * k, min(_TIME, nt)))
        mag2 = np.empty((k, min(_TIME, nt)))
        for j, t0 in enumerate(range(0, nt, _TIME)):
            w = min(_TIME, nt - t0)
            a = buf[:, :w]
            np.matmul(flat, h[:, t0 : t0 + w], out=a)
            np.multiply(a, a, out=a)
            a3 = a.reshape(k, 3, w)
            m2 = mag2[:, :w]
            np.add(a3[:, 0], a3[:, 1], out=m2)
            m2 += a3[:, 2]
            chunk_f2[c0 : c0 + k, j] = m2.max(axis=1)
            chunk_a2[c0 : c0 + k, :, j] = a3.max(axis=2)
    return {
        "peak": np.sqrt(chunk_f2.max(axis=1)),
        "peak_axis": np.sqrt(chunk_a2.max(axis=2)),
        "chunk_f2": chunk_f2,
        "chunk_a2": chunk_a2,
    }


def _segment_bounds(
    group: Rows, force: ForceHistory, t: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Bounds of |h|, |h'|, |h''| of every row on every force segment, each (m', K), and starts.

    Within a segment the unit force is linear, so each modal acceleration obeys the free
    equation ``a'' + 2 sigma a' + omega^2 a = 0``, whose energy ``E = a'^2 + omega^2 a^2`` does
    not increase: ``|a'| <= sqrt(E_k)``, ``|a| <= min(sqrt(E_k)/omega, |a_k| + sqrt(E_k) tau)``,
    ``|a''| <= 2 sigma |a'| + omega^2 |a|`` (rigid rows: ``a = a_k + s tau``, omega = 0).  The
    state at a segment start (``a_k``, and the jerk ``s_k - 2 sigma a_k - omega^2 v_k``) comes
    from :func:`~microg.dynamics.response.modal_pwl_response`.  These are the bounds with which
    :func:`~microg.dynamics.response.peak_response` certifies its search.
    """
    tb, fb = force.breakpoints
    starts = np.unique(tb)
    m = group.omega.size
    r = modal_pwl_response(group.omega, group.zeta, tb, np.outer(np.ones(m), fb), starts)
    a_k, v_k = r.eta_ddot, r.eta_dot  # (m', K), right-continuous at the starts
    right = np.searchsorted(tb, starts, side="right") - 1  # last value at each start
    left = np.searchsorted(tb, starts, side="left")  # first value at each start
    slope = np.zeros(starts.size)
    if starts.size > 1:
        slope[:-1] = (fb[left[1:]] - fb[right[:-1]]) / np.diff(starts)
    w = group.omega[:, None]
    sig = (group.zeta * group.omega)[:, None]
    jerk = slope[None, :] - 2.0 * sig * a_k - w * w * v_k
    sqrt_e = np.hypot(jerk, w * a_k)
    seg_end = np.r_[starts[1:], np.inf]
    tau = np.maximum(np.minimum(seg_end, t[-1]) - starts, 0.0)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        by_energy = np.where(w > 0, sqrt_e / w, np.inf)
    b0 = np.minimum(by_energy, np.abs(a_k) + sqrt_e * tau)
    b1 = sqrt_e
    b2 = 2.0 * sig * b1 + w * w * b0
    return b0, b1, b2, starts


def _candidates(
    c: np.ndarray,
    h: np.ndarray,
    t: np.ndarray,
    bounds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    sampled: dict[str, np.ndarray],
) -> list[np.ndarray]:
    """For each case, the sample intervals whose exact maximum may exceed the sampled one.

    An interval of length ``dt`` inside one force segment cannot exceed the larger of its end
    values by more than ``M2 dt^2 / 8`` (``M2`` bounds the second derivative of the axis, or of
    ``|a|^2``, on the segment).  An interval holding a force breakpoint ``b`` is split there:
    each part cannot exceed its end sample by more than ``M1`` times its length (``M1`` bounds
    the first derivative on its segment), which covers both one-sided limits at ``b``.  Only
    the time chunks whose sampled maximum plus the largest such slack reaches the sampled
    peak are examined sample by sample.
    """
    b0, b1, b2, starts = bounds
    n, nt = c.shape[0], t.size
    dt = float(t[1] - t[0])
    seg = np.searchsorted(starts, t[:-1], side="right") - 1  # segment of each interval
    live = seg >= 0
    segc = np.maximum(seg, 0)
    # intervals holding a breakpoint strictly inside or at their right end
    brk = np.searchsorted(t, starts, side="left") - 1
    ok = (brk >= 0) & (brk < nt - 1)
    brk, bt = brk[ok], starts[ok]
    seg_before = np.searchsorted(starts, bt, side="left") - 1  # the segment ending at b
    seg_after = np.searchsorted(starts, bt, side="right") - 1  # the segment starting at b
    lo_f = sampled["peak"] ** 2 * (1.0 - 1e-9)
    lo_ax = sampled["peak_axis"] * (1.0 - 1e-9)
    ac = np.abs(c)
    B0, B1, B2 = ac @ b0, ac @ b1, ac @ b2  # (n, 3, K)
    bF = 2.0 * np.sum(B1 * B1 + B0 * B2, axis=1)  # (n, K): bound of |(|a|^2)''|
    dF = 2.0 * np.sum(B0 * B1, axis=1)  # (n, K): bound of |(|a|^2)'|
    q = dt * dt / 8.0
    slack_f = bF.max(axis=1) * q  # the largest slack of any interval inside a segment
    slack_a = B2.max(axis=2) * q
    out: list[list[np.ndarray]] = [[] for _ in range(n)]
    # chunk j holds intervals [j T, (j + 1) T): their right ends reach into the next chunk
    nc = sampled["chunk_f2"].shape[1]
    cf = np.maximum(sampled["chunk_f2"], np.r_["1", sampled["chunk_f2"][:, 1:], np.zeros((n, 1))])
    ca = np.maximum(sampled["chunk_a2"], np.concatenate(
        [sampled["chunk_a2"][:, :, 1:], np.zeros((n, 3, 1))], axis=2))  # fmt: skip
    need = (cf + slack_f[:, None] > lo_f[:, None]) | np.any(
        np.sqrt(ca) + slack_a[:, :, None] > lo_ax[:, :, None], axis=1
    )
    for j in range(nc):
        cases = np.flatnonzero(need[:, j])
        i0, i1 = j * _TIME, min((j + 1) * _TIME, nt - 1)  # intervals i0 .. i1 - 1
        if cases.size == 0 or i1 <= i0:
            continue
        for c0 in range(0, cases.size, _CELLS):
            sel = cases[c0 : c0 + _CELLS]
            k = sel.size
            a = (c[sel].reshape(3 * k, -1) @ h[:, i0 : i1 + 1]).reshape(k, 3, -1)
            aa = np.abs(a)
            F = np.einsum("kat,kat->kt", a, a)
            sg = segc[i0:i1]
            uf = np.maximum(F[:, :-1], F[:, 1:]) + bF[sel][:, sg] * q
            ua = np.maximum(aa[:, :, :-1], aa[:, :, 1:]) + B2[sel][:, :, sg] * q
            cand = (uf > lo_f[sel, None]) | np.any(ua > lo_ax[sel, :, None], axis=1)
            cand &= live[None, i0:i1]
            for r, case in enumerate(sel):
                idx = np.flatnonzero(cand[r])
                if idx.size:
                    out[case].append(idx + i0)
    if brk.size:  # the intervals holding a breakpoint, for every case
        left_len, right_len = bt - t[brk], t[brk + 1] - bt
        sb, sa, pre = np.maximum(seg_before, 0), seg_after, seg_before >= 0
        for c0 in range(0, n, _CELLS):
            sel = np.arange(c0, min(c0 + _CELLS, n))
            k = sel.size
            ends = np.r_[brk, brk + 1]
            a = (c[sel].reshape(3 * k, -1) @ h[:, ends]).reshape(k, 3, -1)
            al, ar = a[:, :, : brk.size], a[:, :, brk.size :]
            Fl, Fr = np.sum(al * al, axis=1), np.sum(ar * ar, axis=1)
            ufl = np.where(pre, Fl + dF[sel][:, sb] * left_len, 0.0)
            ufr = Fr + dF[sel][:, sa] * right_len
            ual = np.where(pre, np.abs(al) + B1[sel][:, :, sb] * left_len, 0.0)
            uar = np.abs(ar) + B1[sel][:, :, sa] * right_len
            cand = (np.maximum(ufl, ufr) > lo_f[sel, None]) | np.any(
                np.maximum(ual, uar) > lo_ax[sel, :, None], axis=1
            )
            for r, case in enumerate(sel):
                if cand[r].any():
                    out[case].append(brk[cand[r]])
    return [np.unique(np.concatenate(x)) if x else np.zeros(0, int) for x in out]


def _peak_upper(
    c: np.ndarray,
    t: np.ndarray,
    bounds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    sampled: dict[str, np.ndarray],
    h: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Certified upper bounds of the exact peaks, magnitude (n,) and per axis (n, 3), m/s^2.

    The rule of :func:`_candidates` over the whole record at once: no interval inside a force
    segment exceeds the sampled maximum by more than the case's largest ``M2 dt^2 / 8``, and
    each part of an interval holding a breakpoint stays within ``M1`` times its length of its
    end sample.
    """
    b0, b1, b2, starts = bounds
    nt = t.size
    ac = np.abs(c)
    B0, B1, B2 = ac @ b0, ac @ b1, ac @ b2  # (n, 3, K)
    q = float(t[1] - t[0]) ** 2 / 8.0 if nt > 1 else 0.0
    up_f = sampled["peak"] ** 2 + 2.0 * np.sum(B1 * B1 + B0 * B2, axis=1).max(axis=1) * q
    up_a = sampled["peak_axis"] + B2.max(axis=2) * q
    brk = np.searchsorted(t, starts, side="left") - 1
    ok = (brk >= 0) & (brk < nt - 1)
    brk, bt = brk[ok], starts[ok]
    if brk.size:
        seg_before = np.searchsorted(starts, bt, side="left") - 1
        seg_after = np.searchsorted(starts, bt, side="right") - 1
        left_len, right_len = bt - t[brk], t[brk + 1] - bt
        sb, pre = np.maximum(seg_before, 0), seg_before >= 0
        dF = 2.0 * np.sum(B0 * B1, axis=1)
        n = c.shape[0]
        a = (c.reshape(3 * n, -1) @ h[:, np.r_[brk, brk + 1]]).reshape(n, 3, -1)
        al, ar = a[:, :, : brk.size], a[:, :, brk.size :]
        ufl = np.where(pre, np.sum(al * al, axis=1) + dF[:, sb] * left_len, 0.0)
        ufr = np.sum(ar * ar, axis=1) + dF[:, seg_after] * right_len
        ual = np.where(pre, np.abs(al) + B1[:, :, sb] * left_len, 0.0)
        uar = np.abs(ar) + B1[:, :, seg_after] * right_len
        up_f = np.maximum(up_f, np.maximum(ufl, ufr).max(axis=1))
        up_a = np.maximum(up_a, np.maximum(ual, uar).max(axis=2))
    return np.sqrt(up_f), up_a


def _straddles(value: np.ndarray, upper: np.ndarray, limits: Sequence[float]) -> np.ndarray:
    """Cases whose exact peak, known to lie in ``[value, upper]``, may be on either side of a limit.

    The interval is widened by 1e-9 relative: the g conversion's rounding cannot flip a verdict.
    """
    need = np.zeros(value.shape, bool)
    for lim in limits:
        need |= (value * (1.0 - 1e-9) <= lim) & (lim < upper * (1.0 + 1e-9))
    return need


def _exact_peaks(
    c: np.ndarray,
    group: Rows,
    force: ForceHistory,
    t: np.ndarray,
    limits: tuple[Sequence[float], Sequence[float]] | None = None,
) -> dict[str, np.ndarray]:
    """Certified exact peaks (magnitude and per axis) of the records ``c @ h``, m/s^2.

    The sampled maxima first (:func:`_time_stats`); then
    :func:`~microg.dynamics.peaks.certified_peaks` (the search of
    :func:`~microg.dynamics.response.peak_response`, the analysis' exact peak) on the windows
    of consecutive candidate intervals (:func:`_candidates`), in the rows' coordinates
    (``phi = I``, the unit modal force on every row, each case a "point" whose translation map
    is its coefficients), with the group's prepared modal state and the sampled values of the
    records.  Outside the windows no value can exceed the sampled maximum, so the largest value
    found is the certified supremum over the record (to :data:`PEAK_RTOL`).  Cases sharing a
    window are refined in one call.

    ``limits`` (m/s^2: the magnitude's and the largest axis value's limits of the verdict)
    restricts the search to the cases whose sampled peak and certified upper bound
    (:func:`_peak_upper`) straddle one of them; the others keep their sampled peaks, which
    decide the verdict as the exact ones would.  ``certified`` (n,) marks the cases searched.
    """
    sampled = _time_stats(c, group.h)
    peak = sampled["peak"].copy()
    peak_ax = sampled["peak_axis"].copy()
    n = c.shape[0]
    if limits is None:
        todo = np.arange(n)
    else:
        todo = np.zeros(0, int)
        if any(len(x) for x in limits):
            bounds = _segment_bounds(group, force, t)
            up, up_ax = _peak_upper(c, t, bounds, sampled, group.h)
            need = _straddles(peak, up, limits[0]) | _straddles(
                peak_ax.max(axis=1), up_ax.max(axis=1), limits[1]
            )
            todo = np.flatnonzero(need)
    certified = np.zeros(n, bool)
    certified[todo] = True
    if todo.size == 0:
        return {"peak": peak, "peak_axis": peak_ax, "certified": certified}
    sub = c if todo.size == n else c[todo]
    sub_sampled = {k: v[todo] for k, v in sampled.items()}
    cands = _candidates(sub, group.h, t, _segment_bounds(group, force, t), sub_sampled)
    # windows: each case's candidate intervals, runs closer than _MERGE samples joined
    wins: list[tuple[int, int, int]] = []  # (first sample, last sample, case)
    for j, iv in enumerate(cands):
        if iv.size == 0:
            continue
        case = int(todo[j])
        cut = np.flatnonzero(np.diff(iv) > _MERGE)
        for i0, i1 in zip(np.r_[iv[0], iv[cut + 1]], np.r_[iv[cut], iv[-1]], strict=True):
            wins.append((int(i0), int(i1) + 1, case))
    wins.sort()
    st = group.state
    assert st is not None
    k = 0
    while k < len(wins):
        # a batch: consecutive windows whose hull stays short, at most _PEAK_CELLS of them
        lo, hi, _ = wins[k]
        j = k + 1
        while (j < len(wins) and j - k < _PEAK_CELLS
               and max(hi, wins[j][1]) - lo <= _SPAN):  # fmt: skip
            hi = max(hi, wins[j][1])
            j += 1
        batch = wins[k:j]
        k = j
        names = [str(i) for i in range(len(batch))]
        proj = c[[case for _, _, case in batch]].reshape(3 * len(batch), -1)
        # the sampled values of the records: their rows of h at the window's times
        vals = proj @ group.h[:, lo : hi + 1]
        res = certified_peaks(st, names, proj, t[lo : hi + 1], rtol=PEAK_RTOL,
                              max_rounds=_PEAK_ROUNDS, grid_vals=vals)  # fmt: skip
        for i, (_, _, case) in enumerate(batch):
            r = res[str(i)]
            peak[case] = max(peak[case], r.peak_accel_mps2)
            peak_ax[case] = np.maximum(peak_ax[case], r.peak_accel_mps2_axis)
    return {"peak": peak, "peak_axis": peak_ax, "certified": certified}
