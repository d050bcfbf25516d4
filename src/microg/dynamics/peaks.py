"""The certified true peak of an exact modal acceleration over a time window.

The acceleration of points (rows ``T phi`` contracting the modes) is evaluated exactly (closed
form, :mod:`microg.dynamics.pwl`) at the output times and at every force breakpoint inside the
window, with both one-sided limits at a jump, then refined between samples with certified bounds
of its derivatives until no interval may hold a value above the best one by more than ``rtol``
(:func:`certified_peaks`).  The public entry is
:func:`microg.dynamics.response.peak_response`; the result type is :class:`PeakResponse`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg.dynamics.oscillator import exp_decayed
from microg.dynamics.pwl import ModalState, evaluate
from microg.units import G0

__all__ = ["PeakResponse", "certified_peaks"]


def _accel_coefficients(st: ModalState, seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``a = Re(X exp(lambda tau))`` on segments ``seg``: X (m, n) complex; rigid rows separate.

    For an elastic mode a(tau) = a_k g + j_k h = Re E a_k + Im E (sigma a_k + j_k)/omega_d with
    E = exp(lambda tau), lambda = -sigma + i omega_d; so X = a_k - i (sigma a_k + j_k)/omega_d.
    Rigid rows (omega = 0) get X = 0 here; their a = a_k + j_k tau is added by the callers.
    """
    sigma = (st.zeta * st.omega)[:, None]
    omega_d = (st.omega * np.sqrt(1.0 - st.zeta * st.zeta))[:, None]
    acc, jerk = st.acc[:, seg], st.jerk[:, seg]
    with np.errstate(divide="ignore", invalid="ignore"):
        cs = np.where(omega_d > 0, (sigma * acc + jerk) / omega_d, 0.0)
    cc = np.where(omega_d > 0, acc, 0.0)
    return cc - 1j * cs, np.flatnonzero(st.omega == 0)


def _lam(st: ModalState) -> np.ndarray:
    return (-st.zeta * st.omega + 1j * st.omega * np.sqrt(1.0 - st.zeta * st.zeta))[:, None]


def _accel_direct(st: ModalState, seg: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Modal accelerations (m, n) at elapsed times ``tau`` into segments ``seg`` (>= 0)."""
    X, rigid = _accel_coefficients(st, seg)
    out = (X * exp_decayed(_lam(st) * tau[None, :])).real
    if rigid.size:
        out[rigid] = st.acc[rigid][:, seg] + st.jerk[rigid][:, seg] * tau[None, :]
    return out


def _accel_sub(
    st: ModalState, seg: np.ndarray, tau_a: np.ndarray, delta: float, nsub: int
) -> np.ndarray:
    """Modal accelerations (m, n, nsub - 1) at ``tau_a + r delta``, r = 1 .. nsub - 1.

    One exponential per interval and one small table ``exp(lambda r delta)`` shared by all
    intervals of this length: a complex product per value.
    """
    X, rigid = _accel_coefficients(st, seg)
    lam = _lam(st)
    XA = X * exp_decayed(lam * tau_a[None, :])  # (m, n)
    rd = np.arange(1, nsub) * delta
    W = np.exp(lam * rd[None, :])  # (m, nsub - 1)
    out = XA.real[:, :, None] * W.real[:, None, :] - XA.imag[:, :, None] * W.imag[:, None, :]
    if rigid.size:
        tt = tau_a[None, :, None] + rd[None, None, :]
        out[rigid] = (st.acc[rigid][:, seg])[:, :, None] + (st.jerk[rigid][:, seg])[:, :, None] * tt
    return out


#: each refinement round cuts every interval that may still hold a higher value into this many
_SUBDIVIDE = 16
#: new evaluation times per vectorised batch in the refinement (bounds the scratch memory)
_PEAK_BATCH = 8192
#: consecutive sample intervals sharing one derivative bound (taken at the first one's start)
_BOUND_BLOCK = 32


@dataclass(frozen=True)
class PeakResponse:
    """The true maximum of a point's exact acceleration over a time window (certified).

    Attributes
    ----------
    name : point name
    window_s : (2,) the closed window [t_start, t_end] searched, s (the output grid's span)
    peak_accel_mps2 : supremum of the vector magnitude |a(t)| over the window, m/s^2: the largest
        exact value found (an attained value or a one-sided limit at a force jump)
    peak_time_s : where it occurs, s
    peak_side : ``"left"`` when the supremum is the limit from the left at a force jump (the
        value just before the jump), else ``"right"`` (the right-continuous value at that time)
    upper_bound_mps2 : certified upper bound of the supremum: the true maximum lies in
        [peak_accel_mps2, upper_bound_mps2]
    peak_accel_mps2_axis : (3,) supremum of |a_x|, |a_y|, |a_z|, m/s^2
    peak_time_s_axis : (3,) where each occurs, s
    upper_bound_mps2_axis : (3,) certified upper bounds per axis, m/s^2
    sampled_peak_accel_mps2 : largest |a| at the output times alone (what sampling shows), m/s^2
    rounds : refinement rounds used
    """

    name: str
    window_s: tuple[float, float]
    peak_accel_mps2: float
    peak_time_s: float
    peak_side: str
    upper_bound_mps2: float
    peak_accel_mps2_axis: np.ndarray
    peak_time_s_axis: np.ndarray
    upper_bound_mps2_axis: np.ndarray
    sampled_peak_accel_mps2: float
    rounds: int

    @property
    def peak_accel_g(self) -> float:
        """Peak magnitude in standard gravity (G0 = 9.80665 m/s^2)."""
        return self.peak_accel_mps2 / G0

    @property
    def peak_accel_g_axis(self) -> np.ndarray:
        """Peak per axis in standard gravity, shape (3,)."""
        return self.peak_accel_mps2_axis / G0

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary (SI, names carry units)."""
        return {
            "name": self.name,
            "window_s": list(self.window_s),
            "peak_accel_mps2": self.peak_accel_mps2,
            "peak_accel_g": self.peak_accel_g,
            "peak_time_s": self.peak_time_s,
            "peak_side": self.peak_side,
            "upper_bound_mps2": self.upper_bound_mps2,
            "peak_accel_mps2_axis": self.peak_accel_mps2_axis.tolist(),
            "peak_accel_g_axis": self.peak_accel_g_axis.tolist(),
            "peak_time_s_axis": self.peak_time_s_axis.tolist(),
            "upper_bound_mps2_axis": self.upper_bound_mps2_axis.tolist(),
            "sampled_peak_accel_mps2": self.sampled_peak_accel_mps2,
            "rounds": self.rounds,
        }

    def to_xarray(self) -> Any:
        """The per-axis peaks, times and bounds as an ``xarray.Dataset`` over ``axis``.

        The magnitude's peak, time, side, bound and sampled peak are attributes.
        """
        import xarray as xr

        return xr.Dataset(
            {
                "peak_accel_mps2": ("axis", self.peak_accel_mps2_axis, {"units": "m/s^2"}),
                "peak_time_s": ("axis", self.peak_time_s_axis, {"units": "s"}),
                "upper_bound_mps2": ("axis", self.upper_bound_mps2_axis, {"units": "m/s^2"}),
            },
            coords={"axis": ("axis", ["x", "y", "z"])},
            attrs={
                "point": self.name,
                "window_s": list(self.window_s),
                "magnitude_peak_accel_mps2": self.peak_accel_mps2,
                "magnitude_peak_time_s": self.peak_time_s,
                "magnitude_peak_side": self.peak_side,
                "magnitude_upper_bound_mps2": self.upper_bound_mps2,
                "sampled_peak_accel_mps2": self.sampled_peak_accel_mps2,
                "rounds": self.rounds,
            },
        )


def _derivative_bounds(
    st: ModalState, proj: np.ndarray, seg: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of |a'| and |a''| of every projected row from ``tau`` on in segment ``seg``, (R, n).

    Within a segment every elastic modal acceleration is a free damped sinusoid
    ``a = Re(X exp(lambda tau))`` (:func:`_accel_coefficients`; |lambda| = omega), so from
    elapsed time ``tau`` to the segment's end ``|a'| <= omega A`` and ``|a''| <= omega^2 A`` with
    the amplitude ``A = |X| exp(-sigma tau)``, which does not increase.  A rigid mode's
    acceleration is the line ``a_k + j_k tau``: ``|a'| = |j_k|``, ``a'' = 0``.  A row's bound is the
    sum over modes of ``|T phi|`` times the modal bound.
    """
    el, rigid = st.elastic, st.rigid
    ap = np.abs(proj)
    w = st.omega[el]
    sig = (st.zeta * st.omega)[el][:, None]
    wd = (w * np.sqrt(1.0 - st.zeta[el] ** 2))[:, None]
    acc, jerk = st.acc[el][:, seg], st.jerk[el][:, seg]
    amp = np.hypot(acc, (sig * acc + jerk) / wd) * exp_decayed(-sig * tau[None, :])
    b1 = (ap[:, el] * w) @ amp
    b2 = (ap[:, el] * (w * w)) @ amp
    if rigid.size:
        b1 += ap[:, rigid] @ np.abs(st.jerk[rigid][:, seg])
    return b1, b2


def certified_peaks(
    st: ModalState,
    names: list[str],
    proj: np.ndarray,
    t: np.ndarray,
    *,
    rtol: float,
    max_rounds: int,
    grid_vals: np.ndarray | None = None,
) -> dict[str, PeakResponse]:
    """True maximum of the projected exact acceleration over ``[t[0], t[-1]]``, certified.

    Samples: the output grid (right-continuous values) and the one-sided limits at every force
    jump inside the window.  Refinement: within a force segment each modal acceleration is a
    damped sinusoid (rigid: a line), and :func:`_derivative_bounds` bounds the first and second
    derivatives ``M1, M2`` of each axis from the start of every block of :data:`_BOUND_BLOCK`
    intervals on (the modal amplitudes only decay).  An interval of length ``h`` whose end
    values are ``f_a, f_b`` cannot exceed ``max(f_a, f_b) + M2 h^2 / 8`` (the linear
    interpolant's error); |a|^2 is bounded by the sum of its axes' bounds squared, and on the
    intervals that leaves open by the same rule with ``|(|a|^2)''| <= 2 sum (M1^2 + |f| M2)``,
    ``M1`` tightened to ``|f_b - f_a| / h + M2 h``.  One vectorised pass over all intervals with
    these bounds leaves only those that might exceed the best sample; they are cut into
    :data:`_SUBDIVIDE` and evaluated exactly again, until none might exceed the best value by
    more than ``rtol`` or ``max_rounds`` ran out.

    Parameters
    ----------
    st : the modal state of the (superposed) force (:func:`microg.dynamics.pwl.prepare`)
    names : the P point names, in the order of ``proj``'s row triples
    proj : (3 P, m) rows ``T phi`` of the points (x, y, z of each), m per modal unit
    t : (nt,) sorted output times, s (nt >= 1); their span is the window searched
    rtol : relative tolerance of the certified bound (> 0)
    max_rounds : largest number of refinement rounds (>= 0)
    grid_vals : (3 P, nt) the projected accelerations at ``t`` when the caller has them
        (m/s^2), else they are evaluated here

    Returns
    -------
    dict name -> PeakResponse (m/s^2, s)
    """
    n_pts = len(names)
    t_lo, t_hi = float(t[0]), float(t[-1])
    starts = st.starts

    def accel(seg: np.ndarray, tt: np.ndarray) -> np.ndarray:
        """Projected acceleration (R, n) at times tt evaluated on segments seg (-1: zero)."""
        res = np.zeros((proj.shape[0], tt.size))
        ok = np.flatnonzero(seg >= 0)
        for c0 in range(0, ok.size, _PEAK_BATCH):
            idx = ok[c0 : c0 + _PEAK_BATCH]
            sg = seg[idx]
            res[:, idx] = proj @ _accel_direct(st, sg, tt[idx] - starts[sg])
        return res

    def accel_sub(sg: np.ndarray, ta: np.ndarray, tb_: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Times (na, S-1) cutting each interval into S equal parts, and the values there."""
        h = tb_ - ta
        scale = 1e-12 * max(abs(t_lo), abs(t_hi), 1.0)
        keys = np.rint(h / scale)
        tn = np.empty((ta.size, _SUBDIVIDE - 1))
        vn = np.empty((proj.shape[0], ta.size, _SUBDIVIDE - 1))
        _, inv = np.unique(keys, return_inverse=True)
        inv = inv.reshape(-1)
        for g in range(int(inv.max(initial=-1)) + 1):
            grp = np.flatnonzero(inv == g)
            delta = float(h[grp].mean()) / _SUBDIVIDE
            rd = np.arange(1, _SUBDIVIDE) * delta
            step = max(1, _PEAK_BATCH // (_SUBDIVIDE - 1))
            for c0 in range(0, grp.size, step):
                idx = grp[c0 : c0 + step]
                tau_a = ta[idx] - starts[sg[idx]]
                modal = _accel_sub(st, sg[idx], tau_a, delta, _SUBDIVIDE)
                vn[:, idx] = (proj @ modal.reshape(modal.shape[0], -1)).reshape(
                    proj.shape[0], idx.size, -1
                )
                tn[idx] = ta[idx, None] + rd
        return tn, vn

    # 1. samples: the output grid (right-continuous values) and the one-sided limits at jumps
    if grid_vals is None:
        grid_vals = evaluate(st, t, (2,), proj)[0]  # (R, nt)
    grid_seg = np.searchsorted(starts, t, side="right") - 1
    k_right = np.flatnonzero((starts >= t_lo) & (starts <= t_hi))
    k_left = np.flatnonzero((starts > t_lo) & (starts <= t_hi))
    seg_left = k_left - 1
    times = np.concatenate([t, starts[k_right], starts[k_left]])
    segs = np.concatenate([grid_seg, k_right, seg_left])
    side = np.concatenate([np.ones(t.size + k_right.size), np.zeros(k_left.size)])  # 0: left
    extra = accel(
        np.concatenate([k_right, seg_left]), np.concatenate([starts[k_right], starts[k_left]])
    )
    vals = np.concatenate([grid_vals, extra], axis=1)

    def mag2(v: np.ndarray) -> np.ndarray:
        return (v * v).reshape(n_pts, 3, *v.shape[1:]).sum(axis=1)

    F = np.concatenate([mag2(grid_vals), mag2(extra)], axis=1)  # |a|^2 (P, samples)
    sampled = np.sqrt(F[:, : t.size].max(axis=1, initial=0.0))
    order = np.lexsort((side, times))
    if np.any(order != np.arange(order.size)):
        times, segs, side, vals, F = (
            times[order],
            segs[order],
            side[order],
            vals[:, order],
            F[:, order],
        )
    absv = np.abs(vals)
    rows = np.arange(proj.shape[0])
    arg_ax = absv.argmax(axis=1) if times.size else np.zeros(proj.shape[0], int)
    best_ax = absv[rows, arg_ax] if times.size else np.zeros(proj.shape[0])  # (R,)
    t_ax, side_ax = times[arg_ax], side[arg_ax]
    arg_F = F.argmax(axis=1)
    best_F = F[np.arange(n_pts), arg_F]  # (P,)
    t_F, side_F = times[arg_F], side[arg_F]

    # 2. intervals inside one segment (a jump separates its two limits: no interval across it)
    link = np.flatnonzero((segs[1:] == segs[:-1]) & (segs[:-1] >= 0) & (np.diff(times) > 0))
    ta, tb_, sg = times[link], times[link + 1], segs[link]
    # derivative bounds from the start of blocks of up to _BOUND_BLOCK consecutive intervals
    # of one segment (the bounds only decay within a segment: the block's first start holds)
    n_int = link.size
    new_blk = np.ones(n_int, dtype=bool)
    new_blk[1:] = (sg[1:] != sg[:-1]) | (np.arange(1, n_int) % _BOUND_BLOCK == 0)
    blk = np.cumsum(new_blk) - 1
    first = np.flatnonzero(new_blk)
    d1_blk, d2_blk = _derivative_bounds(st, proj, sg[first], ta[first] - starts[sg[first]])
    # first pass over all intervals, the cheap bounds: f <= max(|f_a|, |f_b|) + M2 h^2 / 8 per
    # axis and |a|^2 <= the sum of its axes' bounds squared; the finer bound of |a|^2
    # (``bounds``) only on the intervals these do not settle
    h = tb_ - ta
    u_ax = np.maximum(absv[:, link], absv[:, link + 1])
    u_ax += d2_blk[:, blk] * (h * h / 8.0)
    m2 = mag2(u_ax)
    grow = 1.0 + rtol
    cand = np.any(u_ax > best_ax[:, None] * grow, axis=0) | np.any(
        m2 > best_F[:, None] * grow * grow, axis=0
    )
    # largest bound of every interval set aside: the certified bound of the supremum
    drop_ax = np.max(u_ax * ~cand, axis=1, initial=0.0)
    drop_F = np.max(m2 * ~cand, axis=1, initial=0.0)
    cand_i = np.flatnonzero(cand)
    ta, tb_, sg, li = ta[cand_i], tb_[cand_i], sg[cand_i], link[cand_i]
    va, vb = vals[:, li], vals[:, li + 1]
    d1, d2 = d1_blk[:, blk[cand_i]], d2_blk[:, blk[cand_i]]  # (R, n): bounds of |a'|, |a''|
    rounds = 0

    def bounds(
        h: np.ndarray, va: np.ndarray, vb: np.ndarray, d1: np.ndarray, d2: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Upper bounds of |a_axis| (R, n) and |a|^2 (P, n) on intervals of lengths h.

        With |f''| <= M2 on an interval of length h, f <= max(f_a, f_b) + M2 h^2 / 8 (the
        linear interpolant's error); |f'| <= |f_b - f_a| / h + M2 h (mean value theorem).  For
        F = |a|^2: F'' = 2 sum (f'^2 + f f''), or directly F <= sum of the axes' bounds squared.
        """
        h2 = h * h / 8.0
        u_ax = np.maximum(np.abs(va), np.abs(vb)) + d2 * h2
        b1 = np.minimum(d1, np.abs(vb - va) / h + d2 * h)
        bF = 2.0 * mag2(b1) + 2.0 * (u_ax * d2).reshape(n_pts, 3, -1).sum(axis=1)
        u_F = np.minimum(np.maximum(mag2(va), mag2(vb)) + bF * h2, mag2(u_ax))
        return u_ax, u_F

    u_ax, u_F = bounds(tb_ - ta, va, vb, d1, d2)
    while True:
        active = np.any(u_ax > best_ax[:, None] * grow, axis=0) | np.any(
            u_F > best_F[:, None] * grow * grow, axis=0
        )
        gone = ~active
        drop_ax = np.maximum(drop_ax, u_ax[:, gone].max(axis=1, initial=0.0))
        drop_F = np.maximum(drop_F, u_F[:, gone].max(axis=1, initial=0.0))
        keep = np.flatnonzero(active)
        ta, tb_, sg, va, vb = ta[keep], tb_[keep], sg[keep], va[:, keep], vb[:, keep]
        d1, d2 = d1[:, keep], d2[:, keep]
        u_ax, u_F = u_ax[:, keep], u_F[:, keep]
        if keep.size == 0 or rounds >= max_rounds:
            break
        rounds += 1
        tn, vn = accel_sub(sg, ta, tb_)  # (na, S-1), (R, na, S-1)
        # new best values
        an = np.abs(vn).reshape(proj.shape[0], -1)
        i_ax = an.argmax(axis=1)
        better = an[np.arange(an.shape[0]), i_ax] > best_ax
        best_ax = np.where(better, an[np.arange(an.shape[0]), i_ax], best_ax)
        t_ax = np.where(better, tn.ravel()[i_ax], t_ax)
        side_ax = np.where(better, 1.0, side_ax)
        Fn = mag2(vn.reshape(proj.shape[0], -1))
        i_F = Fn.argmax(axis=1)
        betterF = Fn[np.arange(n_pts), i_F] > best_F
        best_F = np.where(betterF, Fn[np.arange(n_pts), i_F], best_F)
        t_F = np.where(betterF, tn.ravel()[i_F], t_F)
        side_F = np.where(betterF, 1.0, side_F)
        # the sub-intervals
        pts_t = np.concatenate([ta[:, None], tn, tb_[:, None]], axis=1)  # (na, S+1)
        pts_v = np.concatenate([va[:, :, None], vn, vb[:, :, None]], axis=2)  # (R, na, S+1)
        ta = pts_t[:, :-1].ravel()
        tb_ = pts_t[:, 1:].ravel()
        sg = np.repeat(sg, _SUBDIVIDE)
        d1, d2 = np.repeat(d1, _SUBDIVIDE, axis=1), np.repeat(d2, _SUBDIVIDE, axis=1)
        va = pts_v[:, :, :-1].reshape(proj.shape[0], -1)
        vb = pts_v[:, :, 1:].reshape(proj.shape[0], -1)
        u_ax, u_F = bounds(tb_ - ta, va, vb, d1, d2)

    up_ax = np.maximum(np.maximum(best_ax, drop_ax), u_ax.max(axis=1, initial=0.0))
    up_F = np.maximum(np.maximum(best_F, drop_F), u_F.max(axis=1, initial=0.0))
    out: dict[str, PeakResponse] = {}
    for i, name in enumerate(names):
        r = slice(3 * i, 3 * i + 3)
        out[name] = PeakResponse(
            name=name,
            window_s=(t_lo, t_hi),
            peak_accel_mps2=float(np.sqrt(best_F[i])),
            peak_time_s=float(t_F[i]),
            peak_side="left" if side_F[i] == 0 else "right",
            upper_bound_mps2=float(np.sqrt(up_F[i])),
            peak_accel_mps2_axis=best_ax[r].copy(),
            peak_time_s_axis=np.asarray(t_ax[r], float).copy(),
            upper_bound_mps2_axis=up_ax[r].copy(),
            sampled_peak_accel_mps2=float(sampled[i]),
            rounds=rounds,
        )
    return out
