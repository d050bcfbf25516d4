"""Structure stage: discretisations (assumed modes, frame finite elements) -> ``Structure``."""

from microg.structure.structure import PointMap, Structure

__all__ = ["PointMap", "Structure"]
