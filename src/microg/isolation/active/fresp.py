"""Frequency response of a python-control state space at many frequencies, vectorised with numpy.

``G(s) = C (s I - A)^-1 B + D`` at ``s = i omega`` (continuous) or ``s = exp(i omega dt)``
(sampled).  :meth:`control.StateSpace.frequency_response` evaluates one frequency at a time
(slycot's ``tb05ad``, Laub's Hessenberg method, called from Python per point); the isolator's
checks ask for tens of thousands of points (the record's periodogram, the noise bands'
quadrature nodes, the margins' grid).  Here ``A`` is brought once to complex Schur form
``A = U T U^H`` (:func:`scipy.linalg.schur`, unitary, backward stable), and
``(s I - T) X = U^H B`` is solved by back substitution for every frequency at once:

    X_k = ((U^H B)_k + sum_{j > k} T_kj X_j) / (s - T_kk),   G = C U X + D.

The unitary reduction keeps the accuracy of the per-point method (the test suite compares it
with python-control's own response).  Frequencies are taken in blocks of :data:`BLOCK` to bound
memory.

Responses are kept (:data:`CACHE_BYTES` in all, least recently used dropped first), keyed by
the system's matrices, its sampling time and the frequencies, all by value: ``microg analyze``
checks one controller at every observed point, on the same record's frequencies, and each
check then costs one lookup.  A kept response is returned read-only.
"""

from __future__ import annotations

import hashlib
import math
from typing import Any

import numpy as np

from microg._kept import Kept

__all__ = ["BLOCK", "CACHE_BYTES", "clear_kept", "freq_response", "system_key"]

#: frequencies evaluated together (memory: states x inputs x BLOCK complex numbers)
BLOCK = 4096
#: bytes of responses kept in all, each counted with :data:`_ENTRY_BYTES` more for its key
#: and objects (one larger than a quarter of it is not kept)
CACHE_BYTES = 64 * 2**20
_ENTRY_BYTES = 512

_KEPT: Kept[bytes, np.ndarray] = Kept(
    CACHE_BYTES // _ENTRY_BYTES, CACHE_BYTES, lambda v: v.nbytes + _ENTRY_BYTES
)


def system_key(system: Any) -> bytes:
    """A digest of a state space's matrices (shapes and values) and sampling time."""
    h = hashlib.blake2b(digest_size=20)
    for m in (system.A, system.B, system.C, system.D):
        a = np.ascontiguousarray(m, float)
        h.update(repr(a.shape).encode())
        h.update(a.tobytes())
    h.update(repr(float(system.dt) if system.dt is not None else None).encode())
    return h.digest()


def clear_kept() -> None:
    """Forget every kept response."""
    _KEPT.clear()


def freq_response(system: Any, freq_hz: np.ndarray) -> np.ndarray:
    """Complex frequency response ``(nout, nin, nf)`` of ``system`` at ``freq_hz`` (Hz).

    Parameters
    ----------
    system : ``control.StateSpace`` (continuous, or sampled with its ``dt``)
    freq_hz : (nf,) frequencies, Hz, any order

    Returns a read-only array (it may be shared with earlier and later calls).
    """
    f = np.ascontiguousarray(freq_hz, float).reshape(-1)
    key = system_key(system) + hashlib.blake2b(f.tobytes(), digest_size=20).digest()
    hit = _KEPT.get(key)
    if hit is not None:
        return hit
    out = _response(system, f)
    out.setflags(write=False)
    return out if out.size == 0 else _KEPT.put(key, out)  # an empty one costs nothing


def _response(system: Any, f: np.ndarray) -> np.ndarray:
    """The response of the module docstring at ``f`` (Hz), a new writable array."""
    from scipy.linalg import schur

    a = np.asarray(system.A, float)
    b = np.asarray(system.B, float)
    c = np.asarray(system.C, float)
    d = np.asarray(system.D, float)
    nout, nin, n = d.shape[0], d.shape[1], a.shape[0]
    w = 2 * math.pi * f
    s = np.exp(1j * w * float(system.dt)) if system.isdtime(strict=True) else 1j * w
    out = np.empty((nout, nin, f.size), complex)
    out[...] = d[:, :, None]
    if n == 0 or f.size == 0:
        return out
    t, u = schur(a, output="complex")
    bt = u.conj().T @ b  # (n, nin)
    cu = c @ u  # (nout, n)
    diag = np.diag(t)
    for lo in range(0, f.size, BLOCK):
        sb = s[lo : lo + BLOCK]
        x = np.empty((n, nin, sb.size), complex)
        for k in range(n - 1, -1, -1):
            acc = np.broadcast_to(bt[k][:, None], (nin, sb.size)).astype(complex)
            if k < n - 1:
                acc = acc + np.tensordot(t[k, k + 1 :], x[k + 1 :], axes=(0, 0))
            x[k] = acc / (sb - diag[k])[None, :]
        out[:, :, lo : lo + BLOCK] += np.tensordot(cu, x, axes=(1, 0))
    return out
