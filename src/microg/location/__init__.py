"""Where to put the laboratory: acceleration maps, nodes of the fundamental, layout optimiser.

The report's conclusions 6, 7 and 9 (Section 5, Figure 9).  Modules, one concept each:
:mod:`~microg.location.sampling` (samples along the structure, straight lines, nodes),
:mod:`~microg.location.peaks` (Eq. 3.1 peak factors, the rigid-body part, the time grid, the
elastic rule, the peaks at points), :mod:`~microg.location.mapping` (the acceleration map
and its best location), :mod:`~microg.location.site` (the peaks at one named point),
:mod:`~microg.location.pipeline` (:func:`locate`, from a model), :mod:`~microg.location.layout`
(movable masses and the optimiser); :mod:`~microg.location.amap` gathers the names of the
map, the site and the pipeline.  Figures in :mod:`microg.plotting.location`, the
conclusion-7 reproduction in :mod:`microg.seed.conclusion7`.  See ``docs/locate.md``.

:func:`locate` takes stations and imported models alike: a modal model is mapped over its
grids (named points added as carrier ``"points"``), a NASTRAN deck over its nodes, with the
nodes of the fundamental along the straight chains of its beams and rods
(:func:`~microg.location.sampling.element_lines`).
"""

from microg.location.layout import (
    LayoutResult,
    MovableMass,
    layout_objective,
    movable_masses,
    move_masses,
    optimize_layout,
)
from microg.location.mapping import AccelerationMap, Location, acceleration_map, best_location
from microg.location.pipeline import LocateResult, locate
from microg.location.sampling import Node, SampleLine
from microg.location.site import SitePeak, point_peak

__all__ = [
    "AccelerationMap",
    "LayoutResult",
    "LocateResult",
    "Location",
    "MovableMass",
    "Node",
    "SampleLine",
    "SitePeak",
    "acceleration_map",
    "best_location",
    "layout_objective",
    "locate",
    "movable_masses",
    "move_masses",
    "optimize_layout",
    "point_peak",
]
