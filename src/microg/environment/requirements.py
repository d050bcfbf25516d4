"""Acceleration requirements: frequency bands and band-RMS limits (ISS, the seed report's).

Every requirement is data with its source.  :class:`BandTable` and
:func:`third_octave_bands` define the bands; :class:`Requirement` holds a limit per band
(and optionally a peak limit).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np

from microg.errors import InputError

__all__ = [
    "BandTable",
    "Requirement",
    "third_octave_bands",
    "iss_requirement",
    "report_flat_requirement",
]


@dataclass(frozen=True)
class BandTable:
    """Frequency bands: centres and edges, Hz, each of shape (nb,)."""

    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray


@dataclass(frozen=True)
class Requirement:
    """A band-RMS acceleration limit, optionally with a peak limit.

    Attributes
    ----------
    name : short name, e.g. ``iss``
    bands : the 1/3-octave bands of the limit
    limit_g : (nb,) band-RMS limit per axis, g
    source : citation
    peak_limit_g : optional limit on the peak acceleration (vector magnitude), g
    """

    name: str
    bands: BandTable
    limit_g: np.ndarray
    source: str
    peak_limit_g: float | None = None


def third_octave_bands(fmin_hz: float = 0.01, fmax_hz: float = 316.3, base: int = 10) -> BandTable:
    """Standard 1/3-octave bands whose centres lie in [fmin_hz, fmax_hz].

    Parameters
    ----------
    fmin_hz, fmax_hz : range of the band centres, Hz
    base : 10 (centres 10^(n/10), edges centre * 10^(+-1/20)) or 2 (centres 2^(k/3), edges
        centre * 2^(+-1/6), the table of the ISS requirement)
    """
    if not 0 < fmin_hz <= fmax_hz:
        raise InputError("need 0 < fmin_hz <= fmax_hz", where="third_octave_bands")
    if base == 10:
        n = np.arange(
            np.ceil(10 * np.log10(fmin_hz) - 1e-9), np.floor(10 * np.log10(fmax_hz) + 1e-9) + 1
        )
        center = 10.0 ** (n / 10)
        half = 10.0 ** (1 / 20)
    elif base == 2:
        k = np.arange(
            np.ceil(3 * np.log2(fmin_hz) - 1e-9), np.floor(3 * np.log2(fmax_hz) + 1e-9) + 1
        )
        center = 2.0 ** (k / 3)
        half = 2.0 ** (1 / 6)
    else:
        raise InputError("base must be 10 or 2", where="third_octave_bands")
    return BandTable(center_hz=center, lower_hz=center / half, upper_hz=center * half)


@lru_cache(maxsize=1)
def iss_requirement() -> Requirement:
    """ISS vibratory requirement, 1/3-octave band RMS per axis (``data/iss_requirement.csv``)."""
    text = resources.files("microg").joinpath("data/iss_requirement.csv").read_text("utf-8")
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    rows = list(csv.DictReader(lines))
    col = {k: np.array([float(r[k]) for r in rows]) for k in rows[0] if k != "band"}
    return Requirement(
        name="iss",
        bands=BandTable(col["center_hz"], col["lower_hz"], col["upper_hz"]),
        limit_g=col["limit_ug"] * 1e-6,
        source="ISS vibratory requirement (SSP 41000 curve as coded by NASA PIMS); "
        "see microg/data/iss_requirement.csv",
    )


def report_flat_requirement(level_g: float = 1e-5, bands: BandTable | None = None) -> Requirement:
    """The seed report's criterion: acceleration below ``level_g`` (1e-5 g) at the experiment.

    Applied both as the peak limit and as a flat band-RMS limit on every band (default: the
    base-10 1/3-octave bands with centres 0.01-316 Hz).
    """
    bands = bands or third_octave_bands(0.01, 316.3, base=10)
    return Requirement(
        name="report-1e-5g",
        bands=bands,
        limit_g=np.full(bands.center_hz.shape, level_g),
        source="seed report, Introduction: experiments require acceleration below 1e-5 g",
        peak_limit_g=level_g,
    )
