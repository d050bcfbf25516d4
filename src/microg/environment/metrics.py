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
* Band RMS: ``sqrt(sum of psd_k * df over the bins in the band)`` (PIMS's band sum): a bin
  belongs wholly to the band its frequency lies in (``lower <= f_k < upper``), so a tone on a
  bin keeps its whole power in one band, and the band mean squares of contiguous bands add up
  exactly to the mean square of the record in their range (Parseval).  Bands wholly above
  Nyquist are left out.
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

The names of the metrics, one concept per module: :mod:`~microg.environment.spectrum` (the
PSD), :mod:`~microg.environment.bands` (band RMS, the resolution rule),
:mod:`~microg.environment.third_octave` (band RMS against limits, the worst band),
:mod:`~microg.environment.integrated` (integrated accelerations),
:mod:`~microg.environment.assessment` (:func:`assess` and its result).  This module gathers
them: ``from microg.environment.metrics import assess`` keeps working.
"""

from __future__ import annotations

from microg._json import json_number
from microg.environment._samples import as_axes as _as_axes  # noqa: F401 - the figures' import
from microg.environment._samples import axis_names
from microg.environment.assessment import MAX_SAMPLES, Assessment, assess
from microg.environment.bands import (
    MIN_BINS,
    MIN_TIME_BANDWIDTH,
    BandRMS,
    band_mean_square,
    band_rms,
    band_weights,
)
from microg.environment.integrated import (
    IntegratedAcceleration,
    IntegratedBlocks,
    integrated_acceleration,
    integrated_acceleration_pims,
)
from microg.environment.spectrum import Spectrum, acceleration_psd
from microg.environment.third_octave import ThirdOctave, WorstBand

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
    "axis_names",
    "json_number",
    "acceleration_psd",
    "band_mean_square",
    "band_rms",
    "band_weights",
    "integrated_acceleration",
    "integrated_acceleration_pims",
    "assess",
]
