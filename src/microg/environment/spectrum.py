"""The power spectral density of an acceleration record (one-sided, per axis).

PSD: one-sided power spectral density, (m/s^2)^2/Hz (see docs/assessment.md).  Default
``periodogram``: the whole (demeaned) record, boxcar window (a transient must not be tapered
away; Parseval holds exactly: ``sum(psd) * df`` is the mean square).  ``welch``: Hann window,
segments of ``segment_s`` (default the whole record), 50 % overlap, each segment's mean
removed; for long stationary records.  The record's mean (DC) belongs to the quasi-steady
regime: it is removed before the spectrum by default.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._json import json_by_name, json_numbers
from microg.environment._samples import as_axes, axis_names, sample_rate, xr_dataset
from microg.errors import InputError
from microg.units import G0

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["Spectrum", "acceleration_psd", "periodogram"]


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
    record_s : length of the record the spectrum was taken from, s (None: ``1 / df_hz``)
    """

    freq_hz: np.ndarray
    psd: np.ndarray
    df_hz: float
    nyquist_hz: float
    method: str
    record_s: float | None = None

    @property
    def duration_s(self) -> float:
        """The record length, s."""
        return float(self.record_s) if self.record_s is not None else 1.0 / self.df_hz

    @property
    def psd_g2_per_hz(self) -> np.ndarray:
        """The PSD in g^2/Hz, (naxes, nf)."""
        return self.psd / G0**2

    def to_dict(self, axes: tuple[str, ...] | None = None) -> dict[str, Any]:
        """JSON-ready spectrum: bins (Hz) and the PSD per axis, g^2/Hz."""
        ax = axis_names(self.psd.shape[0], axes)
        return {
            "method": self.method,
            "df_hz": self.df_hz,
            "nyquist_hz": self.nyquist_hz,
            "duration_s": self.duration_s,
            "freq_hz": json_numbers(self.freq_hz),
            "psd_g2_per_hz_axis": json_by_name(ax, self.psd_g2_per_hz),
        }

    def to_xarray(self, axes: tuple[str, ...] | None = None) -> Any:
        """The PSD as an ``xarray.Dataset``: ``psd_g2_per_hz`` on dims ``axis``, ``freq_hz``."""
        ax = axis_names(self.psd.shape[0], axes)
        return xr_dataset(
            {
                "psd_g2_per_hz": (
                    ("axis", "freq_hz"),
                    self.psd_g2_per_hz,
                    {"units": "g^2/Hz", "long_name": "one-sided PSD", "method": self.method},
                )
            },
            {"axis": list(ax), "freq_hz": ("freq_hz", self.freq_hz, {"units": "Hz"})},
            {
                "method": self.method,
                "df_hz": self.df_hz,
                "nyquist_hz": self.nyquist_hz,
                "duration_s": self.duration_s,
            },
        )

    def plot(self, axes: tuple[str, ...] | None = None, ax: Any = None) -> Figure:
        """The PSD, g^2/Hz, log-log (:func:`microg.plotting.environment.plot_psd`).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_psd

        return plot_psd(self, axes=axis_names(self.psd.shape[0], axes), ax=ax)


def periodogram(x: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided boxcar periodogram, density scaling: ``2 |X_k|^2 / (fs n)`` (DC, Nyquist once).

    The same definition as ``scipy.signal.periodogram(x, fs, window="boxcar",
    scaling="density", detrend=False)``; Parseval: ``sum(psd) * fs / n`` is the mean square.

    Parameters
    ----------
    x : ndarray (naxes, n)
        Samples, any unit u.
    fs : float
        Sampling rate, Hz.

    Returns
    -------
    freq_hz : ndarray (n // 2 + 1,)
    psd : ndarray (naxes, n // 2 + 1)
        u^2/Hz.
    """
    n = x.shape[-1]
    spec = np.fft.rfft(x, axis=-1)
    psd = (spec.real**2 + spec.imag**2) / (fs * n)
    last = None if n % 2 else -1  # an even record's last bin is Nyquist: counted once
    psd[..., 1:last] *= 2.0
    return np.fft.rfftfreq(n, 1.0 / fs), psd


def acceleration_psd(
    timepts: np.ndarray,
    accel: np.ndarray,
    *,
    method: str = "periodogram",
    segment_s: float | None = None,
    demean: bool = True,
) -> Spectrum:
    """One-sided PSD of uniformly sampled accelerations.

    Parameters
    ----------
    timepts : (nt,) uniformly spaced times, s
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    method : ``periodogram`` (whole record, boxcar; exact Parseval) or ``welch`` (Hann window,
        50 % overlap)
    segment_s : Welch segment length, s (default: the whole record)
    demean : remove the record's mean first (``welch``: each segment's mean); the mean is the
        quasi-steady part, reported separately by :func:`assess`

    Returns
    -------
    Spectrum with ``psd`` in (m/s^2)^2/Hz.
    """
    a = as_axes(accel)
    fs = sample_rate(timepts)
    n = a.shape[1]
    if a.shape[1] != np.asarray(timepts).size:
        raise InputError("timepts and accel have different lengths", where="accel")
    if method == "periodogram":
        x = a - a.mean(axis=1, keepdims=True) if demean else a
        freq, psd = periodogram(x, fs)
        nseg = n
    elif method == "welch":
        nseg = n if segment_s is None else int(round(segment_s * fs))
        if not 4 <= nseg <= n:
            raise InputError(
                f"Welch segment of {segment_s} s is not between 4 samples and the record",
                where="segment_s",
                fix=f"give a segment between {4 / fs:.3g} s and {n / fs:.6g} s",
            )
        from scipy import signal  # only here: scipy.signal costs ~0.5 s to import

        freq, psd = signal.welch(
            a,
            fs=fs,
            window="hann",
            nperseg=nseg,
            noverlap=nseg // 2,
            detrend="constant" if demean else False,
            scaling="density",
            axis=-1,
        )
    else:
        raise InputError(
            f"unknown PSD method {method!r}", where="psd_method", fix="use periodogram or welch"
        )
    return Spectrum(
        freq_hz=freq,
        psd=np.atleast_2d(psd),
        df_hz=fs / nseg,
        nyquist_hz=fs / 2,
        method=method,
        record_s=n / fs,
    )
