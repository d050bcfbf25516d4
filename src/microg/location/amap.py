"""Where to put the laboratory: the acceleration map along the structure and its quietest point.

The report's conclusions 6 and 7 (Section 5, Figure 9): the acceleration a crew push-off
causes at a point is, mode by mode (Eq. 2.20b, Eq. 3.1 with the report's crew force Eq. 2.16)::

    a_j(P_e) = |phi_j(P_e)| |phi_j(P_a)| f0 / (M_jj omega_j t1) [A_j]max

so the best place for an experiment is near a node of the fundamental elastic mode
(``phi_1(P_e) = 0``).  The map along the whole sampled structure and its quietest sample
are :mod:`~microg.location.mapping` (:func:`acceleration_map`, :func:`best_location`), the
same quantities at one named point :mod:`~microg.location.site` (:func:`point_peak`, what
the layout optimiser minimises), the whole job from a model :mod:`~microg.location.pipeline`
(:func:`locate`: the one discretisation entry :func:`microg.structure.discretize.discretize`,
then :func:`microg.dynamics.modes.solve_modes`).  This module gathers their names
(``from microg.location.amap import locate`` keeps working).

Definitions used throughout:

* the force acts at the crew point along a unit ``direction``; accelerations are the
  component along the same direction (the report's Eq. 3.1 is the lateral component);
* *elastic* modes are those of :func:`microg.location.peaks.elastic_modes` (the one rule on
  ``Modes``);
* the *rigid* part is the rigid-body modes' acceleration ``c f(t)``, exact and independent
  of the basis of the rigid-body subspace (:func:`microg.location.peaks.rigid_part`);
* the *fundamental* is the lowest elastic mode the force excites; its *nodes* are the points
  of each straight line of the structure where its displacement along ``direction``
  changes sign (:func:`microg.location.sampling.find_nodes`).

The map is computed on the free-free structure (``gravity_gradient=False``): the libration
mode (period about an hour) is then the rigid rotation, which it equals over a push-off to
``(omega_lib t)^2 ~ 1e-3``.
"""

from __future__ import annotations

from microg.dynamics.planar import in_plane_fraction
from microg.location.mapping import (
    FUNDAMENTAL_MIN_PARTICIPATION,
    MEASURES,
    POINTS_COMPONENT,
    AccelerationMap,
    Location,
    acceleration_map,
    best_location,
)
from microg.location.peaks import elastic_mask
from microg.location.pipeline import (
    DEFAULTS,
    LATERAL,
    LocateResult,
    check_point,
    default_direction,
    default_point,
    force_to_dict,
    is_imported,
    locate,
    location_structure,
)
from microg.location.sampling import sample_shapes
from microg.location.site import SitePeak, point_peak

__all__ = [
    "DEFAULTS",
    "FUNDAMENTAL_MIN_PARTICIPATION",
    "LATERAL",
    "MEASURES",
    "POINTS_COMPONENT",
    "AccelerationMap",
    "Location",
    "LocateResult",
    "SitePeak",
    "acceleration_map",
    "best_location",
    "check_point",
    "default_direction",
    "default_point",
    "force_to_dict",
    "is_imported",
    "locate",
    "location_structure",
    "point_peak",
    # re-exported (dynamics.planar, location.sampling, .peaks) for the former module's callers
    "elastic_mask",
    "in_plane_fraction",
    "sample_shapes",
]
