"""Converged quadrature of band integrals of modal FRFs under force spectra.

Band integration is converged, not sampled: composite Gauss-Legendre quadrature of order
``order`` on intervals whose breakpoints are the band edges, every natural frequency ``f_j``
inside the band and the geometric grading ``f_j +- 3^k gamma_j`` (``gamma_j = zeta_j f_j``, the
half-power half-width) out to twice the band width, the breakpoints of every spectrum, and the
band's midpoint (:func:`band_quadrature`).  Convergence is checked, per band, on
``int |r_j|^2 df`` of every mode within three band widths (the others are smooth there) and on
every spectrum's ``int S df``: the rule of order ``2 order`` on the same intervals, and the
exact power of the spectrum; a band that fails has its intervals halved (up to
:data:`MAX_REFINEMENTS` times) and a band that still fails is named in the warnings
(:func:`converged_quadrature`).

With a real weight per output row ``w_p(f)`` (an isolator's ``|T|^2``) the check is made on the
weighted integrands: ``int w_p |r_j|^2 df`` of every near mode and ``int w_p S df`` of every
spectrum, each by the rules of order ``order`` and ``2 order`` (a weighted power has no exact
value), beside the exact power of each unweighted spectrum; the weight's own breakpoints (the
loop's poles) join the intervals' breakpoints.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from microg.dynamics.frf import factor
from microg.dynamics.spectra import ForceSpectrum

__all__ = [
    "MAX_REFINEMENTS",
    "BandQuadrature",
    "band_quadrature",
    "default_order",
    "converged_quadrature",
    "per_band",
]

#: largest number of interval halvings of a band that fails the convergence check
MAX_REFINEMENTS = 6
#: grading ratio of the breakpoints around a natural frequency
_GRADING = 3.0


@dataclass(frozen=True)
class BandQuadrature:
    """Composite Gauss-Legendre nodes over a set of bands.

    Attributes
    ----------
    freq_hz : (N,) nodes, Hz, sorted by band then frequency
    weight_hz : (N,) weights, Hz (``sum weight * g(f)`` approximates ``int g df``)
    band : (N,) index of the band of each node
    start : (nb + 1,) ``freq_hz[start[b]:start[b+1]]`` are the nodes of band b
    intervals : (K, 3) rows (band, lo_hz, hi_hz) of the sub-intervals
    order : Gauss-Legendre points per interval
    """

    freq_hz: np.ndarray
    weight_hz: np.ndarray
    band: np.ndarray
    start: np.ndarray
    intervals: np.ndarray
    order: int


def default_order(rtol: float) -> int:
    """Gauss-Legendre points per sub-interval for a relative tolerance: 8, or 6 from 1e-4 up.

    The lower order only saves nodes when the tolerance is loose.  The run-time check (each
    near mode's band integral by this rule against twice the order, and each spectrum's exact
    power) is an estimate: it does not see the cross terms between modes, so it can pass a
    rule that misses the tolerance by a small factor (two modes 1.5e-4 apart, relative: 1.4e-9
    where 1e-9 was asked at 8 points).  Measured on the IOC frame model (200 modes, zeta 0.005,
    the ISS bands, 30 spectral sources; ``benchmarks/bench_frequency.py``): 6 points reach 1.7e-6
    of the band mean squares where 1e-3 is asked, 4 points only 3.7e-6 where 1e-6 is asked and
    the check passed, so 6 is the lowest order used, and only for loose tolerances.

    Parameters
    ----------
    rtol : relative tolerance of the band integration
    """
    return 6 if rtol >= 1e-4 else 8


def _gauss_nodes(intervals: np.ndarray, order: int, nb: int) -> BandQuadrature:
    x, w = np.polynomial.legendre.leggauss(order)
    band = intervals[:, 0].astype(int)
    mid = 0.5 * (intervals[:, 1] + intervals[:, 2])
    half = 0.5 * (intervals[:, 2] - intervals[:, 1])
    nodes = (mid[:, None] + half[:, None] * x[None, :]).ravel()
    weights = (half[:, None] * w[None, :]).ravel()
    nband = np.repeat(band, order)
    start = np.searchsorted(nband, np.arange(nb + 1), side="left")
    return BandQuadrature(nodes, weights, nband, start, intervals, order)


def _band_intervals(
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    mode_freq_hz: np.ndarray,
    mode_zeta: np.ndarray,
    breakpoints_hz: np.ndarray,
) -> np.ndarray:
    """Sub-intervals (band, lo, hi) of every band, graded around the natural frequencies."""
    nb = lower_hz.size
    width = upper_hz - lower_hz
    el = mode_freq_hz > 0
    f = mode_freq_hz[el]
    gam = mode_zeta[el] * f
    pts_band = [np.arange(nb), np.arange(nb), np.arange(nb)]
    pts = [lower_hz, upper_hz, 0.5 * (lower_hz + upper_hz)]
    if f.size:
        kmax = int(np.ceil(np.log(2.0 * width.max() / gam.min()) / np.log(_GRADING))) + 1
        steps = _GRADING ** np.arange(0, max(kmax, 1))
        offs = np.r_[0.0, steps, -steps]
        cand = (f[:, None] + gam[:, None] * offs[None, :]).ravel()
        reach = (gam[:, None] * np.abs(offs)[None, :]).ravel()
        inside = (
            (cand[None, :] > lower_hz[:, None])
            & (cand[None, :] < upper_hz[:, None])
            & (reach[None, :] <= 2.0 * width[:, None])
        )
        bi, ci = np.nonzero(inside)
        pts_band.append(bi)
        pts.append(cand[ci])
    bp = np.asarray(breakpoints_hz, float)
    if bp.size:
        inside = (bp[None, :] > lower_hz[:, None]) & (bp[None, :] < upper_hz[:, None])
        bi, ci = np.nonzero(inside)
        pts_band.append(bi)
        pts.append(bp[ci])
    band = np.concatenate(pts_band)
    x = np.concatenate(pts)
    order = np.lexsort((x, band))
    band, x = band[order], x[order]
    same = band[1:] == band[:-1]
    length = np.diff(x)
    keep = same & (length > 1e-12 * width[band[:-1]])
    return np.column_stack([band[:-1][keep], x[:-1][keep], x[1:][keep]])


def band_quadrature(
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    mode_freq_hz: np.ndarray,
    mode_zeta: np.ndarray,
    breakpoints_hz: np.ndarray | Sequence[float] = (),
    *,
    order: int = 8,
) -> BandQuadrature:
    """Quadrature nodes for band integrals of modal FRFs (see the module docstring).

    Parameters
    ----------
    lower_hz, upper_hz : (nb,) band edges, Hz (bands may touch, overlap or leave gaps)
    mode_freq_hz : (m,) natural frequencies, Hz (0 for rigid modes: no breakpoints)
    mode_zeta : (m,) modal damping ratios (> 0 for elastic modes)
    breakpoints_hz : extra breakpoints (spectrum discontinuities and kinks), Hz
    order : Gauss-Legendre points per sub-interval
    """
    lo = np.asarray(lower_hz, float)
    hi = np.asarray(upper_hz, float)
    iv = _band_intervals(
        lo,
        hi,
        np.asarray(mode_freq_hz, float),
        np.asarray(mode_zeta, float),
        np.asarray(breakpoints_hz, float),
    )
    return _gauss_nodes(iv, order, lo.size)


def _split(intervals: np.ndarray, bands: np.ndarray) -> np.ndarray:
    """Halve every interval of the given bands."""
    sel = np.isin(intervals[:, 0].astype(int), bands)
    if not np.any(sel):
        return intervals
    iv = intervals[sel]
    mid = 0.5 * (iv[:, 1] + iv[:, 2])
    left = np.column_stack([iv[:, 0], iv[:, 1], mid])
    right = np.column_stack([iv[:, 0], mid, iv[:, 2]])
    new = np.concatenate([intervals[~sel], left, right])
    return new[np.lexsort((new[:, 1], new[:, 0]))]


def per_band(values: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Sum the last axis of ``values`` over each band's node range, (..., nb).

    Parameters
    ----------
    values : (..., N) a quantity at the nodes (e.g. PSD times weight, N^2)
    start : (nb + 1,) :attr:`BandQuadrature.start`
    """
    nb = start.size - 1
    out = np.zeros(values.shape[:-1] + (nb,))
    nonempty = start[1:] > start[:-1]
    if np.any(nonempty):
        sums = np.add.reduceat(values, start[:-1][nonempty], axis=-1)
        out[..., nonempty] = sums
    return out


def converged_quadrature(
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    omega_modes: np.ndarray,
    zeta: np.ndarray,
    scale: np.ndarray,
    spectra: Sequence[ForceSpectrum],
    order: int,
    rtol: float,
    *,
    weight: Callable[[np.ndarray], np.ndarray] | None = None,
    breakpoints_hz: Sequence[float] | np.ndarray = (),
) -> tuple[BandQuadrature, np.ndarray, int, list[str]]:
    """Nodes that pass the convergence check; per-band relative error; refinements; warnings.

    Parameters
    ----------
    lower_hz, upper_hz : (nb,) band edges, Hz
    omega_modes : (m,) natural frequencies, rad/s (0: rigid)
    zeta : (m,) modal damping ratios
    scale : (m,) largest ``|c_j|`` of each mode over outputs and sources (0: the mode is not
        checked)
    spectra : the spectral sources (their breakpoints and exact powers), N and Hz
    order : Gauss-Legendre points per sub-interval
    rtol : relative tolerance of the check
    weight : a real weight per output row, frequencies (n,) Hz -> (p, n) values >= 0; the check
        is then made on the weighted integrands (module docstring); None: no weight
    breakpoints_hz : extra breakpoints (where the weight changes quickly), Hz

    Returns
    -------
    quadrature : BandQuadrature
    error : (nb,) relative convergence estimate of each band
    refinements : interval halvings done
    warnings : the bands that did not converge
    """
    bps = [s.breakpoints_hz for s in spectra] + [np.asarray(breakpoints_hz, float).ravel()]
    bp = np.unique(np.concatenate(bps))
    fm = omega_modes / (2.0 * np.pi)
    iv = _band_intervals(lower_hz, upper_hz, fm, zeta, bp)
    nb = lower_hz.size
    active = scale > 0
    wm, zm, sc2 = omega_modes[active], zeta[active], scale[active] ** 2
    exact = np.array([s.power_n2(lower_hz, upper_hz) for s in spectra]).reshape(-1, nb)
    err = np.zeros(nb)
    refinements = 0
    width = upper_hz - lower_hz
    fa = wm / (2.0 * np.pi)
    # modes whose resonance can shape a band; farther modes are smooth over it
    near = (
        (wm[:, None] > 0)
        & (fa[:, None] > lower_hz - 3 * width)
        & (fa[:, None] < upper_hz + 3 * width)
    )
    todo = np.arange(nb)  # bands to (re)check: all, then only those refined
    for attempt in range(MAX_REFINEMENTS + 1):
        sub = iv[np.isin(iv[:, 0].astype(int), todo)]
        q1 = _gauss_nodes(sub, order, nb)
        e = np.zeros(nb)
        q2 = _gauss_nodes(sub, 2 * order, nb) if weight is not None or np.any(near) else q1
        wq = (
            [np.ones((1, q1.freq_hz.size)), np.ones((1, q2.freq_hz.size))]
            if weight is None
            else [weight(q1.freq_hz), weight(q2.freq_hz)]
        )
        if np.any(near[:, todo]):
            diags = []
            for q, wr in zip((q1, q2), wq, strict=True):
                jj, nn = np.nonzero(near[:, q.band])
                re, im = factor(wm[jj], zm[jj], 2.0 * np.pi * q.freq_hz[nn])
                val = (re * re + im * im) * q.weight_hz[nn] * sc2[jj]
                flat = [
                    np.bincount(jj * nb + q.band[nn], weights=val * row[nn], minlength=wm.size * nb)
                    for row in wr
                ]
                diags.append(np.array(flat).reshape(len(wr), wm.size, nb))
            d1, d2 = diags
            big = near[None] & (d2 >= 1e-13 * np.max(d2, axis=1, keepdims=True))
            with np.errstate(divide="ignore", invalid="ignore"):
                rel = np.where(big & (d2 > 0), np.abs(d1 - d2) / d2, 0.0)
            e = rel.max(axis=(0, 1))
        if spectra:
            sp = np.array([s.psd_at(q1.freq_hz) for s in spectra]) * q1.weight_hz[None, :]
            got = per_band(sp, q1.start)
            top = np.max(exact, axis=1, keepdims=True)
            denom = np.maximum(exact, 1e-13 * top)
            with np.errstate(divide="ignore", invalid="ignore"):
                srel = np.where(denom > 0, np.abs(got - exact) / denom, 0.0)
            e = np.maximum(e, srel.max(axis=0))
            if weight is not None:  # the weighted powers by the two rules
                pw = []
                for q, wr in zip((q1, q2), wq, strict=True):
                    psd = np.array([s.psd_at(q.freq_hz) for s in spectra]) * q.weight_hz[None, :]
                    pw.append(per_band(psd[None, :, :] * wr[:, None, :], q.start))  # (p, s, nb)
                w1, w2 = pw
                wtop = np.max(w2, axis=(0, 1), keepdims=True)
                big = w2 >= 1e-13 * wtop
                with np.errstate(divide="ignore", invalid="ignore"):
                    wrel = np.where(big & (w2 > 0), np.abs(w1 - w2) / w2, 0.0)
                e = np.maximum(e, wrel.max(axis=(0, 1)))
        err[todo] = e[todo]
        bad = todo[err[todo] > rtol]
        if bad.size == 0 or attempt == MAX_REFINEMENTS:
            break
        iv = _split(iv, bad)
        refinements += 1
        todo = bad
    warnings = []
    bad = np.flatnonzero(err > rtol)
    if bad.size:
        warnings.append(
            f"band integration converged only to {err[bad].max():.1e} (asked {rtol:.0e}) in "
            f"{bad.size} band(s) near {lower_hz[bad[0]]:.4g} Hz"
        )
    return _gauss_nodes(iv, order, nb), err, refinements, warnings
