"""Package acceleration for a sampled mount acceleration history, exact for piecewise-linear input.

The package ``m1`` on the mount spring ``k1`` (and optional parallel damper ``c1``, not in the
report), with the optional absorber ``m2``, ``k2``, ``c`` of the report's Figure 7 (Eq. 4.1), is
linear and time invariant.  In relative coordinates ``z_i = u_i - u0``

    m1 z1'' + c1 z1' + c (z1' - z2') + k1 z1 + k2 (z1 - z2) = -m1 a0(t)
    m2 z2'' + c (z2' - z1') + k2 (z2 - z1) = -m2 a0(t)

and the package's absolute acceleration is ``u1'' = z1'' + a0`` (no feedthrough).  Writing this as
``x' = A x + B a0``, ``y = C x`` and taking ``a0`` linear between samples (first-order hold), the
exact step from ``t_j`` to ``t_j + h`` is read from one matrix exponential of the augmented matrix

    expm(h [[A, B, 0], [0, 0, 1], [0, 0, 0]]) = [[Phi, G1, G2], [0, 1, h], [0, 0, 1]],
    x_{j+1} = Phi x_j + G1 a0_j + G2 (a0_{j+1} - a0_j)/h.

Steps equal to within the rounding of the time points share one step map.  When ``A``
diagonalises well (eigenvector condition number, after balancing, at most ``_COND_MAX``), the
state is taken in eigen-coordinates ``x = T V z``: each coordinate obeys a scalar recurrence
``z_{j+1} = e^{lam h} z_j + h phi1(lam h) b a0_j + h^2 phi2(lam h) b (a0_{j+1} - a0_j)/h``
(``phi1(z) = (e^z - 1)/z``, ``phi2(z) = (e^z - 1 - z)/z^2``: the same exact step), one of each
conjugate pair kept, run in O(N) on any grid by :func:`~microg._scan.scalar_scan` (running
products and sums in blocks; no loop over samples).  A defective or ill-conditioned ``A``
(critical damping), or a coordinate that decays by more than ~e^12 in one step, takes the matrix
scans instead, and so does a grid of more than ``_SCANS_ABOVE`` steps made mostly of long
uniform runs (the shared-map scan is faster there).  These read the maps from one matrix
exponential per distinct step and run the blocked O(N) scan of :mod:`microg._scan`: on a
uniform grid (one shared map) :func:`~microg._scan.lti_scan` computes only the two outputs
(package acceleration and stroke).
A grid whose steps are all whole multiples of one fine step (e.g. steps of 0.5, 1 and 2 ms in any
order) is refined onto that uniform fine grid, where the input is the same piecewise-linear
function, and takes the shared-map scan too (at most ``_REFINE_AT_MOST`` fine steps per step,
every sample kept within the rounding of its time, see :func:`_commensurate`); the samples are
picked from it.  On any other grid each run of at least ``_RUN_AT_LEAST`` equal steps takes the
shared-map scan, the state carried exactly from run to run, and the steps between runs
:func:`~microg._scan.affine_scan` (the states, one map per distinct step); a grid with fewer long
runs is one ``affine_scan``.  Both are vectorised over blocks of about sqrt(N) steps.
:func:`package_responses` runs several histories on one grid (e.g. three axes) in one call.

Initial condition: the package (and absorber) start at rest relative to the mount, ``z = z' = 0``
at ``timepts[0]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import linalg

from microg._scan import affine_scan, lti_scan, scalar_scan
from microg.errors import InputError

__all__ = [
    "IsolatorModel",
    "IsolationTimeResponse",
    "state_space",
    "foh_discretize",
    "package_response",
    "package_responses",
]


@dataclass(frozen=True)
class IsolatorModel:
    """Physical isolator: package on a mount spring, optional absorber (report Figure 7).

    Attributes
    ----------
    m1 : package mass, kg.
    k1 : mount spring stiffness, N/m.
    m2 : absorber mass, kg (0 for no absorber).
    k2 : absorber spring stiffness, N/m.
    c : absorber damping coefficient, N s/m (acts on ``u1 - u2``).
    c1 : mount damping coefficient, N s/m (acts on ``u1 - u0``; 0 in the report's model).
    """

    m1: float
    k1: float
    m2: float = 0.0
    k2: float = 0.0
    c: float = 0.0
    c1: float = 0.0

    def __post_init__(self) -> None:
        for name in ("m1", "k1"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"must be a finite number > 0, got {v!r}", where=name)
        for name in ("m2", "k2", "c", "c1"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise InputError(f"must be a finite number >= 0, got {v!r}", where=name)
        if (self.m2 > 0) != (self.k2 > 0) or (self.m2 == 0 and self.c > 0):
            raise InputError(
                "an absorber needs both m2 > 0 and k2 > 0 (and c only with them)",
                where="m2/k2/c",
                fix="give m2, k2 (and c) together, or none",
            )

    @property
    def has_absorber(self) -> bool:
        """True when an absorber mass is attached."""
        return self.m2 > 0

    @property
    def omega_n(self) -> float:
        """Mount natural frequency ``sqrt(k1/m1)``, rad/s (Eq. 4.6)."""
        return math.sqrt(self.k1 / self.m1)

    @classmethod
    def from_dimensionless(
        cls,
        m1: float,
        k1: float,
        k: float | None = None,
        mu: float | None = None,
        zeta: float = 0.0,
    ) -> IsolatorModel:
        """Build from the package and the report's ratios ``k = k1/k2``, ``mu = m2/m1``, ``zeta``.

        Parameters
        ----------
        m1 : float
            Package mass, kg.
        k1 : float
            Mount stiffness, N/m.
        k : float, optional
            Spring ratio ``k1/k2`` (Eq. 4.6); None for no absorber.
        mu : float, optional
            Mass ratio ``m2/m1`` (Eq. 4.6); None for no absorber.
        zeta : float
            Absorber damping ratio ``c/(2 sqrt(m2 k2))`` (Eq. 4.6).
        """
        if k is None or mu is None:
            return cls(m1=m1, k1=k1)
        if not (k > 0 and mu > 0 and zeta >= 0):
            raise InputError(
                f"need k > 0, mu > 0, zeta >= 0, got k={k}, mu={mu}, zeta={zeta}", where="k/mu/zeta"
            )
        m2, k2 = mu * m1, k1 / k
        return cls(m1=m1, k1=k1, m2=m2, k2=k2, c=2.0 * zeta * math.sqrt(m2 * k2))


def state_space(
    model: IsolatorModel,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(A, B, C)`` from mount acceleration (m/s^2) to package absolute acceleration (m/s^2).

    States ``[z1, z1']`` or, with an absorber, ``[z1, z2, z1', z2']`` (m, m/s), relative to the
    mount (Eq. 4.1 rewritten in ``z_i = u_i - u0``).

    Parameters
    ----------
    model : IsolatorModel
        Masses in kg, stiffnesses in N/m, damping in N s/m.
    """
    m1, k1, m2, k2, c, c1 = model.m1, model.k1, model.m2, model.k2, model.c, model.c1
    if not model.has_absorber:
        A = np.array([[0.0, 1.0], [-k1 / m1, -c1 / m1]])
        B = np.array([[0.0], [-1.0]])
        C = A[1:2, :].copy()
        return A, B, C
    A = np.array(
        [
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [-(k1 + k2) / m1, k2 / m1, -(c + c1) / m1, c / m1],
            [k2 / m2, -k2 / m2, c / m2, -c / m2],
        ]
    )
    B = np.array([[0.0], [0.0], [-1.0], [-1.0]])
    C = A[2:3, :].copy()  # u1'' = z1'' + a0 = (A x)_3
    return A, B, C


def foh_discretize(
    A: NDArray[np.float64], B: NDArray[np.float64], steps: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """First-order-hold matrices ``(Phi, G1, G2)`` for each step, from the augmented ``expm``.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        State matrix, 1/s.
    B : ndarray, shape (n, 1)
        Input matrix.
    steps : array_like, shape (m,)
        Step lengths ``h``, s.

    Returns
    -------
    Phi : ndarray, shape (m, n, n)
    G1 : ndarray, shape (m, n)
        Response to the input value at the step start.
    G2 : ndarray, shape (m, n)
        Response to the input slope over the step (multiply by ``(a0_{j+1} - a0_j)/h``).
    """
    h = np.asarray(steps, dtype=float).reshape(-1)
    n = A.shape[0]
    M = np.zeros((n + 2, n + 2))
    M[:n, :n] = A
    M[:n, n] = B[:, 0]
    M[n, n + 1] = 1.0
    E = linalg.expm(h[:, None, None] * M[None, :, :])
    return E[:, :n, :n], E[:, :n, n], E[:, :n, n + 1]


#: at most this many distinct steps are found by a linear pass each; more by one sort
_PEEL_AT_MOST = 8


def _group_steps(
    h: NDArray[np.float64], tmax: float, span: float
) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Distinct steps, merging those equal to within the rounding of the time points.

    A uniform grid (every step within the rounding of the mean step ``span / (N - 1)``) gets
    the one map of the mean step: no bias accumulates over many steps.
    """
    tol = 8.0 * np.finfo(float).eps * max(tmax, float(h.max()))
    mean = span / h.size
    if float(np.max(np.abs(h - mean))) <= tol:
        return np.array([mean]), np.zeros(h.size, dtype=np.intp)
    keys = np.rint(h / tol)
    # a few distinct steps (the usual case): peel them off in O(U N), no O(N log N) sort
    inverse = np.full(h.size, -1, dtype=np.intp)
    firsts: list[int] = []
    todo = 0
    while len(firsts) < _PEEL_AT_MOST:
        firsts.append(todo)
        inverse[keys == keys[todo]] = len(firsts) - 1
        rest = inverse[todo:] < 0
        nxt = int(np.argmax(rest))
        if not rest[nxt]:
            return h[np.array(firsts)], inverse
        todo += nxt
    _, first, inv = np.unique(keys, return_index=True, return_inverse=True)
    return h[first], inv.reshape(-1)


#: a commensurate grid is refined onto its fine step only while it has at most this many times
#: as many fine steps as steps (the uniform fast path is ~10x faster than the general scan)
_REFINE_AT_MOST = 6


def _commensurate(
    t: NDArray[np.float64], h_unique: NDArray[np.float64], index: NDArray[np.intp]
) -> tuple[NDArray[np.intp], float] | None:
    """Fine-step counts of every step when all steps are whole multiples of one fine step.

    Each distinct step ``h_u`` must be ``m_u h0`` (``h0`` the shortest) to within the rounding
    of the time points (the tolerance of :func:`_group_steps`, scaled by ``m_u + 1``), the
    refined grid must have at most :data:`_REFINE_AT_MOST` times as many steps, and its fine
    step is the exact mean ``span / sum(m)`` (no bias accumulates over many steps).  The refined
    grid must put every sample ``t_j`` at most as far from its given time as the grouped steps
    of the general path do (both differ from ``t`` only by the rounding accumulated in it, e.g.
    ``t = cumsum(steps)``), or at most the rounding tolerance.  Returns
    ``(counts, h_fine)`` with ``counts`` (K,) the number of fine steps in every step, or None.
    """
    if h_unique.size < 2:
        return None
    tmax, span = float(np.max(np.abs(t))), float(t[-1] - t[0])
    tol = 8.0 * np.finfo(float).eps * max(tmax, float(h_unique.max()))
    h0 = float(h_unique.min())
    m = np.rint(h_unique / h0)
    if np.any(m < 1) or np.any(np.abs(h_unique - m * h0) > tol * (m + 1.0)):
        return None
    counts = m.astype(np.intp)[index]
    total = int(counts.sum())
    if total > _REFINE_AT_MOST * index.size:
        return None
    h_fine = span / total
    # the refined grid must place every sample as close to its given time as the grouped
    # steps do (both are off by the rounding accumulated in the given times only)
    # time reached after j steps: refined pos_j = (sum of counts) h_fine (one rounding), grouped
    # pos_j + sum of (h_u - m_u h_fine) over the steps (tiny residuals: their cumsum rounds at
    # ~1e-16 of their own size)
    off_given = np.cumsum(counts) * h_fine
    off_given -= t[1:]
    off_given += t[0]  # pos - given
    refined = float(np.max(np.abs(off_given)))
    off_given += np.cumsum((h_unique - m * h_fine)[index])  # grouped - given
    if refined > max(float(np.max(np.abs(off_given))), tol):
        return None
    return counts, h_fine


def _refine(
    inputs: NDArray[np.float64], counts: NDArray[np.intp], h_fine: float
) -> NDArray[np.float64]:
    """FOH inputs (value at the step start, slope) of every fine step of the refined grid.

    Step j (value ``a_j``, slope ``s_j``) becomes ``counts[j]`` fine steps with values
    ``a_j + s_j i h_fine`` and the same slope: the same piecewise-linear input.
    """
    total = int(counts.sum())
    first = np.cumsum(counts) - counts  # fine index of every step's start
    owner = np.zeros(total, dtype=np.intp)  # the step each fine step belongs to
    owner[first[1:]] = 1
    np.cumsum(owner, out=owner)
    out = np.take(inputs, owner, axis=0)
    i = np.arange(total, dtype=float)
    i -= np.take(first, owner)  # fine steps into the step
    i *= h_fine
    i *= out[:, 1]
    out[:, 0] += i
    return out


#: equal steps in a row from this many on take the shared-map scan (the state carried exactly)
_RUN_AT_LEAST = 256


def _piecewise_scan(
    Phi: NDArray[np.float64],
    G1: NDArray[np.float64],
    G2: NDArray[np.float64],
    index: NDArray[np.intp],
    inputs: NDArray[np.float64],
    out_map: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Outputs ``out_map x`` (package acceleration, stroke) on a grid of several step lengths.

    Every run of at least :data:`_RUN_AT_LEAST` equal steps is one time-invariant stretch:
    :func:`~microg._scan.lti_scan` with the state carried in from the previous stretch (its
    outputs include the state, so the next stretch starts from the exact end state).  The steps
    between such runs take :func:`~microg._scan.affine_scan` (one map per distinct step) from
    the state reached.  When the runs cover less than half the steps, the whole grid is one
    :func:`~microg._scan.affine_scan`.
    """
    K, n = index.size, Phi.shape[-1]
    bounds = np.r_[0, np.flatnonzero(np.diff(index)) + 1, K]
    lengths = np.diff(bounds)
    long = np.flatnonzero(lengths >= _RUN_AT_LEAST)
    if 2 * int(lengths[long].sum()) < K:
        offsets = G1[index] * inputs[:, :1] + G2[index] * inputs[:, 1:]
        X = affine_scan(Phi, offsets, index=index)
        return X @ out_map[0], X[:, 0]
    full_map = np.vstack([out_map, np.eye(n)])  # the outputs, then the state
    Y = np.empty((K + 1, out_map.shape[0]))
    x = np.zeros(n)
    Y[0] = out_map @ x
    pos = 0
    for r in long:
        for i0, i1, lti in (
            (pos, int(bounds[r]), False),
            (int(bounds[r]), int(bounds[r + 1]), True),
        ):
            if i1 == i0:
                continue
            if lti:
                u = int(index[i0])
                Z = lti_scan(Phi[u], np.stack([G1[u], G2[u]]), inputs[i0:i1], full_map, x0=x)
                Y[i0 + 1 : i1 + 1] = Z[1:, : out_map.shape[0]]
                x = Z[-1, out_map.shape[0] :]
            else:
                idx = index[i0:i1]
                offsets = G1[idx] * inputs[i0:i1, :1] + G2[idx] * inputs[i0:i1, 1:]
                X = affine_scan(Phi, offsets, index=idx, x0=x)
                Y[i0 + 1 : i1 + 1] = X[1:] @ out_map.T
                x = X[-1]
        pos = int(bounds[r + 1])
    if pos < K:
        idx = index[pos:]
        offsets = G1[idx] * inputs[pos:, :1] + G2[idx] * inputs[pos:, 1:]
        X = affine_scan(Phi, offsets, index=idx, x0=x)
        Y[pos + 1 :] = X[1:] @ out_map.T
    return Y[:, 0], Y[:, 1]


#: the diagonal path is refused above this condition number of the (balanced) eigenvectors
_COND_MAX = 1e5
#: take the diagonal path where it applies (tests switch it off to reach the matrix scans)
_DIAGONAL = True


def _phi12(z: NDArray[np.complex128]) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """``phi1(z) = (e^z - 1) / z`` and ``phi2(z) = (e^z - 1 - z) / z^2``, to rounding.

    For ``|z| < 1/2`` their series ``sum z^n / (n+1)!`` and ``sum z^n / (n+2)!`` (24 terms:
    the rest below ``0.5^24 / 25! ~ 4e-33``); elsewhere the closed forms, whose cancellation
    costs at most a few roundings there.
    """
    small = np.abs(z) < 0.5
    zs = np.where(small, z, 0.0)
    p1 = np.zeros_like(z)
    p2 = np.zeros_like(z)
    c1 = np.ones_like(z)  # z^n / (n+1)!
    c2 = np.full_like(z, 0.5)  # z^n / (n+2)!
    for n in range(24):
        p1 += c1
        p2 += c2
        c1 = c1 * zs / (n + 2)
        c2 = c2 * zs / (n + 3)
    zl = np.where(small, 1.0, z)
    em1 = np.expm1(zl)
    return np.where(small, p1, em1 / zl), np.where(small, p2, (em1 - zl) / (zl * zl))


@dataclass(frozen=True)
class _Diagonal:
    """The state space in eigen-coordinates ``x = T V z`` (one of each conjugate pair kept)."""

    lam: NDArray[np.complex128]  # eigenvalues, 1/s
    bt: NDArray[np.complex128]  # (V^-1 T^-1 B), per coordinate
    out: NDArray[np.complex128]  # (q, m): output i is Re(out[i] @ z), pairs counted twice


def _diagonalize(
    A: NDArray[np.float64], B: NDArray[np.float64], out_map: NDArray[np.float64]
) -> _Diagonal | None:
    """Eigen-coordinates of ``x' = A x + B a0`` (balanced first), or None if ill-conditioned.

    A defective or nearly defective ``A`` (critical damping, coalescing modes) has a large
    eigenvector condition number; above :data:`_COND_MAX` the rounding it amplifies would
    exceed the matrix scans', so those take the scans.
    """
    Ab, T = linalg.matrix_balance(A, permute=False)
    lam, V = np.linalg.eig(Ab)
    if not np.all(np.isfinite(lam)):
        return None
    cond = float(np.linalg.cond(V))
    if not cond <= _COND_MAX:
        return None
    t = np.diag(T)
    bt = np.linalg.solve(V, B[:, 0] / t)
    out = (out_map * t[None, :]) @ V
    upper, real = lam.imag > 0, lam.imag == 0
    if int(upper.sum()) != int((lam.imag < 0).sum()):
        return None
    keep = upper | real
    return _Diagonal(lam[keep], bt[keep], out[:, keep] * np.where(upper[keep], 2.0, 1.0))


def _diagonal_outputs(
    d: _Diagonal,
    h_unique: NDArray[np.float64],
    index: NDArray[np.intp] | None,
    value: NDArray[np.float64],
    slope: NDArray[np.float64],
) -> NDArray[np.float64] | None:
    """Outputs ``(rows, q, K + 1)`` of the FOH recurrence in eigen-coordinates, or None.

    Each coordinate obeys ``z_{k+1} = e^{lam h} z_k + h phi1(lam h) bt a0_k + h^2 phi2(lam h)
    bt s_k`` (the exact step for a0 linear over the step, ``s_k`` its slope), run by
    :func:`~microg._scan.scalar_scan` (None where it declines: a coordinate that decays by more
    than ~e^12 per step).  ``value``, ``slope``: (rows, K).
    """
    z = d.lam[:, None] * h_unique[None, :]  # (m, U)
    p1, p2 = _phi12(z)
    a = np.exp(z)
    g1 = h_unique * p1 * d.bt[:, None]
    g2 = h_unique**2 * p2 * d.bt[:, None]
    rows, K = value.shape
    Y = np.zeros((rows, d.out.shape[0], K + 1))
    b = np.empty(K, complex)
    bv = b.view(np.float64).reshape(K, 2)
    tmp = np.empty(K)
    for i in range(d.lam.size):
        for r in range(rows):
            # the offsets g1 a0 + g2 s, real and imaginary parts as contiguous products
            for part in (0, 1):
                if index is None:
                    c1, c2 = (
                        (g1[i, 0].real, g2[i, 0].real)
                        if part == 0
                        else (g1[i, 0].imag, g2[i, 0].imag)
                    )
                    np.multiply(value[r], c1, out=bv[:, part])
                    np.multiply(slope[r], c2, out=tmp)
                else:
                    c1v = (g1[i].real if part == 0 else g1[i].imag)[index]
                    c2v = (g2[i].real if part == 0 else g2[i].imag)[index]
                    np.multiply(value[r], c1v, out=bv[:, part])
                    np.multiply(slope[r], c2v, out=tmp)
                bv[:, part] += tmp
            out = scalar_scan(
                a[i : i + 1], b[None], index=index, weights=d.out[:, i : i + 1], overwrite_b=True
            )
            if out is None:
                return None
            Y[r] += out
    return Y


@dataclass
class IsolationTimeResponse:
    """Mount and package acceleration histories and their peak/RMS reduction.

    Attributes
    ----------
    timepts : times, s (the input times, subdivided when ``oversample > 1``).
    mount_accel : mount (support) acceleration ``a0``, m/s^2.
    package_accel : package absolute acceleration ``u1''``, m/s^2.
    stroke : package displacement relative to the mount ``u1 - u0``, m.
    peak_mount, peak_package : largest absolute sample, m/s^2.
    rms_mount, rms_package : time-weighted RMS (trapezoidal rule on the squared samples), m/s^2.
    peak_ratio, rms_ratio : package over mount (below 1 means isolation).
    peak_stroke : largest ``|u1 - u0|``, m (rattle space the mount needs).
    model : the isolator used.
    """

    timepts: NDArray[np.float64]
    mount_accel: NDArray[np.float64]
    package_accel: NDArray[np.float64]
    stroke: NDArray[np.float64]
    peak_mount: float
    peak_package: float
    rms_mount: float
    rms_package: float
    peak_ratio: float
    rms_ratio: float
    peak_stroke: float
    model: IsolatorModel

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary: peaks, RMS, their ratios, the stroke and the isolator (SI)."""
        from microg.environment.metrics import json_number

        m = self.model
        t = np.asarray(self.timepts, float)
        return {
            "n_samples": int(t.size),
            "t_start_s": float(t[0]) if t.size else None,
            "t_end_s": float(t[-1]) if t.size else None,
            "peak_mount_mps2": self.peak_mount,
            "peak_package_mps2": self.peak_package,
            "rms_mount_mps2": self.rms_mount,
            "rms_package_mps2": self.rms_package,
            "peak_ratio": json_number(self.peak_ratio),
            "rms_ratio": json_number(self.rms_ratio),
            "peak_stroke_m": self.peak_stroke,
            "isolator": {
                "m1_kg": m.m1,
                "k1_N_per_m": m.k1,
                "c1_N_s_per_m": m.c1,
                "m2_kg": m.m2,
                "k2_N_per_m": m.k2,
                "c_N_s_per_m": m.c,
                "freq_hz_n": m.omega_n / (2.0 * math.pi),
            },
        }

    def to_xarray(self) -> Any:
        """Mount and package accelerations and the stroke as an ``xarray.Dataset`` over time."""
        import xarray as xr

        return xr.Dataset(
            {
                "mount_accel_mps2": ("time", self.mount_accel, {"units": "m/s^2"}),
                "package_accel_mps2": ("time", self.package_accel, {"units": "m/s^2"}),
                "stroke_m": ("time", self.stroke, {"units": "m"}),
            },
            coords={"time": ("time", np.asarray(self.timepts, float), {"units": "s"})},
            attrs={"peak_ratio": self.peak_ratio, "rms_ratio": self.rms_ratio},
        )

    def plot(self, ax: Any = None) -> Any:
        """Mount and package accelerations against time, micro-g (a Figure).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.isolation import plot_package_response

        return plot_package_response(self, ax=ax)


def _rms(t: NDArray[np.float64], y: NDArray[np.float64]) -> float:
    return float(math.sqrt(np.trapezoid(y * y, t) / (t[-1] - t[0])))


def _ratio(a: float, b: float) -> float:
    return a / b if b > 0 else math.nan


def _validated(
    timepts: ArrayLike, mount_accel: ArrayLike, oversample: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Times (N,) and rows of mount acceleration (rows, N), subdivided by ``oversample``."""
    t = np.asarray(timepts, dtype=float)
    a0 = np.asarray(mount_accel, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise InputError("need a 1-D array of at least 2 times", where="timepts")
    if a0.shape[-1:] != t.shape or a0.ndim > 2:
        raise InputError(f"shape {a0.shape} differs from timepts {t.shape}", where="mount_accel")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a0))):
        raise InputError("contains NaN or inf", where="timepts/mount_accel")
    h = np.diff(t)
    if not np.all(h > 0):
        raise InputError("times must be strictly increasing", where="timepts")
    if not (isinstance(oversample, int | np.integer) and oversample >= 1):
        raise InputError(f"must be an integer >= 1, got {oversample!r}", where="oversample")
    a0 = np.atleast_2d(a0)
    if oversample > 1:
        frac = np.arange(oversample) / oversample
        t = np.concatenate(((t[:-1, None] + h[:, None] * frac).ravel(), t[-1:]))
        lin = (a0[:, :-1, None] + np.diff(a0, axis=1)[:, :, None] * frac).reshape(a0.shape[0], -1)
        a0 = np.concatenate((lin, a0[:, -1:]), axis=1)
    return t, a0


#: above this many steps, a grid made of long uniform runs takes the shared-map scans (measured
#: faster there on 10^6 steps: BLAS on a few state columns against complex running products)
_SCANS_ABOVE = 100_000


def _runs_favour_scans(index: NDArray[np.intp]) -> bool:
    """True for a long grid whose runs of ``_RUN_AT_LEAST`` equal steps cover half its steps."""
    K = index.size
    if K <= _SCANS_ABOVE:
        return False
    bounds = np.r_[0, np.flatnonzero(np.diff(index)) + 1, K]
    lengths = np.diff(bounds)
    return 2 * int(lengths[lengths >= _RUN_AT_LEAST].sum()) >= K


def _outputs(
    model: IsolatorModel, t: NDArray[np.float64], a0: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Package acceleration and stroke ``(rows, 2, N)`` for mount accelerations ``(rows, N)``.

    The diagonal path (:func:`_diagonal_outputs`, every grid) when ``A`` diagonalises well;
    otherwise the matrix scans of the module docstring.
    """
    h = np.diff(t)
    A, B, C = state_space(model)
    h_unique, index = _group_steps(h, float(np.max(np.abs(t))), float(t[-1] - t[0]))
    slope = np.diff(a0, axis=1) / h
    value = a0[:, :-1]
    out_map = np.vstack([C, np.eye(A.shape[0])[:1]])  # package acceleration, stroke
    d = _diagonalize(A, B, out_map) if _DIAGONAL and not _runs_favour_scans(index) else None
    if d is not None:
        Y = _diagonal_outputs(d, h_unique, None if h_unique.size == 1 else index, value, slope)
        if Y is not None:
            return Y
    Phi, G1, G2 = foh_discretize(A, B, h_unique)
    fine = _commensurate(t, h_unique, index)
    out = np.empty((a0.shape[0], 2, t.size))
    for r in range(a0.shape[0]):
        inputs = np.stack([value[r], slope[r]], axis=1)  # value at the step start, slope
        if h_unique.size == 1:  # uniform steps: one map, only the two outputs are computed
            out[r] = lti_scan(Phi[0], np.stack([G1[0], G2[0]]), inputs, out_map).T
        elif fine is not None:  # every step a whole number of one fine step: uniform fine grid
            counts, h_fine = fine
            Phi_f, G1_f, G2_f = foh_discretize(A, B, [h_fine])
            Y = lti_scan(
                Phi_f[0], np.stack([G1_f[0], G2_f[0]]), _refine(inputs, counts, h_fine), out_map
            )
            out[r] = Y[np.r_[0, np.cumsum(counts)]].T  # fine index of every input sample
        else:
            out[r] = np.stack(_piecewise_scan(Phi, G1, G2, index, inputs, out_map))
    return out


def _result(
    model: IsolatorModel, t: NDArray[np.float64], a0: NDArray[np.float64], Y: NDArray[np.float64]
) -> IsolationTimeResponse:
    y, stroke = Y[0], Y[1]
    peak_mount = float(np.max(np.abs(a0)))
    peak_package = float(np.max(np.abs(y)))
    rms_mount = _rms(t, a0)
    rms_package = _rms(t, y)
    return IsolationTimeResponse(
        timepts=t,
        mount_accel=a0,
        package_accel=y,
        stroke=stroke,
        peak_mount=peak_mount,
        peak_package=peak_package,
        rms_mount=rms_mount,
        rms_package=rms_package,
        peak_ratio=_ratio(peak_package, peak_mount),
        rms_ratio=_ratio(rms_package, rms_mount),
        peak_stroke=float(np.max(np.abs(stroke))),
        model=model,
    )


def package_response(
    model: IsolatorModel, timepts: ArrayLike, mount_accel: ArrayLike, *, oversample: int = 1
) -> IsolationTimeResponse:
    """Package acceleration for a mount acceleration linear between samples (exact, FOH).

    Parameters
    ----------
    model : IsolatorModel
        Package, mount and optional absorber (kg, N/m, N s/m).
    timepts : array_like, shape (N,)
        Strictly increasing sample times, s; steps may be non-uniform.
    mount_accel : array_like, shape (N,)
        Mount acceleration ``a0`` at ``timepts``, m/s^2, taken linear between samples.
    oversample : int
        Subdivide every step into this many equal steps (the input stays the same piecewise-
        linear function) so that peaks between the input samples are resolved.

    Returns
    -------
    IsolationTimeResponse
        Start from rest relative to the mount (``u1 - u0 = 0`` and its rate 0 at ``timepts[0]``).
    """
    if np.ndim(mount_accel) != 1:
        raise InputError(
            f"shape {np.shape(mount_accel)} is not 1-D",
            where="mount_accel",
            fix="give one history, or use package_responses for several",
        )
    t, a0 = _validated(timepts, mount_accel, oversample)
    return _result(model, t, a0[0], _outputs(model, t, a0)[0])


def package_responses(
    model: IsolatorModel, timepts: ArrayLike, mount_accel: ArrayLike, *, oversample: int = 1
) -> list[IsolationTimeResponse]:
    """:func:`package_response` of several mount histories on one time grid (e.g. 3 axes).

    The same results as one call per row; the grid's steps and the model's discretisation are
    found once and every row runs in the same vectorised pass.

    Parameters
    ----------
    model : IsolatorModel
        Package, mount and optional absorber (kg, N/m, N s/m).
    timepts : array_like, shape (N,)
        Strictly increasing sample times, s.
    mount_accel : array_like, shape (rows, N)
        Mount accelerations, m/s^2, each taken linear between samples.
    oversample : int
        As for :func:`package_response`.
    """
    if np.ndim(mount_accel) != 2:
        raise InputError(
            f"shape {np.shape(mount_accel)} is not (rows, N)",
            where="mount_accel",
            fix="give a 2-D array, one row per history",
        )
    t, a0 = _validated(timepts, mount_accel, oversample)
    Y = _outputs(model, t, a0)
    return [_result(model, t, a0[r], Y[r]) for r in range(a0.shape[0])]
