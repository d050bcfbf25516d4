"""Force spectra of vibratory sources and the loads they make (inputs of the frequency response).

* :class:`HarmonicLines`: sinusoidal lines ``A cos(2 pi f t + phase)``, ``A`` the peak amplitude
  (N); mean square ``A^2 / 2``.  Lines closer than a relative 1e-12 are one frequency
  (:func:`same_frequency_index`: phasors of a coherent group add there).
* :class:`BandForceSpectrum`: RMS per band, a one-sided PSD flat inside each band,
  ``S = rms^2 / (upper - lower)``, zero outside its bands.
* :class:`ForcePSD`: a one-sided PSD table (N^2/Hz over Hz) interpolated **log-log** (a power
  law between consecutive points; a segment with a zero end is interpolated linearly), zero
  outside its first and last frequency.

Each spectrum gives its PSD at any frequency (``psd_at``), the exact power over intervals
(``power_n2``) and its breakpoints (where the PSD jumps or kinks, for the band quadrature of
:mod:`microg.dynamics.bandquad`).  A :class:`Load` applies a spectrum at a named point along a
direction, optionally in a coherent group (see :mod:`microg.dynamics.frequency`).  Every
constructor checks its values once (``InputError`` naming the field).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg._vectors import parse_direction
from microg.errors import InputError

__all__ = [
    "BandForceSpectrum",
    "ForcePSD",
    "ForceSpectrum",
    "HarmonicLines",
    "Load",
    "same_frequency_index",
]

#: lines closer than this relative spacing are one frequency (phasors of a group add)
_SAME_FREQ_RTOL = 1e-12


def _readonly(a: Any) -> np.ndarray:
    out: np.ndarray = np.array(a, dtype=float)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class HarmonicLines:
    """Sinusoidal force lines ``A_k cos(2 pi f_k t + phase_k)``.

    Attributes
    ----------
    amplitude_n : (nl,) peak amplitudes, N (>= 0)
    freq_hz : (nl,) frequencies, Hz (> 0)
    phase_rad : (nl,) phases, rad (default 0)
    """

    amplitude_n: np.ndarray
    freq_hz: np.ndarray
    phase_rad: np.ndarray | None = None

    def __post_init__(self) -> None:
        a = np.atleast_1d(np.asarray(self.amplitude_n, float))
        f = np.atleast_1d(np.asarray(self.freq_hz, float))
        p = np.zeros_like(f) if self.phase_rad is None else np.atleast_1d(self.phase_rad)
        p = np.asarray(p, float)
        if a.ndim != 1 or a.shape != f.shape or p.shape != f.shape or a.size < 1:
            raise InputError(
                "amplitude, frequency and phase need one value per line", where="harmonic"
            )
        if not (np.all(np.isfinite(a)) and np.all(a >= 0)):
            raise InputError("amplitudes must be finite and >= 0", where="harmonic.amplitude")
        if not (np.all(np.isfinite(f)) and np.all(f > 0)):
            raise InputError("frequencies must be finite and > 0", where="harmonic.frequency")
        if not np.all(np.isfinite(p)):
            raise InputError("phases must be finite", where="harmonic.phase")
        object.__setattr__(self, "amplitude_n", _readonly(a))
        object.__setattr__(self, "freq_hz", _readonly(f))
        object.__setattr__(self, "phase_rad", _readonly(p))

    kind = "harmonic"

    @property
    def breakpoints_hz(self) -> np.ndarray:
        """Spectral breakpoints (none: lines are evaluated exactly)."""
        return np.zeros(0)

    @property
    def mean_square_n2(self) -> float:
        """Mean square of the force, N^2 (sum of A^2 / 2)."""
        return float(np.sum(self.amplitude_n**2) / 2.0)

    def psd_at(self, freq_hz: np.ndarray) -> np.ndarray:
        """Continuous PSD part: zero everywhere (lines carry no density), N^2/Hz."""
        return np.zeros(np.shape(freq_hz))

    def power_n2(self, lower_hz: np.ndarray, upper_hz: np.ndarray) -> np.ndarray:
        """Mean square of the lines with ``lower <= f < upper``, N^2, per interval."""
        lo = np.atleast_1d(np.asarray(lower_hz, float))[:, None]
        hi = np.atleast_1d(np.asarray(upper_hz, float))[:, None]
        inside = (self.freq_hz[None, :] >= lo) & (self.freq_hz[None, :] < hi)
        return inside @ (self.amplitude_n**2 / 2.0)


@dataclass(frozen=True, eq=False)
class BandForceSpectrum:
    """Force RMS per frequency band, flat (constant PSD) inside each band.

    Attributes
    ----------
    lower_hz, upper_hz : (nb,) band edges, Hz, increasing, bands not overlapping
    rms_n : (nb,) RMS force in each band, N (>= 0)
    center_hz : (nb,) nominal centres, Hz (default the geometric mean of the edges)
    """

    lower_hz: np.ndarray
    upper_hz: np.ndarray
    rms_n: np.ndarray
    center_hz: np.ndarray | None = None

    kind = "bands"

    def __post_init__(self) -> None:
        lo = np.atleast_1d(np.asarray(self.lower_hz, float))
        hi = np.atleast_1d(np.asarray(self.upper_hz, float))
        r = np.atleast_1d(np.asarray(self.rms_n, float))
        if lo.ndim != 1 or lo.shape != hi.shape or r.shape != lo.shape or lo.size < 1:
            raise InputError("need one lower edge, upper edge and RMS per band", where="bands")
        if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo > 0)):
            raise InputError("band edges must be finite and > 0", where="bands")
        if not np.all(hi > lo):
            raise InputError("each band needs upper > lower", where="bands")
        if np.any(lo[1:] < hi[:-1] * (1.0 - 1e-12)):
            raise InputError(
                "bands must be in increasing order and not overlap", where="bands.center_hz"
            )
        if not (np.all(np.isfinite(r)) and np.all(r >= 0)):
            raise InputError("band RMS values must be finite and >= 0", where="bands.rms")
        c = np.sqrt(lo * hi) if self.center_hz is None else np.asarray(self.center_hz, float)
        object.__setattr__(self, "lower_hz", _readonly(lo))
        object.__setattr__(self, "upper_hz", _readonly(hi))
        object.__setattr__(self, "rms_n", _readonly(r))
        object.__setattr__(self, "center_hz", _readonly(c))

    @property
    def breakpoints_hz(self) -> np.ndarray:
        """Band edges (the PSD jumps there), Hz."""
        return np.unique(np.r_[self.lower_hz, self.upper_hz])

    @property
    def level_n2_per_hz(self) -> np.ndarray:
        """(nb,) flat PSD level in each band, N^2/Hz."""
        return self.rms_n**2 / (self.upper_hz - self.lower_hz)

    @property
    def mean_square_n2(self) -> float:
        """Total mean square of the force, N^2."""
        return float(np.sum(self.rms_n**2))

    def psd_at(self, freq_hz: np.ndarray) -> np.ndarray:
        """PSD at ``freq_hz``, N^2/Hz (bands closed below, open above)."""
        f = np.asarray(freq_hz, float)
        i = np.searchsorted(self.lower_hz, f, side="right") - 1
        ic = np.clip(i, 0, self.lower_hz.size - 1)
        inside = (i >= 0) & (f < self.upper_hz[ic])
        return np.where(inside, self.level_n2_per_hz[ic], 0.0)

    def power_n2(self, lower_hz: np.ndarray, upper_hz: np.ndarray) -> np.ndarray:
        """Exact integral of the PSD over each ``[lower, upper]``, N^2."""
        lo = np.atleast_1d(np.asarray(lower_hz, float))[:, None]
        hi = np.atleast_1d(np.asarray(upper_hz, float))[:, None]
        overlap = np.clip(
            np.minimum(hi, self.upper_hz[None]) - np.maximum(lo, self.lower_hz[None]), 0, None
        )
        return overlap @ self.level_n2_per_hz


@dataclass(frozen=True, eq=False)
class ForcePSD:
    """Force PSD table, interpolated log-log (a power law between points).

    Attributes
    ----------
    freq_hz : (np,) strictly increasing frequencies, Hz (> 0), at least 2
    value_n2_per_hz : (np,) one-sided PSD, N^2/Hz (>= 0); a segment with a zero end is linear;
        zero outside ``[freq_hz[0], freq_hz[-1]]``
    """

    freq_hz: np.ndarray
    value_n2_per_hz: np.ndarray

    kind = "psd"

    def __post_init__(self) -> None:
        f = np.atleast_1d(np.asarray(self.freq_hz, float))
        v = np.atleast_1d(np.asarray(self.value_n2_per_hz, float))
        if f.ndim != 1 or f.shape != v.shape or f.size < 2:
            raise InputError("need at least 2 (frequency, value) points", where="psd")
        if not (np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.diff(f) > 0)):
            raise InputError(
                "frequencies must be finite, > 0 and strictly increasing", where="psd.frequency_hz"
            )
        if not (np.all(np.isfinite(v)) and np.all(v >= 0)):
            raise InputError("PSD values must be finite and >= 0", where="psd.value")
        object.__setattr__(self, "freq_hz", _readonly(f))
        object.__setattr__(self, "value_n2_per_hz", _readonly(v))

    @property
    def breakpoints_hz(self) -> np.ndarray:
        """Table frequencies (the interpolant has kinks there), Hz."""
        return self.freq_hz

    def _segments(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        f0, f1 = self.freq_hz[:-1], self.freq_hz[1:]
        v0, v1 = self.value_n2_per_hz[:-1], self.value_n2_per_hz[1:]
        loglog = (v0 > 0) & (v1 > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            alpha = np.where(loglog, np.log(v1 / v0) / np.log(f1 / f0), 0.0)
        return f0, f1, v0, v1, alpha

    def psd_at(self, freq_hz: np.ndarray) -> np.ndarray:
        """PSD at ``freq_hz``, N^2/Hz (log-log interpolation, zero outside the table)."""
        f = np.asarray(freq_hz, float)
        f0, f1, v0, v1, alpha = self._segments()
        i = np.clip(np.searchsorted(self.freq_hz, f, side="right") - 1, 0, f0.size - 1)
        inside = (f >= self.freq_hz[0]) & (f <= self.freq_hz[-1])
        fs = np.where(inside, f, f0[i])
        loglog = (v0[i] > 0) & (v1[i] > 0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            pw = v0[i] * (fs / f0[i]) ** alpha[i]
        lin = v0[i] + (v1[i] - v0[i]) * (fs - f0[i]) / (f1[i] - f0[i])
        return np.where(inside, np.where(loglog, pw, lin), 0.0)

    def power_n2(self, lower_hz: np.ndarray, upper_hz: np.ndarray) -> np.ndarray:
        """Exact integral of the interpolated PSD over each ``[lower, upper]``, N^2.

        On a power-law segment ``S = v0 (f/f0)^alpha``::

            int_a^b S df = v0 f0 x_a^beta ln(x_b/x_a) expm1(beta L)/(beta L),
            beta = alpha + 1, L = ln(x_b/x_a), x = f/f0

        (stable through ``alpha = -1``); a linear segment by the trapezoid.
        """
        lo = np.atleast_1d(np.asarray(lower_hz, float))[:, None]
        hi = np.atleast_1d(np.asarray(upper_hz, float))[:, None]
        f0, f1, v0, v1, alpha = self._segments()
        a = np.clip(lo, f0[None], f1[None])
        b = np.clip(hi, f0[None], f1[None])
        b = np.maximum(a, b)
        loglog = (v0 > 0) & (v1 > 0)
        xa, xb = a / f0, b / f0
        L = np.log(xb / xa)
        beta = alpha + 1.0
        bl = beta * L
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            ratio = np.where(np.abs(bl) > 1e-12, np.expm1(bl) / np.where(bl == 0, 1.0, bl), 1.0)
            pw = v0 * f0 * xa**beta * L * ratio
        slope = (v1 - v0) / (f1 - f0)
        va = v0 + slope * (a - f0)
        vb = v0 + slope * (b - f0)
        lin = 0.5 * (va + vb) * (b - a)
        seg = np.where(loglog, np.where(b > a, pw, 0.0), lin)
        return np.sum(seg, axis=1)


ForceSpectrum = HarmonicLines | BandForceSpectrum | ForcePSD


@dataclass(frozen=True, eq=False)
class Load:
    """A force spectrum applied at a named point along a direction.

    Attributes
    ----------
    name : source name (unique within an analysis)
    at : name of the point of the structure where the force acts
    direction : (3,) direction of the force in the station frame (normalised here)
    spectrum : :class:`HarmonicLines`, :class:`BandForceSpectrum` or :class:`ForcePSD`
    group : coherent group (sources of one group add coherently); None: independent
    """

    name: str
    at: str
    direction: np.ndarray
    spectrum: ForceSpectrum
    group: str | None = None

    def __post_init__(self) -> None:
        d = parse_direction(self.direction, where=f"load {self.name!r}: direction")
        object.__setattr__(self, "direction", _readonly(d))


def same_frequency_index(freq: np.ndarray, group: np.ndarray | None = None) -> np.ndarray:
    """Index of the distinct (group, frequency) of each line; equal within _SAME_FREQ_RTOL.

    Parameters
    ----------
    freq : (nl,) line frequencies, Hz
    group : (nl,) group index of each line (default: one group)

    Returns
    -------
    (nl,) int: 0, 1, ... numbering the distinct (group, frequency) pairs in sorted order.
    """
    g = np.zeros(freq.size, int) if group is None else np.asarray(group, int)
    order = np.lexsort((freq, g))
    fs, gs = freq[order], g[order]
    new = np.r_[True, (gs[1:] != gs[:-1]) | (np.diff(fs) > _SAME_FREQ_RTOL * fs[1:])]
    key_sorted = np.cumsum(new) - 1
    key = np.empty(freq.size, int)
    key[order] = key_sorted
    return key
