"""A measured acceleration record (SI, uniformly sampled) and what its readers share.

The readers (:mod:`~microg.environment.pad`, :mod:`~microg.environment.accel_csv`,
:mod:`~microg.environment.uff58`) return :class:`MeasuredRecord`; they share the limits on
the sampling rate and on the jitter of a time step, and the reading of acceleration units
(``g`` is standard gravity, ``mg`` milli-g, not the gram and the milligram pint would read).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.errors import InputError
from microg.units import G0, LIMITS, parse_quantity

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "CSV_STEP_TOLERANCE",
    "MAX_SAMPLE_RATE_HZ",
    "MeasuredRecord",
    "accel_factor",
    "nonuniform_step",
]

#: highest sampling rate accepted, Hz
MAX_SAMPLE_RATE_HZ = 1e6
#: jitter of a CSV time step tolerated, fraction of the step (rounding of printed times)
CSV_STEP_TOLERANCE = 0.01
#: acceleration unit names that pint would read otherwise (g = gram, mg = milligram)
_ACCEL_ALIASES = {
    "g": "standard_gravity",
    "g0": "standard_gravity",
    "gee": "standard_gravity",
    "mg": "milli_g",
    "milli-g": "milli_g",
    "ug": "micro_g",
    "µg": "micro_g",
    "μg": "micro_g",
    "micro-g": "micro_g",
    "mps2": "m/s^2",
    "m/s2": "m/s^2",
    "m/s/s": "m/s^2",
}


@dataclass(frozen=True)
class MeasuredRecord:
    """A measured acceleration record, SI, uniformly sampled.

    Attributes
    ----------
    path : the data file
    format : ``pad`` or ``csv``
    sensor : the sensor's name (PAD ``SensorID``, CSV ``# sensor:``), or None
    timepts : (n,) times, s, ``t0 + i / sample_rate_hz``
    accel : (naxes, n) acceleration, m/s^2
    sample_rate_hz : samples per second
    axes : axis names of the rows of ``accel``
    cutoff_hz : anti-alias cutoff of the data, Hz, or None
    start : start time as the file gives it (PAD ``TimeZero``, UFF ID line 3), or None
    metadata : further header fields (text)
    warnings : what a reader of the verdict must know about the file's data
    """

    path: str
    format: str
    sensor: str | None
    timepts: np.ndarray
    accel: np.ndarray
    sample_rate_hz: float
    axes: tuple[str, ...] = ("x", "y", "z")
    cutoff_hz: float | None = None
    start: str | None = None
    metadata: dict[str, str] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        # a sample beyond the physical limit (100 g) is a unit or a file error, and its
        # square overflows the band powers: refuse it with the value, never a verdict of nulls
        a = np.asarray(self.accel)
        big = np.abs(a) > LIMITS["acceleration"]
        if np.any(big):
            ax, i = np.unravel_index(int(np.argmax(big)), a.shape)
            raise InputError(
                f"sample {i} of axis {self.axes[ax] if ax < len(self.axes) else ax} is "
                f"{a[ax, i]:.3g} m/s^2 ({a[ax, i] / G0:.3g} g), beyond the physical limit of "
                f"{LIMITS['acceleration']:g} m/s^2",
                where=self.path,
                fix="check the file's unit and its data",
            )

    @property
    def duration_s(self) -> float:
        """Record length ``n / fs``, s."""
        return self.accel.shape[1] / self.sample_rate_hz

    @property
    def key(self) -> str:
        """The key of this record in the ``observations`` contract (``sensor`` if unnamed)."""
        return self.sensor or "sensor"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description of the record (no samples)."""
        return {
            "path": self.path,
            "format": self.format,
            "sensor": self.sensor,
            "axes": list(self.axes),
            "samples": int(self.accel.shape[1]),
            "sample_rate_hz": self.sample_rate_hz,
            "duration_s": self.duration_s,
            "cutoff_hz": self.cutoff_hz,
            "start": self.start,
            "metadata": dict(self.metadata),
            "warnings": list(self.warnings),
        }

    def to_xarray(self) -> Any:
        """The samples as an ``xarray.DataArray`` ``accel_mps2``, the header in the attributes.

        Dims ``axis``, ``time``; m/s^2, times in s.
        """
        import xarray as xr

        return xr.DataArray(
            self.accel,
            dims=("axis", "time"),
            coords={"axis": list(self.axes), "time": ("time", self.timepts, {"units": "s"})},
            name="accel_mps2",
            attrs={
                "units": "m/s^2",
                "long_name": "measured acceleration",
                "sensor": self.sensor or "",
                "path": self.path,
                "format": self.format,
                "sample_rate_hz": self.sample_rate_hz,
                **({} if self.cutoff_hz is None else {"cutoff_hz": self.cutoff_hz}),
                **({} if self.start is None else {"start": self.start}),
            },
        )

    def plot(self, *, title: str = "", ax: Any = None) -> Figure:
        """The record against time, micro-g (``plotting.environment.plot_time_history``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_time_history

        return plot_time_history(
            self.timepts,
            self.accel,
            axes=self.axes,
            title=title or f"Acceleration at {self.key}",
            ax=ax,
        )


def accel_factor(unit: str, where: str) -> float:
    """SI value (m/s^2) of one ``unit`` of acceleration (``g``, ``mg``, ``ug``, ``ft/s^2``...).

    Parameters
    ----------
    unit : str
        The unit as a file writes it.
    where : str
        File and field, for the error of an unknown unit.
    """
    u = _ACCEL_ALIASES.get(unit.strip().lower(), unit.strip())
    u = _ACCEL_ALIASES.get(u, u)
    if u in ("micro_g", "milli_g", "standard_gravity"):
        return {"micro_g": 1e-6 * G0, "milli_g": 1e-3 * G0, "standard_gravity": G0}[u]
    return parse_quantity(f"1 {u}", "acceleration", where=where)


def nonuniform_step(t: np.ndarray) -> tuple[int, float, float] | None:
    """``(i, step, typical)`` of the first time step off the typical one, else None.

    Off: by more than :data:`CSV_STEP_TOLERANCE`; ``i`` is the 0-based index of the sample
    after it.

    Parameters
    ----------
    t : ndarray (n,)
        Times, s.
    """
    steps = np.diff(t)
    typical = float(np.median(steps))  # robust: a single gap does not move it
    off = np.abs(steps - typical) > CSV_STEP_TOLERANCE * abs(typical)
    if typical > 0 and not np.any(off):
        return None
    r = int(np.argmax(off)) + 1 if np.any(off) else 1
    return r, float(steps[r - 1]), typical
