"""The peaks at one named point from a force at another: the acceleration map at a point.

The same kernel and time grid as :func:`microg.location.mapping.acceleration_map`
(:func:`microg.location.peaks.point_peaks`), at one point only: what the layout optimiser
minimises (:mod:`microg.location.layout`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg._vectors import parse_direction
from microg.dynamics.crew import CrewPushoff
from microg.dynamics.modes import Modes
from microg.errors import InputError
from microg.location.peaks import kept_modes, point_peaks
from microg.structure.structure import Structure
from microg.units import G0

__all__ = ["SitePeak", "point_peak"]


@dataclass(frozen=True)
class SitePeak:
    """The peak acceleration at one named point from a force at another (the map at a point).

    Attributes
    ----------
    point, crew_point : str
        Where the acceleration is taken and where the force acts.
    total_mps2 : float
        Peak over the time window of the modal sum (rigid + elastic), m/s^2.
    elastic_mps2 : float
        The same for the elastic modes alone, m/s^2.
    rigid_mps2 : float
        Peak of the rigid-body modes' sum, exact, m/s^2.
    bound_mps2 : float
        ``rigid_mps2`` plus Eq. 3.1 summed over the other modes: an upper bound, m/s^2.
    per_mode_mps2 : ndarray (m,)
        Eq. 3.1 per mode, m/s^2.
    omega : ndarray (m,)
        rad/s.
    rigid, elastic : ndarray (m,) of bool
    window_s : tuple of float
        Time window of the peaks over time, s.
    """

    point: str
    crew_point: str
    total_mps2: float
    elastic_mps2: float
    rigid_mps2: float
    bound_mps2: float
    per_mode_mps2: np.ndarray
    omega: np.ndarray
    rigid: np.ndarray
    elastic: np.ndarray
    window_s: tuple[float, float]

    def measure(self, name: str = "total") -> float:
        """The peak by name (m/s^2): total, elastic, rigid or bound."""
        table = {
            "total": self.total_mps2,
            "elastic": self.elastic_mps2,
            "rigid": self.rigid_mps2,
            "bound": self.bound_mps2,
        }
        if name not in table:
            raise InputError(
                f"unknown measure {name!r}", where="measure", fix="use total, elastic or bound"
            )
        return table[name]

    def to_dict(self) -> dict:
        """Peaks in g, the elastic modes' Eq. 3.1 terms and frequencies."""
        g = 1.0 / G0
        el = self.elastic
        return {
            "point": self.point,
            "crew_point": self.crew_point,
            "total_g": self.total_mps2 * g,
            "elastic_g": self.elastic_mps2 * g,
            "rigid_g": self.rigid_mps2 * g,
            "bound_g": self.bound_mps2 * g,
            "per_mode_g": [float(v) for v in self.per_mode_mps2[el] * g],
            "omega": [float(v) for v in self.omega[el]],
            "window_s": list(self.window_s),
        }


def point_peak(
    structure: Structure,
    modes: Modes,
    point: str,
    crew_point: str,
    direction: np.ndarray | str,
    crew: CrewPushoff | Any,
    *,
    zeta: float | np.ndarray = 0.0,
    include_rigid: bool = True,
    duration: float | None = None,
) -> SitePeak:
    """The peaks of :func:`acceleration_map` at one named point (same kernel, same grid).

    Parameters
    ----------
    structure : Structure
        Samples are not needed.
    modes : Modes
        Modes of ``structure``.
    point : str
        Named point where the acceleration is taken (the experiment site).
    crew_point : str
        Named point where the force acts.
    direction : ndarray (3,) or str
        Force direction; accelerations along it.
    crew : CrewPushoff or ForceHistory
        N.
    zeta : float or ndarray (m,)
        Modal damping ratios.
    include_rigid : bool
        Include the rigid-body modes.
    duration : float, optional
        Time window, s (default as for the map).
    """
    d = parse_direction(direction, "direction")
    ep = structure.point(point)
    cp = structure.point(crew_point)
    use, omega, rigid, elastic, zeta_arr = kept_modes(modes, zeta, include_rigid)
    phi = np.asarray(modes.phi, float)[:, use]
    resp = ((np.asarray(ep.translation, float) @ phi).T @ d)[None, :]
    gamma = (np.asarray(cp.translation, float) @ phi).T @ d
    pk = point_peaks(
        resp, gamma, omega, rigid, elastic, zeta_arr, crew, duration, with_long_time=False
    )
    return SitePeak(
        point=point,
        crew_point=crew_point,
        total_mps2=float(pk.total[0]),
        elastic_mps2=float(pk.elastic[0]),
        rigid_mps2=float(pk.rigid[0]),
        bound_mps2=float(pk.bound[0]),
        per_mode_mps2=pk.per_mode[:, 0],
        omega=omega,
        rigid=rigid,
        elastic=elastic,
        window_s=(float(pk.grid[0]), float(pk.grid[-1])),
    )
