"""Passive mount search against a measured (or computed) acceleration spectrum.

The report's design rule (Section 4.2, :func:`microg.isolation.design.design_mount`) bounds
M_a over the band where a requirement is exceeded; it ignores the mount's own resonance,
which a broadband transient (a crew push-off) excites below that band, where the ISS limit is
strictest.  :func:`search_mount` screens spring-damper mounts on the whole spectrum: the
package's PSD is ``|T(f)|^2`` times the mount's (linear, time-invariant system), band RMS per
1/3-octave band against the limit, and returns the stiffest mount that complies.  The caller
verifies the choice with the exact time-domain response
(:func:`microg.isolation.timedomain.package_response`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.environment.metrics import Spectrum, json_number
from microg.environment.requirements import BandTable, Requirement
from microg.units import G0, IN, LBF

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["mount_transmissibility", "MountChoice", "screen_margins", "search_mount"]


def mount_transmissibility(
    k1: np.ndarray | float, c1: np.ndarray | float, m1: float, omega: np.ndarray
) -> np.ndarray:
    """Absolute transmissibility U1/U0 of a spring-damper mount (no absorber), complex.

    ``T = (k1 + i c1 w) / (k1 - m1 w^2 + i c1 w)``; with ``c1 = 0`` this is Eq. 4.3 with
    ``m2 = 0``.

    Parameters
    ----------
    k1 : float or ndarray
        Mount stiffness, N/m.
    c1 : float or ndarray
        Mount damping, N s/m.
    m1 : float
        Package mass, kg.
    omega : ndarray
        Circular frequency, rad/s.
    """
    num = k1 + 1j * c1 * omega
    return num / (k1 - m1 * omega**2 + 1j * c1 * omega)


@dataclass(frozen=True)
class MountChoice:
    """Result of :func:`search_mount`.

    Attributes
    ----------
    found : bool
        A screened mount complies in every band.
    k1 : float
        Stiffness of the chosen mount (the stiffest compliant one, else the best), N/m.
    zeta1 : float
        Its damping ratio ``c1 / (2 sqrt(k1 m1))``.
    c1 : float
        N s/m.
    min_margin : float
        Smallest limit / band RMS over axes and bands (>= 1 means compliance).
    freq_hz_n : float
        Mount natural frequency, Hz.
    screened : int
        Number of (k1, zeta1) pairs screened.
    """

    found: bool
    k1: float
    zeta1: float
    c1: float
    min_margin: float
    freq_hz_n: float
    screened: int

    @property
    def mass_kg(self) -> float:
        """Package mass ``k1 / (2 pi f_n)^2``, kg."""
        return self.k1 / (2 * np.pi * self.freq_hz_n) ** 2

    def transmissibility(self, freq_hz: np.ndarray) -> np.ndarray:
        """``|U1/U0|`` of this mount at support frequencies ``freq_hz`` (Hz)."""
        w = 2 * np.pi * np.asarray(freq_hz, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.abs(mount_transmissibility(self.k1, self.c1, self.mass_kg, w))

    def default_freq_hz(self) -> np.ndarray:
        """801 log-spaced frequencies from f_n / 20 to 50 f_n, Hz."""
        return np.geomspace(self.freq_hz_n / 20, 50 * self.freq_hz_n, 801)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready choice; keys carry units (the ``screened_mount`` of the advice)."""
        return {
            "found": bool(self.found),
            "k1_N_per_m": self.k1,
            "k1_lbf_per_in": self.k1 * IN / LBF,
            "zeta1": self.zeta1,
            "c1_N_s_per_m": self.c1,
            "natural_freq_hz": self.freq_hz_n,
            "screen_min_margin": json_number(self.min_margin),
            "screened": self.screened,
        }

    def to_xarray(self, freq_hz: np.ndarray | None = None) -> Any:
        """``|U1/U0|`` over support frequency as an ``xarray.Dataset`` (dim ``freq_hz``)."""
        import xarray as xr

        f = self.default_freq_hz() if freq_hz is None else np.asarray(freq_hz, float)
        return xr.Dataset(
            {"transmissibility": ("freq_hz", self.transmissibility(f), {"units": "1"})},
            coords={"freq_hz": ("freq_hz", f, {"units": "Hz"})},
            attrs=self.to_dict() | {"found": int(self.found), "mass_kg": self.mass_kg},
        )

    def plot(self, ax: Any = None) -> Figure:
        """``|U1/U0|`` against frequency (``plotting.isolation.plot_mount_choice``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.isolation import plot_mount_choice

        return plot_mount_choice(self, ax=ax)


#: a candidate's power in a band is a Taylor series of ``|T|^2`` about the band's centre of at
#: most this many terms (more are needed near its resonance: those bands are summed bin by bin)
_SERIES_MAX_TERMS = 32
#: the series' truncated tail is bounded below this fraction of the band's power (rounding)
_SERIES_TOL = 2.0**-56
#: the series lengths actually run (a pair's length is rounded up to one of these)
_SERIES_LENGTHS = (4, 6, 8, 12, 16, 24, 32)


def _t2(k: np.ndarray, c: np.ndarray, mass: float, w2: np.ndarray) -> np.ndarray:
    """``|T|^2 = (k^2 + c^2 w^2) / ((k - m w^2)^2 + c^2 w^2)``, broadcast (inf at a pole)."""
    cw2 = (c * c) * w2
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return (k * k + cw2) / ((k - mass * w2) ** 2 + cw2)


def _quadratic(
    alpha: np.ndarray | float, beta: np.ndarray | float, c2: np.ndarray, x0: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(beta - alpha x)^2 + c2 x`` at ``x0 + h``: coefficients of ``1, h, h^2``, and the poles.

    Returns ``d0``, ``d1`` and the distance from ``x0`` to the nearest root (``d2 = alpha^2``).
    The roots are ``p +- sqrt(c2 (c2 - 4 alpha beta)) / (2 alpha^2)`` with
    ``p = (2 alpha beta - c2) / (2 alpha^2)``: a complex pair of modulus ``beta / alpha`` below
    critical damping, two negative reals above it.
    """
    d0 = (beta - alpha * x0) ** 2 + c2 * x0
    d1 = 2.0 * alpha * (alpha * x0 - beta) + c2
    a2 = 2.0 * alpha * alpha
    disc = c2 * (c2 - 2.0 * a2 * beta / alpha)
    q = np.sqrt(np.abs(disc)) / a2
    dp = (2.0 * alpha * beta - c2) / a2 - x0
    dist = np.where(disc < 0, np.hypot(dp, q), np.minimum(np.abs(dp + q), np.abs(dp - q)))
    return d0, d1, dist


@functools.cache
def _reach_table() -> tuple[np.ndarray, np.ndarray]:
    """:func:`_series_reach` tabulated: ``log(d_num - 1)`` grid and the reach at each, once."""
    log_gap = np.linspace(np.log(1e-9), np.log(1e9), 241)
    J = np.asarray(_SERIES_LENGTHS, float)[None, :, None]
    frac = np.array([0.5, 0.7, 0.85])[None, None, :]
    dn = (1.0 + np.exp(log_gap))[:, None, None]
    lo = np.full((dn.shape[0], J.shape[1], frac.shape[2]), np.log(2.5))  # r > 1 at f = 0.5
    hi = np.full_like(lo, np.log(1e30))
    for _ in range(60):  # bisection in log d: the tail bound falls as d grows
        mid = 0.5 * (lo + hi)
        d = np.exp(mid)
        r = frac * d
        log_f = 2 * np.log((d + 1) / (d - r)) + 2 * np.log((r + dn) / (dn - 1))
        ok = log_f - J * np.log(r) - np.log1p(-1 / r) <= np.log(_SERIES_TOL)
        hi = np.where(ok, mid, hi)
        lo = np.where(ok, lo, mid)
    return log_gap, np.exp(hi).min(axis=2)


def _series_reach(d_num: np.ndarray) -> np.ndarray:
    """Least pole distance at which each series length bounds the tail below the tolerance.

    ``d_num`` (nb,): a bound below the distance of the numerator's roots from each band's
    centre (band half-widths).  With Cauchy's estimate on ``|h| = r < d`` the tail after J terms
    is at most ``F r^-J / (1 - 1/r)`` of the band's power, ``F = ((d + 1) / (d - r))^2
    ((r + d_num) / (d_num - 1))^2`` (see :func:`_band_power`).  Returns ``(nb, len(lengths))``:
    for each length of :data:`_SERIES_LENGTHS` the least ``d`` (over radii ``r`` = 0.5, 0.7,
    0.85 ``d``, by bisection in ``log d``) at the tabulated ``d_num`` just below the band's
    (the reach falls as ``d_num`` grows: a conservative lookup); ``inf`` where ``d_num <= 1``
    or is below the table.
    """
    log_gap, table = _reach_table()
    with np.errstate(divide="ignore", invalid="ignore"):
        gap = np.log(np.where(d_num > 1.0, d_num - 1.0, 0.0))
    row = np.searchsorted(log_gap, gap, side="right") - 1
    reach = table[np.clip(row, 0, log_gap.size - 1)]
    reach[(row < 0) | ~(d_num > 1.0)] = np.inf
    return reach


def _band_power(
    weights: Any, psd: np.ndarray, w2: np.ndarray, mass: float, k: np.ndarray, c: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Power of each axis in each band on each candidate mount, and the unbounded candidates.

    ``power[a, b, p] = sum_f W[b, f] psd[a, f] |T_p(w_f)|^2`` (``W`` of
    :func:`~microg.environment.metrics.band_weights`), shape ``(naxes, nb, ncand)``.

    ``|T|^2`` is rational in ``s = w^2``, ``(k^2 + c^2 s) / ((k - m s)^2 + c^2 s)``, and in
    ``y = 1 / s``, ``(k^2 y^2 + c^2 y) / ((k y - m)^2 + c^2 y)``.  For a band whose bins span
    ``x0 +- R`` in one of these variables ``x``, ``|T|^2 = N(h) / D(h)`` in ``h = (x - x0) / R``
    (``|h| <= 1`` on its bins), ``N`` and ``D`` quadratic, and its Taylor coefficients follow
    ``d0 t_j = n_j - d1 t_{j-1} - d2 t_{j-2}``; the band's power is ``sum_j t_j M_j`` with the
    band's moments ``M_j = sum_f W psd h_f^j`` (shared by every candidate).

    The truncation is bounded, not estimated.  On the circle ``|h| = r`` inside the poles
    (distance ``d``), ``|t_j| <= max_{|h|=r} |T|^2 r^-j`` (Cauchy), and that maximum is at most
    ``F = ((d + 1) / (d - r))^2 ((r + d_N) / (d_N - 1))^2`` times the least ``|T|^2`` on the
    band (``D`` at least ``(d - r)^2 / (d + 1)^2`` of its largest value on the band; the real
    roots of ``N`` lie at least ``d_N = x0 / R`` away).  As the weights are positive the power
    is at least ``M_0`` times that least value, so the tail after J terms is below
    ``F r^-J / (1 - 1/r)`` of the power.  Each (band, candidate) pair takes the variable with
    the shorter series (``s`` below the resonance, ``y`` above it) and the fewest terms that
    bound the tail below :data:`_SERIES_TOL` (:func:`_series_terms`); pairs needing more than
    :data:`_SERIES_MAX_TERMS` (the bands about the resonance) are summed bin by bin.

    An undamped candidate resonant exactly on a bin carrying power (any bin, in a band or not)
    is unbounded (``|T|^2`` not finite there); non-finite terms count 0 in the power.
    """
    W = weights.tocsr()
    nb, ncand, naxes = W.shape[0], k.size, psd.shape[0]
    indptr, cols = W.indptr, W.indices
    X = psd[:, cols] * W.data  # (naxes, nnz): the weighted PSD of every band's bins
    s = w2[cols]
    nbins = np.diff(indptr)
    out = np.empty((naxes, nb, ncand))
    full = np.flatnonzero(nbins > 0)
    direct = np.ones((nb, ncand), bool)
    if full.size:
        pos = s > 0  # bin 0 (s = 0) has no weight
        y = np.divide(1.0, s, out=np.zeros_like(s), where=pos)
        c2 = c * c
        geometry = []
        for x, lo_val, hi_val, alpha, beta in (
            (s, s, s, mass, k),
            (y, np.where(pos, y, np.inf), np.where(pos, y, 0.0), k, mass),
        ):
            # the band's centre and half-width in x (a band's bins are consecutive entries)
            x_lo = np.full(nb, np.nan)
            x_hi = np.full(nb, np.nan)
            x_lo[full] = np.minimum.reduceat(lo_val, indptr[full])
            x_hi[full] = np.maximum.reduceat(hi_val, indptr[full])
            good = np.isfinite(x_hi - x_lo) & (x_hi > x_lo)
            x0 = np.where(good, 0.5 * (x_lo + x_hi), 1.0)[:, None]
            half = np.where(good, 0.5 * (x_hi - x_lo), 1.0)[:, None]
            d0, d1, dist = _quadratic(alpha, beta, c2, x0)
            dist /= half
            # the series length: the first whose reach the poles' distance attains
            reach = _series_reach(np.where(good, x0[:, 0] / half[:, 0], 0.0))
            size = np.zeros(dist.shape, np.intp)
            for g in range(reach.shape[1]):
                size += dist < reach[:, g : g + 1]
            geometry.append((x, x0, half, d0, d1, size))
        use_y = geometry[1][5] < geometry[0][5]
        size = np.where(use_y, geometry[1][5], geometry[0][5])
        direct = size >= len(_SERIES_LENGTHS)
        (_, s0, rs, d0s, d1s, _), (_, y0, ry, d0y, d1y, _) = geometry
        # the series pairs: numerator n0 + n1 h + n2 h^2 and denominator d0 + d1 h + d2 h^2
        # of each pair's variable over d0 (zero for the direct pairs: their series is 0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            d0 = np.where(use_y, d0y, d0s)
            keep_s = ~direct & ~use_y
            keep_y = ~direct & use_y
            pick = [
                np.where(keep_s, v_s, np.where(keep_y, v_y, 0.0)) / d0
                for v_s, v_y in (
                    (k * k + c2 * s0, y0 * (k * k * y0 + c2)),  # n0
                    (c2 * rs, ry * (2.0 * k * k * y0 + c2)),  # n1
                    (0.0, (k * ry) ** 2),  # n2
                    (d1s * rs, d1y * ry),  # d1
                    ((mass * rs) ** 2, (k * ry) ** 2),  # d2
                )
            ]
        n0, n1, n2, d1, d2 = pick
        # bands grouped by their longest series: moments and coefficients of a group at once
        group = np.where(direct, -1, size).max(axis=1)
        for g, nj in enumerate(_SERIES_LENGTHS):
            bands = np.flatnonzero(group == g)
            if not bands.size:
                continue
            n = nbins[bands]
            starts = np.cumsum(n) - n
            ent = np.arange(int(n.sum())) - np.repeat(starts, n) + np.repeat(indptr[bands], n)
            owner = np.repeat(np.arange(bands.size), n)
            coef = np.empty((bands.size, nj, ncand))
            coef[:, 0] = n0[bands]
            coef[:, 1] = n1[bands] - d1[bands] * coef[:, 0]
            coef[:, 2] = n2[bands] - d1[bands] * coef[:, 1] - d2[bands] * coef[:, 0]
            md1, md2 = -d1[bands], -d2[bands]
            tmp = np.empty_like(md1)
            for j in range(3, nj):
                np.multiply(md1, coef[:, j - 1], out=coef[:, j])
                np.multiply(md2, coef[:, j - 2], out=tmp)
                coef[:, j] += tmp
            power = np.zeros((bands.size, naxes, ncand))
            for (x, x0, half, *_), sel in zip(geometry, (keep_s, keep_y), strict=True):
                if not sel[bands].any():
                    continue
                # moments M_j = sum W psd h^j of the group's bands in this variable
                h = np.where(pos[ent], (x[ent] - x0[bands[owner], 0]) / half[bands[owner], 0], 0)
                vt = np.empty((nj, ent.size))
                vt[0] = 1.0
                vt[1] = h
                for j in range(2, nj):
                    np.multiply(vt[j - 1], h, out=vt[j])
                mom = np.add.reduceat(X[:, None, ent] * vt[None], starts, axis=2)
                part = np.matmul(np.moveaxis(mom, 2, 0), coef)  # (bands, naxes, ncand)
                power += np.where(sel[bands][:, None, :], part, 0.0)
            out[:, bands] = np.swapaxes(power, 0, 1)
    # the pairs near a resonance: bin by bin
    pb, pp = np.nonzero(direct)
    if pb.size:
        n = nbins[pb]
        pair = np.repeat(np.arange(pb.size), n)
        ent = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n) + np.repeat(indptr[pb], n)
        cand = pp[pair]
        t2 = _t2(k[cand], c[cand], mass, s[ent])
        t2[~np.isfinite(t2)] = 0.0
        for a in range(naxes):
            out[a, pb, pp] = np.bincount(pair, weights=X[a, ent] * t2, minlength=pb.size)
    # unbounded: |T|^2 infinite at a bin with power; only an undamped mount has a real pole, so
    # look at the few bins about its resonance (m w^2 rises with the bin)
    unbounded = np.zeros(ncand, bool)
    undamped = np.flatnonzero(c == 0)
    pw2 = w2[np.any(psd > 0, axis=0)]
    if undamped.size and pw2.size:
        at = np.searchsorted(mass * pw2, k[undamped])
        near_bins = np.clip(at[:, None] + np.arange(-2, 3), 0, pw2.size - 1)
        t2 = _t2(k[undamped, None], c[undamped, None], mass, pw2[near_bins])
        unbounded[undamped] = ~np.all(np.isfinite(t2), axis=1)
    return out, unbounded


def screen_margins(
    spectrum: Spectrum,
    requirement: Requirement,
    mass: float,
    k_max: float,
    zetas: tuple[float, ...],
    decades: float,
    n_k: int,
) -> np.ndarray:
    """Smallest band margin of the package on each screened mount, ``(len(zetas), n_k)``.

    The package's PSD is ``|T(omega)|^2`` times the mount's, with
    ``|T|^2 = (k^2 + (c omega)^2) / ((k - m omega^2)^2 + (c omega)^2)`` (the modulus of
    :func:`mount_transmissibility`), and a band's power is linear in the PSD
    (:func:`~microg.environment.metrics.band_weights`, the integration of
    :func:`~microg.environment.metrics.band_rms`).  Every candidate's band powers are computed
    at once: directly near its resonance and in narrow bands, by the band's moments elsewhere
    (exact to rounding, :func:`_band_power`).  The margin is ``min limit / band RMS`` over the
    bands below Nyquist and the axes (``inf`` where no band has power); 0 for an undamped mount
    resonant exactly on a bin carrying power (an unbounded response).

    Parameters
    ----------
    spectrum : Spectrum
        One-sided PSD of the mount acceleration, per axis ((m/s^2)^2/Hz).
    requirement : Requirement
        Band limits (g).
    mass : float
        Package mass, kg.
    k_max : float
        Stiffest mount, N/m; the stiffnesses are ``k_max * logspace(-decades, 0, n_k)``.
    zetas : tuple of float
        Mount damping ratios.
    decades : float
        Width of the log-spaced stiffness range.
    n_k : int
        Number of stiffness values.
    """
    from microg.environment.metrics import band_weights

    omega = 2 * np.pi * spectrum.freq_hz
    keep = requirement.bands.lower_hz < spectrum.nyquist_hz
    limit = requirement.limit_g[keep]
    kept = BandTable(
        requirement.bands.center_hz[keep],
        requirement.bands.lower_hz[keep],
        requirement.bands.upper_hz[keep],
    )
    w = band_weights(spectrum.freq_hz, spectrum.df_hz, spectrum.nyquist_hz, kept)
    psd = np.atleast_2d(spectrum.psd)
    k_grid = k_max * np.logspace(-decades, 0.0, n_k)
    z = np.asarray(zetas, float)
    k = np.broadcast_to(k_grid, (z.size, n_k)).ravel()
    c = (2 * z[:, None] * np.sqrt(k_grid * mass)).ravel()
    power, unbounded = _band_power(w, psd, omega**2, mass, k, c)
    rms_g = np.sqrt(np.maximum(power, 0.0)) / G0
    with np.errstate(divide="ignore"):
        ratio = np.where(rms_g > 0, limit[None, :, None] / np.maximum(rms_g, 1e-300), np.inf)
    m = np.min(ratio, axis=(0, 1)) if ratio.size else np.full(k.size, np.inf)
    return np.where(unbounded, 0.0, m).reshape(z.size, n_k)


def search_mount(
    spectrum: Spectrum,
    requirement: Requirement,
    mass: float,
    k_max: float,
    *,
    zetas: tuple[float, ...] = (0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0),
    decades: float = 4.0,
    n_k: int = 81,
) -> MountChoice:
    """Stiffest spring-damper mount whose package spectrum meets ``requirement`` everywhere.

    Parameters
    ----------
    spectrum : Spectrum
        One-sided PSD of the mount acceleration, per axis ((m/s^2)^2/Hz).
    requirement : Requirement
        Band limits (g).
    mass : float
        Package mass, kg.
    k_max : float
        Stiffest mount to consider, N/m (e.g. the report's rule's answer); the search spans
        ``decades`` below it.
    zetas : tuple of float
        Mount damping ratios to screen.
    decades : float
        Width of the log-spaced stiffness range.
    n_k : int
        Number of stiffness values.
    """
    margins = screen_margins(spectrum, requirement, mass, k_max, zetas, decades, n_k)
    k_grid = k_max * np.logspace(-decades, 0.0, n_k)
    # the stiffest compliant candidate, else the largest margin; the first of equal candidates
    # (damping ratios in the order given) wins, as screened
    flat = margins.ravel()
    ok = flat >= 1.0
    key = (
        np.where(ok, np.broadcast_to(k_grid, margins.shape).ravel(), -np.inf) if ok.any() else flat
    )
    best = int(np.argmax(np.where(np.isnan(key), -np.inf, key)))
    iz, ik = divmod(best, n_k)
    found, k1, zeta1 = bool(ok.any()), float(k_grid[ik]), float(zetas[iz])
    c1 = 2 * zeta1 * np.sqrt(k1 * mass)
    margin = float(flat[best])
    return MountChoice(
        found=found,
        k1=k1,
        zeta1=zeta1,
        c1=float(c1),
        min_margin=margin,
        freq_hz_n=float(np.sqrt(k1 / mass) / (2 * np.pi)),
        screened=len(zetas) * n_k,
    )
