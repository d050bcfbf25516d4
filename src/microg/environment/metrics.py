"""Microgravity assessment of acceleration histories: peak, RMS, PSD, 1/3-octave bands, limits.

Definitions (see docs/assessment.md):

* PSD: one-sided power spectral density, (m/s^2)^2/Hz.  Default ``periodogram``: the whole record,
  boxcar window, no detrending (a transient must not be tapered away; Parseval holds exactly:
  ``sum(psd) * df`` is the mean square).  ``welch``: Hann window, segments of ``segment_s``
  (default the whole record), 50 % overlap, no detrending.
* Band RMS: ``sqrt(integral of the PSD over [lower, upper])``.  Each frequency bin's power
  ``psd_k * df`` is spread uniformly over its own interval ``[f_k - df/2, f_k + df/2]`` (clipped to
  ``[0, Nyquist]``); a bin straddling a band edge is shared in proportion.  So the band mean
  squares of contiguous bands add up exactly to the mean square of the record in their range
  (Parseval).  A band narrower than one bin is flagged ``resolved = False``; a band that reaches
  beyond the Nyquist frequency has ``coverage < 1``; bands wholly above Nyquist are left out.
* Integrated acceleration: ``max over t of |int_t^{t+W} a dt|`` for windows of ``W = 10 s`` sliding
  over the record (window starts at the samples, the end time interpolated in the running
  trapezoidal integral); per axis and for the vector.  A record shorter than W is one window.
* Margin: ``limit / band RMS`` (>= 1 passes, infinite for a zero band).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import signal

from microg.environment.requirements import BandTable, Requirement, iss_requirement
from microg.errors import InputError
from microg.units import G0

__all__ = [
    "Spectrum",
    "BandRMS",
    "ThirdOctave",
    "IntegratedAcceleration",
    "Assessment",
    "acceleration_psd",
    "band_rms",
    "integrated_acceleration",
    "assess",
]


@dataclass(frozen=True)
class Spectrum:
    """One-sided PSD of each axis.

    Attributes
    ----------
    freq_hz : (nf,) bin frequencies, Hz, uniformly spaced from 0
    psd : (naxes, nf) power spectral density, (m/s^2)^2/Hz
    df_hz : bin spacing, Hz
    nyquist_hz : half the sampling rate, Hz
    method : "periodogram" or "welch"
    """

    freq_hz: np.ndarray
    psd: np.ndarray
    df_hz: float
    nyquist_hz: float
    method: str


@dataclass(frozen=True)
class BandRMS:
    """Band RMS of each axis.

    Attributes
    ----------
    bands : the bands evaluated (those whose lower edge is below Nyquist)
    rms : (naxes, nb) band RMS, m/s^2
    coverage : (nb,) fraction of the band below the Nyquist frequency
    resolved : (nb,) True where the band is at least one frequency bin wide
    """

    bands: BandTable
    rms: np.ndarray
    coverage: np.ndarray
    resolved: np.ndarray


@dataclass(frozen=True)
class ThirdOctave:
    """1/3-octave band RMS against a requirement (g; margin = limit / rms)."""

    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray
    rms_g: np.ndarray  # (naxes, nb)
    limit_g: np.ndarray  # (nb,)
    margin: np.ndarray  # (naxes, nb)
    coverage: np.ndarray
    resolved: np.ndarray

    @property
    def worst_rms_g(self) -> np.ndarray:
        """Largest band RMS over the axes, (nb,), g."""
        return self.rms_g.max(axis=0)

    @property
    def passes(self) -> np.ndarray:
        """(nb,) True where every axis is within the limit."""
        return np.all(self.rms_g <= self.limit_g, axis=0)


@dataclass(frozen=True)
class IntegratedAcceleration:
    """Integral of the acceleration over sliding windows (velocity change), m/s.

    Attributes
    ----------
    window_s : window length, s (the record length if the record is shorter)
    t_start : (nw,) window start times, s
    delta_v : (naxes, nw) integral over each window, m/s
    max_mps : (naxes,) max |delta_v| per axis, m/s
    max_magnitude_mps : max over windows of the vector norm of delta_v, m/s
    """

    window_s: float
    t_start: np.ndarray
    delta_v: np.ndarray
    max_mps: np.ndarray
    max_magnitude_mps: float


@dataclass(frozen=True)
class WorstBand:
    """The band and axis with the smallest margin."""

    center_hz: float
    axis: str
    rms_g: float
    limit_g: float
    margin: float


@dataclass(frozen=True)
class Assessment:
    """Assessment of an acceleration history at one point.

    Attributes
    ----------
    axes : axis names
    requirement : requirement name
    peak_accel_g : peak of the acceleration vector magnitude, g
    rms_accel_g : RMS of the vector magnitude over the record, g
    peak_accel_g_axis, rms_accel_g_axis : (naxes,) per axis, g
    third_octave : band RMS, limits and margins
    complies : every band of every axis within its limit (and the peak within ``peak_limit_g``
        when the requirement has one)
    peak_limit_g : the requirement's peak limit, g, or None
    worst_band : the band and axis with the smallest margin
    integrated : integrated acceleration over sliding windows (maxima only kept here)
    spectrum : the PSD used for the bands
    """

    axes: tuple[str, ...]
    requirement: str
    peak_accel_g: float
    rms_accel_g: float
    peak_accel_g_axis: np.ndarray
    rms_accel_g_axis: np.ndarray
    third_octave: ThirdOctave
    complies: bool
    peak_limit_g: float | None
    worst_band: WorstBand | None
    integrated_window_s: float
    integrated_max_mps: np.ndarray
    integrated_max_magnitude_mps: float
    spectrum: Spectrum = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (the ``microg analyze --json`` observation layout)."""
        to = self.third_octave

        def clean(a: np.ndarray) -> list[float | None]:
            return [float(v) if np.isfinite(v) else None for v in np.ravel(a)]

        return {
            "peak_accel_g": self.peak_accel_g,
            "rms_accel_g": self.rms_accel_g,
            "peak_accel_g_axis": dict(zip(self.axes, clean(self.peak_accel_g_axis), strict=True)),
            "rms_accel_g_axis": dict(zip(self.axes, clean(self.rms_accel_g_axis), strict=True)),
            "third_octave": {
                "center_hz": clean(to.center_hz),
                "rms_g": clean(to.worst_rms_g),
                "limit_g": clean(to.limit_g),
                "margin": clean(to.margin.min(axis=0)),
                "rms_g_axis": {a: clean(r) for a, r in zip(self.axes, to.rms_g, strict=True)},
                "resolved": [bool(v) for v in to.resolved],
            },
            "requirement": self.requirement,
            "complies": bool(self.complies),
            "peak_limit_g": self.peak_limit_g,
            "worst_band": None
            if self.worst_band is None
            else {
                "center_hz": self.worst_band.center_hz,
                "axis": self.worst_band.axis,
                "rms_g": self.worst_band.rms_g,
                "limit_g": self.worst_band.limit_g,
                "margin": self.worst_band.margin if np.isfinite(self.worst_band.margin) else None,
            },
            "integrated_accel": {
                "window_s": self.integrated_window_s,
                "max_mps_axis": dict(zip(self.axes, clean(self.integrated_max_mps), strict=True)),
                "max_magnitude_mps": self.integrated_max_magnitude_mps,
            },
        }


# ------------------------------------------------------------------------------- spectra


def _as_axes(accel: np.ndarray) -> np.ndarray:
    a = np.asarray(accel, dtype=float)
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2:
        raise InputError("acceleration must have shape (naxes, nt) or (nt,)", where="assess")
    return a


def _sample_rate(timepts: np.ndarray) -> float:
    t = np.asarray(timepts, dtype=float)
    if t.ndim != 1 or t.size < 4:
        raise InputError("need at least 4 uniformly spaced samples", where="assess: timepts")
    dt = np.diff(t)
    mean = (t[-1] - t[0]) / (t.size - 1)
    if not mean > 0 or np.max(np.abs(dt - mean)) > 1e-6 * mean:
        raise InputError(
            "a spectrum needs uniformly spaced output times",
            where="assess: timepts",
            fix="evaluate the response on a uniform grid (np.linspace)",
        )
    return 1.0 / mean


def acceleration_psd(
    timepts: np.ndarray,
    accel: np.ndarray,
    *,
    method: str = "periodogram",
    segment_s: float | None = None,
) -> Spectrum:
    """One-sided PSD of uniformly sampled accelerations.

    Parameters
    ----------
    timepts : (nt,) uniformly spaced times, s
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    method : ``periodogram`` (whole record, boxcar, no detrend; exact Parseval) or ``welch``
        (Hann window, 50 % overlap, no detrend)
    segment_s : Welch segment length, s (default: the whole record)

    Returns
    -------
    Spectrum with ``psd`` in (m/s^2)^2/Hz.
    """
    a = _as_axes(accel)
    fs = _sample_rate(timepts)
    n = a.shape[1]
    if method == "periodogram":
        freq, psd = signal.periodogram(
            a, fs=fs, window="boxcar", detrend=False, scaling="density", axis=-1
        )
        nseg = n
    elif method == "welch":
        nseg = n if segment_s is None else int(round(segment_s * fs))
        if not 4 <= nseg <= n:
            raise InputError(
                f"Welch segment of {segment_s} s is not between 4 samples and the record",
                where="assess: segment_s",
            )
        freq, psd = signal.welch(
            a,
            fs=fs,
            window="hann",
            nperseg=nseg,
            noverlap=nseg // 2,
            detrend=False,
            scaling="density",
            axis=-1,
        )
    else:
        raise InputError(
            f"unknown PSD method {method!r}", where="assess", fix="use periodogram or welch"
        )
    return Spectrum(
        freq_hz=freq, psd=np.atleast_2d(psd), df_hz=fs / nseg, nyquist_hz=fs / 2, method=method
    )


def band_rms(spectrum: Spectrum, bands: BandTable) -> BandRMS:
    """RMS of each axis in each band: sqrt of the PSD integrated over the band (see module doc).

    Parameters
    ----------
    spectrum : a :class:`Spectrum`
    bands : bands, Hz; those whose lower edge is at or above Nyquist are dropped
    """
    f, psd, df = spectrum.freq_hz, spectrum.psd, spectrum.df_hz
    nyq = spectrum.nyquist_hz
    keep = bands.lower_hz < nyq
    kept = BandTable(bands.center_hz[keep], bands.lower_hz[keep], bands.upper_hz[keep])
    # bin k covers [f_k - df/2, f_k + df/2] clipped to [0, nyq]
    edges = np.r_[0.0, np.minimum(f + df / 2, nyq)]
    cum = np.concatenate([np.zeros((psd.shape[0], 1)), np.cumsum(psd * df, axis=1)], axis=1)
    lo = np.minimum(kept.lower_hz, nyq)
    hi = np.minimum(kept.upper_hz, nyq)
    power = np.array([np.interp(hi, edges, c) - np.interp(lo, edges, c) for c in cum])
    coverage = (hi - lo) / (kept.upper_hz - kept.lower_hz)
    resolved = (kept.upper_hz - kept.lower_hz) >= df
    return BandRMS(kept, np.sqrt(np.maximum(power, 0.0)), coverage, resolved)


# ----------------------------------------------------------------------------- integrals


def integrated_acceleration(
    timepts: np.ndarray, accel: np.ndarray, window_s: float = 10.0
) -> IntegratedAcceleration:
    """Integral of the acceleration over sliding windows of ``window_s`` (NASA PIMS practice).

    Parameters
    ----------
    timepts : (nt,) sorted times, s (any spacing)
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    window_s : window length, s (the whole record if it is shorter)
    """
    t = np.asarray(timepts, dtype=float)
    a = _as_axes(accel)
    if a.shape[1] != t.size or t.size < 2:
        raise InputError("timepts and accel do not match", where="integrated_acceleration")
    if not window_s > 0:
        raise InputError("window must be positive", where="integrated_acceleration")
    cum = np.concatenate(
        [np.zeros((a.shape[0], 1)), np.cumsum(0.5 * (a[:, 1:] + a[:, :-1]) * np.diff(t), axis=1)],
        axis=1,
    )
    span = t[-1] - t[0]
    window = min(window_s, span)
    starts = t[t + window <= t[-1] + 1e-12 * max(1.0, abs(t[-1]))]
    ends = np.minimum(starts + window, t[-1])
    i0 = np.searchsorted(t, starts)
    dv = np.array([np.interp(ends, t, c) - c[i0] for c in cum])
    return IntegratedAcceleration(
        window_s=float(window),
        t_start=starts,
        delta_v=dv,
        max_mps=np.max(np.abs(dv), axis=1),
        max_magnitude_mps=float(np.max(np.linalg.norm(dv, axis=0))),
    )


# ------------------------------------------------------------------------------ assessment


def assess(
    timepts: np.ndarray,
    accel: np.ndarray,
    requirement: Requirement | None = None,
    *,
    axes: tuple[str, ...] = ("x", "y", "z"),
    psd_method: str = "periodogram",
    segment_s: float | None = None,
    window_s: float = 10.0,
) -> Assessment:
    """Assess an acceleration history against a requirement (default: the ISS requirement).

    Parameters
    ----------
    timepts : (nt,) uniformly spaced times, s
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    requirement : band limits (default :func:`iss_requirement`)
    axes : names of the rows of ``accel``
    psd_method, segment_s : see :func:`acceleration_psd`
    window_s : window of the integrated acceleration, s (PIMS: 10 s)
    """
    a = _as_axes(accel)
    if len(axes) >= a.shape[0]:
        axes = tuple(axes)[: a.shape[0]]
    else:
        axes = tuple(f"axis{i}" for i in range(a.shape[0]))
    req = requirement or iss_requirement()
    spec = acceleration_psd(timepts, a, method=psd_method, segment_s=segment_s)
    br = band_rms(spec, req.bands)
    keep = req.bands.lower_hz < spec.nyquist_hz
    limit = req.limit_g[keep]
    rms_g = br.rms / G0
    with np.errstate(divide="ignore"):
        margin = np.where(rms_g > 0, limit / np.where(rms_g > 0, rms_g, 1.0), np.inf)
    third = ThirdOctave(
        center_hz=br.bands.center_hz,
        lower_hz=br.bands.lower_hz,
        upper_hz=br.bands.upper_hz,
        rms_g=rms_g,
        limit_g=limit,
        margin=margin,
        coverage=br.coverage,
        resolved=br.resolved,
    )
    mag = np.linalg.norm(a, axis=0)
    peak = float(mag.max()) / G0
    worst = None
    if margin.size:
        ax, band = np.unravel_index(np.argmin(margin), margin.shape)
        worst = WorstBand(
            center_hz=float(third.center_hz[band]),
            axis=axes[ax],
            rms_g=float(rms_g[ax, band]),
            limit_g=float(limit[band]),
            margin=float(margin[ax, band]),
        )
    complies = bool(np.all(rms_g <= limit))
    if req.peak_limit_g is not None:
        complies = complies and peak <= req.peak_limit_g
    integ = integrated_acceleration(timepts, a, window_s)
    return Assessment(
        axes=axes,
        requirement=req.name,
        peak_accel_g=peak,
        rms_accel_g=float(np.sqrt(np.mean(mag * mag))) / G0,
        peak_accel_g_axis=np.max(np.abs(a), axis=1) / G0,
        rms_accel_g_axis=np.sqrt(np.mean(a * a, axis=1)) / G0,
        third_octave=third,
        complies=complies,
        peak_limit_g=req.peak_limit_g,
        worst_band=worst,
        integrated_window_s=integ.window_s,
        integrated_max_mps=integ.max_mps,
        integrated_max_magnitude_mps=integ.max_magnitude_mps,
        spectrum=spec,
    )
