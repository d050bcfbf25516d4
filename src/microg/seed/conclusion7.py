"""The report's conclusion 7 and Figure 9 recomputed: the laboratory and the fundamental's node.

Conclusion 7 of the seed report (Section 5): removing the orbiter moves the node of the
fundamental X-Z bending mode next to the laboratory (z = -55 ft), so the lab's acceleration
from a crew push-off falls "by about 3 orders".  This module recomputes it on the shipped
models ``ioc`` and ``ioc-no-orbiter`` with the report's own model (X-Z plane, one assumed
function per beam), through the location stage (:func:`microg.location.pipeline.locate`'s
pipeline), and compares with the report's printed Table 4 ratio
(``data/_seed_printed.toml``).  ``docs/locate.md`` states what holds and what does not.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from microg.defaults import PRESETS
from microg.dynamics.crew import CrewPushoff
from microg.location.mapping import AccelerationMap, acceleration_map, best_location
from microg.location.peaks import elastic_modes
from microg.location.pipeline import location_structure
from microg.location.site import point_peak
from microg.models.station import Station
from microg.units import G0

__all__ = ["Conclusion7", "Conclusion7Case", "conclusion7", "conclusion7_case"]


@dataclass(frozen=True)
class Conclusion7Case:
    """One orbiter case of the report's conclusion 7 recomputed (X-Z plane, Ritz).

    Attributes
    ----------
    model : str
    body : str
        The body where laboratories go.
    total_mass : float
        kg.
    cm_z : float
        Centre of mass z, m.
    lab_z : float
        Laboratory (experiment and crew) z, m.
    lab_to_cm : float
        |lab_z - cm_z|, m.
    omega : ndarray (k,)
        Elastic frequencies, rad/s.
    lab_per_mode : ndarray (k,)
        Eq. 3.1 at the lab per elastic mode, m/s^2.
    lab_elastic_peak : float
        Peak of the elastic modal sum at the lab over the window, m/s^2.
    lab_total_peak : float
        The same with the rigid-body modes, m/s^2.
    lab_rigid_peak : float
        The rigid-body modes' peak at the lab (translation and rotation), m/s^2.
    rigid_translation : float
        f0 / total mass, m/s^2 (the same everywhere).
    body_nodes_z : ndarray
        z of the fundamental's nodes on the body, m.
    best_z : float
        z of the quietest body sample (elastic measure), m.
    best_elastic_peak : float
        Its elastic peak, m/s^2.
    amap : AccelerationMap
    """

    model: str
    body: str
    total_mass: float
    cm_z: float
    lab_z: float
    lab_to_cm: float
    omega: np.ndarray
    lab_per_mode: np.ndarray
    lab_elastic_peak: float
    lab_total_peak: float
    lab_rigid_peak: float
    rigid_translation: float
    body_nodes_z: np.ndarray
    best_z: float
    best_elastic_peak: float
    amap: AccelerationMap = dataclasses.field(repr=False)

    def to_dict(self) -> dict:
        """JSON-ready values, accelerations in g, lengths in m."""
        g = 1.0 / G0
        return {
            "model": self.model,
            "body": self.body,
            "total_mass_kg": self.total_mass,
            "cm_z_m": self.cm_z,
            "lab_z_m": self.lab_z,
            "lab_to_cm_m": self.lab_to_cm,
            "omega": [float(w) for w in self.omega],
            "lab_per_mode_g": [float(a * g) for a in self.lab_per_mode],
            "lab_elastic_peak_g": self.lab_elastic_peak * g,
            "lab_total_peak_g": self.lab_total_peak * g,
            "lab_rigid_peak_g": self.lab_rigid_peak * g,
            "rigid_translation_g": self.rigid_translation * g,
            "body_nodes_z_m": [float(z) for z in self.body_nodes_z],
            "best_z_m": self.best_z,
            "best_elastic_peak_g": self.best_elastic_peak * g,
        }


@dataclass(frozen=True)
class Conclusion7:
    """Conclusion 7 / Figure 9 recomputed for the IOC with and without the orbiter.

    Attributes
    ----------
    orbiter, no_orbiter : Conclusion7Case
    ratio_mode1 : float
        Fundamental's Eq. 3.1 at the lab, orbiter / no orbiter (the report: 1.14e-5/1.44e-8).
    ratio_elastic : float
        Elastic peak at the lab, orbiter / no orbiter.
    ratio_total : float
        Total peak (rigid-body modes included) at the lab, orbiter / no orbiter.
    printed_ratio_mode1 : float
        The report's Table 4 ratio for the first bending mode.
    moved : float
        Increase of the lab's distance from the centre of mass without the orbiter, m
        (the report: 59.9 ft).
    """

    orbiter: Conclusion7Case
    no_orbiter: Conclusion7Case
    ratio_mode1: float
    ratio_elastic: float
    ratio_total: float
    printed_ratio_mode1: float
    moved: float

    def to_dict(self) -> dict:
        """JSON-ready values of both cases and the ratios."""
        return {
            "orbiter": self.orbiter.to_dict(),
            "no_orbiter": self.no_orbiter.to_dict(),
            "ratio_mode1": self.ratio_mode1,
            "ratio_elastic": self.ratio_elastic,
            "ratio_total": self.ratio_total,
            "printed_ratio_mode1": self.printed_ratio_mode1,
            "moved_m": self.moved,
        }

    def plot(self, ax: Any = None) -> Any:
        """Figure 9 recomputed (:func:`microg.plotting.location.plot_conclusion7`).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.location import plot_conclusion7

        return plot_conclusion7(self, ax=ax)


def conclusion7_case(
    station: Station, crew: CrewPushoff, point: str = "crew", body: str = "main"
) -> Conclusion7Case:
    """One case: the map and the lab's peaks, X-Z plane, one function per beam, push along x.

    Parameters
    ----------
    station : Station
    crew : CrewPushoff
        N.
    point : str
        Named point of both the crew force and the experiment.
    body : str
        The body where laboratories go.
    """
    from microg.dynamics.modes import solve_modes

    report = PRESETS["report"]
    structure, d = location_structure(
        station, report["method"], report["plane"], report["functions"], "x"
    )
    modes = solve_modes(structure)
    amap = acceleration_map(structure, modes, point, d, crew, zeta=report["damping"])
    site = point_peak(structure, modes, point, point, d, crew, zeta=report["damping"])
    el = elastic_modes(modes)
    total, cm, _ = station.mass_properties()
    lab_z = float(structure.point(point).position[2])
    best = best_location(amap, component=body, measure="elastic")
    nodes = np.array([n.position[2] for n in amap.nodes if n.component == body])
    return Conclusion7Case(
        model=station.name,
        body=body,
        total_mass=total,
        cm_z=float(cm[2]),
        lab_z=lab_z,
        lab_to_cm=abs(lab_z - float(cm[2])),
        omega=modes.omega[el],
        lab_per_mode=site.per_mode_mps2[el],
        lab_elastic_peak=site.elastic_mps2,
        lab_total_peak=site.total_mps2,
        lab_rigid_peak=site.rigid_mps2,
        rigid_translation=abs(crew.f0) / total,
        body_nodes_z=nodes,
        best_z=float(best.position[2]),
        best_elastic_peak=best.peak,
        amap=amap,
    )


def conclusion7(
    crew: CrewPushoff | None = None,
    stations: tuple[Station, Station] | None = None,
    *,
    point: str = "crew",
    body: str = "main",
) -> Conclusion7:
    """Recompute the report's conclusion 7 and Figure 9 (X-Z plane, one function per beam).

    The crew force and the experiment are both at ``point`` (the shipped models' ``crew``,
    z = -55 ft); the push-off is along x.

    Parameters
    ----------
    crew : CrewPushoff, optional
        Default: the report's 25 lbf, 1 s, 13 s, 14 s.
    stations : (with orbiter, without), optional
        Default: the shipped ``ioc`` and ``ioc-no-orbiter``.
    point : str
        Named point of crew and experiment.
    body : str
        The body where laboratories go (for nodes and the best location).
    """
    from microg.dynamics.forces import REPORT_F0_N
    from microg.models.toml import load_station
    from microg.seed.ioc import printed

    crew = crew or CrewPushoff(REPORT_F0_N)
    if stations is None:
        stations = (load_station("ioc"), load_station("ioc-no-orbiter"))
    a = conclusion7_case(stations[0], crew, point, body)
    b = conclusion7_case(stations[1], crew, point, body)
    t4 = printed()["table4"]
    pr = t4["xz_orbiter"]["bending_accel_g"][0] / t4["xz_no_orbiter"]["bending_accel_g"][0]
    return Conclusion7(
        orbiter=a,
        no_orbiter=b,
        ratio_mode1=float(a.lab_per_mode[0] / b.lab_per_mode[0]),
        ratio_elastic=a.lab_elastic_peak / b.lab_elastic_peak,
        ratio_total=a.lab_total_peak / b.lab_total_peak,
        printed_ratio_mode1=float(pr),
        moved=b.lab_to_cm - a.lab_to_cm,
    )
