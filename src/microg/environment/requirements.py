"""Acceleration requirements: frequency bands and band-RMS limits (ISS, SSP 41000, the report's).

Every requirement is data with its source.  :class:`BandTable` and
:func:`third_octave_bands` define the bands; :class:`Requirement` holds a limit per band
(and optionally a peak limit); :func:`requirement` looks one up by name.

* ``iss`` (default): NASA PIMS's table of 46 one-third-octave bands exactly as PIMS codes it
  (``get_oto_iss_req_steps`` in ``otorunhist/main.py`` of github.com/baluneboy/pims; see
  ``microg/data/iss_requirement.csv`` for the commit).  It is not one formula: bands 1-10 and
  39-46 have base-2 centres, bands 11-38 base-10 (IEC 61260) edges with nominal centres, and
  the limits are 1.8 micro-g, 18 x nominal centre micro-g, 1.8 milli-g.
* ``ssp41000``: the continuous SSP 41000 curve (1.6 micro-g for f <= 0.1 Hz, 16 f micro-g for
  0.1 < f <= 100 Hz, 1600 micro-g above), evaluated at each band's centre on PIMS's bands.
* ``flat`` (``report-1e-5g``): the seed report's 1e-5 g, as peak and flat band limit.
"""

from __future__ import annotations

import csv
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.errors import InputError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "BandTable",
    "Requirement",
    "third_octave_bands",
    "iss_requirement",
    "ssp41000_limit_g",
    "ssp41000_requirement",
    "report_flat_requirement",
    "requirement",
    "requirement_names",
]


@dataclass(frozen=True)
class BandTable:
    """Frequency bands: centres and edges, Hz, each of shape (nb,)."""

    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready bands: centres and edges, Hz."""
        return {
            "center_hz": [float(v) for v in self.center_hz],
            "lower_hz": [float(v) for v in self.lower_hz],
            "upper_hz": [float(v) for v in self.upper_hz],
        }

    def to_xarray(self) -> Any:
        """The bands as an ``xarray.Dataset`` on dim ``center_hz``.

        The edges are coordinates, and ``width_hz`` (upper - lower) is the data variable.
        """
        import xarray as xr

        return xr.Dataset(
            {"width_hz": ("center_hz", self.upper_hz - self.lower_hz, {"units": "Hz"})},
            coords={
                "center_hz": ("center_hz", self.center_hz, {"units": "Hz"}),
                "lower_hz": ("center_hz", self.lower_hz, {"units": "Hz"}),
                "upper_hz": ("center_hz", self.upper_hz, {"units": "Hz"}),
            },
        )


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

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready requirement: name, source, bands (Hz), limit per band (g), peak limit."""
        return {
            "name": self.name,
            "source": self.source,
            **self.bands.to_dict(),
            "limit_g": [float(v) for v in self.limit_g],
            "peak_limit_g": self.peak_limit_g,
        }

    def to_xarray(self) -> Any:
        """The limit per band as an ``xarray.Dataset`` (dim ``center_hz``; units in attrs)."""
        ds = self.bands.to_xarray()
        ds["limit_g"] = ("center_hz", np.asarray(self.limit_g, float), {"units": "g"})
        ds.attrs.update(name=self.name, source=self.source)
        if self.peak_limit_g is not None:
            ds.attrs["peak_limit_g"] = self.peak_limit_g
        return ds

    def plot(self, *, title: str = "", ax: Any = None) -> Figure:
        """The limit as steps on the band edges (``plotting.environment.plot_requirement``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_requirement

        return plot_requirement(self, title=title, ax=ax)


def third_octave_bands(fmin_hz: float = 0.01, fmax_hz: float = 316.3, base: int = 10) -> BandTable:
    """Standard 1/3-octave bands whose centres lie in [fmin_hz, fmax_hz].

    Parameters
    ----------
    fmin_hz, fmax_hz : range of the band centres, Hz
    base : 10 (centres 10^(n/10), edges centre * 10^(+-1/20), IEC 61260 exact) or 2 (centres
        2^(k/3), edges centre * 2^(+-1/6))
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
    """ISS vibratory requirement as NASA PIMS codes it (``data/iss_requirement.csv``).

    46 one-third-octave bands, 0.0088-362 Hz, limit per axis in g RMS; source:
    ``get_oto_iss_req_steps`` in ``otorunhist/main.py`` of github.com/baluneboy/pims.
    """
    text = resources.files("microg").joinpath("data/iss_requirement.csv").read_text("utf-8")
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    rows = list(csv.DictReader(lines))
    col = {k: np.array([float(r[k]) for r in rows]) for k in rows[0] if k != "band"}
    return Requirement(
        name="iss",
        bands=BandTable(col["center_hz"], col["lower_hz"], col["upper_hz"]),
        limit_g=col["limit_g"],
        source="NASA PIMS, get_oto_iss_req_steps() in otorunhist/main.py of "
        "github.com/baluneboy/pims (ISS Microgravity Control Plan steps); "
        "microg/data/iss_requirement.csv",
    )


def ssp41000_limit_g(freq_hz: np.ndarray | float) -> np.ndarray:
    """The continuous SSP 41000 vibratory curve, g RMS per 1/3-octave band.

    ``1.6e-6`` for f <= 0.1 Hz, ``16e-6 f`` for 0.1 < f <= 100 Hz, ``1.6e-3`` above
    (``f`` = band centre frequency, Hz).

    Parameters
    ----------
    freq_hz : band centre frequency, Hz
    """
    f = np.asarray(freq_hz, dtype=float)
    return np.where(f <= 0.1, 1.6e-6, np.where(f <= 100.0, 16e-6 * f, 1.6e-3))


@lru_cache(maxsize=1)
def ssp41000_requirement() -> Requirement:
    """The SSP 41000 curve, evaluated at the band centres of PIMS's 46 bands (name ``ssp41000``).

    Stricter than PIMS's steps by 1.8/1.6 = 1.125 (PIMS's steps are the curve near each
    band's upper edge, rounded); the bands are the same, so only the limits differ.
    """
    bands = iss_requirement().bands
    return Requirement(
        name="ssp41000",
        bands=bands,
        limit_g=ssp41000_limit_g(bands.center_hz),
        source="SSP 41000 vibratory curve (1.6 ug to 0.1 Hz, 16 f ug to 100 Hz, 1600 ug "
        "above), evaluated at the band centres of PIMS's 1/3-octave table "
        "(get_oto_iss_req_steps, otorunhist/main.py, github.com/baluneboy/pims)",
    )


def report_flat_requirement(level_g: float = 1e-5, bands: BandTable | None = None) -> Requirement:
    """The seed report's criterion: acceleration below ``level_g`` (1e-5 g) at the experiment.

    Applied both as the peak limit and as a flat band-RMS limit on every band (default: the
    base-10 1/3-octave bands with centres 0.01-316 Hz).

    Parameters
    ----------
    level_g : the limit, g
    bands : bands of the flat limit
    """
    bands = bands or third_octave_bands(0.01, 316.3, base=10)
    return Requirement(
        name="report-1e-5g",
        bands=bands,
        limit_g=np.full(bands.center_hz.shape, level_g),
        source="seed report, Introduction: experiments require acceleration below 1e-5 g",
        peak_limit_g=level_g,
    )


_NAMES: dict[str, Callable[[], Requirement]] = {
    "iss": iss_requirement,
    "ssp41000": ssp41000_requirement,
    "flat": report_flat_requirement,
    "report-1e-5g": report_flat_requirement,
}


def requirement_names() -> tuple[str, ...]:
    """Names :func:`requirement` accepts."""
    return tuple(_NAMES)


def requirement(name: str | Requirement) -> Requirement:
    """The requirement called ``name`` (``iss``, ``ssp41000``, ``flat`` = ``report-1e-5g``).

    Parameters
    ----------
    name : a name of :func:`requirement_names`, or a :class:`Requirement` (returned as is)
    """
    if isinstance(name, Requirement):
        return name
    key = str(name).strip().lower()
    if key not in _NAMES:
        raise InputError(
            f"unknown requirement {name!r}",
            where="requirement",
            fix=f"use one of: {', '.join(_NAMES)}",
        )
    return _NAMES[key]()
