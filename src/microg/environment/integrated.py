"""Integrated acceleration (velocity change over a window), two named definitions.

``sliding`` (microg's, conservative): ``max over t of |int_t^{t+W} a dt|`` over the raw
record, windows of ``W = 10 s`` starting at every sample (end interpolated in the running
trapezoidal integral).  ``pims`` (NASA PIMS ``file_trapz``): the record demeaned, cut into
consecutive blocks of ``ceil(W / dt)`` samples (an incomplete last block dropped), each block
integrated by the trapezoid rule (see docs/assessment.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._json import json_number, json_numbers
from microg.environment._samples import as_axes, axis_names, sample_rate, xr_dataset
from microg.errors import InputError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "IntegratedAcceleration",
    "IntegratedBlocks",
    "integrated_acceleration",
    "integrated_acceleration_pims",
]


class _WindowIntegrals:
    """The methods shared by the two integrated-acceleration results (sliding and PIMS)."""

    DEFINITION: str
    window_s: float
    t_start: np.ndarray
    delta_v: np.ndarray
    max_mps: np.ndarray
    max_magnitude_mps: float

    def _extra(self) -> dict[str, Any]:
        """Keys a result adds to :meth:`to_dict` after ``window_s``."""
        return {}

    def to_dict(self, axes: tuple[str, ...] | None = None) -> dict[str, Any]:
        """JSON-ready summary: the window and the largest integrals, m/s.

        No per-window rows; those are in :meth:`to_xarray`.
        """
        ax = axis_names(self.delta_v.shape[0], axes)
        return {
            "definition": self.DEFINITION,
            "window_s": self.window_s,
            **self._extra(),
            "n_windows": int(self.t_start.size),
            "max_mps_axis": dict(zip(ax, json_numbers(self.max_mps), strict=True)),
            "max_magnitude_mps": json_number(self.max_magnitude_mps),
        }

    def to_xarray(self, axes: tuple[str, ...] | None = None) -> Any:
        """The integral of each window as an ``xarray.Dataset``.

        ``delta_v_mps`` on dims ``axis``, ``t_start_s``.
        """
        ax = axis_names(self.delta_v.shape[0], axes)
        return xr_dataset(
            {
                "delta_v_mps": (
                    ("axis", "t_start_s"),
                    self.delta_v,
                    {"units": "m/s", "long_name": "integral of the acceleration"},
                ),
                "max_mps": ("axis", self.max_mps, {"units": "m/s"}),
            },
            {"axis": list(ax), "t_start_s": ("t_start_s", self.t_start, {"units": "s"})},
            {
                "definition": self.DEFINITION,
                "window_s": self.window_s,
                "max_magnitude_mps": self.max_magnitude_mps,
            },
        )

    def plot(
        self, axes: tuple[str, ...] | None = None, *, title: str = "", ax: Any = None
    ) -> Figure:
        """Each window's integral against its start (``plotting.environment.plot_integrated``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.environment import plot_integrated

        me: Any = self  # one of the two subclasses
        return plot_integrated(me, axes=axis_names(self.delta_v.shape[0], axes), title=title, ax=ax)


@dataclass(frozen=True)
class IntegratedAcceleration(_WindowIntegrals):
    """Integral of the acceleration over sliding windows (velocity change), m/s.

    Attributes
    ----------
    window_s : window length, s (the record length if the record is shorter)
    t_start : (nw,) window start times, s
    delta_v : (naxes, nw) integral over each window, m/s
    max_mps : (naxes,) max |delta_v| per axis, m/s
    max_magnitude_mps : max over windows of the vector norm of delta_v, m/s
    """

    window_s: float
    t_start: np.ndarray
    delta_v: np.ndarray
    max_mps: np.ndarray
    max_magnitude_mps: float

    #: what the integral is (in :meth:`to_dict` and :meth:`to_xarray`)
    DEFINITION = (
        "max over windows starting at every sample of |integral of the raw acceleration "
        "over window_s| (microg, conservative)"
    )


@dataclass(frozen=True)
class IntegratedBlocks(_WindowIntegrals):
    """PIMS's integrated acceleration: consecutive demeaned blocks, m/s.

    Attributes
    ----------
    window_s : nominal block length, s
    block_samples : samples per block, ``ceil(window_s / dt)`` as PIMS computes it
    t_start : (nb,) block start times, s
    delta_v : (naxes, nb) trapezoidal integral of each block, m/s
    max_mps : (naxes,) max |delta_v| per axis, m/s (0 when there is no complete block)
    max_magnitude_mps : max over blocks of the vector norm, m/s
    """

    window_s: float
    block_samples: int
    t_start: np.ndarray
    delta_v: np.ndarray
    max_mps: np.ndarray
    max_magnitude_mps: float

    @property
    def n_blocks(self) -> int:
        """Complete blocks in the record."""
        return int(self.t_start.size)

    #: what the integral is (in :meth:`to_dict` and :meth:`to_xarray`)
    DEFINITION = (
        "record demeaned, consecutive blocks of block_samples = ceil(window_s / dt) samples, "
        "trapezoidal integral of each (NASA PIMS file_trapz)"
    )

    def _extra(self) -> dict[str, Any]:
        """``block_samples`` (PIMS's block length in samples)."""
        return {"block_samples": self.block_samples}


def integrated_acceleration(
    timepts: np.ndarray, accel: np.ndarray, window_s: float = 10.0
) -> IntegratedAcceleration:
    """Integral of the raw acceleration over sliding windows of ``window_s`` (microg's).

    Windows start at every sample; the end is interpolated in the running trapezoidal
    integral.  Conservative: the worst window anywhere, the mean kept.

    Parameters
    ----------
    timepts : (nt,) sorted times, s (any spacing)
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    window_s : window length, s (the whole record if it is shorter)
    """
    t = np.asarray(timepts, dtype=float)
    a = as_axes(accel)
    if a.shape[1] != t.size or t.size < 2:
        raise InputError("timepts and accel do not match", where="accel")
    if not window_s > 0:
        raise InputError("window must be positive", where="window_s")
    cum = np.concatenate(
        [np.zeros((a.shape[0], 1)), np.cumsum(0.5 * (a[:, 1:] + a[:, :-1]) * np.diff(t), axis=1)],
        axis=1,
    )
    span = t[-1] - t[0]
    window = min(window_s, span)
    # the windows start at a prefix of the samples (t sorted), their ends interpolated in the
    # running integral
    n_win = int(np.count_nonzero(t + window <= t[-1] + 1e-12 * max(1.0, abs(t[-1]))))
    starts = t[:n_win]
    ends = np.minimum(starts + window, t[-1])
    dv = np.array([np.interp(ends, t, c) - c[:n_win] for c in cum])
    return IntegratedAcceleration(
        window_s=float(window),
        t_start=starts,
        delta_v=dv,
        max_mps=np.max(np.abs(dv), axis=1),
        max_magnitude_mps=float(np.max(np.linalg.norm(dv, axis=0))),
    )


def integrated_acceleration_pims(
    timepts: np.ndarray,
    accel: np.ndarray,
    window_s: float = 10.0,
    *,
    sample_rate_hz: float | None = None,
) -> IntegratedBlocks:
    """PIMS's integrated acceleration: the demeaned record in consecutive blocks, m/s.

    As ``file_trapz`` in ``transient/main.py`` of github.com/baluneboy/pims: the record's mean
    is removed (over the whole record), ``nt = ceil(window_s / dt)`` with ``dt = 1 / fs`` (a
    ratio within 1e-9 of an integer taken as that integer), consecutive blocks of ``nt``
    samples, an incomplete last block dropped, and each block integrated by the trapezoid rule
    with spacing ``dt``.

    Parameters
    ----------
    timepts : (nt,) uniformly spaced times, s
    accel : (naxes, nt) or (nt,) acceleration, m/s^2
    window_s : nominal block length, s (PIMS: 10 s)
    sample_rate_hz : the sampling rate, Hz (default: from ``timepts``; measured files give it)
    """
    a = as_axes(accel)
    fs = float(sample_rate_hz) if sample_rate_hz is not None else sample_rate(timepts)
    t = np.asarray(timepts, dtype=float)
    if a.shape[1] != t.size:
        raise InputError("timepts and accel do not match", where="accel")
    if not window_s > 0:
        raise InputError("window must be positive", where="window_s")
    dt = 1.0 / fs
    # PIMS: int(np.ceil(sec / dt)); a rate taken from rounded times must not turn an exact
    # 1000.0000000001 into 1001, so a ratio within 1e-9 of an integer counts as that integer
    ratio = window_s / dt
    nt = max(1, int(np.ceil(ratio - 1e-9 * ratio)))
    b = a - a.mean(axis=1, keepdims=True)
    nblk = a.shape[1] // nt
    blocks = b[:, : nblk * nt].reshape(a.shape[0], nblk, nt)
    dv = np.trapezoid(blocks, dx=dt, axis=2) if nblk else np.zeros((a.shape[0], 0))
    return IntegratedBlocks(
        window_s=float(window_s),
        block_samples=nt,
        t_start=t[: nblk * nt : nt] if nblk else np.zeros(0),
        delta_v=dv,
        max_mps=np.max(np.abs(dv), axis=1) if nblk else np.zeros(a.shape[0]),
        max_magnitude_mps=float(np.max(np.linalg.norm(dv, axis=0))) if nblk else 0.0,
    )
