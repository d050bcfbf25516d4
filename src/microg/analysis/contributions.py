"""What each mode contributes at an observed point (which mode to stiffen or detune).

Mode ``j``'s own series at a point is ``tphi[:, j] acc_j(t)`` (``tphi`` the point's rows
``T phi``, ``acc_j`` the modal acceleration): its acceleration at the instant of the peak,
projected on the peak's direction (these sum to the peak magnitude), its own largest
magnitude ``|tphi[:, j]| max_t |acc_j|`` and its band RMS on the worst band's axis
``|tphi[ax, j]|`` times the band RMS of ``acc_j`` (:class:`ModalSeries`, computed once per run).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg.dynamics.modes import Modes
from microg.environment.metrics import Assessment, band_mean_square
from microg.environment.requirements import BandTable
from microg.units import G0

__all__ = ["ModalSeries", "ModeContributions", "mode_contributions"]


@dataclass(frozen=True)
class ModeContributions:
    """What each mode contributes at one observed point: which mode to stiffen or detune.

    Attributes
    ----------
    mode : ndarray of int (k,)
        Mode numbers (1-based, as in the modes table) of the modes in the response.
    freq_hz : ndarray (k,)
        Their frequencies, Hz.
    at_peak_g : ndarray (k,)
        Each mode's acceleration at the instant of the peak, projected on the peak's
        direction, g.  They sum to the peak magnitude.
    own_peak_g : ndarray (k,)
        Each mode's own largest acceleration magnitude over the record, g.
    worst_band_rms_g : ndarray (k,) or None
        Each mode's band RMS in the worst band on the worst axis, g (None when no band).
    worst_band_hz : float or None
        Centre of that band, Hz.
    worst_axis : str or None
    """

    mode: np.ndarray
    freq_hz: np.ndarray
    at_peak_g: np.ndarray
    own_peak_g: np.ndarray
    worst_band_rms_g: np.ndarray | None
    worst_band_hz: float | None
    worst_axis: str | None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready table, one row per mode."""
        rows = []
        for i in range(self.mode.size):
            row: dict[str, Any] = {
                "mode": int(self.mode[i]),
                "freq_hz": float(self.freq_hz[i]),
                "at_peak_g": float(self.at_peak_g[i]),
                "own_peak_g": float(self.own_peak_g[i]),
            }
            if self.worst_band_rms_g is not None:
                row["worst_band_rms_g"] = float(self.worst_band_rms_g[i])
            rows.append(row)
        return {"worst_band_hz": self.worst_band_hz, "worst_axis": self.worst_axis, "modes": rows}

    def to_xarray(self) -> Any:
        """The table as an ``xarray.Dataset`` over ``mode`` (g; ``freq_hz`` a coordinate)."""
        import xarray as xr

        data: dict[str, Any] = {
            "at_peak_g": ("mode", self.at_peak_g, {"units": "g"}),
            "own_peak_g": ("mode", self.own_peak_g, {"units": "g"}),
        }
        if self.worst_band_rms_g is not None:
            data["worst_band_rms_g"] = ("mode", self.worst_band_rms_g, {"units": "g"})
        attrs: dict[str, Any] = {"worst_axis": self.worst_axis or ""}
        if self.worst_band_hz is not None:
            attrs["worst_band_hz"] = float(self.worst_band_hz)
        return xr.Dataset(
            data,
            coords={
                "mode": ("mode", self.mode, {"units": "1"}),
                "freq_hz": ("mode", self.freq_hz, {"units": "Hz"}),
            },
            attrs=attrs,
        )


class ModalSeries:
    """The modal accelerations (k, nt) of a run, with the per-mode quantities every point shares.

    A point's per-mode series is its map coefficient times the modal acceleration, so its
    peak and band RMS are ``|coefficient|`` times the modal one (the PSD scales with the
    square: demeaning, the periodogram and the band sum are linear in ``|X|^2``); these are
    computed once per run, not once per observed point.
    """

    def __init__(self, t: np.ndarray, acc: np.ndarray):
        self.t = t
        self.acc = acc
        self._peak: np.ndarray | None = None
        self._band: dict[float, np.ndarray] = {}

    def peak_abs(self) -> np.ndarray:
        """``max_t |acc_j(t)|`` per mode, m/s^2 (k,)."""
        if self._peak is None:  # max |x| = max(max x, -min x): no |acc| temporary
            self._peak = np.maximum(self.acc.max(axis=1), -self.acc.min(axis=1))
        return self._peak

    def band_rms(self, center_hz: float, lower_hz: float, upper_hz: float) -> np.ndarray:
        """RMS of each modal acceleration in one band, m/s^2 (k,)."""
        key = float(center_hz)
        if key not in self._band:
            bands = BandTable(np.array([center_hz]), np.array([lower_hz]), np.array([upper_hz]))
            ms = band_mean_square(self.t, self.acc, bands)[:, 0]
            self._band[key] = np.sqrt(np.maximum(ms, 0.0))
        return self._band[key]


def mode_contributions(
    mode_numbers: np.ndarray,
    m: Modes,
    tphi: np.ndarray,
    modal: ModalSeries,
    a: Assessment,
    acc_at_peak: np.ndarray,
) -> ModeContributions:
    """Per-mode contributions at a point (``acc_at_peak``: modal accelerations at the peak).

    Mode j's own series at the point is ``tphi[:, j] acc_j(t)``: its peak magnitude is
    ``|tphi[:, j]| max_t |acc_j|`` and its band RMS on an axis ``|tphi[ax, j]|`` times the
    band RMS of ``acc_j`` (:class:`ModalSeries`).
    """
    total = tphi @ acc_at_peak  # (3,)
    size = float(np.linalg.norm(total))
    u = total / size if size > 0 else np.zeros(3)
    at_peak = (u @ tphi) * acc_at_peak / G0
    own = np.linalg.norm(tphi, axis=0) * modal.peak_abs() / G0
    wb = a.worst_band
    band_rms_g = None
    band_hz = None
    axis = None
    if wb is not None and np.isfinite(wb.margin):
        ax = "xyz".index(wb.axis) if wb.axis in "xyz" else 0
        to = a.third_octave
        i = int(np.argmin(np.abs(to.center_hz - wb.center_hz)))
        rms = modal.band_rms(to.center_hz[i], to.lower_hz[i], to.upper_hz[i])
        band_rms_g = np.abs(tphi[ax]) * rms / G0
        band_hz = float(wb.center_hz)
        axis = wb.axis
    return ModeContributions(
        mode=mode_numbers,
        freq_hz=m.freq_hz,
        at_peak_g=at_peak,
        own_peak_g=own,
        worst_band_rms_g=band_rms_g,
        worst_band_hz=band_hz,
        worst_axis=axis,
    )
