"""Frequency-domain response of a modal model (the SOL 111 equivalent).

FRFs, harmonic lines, band RMS of force spectra, combination over sources, modal and source
contributions.

Conventions (SI; frequencies in Hz where named ``_hz``, circular frequencies ``omega`` in rad/s)

* **Acceleration FRF** per newton of force at an input point along a unit direction ``d``, at an
  output coordinate (a translation axis of an observed point)::

      H_a(w) = sum_j c_j r_j(w),   r_j(w) = -w^2 / (w_j^2 - w^2 + 2 i zeta_j w_j w),
      c_j = (T_out phi_j) (d . T_in phi_j)

  with mass-normalised modes ``phi`` and the point translation maps ``T`` (which carry the
  rotation of offset points).  A rigid mode (``w_j = 0``) gives ``r_j = 1`` at every ``w > 0``:
  the constant mass line.  This is the modal frequency response of MSC Nastran SOL 111 with
  modal damping ``zeta_j`` (Craig & Kurdila, *Fundamentals of Structural Dynamics*, 2nd ed.,
  Sec. 10.4).
* **Harmonic force** ``f(t) = A cos(2 pi f t + phase)``, ``A`` the peak amplitude (N).  The
  steady-state acceleration is ``a(t) = Re(H_a(w) A e^{i phase} e^{i w t})``, mean square
  ``|H_a A|^2 / 2``.
* **Force spectra** are one-sided PSDs in N^2/Hz over frequency in Hz.  A band spectrum (RMS per
  band) is flat inside each band, ``S = rms^2 / (upper - lower)``, and zero outside its bands.  A
  PSD table is interpolated **log-log** (a power law between consecutive points; a segment with a
  zero end is interpolated linearly) and is zero outside its first and last frequency.
* **Band mean square** of a spectral source: ``int_lower^upper |H_a(2 pi f)|^2 S(f) df``.  A
  harmonic line counts in each band with ``lower <= f < upper`` (the top band is closed).
* **Combination.**  Sources in different coherent groups (a source without a group is a group
  of its own) are independent: mean squares add (the RSS of the RMS values).  Within a coherent
  group (one machine) the responses add as complex numbers before squaring: harmonic lines of
  the group at one frequency add as phasors (their phases count), lines at different
  frequencies are orthogonal; spectral sources of a group are fully coherent and in phase
  (cross-spectrum ``sqrt(S_1 S_2)``).  A line and a continuous spectrum never interfere.
* **Contributions** of a band's mean square ``MS = sum_g int |Y_g|^2`` (``Y_g`` the complex
  response of group ``g``):

  - ``source_rms``: the source acting alone; ``source_share``: ``sum Re(Y_s conj(Y_g)) / MS``
    (its signed part of the mean square, which sums to 1 over the sources; for an independent
    source it is ``(source_rms / rms)^2``; a member of a coherent group can have a negative share
    when it cancels the others);
  - ``mode_rms``: the response of mode ``j`` alone under all sources (RSS over groups);
    ``mode_share``: ``sum_g int Re(Y_gj conj(Y_g)) / MS`` with ``Y_gj`` the mode-``j`` term of
    ``Y_g``: the same projection, so a coherent sum is attributed to modes through the complex
    total, and the shares sum to 1 over the modes.  Modes of one repeated frequency share a
    subspace: their individual split depends on the eigensolver's basis, their sum does not.

The pieces: force spectra and loads (:mod:`microg.dynamics.spectra`), the FRF kernels
(:mod:`microg.dynamics.frf`), the converged band quadrature (:mod:`microg.dynamics.bandquad`)
and the band mean squares with their contributions (:mod:`microg.dynamics.bands`).  This module
is the entry from a :class:`~microg.dynamics.modes.Modes`: it checks the damping, the points and
the frequencies once and returns the results (:class:`AccelerationFRF`,
:class:`HarmonicResponse`, :class:`BandResponse`); the kernels trust their inputs.  Every name of
the pieces' public API is importable from here too.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg._json import finite_list
from microg._vectors import AXIS_NAMES, parse_direction
from microg.dynamics.bandquad import MAX_REFINEMENTS, BandQuadrature, band_quadrature
from microg.dynamics.bands import MAX_LINES, BandArrays, band_mean_squares
from microg.dynamics.frf import acceleration_frf, modal_frf_factor
from microg.dynamics.modes import Modes
from microg.dynamics.spectra import (
    BandForceSpectrum,
    ForcePSD,
    ForceSpectrum,
    HarmonicLines,
    Load,
    same_frequency_index,
)
from microg.errors import InputError

__all__ = [
    "MAX_FREQUENCIES",
    "MAX_LINES",
    "MAX_REFINEMENTS",
    "HarmonicLines",
    "BandForceSpectrum",
    "ForcePSD",
    "ForceSpectrum",
    "Load",
    "modal_frf_factor",
    "acceleration_frf",
    "AccelerationFRF",
    "frf",
    "HarmonicResponse",
    "harmonic_response",
    "BandQuadrature",
    "band_quadrature",
    "BandArrays",
    "band_mean_squares",
    "BandResponse",
    "band_response",
    "damping_ratios",
    "output_modal",
    "input_modal",
]

#: largest number of frequencies of one FRF evaluation (memory: points x 3 x frequencies)
MAX_FREQUENCIES = 1_000_000


def damping_ratios(modes: Modes, zeta: float | Sequence[float] | np.ndarray) -> np.ndarray:
    """Per-mode damping ratios: a scalar for every elastic mode, or one value per mode.

    Rigid modes get 0 (their FRF is the mass line whatever the damping).  Elastic modes need
    ``0 < zeta < 1``: an undamped resonance inside a band has an infinite band integral.
    """
    z = np.asarray(zeta, float)
    if z.ndim == 0:
        z = np.full(modes.n_modes, float(z))
    if z.shape != (modes.n_modes,):
        raise InputError(
            f"zeta must be a scalar or have one value per mode ({modes.n_modes})", where="zeta"
        )
    el = ~np.asarray(modes.rigid, bool)
    ze = z[el]
    if not (np.all(np.isfinite(ze)) and np.all(ze > 0) and np.all(ze < 1)):
        raise InputError(
            "modal damping of elastic modes must satisfy 0 < zeta < 1",
            where="zeta",
            fix="give e.g. zeta = 0.005 (an undamped resonance has an infinite band integral)",
        )
    return np.where(el, z, 0.0)


def _point(modes: Modes, name: str, where: str) -> Any:
    pts = modes.structure.points
    if name not in pts:
        known = ", ".join(sorted(pts)) or "(none)"
        raise InputError(f"unknown point {name!r}", where=where, fix=f"known points: {known}")
    return pts[name]


def output_modal(modes: Modes, observe: Sequence[str]) -> np.ndarray:
    """Output rows ``T_p phi`` of the observed points, (npt * 3, m), m per unit modal coordinate.

    Rows are ordered point by point, axes x, y, z.
    """
    if isinstance(observe, str):
        observe = [observe]
    if len(observe) == 0:
        raise InputError("no observed point", where="observe", fix="name at least one point")
    rows = [
        np.asarray(_point(modes, n, f"observe[{i}]").translation, float) @ modes.phi
        for i, n in enumerate(observe)
    ]
    return np.concatenate(rows, axis=0)


def input_modal(modes: Modes, at: str, direction: Any, where: str = "at") -> np.ndarray:
    """Generalized force per newton on each mode, ``phi^T T_at^T d``, (m,)."""
    d = parse_direction(direction, where=f"{where}: direction")
    tmap = np.asarray(_point(modes, at, where).translation, float)
    return modes.phi.T @ (tmap.T @ d)


def _frequencies(freq_hz: Any, where: str) -> np.ndarray:
    f = np.atleast_1d(np.asarray(freq_hz, float))
    if f.ndim != 1 or f.size < 1 or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise InputError("frequencies must be a 1-D array of finite values >= 0 Hz", where=where)
    if f.size > MAX_FREQUENCIES:
        raise InputError(f"{f.size:,} frequencies is more than {MAX_FREQUENCIES:,}", where=where)
    return f


@dataclass(frozen=True)
class AccelerationFRF:
    """Acceleration FRFs of observed points per newton at one input.

    Attributes
    ----------
    points : observed point names
    axes : ("x", "y", "z")
    at : input point name
    direction : (3,) unit force direction
    freq_hz : (nf,) frequencies, Hz
    accel_per_n : (npt, 3, nf) complex acceleration per newton, (m/s^2)/N
    """

    points: tuple[str, ...]
    axes: tuple[str, ...]
    at: str
    direction: np.ndarray
    freq_hz: np.ndarray
    accel_per_n: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: magnitude and phase per point and axis."""
        return {
            "at": self.at,
            "direction": [float(v) for v in self.direction],
            "freq_hz": finite_list(self.freq_hz),
            "unit": "(m/s^2)/N",
            "points": {
                p: {
                    a: {
                        "magnitude": finite_list(np.abs(self.accel_per_n[i, k])),
                        "phase_rad": finite_list(np.angle(self.accel_per_n[i, k])),
                    }
                    for k, a in enumerate(self.axes)
                }
                for i, p in enumerate(self.points)
            },
        }

    def to_xarray(self) -> Any:
        """xarray.DataArray (point, axis, freq) of the complex FRF, units in attrs."""
        import xarray as xr

        return xr.DataArray(
            self.accel_per_n,
            dims=("point", "axis", "freq"),
            coords={
                "point": list(self.points),
                "axis": list(self.axes),
                "freq": ("freq", self.freq_hz, {"units": "Hz"}),
            },
            name="accel_per_n",
            attrs={"units": "(m/s^2)/N", "at": self.at, "direction": list(self.direction)},
        )

    def plot(self, point: str | None = None, ax: Any = None) -> Any:
        """Magnitude of the FRF per axis (log-log); returns a matplotlib Figure.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.frequency import plot_frf

        return plot_frf(self, point=point, ax=ax)


def frf(
    modes: Modes,
    zeta: float | np.ndarray,
    observe: Sequence[str],
    at: str,
    direction: Any,
    freq_hz: Any,
) -> AccelerationFRF:
    """Acceleration FRFs at observed points per newton at ``at`` along ``direction``.

    Parameters
    ----------
    modes : Modes (mass-normalised, rigid modes included)
    zeta : modal damping ratio of the elastic modes, scalar or (m,)
    observe : names of the observed points (3 axes each)
    at : name of the input point
    direction : force direction (``"x"``, ``"-z"``, ``"1 0 0"`` or a 3-vector)
    freq_hz : (nf,) frequencies, Hz (>= 0)

    Returns
    -------
    AccelerationFRF with ``accel_per_n`` of shape (npt, 3, nf), (m/s^2)/N.
    """
    z = damping_ratios(modes, zeta)
    f = _frequencies(freq_hz, "freq_hz")
    obs = [observe] if isinstance(observe, str) else list(observe)
    out = output_modal(modes, obs)
    inp = input_modal(modes, at, direction)
    h = acceleration_frf(modes.omega, z, out, inp[None, :], 2.0 * np.pi * f)[:, 0, :]
    return AccelerationFRF(
        points=tuple(obs),
        axes=AXIS_NAMES,
        at=at,
        direction=parse_direction(direction, where="direction"),
        freq_hz=f,
        accel_per_n=h.reshape(len(obs), 3, f.size),
    )


@dataclass(frozen=True)
class HarmonicResponse:
    """Steady-state acceleration of observed points to harmonic force lines at one input.

    ``a(t) = Re(sum_k A_k e^{i 2 pi f_k t})`` per axis.

    Attributes
    ----------
    points, axes : observed point names and ("x", "y", "z")
    freq_hz : (nl,) line frequencies, Hz
    accel_mps2 : (npt, 3, nl) complex acceleration phasors (peak), m/s^2
    rms_mps2 : (npt, 3) RMS over a long time (lines at distinct frequencies are orthogonal;
        lines at one frequency add as phasors), m/s^2
    """

    points: tuple[str, ...]
    axes: tuple[str, ...]
    freq_hz: np.ndarray
    accel_mps2: np.ndarray
    rms_mps2: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: amplitude and phase per line, point and axis; the RMS."""
        return {
            "freq_hz": finite_list(self.freq_hz),
            "points": {
                p: {
                    a: {
                        "amplitude_mps2": finite_list(np.abs(self.accel_mps2[i, k])),
                        "phase_rad": finite_list(np.angle(self.accel_mps2[i, k])),
                        "rms_mps2": float(self.rms_mps2[i, k]),
                    }
                    for k, a in enumerate(self.axes)
                }
                for i, p in enumerate(self.points)
            },
        }

    def to_xarray(self) -> Any:
        """xarray.Dataset with the phasors (point, axis, line) and the RMS (point, axis)."""
        import xarray as xr

        return xr.Dataset(
            {
                "accel_mps2": (("point", "axis", "line"), self.accel_mps2, {"units": "m/s^2"}),
                "rms_mps2": (("point", "axis"), self.rms_mps2, {"units": "m/s^2"}),
            },
            coords={
                "point": list(self.points),
                "axis": list(self.axes),
                "freq_hz": ("line", self.freq_hz, {"units": "Hz"}),
            },
        )

    def plot(self, point: str | None = None, ax: Any = None) -> Any:
        """Amplitude of each line per axis; returns a matplotlib Figure.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.frequency import plot_harmonic

        return plot_harmonic(self, point=point, ax=ax)


def harmonic_response(
    modes: Modes,
    zeta: float | np.ndarray,
    observe: Sequence[str],
    at: str,
    direction: Any,
    lines: HarmonicLines,
) -> HarmonicResponse:
    """Steady-state acceleration at observed points to force lines ``A cos(2 pi f t + phase)``.

    Parameters
    ----------
    modes : Modes
    zeta : modal damping ratio, scalar or (m,)
    observe : observed point names
    at : input point name
    direction : force direction
    lines : the force lines (amplitude N peak, frequency Hz, phase rad)
    """
    z = damping_ratios(modes, zeta)
    obs = [observe] if isinstance(observe, str) else list(observe)
    out = output_modal(modes, obs)
    inp = input_modal(modes, at, direction)
    h = acceleration_frf(modes.omega, z, out, inp[None, :], 2.0 * np.pi * lines.freq_hz)[:, 0]
    phasor = h * (lines.amplitude_n * np.exp(1j * np.asarray(lines.phase_rad)))[None, :]
    key = same_frequency_index(lines.freq_hz)
    summed = np.zeros((int(key.max()) + 1, phasor.shape[0]), complex)
    np.add.at(summed, key, phasor.T)
    summed = summed.T
    rms = np.sqrt(np.sum(np.abs(summed) ** 2, axis=1) / 2.0)
    return HarmonicResponse(
        points=tuple(obs),
        axes=AXIS_NAMES,
        freq_hz=lines.freq_hz,
        accel_mps2=phasor.reshape(len(obs), 3, -1),
        rms_mps2=rms.reshape(len(obs), 3),
    )


@dataclass(frozen=True)
class BandResponse:
    """Band RMS acceleration of observed points under a set of loads, with contributions.

    Attributes
    ----------
    points, axes : observed point names; ("x", "y", "z")
    sources : load names; ``groups``: the independent group of each source (its coherent group,
        or its own name)
    group_names : the distinct groups
    center_hz, lower_hz, upper_hz : (nb,) bands, Hz
    mode_freq_hz : (m,) natural frequencies of the modes used, Hz
    rms_mps2 : (npt, 3, nb) band RMS acceleration, m/s^2
    source_rms_mps2 : (npt, 3, nb, ns) each source acting alone, m/s^2
    source_share : (npt, 3, nb, ns) signed fraction of the band mean square (sums to 1)
    group_rms_mps2 : (npt, 3, nb, ng) each independent group, m/s^2
    mode_rms_mps2 : (npt, 3, nb, m) each mode alone under all sources, m/s^2
    mode_share : (npt, 3, nb, m) signed fraction of the band mean square (sums to 1)
    quad_nodes, quad_error, near_modes, refinements : band-integration diagnostics
    warnings : messages (lines outside the bands, truncation, convergence)
    """

    points: tuple[str, ...]
    axes: tuple[str, ...]
    sources: tuple[str, ...]
    groups: tuple[str, ...]
    group_names: tuple[str, ...]
    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray
    mode_freq_hz: np.ndarray
    rms_mps2: np.ndarray
    source_rms_mps2: np.ndarray
    source_share: np.ndarray
    group_rms_mps2: np.ndarray
    mode_rms_mps2: np.ndarray
    mode_share: np.ndarray
    quad_nodes: int
    quad_error: np.ndarray
    near_modes: np.ndarray
    refinements: int
    warnings: tuple[str, ...] = field(default=())

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: band RMS per point and axis, sources alone, diagnostics."""
        return {
            "center_hz": finite_list(self.center_hz),
            "lower_hz": finite_list(self.lower_hz),
            "upper_hz": finite_list(self.upper_hz),
            "unit": "m/s^2 RMS",
            "points": {
                p: {
                    "rms_mps2_axis": {
                        a: finite_list(self.rms_mps2[i, k]) for k, a in enumerate(self.axes)
                    },
                    "sources": {
                        s: {
                            a: finite_list(self.source_rms_mps2[i, k, :, j])
                            for k, a in enumerate(self.axes)
                        }
                        for j, s in enumerate(self.sources)
                    },
                }
                for i, p in enumerate(self.points)
            },
            "quadrature": {
                "nodes": self.quad_nodes,
                "max_error": float(np.max(self.quad_error, initial=0.0)),
                "refinements": self.refinements,
            },
            "warnings": list(self.warnings),
        }

    def to_xarray(self) -> Any:
        """xarray.Dataset with dims point/axis/band/source/group/mode, units in attrs."""
        import xarray as xr

        a = ("point", "axis", "band")
        return xr.Dataset(
            {
                "rms_mps2": (a, self.rms_mps2, {"units": "m/s^2", "long_name": "band RMS"}),
                "source_rms_mps2": (
                    (*a, "source"),
                    self.source_rms_mps2,
                    {"units": "m/s^2", "long_name": "band RMS of the source acting alone"},
                ),
                "source_share": (
                    (*a, "source"),
                    self.source_share,
                    {"units": "1", "long_name": "signed fraction of the band mean square"},
                ),
                "group_rms_mps2": ((*a, "group"), self.group_rms_mps2, {"units": "m/s^2"}),
                "mode_rms_mps2": (
                    (*a, "mode"),
                    self.mode_rms_mps2,
                    {"units": "m/s^2", "long_name": "band RMS of the mode alone"},
                ),
                "mode_share": (
                    (*a, "mode"),
                    self.mode_share,
                    {"units": "1", "long_name": "signed fraction of the band mean square"},
                ),
            },
            coords={
                "point": list(self.points),
                "axis": list(self.axes),
                "band": np.arange(self.center_hz.size),
                "center_hz": ("band", self.center_hz, {"units": "Hz"}),
                "lower_hz": ("band", self.lower_hz, {"units": "Hz"}),
                "upper_hz": ("band", self.upper_hz, {"units": "Hz"}),
                "source": list(self.sources),
                "source_group": ("source", list(self.groups)),
                "group": list(self.group_names),
                "mode": np.arange(self.mode_freq_hz.size),
                "mode_freq_hz": ("mode", self.mode_freq_hz, {"units": "Hz"}),
            },
            attrs={"quad_nodes": self.quad_nodes, "warnings": "; ".join(self.warnings)},
        )

    def plot(self, point: str | None = None, ax: Any = None) -> Any:
        """Band RMS per axis at one point (log-log); returns a matplotlib Figure.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.frequency import plot_band_response

        return plot_band_response(self, point=point, ax=ax)


def _shares(share: np.ndarray, total: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(total > 0, share / np.where(total > 0, total, 1.0), 0.0)


def band_response(
    modes: Modes,
    zeta: float | np.ndarray,
    observe: Sequence[str],
    loads: Sequence[Load],
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    *,
    center_hz: np.ndarray | None = None,
    order: int | None = None,
    rtol: float = 1e-9,
    workers: int | None = None,
    contributions: bool = True,
    weight: Any = None,
    weight_breakpoints_hz: Sequence[float] | np.ndarray = (),
) -> BandResponse:
    """Band RMS acceleration at observed points under force spectra at named points.

    Parameters
    ----------
    modes : Modes (mass-normalised; rigid modes included: their term is the mass line)
    zeta : modal damping ratio of the elastic modes, scalar or (m,)
    observe : observed point names (3 axes each)
    loads : the sources (see :class:`Load`); names unique
    lower_hz, upper_hz : (nb,) band edges, Hz
    center_hz : (nb,) band centres for output (default the geometric mean of the edges)
    order, rtol, workers, contributions : see :func:`band_mean_squares`
    weight, weight_breakpoints_hz : a real weight per output row (3 per observed point, x y z)
        and its breakpoints, Hz; see :func:`band_mean_squares` (e.g. ``|T_axis(f)|^2`` of an
        isolator on the point: the RMS is then the isolated platform's)

    Returns
    -------
    BandResponse (m/s^2 RMS per band, contributions per source and per mode).
    """
    z = damping_ratios(modes, zeta)
    obs = [observe] if isinstance(observe, str) else list(observe)
    out = output_modal(modes, obs)
    names = [ld.name for ld in loads]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise InputError(f"source name {dup!r} is used twice", where="loads")
    inp = (
        np.array(
            [
                input_modal(modes, ld.at, ld.direction, f"loads[{i}].at")
                for i, ld in enumerate(loads)
            ]
        )
        if loads
        else np.zeros((0, modes.n_modes))
    )
    labels = [ld.group if ld.group is not None else ld.name for ld in loads]
    group_names = list(dict.fromkeys(labels))
    gidx = [group_names.index(g) for g in labels]
    lo = np.asarray(lower_hz, float)
    hi = np.asarray(upper_hz, float)
    arr = band_mean_squares(
        modes.omega,
        z,
        out,
        inp,
        [ld.spectrum for ld in loads],
        lo,
        hi,
        groups=gidx,
        order=order,
        rtol=rtol,
        workers=workers,
        contributions=contributions,
        weight=weight,
        weight_breakpoints_hz=weight_breakpoints_hz,
    )
    warnings = list(arr.warnings)
    unstable = np.asarray(modes.unstable, bool)
    if unstable.any():
        g = np.asarray(modes.growth_rate, float)[unstable]
        warnings.append(
            f"{int(unstable.sum())} unstable mode(s) (growth rate up to {g.max():.3g} rad/s): "
            "no steady state exists; their terms are taken as the mass line, which is off by "
            f"(growth rate / w)^2, {(g.max() / (2 * np.pi * lo.min())) ** 2:.1e} at the lowest band"
        )
    fm = modes.freq_hz
    elastic = fm[~np.asarray(modes.rigid, bool)]
    top_band = float(hi[np.any(arr.total > 0, axis=0)].max(initial=0.0))
    if top_band > 0 and (elastic.size == 0 or 1.5 * top_band > elastic.max()):
        highest = f"{elastic.max():.4g} Hz" if elastic.size else "none"
        warnings.append(
            f"modes end at {highest} but bands with response reach {top_band:.4g} Hz: keep "
            "modes to at least 1.5 times the highest band (modal truncation underestimates "
            "the response there)"
        )
    npt = len(obs)
    nb = lo.size

    def shape(a: np.ndarray) -> np.ndarray:  # (p, k, nb) -> (npt, 3, nb, k)
        return np.moveaxis(a.reshape(npt, 3, a.shape[1], nb), 2, 3)

    total = arr.total.reshape(npt, 3, nb)
    tot4 = total[..., None]
    return BandResponse(
        points=tuple(obs),
        axes=AXIS_NAMES,
        sources=tuple(names),
        groups=tuple(labels),
        group_names=tuple(group_names),
        center_hz=np.sqrt(lo * hi) if center_hz is None else np.asarray(center_hz, float),
        lower_hz=lo,
        upper_hz=hi,
        mode_freq_hz=fm,
        rms_mps2=np.sqrt(np.maximum(total, 0.0)),
        source_rms_mps2=np.sqrt(np.maximum(shape(arr.source_alone), 0.0)),
        source_share=_shares(shape(arr.source_share), tot4),
        group_rms_mps2=np.sqrt(np.maximum(shape(arr.group), 0.0)),
        mode_rms_mps2=np.sqrt(np.maximum(shape(arr.mode_alone), 0.0)),
        mode_share=_shares(shape(arr.mode_share), tot4),
        quad_nodes=arr.quad_nodes,
        quad_error=arr.quad_error,
        near_modes=arr.near_modes,
        refinements=arr.refinements,
        warnings=tuple(warnings),
    )
