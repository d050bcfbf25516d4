"""Modal acceleration FRFs: pure kernels of natural frequencies, damping and modal rows.

Acceleration per newton of force, summed over the modes (the modal frequency response of MSC
Nastran SOL 111 with modal damping ``zeta_j``; Craig & Kurdila, *Fundamentals of Structural
Dynamics*, 2nd ed., Sec. 10.4)::

    H_a(w) = sum_j c_j r_j(w),   r_j(w) = -w^2 / (w_j^2 - w^2 + 2 i zeta_j w_j w),

with ``c_j`` the product of the output row and the input's generalized force on mode ``j``.  A
rigid mode (``w_j = 0``) gives ``r_j = 1`` at every ``w > 0``: the constant mass line.  The
kernels trust their inputs (the Modes-level entries of :mod:`microg.dynamics.frequency` check
them).
"""

from __future__ import annotations

import numpy as np

__all__ = ["acceleration_frf", "factor", "factor_parts", "modal_frf_factor"]


def factor(wj: np.ndarray, z: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real and imaginary parts of r = -w^2 / (wj^2 - w^2 + 2 i z wj w), broadcasting.

    Parameters
    ----------
    wj : natural frequencies, rad/s (0: rigid)
    z : damping ratios
    w : excitation frequencies, rad/s (>= 0; at 0 the limit, 1 for rigid modes, 0 otherwise)
    """
    w2 = w * w
    d_re = wj * wj - w2
    d_im = 2.0 * z * wj * w
    den = d_re * d_re + d_im * d_im
    with np.errstate(divide="ignore", invalid="ignore"):
        re = -w2 * d_re / den
        im = w2 * d_im / den
    zero = den == 0  # only at w = 0 (and w_j = 0): the limit is 1 for rigid, 0 for elastic
    if np.any(zero):
        rigid_limit = np.broadcast_to(wj == 0, re.shape)
        re = np.where(zero, np.where(rigid_limit, 1.0, 0.0), re)
        im = np.where(zero, 0.0, im)
    return re, im


def factor_parts(
    omega_modes: np.ndarray, zeta: np.ndarray, omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Real and imaginary parts of r_j(w) = -w^2 / (w_j^2 - w^2 + 2 i zeta_j w_j w), (m, nf).

    Parameters
    ----------
    omega_modes : (m,) natural frequencies, rad/s
    zeta : (m,) damping ratios
    omega : (nf,) excitation frequencies, rad/s
    """
    return factor(omega_modes[:, None], zeta[:, None], omega[None, :])


def modal_frf_factor(
    omega_modes: np.ndarray, zeta: np.ndarray | float, omega: np.ndarray
) -> np.ndarray:
    """Modal acceleration factors ``r_j(w) = -w^2 / (w_j^2 - w^2 + 2 i zeta_j w_j w)``.

    Parameters
    ----------
    omega_modes : (m,) natural frequencies, rad/s (0 for rigid modes: r = 1, the mass line)
    zeta : (m,) or scalar modal damping ratios
    omega : (nf,) excitation frequencies, rad/s (>= 0; r(0) = 1 for rigid modes, 0 otherwise)

    Returns
    -------
    (m, nf) complex: modal acceleration per unit modal force.
    """
    wm = np.asarray(omega_modes, float)
    z = np.broadcast_to(np.asarray(zeta, float), wm.shape)
    re, im = factor_parts(wm, z, np.atleast_1d(np.asarray(omega, float)))
    return re + 1j * im


def acceleration_frf(
    omega_modes: np.ndarray,
    zeta: np.ndarray | float,
    out_modal: np.ndarray,
    in_modal: np.ndarray,
    omega: np.ndarray,
) -> np.ndarray:
    """Acceleration FRFs ``H[p, s, f] = sum_j out[p, j] in[s, j] r_j(w_f)`` (module docstring).

    Parameters
    ----------
    omega_modes : (m,) natural frequencies, rad/s
    zeta : (m,) or scalar modal damping ratios
    out_modal : (p, m) output rows: translation of each output coordinate per unit modal
        coordinate, m (``T_out @ phi``)
    in_modal : (s, m) generalized force of each input per newton on each mode (``phi^T T_in^T d``)
    omega : (nf,) excitation frequencies, rad/s

    Returns
    -------
    (p, s, nf) complex, (m/s^2)/N.
    """
    r = modal_frf_factor(omega_modes, zeta, omega)  # (m, nf)
    out = np.asarray(out_modal, float)
    inp = np.asarray(in_modal, float)
    c = (out[:, None, :] * inp[None, :, :]).reshape(-1, out.shape[1])
    return (c @ r).reshape(out.shape[0], inp.shape[0], -1)
