"""The assessment of one acceleration record against a requirement: :func:`assess`.

Definitions (see docs/assessment.md): the record's mean (DC) is the quasi-steady part,
reported (``mean_accel_g_axis``) and removed before the spectrum
(:mod:`microg.environment.spectrum`); band RMS and the resolution rule are those of
:mod:`microg.environment.bands`, margins those of :mod:`microg.environment.third_octave`;
the integrated accelerations those of :mod:`microg.environment.integrated`; transient
criteria are judged by :mod:`microg.environment.transient`.  An unresolved band whose
estimate exceeds its limit makes ``complies`` false (compliance cannot be shown), with a
warning naming the record length that would resolve it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._json import json_numbers
from microg.environment._samples import as_axes, check_finite
from microg.environment.bands import MIN_BINS, MIN_TIME_BANDWIDTH, band_rms
from microg.environment.criteria import CriterionVerdict, criterion_verdicts, overall_verdict
from microg.environment.integrated import (
    IntegratedAcceleration,
    IntegratedBlocks,
    integrated_acceleration,
    integrated_acceleration_pims,
)
from microg.environment.requirements import Requirement
from microg.environment.requirements import requirement as requirement_by_name
from microg.environment.spectrum import Spectrum, acceleration_psd
from microg.environment.third_octave import ThirdOctave, WorstBand
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

__all__ = ["MAX_SAMPLES", "Assessment", "assess"]

#: largest record accepted by :func:`assess` (samples per axis; about 0.5 GB of work arrays)
MAX_SAMPLES = 20_000_000


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
    warnings : what makes the verdict shaky (unresolved exceedances, no band resolved, no PIMS
        block, ...); an exceeded criterion is its line in ``criteria``, not a warning
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

    @property
    def criteria(self) -> tuple[CriterionVerdict, ...]:
        """One verdict per criterion: judged, reported only or undecided.

        See :mod:`microg.environment.criteria`; ``complies`` is ``verdict_complies`` of these.
        """
        return criterion_verdicts(self)

    @property
    def verdict(self) -> str:
        """``complies``, ``fails`` or ``undecided``, from :attr:`criteria`.

        ``complies`` exactly when :attr:`complies`; ``undecided`` when no judged criterion
        fails but the record cannot decide one
        (:func:`~microg.environment.criteria.overall_verdict`).
        """
        return overall_verdict(self.criteria)

    # ---------------------------------------------------------------------------- outputs

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (the ``microg analyze --json`` observation layout).

        Keys carry units in their names; an infinite margin is the string ``"inf"``.
        """
        to = self.third_octave
        ax = self.axes

        def per_axis(a: np.ndarray) -> dict[str, float | str | None]:
            return dict(zip(ax, json_numbers(a), strict=True))

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
            "verdict": self.verdict,
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
            "criteria": [c.to_dict() for c in self.criteria],
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

    def plot_interactive(self, kind: str = "third_octave") -> Any:
        """An interactive chart of the assessment (a plotly Figure).

        Parameters
        ----------
        kind : {"third_octave", "psd", "integrated"}
            The bands against the limit (micro-g, judged bands filled), the PSD (g^2/Hz), or
            the integrated acceleration the transient criteria judge (micro-g s: PIMS's blocks
            when ``transient_basis`` is ``pims`` and the record holds one, else sliding).
        """
        from microg.plotting.interactive import bands, histories, spectra

        if kind == "third_octave":
            return bands.bands_chart(
                self.third_octave,
                axes=self.axes,
                title=f"1/3-octave band RMS vs {self.requirement}",
                verdict_range_hz=self.verdict_range_hz,
            )
        if kind == "psd":
            return spectra.psd_chart(self.spectrum, axes=self.axes)
        if kind == "integrated":
            pims = self.transient_basis == "pims" and self.integrated_pims is not None
            integ = self.integrated_pims if pims else self.integrated_sliding
            return histories.integrated_chart(integ, axes=self.axes)  # type: ignore[arg-type]
        raise InputError(
            f"unknown chart {kind!r}", where="kind", fix="use third_octave, psd or integrated"
        )


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
    a = as_axes(accel)
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
    check_finite(a)
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
    if np.any(over):  # one warning for the kind, listing its bands
        listed = "; ".join(
            f"{third.center_hz[i]:.4g} Hz ({rms_g[:, i].max():.3g} g > {limit[i]:.3g} g: "
            f"{br.reasons[i]})"
            for i in np.nonzero(over)[0]
        )
        one = int(over.sum()) == 1
        warnings.append(
            (
                "1 band is not resolved and has a band RMS estimate above its limit"
                if one
                else f"{int(over.sum())} bands are not resolved and have a band RMS estimate "
                "above their limits"
            )
            + f", so compliance cannot be shown and the verdict is undecided: {listed}; "
            f"lengthen the record (or sample faster, for bands at Nyquist) to judge "
            f"{'it' if one else 'them'}"
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
        # an exceeded transient criterion is its criterion's line (``criteria``: judged or
        # reported only, with its source), printed once on the console and the page; it is not
        # repeated in ``warnings``, which hold what makes the verdict shaky
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
