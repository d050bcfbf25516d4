"""Microgravity assessment of acceleration histories: peak, RMS, PSD, 1/3-octave bands, limits.

Definitions (see docs/assessment.md):

* Mean (DC): the record's mean per axis belongs to the quasi-steady regime.  It is reported
  (``mean_accel_g_axis``) and removed before the spectrum; the power of the 0-Hz bin is excluded
  from every band in any case.
* PSD: one-sided power spectral density, (m/s^2)^2/Hz.  Default ``periodogram``: the whole
  (demeaned) record, boxcar window (a transient must not be tapered away; Parseval holds
  exactly: ``sum(psd) * df`` is the mean square).  ``welch``: Hann window, segments of
  ``segment_s`` (default the whole record), 50 % overlap, each segment's mean removed; for long
  stationary records.
* Band RMS: ``sqrt(integral of the PSD over [lower, upper])``.  Each frequency bin's power
  ``psd_k * df`` is spread uniformly over its own interval ``[f_k - df/2, f_k + df/2]`` (clipped to
  ``[0, Nyquist]``); a bin straddling a band edge is shared in proportion.  So the band mean
  squares of contiguous bands add up exactly to the mean square of the record in their range
  (Parseval).  Bands wholly above Nyquist are left out.
* Resolved band: at least ``MIN_BINS`` (5) frequency bins in the band, a record at least
  ``MIN_TIME_BANDWIDTH`` (5) times 1/bandwidth long, wholly below Nyquist (and below the data's
  anti-alias cutoff when one is given).  Only resolved bands are judged; the others are listed
  with the reason.  An unresolved band whose estimate exceeds its limit makes ``complies``
  false (compliance cannot be shown), with a warning naming the record length that would
  resolve it.
* Integrated acceleration, two named quantities:
  ``sliding`` (microg's, conservative): ``max over t of |int_t^{t+W} a dt|`` over the raw record,
  windows of ``W = 10 s`` starting at every sample (end interpolated in the running trapezoidal
  integral); ``pims`` (NASA PIMS ``file_trapz``): the record demeaned, cut into consecutive
  blocks of ``ceil(W / dt)`` samples (an incomplete last block dropped), each block integrated
  by the trapezoid rule.
* Margin: ``limit / band RMS`` (>= 1 passes, infinite for a zero band; ``"inf"`` in JSON).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.environment.requirements import BandTable, Requirement
from microg.environment.requirements import requirement as requirement_by_name
from microg.environment.transient import (
    TransientCriteria,
    TransientVerdict,
    judge_transient,
    transient_criteria,
)
from microg.errors import InputError
from microg.units import G0

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "MIN_BINS",
    "MIN_TIME_BANDWIDTH",
    "MAX_SAMPLES",
    "Spectrum",
    "BandRMS",
    "ThirdOctave",
    "WorstBand",
    "IntegratedAcceleration",
    "IntegratedBlocks",
    "Assessment",
    "json_number",
    "acceleration_psd",
    "band_mean_square",
    "band_rms",
    "band_weights",
    "integrated_acceleration",
    "integrated_acceleration_pims",
    "assess",
]

#: fewest frequency bins in a band for its RMS to be judged (see docs/assessment.md)
MIN_BINS = 5.0
#: fewest record lengths per 1/bandwidth for a band to be judged
MIN_TIME_BANDWIDTH = 5.0
#: largest record accepted by :func:`assess` (samples per axis; about 0.5 GB of work arrays)
MAX_SAMPLES = 20_000_000


def json_number(value: float) -> float | str | None:
    """A float for JSON: finite as is, +-inf as the strings ``"inf"``/``"-inf"``, NaN as None.

    ``"inf"`` is the documented representation of an infinite margin (a band with no power);
    None means "not computed".
    """
    v = float(value)
    if math.isfinite(v):
        return v
    if math.isnan(v):
        return None
    return "inf" if v > 0 else "-inf"


def _numbers(a: np.ndarray) -> list[float | str | None]:
    return [json_number(v) for v in np.ravel(a)]


def axis_names(n: int, axes: tuple[str, ...] | None = None) -> tuple[str, ...]:
    """Names of ``n`` axes: ``axes`` when given (checked), ``x, y, z`` for 3, else ``a0, a1``."""
    if axes is not None:
        if len(axes) != n:
            raise InputError(f"{len(axes)} axis names for {n} axes", where="axes")
        return tuple(axes)
    return ("x", "y", "z")[:n] if n <= 3 else tuple(f"a{i}" for i in range(n))


def _per_axis(axes: tuple[str, ...], a: np.ndarray) -> dict[str, list[float | str | None]]:
    return {name: _numbers(row) for name, row in zip(axes, np.atleast_2d(a), strict=True)}


def _dataset(data: dict[str, Any], coords: dict[str, Any], attrs: dict[str, Any]) -> Any:
    import xarray as xr

    return xr.Dataset(data, coords=coords, attrs=attrs)


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
            "freq_hz": _numbers(self.freq_hz),
            "psd_g2_per_hz_axis": _per_axis(ax, self.psd_g2_per_hz),
        }

    def to_xarray(self, axes: tuple[str, ...] | None = None) -> Any:
        """The PSD as an ``xarray.Dataset``: ``psd_g2_per_hz`` on dims ``axis``, ``freq_hz``."""
        ax = axis_names(self.psd.shape[0], axes)
        return _dataset(
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
            "rms_g_axis": _per_axis(ax, self.rms_g),
            "coverage": _numbers(self.coverage),
            "n_bins": _numbers(self.n_bins),
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
    n_bins: np.ndarray = field(default_factory=lambda: np.zeros(0))
    reasons: tuple[str, ...] = ()

    @property
    def worst_rms_g(self) -> np.ndarray:
        """Largest band RMS over the axes, (nb,), g."""
        return self.rms_g.max(axis=0)

    @property
    def rss_rms_g(self) -> np.ndarray:
        """Root sum of squares of the axes' band RMS, (nb,), g (PIMS's ``v`` column)."""
        return np.sqrt(np.sum(self.rms_g**2, axis=0))

    @property
    def passes(self) -> np.ndarray:
        """(nb,) True where every axis is within the limit."""
        return np.all(self.rms_g <= self.limit_g, axis=0)

    @property
    def judged(self) -> np.ndarray:
        """(nb,) the bands that enter the verdict (resolved)."""
        return np.asarray(self.resolved, bool)

    @property
    def unresolved_bands(self) -> list[dict[str, Any]]:
        """The bands left out of the verdict: centre, edges and why."""
        return [
            {
                "center_hz": float(self.center_hz[i]),
                "lower_hz": float(self.lower_hz[i]),
                "upper_hz": float(self.upper_hz[i]),
                "reason": self.reasons[i] if i < len(self.reasons) else "unresolved",
            }
            for i in np.nonzero(~self.judged)[0]
        ]

    @property
    def verdict_range_hz(self) -> tuple[float, float] | None:
        """(lowest lower edge, highest upper edge) of the judged bands, Hz; None if none."""
        j = self.judged
        if not np.any(j):
            return None
        return float(self.lower_hz[j].min()), float(self.upper_hz[j].max())

    def to_dict(self, axes: tuple[str, ...] | None = None) -> dict[str, Any]:
        """JSON-ready bands (the ``third_octave`` block of :meth:`Assessment.to_dict`).

        ``rms_g`` and ``margin`` are the worst over the axes; ``*_axis`` per axis; an infinite
        margin is ``"inf"``.
        """
        ax = axis_names(self.rms_g.shape[0], axes)
        vr = self.verdict_range_hz
        return {
            "center_hz": _numbers(self.center_hz),
            "lower_hz": _numbers(self.lower_hz),
            "upper_hz": _numbers(self.upper_hz),
            "rms_g": _numbers(self.worst_rms_g),
            "limit_g": _numbers(self.limit_g),
            "margin": _numbers(self.margin.min(axis=0) if self.margin.size else self.margin),
            "rms_g_axis": _per_axis(ax, self.rms_g),
            "margin_axis": _per_axis(ax, self.margin),
            "rss_rms_g": _numbers(self.rss_rms_g),
            "resolved": [bool(v) for v in self.resolved],
            "n_bins": _numbers(self.n_bins),
            "coverage": _numbers(self.coverage),
            "unresolved_bands": self.unresolved_bands,
            "unresolved_exceeding_hz": _numbers(
                self.center_hz[~self.judged & np.any(self.rms_g > self.limit_g, axis=0)]
            ),
            "verdict_bands_hz": _numbers(self.center_hz[self.judged]),
            "verdict_range_hz": None if vr is None else list(vr),
        }

    def to_xarray(self, axes: tuple[str, ...] | None = None) -> Any:
        """Band RMS, limits and margins as an ``xarray.Dataset`` (dims ``axis``, ``center_hz``)."""
        ax = axis_names(self.rms_g.shape[0], axes)
        nb = self.center_hz.size
        return _dataset(
            {
                "rms_g": (
                    ("axis", "center_hz"),
                    self.rms_g,
                    {"units": "g", "long_name": "band RMS"},
                ),
                "margin": (("axis", "center_hz"), self.margin, {"units": "1"}),
                "limit_g": ("center_hz", self.limit_g, {"units": "g"}),
                "rss_rms_g": ("center_hz", self.rss_rms_g, {"units": "g"}),
                "resolved": ("center_hz", np.asarray(self.resolved, np.int8), {"units": "1"}),
                "coverage": ("center_hz", self.coverage, {"units": "1"}),
                "n_bins": (
                    "center_hz",
                    self.n_bins if self.n_bins.size == nb else np.full(nb, np.nan),
                    {"units": "1"},
                ),
            },
            {
                "axis": list(ax),
                "center_hz": ("center_hz", self.center_hz, {"units": "Hz"}),
                "lower_hz": ("center_hz", self.lower_hz, {"units": "Hz"}),
                "upper_hz": ("center_hz", self.upper_hz, {"units": "Hz"}),
            },
            {},
        )

    def plot(
        self, axes: tuple[str, ...] | None = None, *, title: str = "", ax: Any = None
    ) -> Figure:
        """Band RMS per axis against the limit steps (``plotting.environment.plot_bands``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_bands

        return plot_bands(self, axes=axis_names(self.rms_g.shape[0], axes), title=title, ax=ax)


class _WindowIntegrals:
    """The methods shared by the two integrated-acceleration results (sliding and PIMS)."""

    DEFINITION: str
    window_s: float
    t_start: np.ndarray
    delta_v: np.ndarray
    max_mps: np.ndarray
    max_magnitude_mps: float

    def _extra(self) -> dict[str, Any]:
        """Keys a result adds to :meth:`to_dict` after ``window_s``."""
        return {}

    def to_dict(self, axes: tuple[str, ...] | None = None) -> dict[str, Any]:
        """JSON-ready summary: the window and the largest integrals, m/s.

        No per-window rows; those are in :meth:`to_xarray`.
        """
        ax = axis_names(self.delta_v.shape[0], axes)
        return {
            "definition": self.DEFINITION,
            "window_s": self.window_s,
            **self._extra(),
            "n_windows": int(self.t_start.size),
            "max_mps_axis": dict(zip(ax, _numbers(self.max_mps), strict=True)),
            "max_magnitude_mps": json_number(self.max_magnitude_mps),
        }

    def to_xarray(self, axes: tuple[str, ...] | None = None) -> Any:
        """The integral of each window as an ``xarray.Dataset``.

        ``delta_v_mps`` on dims ``axis``, ``t_start_s``.
        """
        ax = axis_names(self.delta_v.shape[0], axes)
        return _dataset(
            {
                "delta_v_mps": (
                    ("axis", "t_start_s"),
                    self.delta_v,
                    {"units": "m/s", "long_name": "integral of the acceleration"},
                ),
                "max_mps": ("axis", self.max_mps, {"units": "m/s"}),
            },
            {"axis": list(ax), "t_start_s": ("t_start_s", self.t_start, {"units": "s"})},
            {
                "definition": self.DEFINITION,
                "window_s": self.window_s,
                "max_magnitude_mps": self.max_magnitude_mps,
            },
        )

    def plot(
        self, axes: tuple[str, ...] | None = None, *, title: str = "", ax: Any = None
    ) -> Figure:
        """Each window's integral against its start (``plotting.environment.plot_integrated``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_integrated

        me: Any = self  # one of the two subclasses
        return plot_integrated(me, axes=axis_names(self.delta_v.shape[0], axes), title=title, ax=ax)


@dataclass(frozen=True)
class IntegratedAcceleration(_WindowIntegrals):
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

    #: what the integral is (in :meth:`to_dict` and :meth:`to_xarray`)
    DEFINITION = (
        "max over windows starting at every sample of |integral of the raw acceleration "
        "over window_s| (microg, conservative)"
    )


@dataclass(frozen=True)
class IntegratedBlocks(_WindowIntegrals):
    """PIMS's integrated acceleration: consecutive demeaned blocks, m/s.

    Attributes
    ----------
    window_s : nominal block length, s
    block_samples : samples per block, ``ceil(window_s / dt)`` as PIMS computes it
    t_start : (nb,) block start times, s
    delta_v : (naxes, nb) trapezoidal integral of each block, m/s
    max_mps : (naxes,) max |delta_v| per axis, m/s (0 when there is no complete block)
    max_magnitude_mps : max over blocks of the vector norm, m/s
    """

    window_s: float
    block_samples: int
    t_start: np.ndarray
    delta_v: np.ndarray
    max_mps: np.ndarray
    max_magnitude_mps: float

    @property
    def n_blocks(self) -> int:
        """Complete blocks in the record."""
        return int(self.t_start.size)

    #: what the integral is (in :meth:`to_dict` and :meth:`to_xarray`)
    DEFINITION = (
        "record demeaned, consecutive blocks of block_samples = ceil(window_s / dt) samples, "
        "trapezoidal integral of each (NASA PIMS file_trapz)"
    )

    def _extra(self) -> dict[str, Any]:
        """``block_samples`` (PIMS's block length in samples)."""
        return {"block_samples": self.block_samples}


@dataclass(frozen=True)
class WorstBand:
    """The resolved band and axis with the smallest margin."""

    center_hz: float
    axis: str
    rms_g: float
    limit_g: float
    margin: float
    lower_hz: float = float("nan")
    upper_hz: float = float("nan")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready band (an infinite margin is ``"inf"``, an unknown edge None)."""
        return {
            "center_hz": self.center_hz,
            "lower_hz": json_number(self.lower_hz),
            "upper_hz": json_number(self.upper_hz),
            "axis": self.axis,
            "rms_g": self.rms_g,
            "limit_g": self.limit_g,
            "margin": json_number(self.margin),
        }


@dataclass(frozen=True)
class Assessment:
    """Assessment of an acceleration history at one point.

    Attributes
    ----------
    axes : axis names
    requirement : requirement name
    peak_accel_g : peak of the acceleration vector magnitude (raw record), g
    rms_accel_g : RMS of the vector magnitude over the record (raw), g
    peak_accel_g_axis, rms_accel_g_axis : (naxes,) per axis (raw), g
    third_octave : band RMS, limits, margins, resolution of each band
    complies : every resolved band of every axis within its limit, no unresolved band's
        estimate above its limit, the peak within ``peak_limit_g`` when the requirement has one,
        and every *verified* transient criterion met; False when no band is resolved
    peak_limit_g : the requirement's peak limit, g, or None
    worst_band : the resolved band and axis with the smallest margin (None: none resolved)
    mean_accel_g_axis : (naxes,) record mean (the quasi-steady part), g
    integrated_sliding : microg's sliding-window integral (raw record)
    integrated_pims : PIMS's consecutive demeaned blocks (None: record shorter than a block)
    transient : the transient criteria judged (None when none were asked for)
    transient_basis : ``sliding`` or ``pims``: which integral and peak the criteria judge
    requirement_source : citation of the requirement
    record_s : record length ``n dt``, s
    dt_s : sample interval, s
    cutoff_hz : the data's anti-alias cutoff, Hz, or None
    warnings : lines for the user (unresolved exceedances, unverified criteria exceeded, ...)
    spectrum : the PSD used for the bands (of the demeaned record)
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
    mean_accel_g_axis: np.ndarray
    integrated_sliding: IntegratedAcceleration = field(repr=False)
    integrated_pims: IntegratedBlocks | None = field(repr=False)
    transient: TransientVerdict | None
    transient_basis: str
    requirement_source: str
    record_s: float
    dt_s: float
    cutoff_hz: float | None
    warnings: tuple[str, ...]
    spectrum: Spectrum = field(repr=False)

    # ------------------------------------------------------------------ derived quantities

    @property
    def mean_accel_g(self) -> float:
        """Magnitude of the mean acceleration vector, g."""
        return float(np.linalg.norm(self.mean_accel_g_axis))

    @property
    def verdict_bands_hz(self) -> np.ndarray:
        """Centres of the bands the verdict covers (resolved), Hz."""
        to = self.third_octave
        return to.center_hz[to.judged]

    @property
    def verdict_range_hz(self) -> tuple[float, float] | None:
        """(lowest lower edge, highest upper edge) of the judged bands, Hz; None if none."""
        return self.third_octave.verdict_range_hz

    @property
    def unresolved_bands(self) -> list[dict[str, Any]]:
        """The bands left out of the verdict: centre, edges and why."""
        return self.third_octave.unresolved_bands

    # ---------------------------------------------------------------------------- outputs

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (the ``microg analyze --json`` observation layout).

        Keys carry units in their names; an infinite margin is the string ``"inf"``.
        """
        to = self.third_octave
        ax = self.axes

        def per_axis(a: np.ndarray) -> dict[str, float | str | None]:
            return dict(zip(ax, _numbers(a), strict=True))

        sl = self.integrated_sliding
        out: dict[str, Any] = {
            "peak_accel_g": self.peak_accel_g,
            "rms_accel_g": self.rms_accel_g,
            "peak_accel_g_axis": per_axis(self.peak_accel_g_axis),
            "rms_accel_g_axis": per_axis(self.rms_accel_g_axis),
            "mean_accel_g": self.mean_accel_g,
            "mean_accel_g_axis": per_axis(self.mean_accel_g_axis),
            "record": {
                "duration_s": self.record_s,
                "dt_s": self.dt_s,
                "samples": int(round(self.record_s / self.dt_s)),
                "psd_method": self.spectrum.method,
                "df_hz": self.spectrum.df_hz,
                "nyquist_hz": self.spectrum.nyquist_hz,
                "cutoff_hz": self.cutoff_hz,
                "demeaned": True,
            },
            "third_octave": to.to_dict(ax),
            "requirement": self.requirement,
            "requirement_source": self.requirement_source,
            "complies": bool(self.complies),
            "peak_limit_g": self.peak_limit_g,
            "worst_band": None if self.worst_band is None else self.worst_band.to_dict(),
            "integrated_accel_sliding": {
                "definition": sl.DEFINITION,
                "window_s": sl.window_s,
                "max_mps_axis": per_axis(sl.max_mps),
                "max_magnitude_mps": sl.max_magnitude_mps,
            },
            "integrated_accel_pims": None,
            "transient": None
            if self.transient is None
            else {"basis": self.transient_basis, **self.transient.to_dict(ax)},
            "warnings": list(self.warnings),
        }
        pb = self.integrated_pims
        if pb is not None:
            out["integrated_accel_pims"] = {
                "definition": pb.DEFINITION,
                "window_s": pb.window_s,
                "block_samples": pb.block_samples,
                "n_blocks": pb.n_blocks,
                "max_mps_axis": per_axis(pb.max_mps),
                "max_magnitude_mps": pb.max_magnitude_mps,
            }
        return out

    def to_xarray(self) -> Any:
        """Band RMS, margins, limits and PSD as an ``xarray.Dataset``.

        Dims ``axis``, ``center_hz`` (bands) and ``freq_hz`` (PSD bins).

        Units in each variable's ``units`` attribute; the verdict and the requirement in the
        dataset's attributes.
        """
        import xarray as xr

        to = self.third_octave
        spec = self.spectrum
        coords = {
            "axis": list(self.axes),
            "center_hz": ("center_hz", to.center_hz, {"units": "Hz"}),
            "lower_hz": ("center_hz", to.lower_hz, {"units": "Hz"}),
            "upper_hz": ("center_hz", to.upper_hz, {"units": "Hz"}),
            "freq_hz": ("freq_hz", spec.freq_hz, {"units": "Hz"}),
        }
        data = {
            "rms_g": (("axis", "center_hz"), to.rms_g, {"units": "g", "long_name": "band RMS"}),
            "margin": (("axis", "center_hz"), to.margin, {"units": "1"}),
            "limit_g": ("center_hz", to.limit_g, {"units": "g"}),
            "rss_rms_g": ("center_hz", to.rss_rms_g, {"units": "g"}),
            "resolved": ("center_hz", np.asarray(to.resolved, np.int8), {"units": "1"}),
            "n_bins": ("center_hz", to.n_bins, {"units": "1"}),
            "psd_g2_per_hz": (
                ("axis", "freq_hz"),
                spec.psd / G0**2,
                {"units": "g^2/Hz", "method": spec.method},
            ),
            "peak_accel_g_axis": ("axis", self.peak_accel_g_axis, {"units": "g"}),
            "rms_accel_g_axis": ("axis", self.rms_accel_g_axis, {"units": "g"}),
            "mean_accel_g_axis": ("axis", self.mean_accel_g_axis, {"units": "g"}),
        }
        return xr.Dataset(
            data,
            coords=coords,
            attrs={
                "requirement": self.requirement,
                "requirement_source": self.requirement_source,
                "complies": int(self.complies),
                "peak_accel_g": self.peak_accel_g,
                "rms_accel_g": self.rms_accel_g,
                "record_s": self.record_s,
                "dt_s": self.dt_s,
            },
        )

    def plot(self, kind: str = "third_octave", ax: Any = None) -> Figure:
        """A figure of the assessment: ``third_octave`` (default) or ``psd``.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_psd, plot_third_octave

        if kind == "third_octave":
            return plot_third_octave(self, ax=ax)
        if kind == "psd":
            return plot_psd(self.spectrum, axes=self.axes, ax=ax)
        raise InputError(f"unknown plot {kind!r}", where="kind", fix="use third_octave or psd")


# ------------------------------------------------------------------------------- spectra


def _as_axes(accel: np.ndarray) -> np.ndarray:
    a = np.asarray(accel, dtype=float)
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2:
        raise InputError("acceleration must have shape (naxes, nt) or (nt,)", where="accel")
    return a


def _sample_rate(timepts: np.ndarray) -> float:
    """Sampling rate of uniformly spaced times, Hz (steps within 1e-6 of their mean)."""
    t = np.asarray(timepts, dtype=float)
    if t.ndim != 1 or t.size < 4:
        raise InputError("need at least 4 uniformly spaced samples", where="timepts")
    mean = float(t[-1] - t[0]) / (t.size - 1)
    dev = np.diff(t)
    dev -= mean
    # written so that a NaN anywhere fails it (a NaN compares false); max |dev| without |dev|
    if not (mean > 0 and max(float(dev.max()), -float(dev.min())) <= 1e-6 * mean):
        if not np.all(np.isfinite(t)):
            raise InputError(
                "times are not all finite", where="timepts", fix="remove NaN/inf times"
            )
        raise InputError(
            "a spectrum needs uniformly spaced output times",
            where="timepts",
            fix="evaluate the response on a uniform grid (np.linspace)",
        )
    return 1.0 / mean


def _check_finite(a: np.ndarray) -> None:
    bad = ~np.isfinite(a)
    if np.any(bad):
        ax, i = np.unravel_index(int(np.argmax(bad)), a.shape)
        raise InputError(
            f"acceleration is not finite (row {ax}, sample {i})",
            where="accel",
            fix="remove or fill the NaN/inf samples before assessing",
        )


def _periodogram(x: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
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
    a = _as_axes(accel)
    fs = _sample_rate(timepts)
    n = a.shape[1]
    if a.shape[1] != np.asarray(timepts).size:
        raise InputError("timepts and accel have different lengths", where="accel")
    if method == "periodogram":
        x = a - a.mean(axis=1, keepdims=True) if demean else a
        freq, psd = _periodogram(x, fs)
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


def band_weights(freq_hz: np.ndarray, df_hz: float, nyquist_hz: float, bands: BandTable) -> Any:
    """The band integration as a linear map: ``power_b = sum_k W[b, k] psd_k``, Hz.

    Bin ``k`` covers ``[f_k - df/2, f_k + df/2]`` clipped to ``[0, nyquist]`` and carries
    ``psd_k df``; a band ``[lo, hi]`` (clipped to Nyquist) takes the fraction of each bin it
    overlaps (the PSD constant across a bin), and the 0-Hz bin's power (the mean) is left out.
    ``W[b, k] = df |[lo, hi] ∩ bin_k| / |bin_k|``.  Sparse: each band covers a run of bins.
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
    edges = np.r_[0.0, np.minimum(f + df_hz / 2, nyquist_hz)]
    lo = np.minimum(lower_hz, nyquist_hz)
    hi = np.minimum(upper_hz, nyquist_hz)
    # bins j0 <= j < j1 overlap [lo, hi]
    j0 = np.clip(np.searchsorted(edges, lo, side="right") - 1, 0, f.size)
    j1 = np.clip(np.searchsorted(edges, hi, side="left"), 0, f.size)
    j1 = np.maximum(j1, j0)
    count = j1 - j0
    rows = np.repeat(np.arange(nb), count)
    cols = np.repeat(j0 - np.cumsum(np.r_[0, count[:-1]]), count) + np.arange(int(count.sum()))
    a, b = edges[cols], edges[cols + 1]
    width = b - a
    overlap = np.minimum(b, hi[rows]) - np.maximum(a, lo[rows])
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.where(width > 0, np.clip(overlap, 0.0, None) / width, 0.0)
    w = frac * df_hz
    if f.size and f[0] == 0.0:
        w = np.where(cols == 0, 0.0, w)  # the mean is no vibration
    return sp.csr_matrix((w, (rows, cols)), shape=(nb, f.size))


#: direct DFT of the bins a band table needs, instead of the whole FFT, up to this many bins
_DFT_MAX_BINS = 64
#: ... and up to this many (samples x bins) entries in its cosine and sine tables
_DFT_MAX_ENTRIES = 1 << 22


def band_mean_square(timepts: np.ndarray, accel: np.ndarray, bands: BandTable) -> np.ndarray:
    """Mean square of each demeaned row in each band, from the boxcar periodogram, (u)^2.

    The same number as ``band_rms(acceleration_psd(timepts, accel), bands).rms ** 2`` (the
    periodogram of :func:`_periodogram` integrated by :func:`band_weights`), computed from
    only the DFT bins the bands overlap when they are few: ``X_k = sum_n x_n e^{-2 pi i k n /
    N}`` as two matrix products with exact integer phases ``(k n) mod N``.  Many series in
    a few narrow bands (a run's modal accelerations in a point's worst band) then cost a
    fraction of a full FFT, above all for record lengths with large prime factors (20,001 =
    3 x 59 x 113).  Otherwise the whole periodogram is taken.

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
    a = _as_axes(accel)
    fs = _sample_rate(timepts)
    n = a.shape[1]
    if n != np.asarray(timepts).size:
        raise InputError("timepts and accel have different lengths", where="accel")
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    w = band_weights(freq, fs / n, fs / 2, bands).tocsc()
    w.eliminate_zeros()
    cols = np.flatnonzero(np.diff(w.indptr))  # bins with a nonzero weight (never bin 0)
    x = a - a.mean(axis=1, keepdims=True)
    if cols.size > _DFT_MAX_BINS or n * cols.size > _DFT_MAX_ENTRIES:
        _, psd = _periodogram(x, fs)
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


# ----------------------------------------------------------------------------- integrals


def integrated_acceleration(
    timepts: np.ndarray, accel: np.ndarray, window_s: float = 10.0
) -> IntegratedAcceleration:
    """Integral of the raw acceleration over sliding windows of ``window_s`` (microg's).

    Windows start at every sample; the end is interpolated in the running trapezoidal
    integral.  Conservative: the worst window anywhere, the mean kept.

    Parameters
    ----------
    timepts : (nt,) sorted times, s (any spacing)
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    window_s : window length, s (the whole record if it is shorter)
    """
    t = np.asarray(timepts, dtype=float)
    a = _as_axes(accel)
    if a.shape[1] != t.size or t.size < 2:
        raise InputError("timepts and accel do not match", where="accel")
    if not window_s > 0:
        raise InputError("window must be positive", where="window_s")
    cum = np.concatenate(
        [np.zeros((a.shape[0], 1)), np.cumsum(0.5 * (a[:, 1:] + a[:, :-1]) * np.diff(t), axis=1)],
        axis=1,
    )
    span = t[-1] - t[0]
    window = min(window_s, span)
    # the windows start at a prefix of the samples (t sorted), their ends interpolated in the
    # running integral
    n_win = int(np.count_nonzero(t + window <= t[-1] + 1e-12 * max(1.0, abs(t[-1]))))
    starts = t[:n_win]
    ends = np.minimum(starts + window, t[-1])
    dv = np.array([np.interp(ends, t, c) - c[:n_win] for c in cum])
    return IntegratedAcceleration(
        window_s=float(window),
        t_start=starts,
        delta_v=dv,
        max_mps=np.max(np.abs(dv), axis=1),
        max_magnitude_mps=float(np.max(np.linalg.norm(dv, axis=0))),
    )


def integrated_acceleration_pims(
    timepts: np.ndarray,
    accel: np.ndarray,
    window_s: float = 10.0,
    *,
    sample_rate_hz: float | None = None,
) -> IntegratedBlocks:
    """PIMS's integrated acceleration: the demeaned record in consecutive blocks, m/s.

    As ``file_trapz`` in ``transient/main.py`` of github.com/baluneboy/pims: the record's mean
    is removed (over the whole record), ``nt = ceil(window_s / dt)`` with ``dt = 1 / fs`` (a
    ratio within 1e-9 of an integer taken as that integer), consecutive blocks of ``nt``
    samples, an incomplete last block dropped, and each block integrated by the trapezoid rule
    with spacing ``dt``.

    Parameters
    ----------
    timepts : (nt,) uniformly spaced times, s
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    window_s : nominal block length, s (PIMS: 10 s)
    sample_rate_hz : the sampling rate, Hz (default: from ``timepts``; measured files give it)
    """
    a = _as_axes(accel)
    fs = float(sample_rate_hz) if sample_rate_hz is not None else _sample_rate(timepts)
    t = np.asarray(timepts, dtype=float)
    if a.shape[1] != t.size:
        raise InputError("timepts and accel do not match", where="accel")
    if not window_s > 0:
        raise InputError("window must be positive", where="window_s")
    dt = 1.0 / fs
    # PIMS: int(np.ceil(sec / dt)); a rate taken from rounded times must not turn an exact
    # 1000.0000000001 into 1001, so a ratio within 1e-9 of an integer counts as that integer
    ratio = window_s / dt
    nt = max(1, int(np.ceil(ratio - 1e-9 * ratio)))
    b = a - a.mean(axis=1, keepdims=True)
    nblk = a.shape[1] // nt
    blocks = b[:, : nblk * nt].reshape(a.shape[0], nblk, nt)
    dv = np.trapezoid(blocks, dx=dt, axis=2) if nblk else np.zeros((a.shape[0], 0))
    return IntegratedBlocks(
        window_s=float(window_s),
        block_samples=nt,
        t_start=t[: nblk * nt : nt] if nblk else np.zeros(0),
        delta_v=dv,
        max_mps=np.max(np.abs(dv), axis=1) if nblk else np.zeros(a.shape[0]),
        max_magnitude_mps=float(np.max(np.linalg.norm(dv, axis=0))) if nblk else 0.0,
    )


# ------------------------------------------------------------------------------ assessment


def assess(
    timepts: np.ndarray,
    accel: np.ndarray,
    requirement: Requirement | str | None = None,
    *,
    axes: tuple[str, ...] = ("x", "y", "z"),
    psd_method: str = "periodogram",
    segment_s: float | None = None,
    window_s: float = 10.0,
    transient: TransientCriteria | str | None = "iss",
    transient_basis: str = "sliding",
    cutoff_hz: float | None = None,
    sample_rate_hz: float | None = None,
    min_bins: float = MIN_BINS,
    min_time_bandwidth: float = MIN_TIME_BANDWIDTH,
) -> Assessment:
    """Assess an acceleration history against a requirement (default: ``iss``, PIMS's table).

    Parameters
    ----------
    timepts : (nt,) uniformly spaced times, s
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    requirement : a :class:`Requirement` or its name
        (:func:`~microg.environment.requirements.requirement`); default ``iss``
    axes : names of the rows of ``accel``
    psd_method, segment_s : see :func:`acceleration_psd`
    window_s : window of the integrated accelerations, s (PIMS: 10 s)
    transient : transient criteria set (name or object; None: none judged)
    transient_basis : ``sliding`` (predictions: raw peak per axis, the sliding integral) or
        ``pims`` (measurements: peak of the demeaned record, PIMS's block integral)
    cutoff_hz : anti-alias cutoff of measured data, Hz (bands above it are unresolved)
    sample_rate_hz : exact sampling rate, Hz, when known (PIMS's block length uses it)
    min_bins, min_time_bandwidth : the resolution rule (see :func:`band_rms`)
    """
    a = _as_axes(accel)
    t = np.asarray(timepts, dtype=float)
    if a.shape[1] != t.size:
        raise InputError(
            f"timepts has {t.size} samples, accel {a.shape[1]}",
            where="accel",
            fix="give one acceleration sample per time",
        )
    if a.shape[1] > MAX_SAMPLES:
        raise InputError(
            f"{a.shape[1]:,} samples is more than {MAX_SAMPLES:,}",
            where="accel",
            fix="assess the record in shorter pieces (microg.environment.intervals)",
        )
    _check_finite(a)
    if transient_basis not in ("sliding", "pims"):
        raise InputError(
            f"unknown transient basis {transient_basis!r}",
            where="transient_basis",
            fix="use sliding or pims",
        )
    if len(axes) >= a.shape[0]:
        axes = tuple(axes)[: a.shape[0]]
    else:
        axes = tuple(f"axis{i}" for i in range(a.shape[0]))
    req = requirement_by_name(requirement if requirement is not None else "iss")
    spec = acceleration_psd(t, a, method=psd_method, segment_s=segment_s)
    dt = 1.0 / (2.0 * spec.nyquist_hz)
    br = band_rms(
        spec,
        req.bands,
        min_bins=min_bins,
        min_time_bandwidth=min_time_bandwidth,
        cutoff_hz=cutoff_hz,
    )
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
        n_bins=br.n_bins,
        reasons=br.reasons,
    )
    warnings: list[str] = []
    mag = np.linalg.norm(a, axis=0)
    peak = float(mag.max()) / G0
    judged = br.resolved
    worst = None
    if np.any(judged):
        m = np.where(judged[None, :], margin, np.inf)
        ax, band = np.unravel_index(int(np.argmin(m)), m.shape)
        worst = WorstBand(
            center_hz=float(third.center_hz[band]),
            axis=axes[ax],
            rms_g=float(rms_g[ax, band]),
            limit_g=float(limit[band]),
            margin=float(margin[ax, band]),
            lower_hz=float(third.lower_hz[band]),
            upper_hz=float(third.upper_hz[band]),
        )
        complies = bool(np.all(rms_g[:, judged] <= limit[judged]))
    else:
        complies = False
        warnings.append(
            f"no band of {req.name} is resolved by this record ({a.shape[1] * dt:.4g} s at "
            f"dt = {dt:.3g} s): the vibratory requirement cannot be judged, so it is not "
            "called compliant; lengthen the record"
        )
    over = ~judged & np.any(rms_g > limit, axis=0)
    for i in np.nonzero(over)[0]:
        warnings.append(
            f"band {third.center_hz[i]:.4g} Hz is not resolved ({br.reasons[i]}), and its band "
            f"RMS estimate {rms_g[:, i].max():.3g} g exceeds its limit {limit[i]:.3g} g: "
            "compliance cannot be shown, so the verdict is not a pass; lengthen the record to "
            "judge the band"
        )
    if np.any(over):
        complies = False
    if req.peak_limit_g is not None:
        complies = complies and peak <= req.peak_limit_g
    sliding = integrated_acceleration(t, a, window_s)
    pims = integrated_acceleration_pims(t, a, window_s, sample_rate_hz=sample_rate_hz)
    pims_out: IntegratedBlocks | None = pims
    if pims.n_blocks == 0:
        pims_out = None
        warnings.append(
            f"record shorter than one {window_s:g}-s block: no PIMS integrated acceleration"
        )
    mean = a.mean(axis=1)
    verdict = None
    if transient is not None:
        crit = transient_criteria(transient)
        demeaned = a - mean[:, None]
        if transient_basis == "sliding":
            peak_axis, peak_mag = np.max(np.abs(a), axis=1), float(mag.max())
        else:
            peak_axis = np.max(np.abs(demeaned), axis=1)
            peak_mag = float(np.max(np.linalg.norm(demeaned, axis=0)))
        integ: dict[float, tuple[np.ndarray, float]] = {}
        for w in crit.windows_s:
            if transient_basis == "sliding":
                s = sliding if w == window_s else integrated_acceleration(t, a, w)
                integ[w] = (s.max_mps, s.max_magnitude_mps)
            else:
                p = (
                    pims
                    if w == window_s
                    else integrated_acceleration_pims(t, a, w, sample_rate_hz=sample_rate_hz)
                )
                integ[w] = (p.max_mps, p.max_magnitude_mps)
        verdict = judge_transient(
            crit,
            peak_axis=peak_axis,
            peak_magnitude=peak_mag,
            integrated=integ,
            basis=transient_basis,
        )
        warnings.extend(verdict.warnings())
        complies = complies and verdict.complies_verified
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
        mean_accel_g_axis=mean / G0,
        integrated_sliding=sliding,
        integrated_pims=pims_out,
        transient=verdict,
        transient_basis=transient_basis,
        requirement_source=req.source,
        record_s=a.shape[1] * dt,
        dt_s=dt,
        cutoff_hz=cutoff_hz,
        warnings=tuple(warnings),
        spectrum=spec,
    )
