"""Attenuation targets of an active isolator: the largest base-to-platform transmissibility allowed.

Three kinds:

* ``g-limit`` -- the g-LIMIT design requirement (Whorton et al., "Optimal control design using
  an H2 method for g-LIMIT", NASA MSFC 2001): three orders of magnitude of attenuation with a
  20 dB/decade roll-off from 0.01 to 10 Hz, passing the quasi-steady acceleration below
  0.01 Hz.  Read as ``|T(f)| <= 0.01 Hz / f`` for 0.01-10 Hz and ``|T| <= 1e-3`` from 10 Hz
  to ``F_TOP_HZ``, with ``|T| >= PASS_LEVEL`` at a tenth of the corner (quasi-steady passed).
* ``aris`` -- the ARIS flight figure (Bushnell, Fialho, Allen, Quraishi, SPIE 5052, 2003): over
  an order of magnitude of reduction at 0.1 Hz, ``|T(0.1 Hz)| <= 0.1``.
* per band -- the attenuation the analysis asks for (``microg analyze``'s
  ``attenuation_needed``): in each exceeding band ``[lo, hi]``, ``|T(f)| <= 1 / factor``
  throughout (which bounds the band RMS of the output by that of the input over 1 / factor).

:meth:`Target.limit` gives the largest allowed ``|T|`` at each frequency (inf where nothing is
asked).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from microg._kept import frozen_array, frozen_state
from microg.errors import InputError

__all__ = ["Target", "g_limit_target", "aris_target", "band_target", "target_by_name", "F_TOP_HZ"]

#: top of the g-LIMIT curve's 1e-3 plateau checked, Hz (the ISS vibratory range ends at 300 Hz)
F_TOP_HZ = 300.0
#: least ``|T|`` a decade below the quasi-steady corner: there the platform follows the station
PASS_LEVEL = 0.9


@dataclass(frozen=True)
class Target:
    """Largest transmissibility allowed, as segments ``[lo_hz, hi_hz]`` of a power law.

    Attributes
    ----------
    name : ``g-limit``, ``aris`` or ``bands``
    lo_hz, hi_hz : (ns,) segment edges, Hz (a segment with ``lo == hi`` is one frequency)
    level : (ns,) allowed ``|T|`` at ``lo_hz``
    slope : (ns,) log-log slope of the limit over the segment (0: flat; -1: 20 dB/decade)
    pass_below_hz : frequency below which the platform must follow the station (``|T| >=
        PASS_LEVEL`` at a tenth of it), Hz, or None
    source : citation
    """

    name: str
    lo_hz: np.ndarray
    hi_hz: np.ndarray
    level: np.ndarray
    slope: np.ndarray
    pass_below_hz: float | None
    source: str

    def __post_init__(self) -> None:
        for name in ("lo_hz", "hi_hz", "level", "slope"):  # its own, read-only (it is frozen)
            object.__setattr__(self, name, frozen_array(np.asarray(getattr(self, name), float)))

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(frozen_state(state))

    def limit(self, freq_hz: np.ndarray) -> np.ndarray:
        """Largest allowed ``|T|`` at ``freq_hz`` (inf where the target says nothing)."""
        f = np.asarray(freq_hz, float)
        out = np.full(f.shape, np.inf)
        for lo, hi, lev, sl in zip(self.lo_hz, self.hi_hz, self.level, self.slope, strict=True):
            inside = (f >= lo * (1 - 1e-12)) & (f <= hi * (1 + 1e-12))
            val = lev * (np.where(inside, f, lo) / lo) ** sl
            out = np.where(inside, np.minimum(out, val), out)
        return out

    def check_freq_hz(self, per_decade: int = 40) -> np.ndarray:
        """Frequencies the target is checked at: its segment edges and ``per_decade`` between.

        Formed once per target and ``per_decade`` (a design asks three times), read-only.
        """
        kept: dict[int, np.ndarray] = self.__dict__.setdefault("_checks", {})
        hit = kept.get(per_decade)
        if hit is None:
            pts = [self.lo_hz, self.hi_hz]
            for lo, hi in zip(self.lo_hz, self.hi_hz, strict=True):
                if hi > lo:
                    n = max(2, int(np.ceil(per_decade * np.log10(hi / lo))) + 1)
                    pts.append(np.geomspace(lo, hi, n))
            hit = np.unique(np.concatenate(pts))
            hit.setflags(write=False)
            kept[per_decade] = hit
        return hit

    def span_hz(self) -> tuple[float, float]:
        """Lowest and highest frequency the target constrains, Hz."""
        lo = float(self.lo_hz.min())
        if self.pass_below_hz is not None:
            lo = min(lo, 0.1 * self.pass_below_hz)
        return lo, float(self.hi_hz.max())

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready target: its segments and what they mean."""
        return {
            "name": self.name,
            "source": self.source,
            "segments": [
                {
                    "lo_hz": float(lo),
                    "hi_hz": float(hi),
                    "max_transmissibility": float(lev),
                    "log_slope": float(sl),
                }
                for lo, hi, lev, sl in zip(
                    self.lo_hz, self.hi_hz, self.level, self.slope, strict=True
                )
            ],
            "pass_below_hz": self.pass_below_hz,
            "pass_level": PASS_LEVEL if self.pass_below_hz is not None else None,
        }


def g_limit_target() -> Target:
    """The g-LIMIT requirement (module docstring)."""
    return Target(
        name="g-limit",
        lo_hz=np.array([0.01, 10.0]),
        hi_hz=np.array([10.0, F_TOP_HZ]),
        level=np.array([1.0, 1e-3]),
        slope=np.array([-1.0, 0.0]),
        pass_below_hz=0.01,
        source="Whorton et al., 'Optimal control design using an H2 method for g-LIMIT' (NASA "
        "MSFC 2001): three orders of magnitude of attenuation, 20 dB/decade roll-off from "
        "0.01 to 10 Hz, quasi-steady (< 0.01 Hz) passed",
    )


def aris_target() -> Target:
    """The ARIS flight figure: ``|T(0.1 Hz)| <= 0.1`` (module docstring)."""
    return Target(
        name="aris",
        lo_hz=np.array([0.1]),
        hi_hz=np.array([0.1]),
        level=np.array([0.1]),
        slope=np.array([0.0]),
        pass_below_hz=None,
        source="Bushnell, Fialho, Allen, Quraishi, SPIE 5052 (2003): over an order of magnitude "
        "reduction in the acceleration at 0.1 Hz in flight",
    )


def band_target(
    attenuation: Mapping[float, float], edges: Mapping[float, tuple[float, float]]
) -> Target:
    """The attenuation asked per band: ``|T| <= 1 / factor`` over each band.

    Parameters
    ----------
    attenuation : band centre (Hz) -> factor (> 1) by which the band must be attenuated
    edges : band centre (Hz) -> (lower, upper) edge, Hz
    """
    if not attenuation:
        raise InputError("no band needs attenuation", where="target")
    centers = sorted(attenuation)
    bad = [c for c in centers if not (np.isfinite(attenuation[c]) and attenuation[c] > 0)]
    if bad:
        raise InputError(f"band {bad[0]:g} Hz: factor must be > 0", where="target")
    return Target(
        name="bands",
        lo_hz=np.array([edges[c][0] for c in centers], float),
        hi_hz=np.array([edges[c][1] for c in centers], float),
        level=np.array([1.0 / attenuation[c] for c in centers], float),
        slope=np.zeros(len(centers)),
        pass_below_hz=None,
        source="the attenuation the analysis needs per exceeding 1/3-octave band (1 / margin)",
    )


def target_by_name(name: str) -> Target:
    """``g-limit`` or ``aris``."""
    if name == "g-limit":
        return g_limit_target()
    if name == "aris":
        return aris_target()
    raise InputError(f"unknown target {name!r}", where="target", fix="use g-limit or aris")
