"""Band RMS against a requirement: the one-third-octave table of a record and its worst band.

Margin: ``limit / band RMS`` per axis and band (>= 1 passes, infinite for a zero band;
``"inf"`` in JSON).  Only the resolved bands (:mod:`microg.environment.bands`) enter the
verdict.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._json import json_by_name, json_number, json_numbers
from microg.environment._samples import axis_names, xr_dataset

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["ThirdOctave", "WorstBand"]


@dataclass(frozen=True)
class ThirdOctave:
    """1/3-octave band RMS against a requirement (g; margin = limit / rms)."""

    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray
    rms_g: np.ndarray  # (naxes, nb)
    limit_g: np.ndarray  # (nb,)
    margin: np.ndarray  # (naxes, nb)
    coverage: np.ndarray
    resolved: np.ndarray
    n_bins: np.ndarray = field(default_factory=lambda: np.zeros(0))
    reasons: tuple[str, ...] = ()

    @property
    def worst_rms_g(self) -> np.ndarray:
        """Largest band RMS over the axes, (nb,), g."""
        return self.rms_g.max(axis=0)

    @property
    def rss_rms_g(self) -> np.ndarray:
        """Root sum of squares of the axes' band RMS, (nb,), g (PIMS's ``v`` column)."""
        return np.sqrt(np.sum(self.rms_g**2, axis=0))

    @property
    def passes(self) -> np.ndarray:
        """(nb,) True where every axis is within the limit."""
        return np.all(self.rms_g <= self.limit_g, axis=0)

    @property
    def judged(self) -> np.ndarray:
        """(nb,) the bands that enter the verdict (resolved)."""
        return np.asarray(self.resolved, bool)

    @property
    def unresolved_bands(self) -> list[dict[str, Any]]:
        """The bands left out of the verdict: centre, edges and why."""
        return [
            {
                "center_hz": float(self.center_hz[i]),
                "lower_hz": float(self.lower_hz[i]),
                "upper_hz": float(self.upper_hz[i]),
                "reason": self.reasons[i] if i < len(self.reasons) else "unresolved",
            }
            for i in np.nonzero(~self.judged)[0]
        ]

    @property
    def verdict_range_hz(self) -> tuple[float, float] | None:
        """(lowest lower edge, highest upper edge) of the judged bands, Hz; None if none."""
        j = self.judged
        if not np.any(j):
            return None
        return float(self.lower_hz[j].min()), float(self.upper_hz[j].max())

    def to_dict(self, axes: tuple[str, ...] | None = None) -> dict[str, Any]:
        """JSON-ready bands (the ``third_octave`` block of :meth:`Assessment.to_dict`).

        ``rms_g`` and ``margin`` are the worst over the axes; ``*_axis`` per axis; an infinite
        margin is ``"inf"``.
        """
        ax = axis_names(self.rms_g.shape[0], axes)
        vr = self.verdict_range_hz
        return {
            "center_hz": json_numbers(self.center_hz),
            "lower_hz": json_numbers(self.lower_hz),
            "upper_hz": json_numbers(self.upper_hz),
            "rms_g": json_numbers(self.worst_rms_g),
            "limit_g": json_numbers(self.limit_g),
            "margin": json_numbers(self.margin.min(axis=0) if self.margin.size else self.margin),
            "rms_g_axis": json_by_name(ax, self.rms_g),
            "margin_axis": json_by_name(ax, self.margin),
            "rss_rms_g": json_numbers(self.rss_rms_g),
            "resolved": [bool(v) for v in self.resolved],
            "n_bins": json_numbers(self.n_bins),
            "coverage": json_numbers(self.coverage),
            "unresolved_bands": self.unresolved_bands,
            "unresolved_exceeding_hz": json_numbers(
                self.center_hz[~self.judged & np.any(self.rms_g > self.limit_g, axis=0)]
            ),
            "verdict_bands_hz": json_numbers(self.center_hz[self.judged]),
            "verdict_range_hz": None if vr is None else list(vr),
        }

    def to_xarray(self, axes: tuple[str, ...] | None = None) -> Any:
        """Band RMS, limits and margins as an ``xarray.Dataset`` (dims ``axis``, ``center_hz``)."""
        ax = axis_names(self.rms_g.shape[0], axes)
        nb = self.center_hz.size
        return xr_dataset(
            {
                "rms_g": (
                    ("axis", "center_hz"),
                    self.rms_g,
                    {"units": "g", "long_name": "band RMS"},
                ),
                "margin": (("axis", "center_hz"), self.margin, {"units": "1"}),
                "limit_g": ("center_hz", self.limit_g, {"units": "g"}),
                "rss_rms_g": ("center_hz", self.rss_rms_g, {"units": "g"}),
                "resolved": ("center_hz", np.asarray(self.resolved, np.int8), {"units": "1"}),
                "coverage": ("center_hz", self.coverage, {"units": "1"}),
                "n_bins": (
                    "center_hz",
                    self.n_bins if self.n_bins.size == nb else np.full(nb, np.nan),
                    {"units": "1"},
                ),
            },
            {
                "axis": list(ax),
                "center_hz": ("center_hz", self.center_hz, {"units": "Hz"}),
                "lower_hz": ("center_hz", self.lower_hz, {"units": "Hz"}),
                "upper_hz": ("center_hz", self.upper_hz, {"units": "Hz"}),
            },
            {},
        )

    def plot(
        self, axes: tuple[str, ...] | None = None, *, title: str = "", ax: Any = None
    ) -> Figure:
        """Band RMS per axis against the limit steps (``plotting.environment.plot_bands``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_bands

        return plot_bands(self, axes=axis_names(self.rms_g.shape[0], axes), title=title, ax=ax)


@dataclass(frozen=True)
class WorstBand:
    """The resolved band and axis with the smallest margin."""

    center_hz: float
    axis: str
    rms_g: float
    limit_g: float
    margin: float
    lower_hz: float = float("nan")
    upper_hz: float = float("nan")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready band (an infinite margin is ``"inf"``, an unknown edge None)."""
        return {
            "center_hz": self.center_hz,
            "lower_hz": json_number(self.lower_hz),
            "upper_hz": json_number(self.upper_hz),
            "axis": self.axis,
            "rms_g": self.rms_g,
            "limit_g": self.limit_g,
            "margin": json_number(self.margin),
        }
