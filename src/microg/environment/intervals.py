"""PIMS-style products of an acceleration record (prediction or measurement), per interval.

NASA's PIMS group judges measured data on consecutive intervals (its one-third-octave files
cover about 10 minutes each; ``otorunhist`` in github.com/baluneboy/pims).  On any uniformly
sampled record this module computes:

* per-interval 1/3-octave band RMS (interval length a parameter, default 100 s), per axis and
  the root sum of squares of x, y, z (PIMS's ``v`` column, ``np.linalg.norm`` over the axes),
  with percentiles over the intervals (default 1, 25, 50, 75, 99, PIMS's) against the
  requirement, and the fraction of intervals over the limit;
* interval minimum, maximum and mean of the raw acceleration (and the RMS of the demeaned one);
* band-limited RMS against time (one band, per interval);
* a spectrogram (Hann window, 50 % overlap);
* cumulative RMS against frequency (from the whole record's spectrum);
* the whole record's PSD, periodogram (boxcar, default) or Welch (Hann) for long stationary
  records.

Conventions are those of :mod:`microg.environment.metrics`: each interval is demeaned before
its spectrum (the mean is the quasi-steady part), band RMS by the bin-sharing rule with the
0-Hz bin in no band, resolution by the same rule on the interval length.  The last, incomplete
interval is dropped (as PIMS drops its incomplete 10-s block).  PIMS takes its percentiles
from running histograms of log10(g RMS) with bins 0.001 wide (0.23 % in RMS); here they are
exact order statistics with linear interpolation between ranks.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._json import json_by_name, json_nested, json_numbers
from microg.environment._samples import as_axes, check_finite, sample_rate
from microg.environment.assessment import MAX_SAMPLES
from microg.environment.bands import MIN_BINS, MIN_TIME_BANDWIDTH, band_rms
from microg.environment.requirements import BandTable, Requirement
from microg.environment.requirements import requirement as requirement_by_name
from microg.environment.spectrum import Spectrum, acceleration_psd
from microg.errors import InputError
from microg.units import G0

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "PIMS_PERCENTILES",
    "MAX_SPECTROGRAM_VALUES",
    "IntervalBandRMS",
    "IntervalStats",
    "BandLimitedRMS",
    "Spectrogram",
    "CumulativeRMS",
    "IntervalAnalysis",
    "percentile_linear",
    "interval_band_rms",
    "interval_products",
]

#: the percentiles PIMS plots against the requirement (otorunhist/main.py)
PIMS_PERCENTILES = (1.0, 25.0, 50.0, 75.0, 99.0)
#: largest spectrogram kept (values over axes, frequencies and times); longer segments beyond
MAX_SPECTROGRAM_VALUES = 6_000_000


def percentile_linear(values: np.ndarray, q: tuple[float, ...], axis: int = 0) -> np.ndarray:
    """Percentiles ``q`` (0-100) along ``axis`` by linear interpolation between order statistics.

    The rank of percentile p among n sorted values is ``p / 100 (n - 1)`` (numpy's default
    ``linear`` method).  Result shape: ``(len(q),) + values.shape without axis``.
    """
    return np.percentile(np.asarray(values, float), q, axis=axis, method="linear")


@dataclass(frozen=True)
class IntervalBandRMS:
    """Per-interval 1/3-octave band RMS against a requirement.

    Attributes
    ----------
    axes : axis names
    interval_s : interval length, s
    t_start_s : (ni,) interval start times, s
    bands : the bands (those starting below Nyquist)
    limit_g : (nb,) limit per axis, g
    requirement : requirement name
    rms_g : (ni, naxes, nb) band RMS per interval and axis, g
    rss_g : (ni, nb) root sum of squares over the axes, g
    resolved : (nb,) bands resolved by one interval (the only ones judged)
    reasons : (nb,) why a band is not resolved
    percentiles : the percentiles, 0-100
    percentile_rms_g : (np, naxes + 1, nb) percentiles over intervals; the last row is the RSS
    exceed_fraction : (naxes, nb) fraction of intervals whose band RMS exceeds the limit
    """

    axes: tuple[str, ...]
    interval_s: float
    t_start_s: np.ndarray
    bands: BandTable
    limit_g: np.ndarray
    requirement: str
    rms_g: np.ndarray
    rss_g: np.ndarray
    resolved: np.ndarray
    reasons: tuple[str, ...]
    percentiles: tuple[float, ...]
    percentile_rms_g: np.ndarray
    exceed_fraction: np.ndarray

    @property
    def rows(self) -> tuple[str, ...]:
        """Names of the rows of :attr:`percentile_rms_g`: the axes, then ``rss``."""
        return (*self.axes, "rss")

    def complies_at(self, percentile: float) -> bool:
        """Every resolved band of every axis has its ``percentile`` within the limit."""
        i = list(self.percentiles).index(percentile)
        p = self.percentile_rms_g[i, : len(self.axes)][:, self.resolved]
        return bool(np.all(p <= self.limit_g[self.resolved]))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (g, Hz, s)."""
        return {
            "requirement": self.requirement,
            "interval_s": self.interval_s,
            "t_start_s": json_numbers(self.t_start_s),
            "center_hz": json_numbers(self.bands.center_hz),
            "lower_hz": json_numbers(self.bands.lower_hz),
            "upper_hz": json_numbers(self.bands.upper_hz),
            "limit_g": json_numbers(self.limit_g),
            "resolved": [bool(v) for v in self.resolved],
            "unresolved_bands": [
                {"center_hz": float(c), "reason": r}
                for c, r in zip(self.bands.center_hz, self.reasons, strict=True)
                if r
            ],
            "percentiles": list(self.percentiles),
            "percentile_rms_g": json_by_name(
                self.rows, np.moveaxis(self.percentile_rms_g, 1, 0)
            ),  # {row: [percentile][band]}
            "exceed_fraction_axis": json_by_name(self.axes, self.exceed_fraction),
            # [interval][band] per axis
            "rms_g_axis": json_by_name(self.axes, np.moveaxis(self.rms_g, 1, 0)),
            "rss_rms_g": json_nested(self.rss_g),
            "complies_at_percentile": {
                str(p): self.complies_at(p) for p in self.percentiles if np.any(self.resolved)
            },
        }

    def to_xarray(self) -> Any:
        """``xarray.Dataset`` with dims interval, axis, center_hz, percentile, row."""
        import xarray as xr

        return xr.Dataset(
            {
                "rms_g": (("interval", "axis", "center_hz"), self.rms_g, {"units": "g"}),
                "rss_g": (("interval", "center_hz"), self.rss_g, {"units": "g"}),
                "percentile_rms_g": (
                    ("percentile", "row", "center_hz"),
                    self.percentile_rms_g,
                    {"units": "g"},
                ),
                "exceed_fraction": (("axis", "center_hz"), self.exceed_fraction, {"units": "1"}),
                "limit_g": ("center_hz", self.limit_g, {"units": "g"}),
                "resolved": ("center_hz", np.asarray(self.resolved, np.int8), {"units": "1"}),
            },
            coords={
                "interval": ("interval", self.t_start_s, {"units": "s", "long_name": "start"}),
                "axis": list(self.axes),
                "row": list(self.rows),
                "center_hz": ("center_hz", self.bands.center_hz, {"units": "Hz"}),
                "lower_hz": ("center_hz", self.bands.lower_hz, {"units": "Hz"}),
                "upper_hz": ("center_hz", self.bands.upper_hz, {"units": "Hz"}),
                "percentile": ("percentile", np.asarray(self.percentiles), {"units": "%"}),
            },
            attrs={"requirement": self.requirement, "interval_s": self.interval_s},
        )

    def plot(self, row: str = "rss", ax: Any = None) -> Figure:
        """Percentiles over intervals against the requirement steps (PIMS's box plot).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.intervals import plot_interval_percentiles

        return plot_interval_percentiles(self, row=row, ax=ax)

    def plot_interactive(self, row: str = "rss") -> Any:
        """The percentiles against the limit as an interactive chart (a plotly Figure)."""
        from microg.plotting.interactive.bands import percentiles_chart

        return percentiles_chart(self, row=row)


@dataclass(frozen=True)
class IntervalStats:
    """Minimum, maximum and mean of the raw acceleration per interval, and the demeaned RMS.

    Attributes
    ----------
    axes : axis names
    t_start_s : (ni,) interval starts, s
    min_g, max_g, mean_g : (ni, naxes) of the raw acceleration, g
    rms_g : (ni, naxes) RMS of the demeaned acceleration, g
    """

    axes: tuple[str, ...]
    t_start_s: np.ndarray
    min_g: np.ndarray
    max_g: np.ndarray
    mean_g: np.ndarray
    rms_g: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (g, s)."""
        return {
            "t_start_s": json_numbers(self.t_start_s),
            "min_g_axis": json_by_name(self.axes, self.min_g.T),
            "max_g_axis": json_by_name(self.axes, self.max_g.T),
            "mean_g_axis": json_by_name(self.axes, self.mean_g.T),
            "rms_g_axis": json_by_name(self.axes, self.rms_g.T),
        }

    def to_xarray(self) -> Any:
        """``xarray.Dataset`` with dims interval, axis."""
        import xarray as xr

        dims = ("interval", "axis")
        return xr.Dataset(
            {
                "min_g": (dims, self.min_g, {"units": "g"}),
                "max_g": (dims, self.max_g, {"units": "g"}),
                "mean_g": (dims, self.mean_g, {"units": "g"}),
                "rms_demeaned_g": (dims, self.rms_g, {"units": "g"}),
            },
            coords={
                "interval": ("interval", self.t_start_s, {"units": "s"}),
                "axis": list(self.axes),
            },
        )

    def plot(self, ax: Any = None) -> Figure:
        """Interval min, max and mean against time.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.intervals import plot_interval_stats

        return plot_interval_stats(self, ax=ax)

    def plot_interactive(self) -> Any:
        """Interval min, max and mean as an interactive chart (a plotly Figure, micro-g)."""
        from microg.plotting.interactive.histories import interval_stats_chart

        return interval_stats_chart(self)


@dataclass(frozen=True)
class BandLimitedRMS:
    """RMS in one frequency band per interval (band-limited RMS against time).

    Attributes
    ----------
    axes : axis names
    band_hz : (lower, upper) of the band, Hz
    t_start_s : (ni,) interval starts, s
    interval_s : interval length, s
    rms_g : (ni, naxes) band RMS, g
    rss_g : (ni,) root sum of squares over the axes, g
    """

    axes: tuple[str, ...]
    band_hz: tuple[float, float]
    t_start_s: np.ndarray
    interval_s: float
    rms_g: np.ndarray
    rss_g: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (g, Hz, s)."""
        return {
            "band_hz": list(self.band_hz),
            "interval_s": self.interval_s,
            "t_start_s": json_numbers(self.t_start_s),
            "rms_g_axis": json_by_name(self.axes, self.rms_g.T),
            "rss_g": json_numbers(self.rss_g),
        }

    def to_xarray(self) -> Any:
        """``xarray.Dataset`` with dims interval, axis."""
        import xarray as xr

        return xr.Dataset(
            {
                "band_rms_g": (("interval", "axis"), self.rms_g, {"units": "g"}),
                "band_rss_g": ("interval", self.rss_g, {"units": "g"}),
            },
            coords={
                "interval": ("interval", self.t_start_s, {"units": "s"}),
                "axis": list(self.axes),
            },
            attrs={"band_lower_hz": self.band_hz[0], "band_upper_hz": self.band_hz[1]},
        )

    def plot(self, ax: Any = None) -> Figure:
        """Band-limited RMS against time.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.intervals import plot_band_limited_rms

        return plot_band_limited_rms(self, ax=ax)

    def plot_interactive(self) -> Any:
        """Band-limited RMS against time as an interactive chart (a plotly Figure, micro-g)."""
        from microg.plotting.interactive.histories import band_limited_chart

        return band_limited_chart(self)


@dataclass(frozen=True)
class Spectrogram:
    """PSD against time and frequency (Hann window, each segment demeaned).

    Attributes
    ----------
    axes : axis names
    freq_hz : (nf,) Hz
    time_s : (nt,) segment centres, s
    psd_g2_per_hz : (naxes, nf, nt) g^2/Hz
    segment_s : segment length, s
    overlap : fraction of a segment shared with the next
    """

    axes: tuple[str, ...]
    freq_hz: np.ndarray
    time_s: np.ndarray
    psd_g2_per_hz: np.ndarray
    segment_s: float
    overlap: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description (the data is in :meth:`to_xarray`)."""
        return {
            "window": "hann",
            "segment_s": self.segment_s,
            "overlap": self.overlap,
            "n_segments": int(self.time_s.size),
            "df_hz": float(self.freq_hz[1] - self.freq_hz[0]) if self.freq_hz.size > 1 else None,
            "max_freq_hz": float(self.freq_hz[-1]) if self.freq_hz.size else None,
        }

    def to_xarray(self) -> Any:
        """``xarray.DataArray`` with dims axis, freq_hz, time_s (g^2/Hz)."""
        import xarray as xr

        return xr.DataArray(
            self.psd_g2_per_hz,
            dims=("axis", "spec_freq_hz", "spec_time_s"),
            coords={
                "axis": list(self.axes),
                "spec_freq_hz": ("spec_freq_hz", self.freq_hz, {"units": "Hz"}),
                "spec_time_s": ("spec_time_s", self.time_s, {"units": "s"}),
            },
            name="spectrogram_g2_per_hz",
            attrs={"units": "g^2/Hz", "window": "hann", "segment_s": self.segment_s},
        )

    def plot(self, axis: str | None = None, ax: Any = None) -> Figure:
        """The spectrogram of one axis (default: the one with the most power).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.intervals import plot_spectrogram

        return plot_spectrogram(self, axis=axis, ax=ax)

    def plot_interactive(self, axis: str | None = None) -> Any:
        """The spectrogram of one axis as an interactive heat map (a plotly Figure)."""
        from microg.plotting.interactive.spectra import spectrogram_chart

        return spectrogram_chart(self, axis=axis)


@dataclass(frozen=True)
class CumulativeRMS:
    """Cumulative RMS against frequency: sqrt of the PSD integrated from 0 to f (0 Hz excluded).

    Attributes
    ----------
    axes : axis names
    freq_hz : (nf,) upper edge of each bin's interval, Hz
    rms_g : (naxes, nf) g
    rss_g : (nf,) root sum of squares over the axes, g
    """

    axes: tuple[str, ...]
    freq_hz: np.ndarray
    rms_g: np.ndarray
    rss_g: np.ndarray

    def at(self, freq_hz: np.ndarray) -> np.ndarray:
        """Cumulative RMS per axis at ``freq_hz`` (interpolated in the mean square), (naxes, n)."""
        f = np.r_[0.0, self.freq_hz]
        ms = np.concatenate([np.zeros((self.rms_g.shape[0], 1)), self.rms_g**2], axis=1)
        return np.sqrt(np.array([np.interp(freq_hz, f, m) for m in ms]))

    def to_dict(self, at_hz: np.ndarray | None = None) -> dict[str, Any]:
        """JSON-ready, at ``at_hz`` (default: the bin edges; a long record has many)."""
        f = self.freq_hz if at_hz is None else np.asarray(at_hz, float)
        r = self.rms_g if at_hz is None else self.at(f)
        return {
            "freq_hz": json_numbers(f),
            "rms_g_axis": json_by_name(self.axes, r),
            "rss_g": json_numbers(np.sqrt(np.sum(r**2, axis=0))),
        }

    def to_xarray(self) -> Any:
        """``xarray.Dataset`` with dims axis, cum_freq_hz."""
        import xarray as xr

        return xr.Dataset(
            {
                "cumulative_rms_g": (("axis", "cum_freq_hz"), self.rms_g, {"units": "g"}),
                "cumulative_rss_g": ("cum_freq_hz", self.rss_g, {"units": "g"}),
            },
            coords={
                "axis": list(self.axes),
                "cum_freq_hz": ("cum_freq_hz", self.freq_hz, {"units": "Hz"}),
            },
        )

    def plot(self, ax: Any = None) -> Figure:
        """Cumulative RMS against frequency.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.intervals import plot_cumulative_rms

        return plot_cumulative_rms(self, ax=ax)

    def plot_interactive(self) -> Any:
        """Cumulative RMS as an interactive chart (a plotly Figure, micro-g)."""
        from microg.plotting.interactive.spectra import cumulative_chart

        return cumulative_chart(self)


@dataclass(frozen=True)
class IntervalAnalysis:
    """Every PIMS-style product of one record (see the module doc).

    Attributes
    ----------
    axes : axis names
    record_s : record length analysed, s
    dt_s : sample interval, s
    interval_s : interval length, s
    dropped_s : the incomplete last interval left out, s
    psd_method : ``periodogram`` or ``welch`` (intervals and whole record)
    bands : per-interval band RMS and percentiles
    stats : interval min/max/mean
    band_limited : band-limited RMS against time
    spectrogram : PSD against time
    cumulative : cumulative RMS against frequency
    spectrum : the whole record's PSD (demeaned)
    warnings : lines for the user
    """

    axes: tuple[str, ...]
    record_s: float
    dt_s: float
    interval_s: float
    dropped_s: float
    psd_method: str
    bands: IntervalBandRMS
    stats: IntervalStats
    band_limited: BandLimitedRMS
    spectrogram: Spectrogram
    cumulative: CumulativeRMS
    spectrum: Spectrum = field(repr=False)
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (g, Hz, s); the spectrogram and full curves are in to_xarray."""
        b = self.bands.bands
        return {
            "record_s": self.record_s,
            "dt_s": self.dt_s,
            "interval_s": self.interval_s,
            "n_intervals": int(self.bands.t_start_s.size),
            "dropped_s": self.dropped_s,
            "psd_method": self.psd_method,
            "third_octave": self.bands.to_dict(),
            "stats": self.stats.to_dict(),
            "band_limited_rms": self.band_limited.to_dict(),
            "spectrogram": self.spectrogram.to_dict(),
            "cumulative_rms": self.cumulative.to_dict(
                at_hz=np.minimum(b.upper_hz, self.spectrum.nyquist_hz)
            ),
            "warnings": list(self.warnings),
        }

    def to_xarray(self) -> Any:
        """All products in one ``xarray.Dataset`` (units in attrs)."""
        import xarray as xr

        ds = xr.merge(
            [
                self.bands.to_xarray(),
                self.stats.to_xarray(),
                self.band_limited.to_xarray(),
                self.cumulative.to_xarray(),
                self.spectrogram.to_xarray().to_dataset(),
            ],
            combine_attrs="drop_conflicts",
        )
        ds["psd_g2_per_hz"] = xr.DataArray(
            self.spectrum.psd / G0**2,
            dims=("axis", "freq_hz"),
            coords={"freq_hz": ("freq_hz", self.spectrum.freq_hz, {"units": "Hz"})},
            attrs={"units": "g^2/Hz", "method": self.psd_method},
        )
        ds.attrs.update(
            {"record_s": self.record_s, "dt_s": self.dt_s, "interval_s": self.interval_s}
        )
        return ds

    def plot(self, row: str = "rss", ax: Any = None) -> Figure:
        """The percentiles of interval band RMS against the requirement (PIMS's summary plot).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        return self.bands.plot(row=row, ax=ax)

    def plot_interactive(self, row: str = "rss") -> Any:
        """The percentiles of interval band RMS as an interactive chart (a plotly Figure)."""
        return self.bands.plot_interactive(row=row)


def _interval_spectrum(
    blocks: np.ndarray, fs: float, method: str, segment_s: float | None
) -> Spectrum:
    """PSD of each interval: blocks (naxes, ni, n) -> Spectrum with psd (naxes * ni, nf)."""
    na, ni, n = blocks.shape
    x = blocks.reshape(na * ni, n)
    t = np.arange(n) / fs
    return acceleration_psd(t, x, method=method, segment_s=segment_s)


def _interval_bands(
    blocks: np.ndarray,
    fs: float,
    req: Requirement,
    axes: tuple[str, ...],
    t0: np.ndarray,
    interval_s: float,
    psd_method: str,
    segment_s: float | None,
    percentiles: tuple[float, ...],
    cutoff_hz: float | None,
) -> tuple[IntervalBandRMS, Spectrum]:
    """Band RMS of each interval (blocks (naxes, ni, per)) against ``req``, and the spectra."""
    naxes, ni, per = blocks.shape
    iseg = None if segment_s is None else min(segment_s, interval_s)
    spec_i = _interval_spectrum(blocks, fs, psd_method, iseg)
    br = band_rms(
        spec_i, req.bands, min_bins=MIN_BINS, min_time_bandwidth=MIN_TIME_BANDWIDTH,
        cutoff_hz=cutoff_hz,
    )  # fmt: skip
    nb = br.bands.center_hz.size
    rms = (br.rms / G0).reshape(naxes, ni, nb).transpose(1, 0, 2)  # (ni, naxes, nb)
    rss = np.sqrt(np.sum(rms**2, axis=1))
    limit = req.limit_g[req.bands.lower_hz < spec_i.nyquist_hz]
    pct = percentile_linear(np.concatenate([rms, rss[:, None, :]], axis=1), percentiles, axis=0)
    exceed = np.mean(rms > limit[None, None, :], axis=0)
    bands = IntervalBandRMS(
        axes=axes,
        interval_s=interval_s,
        t_start_s=t0,
        bands=br.bands,
        limit_g=limit,
        requirement=req.name,
        rms_g=rms,
        rss_g=rss,
        resolved=br.resolved,
        reasons=br.reasons,
        percentiles=tuple(float(p) for p in percentiles),
        percentile_rms_g=pct,
        exceed_fraction=exceed,
    )
    return bands, spec_i


def interval_band_rms(
    timepts: np.ndarray,
    accel: np.ndarray,
    requirement: Requirement | str | None = None,
    *,
    interval_s: float = 100.0,
    axes: tuple[str, ...] = ("x", "y", "z"),
    percentiles: tuple[float, ...] = PIMS_PERCENTILES,
) -> IntervalBandRMS:
    """Band RMS over consecutive intervals only (the first product of :func:`interval_products`).

    Parameters
    ----------
    timepts : (nt,) uniformly spaced times, s
    accel : (naxes, nt) acceleration, m/s^2
    requirement : a :class:`Requirement` or its name (default ``iss``)
    interval_s : interval length, s; the incomplete last interval is left out
    axes : names of the rows of ``accel``
    percentiles : percentiles over intervals, 0-100
    """
    a = as_axes(accel)
    t = np.asarray(timepts, dtype=float)
    fs = sample_rate(t)
    per = int(round(interval_s * fs))
    ni = a.shape[1] // per if per >= 8 else 0
    if ni == 0:
        raise InputError(
            f"the record ({a.shape[1] / fs:.6g} s) is shorter than one {interval_s:g}-s interval",
            where="interval_s",
        )
    req = requirement_by_name(requirement if requirement is not None else "iss")
    blocks = a[:, : ni * per].reshape(a.shape[0], ni, per)
    t0 = t[0] + np.arange(ni) * per / fs
    names = tuple(axes)[: a.shape[0]]
    return _interval_bands(
        blocks, fs, req, names, t0, per / fs, "periodogram", None, percentiles, None
    )[0]


def interval_products(
    timepts: np.ndarray,
    accel: np.ndarray,
    requirement: Requirement | str | None = None,
    *,
    axes: tuple[str, ...] = ("x", "y", "z"),
    interval_s: float = 100.0,
    psd_method: str = "periodogram",
    segment_s: float | None = None,
    percentiles: tuple[float, ...] = PIMS_PERCENTILES,
    band_hz: tuple[float, float] | None = None,
    spectrogram_segment_s: float | None = None,
    cutoff_hz: float | None = None,
    sample_rate_hz: float | None = None,
) -> IntervalAnalysis:
    """PIMS-style products of a uniformly sampled record (see the module doc).

    Parameters
    ----------
    timepts : (nt,) uniformly spaced times, s
    accel : (naxes, nt) acceleration, m/s^2
    requirement : a :class:`Requirement` or its name (default ``iss``)
    axes : names of the rows of ``accel``
    interval_s : interval length, s (PIMS practice: 100 s to 10 min)
    psd_method : ``periodogram`` (boxcar, default) or ``welch`` (Hann, for long stationary
        records), for each interval and the whole record
    segment_s : Welch segment, s (default: the interval for intervals, the record for the
        whole-record spectrum)
    percentiles : percentiles over intervals, 0-100
    band_hz : band of the band-limited RMS, Hz (default: 0.01 Hz to Nyquist or the cutoff)
    spectrogram_segment_s : spectrogram segment, s (default: interval / 8, at least 16 samples)
    cutoff_hz : the data's anti-alias cutoff, Hz (bands above it are not judged)
    sample_rate_hz : exact sampling rate, Hz, when known (else from ``timepts``)
    """
    a = as_axes(accel)
    t = np.asarray(timepts, dtype=float)
    if a.shape[1] != t.size:
        raise InputError(f"timepts has {t.size} samples, accel {a.shape[1]}", where="accel")
    if a.shape[1] > MAX_SAMPLES:
        raise InputError(
            f"{a.shape[1]:,} samples is more than {MAX_SAMPLES:,}",
            where="accel",
            fix="split the record",
        )
    check_finite(a)
    axes = (
        tuple(axes)[: a.shape[0]]
        if len(axes) >= a.shape[0]
        else tuple(f"axis{i}" for i in range(a.shape[0]))
    )
    fs = float(sample_rate_hz) if sample_rate_hz is not None else sample_rate(t)
    dt = 1.0 / fs
    if not (np.isfinite(interval_s) and interval_s > 0):
        raise InputError(f"interval {interval_s!r} s is not positive", where="interval_s")
    per = int(round(interval_s * fs))
    ni = a.shape[1] // per if per >= 8 else 0
    if ni == 0:
        raise InputError(
            f"the record ({a.shape[1] * dt:.6g} s) is shorter than one interval of "
            f"{interval_s:g} s (or the interval holds fewer than 8 samples)",
            where="interval_s",
            fix=f"choose an interval between {8 * dt:.3g} s and {a.shape[1] * dt:.6g} s",
        )
    if any(not 0 <= p <= 100 for p in percentiles) or not percentiles:
        raise InputError("percentiles must lie in 0-100", where="percentiles")
    req = requirement_by_name(requirement if requirement is not None else "iss")
    warnings: list[str] = []
    used = ni * per
    dropped = (a.shape[1] - used) * dt
    if dropped > 0:
        warnings.append(f"the last {dropped:.4g} s (an incomplete interval) are left out")
    blocks = a[:, :used].reshape(a.shape[0], ni, per)
    t0 = t[0] + np.arange(ni) * per * dt

    # -- interval statistics (raw min/max/mean, demeaned RMS)
    mean = blocks.mean(axis=2)
    stats = IntervalStats(
        axes,
        t0,
        min_g=blocks.min(axis=2).T / G0,
        max_g=blocks.max(axis=2).T / G0,
        mean_g=mean.T / G0,
        rms_g=np.sqrt(np.mean((blocks - mean[:, :, None]) ** 2, axis=2)).T / G0,
    )

    # -- per-interval band RMS
    bands, spec_i = _interval_bands(
        blocks, fs, req, axes, t0, per * dt, psd_method, segment_s, percentiles, cutoff_hz
    )
    if not np.any(bands.resolved):
        warnings.append(
            f"no band of {req.name} is resolved by {per * dt:.4g}-s intervals: lengthen --interval"
        )

    # -- band-limited RMS against time
    nyq = fs / 2
    top = nyq if cutoff_hz is None else min(nyq, cutoff_hz)
    lo, hi = band_hz if band_hz is not None else (min(0.01, top / 2), top)
    if not 0 <= lo < hi or lo >= nyq:
        raise InputError(
            f"band {lo:g}-{hi:g} Hz is empty or above Nyquist ({nyq:g} Hz)",
            where="band_hz",
            fix="give 0 <= LO < HI with LO below Nyquist",
        )
    one = BandTable(np.array([np.sqrt(max(lo, 1e-12) * hi)]), np.array([lo]), np.array([hi]))
    bl = band_rms(spec_i, one).rms[:, 0].reshape(a.shape[0], ni).T / G0
    band_limited = BandLimitedRMS(
        axes, (float(lo), float(min(hi, nyq))), t0, per * dt, bl, np.sqrt(np.sum(bl**2, axis=1))
    )

    # -- whole-record spectrum and cumulative RMS
    spec = acceleration_psd(t, a, method=psd_method, segment_s=segment_s)
    power = spec.psd * spec.df_hz
    power[:, 0] = 0.0  # the mean is in no band
    cum = np.sqrt(np.cumsum(power, axis=1)) / G0
    cumulative = CumulativeRMS(
        axes,
        np.minimum(spec.freq_hz + spec.df_hz / 2, spec.nyquist_hz),
        cum,
        np.sqrt(np.sum(cum**2, axis=0)),
    )

    # -- spectrogram
    seg = spectrogram_segment_s if spectrogram_segment_s is not None else per * dt / 8
    nseg = int(min(max(16, round(seg * fs)), a.shape[1]))
    noverlap = nseg // 2
    adjusted = False

    def size(nseg: int, noverlap: int) -> int:
        return a.shape[0] * (nseg // 2 + 1) * max(1, (a.shape[1] - noverlap) // (nseg - noverlap))

    while size(nseg, noverlap) > MAX_SPECTROGRAM_VALUES and nseg < a.shape[1]:
        adjusted = True
        if noverlap:
            noverlap = 0
        else:
            nseg = min(2 * nseg, a.shape[1])
    if adjusted:
        warnings.append(
            f"spectrogram: segments of {nseg * dt:.4g} s with {noverlap / nseg:.0%} overlap "
            f"to stay under {MAX_SPECTROGRAM_VALUES:,} values"
        )
    from scipy import signal  # lazily: scipy.signal costs ~0.5 s to import

    f_s, t_s, sxx = signal.spectrogram(
        a,
        fs=fs,
        window="hann",
        nperseg=nseg,
        noverlap=noverlap,
        detrend="constant",
        scaling="density",
        mode="psd",
        axis=-1,
    )
    spectrogram = Spectrogram(axes, f_s, t[0] + t_s, sxx / G0**2, nseg * dt, noverlap / nseg)
    return IntervalAnalysis(
        axes=axes,
        record_s=a.shape[1] * dt,
        dt_s=dt,
        interval_s=per * dt,
        dropped_s=dropped,
        psd_method=psd_method,
        bands=bands,
        stats=stats,
        band_limited=band_limited,
        spectrogram=spectrogram,
        cumulative=cumulative,
        spectrum=spec,
        warnings=tuple(warnings),
    )
