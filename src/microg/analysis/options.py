"""The main job's inputs: its defaults (once), the disturbances and the validated options.

Every default of :func:`microg.analyze` and ``microg analyze`` lives here, once
(:data:`DEFAULTS`, SI); :class:`AnalysisOptions` is what :func:`microg.analysis.run_analysis`
takes, with every value in SI.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from microg import defaults
from microg._vectors import parse_direction
from microg.dynamics.forces import ForceHistory
from microg.units import LB

__all__ = [
    "DEFAULTS",
    "DEFAULT_SOURCE_MODES",
    "MAX_SAMPLES",
    "REPORT_LIMIT_G",
    "REQUIREMENT_INTERVAL_S",
    "AnalysisOptions",
    "Disturbance",
]

#: the seed report's criterion: peak acceleration below 1e-5 g (Introduction)
REPORT_LIMIT_G = 1e-5
#: largest number of output samples of one analysis (memory: ~100 bytes per sample and mode)
MAX_SAMPLES = 2_000_000
#: interval over which the requirement's band RMS is stated (PIMS judges 100-s intervals)
REQUIREMENT_INTERVAL_S = 100.0
#: modes solved for a sparse model when vibratory sources are assessed (their bands reach 300 Hz)
DEFAULT_SOURCE_MODES = 300
#: the defaults of :func:`microg.analyze` and ``microg analyze``, SI (from :mod:`microg.defaults`)
DEFAULTS: dict[str, Any] = {
    "force": defaults.FORCE,
    "direction": defaults.DIRECTION,
    "method": defaults.METHOD,
    "plane": defaults.PLANE,
    "damping": defaults.DAMPING,
    "max_freq_hz": defaults.MAX_FREQ_HZ,
    "duration_s": defaults.DURATION_S,
    "dt_s": defaults.DT_S,
    "requirement": defaults.REQUIREMENT,
    "package_mass_kg": 1000.0 * LB,
    "gravity_gradient": False,
}


@dataclass(frozen=True)
class Disturbance:
    """A force history applied at a named point.

    Attributes
    ----------
    force : ForceHistory
        Breakpoints (s, N).
    point : str
        Named point of the model where it acts.
    direction : ndarray (3,)
        Unit vector of the force in the station frame (a CSV force's own direction wins).
    """

    force: ForceHistory
    point: str
    direction: np.ndarray

    @property
    def unit_direction(self) -> np.ndarray:
        """The direction used: the force's own (CSV) direction if it has one, unit length.

        For a vector force (a direction that varies in time) it is the direction at the
        largest force, for display; the response uses every component.
        """
        if self.force.is_vector:
            vec = self.force.components()
            return parse_direction(vec[:, int(np.argmax(np.linalg.norm(vec, axis=0)))], "force")
        d = self.force.direction if self.force.direction is not None else self.direction
        return parse_direction(np.asarray(d, float), "direction")


@dataclass(frozen=True)
class AnalysisOptions:
    """Everything the main job needs besides the model, SI (defaults: :data:`DEFAULTS`).

    Attributes
    ----------
    disturbances : sequence of Disturbance
        Applied together (superposed).
    observe : sequence of str
        Named points to assess.
    method : str
        ``"fem"`` (3-D frame elements) or ``"ritz"`` (assumed modes).
    plane : str
        ``"3d"``, or ``"xz"``/``"yz"`` for the report's planar ``ritz`` model.
    n : int or None
        Elements per beam (fem) or functions per beam (ritz); None: the discretisation's
        default.
    n_modes : int or None
        Modes to solve for sparse models (None: :data:`~microg.dynamics.modes.DEFAULT_N_MODES`).
    zeta : float
        Modal damping ratio of the elastic modes.
    max_freq_hz : float
        Elastic modes up to this frequency enter the response (rigid-body modes always).
    duration_s : float
        Length of the output record, s.
    dt_s : float
        Output sample interval, s.
    requirement : str
        Name of the band requirement (``"iss"`` or ``"flat"``).
    package_mass_kg : float
        Experiment package mass for the isolation advice, kg.
    absorber_mu : float or None
        Absorber mass ratio for the isolation advice (None: spring only).
    isolation : bool
        Advise isolation where a point does not comply.
    gravity_gradient : bool
        Restrain the rigid rotations by the gravity-gradient (libration) stiffness.
    sources : SourceCatalogue or None
        Continuous vibratory sources, assessed in the frequency domain beside (or, with no
        disturbance, instead of) the transient response.
    """

    disturbances: Sequence[Disturbance]
    observe: Sequence[str]
    method: str = DEFAULTS["method"]
    plane: str = DEFAULTS["plane"]
    n: int | None = None
    n_modes: int | None = None
    zeta: float = DEFAULTS["damping"]
    max_freq_hz: float = DEFAULTS["max_freq_hz"]
    duration_s: float = DEFAULTS["duration_s"]
    dt_s: float = DEFAULTS["dt_s"]
    requirement: str = DEFAULTS["requirement"]
    package_mass_kg: float = DEFAULTS["package_mass_kg"]
    absorber_mu: float | None = None
    isolation: bool = True
    gravity_gradient: bool = DEFAULTS["gravity_gradient"]
    sources: Any = None
