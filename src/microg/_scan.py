"""The one affine prefix scan: states of a chain of affine maps ``x_{k+1} = M_k x_k + c_k``.

Both exact time integrators of microg reduce to this recurrence: the modal response
(:mod:`microg.dynamics.response`: one 2x2 map per mode and force segment, the start state of every
segment) and the isolator's first-order-hold response (:mod:`microg.isolation.timedomain`: one
``n x n`` map per time step, ``n`` = 2 or 4).

Algorithm (O(K) work, O(sqrt K) Python steps, each vectorised over the batch axes and blocks).
The K maps are cut into ``B`` blocks of ``L`` consecutive maps (``B L >= K``, the tail padded
with identity maps):

1. run the recurrence inside every block at once from a zero start (``L`` steps on arrays of
   ``B`` blocks), keeping each block's end state ``e_b`` and, unless all maps are equal, the
   block's composed map ``P_b = M_{bL+L-1} ... M_{bL}`` (equal maps: ``P = M^L`` once);
2. carry the block start states ``s_{b+1} = P_b s_b + e_b`` (``B`` small steps);
3. run the recurrence inside every block again from ``s_b``, storing every state.

Every state is therefore the plain forward recurrence, except that a block's start state comes
from the composed maps (the same products in another order): the result equals a sequential loop
to a few roundings per block, with no log-depth amplification.  Short chains (K <= 64) are one
sequential loop.  Costs for K = 10^6 steps of a 4-state map: about 2 x 1000 vectorised steps.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["affine_scan", "lti_scan", "scalar_scan", "SEQUENTIAL_BELOW"]

#: chains of at most this many maps are one sequential loop (vectorised over the batch axes)
SEQUENTIAL_BELOW = 64


def _matvec(M: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``M @ x`` over leading axes, ``M`` (..., n, n), ``x`` (..., n); unrolled for small n."""
    n = x.shape[-1]
    if n <= 4:
        y = M[..., :, 0] * x[..., 0, None]
        for j in range(1, n):
            y += M[..., :, j] * x[..., j, None]
        return y
    return np.matmul(M, x[..., None])[..., 0]


def affine_scan(
    M: NDArray[np.float64],
    c: NDArray[np.float64],
    *,
    index: NDArray[np.intp] | None = None,
    x0: NDArray[np.float64] | None = None,
    block: int | None = None,
) -> NDArray[np.float64]:
    """All states of ``x_{k+1} = M_k x_k + c_k``, k = 0 .. K-1, from ``x_0`` (zero by default).

    Parameters
    ----------
    M : ndarray, shape (..., U, n, n)
        The maps (dimensionless or in the units that make ``M x`` a state).  Without ``index``
        ``U`` must equal K and ``M_k = M[..., k, :, :]``; with ``index`` the ``U`` distinct maps
        are shared, ``M_k = M[..., index[k], :, :]`` (steps of equal length share one map).
    c : ndarray, shape (..., K, n)
        The offsets, in the units of the state.
    index : ndarray of int, shape (K,), optional
        Map of each step into ``M``'s ``U`` axis.
    x0 : ndarray, shape (..., n), optional
        Start state (zero when omitted).
    block : int, optional
        Block length ``L`` (default about ``sqrt(K / 2)``); a tuning knob, the result does not
        depend on it beyond rounding.

    Returns
    -------
    ndarray, shape (..., K + 1, n)
        ``X[..., 0, :] = x0`` and ``X[..., k + 1, :] = M_k X[..., k, :] + c_k``.
    """
    M = np.asarray(M, dtype=float)
    c = np.asarray(c, dtype=float)
    n = c.shape[-1]
    K = c.shape[-2]
    batch = np.broadcast_shapes(M.shape[:-3], c.shape[:-2])
    if index is not None:
        index = np.asarray(index, dtype=np.intp).reshape(-1)
        if index.size != K:
            raise ValueError(f"index has {index.size} entries for {K} offsets")
    elif M.shape[-3] != K:
        raise ValueError(f"M has {M.shape[-3]} maps for {K} offsets")
    X = np.empty((*batch, K + 1, n))
    X[..., 0, :] = 0.0 if x0 is None else x0
    if K == 0:
        return X

    def map_k(k: int | NDArray[np.intp]) -> NDArray[np.float64]:
        return M[..., k if index is None else index[k], :, :]

    if K <= SEQUENTIAL_BELOW:
        x = X[..., 0, :]
        for k in range(K):
            x = _matvec(map_k(k), x) + c[..., k, :]
            X[..., k + 1, :] = x
        return X

    L = block or max(1, math.isqrt(K // 2))
    B = -(-K // L)
    pad = B * L - K
    eye = np.eye(n)
    # offsets and maps as (..., B, L, ...) views; padded steps are identities with c = 0
    if pad:
        c = np.concatenate([c, np.zeros((*c.shape[:-2], pad, n))], axis=-2)
    # position-major copy (..., L, B, n): each vectorised step below reads and writes one
    # contiguous slab instead of B scattered rows
    c4 = np.ascontiguousarray(np.swapaxes(c.reshape(*c.shape[:-2], B, L, n), -2, -3))
    shared = index is not None and M.ndim == 3 and M.shape[0] == 1
    if shared:  # one map for every step: padded steps may use it too (their states are dropped)
        idx4 = np.zeros((B, L), dtype=np.intp)
    elif index is not None:
        if pad:
            M = np.concatenate([M, np.broadcast_to(eye, (*M.shape[:-3], 1, n, n))], axis=-3)
            index = np.r_[index, np.full(pad, M.shape[-3] - 1)]
        idx4 = index.reshape(B, L)
    else:
        if pad:
            M = np.concatenate([M, np.broadcast_to(eye, (*M.shape[:-3], pad, n, n))], axis=-3)
        M4 = M.reshape(*M.shape[:-3], B, L, n, n)

    def maps_at(r: int) -> NDArray[np.float64]:
        """Maps of position r in every block, shape (..., B, n, n)."""
        return M[..., idx4[:, r], :, :] if index is not None else M4[..., :, r, :, :]

    # 1. local recurrence from zero in every block, and the blocks' composed maps
    e = np.zeros((*batch, B, n))
    if shared:
        MT = M[0].T.copy()
        for r in range(L):
            e = e @ MT
            e += c4[..., r, :, :]
        P = np.broadcast_to(np.linalg.matrix_power(M[0], L), (B, n, n))
    else:
        P = np.broadcast_to(eye, (*batch, B, n, n)).copy()
        for r in range(L):
            Mr = maps_at(r)
            e = _matvec(Mr, e) + c4[..., r, :, :]
            P = np.matmul(Mr, P)
    # 2. block start states
    s = np.empty((*batch, B, n))
    s[..., 0, :] = X[..., 0, :]
    for b in range(B - 1):
        s[..., b + 1, :] = _matvec(P[..., b, :, :], s[..., b, :]) + e[..., b, :]
    # 3. the recurrence again from the true block starts, storing every state
    full = np.empty((*batch, L, B, n))
    x = s
    for r in range(L):
        if shared:
            x = x @ MT
            x += c4[..., r, :, :]
        else:
            x = _matvec(maps_at(r), x) + c4[..., r, :, :]
        full[..., r, :, :] = x
    X[..., 1:, :] = np.swapaxes(full, -2, -3).reshape(*batch, B * L, n)[..., :K, :]
    return X


def lti_scan(
    Phi: NDArray[np.float64],
    G: NDArray[np.float64],
    u: NDArray[np.float64],
    C: NDArray[np.float64],
    *,
    x0: NDArray[np.float64] | None = None,
    block: int | None = None,
) -> NDArray[np.float64]:
    """Outputs ``y_k = C x_k`` of one shared map ``x_{k+1} = Phi x_k + G^T u_k``, from ``x_0``.

    The same blocked algorithm as :func:`affine_scan` for the time-invariant case (one map for
    every step, the offsets a fixed linear function of ``p`` inputs), without materialising the
    offsets or the states: only ``p`` inputs are read and ``q`` outputs written per step, which
    is what makes a long first-order-hold record fast.

    Parameters
    ----------
    Phi : ndarray, shape (n, n)
        The step map.
    G : ndarray, shape (p, n)
        Input map: the offset of step k is ``u_k @ G``.
    u : ndarray, shape (K, p)
        Inputs of each step.
    C : ndarray, shape (q, n)
        Output map.
    x0 : ndarray, shape (n,), optional
        Start state (zero when omitted).
    block : int, optional
        Block length (tuning only).

    Returns
    -------
    ndarray, shape (K + 1, q)
        ``Y[k] = C x_k`` for k = 0 .. K.
    """
    Phi = np.asarray(Phi, dtype=float)
    G = np.asarray(G, dtype=float)
    u = np.asarray(u, dtype=float)
    C = np.asarray(C, dtype=float)
    n = Phi.shape[0]
    K, p = u.shape
    x = np.zeros(n) if x0 is None else np.asarray(x0, dtype=float)
    Y = np.empty((K + 1, C.shape[0]))
    Y[0] = C @ x
    PhiT, CT = Phi.T.copy(), C.T.copy()
    if K <= SEQUENTIAL_BELOW:
        offs = u @ G
        for k in range(K):
            x = x @ PhiT + offs[k]
            Y[k + 1] = x @ CT
        return Y
    L = block or max(1, math.isqrt(K // 2))
    B = K // L
    head = B * L  # blocked steps; the remaining K - head < L steps continue from the last state
    uT = np.swapaxes(u[:head].reshape(B, L, p), 0, 1)  # (L, B, p) view: step b L + r at [r, b]
    # 1. local recurrence from zero in every block
    e = np.zeros((B, n))
    for r in range(L):
        e = e @ PhiT
        e += uT[r] @ G
    # 2. block start states, P = Phi^L for every block
    PL = np.linalg.matrix_power(Phi, L)
    s = np.empty((B, n))
    s[0] = x
    for b in range(B - 1):
        s[b + 1] = PL @ s[b] + e[b]
    # 3. again from the true starts, writing only the outputs
    out = Y[1 : head + 1].reshape(B, L, -1)
    xs = s
    for r in range(L):
        xs = xs @ PhiT
        xs += uT[r] @ G
        np.matmul(xs, CT, out=out[:, r, :])
    if head < K:
        end = PL @ s[-1] + e[-1]
        Y[head:] = lti_scan(Phi, G, u[head:], C, x0=end)
    return Y


#: blocks of :func:`scalar_scan` span at most this decay (or growth) of ``|prod a|``, e-folds,
#: so that the reciprocal products stay far from overflow (e^200 ~ 1e87)
SCALAR_SPAN = 200.0
#: :func:`scalar_scan` declines (returns None) when its blocks would be shorter than this
SCALAR_BLOCK_AT_LEAST = 16


def scalar_scan(
    a: NDArray[np.complexfloating] | NDArray[np.float64],
    b: NDArray[np.complexfloating] | NDArray[np.float64],
    *,
    index: NDArray[np.intp] | None = None,
    x0: NDArray[np.complexfloating] | None = None,
    weights: NDArray[np.complexfloating] | None = None,
    overwrite_b: bool = False,
    block: int | None = None,
) -> NDArray[np.complex128] | NDArray[np.float64] | None:
    """All states of scalar recurrences ``z_{k+1} = a_k z_k + b_k`` (one per row), in O(K).

    The diagonal form of a linear time-invariant step (each eigen-coordinate of the state on
    its own), evaluated with no loop over samples: the K steps are cut into blocks of ``L``;
    inside a block, with ``P_r = a_0 ... a_r`` and ``Q_r = (1/a_0) ... (1/a_r)`` (running
    products of the block's steps), ``z_{r+1} = P_r (z_0 + sum_{j<=r} Q_j b_j)`` (one
    ``cumprod`` and one ``cumsum``); the block start states follow from the blocks' end products
    by a loop over the ``K / L`` blocks.  The rounding of ``Q_j b_j`` in the running sum is
    ``eps |b_j| |P_r / P_j|`` at step r, the sequential loop's own bound: the same accuracy.
    Blocks span at most :data:`SCALAR_SPAN` e-folds of ``|a|`` so that ``Q`` cannot overflow;
    when that would make them shorter than :data:`SCALAR_BLOCK_AT_LEAST` steps (a coordinate
    that decays by more than ~e^12 in one step) the function returns None: the caller takes
    another method.

    Parameters
    ----------
    a : ndarray, shape (m, U)
        Step factors (dimensionless), the ``U`` distinct steps of each row.
    b : ndarray, shape (m, K)
        Offsets, in the units of the state.
    index : ndarray of int, shape (K,), optional
        Distinct step of every step (``a[:, index[k]]``); omitted: ``U`` must be 1 (every step
        the same) or K.
    x0 : ndarray, shape (m,), optional
        Start states (zero when omitted).
    weights : ndarray, shape (q, m), optional
        Return only the real outputs ``Re(weights @ Z)`` instead of the states.
    overwrite_b : bool
        ``b`` (complex) may be used as workspace (saves a copy of the size of ``b``).
    block : int, optional
        Block length (tuning only).

    Returns
    -------
    ndarray or None
        States ``Z`` (m, K + 1), complex: ``Z[:, 0] = x0`` and ``Z[:, k + 1] = a_k Z[:, k] +
        b_k``; with ``weights`` the outputs (q, K + 1), real.  None where declined (above).
    """
    a = np.asarray(a, dtype=complex)
    b = np.asarray(b, dtype=complex)
    m, K = b.shape
    U = a.shape[1]
    if index is None and U not in (1, K):
        raise ValueError(f"a has {U} steps for {K} offsets and no index")
    start = np.zeros(m, complex) if x0 is None else np.asarray(x0, complex)
    if weights is None:
        Z = np.empty((m, K + 1), dtype=complex)
        Z[:, 0] = start
    else:
        w = np.asarray(weights, complex)
        Y = np.zeros((w.shape[0], K + 1))
        Y[:, 0] = (w @ start).real
    if K == 0:
        return Z if weights is None else Y
    with np.errstate(divide="ignore"):
        decay = float(np.max(np.abs(np.log(np.abs(a))), initial=0.0))
    if not np.isfinite(decay):
        return None
    L = block or max(SEQUENTIAL_BELOW, math.isqrt(2 * K))
    if decay * L > SCALAR_SPAN:
        L = int(SCALAR_SPAN / decay)
        if L < SCALAR_BLOCK_AT_LEAST and K > L:
            return None
    L = max(1, min(L, K))
    B, tail = divmod(K, L)
    for i in range(m):
        s = complex(start[i])
        # the whole blocks, then the last partial block alone (no padded copies)
        for k0, nb, nl in ((0, B, L), (B * L, 1 if tail else 0, tail)):
            if not nb:
                continue
            k1 = k0 + nb * nl
            if index is None and U == 1:  # every step the same: the products once, shared
                P = np.cumprod(np.full(nl, a[i, 0]))
                Q = np.cumprod(np.full(nl, 1.0 / a[i, 0]))
            else:
                ai = a[i, k0:k1] if index is None else a[i, index[k0:k1]]
                qi = 1.0 / ai if index is None else (1.0 / a[i])[index[k0:k1]]
                P = np.cumprod(ai.reshape(nb, nl), axis=1)
                Q = np.cumprod(qi.reshape(nb, nl), axis=1)
            bi = b[i, k0:k1].reshape(nb, nl)
            into = Q if Q.ndim == 2 else (bi if overwrite_b and b.dtype == complex else None)
            loc = np.multiply(bi, Q, out=into)
            np.cumsum(loc, axis=1, out=loc)
            # block start states: s_{j+1} = P_end(j) (s_j + S_end(j)), a loop over the blocks
            p_end = np.broadcast_to(P, (nb, nl))[:, -1].tolist()
            s_end = loc[:, -1].tolist()
            starts = [s]
            for j in range(nb - 1):
                starts.append(p_end[j] * (starts[j] + s_end[j]))
            s = p_end[-1] * (starts[-1] + s_end[-1])
            loc += np.array(starts)[:, None]
            if weights is None:
                loc *= P
                Z[i, k0 + 1 : k1 + 1] = loc.reshape(-1)
            else:  # Re(w P S) for every output: one complex product each
                for q in range(w.shape[0]):
                    Y[q, k0 + 1 : k1 + 1] += np.multiply(loc, w[q, i] * P).real.reshape(-1)
    return Z if weights is None else Y
