"""The station's frequency-domain environment at the mount point pushed through the closed loop.

The vibratory sources (:mod:`microg.environment.sources`) give, at the mount point, the band
mean square ``int |H_i(f)|^2 S(f) df`` of each axis ``i``
(:func:`~microg.environment.vibratory.assess_sources`).  On the isolated platform the
acceleration of axis ``i`` is ``T_ii(f)`` times the base's, ``T`` the closed loop's
transmissibility (:func:`~microg.isolation.active.verify.transmissibility_matrix`), so its band
mean square is the same integral with the real weight ``|T_ii(f)|^2``: harmonic lines are
weighted at their own frequencies, the quadrature nodes at theirs, and the kernel's
convergence check is made on the weighted integrand
(:func:`~microg.dynamics.bands.band_mean_squares`).  The closed loop's poles are breakpoints of
the quadrature.  The cross-axis terms ``T_ij`` (``i != j``, from a centre of mass off the
umbilicals' attachment) are left out; their largest size relative to ``|T_ii|`` over the bands
is reported (``cross_axis_ratio``).

The verdict adds the sensors' noise floor in quadrature, as the time-domain check does:
``combined = sqrt(rms^2 + noise^2)`` per band and axis against the requirement's limit.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg import defaults
from microg.dynamics.modes import Modes
from microg.environment.metrics import json_number
from microg.environment.requirements import Requirement
from microg.environment.sources import Source, SourceCatalogue
from microg.environment.vibratory import VibratoryAssessment, assess_sources
from microg.errors import InputError

__all__ = ["MountSources", "SourcesCheck", "sources_check", "CROSS_AXIS_NOTE"]

_AXES = ("x", "y", "z")
#: a cross-axis transmissibility above this fraction of the direct one is named in the notes
CROSS_AXIS_NOTE = 1e-3


@dataclass(frozen=True)
class MountSources:
    """The station's vibratory sources as seen at a mount point (the inputs of the check).

    Attributes
    ----------
    modes : the station's modes (mass-normalised, rigid modes included)
    sources : the source catalogue (or a sequence of sources)
    zeta : modal damping ratio of the elastic modes, scalar or one per mode
    workers : threads over bands (None: the CPU count)
    """

    modes: Modes
    sources: SourceCatalogue | Sequence[Source]
    zeta: float | np.ndarray = defaults.DAMPING
    workers: int | None = None


def _nums(a: np.ndarray) -> list[float | str | None]:
    return [json_number(v) for v in np.asarray(a, float).ravel()]


@dataclass(frozen=True)
class SourcesCheck:
    """The platform's band table and verdict under the station's sources (module docstring).

    Attributes
    ----------
    point : the mount point's name
    base : the sources' assessment at the mount point (no isolation)
    platform : the same through the closed loop (``|T_ii|^2``-weighted band integrals)
    noise_rms_g : (3, nb) the sensors' noise floor per band, g
    combined_rms_g : (3, nb) ``sqrt(platform^2 + noise^2)``, g
    combined_margin : (nb,) limit / combined, worst axis (inf: no response)
    complies : every band and axis of the combined level within its limit
    cross_axis_ratio : largest ``|T_ij| / |T_ii|`` (``i != j``) over the bands' frequencies
    """

    point: str
    base: VibratoryAssessment = field(repr=False)
    platform: VibratoryAssessment = field(repr=False)
    noise_rms_g: np.ndarray
    combined_rms_g: np.ndarray
    combined_margin: np.ndarray
    complies: bool
    cross_axis_ratio: float

    @property
    def worst_band(self) -> dict[str, Any] | None:
        """The band of least combined margin: centre, axis, level, limit and margin (g)."""
        m = self.combined_margin
        if m.size == 0 or not np.isfinite(np.min(m)):
            return None
        k = int(np.argmin(m))
        axis = int(np.argmax(self.combined_rms_g[:, k]))
        return {
            "center_hz": float(self.platform.center_hz[k]),
            "axis": _AXES[axis],
            "rms_g": float(self.combined_rms_g[axis, k]),
            "limit_g": float(self.platform.limit_g[k]),
            "margin": float(m[k]),
        }

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready band table and verdict (strict JSON)."""
        p = self.platform
        base = self.base.point_dict(self.point)
        return {
            "point": self.point,
            "complies": bool(self.complies),
            "worst_band": self.worst_band,
            "sources_only_complies": bool(p.complies[0]),
            "base_complies": bool(base["complies"]),
            "base_worst_band": base["worst_band"],
            "cross_axis_ratio": json_number(self.cross_axis_ratio),
            "third_octave": {
                "center_hz": _nums(p.center_hz),
                "lower_hz": _nums(p.lower_hz),
                "upper_hz": _nums(p.upper_hz),
                "limit_g": _nums(p.limit_g),
                "base_rms_g_axis": {a: _nums(self.base.rms_g[0, i]) for i, a in enumerate(_AXES)},
                "rms_g_axis": {a: _nums(p.rms_g[0, i]) for i, a in enumerate(_AXES)},
                "noise_rms_g_axis": {a: _nums(self.noise_rms_g[i]) for i, a in enumerate(_AXES)},
                "combined_rms_g_axis": {
                    a: _nums(self.combined_rms_g[i]) for i, a in enumerate(_AXES)
                },
                "combined_margin": _nums(self.combined_margin),
            },
            "warnings": list(p.warnings),
        }


def _pole_breakpoints(cl: Any) -> np.ndarray:
    """The closed loop's pole frequencies ``|p| / 2 pi``, Hz (nonzero, finite)."""
    p = np.asarray(cl.poles())
    f = np.abs(p) / (2 * math.pi)
    return np.unique(f[np.isfinite(f) & (f > 0)])


def sources_check(
    cl: Any,
    src: MountSources,
    point: str,
    requirement: Requirement,
    noise_rms_g: np.ndarray,
) -> SourcesCheck:
    """The sources at ``point`` through the closed loop ``cl``: band table and verdict.

    Parameters
    ----------
    cl : the continuous closed loop (:func:`~microg.isolation.active.verify.closed_loop`)
    src : the station's modes and sources (:class:`MountSources`)
    point : the mount point, a point of the station's structure
    requirement : the band requirement (bands and limits, g)
    noise_rms_g : (3, nb) the sensors' noise floor on the requirement's bands, g
    """
    from microg.isolation.active.verify import transmissibility_matrix

    if not isinstance(src, MountSources):
        raise InputError("must be a MountSources (modes, sources, zeta)", where="sources")
    if point not in src.modes.structure.points:
        raise InputError(
            f"{point!r} is not a point of the station's model", where="point", fix="name a point"
        )

    def weight(freq_hz: np.ndarray) -> np.ndarray:
        t = transmissibility_matrix(cl, freq_hz)
        return np.abs(np.array([t[i, i] for i in range(3)])) ** 2

    base = assess_sources(
        src.modes, src.sources, [point], requirement, src.zeta, workers=src.workers
    )
    plat = assess_sources(
        src.modes,
        src.sources,
        [point],
        requirement,
        src.zeta,
        workers=src.workers,
        weight=weight,
        weight_breakpoints_hz=_pole_breakpoints(cl),
    )
    bands = requirement.bands
    fb = np.geomspace(float(np.min(bands.lower_hz)), float(np.max(bands.upper_hz)), 400)
    t = np.abs(transmissibility_matrix(cl, fb))
    diag = np.maximum(np.array([t[i, i] for i in range(3)]), 1e-300)
    off = ~np.eye(3, dtype=bool)
    cross = float(np.max((t / diag[:, None, :])[off])) if t.size else 0.0
    noise = np.asarray(noise_rms_g, float)
    if noise.shape != plat.rms_g[0].shape:
        raise InputError(
            f"needs shape {plat.rms_g[0].shape}, got {noise.shape}", where="noise_rms_g"
        )
    combined = np.sqrt(plat.rms_g[0] ** 2 + noise**2)
    limit = np.asarray(plat.limit_g, float)
    with np.errstate(divide="ignore"):
        ratio = limit[None, :] / np.where(combined > 0, combined, 1.0)
    margin = np.where(combined > 0, ratio, np.inf)
    return SourcesCheck(
        point=point,
        base=base,
        platform=plat,
        noise_rms_g=noise,
        combined_rms_g=combined,
        combined_margin=np.min(margin, axis=0),
        complies=bool(np.all(combined <= limit[None, :])),
        cross_axis_ratio=cross,
    )
