"""Band RMS of a spectrum: the band integration, its resolution rule, and its fast path.

Band RMS (see docs/assessment.md): ``sqrt(sum of psd_k * df over the bins in the band)``, the
band sum of NASA PIMS: a frequency bin belongs wholly to the band its frequency ``f_k`` lies
in (``lower <= f_k < upper``; a bin on an edge belongs to the band above it, a band reaching
Nyquist also holds the Nyquist bin).  A tone on a bin therefore keeps its whole power in
one band wherever the band edges fall, and the band mean squares of contiguous bands add up
exactly to the mean square of the record in their range (Parseval).  Bands wholly above
Nyquist are left out, and the power of the 0-Hz bin (the mean) is excluded from every band.

Resolved band: at least ``MIN_BINS`` (5) frequency bins in the band, a record at least
``MIN_TIME_BANDWIDTH`` (5) times 1/bandwidth long, wholly below Nyquist (and below the data's
anti-alias cutoff when one is given).  Only resolved bands are judged; the others are listed
with the reason.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg._json import json_by_name, json_numbers
from microg.environment._samples import as_axes, axis_names, sample_rate
from microg.environment.requirements import BandTable
from microg.environment.spectrum import Spectrum, periodogram
from microg.errors import InputError
from microg.units import G0

__all__ = [
    "MIN_BINS",
    "MIN_TIME_BANDWIDTH",
    "BandRMS",
    "band_mean_square",
    "band_rms",
    "band_weights",
]

#: fewest frequency bins in a band for its RMS to be judged (see docs/assessment.md)
MIN_BINS = 5.0
#: fewest record lengths per 1/bandwidth for a band to be judged
MIN_TIME_BANDWIDTH = 5.0


@dataclass(frozen=True)
class BandRMS:
    """Band RMS of each axis.

    Attributes
    ----------
    bands : the bands evaluated (those whose lower edge is below Nyquist)
    rms : (naxes, nb) band RMS, m/s^2
    coverage : (nb,) fraction of the band below the Nyquist frequency
    n_bins : (nb,) frequency bins in the band (below Nyquist), bandwidth / df
    resolved : (nb,) True where the band may be judged (see the module doc)
    reasons : (nb,) why a band is not resolved ("" where it is)
    """

    bands: BandTable
    rms: np.ndarray
    coverage: np.ndarray
    resolved: np.ndarray
    n_bins: np.ndarray = field(default_factory=lambda: np.zeros(0))
    reasons: tuple[str, ...] = ()

    @property
    def rms_g(self) -> np.ndarray:
        """Band RMS in g, (naxes, nb)."""
        return self.rms / G0

    def to_dict(self, axes: tuple[str, ...] | None = None) -> dict[str, Any]:
        """JSON-ready band RMS: the bands (Hz), band RMS per axis (g), resolution per band."""
        ax = axis_names(self.rms.shape[0], axes)
        return {
            **self.bands.to_dict(),
            "rms_g_axis": json_by_name(ax, self.rms_g),
            "coverage": json_numbers(self.coverage),
            "n_bins": json_numbers(self.n_bins),
            "resolved": [bool(v) for v in self.resolved],
            "reasons": list(self.reasons),
        }

    def to_xarray(self, axes: tuple[str, ...] | None = None) -> Any:
        """Band RMS as an ``xarray.Dataset``: dims ``axis``, ``center_hz``; units in attrs."""
        ax = axis_names(self.rms.shape[0], axes)
        ds = self.bands.to_xarray()
        nb = self.bands.center_hz.size
        ds["rms_g"] = (("axis", "center_hz"), self.rms_g, {"units": "g", "long_name": "band RMS"})
        ds["coverage"] = ("center_hz", self.coverage, {"units": "1"})
        n_bins = self.n_bins if self.n_bins.size == nb else np.full(nb, np.nan)
        ds["n_bins"] = ("center_hz", n_bins, {"units": "1"})
        ds["resolved"] = ("center_hz", np.asarray(self.resolved, np.int8), {"units": "1"})
        return ds.assign_coords(axis=list(ax))


def band_weights(freq_hz: np.ndarray, df_hz: float, nyquist_hz: float, bands: BandTable) -> Any:
    """The band integration as a linear map: ``power_b = sum_k W[b, k] psd_k``, Hz.

    Bin ``k`` carries ``psd_k df`` and belongs wholly to the band its frequency lies in:
    ``W[b, k] = df`` when ``lo_b <= f_k < hi_b`` (a band reaching Nyquist also holds the
    Nyquist bin; a bin on an edge, to ``EDGE_RTOL``, belongs to the band above), else 0.  The
    0-Hz bin's power (the mean) is left out.  This is PIMS's band sum: a tone on a bin keeps
    its whole power in one band wherever the band edges fall.  Sparse: each band holds a run
    of bins.
    The last few maps are kept (a run judges many series on one grid and band table) and
    shared, so they are read-only.

    Parameters
    ----------
    freq_hz : ndarray (nf,)
        Bin frequencies, Hz, uniformly spaced from 0.
    df_hz : float
        Bin spacing, Hz.
    nyquist_hz : float
        Half the sampling rate, Hz.
    bands : BandTable
        The bands, Hz.

    Returns
    -------
    scipy.sparse.csr_matrix (nb, nf)
        Hz.
    """
    f = np.asarray(freq_hz, float)
    lo = np.asarray(bands.lower_hz, float)
    hi = np.asarray(bands.upper_hz, float)
    key = (f.tobytes(), float(df_hz), float(nyquist_hz), lo.tobytes(), hi.tobytes())
    w = _BAND_WEIGHTS.get(key)
    if w is None:
        w = _band_weights(f, float(df_hz), float(nyquist_hz), lo, hi)
        for a in (w.data, w.indices, w.indptr):
            a.flags.writeable = False  # shared between callers: never changed in place
        with _BAND_WEIGHTS_LOCK:
            if len(_BAND_WEIGHTS) >= _BAND_WEIGHTS_MAX:
                _BAND_WEIGHTS.pop(next(iter(_BAND_WEIGHTS)))
            _BAND_WEIGHTS[key] = w
    return w


#: band_weights' last maps, by their inputs (a run judges many series on one grid and table)
_BAND_WEIGHTS: dict[tuple[bytes, float, float, bytes, bytes], Any] = {}
_BAND_WEIGHTS_MAX = 8
_BAND_WEIGHTS_LOCK = threading.Lock()


def _band_weights(
    f: np.ndarray, df_hz: float, nyquist_hz: float, lower_hz: np.ndarray, upper_hz: np.ndarray
) -> Any:
    """:func:`band_weights` computed (no cache)."""
    import scipy.sparse as sp

    nb = lower_hz.size
    lo, hi = _member_edges(lower_hz, upper_hz, nyquist_hz)
    # bins j0 <= j < j1 lie in [lo, hi): their frequencies are sorted
    j0 = np.searchsorted(f, lo, side="left")
    j1 = np.maximum(np.searchsorted(f, hi, side="left"), j0)
    if f.size and f[0] == 0.0:
        j0 = np.maximum(j0, 1)  # the mean is no vibration
        j1 = np.maximum(j1, j0)
    count = j1 - j0
    rows = np.repeat(np.arange(nb), count)
    cols = np.repeat(j0 - np.cumsum(np.r_[0, count[:-1]]), count) + np.arange(int(count.sum()))
    w = np.full(cols.size, float(df_hz))
    return sp.csr_matrix((w, (rows, cols)), shape=(nb, f.size))


#: relative tolerance of the band-membership test: a bin whose frequency is a band edge to
#: rounding belongs to the band that the edge starts
EDGE_RTOL = 1e-9


def _member_edges(
    lower_hz: np.ndarray, upper_hz: np.ndarray, nyquist_hz: float
) -> tuple[np.ndarray, np.ndarray]:
    """The half-open interval ``[lo, hi)`` of bin frequencies each band holds, Hz.

    Edges are moved down by ``EDGE_RTOL`` so that a bin on an edge (to rounding) belongs to
    the band above it; a band reaching Nyquist or past it also holds the Nyquist bin.
    """
    lo = np.asarray(lower_hz, float) * (1.0 - EDGE_RTOL)
    hi = np.asarray(upper_hz, float) * (1.0 - EDGE_RTOL)
    hi = np.where(np.asarray(upper_hz, float) >= nyquist_hz * (1.0 - EDGE_RTOL), np.inf, hi)
    lo = np.where(np.asarray(lower_hz, float) >= nyquist_hz, np.inf, lo)  # wholly above
    return lo, hi


#: direct DFT of the bins a band table needs, instead of the whole FFT, up to this many bins
_DFT_MAX_BINS = 64
#: ... and up to this many (samples x bins) entries in its cosine and sine tables
_DFT_MAX_ENTRIES = 1 << 22


def band_mean_square(timepts: np.ndarray, accel: np.ndarray, bands: BandTable) -> np.ndarray:
    """Mean square of each demeaned row in each band, from the boxcar periodogram, (u)^2.

    The same number as ``band_rms(acceleration_psd(timepts, accel), bands).rms ** 2`` (the
    periodogram of :func:`~microg.environment.spectrum.periodogram` integrated by
    :func:`band_weights`), computed from only the DFT bins the bands overlap when they are
    few: ``X_k = sum_n x_n e^{-2 pi i k n / N}`` as two matrix products with exact integer
    phases ``(k n) mod N``.  Many series in a few narrow bands (a run's modal accelerations
    in a point's worst band) then cost a fraction of a full FFT, above all for record
    lengths with large prime factors (20,001 = 3 x 59 x 113).  Otherwise the whole
    periodogram is taken.

    Parameters
    ----------
    timepts : ndarray (n,)
        Uniformly spaced times, s.
    accel : ndarray (rows, n) or (n,)
        Series, any unit u (m/s^2 for accelerations).
    bands : BandTable
        Bands, Hz; all of them are returned (a band above Nyquist has zero power).

    Returns
    -------
    ndarray (rows, nb)
        u^2.
    """
    a = as_axes(accel)
    fs = sample_rate(timepts)
    n = a.shape[1]
    if n != np.asarray(timepts).size:
        raise InputError("timepts and accel have different lengths", where="accel")
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    w = band_weights(freq, fs / n, fs / 2, bands).tocsc()
    w.eliminate_zeros()
    cols = np.flatnonzero(np.diff(w.indptr))  # bins with a nonzero weight (never bin 0)
    x = a - a.mean(axis=1, keepdims=True)
    if cols.size > _DFT_MAX_BINS or n * cols.size > _DFT_MAX_ENTRIES:
        _, psd = periodogram(x, fs)
        return np.asarray(w @ psd.T).T
    # the N roots of unity once, gathered at the exact integer phases (k n) mod N
    arg = (2.0 * np.pi / n) * np.arange(n)
    idx = (np.arange(n)[:, None] * cols[None, :]) % n
    re = x @ np.cos(arg)[idx]
    im = x @ np.sin(arg)[idx]
    scale = np.where((cols == 0) | (2 * cols == n), 1.0, 2.0) / (fs * n)
    psd = (re * re + im * im) * scale
    return np.asarray(w[:, cols] @ psd.T).T


def band_rms(
    spectrum: Spectrum,
    bands: BandTable,
    *,
    min_bins: float = MIN_BINS,
    min_time_bandwidth: float = MIN_TIME_BANDWIDTH,
    cutoff_hz: float | None = None,
) -> BandRMS:
    """RMS of each axis in each band: sqrt of the PSD integrated over the band (see module doc).

    The 0-Hz bin's power (the mean) is excluded from every band.

    Parameters
    ----------
    spectrum : a :class:`Spectrum`
    bands : bands, Hz; those whose lower edge is at or above Nyquist are dropped
    min_bins : fewest frequency bins for a resolved band
    min_time_bandwidth : fewest multiples of 1/bandwidth in the record for a resolved band
    cutoff_hz : the data's anti-alias cutoff, Hz: bands reaching above it are unresolved
    """
    f, psd, df = spectrum.freq_hz, spectrum.psd, spectrum.df_hz
    nyq = spectrum.nyquist_hz
    keep = bands.lower_hz < nyq
    kept = BandTable(bands.center_hz[keep], bands.lower_hz[keep], bands.upper_hz[keep])
    lo = np.minimum(kept.lower_hz, nyq)
    hi = np.minimum(kept.upper_hz, nyq)
    power = np.asarray(band_weights(f, df, nyq, kept) @ np.atleast_2d(psd).T).T
    width = kept.upper_hz - kept.lower_hz
    coverage = (hi - lo) / width
    n_bins = (hi - lo) / df
    record = spectrum.duration_s
    welch = spectrum.method == "welch"
    reasons = []
    for w, nb, cov, top in zip(width, n_bins, coverage, kept.upper_hz, strict=True):
        if cutoff_hz is not None and top > cutoff_hz:
            reasons.append(f"above the data's cutoff frequency {cutoff_hz:.4g} Hz")
        elif cov < 1.0:
            reasons.append(f"reaches past the Nyquist frequency {nyq:.4g} Hz")
        elif nb < min_bins:
            what = "Welch segments" if welch else "a record"
            reasons.append(
                f"{nb:.2g} frequency bins (df = {df:.3g} Hz; {min_bins:g} needed: "
                f"{what} of >= {min_bins / w:.4g} s)"
            )
        elif record * w < min_time_bandwidth:
            reasons.append(
                f"record of {record:.4g} s is shorter than {min_time_bandwidth:g}/bandwidth "
                f"= {min_time_bandwidth / w:.4g} s"
            )
        else:
            reasons.append("")
    resolved = np.array([r == "" for r in reasons], bool)
    return BandRMS(
        kept, np.sqrt(np.maximum(power, 0.0)), coverage, resolved, n_bins, tuple(reasons)
    )
