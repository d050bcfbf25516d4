"""Disturbance allocation (the inverse problem): the largest force spectrum a new source may emit.

For a site (an observed point), a location and a direction of a new source, and the sources
already there, :func:`allocate` gives the largest force RMS per band of the requirement such
that the site still complies in every band and every axis.

Assumptions (stated in the result):

* the new source is independent of the existing ones (its mean square adds: RSS);
* its spectrum is flat within each band of the requirement and its power in a band stays in
  that band (the bands' flat PSDs ``F_b^2 / (upper_b - lower_b)``), so each band is allocated
  on its own;
* per band ``b`` and axis ``a``: ``F_b^2 <= (limit_b^2 - MS_existing[a, b]) / avg|H_a|^2_b``
  with ``avg|H_a|^2_b = int_b |H_a(f)|^2 df / (upper_b - lower_b)`` the band-averaged squared
  acceleration FRF per newton (integrated exactly as in the forward path), and the allocation
  is the minimum over the axes;
* a band the site already exceeds gets 0 N; a band the new source cannot reach at all (zero
  FRF) is unlimited (``inf``, ``null`` in JSON).

A source at the allocated level, assessed by the forward path, makes every allocated band's
worst-axis margin exactly 1 (tested).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from microg import defaults
from microg._json import finite_list, json_numbers
from microg._vectors import AXIS_NAMES, parse_direction
from microg.dynamics.frequency import BandForceSpectrum, Load, band_response, damping_ratios
from microg.dynamics.modes import Modes
from microg.environment.requirements import Requirement, iss_requirement
from microg.environment.sources import BandLevels, Source, SourceCatalogue, as_sources
from microg.environment.vibratory import assess_sources
from microg.units import G0

__all__ = ["Allocation", "allocate", "ALLOCATION_ASSUMPTIONS"]

ALLOCATION_ASSUMPTIONS = (
    "the new source is independent of the existing sources (mean squares add); its spectrum "
    "is flat within each requirement band and its power stays in that band; each band is "
    "allocated on its own, to the minimum over the three axes"
)


@dataclass(frozen=True)
class Allocation:
    """Largest force RMS per band for a new source so that a site still complies.

    Attributes
    ----------
    site : observed point
    at, direction : location and unit direction of the new source
    requirement : requirement name
    center_hz, lower_hz, upper_hz, limit_g : (nb,) the requirement's bands and limits
    existing_rms_g : (3, nb) band RMS at the site from the sources already there, g
    frf_g2_per_n2 : (3, nb) band-averaged squared acceleration FRF per newton, g^2/N^2
    allowed_rms_n : (nb,) the allocation, N RMS per band (0: already exceeded; inf: no response)
    governing_axis : (nb,) the axis that sets each band's allocation ("" when unlimited)
    exceeded : (nb,) the existing sources alone exceed the limit there
    assumptions : the allocation's assumptions
    warnings : messages from the forward analysis
    """

    site: str
    at: str
    direction: np.ndarray
    requirement: str
    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray
    limit_g: np.ndarray
    existing_rms_g: np.ndarray
    frf_g2_per_n2: np.ndarray
    allowed_rms_n: np.ndarray
    governing_axis: tuple[str, ...]
    exceeded: np.ndarray
    assumptions: str = ALLOCATION_ASSUMPTIONS
    warnings: tuple[str, ...] = ()

    def as_source(self, name: str = "allocated", *, floor_n: float = 0.0) -> Source:
        """A :class:`Source` emitting exactly the allocation (unlimited bands get ``floor_n``)."""
        rms = np.where(np.isfinite(self.allowed_rms_n), self.allowed_rms_n, floor_n)
        return Source(
            name=name,
            at=self.at,
            direction=self.direction,
            spectrum=BandLevels(self.center_hz, rms),
            source=f"allocation for site {self.site!r} against {self.requirement}",
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: per band the allowed force RMS (N), the governing axis, the inputs."""
        return {
            "site": self.site,
            "at": self.at,
            "direction": [float(v) for v in self.direction],
            "requirement": self.requirement,
            "center_hz": finite_list(self.center_hz),
            "lower_hz": finite_list(self.lower_hz),
            "upper_hz": finite_list(self.upper_hz),
            "limit_g": finite_list(self.limit_g),
            "allowed_rms_n": json_numbers(self.allowed_rms_n),  # "inf": no limit
            "governing_axis": list(self.governing_axis),
            "exceeded": [bool(v) for v in self.exceeded],
            "existing_rms_g_axis": {
                a: finite_list(self.existing_rms_g[k]) for k, a in enumerate(AXIS_NAMES)
            },
            "frf_g2_per_n2_axis": {
                a: finite_list(self.frf_g2_per_n2[k]) for k, a in enumerate(AXIS_NAMES)
            },
            "assumptions": self.assumptions,
            "warnings": list(self.warnings),
        }

    def to_xarray(self) -> Any:
        """xarray.Dataset (axis, band) with units in attrs."""
        import xarray as xr

        return xr.Dataset(
            {
                "allowed_rms_n": (("band",), self.allowed_rms_n, {"units": "N"}),
                "limit_g": (("band",), self.limit_g, {"units": "g"}),
                "existing_rms_g": (("axis", "band"), self.existing_rms_g, {"units": "g"}),
                "frf_g2_per_n2": (("axis", "band"), self.frf_g2_per_n2, {"units": "g^2/N^2"}),
                "exceeded": (("band",), self.exceeded),
            },
            coords={
                "axis": list(AXIS_NAMES),
                "band": np.arange(self.center_hz.size),
                "center_hz": ("band", self.center_hz, {"units": "Hz"}),
                "lower_hz": ("band", self.lower_hz, {"units": "Hz"}),
                "upper_hz": ("band", self.upper_hz, {"units": "Hz"}),
            },
            attrs={
                "site": self.site,
                "at": self.at,
                "requirement": self.requirement,
                "assumptions": self.assumptions,
            },
        )

    def plot(self, ax: Any = None) -> Any:
        """The allowed force RMS per band (log-log); returns a matplotlib Figure.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.frequency import plot_allocation

        return plot_allocation(self, ax=ax)


def allocate(
    modes: Modes,
    site: str,
    at: str,
    direction: Any,
    requirement: Requirement | None = None,
    zeta: float | np.ndarray = defaults.DAMPING,
    existing: SourceCatalogue | Sequence[Source] | None = None,
    *,
    duty_weighted: bool = False,
    workers: int | None = None,
) -> Allocation:
    """Largest force RMS per requirement band a new source at ``at`` may emit (module doc).

    Parameters
    ----------
    modes : Modes of the station
    site : the observed point that must keep complying
    at : point where the new source acts
    direction : its direction (``"x"``, ``"1 0 0"``, 3-vector)
    requirement : band limits (default the ISS requirement)
    zeta : modal damping ratio of the elastic modes, scalar or per mode
    existing : sources already there (catalogue or sequence); None: none
    duty_weighted : scale the existing sources' mean squares by their duty
    workers : threads over bands

    Returns
    -------
    Allocation (N RMS per band).
    """
    req = requirement or iss_requirement()
    d = parse_direction(direction, where="direction")
    z = damping_ratios(modes, zeta)
    bands = req.bands
    nb = bands.center_hz.size
    warnings: list[str] = []
    existing_ms = np.zeros((3, nb))
    srcs = as_sources(existing) if existing is not None else ()
    if any(s.state == "on" for s in srcs):
        prior = assess_sources(
            modes,
            existing if existing is not None else srcs,
            [site],
            req,
            z,
            duty_weighted=duty_weighted,
            workers=workers,
        )
        existing_ms = (prior.rms_g[0] * G0) ** 2
        warnings += list(prior.warnings)
    # band-averaged |H|^2: one unit-RMS flat band per requirement band, each on its own
    loads = [
        Load(
            f"band{b}",
            at,
            d,
            BandForceSpectrum(bands.lower_hz[b : b + 1], bands.upper_hz[b : b + 1], np.ones(1)),
        )
        for b in range(nb)
    ]
    unit = band_response(modes, z, [site], loads, bands.lower_hz, bands.upper_hz, workers=workers)
    idx = np.arange(nb)
    h2 = unit.source_rms_mps2[0][:, idx, idx] ** 2  # (3, nb): (m/s^2)^2 per N^2, band-averaged
    warnings += [w for w in unit.warnings if w not in warnings]
    budget = (np.asarray(req.limit_g, float) * G0) ** 2 - existing_ms  # (3, nb)
    exceeded = np.any(budget < 0, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        per_axis = np.where(h2 > 0, np.maximum(budget, 0.0) / np.where(h2 > 0, h2, 1.0), np.inf)
    k = np.argmin(per_axis, axis=0)
    allowed = np.where(exceeded, 0.0, np.sqrt(per_axis[k, idx]))
    gov = tuple(AXIS_NAMES[int(j)] if np.isfinite(allowed[b]) else "" for b, j in enumerate(k))
    if np.any(exceeded):
        warnings.append(
            f"the existing sources already exceed the limit in {int(exceeded.sum())} band(s) at "
            f"{site!r}: nothing can be allocated there"
        )
    return Allocation(
        site=site,
        at=at,
        direction=d,
        requirement=req.name,
        center_hz=np.asarray(bands.center_hz, float),
        lower_hz=np.asarray(bands.lower_hz, float),
        upper_hz=np.asarray(bands.upper_hz, float),
        limit_g=np.asarray(req.limit_g, float),
        existing_rms_g=np.sqrt(existing_ms) / G0,
        frf_g2_per_n2=h2 / G0**2,
        allowed_rms_n=allowed,
        governing_axis=gov,
        exceeded=exceeded,
        warnings=tuple(warnings),
    )
