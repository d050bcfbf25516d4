"""Acceleration transmissibility of a spring-mounted package with a damped vibration absorber.

The model is the report's Figure 7 (Section 4.1, Eq. 4.1): the package ``m1`` hangs on the
spring ``k1`` from the moving support ``u0``; the absorber ``m2`` is joined to ``m1`` by the
spring ``k2`` and the damper ``c`` (the damper acts on ``u1 - u2``; the support drives the package
only through ``k1``).  With the dimensionless parameters of Eq. 4.6

    k = k1/k2,  mu = m2/m1,  zeta = c/(2 sqrt(m2 k2)),  r = omega/omega_n,  omega_n^2 = k1/m1,

the solution of Eq. 4.3 is (derivation in ``docs/isolation.md``; the printed Eq. 4.7 is garbled)

    U1/U0 = (1 - mu k r^2 + 2i zeta r sqrt(mu k))
            / (1 - [1 + (1 + k) mu] r^2 + mu k r^4 + 2i zeta r sqrt(mu k) [1 - (1 + mu) r^2])

and the acceleration magnification factor of Eq. 4.5 is ``M_a = |A1|/(omega^2 |U0|) = |U1/U0|``.

Every function here is a pure kernel: floats or numpy arrays in, arrays out, any broadcast shape.
Parameters are not validated (validate at the boundary, see :mod:`microg.isolation.design`).
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "transmissibility",
    "accel_magnification",
    "accel_magnification_grid",
    "accel_magnification_no_absorber",
    "transmissibility_no_absorber",
    "absorber_tuning_ratio",
    "spring_ratio_from_tuning",
]


def absorber_tuning_ratio(k: ArrayLike, mu: ArrayLike) -> NDArray[np.float64]:
    """Absorber-to-package natural frequency ratio ``f = omega_a/omega_n = 1/sqrt(k mu)``.

    Parameters
    ----------
    k : array_like
        Spring ratio ``k1/k2`` (Eq. 4.6), dimensionless.
    mu : array_like
        Mass ratio ``m2/m1`` (Eq. 4.6), dimensionless.
    """
    return 1.0 / np.sqrt(np.asarray(k, dtype=float) * np.asarray(mu, dtype=float))


def spring_ratio_from_tuning(f: ArrayLike, mu: ArrayLike) -> NDArray[np.float64]:
    """Spring ratio ``k = k1/k2 = 1/(f^2 mu)`` giving the tuning ratio ``f`` (inverse of above).

    Parameters
    ----------
    f : array_like
        Tuning ratio ``omega_a/omega_n``, dimensionless.
    mu : array_like
        Mass ratio ``m2/m1``, dimensionless.
    """
    f = np.asarray(f, dtype=float)
    return 1.0 / (f * f * np.asarray(mu, dtype=float))


def transmissibility(
    k: ArrayLike, mu: ArrayLike, zeta: ArrayLike, r: ArrayLike
) -> NDArray[np.complex128]:
    """Complex transmissibility ``U1/U0`` of the package with absorber (Eq. 4.3, solved).

    Equals the ratio of the package's absolute acceleration to the support acceleration.

    Parameters
    ----------
    k : array_like
        Spring ratio ``k1/k2`` (Eq. 4.6), > 0.
    mu : array_like
        Mass ratio ``m2/m1`` (Eq. 4.6), > 0.
    zeta : array_like
        Absorber damping ratio ``c/(2 sqrt(m2 k2))`` (Eq. 4.6), >= 0.
    r : array_like
        Frequency ratio ``omega/omega_n``, ``omega_n = sqrt(k1/m1)``, >= 0.

    Returns
    -------
    ndarray of complex
        ``U1/U0`` with the broadcast shape of the inputs.
    """
    k, mu, zeta, r = (np.asarray(a, dtype=float) for a in (k, mu, zeta, r))
    s2 = mu * k  # = 1/f^2
    q = r * r
    a = 1.0 - s2 * q
    g = 2.0 * zeta * r * np.sqrt(s2)
    num = a + 1j * g
    den = (1.0 - q) * a - mu * q + 1j * g * (1.0 - (1.0 + mu) * q)
    return num / den


def accel_magnification(
    k: ArrayLike, mu: ArrayLike, zeta: ArrayLike, r: ArrayLike
) -> NDArray[np.float64]:
    """Acceleration magnification factor ``M_a = |U1/U0|`` (Eq. 4.5 with Eq. 4.3 solved).

    Real arithmetic, ``M_a^2 = (a^2 + t)/(D_r^2 + t b^2)`` with ``q = r^2``, ``a = 1 - mu k q``,
    ``b = 1 - (1 + mu) q``, ``D_r = (1 - q) a - mu q``, ``t = 4 zeta^2 mu k q``.

    Parameters
    ----------
    k : array_like
        Spring ratio ``k1/k2`` (Eq. 4.6), > 0.
    mu : array_like
        Mass ratio ``m2/m1`` (Eq. 4.6), > 0.
    zeta : array_like
        Absorber damping ratio ``c/(2 sqrt(m2 k2))`` (Eq. 4.6), >= 0.
    r : array_like
        Frequency ratio ``omega/omega_n`` (Eq. 4.6), >= 0.

    Returns
    -------
    ndarray of float
        ``M_a`` with the broadcast shape of the inputs (``inf`` exactly at an undamped pole).
    """
    k, mu, zeta, r = (np.asarray(x, dtype=float) for x in (k, mu, zeta, r))
    s2 = mu * k
    q = r * r
    a = 1.0 - s2 * q
    b = 1.0 - (1.0 + mu) * q
    dr = (1.0 - q) * a
    dr -= mu * q
    t = (4.0 * zeta * zeta) * s2 * q
    num = np.add(a * a, t)
    b *= b
    den = np.multiply(b, t)
    den += dr * dr
    with np.errstate(divide="ignore", invalid="ignore"):
        num = num / den
    return np.sqrt(num)


def accel_magnification_no_absorber(r: ArrayLike) -> NDArray[np.float64]:
    """``M_a = 1/|1 - r^2|`` of the package on its spring alone (the ``mu -> 0`` limit).

    Parameters
    ----------
    r : array_like
        Frequency ratio ``omega/omega_n``, >= 0.
    """
    return np.abs(transmissibility_no_absorber(r))


def transmissibility_no_absorber(r: ArrayLike) -> NDArray[np.float64]:
    """``U1/U0 = 1/(1 - r^2)`` of the package on its spring alone (real: no damping).

    Parameters
    ----------
    r : array_like
        Frequency ratio ``omega/omega_n``, >= 0.
    """
    r = np.asarray(r, dtype=float)
    with np.errstate(divide="ignore"):
        return 1.0 / (1.0 - r * r)


def _grid_block(
    s2: NDArray[np.float64],
    mu1: NDArray[np.float64],
    mu: NDArray[np.float64],
    t0: NDArray[np.float64],
    q: NDArray[np.float64],
    one_minus_q: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    """Fill ``out[p, j]`` = M_a for parameter rows ``p`` (column vectors) and ``q`` (a row)."""
    shape = out.shape
    a = np.empty(shape)
    w = np.empty(shape)
    np.multiply(s2, q, out=a)
    np.subtract(1.0, a, out=a)  # a = 1 - mu k q
    np.multiply(one_minus_q, a, out=out)
    np.multiply(mu, q, out=w)
    np.subtract(out, w, out=out)  # D_r
    np.multiply(out, out, out=out)  # D_r^2
    np.multiply(a, a, out=a)  # a^2
    np.multiply(mu1, q, out=w)
    np.subtract(1.0, w, out=w)  # b
    np.multiply(w, w, out=w)  # b^2
    tq = np.multiply(t0, q)  # t = 4 zeta^2 mu k q
    np.multiply(w, tq, out=w)
    np.add(out, w, out=out)  # den
    np.add(a, tq, out=a)  # num
    np.divide(a, out, out=out)
    np.sqrt(out, out=out)


def accel_magnification_grid(
    k: ArrayLike,
    mu: ArrayLike,
    zeta: ArrayLike,
    r: ArrayLike,
    *,
    block: int = 32768,
    workers: int | None = None,
) -> NDArray[np.float64]:
    """``M_a`` on the outer-product grid ``k x mu x zeta x r`` (fast, cache-blocked, threaded).

    Same formula as :func:`accel_magnification`; per-parameter scalars are computed once and
    the work is split in cache-sized blocks over a thread pool (numpy releases the GIL).

    Parameters
    ----------
    k, mu, zeta, r : array_like
        1-D sequences of the spring ratio ``k1/k2``, mass ratio ``m2/m1``, absorber damping
        ratio and frequency ratio ``omega/omega_n`` (Eq. 4.6).
    block : int
        Target number of grid points per block (about 256 kB per float64 temporary).
    workers : int, optional
        Threads; default ``os.cpu_count()``.

    Returns
    -------
    ndarray of float, shape (len(k), len(mu), len(zeta), len(r))
    """
    k, mu, zeta, r = (np.atleast_1d(np.asarray(x, dtype=float)).ravel() for x in (k, mu, zeta, r))
    kk, mm, zz = np.meshgrid(k, mu, zeta, indexing="ij")
    s2 = (kk * mm).reshape(-1, 1)
    mu_col = mm.reshape(-1, 1)
    mu1 = 1.0 + mu_col
    t0 = (4.0 * zz * zz).reshape(-1, 1) * s2
    q = (r * r)[None, :]
    one_minus_q = 1.0 - q
    n_rows, n_r = s2.shape[0], q.shape[1]
    out = np.empty((n_rows, n_r))
    col_block = min(n_r, block)
    row_block = max(1, block // col_block)
    tasks = [
        (slice(i, min(i + row_block, n_rows)), slice(j, min(j + col_block, n_r)))
        for i in range(0, n_rows, row_block)
        for j in range(0, n_r, col_block)
    ]

    def run(task: tuple[slice, slice]) -> None:
        rs, cs = task
        with np.errstate(divide="ignore", invalid="ignore"):  # errstate is per thread
            _grid_block(
                s2[rs], mu1[rs], mu_col[rs], t0[rs], q[:, cs], one_minus_q[:, cs], out[rs, cs]
            )

    n_workers = workers or os.cpu_count() or 1
    if n_workers == 1 or len(tasks) == 1:
        for task in tasks:
            run(task)
    else:
        with ThreadPoolExecutor(max_workers=n_workers) as pool:
            list(pool.map(run, tasks))
    return out.reshape(k.size, mu.size, zeta.size, r.size)
