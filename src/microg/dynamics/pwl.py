"""The exact modal response to piecewise-linear forces: the kernel (pure functions of arrays).

Each modal coordinate obeys (report Eq. 2.15, with modal damping added)::

    eta'' + 2 zeta omega eta' + omega^2 eta = p(t),      eta(t0) = eta'(t0) = 0,

where ``p = phi^T f / modal_mass`` is piecewise linear between breakpoints.  On a segment
starting at ``t_k`` with state ``(eta_k, v_k)`` and force ``p = p_k + s_k tau``
(``tau = t - t_k``) the solution is, exactly::

    eta(tau) = eta_k g(tau) + v_k h(tau) + p_k S(tau) + s_k R(tau)
    v(tau)   = v_k g(tau) + a_k h(tau) + s_k S(tau)            (v obeys the ODE with p = s_k)
    a(tau)   = a_k g(tau) + j_k h(tau)                          (a obeys the free ODE)

with ``a_k = p_k - 2 zeta omega v_k - omega^2 eta_k`` (the equation of motion, right-continuous at
a jump of p), ``j_k = s_k - 2 zeta omega a_k - omega^2 v_k``, and the four functions ``g, h, S,
R`` of the mode (:mod:`microg.dynamics.oscillator`).

The start states of all segments are the chain of the segments' affine state maps, computed by
the one blocked O(K) scan :func:`microg._scan.affine_scan`, vectorised over modes
(:func:`prepare`, a :class:`ModalState`).  The output times are then split into uniformly
spaced runs inside one segment, each evaluated by two small tables of exact exponentials and one
batched matrix product (:func:`_table_run`), and the rest, evaluated directly by the closed form
(:func:`evaluate`, which can contract the modes with rows ``T phi`` block by block, never
building the (3, modes, times) array).

Conventions: the force is zero before the first breakpoint; a repeated breakpoint time is a jump
(the last value at that time holds from it on, i.e. the force is right-continuous; times closer than
4 roundings of max(|t|, 1 s) count as repeated); after the last breakpoint the force holds its last
value.

The kernels trust their inputs; :func:`check_inputs` is the one check, made by the public
entries of :mod:`microg.dynamics.response`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from microg._scan import affine_scan
from microg.dynamics.oscillator import (
    SERIES_BELOW,
    exp_table,
    oscillator_functions,
    sinc,
    step_ramp_series,
)
from microg.errors import InputError

if TYPE_CHECKING:
    from microg.dynamics.forces import ForceHistory

__all__ = [
    "ModalState",
    "check_inputs",
    "evaluate",
    "prepare",
    "superposed_force",
]


def _validate(
    omega: np.ndarray,
    zeta: np.ndarray,
    timepts_force: np.ndarray,
    modal_force: np.ndarray,
    timepts_out: np.ndarray,
) -> None:
    if omega.ndim != 1:
        raise InputError("omega must be a 1-D array of rad/s", where="modal_pwl_response: omega")
    m = omega.size
    if zeta.shape != (m,):
        raise InputError(f"zeta must have shape ({m},)", where="modal_pwl_response: zeta")
    if timepts_force.ndim != 1 or timepts_force.size < 1:
        raise InputError("need at least one force breakpoint", where="modal_pwl_response")
    if modal_force.shape != (m, timepts_force.size):
        raise InputError(
            f"modal_force must have shape ({m}, {timepts_force.size}), got {modal_force.shape}",
            where="modal_pwl_response: modal_force",
        )
    if timepts_out.ndim != 1:
        raise InputError("timepts_out must be 1-D", where="modal_pwl_response: timepts_out")
    checks = [
        (np.all(np.isfinite(omega)) and np.all(omega >= 0), "omega must be finite and >= 0"),
        (
            np.all(np.isfinite(zeta)) and np.all(zeta >= 0) and np.all(zeta < 1),
            "zeta must satisfy 0 <= zeta < 1 (critical and over-damped modes are not supported)",
        ),
        (np.all(np.isfinite(timepts_force)), "force breakpoint times must be finite"),
        (np.all(np.diff(timepts_force) >= 0), "force breakpoint times must be non-decreasing"),
        (np.all(np.isfinite(modal_force)), "modal forces must be finite"),
        (np.all(np.isfinite(timepts_out)), "output times must be finite"),
        (np.all(np.diff(timepts_out) >= 0), "output times must be sorted"),
    ]
    for ok, msg in checks:
        if not ok:
            raise InputError(msg, where="modal_pwl_response")


def _segments(
    timepts_force: np.ndarray, modal_force: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Unique breakpoint times, right values p_k, slopes s_k and lengths of the finite segments."""
    t = timepts_force
    # times equal to within a few roundings are one time (a jump), not a vanishing ramp
    new_time = np.diff(t) > 4.0 * np.spacing(max(float(np.max(np.abs(t))), 1.0))
    last = np.r_[new_time, True]  # last occurrence of each time: right value
    first = np.r_[True, new_time]  # first occurrence: left value (end of previous segment)
    starts = t[last]
    p_right = modal_force[:, last]  # (m, K)
    p_left = modal_force[:, first]  # (m, K)
    lengths = np.diff(starts)  # (K-1,)
    slopes = np.zeros_like(p_right)
    if lengths.size:
        slopes[:, :-1] = (p_left[:, 1:] - p_right[:, :-1]) / lengths
    return starts, p_right, slopes, lengths


def _start_states(
    omega: np.ndarray,
    zeta: np.ndarray,
    p_right: np.ndarray,
    slopes: np.ndarray,
    lengths: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """States (eta, eta') at the start of every segment, zero at the first breakpoint.

    Segment k maps its start state z_k to z_{k+1} = M_k z_k + c_k; the chain of these affine
    maps is :func:`microg._scan.affine_scan` (vectorised over modes).
    """
    m, K = p_right.shape
    if K == 1:
        return np.zeros((m, 1)), np.zeros((m, 1))
    w = omega[:, None]
    z = zeta[:, None]
    tau = lengths[None, :]
    g, h, S, R = oscillator_functions(w, z, tau)
    assert R is not None
    p = p_right[:, :-1]
    s = slopes[:, :-1]
    # state map of one segment: [eta, v] -> [[g, h], [-w^2 h, g - 2 sigma h]] [eta, v] + c
    # (v(tau) = v0 g + a0 h + s S with a0 = p - 2 sigma v0 - w^2 eta0)
    maps = np.empty((m, K - 1, 2, 2))
    maps[..., 0, 0] = g
    maps[..., 0, 1] = h
    maps[..., 1, 0] = -(w * w) * h
    maps[..., 1, 1] = g - 2.0 * z * w * h
    offsets = np.stack([p * S + s * R, p * h + s * S], axis=-1)
    states = affine_scan(maps, offsets)  # (m, K, 2)
    return states[..., 0], states[..., 1]


@dataclass(frozen=True)
class ModalState:
    """Modal state at the start of every force segment (what :func:`evaluate` reads).

    ``omega`` (m,) rad/s, ``zeta`` (m,); ``starts`` (K,) s; the others (m, K): eta, eta',
    eta'' (right-continuous), eta''' and the force value p and slope s on the segment, in the
    modal unit of ``p`` (e.g. m sqrt(kg) for eta of mass-normalised modes) per s^d.
    """

    omega: np.ndarray
    zeta: np.ndarray
    starts: np.ndarray
    eta: np.ndarray
    vel: np.ndarray
    acc: np.ndarray
    jerk: np.ndarray
    p: np.ndarray
    s: np.ndarray

    @property
    def rigid(self) -> np.ndarray:
        """Indices of the rigid modes (omega = 0)."""
        return np.flatnonzero(self.omega == 0)

    @property
    def elastic(self) -> np.ndarray:
        """Indices of the modes with omega > 0."""
        return np.flatnonzero(self.omega != 0)


def prepare(
    omega: np.ndarray, zeta: np.ndarray, timepts_force: np.ndarray, modal_force: np.ndarray
) -> ModalState:
    """The state of every mode at the start of every force segment (the affine scan).

    Parameters
    ----------
    omega : (m,) natural frequencies, rad/s (0 for rigid modes)
    zeta : (m,) modal damping ratios, 0 <= zeta < 1
    timepts_force : (nb,) breakpoint times, s, non-decreasing (a repeated time is a jump)
    modal_force : (m, nb) modal force at each breakpoint (see
        :func:`microg.dynamics.response.modal_pwl_response`)
    """
    starts, p_right, slopes, lengths = _segments(timepts_force, modal_force)
    eta_k, vel_k = _start_states(omega, zeta, p_right, slopes, lengths)
    w = omega[:, None]
    two_sigma = 2.0 * zeta[:, None] * w
    w2 = w * w
    acc_k = p_right - two_sigma * vel_k - w2 * eta_k
    jerk_k = slopes - two_sigma * acc_k - w2 * vel_k
    return ModalState(omega, zeta, starts, eta_k, vel_k, acc_k, jerk_k, p_right, slopes)


def check_inputs(
    omega: np.ndarray,
    zeta: np.ndarray | float,
    timepts_force: np.ndarray,
    modal_force: np.ndarray,
    timepts_out: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The kernel's inputs as float arrays, checked once (``InputError`` naming the argument).

    Parameters are those of :func:`microg.dynamics.response.modal_pwl_response` (rad/s, -, s,
    modal force, s); a scalar ``zeta`` is broadcast to every mode.
    """
    omega = np.asarray(omega, dtype=float)
    zeta = np.broadcast_to(np.asarray(zeta, dtype=float), omega.shape).astype(float)
    timepts_force = np.asarray(timepts_force, dtype=float)
    modal_force = np.asarray(modal_force, dtype=float)
    if modal_force.ndim == 1 and omega.size == 1:
        modal_force = modal_force[None, :]
    timepts_out = np.asarray(timepts_out, dtype=float)
    _validate(omega, zeta, timepts_force, modal_force, timepts_out)
    return omega, zeta, timepts_force, modal_force, timepts_out


# --------------------------------------------------------------------------- evaluation

#: uniform runs of at least this many output times (inside one segment) use the table path
_MIN_RUN = 64
#: output times per evaluation block when projecting onto points (bounds the scratch memory)
_CHUNK = 4096


def _runs(t: np.ndarray, starts: np.ndarray) -> tuple[list[tuple[int, int, int]], np.ndarray]:
    """Uniform runs ``(segment, i0, i1)`` of the output times and the indices of the others.

    A run is a maximal set of consecutive output times inside one force segment with equal
    spacing (to a few roundings of the largest time, and within that of ``t0 + i dt``); runs
    shorter than :data:`_MIN_RUN` and irregular times are returned as indices for the direct
    (gathered) evaluation.  Times before the first breakpoint are in neither (zero response).
    """
    nt = t.size
    seg = np.searchsorted(starts, t, side="right") - 1
    tol = 8.0 * np.spacing(max(float(np.max(np.abs(t))) if nt else 0.0, 1.0))
    runs: list[tuple[int, int, int]] = []
    covered = np.zeros(nt + 1, dtype=np.int64)
    if nt >= 2:
        d = np.diff(t)
        valid = (seg[1:] == seg[:-1]) & (seg[1:] >= 0)  # diff j joins points j, j+1
        same = np.r_[False, np.abs(np.diff(d)) <= tol] & np.r_[False, valid[:-1]]
        first = valid & ~same  # a diff that starts a new run
        j0 = np.flatnonzero(first)
        if j0.size:
            run_id = np.cumsum(first) - 1
            j_last = np.flatnonzero(valid)
            # last valid diff of each run
            ends = np.zeros(j0.size, dtype=np.intp)
            np.maximum.at(ends, run_id[j_last], j_last)
            p1 = ends + 1  # last point of each run (inclusive)
            p0 = np.maximum(j0, np.r_[-1, p1[:-1]] + 1)  # a shared point goes to the earlier run
            long = np.flatnonzero(p1 - p0 + 1 >= _MIN_RUN)
            for r in long:
                i0, i1 = int(p0[r]), int(p1[r]) + 1
                tt = t[i0:i1]
                n = i1 - i0
                dt = (tt[-1] - tt[0]) / (n - 1)
                if np.max(np.abs(tt - (tt[0] + np.arange(n) * dt))) > tol:
                    continue  # a slowly drifting spacing: not uniform, evaluate directly
                runs.append((int(seg[i0]), i0, i1))
                covered[i0] += 1
                covered[i1] -= 1
    mask = (np.cumsum(covered[:nt]) == 0) & (seg >= 0)
    return runs, np.flatnonzero(mask)


def _table_run(
    st: ModalState,
    k: int,
    tau: np.ndarray,
    qs: tuple[int, ...],
    dest: np.ndarray,
    defer: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]] | None = None,
    offset: int = 0,
) -> None:
    """Quantities ``qs`` (0 eta, 1 eta', 2 eta'') of all modes on a uniform run of segment k.

    Writes ``dest`` (len(qs), m, n).  Elastic modes: with E = exp(lambda tau), lambda =
    -sigma + i omega_d, each quantity is ``Re E * cc + Im E * cs + q0 + q1 tau`` with per-mode
    coefficients folding in the start state and the force.  On the run tau_i = tau_0 + i dt,
    with i = b L + r, E_i = exp(lambda (tau_0 + b L dt)) exp(lambda r dt): two small tables of
    direct evaluations, and the whole block is one batched matrix product with inner dimension 4
    (a few roundings per entry, no recurrence).  Where omega tau < SERIES_BELOW (a prefix of the
    run for each mode) the folded eta and eta' lose digits by cancellation; those entries are
    recomputed with :func:`oscillator_functions` (eta'' has no cancellation).  Rigid modes are
    the exact polynomials of a double integration.
    """
    n = tau.size
    nq = len(qs)
    e0, v0, a0, j0, p0, s0 = (x[:, k] for x in (st.eta, st.vel, st.acc, st.jerk, st.p, st.s))
    rigid, el = st.rigid, st.elastic
    if rigid.size:
        polys = {
            0: (e0[rigid], v0[rigid], p0[rigid] / 2.0, s0[rigid] / 6.0),
            1: (v0[rigid], p0[rigid], s0[rigid] / 2.0, np.zeros(rigid.size)),
            2: (p0[rigid], s0[rigid], np.zeros(rigid.size), np.zeros(rigid.size)),
        }
        powers = np.empty((4, n))
        powers[0] = 1.0
        powers[1] = tau
        np.multiply(tau, tau, out=powers[2])
        np.multiply(powers[2], tau, out=powers[3])
        coef = np.stack([np.stack(polys[q], axis=1) for q in qs])  # (nq, r, 4)
        if rigid[-1] - rigid[0] + 1 == rigid.size:  # a slice: the product written in place
            np.matmul(coef, powers, out=dest[:, int(rigid[0]) : int(rigid[-1]) + 1])
        else:
            dest[:, rigid] = coef @ powers
    if not el.size:
        return
    omega, zeta = st.omega[el], st.zeta[el]
    e0, v0, a0, j0, p0, s0 = e0[el], v0[el], a0[el], j0[el], p0[el], s0[el]
    sigma = zeta * omega
    omega_d = omega * np.sqrt(1.0 - zeta * zeta)
    w2 = omega * omega
    beta = s0 / w2
    alpha = p0 / w2 - 2.0 * sigma * s0 / (w2 * w2)
    zero = np.zeros_like(omega)
    cc_all = (e0 - alpha, v0 - beta, a0)  # coefficient of Re E
    nxt = (v0 - beta, a0, j0)
    cc = np.stack([cc_all[q] for q in qs])  # (nq, me)
    cs = (sigma * cc + np.stack([nxt[q] for q in qs])) / omega_d  # coefficient of Im E
    q0 = np.stack([(alpha, beta, zero)[q] for q in qs])
    q1 = np.stack([(beta, zero, zero)[q] for q in qs])
    lam = (-sigma + 1j * omega_d)[:, None]
    me = el.size
    dt = (tau[-1] - tau[0]) / (n - 1) if n > 1 else 0.0
    L = max(1, int(np.ceil(np.sqrt(n))))
    nb = -(-n // L)
    tau_b = tau[0] + (np.arange(nb) * L) * dt
    A = exp_table(lam, float(tau[0]), L * dt, nb)  # (me, nb)
    rdt = np.arange(L) * dt
    W = exp_table(lam, 0.0, dt, L)  # (me, L)
    # Re E cc + Im E cs = Re(Z), Z = (cc - i cs) E, and the other column -Im(Z)
    lhs = np.empty((nq, me, nb, 4))
    Z = (cc - 1j * cs)[:, :, None] * A
    lhs[..., 0] = Z.real
    np.negative(Z.imag, out=lhs[..., 1])
    poly = [iq for iq, q in enumerate(qs) if q < 2]
    if poly:
        ps = slice(poly[0], poly[-1] + 1)
        np.multiply(q1[ps, :, None], tau_b, out=lhs[ps, :, :, 2])
        lhs[ps, :, :, 2] += q0[ps, :, None]
        lhs[ps, :, :, 3] = q1[ps, :, None]
    rhs = np.empty((me, 4, L))
    rhs[:, 0] = W.real
    rhs[:, 1] = W.imag
    rhs[:, 2] = 1.0
    rhs[:, 3] = rdt
    full_blocks = n // L
    rem = n - full_blocks * L
    contiguous = el[-1] - el[0] + 1 == me
    rows = slice(int(el[0]), int(el[-1]) + 1) if contiguous else el
    target = dest[:, rows] if contiguous else np.empty((nq, me, n))
    # eta'' has no polynomial part: its rows need only the inner dimension 2
    groups = [[iq for iq, q in enumerate(qs) if q < 2], [iq for iq, q in enumerate(qs) if q == 2]]
    for grp, width in zip(groups, (4, 2), strict=True):
        if not grp:
            continue
        sl = slice(grp[0], grp[-1] + 1)  # qs is ordered, so each group is a contiguous slice
        lh, rh = lhs[sl, :, :, :width], rhs[:, :width]
        tg = target[sl]
        if full_blocks:
            body = tg[:, :, : full_blocks * L].reshape(len(grp), me, full_blocks, L)
            # splitting the last axis of a slice is always a view: the product lands in tg
            np.matmul(lh[:, :, :full_blocks], rh, out=body)
        if rem:
            tg[:, :, full_blocks * L :] = (lh[:, :, -1, None, :] @ rh[:, :, :rem])[:, :, 0]
    # stable recomputation of eta, eta' where omega tau < SERIES_BELOW: only those entries (a
    # prefix of the run for each mode), gathered flat, so a run starting at a breakpoint costs
    # about sum_j 0.5 / (omega_j dt) evaluations instead of a (modes x longest prefix) block;
    # with ``defer`` they are handed back (segment, mode, column offset + i, tau) and written by
    # the caller, all runs in one call of :func:`_small_tau_values`
    fix = [iq for iq, q in enumerate(qs) if q < 2]
    if fix:
        n_small = np.searchsorted(tau, SERIES_BELOW / omega, side="left")
        total = int(n_small.sum())
        if total:
            sel = np.flatnonzero(n_small)
            cnt = n_small[sel]
            rows_f = np.repeat(sel, cnt)  # elastic-mode index of each entry
            starts_f = np.cumsum(cnt) - cnt
            cols_f = np.arange(total) - np.repeat(starts_f, cnt)  # position in the run
            if defer is not None:
                defer.append((k, el[rows_f], cols_f + offset, tau[cols_f]))
            else:
                small = _small_tau_values(st, np.full(total, k), el[rows_f], tau[cols_f], qs)
                for iq in fix:
                    target[iq][rows_f, cols_f] = small[iq]
    if not contiguous:
        dest[:, el] = target


def _small_tau_values(
    st: ModalState, seg: np.ndarray, mode: np.ndarray, tau: np.ndarray, qs: tuple[int, ...]
) -> list[np.ndarray | None]:
    """eta, eta' (those of ``qs`` below 2) of single entries (segment, mode, elapsed time).

    The closed form ``e g + v h + p S + s R`` and ``v g + a h + s S`` with S, R from their
    series (every entry has ``omega tau < SERIES_BELOW``); None for the other quantities.
    """
    omega, zeta = st.omega[mode], st.zeta[mode]
    sigma_tau = zeta * omega * tau
    theta = omega * np.sqrt(1.0 - zeta * zeta) * tau
    tsinc = tau * sinc(theta)  # sin(omega_d tau) / omega_d
    decay = np.exp(-sigma_tau)  # sigma tau < 0.5 here: no underflow
    h = decay * tsinc
    g = decay * (np.cos(theta) + (zeta * omega) * tsinc)
    S, R = step_ramp_series(omega * tau, 2.0 * sigma_tau, tau)
    vv = st.vel[mode, seg]
    out: list[np.ndarray | None] = []
    for q in qs:
        if q == 0:
            out.append(st.eta[mode, seg] * g + vv * h + st.p[mode, seg] * S + st.s[mode, seg] * R)
        elif q == 1:
            out.append(vv * g + st.acc[mode, seg] * h + st.s[mode, seg] * S)
        else:
            out.append(None)
    return out


def _direct(st: ModalState, seg: np.ndarray, tau: np.ndarray, qs: tuple[int, ...]) -> np.ndarray:
    """Quantities ``qs`` of all modes at elapsed times ``tau`` into segments ``seg`` (>= 0).

    The closed form of the module docstring evaluated directly, shape (len(qs), m, n).
    """
    w, z = st.omega[:, None], st.zeta[:, None]
    g, h, S, R = oscillator_functions(w, z, tau[None, :], need_ramp=0 in qs)
    out = np.empty((len(qs), st.omega.size, tau.size))
    for iq, q in enumerate(qs):
        if q == 0:
            assert R is not None
            out[iq] = st.eta[:, seg] * g + st.vel[:, seg] * h + st.p[:, seg] * S + st.s[:, seg] * R
        elif q == 1:
            out[iq] = st.vel[:, seg] * g + st.acc[:, seg] * h + st.s[:, seg] * S
        else:
            out[iq] = st.acc[:, seg] * g + st.jerk[:, seg] * h
    return out


def evaluate(
    st: ModalState, t: np.ndarray, qs: tuple[int, ...], project: np.ndarray | None = None
) -> np.ndarray:
    """Quantities ``qs`` at the output times ``t``: (len(qs), m, nt), or projected (len(qs), r, nt).

    ``project`` (r, m) contracts the modes block by block (at most :data:`_CHUNK` times at a
    time), so the (len(qs), m, nt) modal array is never built.  Uniform runs take the table path
    (:func:`_table_run`), everything else the direct closed form; zero before the first
    breakpoint.

    Parameters
    ----------
    st : the modal state of the force (:func:`prepare`)
    t : (nt,) sorted output times, s
    qs : derivatives wanted, each 0 (eta), 1 (eta') or 2 (eta''), in increasing order
    project : (r, m) rows to contract the modes with (e.g. ``T phi``, m per modal unit)

    Returns
    -------
    ndarray in the modal unit (times the projection's) per s^d.
    """
    m, nt, nq = st.omega.size, t.size, len(qs)
    rows = m if project is None else project.shape[0]
    # every entry is written below (np.empty: no zero-filled pages to fault in first)
    out = np.empty((nq, rows, nt))
    out[:, :, : int(np.searchsorted(t, st.starts[0], side="left"))] = 0.0  # before the force
    runs, rest = _runs(t, st.starts)
    scratch = None if project is None else np.empty((nq, m, min(_CHUNK, max(nt, 1))))
    defer: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]] = []
    for k, i0, i1 in runs:
        if project is None:
            _table_run(st, k, t[i0:i1] - st.starts[k], qs, out[:, :, i0:i1], defer, i0)
            continue
        assert scratch is not None
        for c0 in range(i0, i1, _CHUNK):
            c1 = min(c0 + _CHUNK, i1)
            buf = scratch[:, :, : c1 - c0]
            _table_run(st, k, t[c0:c1] - st.starts[k], qs, buf)
            for iq in range(nq):  # 2-D products (BLAS), then one copy into the strided output
                out[iq, :, c0:c1] = project @ buf[iq]
    if defer:  # the small-omega-tau entries of every run, in one evaluation
        seg_f, mode_f, col_f, tau_f = (
            np.concatenate(x)
            for x in zip(
                *[(np.full(m_.size, k), m_, c_, t_) for k, m_, c_, t_ in defer], strict=True
            )
        )
        vals_f = _small_tau_values(st, seg_f, mode_f, tau_f, qs)
        for iq, v in enumerate(vals_f):
            if v is not None:
                out[iq][mode_f, col_f] = v
    seg_all = np.searchsorted(st.starts, t, side="right") - 1
    for c0 in range(0, rest.size, _CHUNK):
        idx = rest[c0 : c0 + _CHUNK]
        seg = seg_all[idx]
        vals = _direct(st, seg, t[idx] - st.starts[seg], qs)
        if project is None:
            out[:, :, idx] = vals
        else:
            for iq in range(nq):
                out[iq][:, idx] = project @ vals[iq]
    return out


def _one_sided(force: ForceHistory, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Limits from the left and values (right-continuous) of a force history at times ``u``."""
    tp, fp = force.breakpoints
    right = force.at(u)
    i = np.searchsorted(tp, u, side="left") - 1  # last breakpoint strictly before u
    last = tp.size - 1
    i_c = np.clip(i, 0, max(last - 1, 0))
    if last == 0:
        left = np.full(u.shape, fp[0])
    else:
        t0, t1 = tp[i_c], tp[i_c + 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where(t1 > t0, (u - t0) / (t1 - t0), 1.0)
        left = fp[i_c] + (fp[i_c + 1] - fp[i_c]) * frac
    left = np.where(i >= last, fp[-1], left)
    return np.where(i < 0, 0.0, left), right


def superposed_force(
    loads: Sequence[tuple[ForceHistory, np.ndarray]],
) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoints and modal force of the sum of several loads, for :func:`prepare`.

    The sum of piecewise-linear forces is piecewise linear on the union of their breakpoints.
    Every union time appears twice: first with the limit from the left, then with the value from
    that time on (a jump where they differ; :func:`prepare` merges equal times).

    Parameters
    ----------
    loads : non-empty sequence of (force history, (m,) modal participation ``phi^T b`` per
        newton); force in N

    Returns
    -------
    timepts_force : (2 U,) s
    modal_force : (m, 2 U) modal force p_j per unit modal mass, m/s^2 per unit coordinate
    """
    u = np.unique(np.concatenate([f.breakpoints[0] for f, _ in loads]))
    pf = np.zeros((np.shape(loads[0][1])[0], 2 * u.size))
    for force, gamma in loads:
        left, right = _one_sided(force, u)
        pf[:, 0::2] += np.outer(gamma, left)
        pf[:, 1::2] += np.outer(gamma, right)
    return np.repeat(u, 2), pf
