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

Band integration is converged, not sampled: composite Gauss-Legendre quadrature of order
``order`` on intervals whose breakpoints are the band edges, every natural frequency ``f_j``
inside the band and the geometric grading ``f_j +- 3^k gamma_j`` (``gamma_j = zeta_j f_j``, the
half-power half-width) out to twice the band width, the breakpoints of every spectrum, and the
band's midpoint.  Convergence is checked, per band, on ``int |r_j|^2 df`` of every mode within
three band widths (the others are smooth there) and on every spectrum's ``int S df``: the rule
of order ``2 order`` on the same intervals, and the exact power of the spectrum; a band that
fails has its intervals halved (up to :data:`MAX_REFINEMENTS` times) and a band that still fails
is named in ``warnings``.

Each band's response is summed in amplitude at the nodes (never from squared sums, so a
response that is small by cancellation between modes keeps its relative accuracy): the modes
whose natural frequency lies within two band widths of the band node by node, the others --
smooth over the band -- through a 16-point Chebyshev interpolant of their sum, each far mode's
interpolant checked at 49 points across the band to 1e-14 of the mode's size there (a mode that
fails is summed node by node).  Harmonic lines are evaluated exactly at their frequencies.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from microg._vectors import AXIS_NAMES, parse_direction
from microg.dynamics.modes import Modes
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
#: largest number of harmonic lines over all sources
MAX_LINES = 100_000
#: largest number of interval halvings of a band that fails the convergence check
MAX_REFINEMENTS = 6
#: grading ratio of the breakpoints around a natural frequency
_GRADING = 3.0
#: lines closer than this relative spacing are one frequency (phasors of a group add)
_SAME_FREQ_RTOL = 1e-12


def _readonly(a: Any, dtype: type = float) -> np.ndarray:
    out: np.ndarray = np.array(a, dtype=dtype)
    out.setflags(write=False)
    return out


# ------------------------------------------------------------------------------ spectra


@dataclass(frozen=True, eq=False)
class HarmonicLines:
    """Sinusoidal force lines ``A_k cos(2 pi f_k t + phase_k)``.

    Attributes
    ----------
    amplitude_n : (nl,) peak amplitudes, N (>= 0)
    freq_hz : (nl,) frequencies, Hz (> 0)
    phase_rad : (nl,) phases, rad (default 0)
    """

    amplitude_n: np.ndarray
    freq_hz: np.ndarray
    phase_rad: np.ndarray | None = None

    def __post_init__(self) -> None:
        a = np.atleast_1d(np.asarray(self.amplitude_n, float))
        f = np.atleast_1d(np.asarray(self.freq_hz, float))
        p = np.zeros_like(f) if self.phase_rad is None else np.atleast_1d(self.phase_rad)
        p = np.asarray(p, float)
        if a.ndim != 1 or a.shape != f.shape or p.shape != f.shape or a.size < 1:
            raise InputError(
                "amplitude, frequency and phase need one value per line", where="harmonic"
            )
        if not (np.all(np.isfinite(a)) and np.all(a >= 0)):
            raise InputError("amplitudes must be finite and >= 0", where="harmonic.amplitude")
        if not (np.all(np.isfinite(f)) and np.all(f > 0)):
            raise InputError("frequencies must be finite and > 0", where="harmonic.frequency")
        if not np.all(np.isfinite(p)):
            raise InputError("phases must be finite", where="harmonic.phase")
        object.__setattr__(self, "amplitude_n", _readonly(a))
        object.__setattr__(self, "freq_hz", _readonly(f))
        object.__setattr__(self, "phase_rad", _readonly(p))

    kind = "harmonic"

    @property
    def breakpoints_hz(self) -> np.ndarray:
        """Spectral breakpoints (none: lines are evaluated exactly)."""
        return np.zeros(0)

    @property
    def mean_square_n2(self) -> float:
        """Mean square of the force, N^2 (sum of A^2 / 2)."""
        return float(np.sum(self.amplitude_n**2) / 2.0)

    def psd_at(self, freq_hz: np.ndarray) -> np.ndarray:
        """Continuous PSD part: zero everywhere (lines carry no density), N^2/Hz."""
        return np.zeros(np.shape(freq_hz))

    def power_n2(self, lower_hz: np.ndarray, upper_hz: np.ndarray) -> np.ndarray:
        """Mean square of the lines with ``lower <= f < upper``, N^2, per interval."""
        lo = np.atleast_1d(np.asarray(lower_hz, float))[:, None]
        hi = np.atleast_1d(np.asarray(upper_hz, float))[:, None]
        inside = (self.freq_hz[None, :] >= lo) & (self.freq_hz[None, :] < hi)
        return inside @ (self.amplitude_n**2 / 2.0)


@dataclass(frozen=True, eq=False)
class BandForceSpectrum:
    """Force RMS per frequency band, flat (constant PSD) inside each band.

    Attributes
    ----------
    lower_hz, upper_hz : (nb,) band edges, Hz, increasing, bands not overlapping
    rms_n : (nb,) RMS force in each band, N (>= 0)
    center_hz : (nb,) nominal centres, Hz (default the geometric mean of the edges)
    """

    lower_hz: np.ndarray
    upper_hz: np.ndarray
    rms_n: np.ndarray
    center_hz: np.ndarray | None = None

    kind = "bands"

    def __post_init__(self) -> None:
        lo = np.atleast_1d(np.asarray(self.lower_hz, float))
        hi = np.atleast_1d(np.asarray(self.upper_hz, float))
        r = np.atleast_1d(np.asarray(self.rms_n, float))
        if lo.ndim != 1 or lo.shape != hi.shape or r.shape != lo.shape or lo.size < 1:
            raise InputError("need one lower edge, upper edge and RMS per band", where="bands")
        if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo > 0)):
            raise InputError("band edges must be finite and > 0", where="bands")
        if not np.all(hi > lo):
            raise InputError("each band needs upper > lower", where="bands")
        if np.any(lo[1:] < hi[:-1] * (1.0 - 1e-12)):
            raise InputError(
                "bands must be in increasing order and not overlap", where="bands.center_hz"
            )
        if not (np.all(np.isfinite(r)) and np.all(r >= 0)):
            raise InputError("band RMS values must be finite and >= 0", where="bands.rms")
        c = np.sqrt(lo * hi) if self.center_hz is None else np.asarray(self.center_hz, float)
        object.__setattr__(self, "lower_hz", _readonly(lo))
        object.__setattr__(self, "upper_hz", _readonly(hi))
        object.__setattr__(self, "rms_n", _readonly(r))
        object.__setattr__(self, "center_hz", _readonly(c))

    @property
    def breakpoints_hz(self) -> np.ndarray:
        """Band edges (the PSD jumps there), Hz."""
        return np.unique(np.r_[self.lower_hz, self.upper_hz])

    @property
    def level_n2_per_hz(self) -> np.ndarray:
        """(nb,) flat PSD level in each band, N^2/Hz."""
        return self.rms_n**2 / (self.upper_hz - self.lower_hz)

    @property
    def mean_square_n2(self) -> float:
        """Total mean square of the force, N^2."""
        return float(np.sum(self.rms_n**2))

    def psd_at(self, freq_hz: np.ndarray) -> np.ndarray:
        """PSD at ``freq_hz``, N^2/Hz (bands closed below, open above)."""
        f = np.asarray(freq_hz, float)
        i = np.searchsorted(self.lower_hz, f, side="right") - 1
        ic = np.clip(i, 0, self.lower_hz.size - 1)
        inside = (i >= 0) & (f < self.upper_hz[ic])
        return np.where(inside, self.level_n2_per_hz[ic], 0.0)

    def power_n2(self, lower_hz: np.ndarray, upper_hz: np.ndarray) -> np.ndarray:
        """Exact integral of the PSD over each ``[lower, upper]``, N^2."""
        lo = np.atleast_1d(np.asarray(lower_hz, float))[:, None]
        hi = np.atleast_1d(np.asarray(upper_hz, float))[:, None]
        overlap = np.clip(
            np.minimum(hi, self.upper_hz[None]) - np.maximum(lo, self.lower_hz[None]), 0, None
        )
        return overlap @ self.level_n2_per_hz


@dataclass(frozen=True, eq=False)
class ForcePSD:
    """Force PSD table, interpolated log-log (a power law between points).

    Attributes
    ----------
    freq_hz : (np,) strictly increasing frequencies, Hz (> 0), at least 2
    value_n2_per_hz : (np,) one-sided PSD, N^2/Hz (>= 0); a segment with a zero end is linear;
        zero outside ``[freq_hz[0], freq_hz[-1]]``
    """

    freq_hz: np.ndarray
    value_n2_per_hz: np.ndarray

    kind = "psd"

    def __post_init__(self) -> None:
        f = np.atleast_1d(np.asarray(self.freq_hz, float))
        v = np.atleast_1d(np.asarray(self.value_n2_per_hz, float))
        if f.ndim != 1 or f.shape != v.shape or f.size < 2:
            raise InputError("need at least 2 (frequency, value) points", where="psd")
        if not (np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.diff(f) > 0)):
            raise InputError(
                "frequencies must be finite, > 0 and strictly increasing", where="psd.frequency_hz"
            )
        if not (np.all(np.isfinite(v)) and np.all(v >= 0)):
            raise InputError("PSD values must be finite and >= 0", where="psd.value")
        object.__setattr__(self, "freq_hz", _readonly(f))
        object.__setattr__(self, "value_n2_per_hz", _readonly(v))

    @property
    def breakpoints_hz(self) -> np.ndarray:
        """Table frequencies (the interpolant has kinks there), Hz."""
        return self.freq_hz

    def _segments(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        f0, f1 = self.freq_hz[:-1], self.freq_hz[1:]
        v0, v1 = self.value_n2_per_hz[:-1], self.value_n2_per_hz[1:]
        loglog = (v0 > 0) & (v1 > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            alpha = np.where(loglog, np.log(v1 / v0) / np.log(f1 / f0), 0.0)
        return f0, f1, v0, v1, alpha

    def psd_at(self, freq_hz: np.ndarray) -> np.ndarray:
        """PSD at ``freq_hz``, N^2/Hz (log-log interpolation, zero outside the table)."""
        f = np.asarray(freq_hz, float)
        f0, f1, v0, v1, alpha = self._segments()
        i = np.clip(np.searchsorted(self.freq_hz, f, side="right") - 1, 0, f0.size - 1)
        inside = (f >= self.freq_hz[0]) & (f <= self.freq_hz[-1])
        fs = np.where(inside, f, f0[i])
        loglog = (v0[i] > 0) & (v1[i] > 0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            pw = v0[i] * (fs / f0[i]) ** alpha[i]
        lin = v0[i] + (v1[i] - v0[i]) * (fs - f0[i]) / (f1[i] - f0[i])
        return np.where(inside, np.where(loglog, pw, lin), 0.0)

    def power_n2(self, lower_hz: np.ndarray, upper_hz: np.ndarray) -> np.ndarray:
        """Exact integral of the interpolated PSD over each ``[lower, upper]``, N^2.

        On a power-law segment ``S = v0 (f/f0)^alpha``::

            int_a^b S df = v0 f0 x_a^beta ln(x_b/x_a) expm1(beta L)/(beta L),
            beta = alpha + 1, L = ln(x_b/x_a), x = f/f0

        (stable through ``alpha = -1``); a linear segment by the trapezoid.
        """
        lo = np.atleast_1d(np.asarray(lower_hz, float))[:, None]
        hi = np.atleast_1d(np.asarray(upper_hz, float))[:, None]
        f0, f1, v0, v1, alpha = self._segments()
        a = np.clip(lo, f0[None], f1[None])
        b = np.clip(hi, f0[None], f1[None])
        b = np.maximum(a, b)
        loglog = (v0 > 0) & (v1 > 0)
        xa, xb = a / f0, b / f0
        L = np.log(xb / xa)
        beta = alpha + 1.0
        bl = beta * L
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            ratio = np.where(np.abs(bl) > 1e-12, np.expm1(bl) / np.where(bl == 0, 1.0, bl), 1.0)
            pw = v0 * f0 * xa**beta * L * ratio
        slope = (v1 - v0) / (f1 - f0)
        va = v0 + slope * (a - f0)
        vb = v0 + slope * (b - f0)
        lin = 0.5 * (va + vb) * (b - a)
        seg = np.where(loglog, np.where(b > a, pw, 0.0), lin)
        return np.sum(seg, axis=1)


ForceSpectrum = HarmonicLines | BandForceSpectrum | ForcePSD


@dataclass(frozen=True, eq=False)
class Load:
    """A force spectrum applied at a named point along a direction.

    Attributes
    ----------
    name : source name (unique within an analysis)
    at : name of the point of the structure where the force acts
    direction : (3,) direction of the force in the station frame (normalised here)
    spectrum : :class:`HarmonicLines`, :class:`BandForceSpectrum` or :class:`ForcePSD`
    group : coherent group (sources of one group add coherently); None: independent
    """

    name: str
    at: str
    direction: np.ndarray
    spectrum: ForceSpectrum
    group: str | None = None

    def __post_init__(self) -> None:
        d = parse_direction(self.direction, where=f"load {self.name!r}: direction")
        object.__setattr__(self, "direction", _readonly(d))


# ---------------------------------------------------------------------------- FRF kernels


def _factor(wj: np.ndarray, z: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real and imaginary parts of r = -w^2 / (wj^2 - w^2 + 2 i z wj w), broadcasting."""
    w2 = w * w
    d_re = wj * wj - w2
    d_im = 2.0 * z * wj * w
    den = d_re * d_re + d_im * d_im
    with np.errstate(divide="ignore", invalid="ignore"):
        re = -w2 * d_re / den
        im = w2 * d_im / den
    zero = den == 0  # only at w = 0 (and w_j = 0): the limit is 1 for rigid, 0 for elastic
    if np.any(zero):
        rigid_limit = np.broadcast_to(wj == 0, re.shape)
        re = np.where(zero, np.where(rigid_limit, 1.0, 0.0), re)
        im = np.where(zero, 0.0, im)
    return re, im


def _factor_parts(
    omega_modes: np.ndarray, zeta: np.ndarray, omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Real and imaginary parts of r_j(w) = -w^2 / (w_j^2 - w^2 + 2 i zeta_j w_j w), (m, nf)."""
    return _factor(omega_modes[:, None], zeta[:, None], omega[None, :])


def modal_frf_factor(
    omega_modes: np.ndarray, zeta: np.ndarray | float, omega: np.ndarray
) -> np.ndarray:
    """Modal acceleration factors ``r_j(w) = -w^2 / (w_j^2 - w^2 + 2 i zeta_j w_j w)``.

    Parameters
    ----------
    omega_modes : (m,) natural frequencies, rad/s (0 for rigid modes: r = 1, the mass line)
    zeta : (m,) or scalar modal damping ratios
    omega : (nf,) excitation frequencies, rad/s (>= 0; r(0) = 1 for rigid modes, 0 otherwise)

    Returns
    -------
    (m, nf) complex: modal acceleration per unit modal force.
    """
    wm = np.asarray(omega_modes, float)
    z = np.broadcast_to(np.asarray(zeta, float), wm.shape)
    re, im = _factor_parts(wm, z, np.atleast_1d(np.asarray(omega, float)))
    return re + 1j * im


def acceleration_frf(
    omega_modes: np.ndarray,
    zeta: np.ndarray | float,
    out_modal: np.ndarray,
    in_modal: np.ndarray,
    omega: np.ndarray,
) -> np.ndarray:
    """Acceleration FRFs ``H[p, s, f] = sum_j out[p, j] in[s, j] r_j(w_f)`` (module docstring).

    Parameters
    ----------
    omega_modes : (m,) natural frequencies, rad/s
    zeta : (m,) or scalar modal damping ratios
    out_modal : (p, m) output rows: translation of each output coordinate per unit modal
        coordinate, m (``T_out @ phi``)
    in_modal : (s, m) generalized force of each input per newton on each mode (``phi^T T_in^T d``)
    omega : (nf,) excitation frequencies, rad/s

    Returns
    -------
    (p, s, nf) complex, (m/s^2)/N.
    """
    r = modal_frf_factor(omega_modes, zeta, omega)  # (m, nf)
    out = np.asarray(out_modal, float)
    inp = np.asarray(in_modal, float)
    c = (out[:, None, :] * inp[None, :, :]).reshape(-1, out.shape[1])
    return (c @ r).reshape(out.shape[0], inp.shape[0], -1)


# ------------------------------------------------------------------- geometry from Modes


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


def _clean(a: np.ndarray) -> list[Any]:
    return [float(v) if np.isfinite(v) else None for v in np.ravel(a)]


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
            "freq_hz": _clean(self.freq_hz),
            "unit": "(m/s^2)/N",
            "points": {
                p: {
                    a: {
                        "magnitude": _clean(np.abs(self.accel_per_n[i, k])),
                        "phase_rad": _clean(np.angle(self.accel_per_n[i, k])),
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

    def plot(self, point: str | None = None) -> Any:
        """Magnitude of the FRF per axis (log-log); returns a matplotlib Figure."""
        from microg.plotting.frequency import plot_frf

        return plot_frf(self, point=point)


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
            "freq_hz": _clean(self.freq_hz),
            "points": {
                p: {
                    a: {
                        "amplitude_mps2": _clean(np.abs(self.accel_mps2[i, k])),
                        "phase_rad": _clean(np.angle(self.accel_mps2[i, k])),
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

    def plot(self, point: str | None = None) -> Any:
        """Amplitude of each line per axis; returns a matplotlib Figure."""
        from microg.plotting.frequency import plot_harmonic

        return plot_harmonic(self, point=point)


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
    key = _same_frequency_index(lines.freq_hz)
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


def _same_frequency_index(freq: np.ndarray, group: np.ndarray | None = None) -> np.ndarray:
    """Index of the distinct (group, frequency) of each line; equal within _SAME_FREQ_RTOL."""
    g = np.zeros(freq.size, int) if group is None else np.asarray(group, int)
    order = np.lexsort((freq, g))
    fs, gs = freq[order], g[order]
    new = np.r_[True, (gs[1:] != gs[:-1]) | (np.diff(fs) > _SAME_FREQ_RTOL * fs[1:])]
    key_sorted = np.cumsum(new) - 1
    key = np.empty(freq.size, int)
    key[order] = key_sorted
    return key


# ------------------------------------------------------------------------- band quadrature


@dataclass(frozen=True)
class BandQuadrature:
    """Composite Gauss-Legendre nodes over a set of bands.

    Attributes
    ----------
    freq_hz : (N,) nodes, Hz, sorted by band then frequency
    weight_hz : (N,) weights, Hz (``sum weight * g(f)`` approximates ``int g df``)
    band : (N,) index of the band of each node
    start : (nb + 1,) ``freq_hz[start[b]:start[b+1]]`` are the nodes of band b
    intervals : (K, 3) rows (band, lo_hz, hi_hz) of the sub-intervals
    order : Gauss-Legendre points per interval
    """

    freq_hz: np.ndarray
    weight_hz: np.ndarray
    band: np.ndarray
    start: np.ndarray
    intervals: np.ndarray
    order: int


def _gauss_nodes(intervals: np.ndarray, order: int, nb: int) -> BandQuadrature:
    x, w = np.polynomial.legendre.leggauss(order)
    band = intervals[:, 0].astype(int)
    mid = 0.5 * (intervals[:, 1] + intervals[:, 2])
    half = 0.5 * (intervals[:, 2] - intervals[:, 1])
    nodes = (mid[:, None] + half[:, None] * x[None, :]).ravel()
    weights = (half[:, None] * w[None, :]).ravel()
    nband = np.repeat(band, order)
    start = np.searchsorted(nband, np.arange(nb + 1), side="left")
    return BandQuadrature(nodes, weights, nband, start, intervals, order)


def _band_intervals(
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    mode_freq_hz: np.ndarray,
    mode_zeta: np.ndarray,
    breakpoints_hz: np.ndarray,
) -> np.ndarray:
    """Sub-intervals (band, lo, hi) of every band, graded around the natural frequencies."""
    nb = lower_hz.size
    width = upper_hz - lower_hz
    el = mode_freq_hz > 0
    f = mode_freq_hz[el]
    gam = mode_zeta[el] * f
    pts_band = [np.arange(nb), np.arange(nb), np.arange(nb)]
    pts = [lower_hz, upper_hz, 0.5 * (lower_hz + upper_hz)]
    if f.size:
        kmax = int(np.ceil(np.log(2.0 * width.max() / gam.min()) / np.log(_GRADING))) + 1
        steps = _GRADING ** np.arange(0, max(kmax, 1))
        offs = np.r_[0.0, steps, -steps]
        cand = (f[:, None] + gam[:, None] * offs[None, :]).ravel()
        reach = (gam[:, None] * np.abs(offs)[None, :]).ravel()
        inside = (
            (cand[None, :] > lower_hz[:, None])
            & (cand[None, :] < upper_hz[:, None])
            & (reach[None, :] <= 2.0 * width[:, None])
        )
        bi, ci = np.nonzero(inside)
        pts_band.append(bi)
        pts.append(cand[ci])
    bp = np.asarray(breakpoints_hz, float)
    if bp.size:
        inside = (bp[None, :] > lower_hz[:, None]) & (bp[None, :] < upper_hz[:, None])
        bi, ci = np.nonzero(inside)
        pts_band.append(bi)
        pts.append(bp[ci])
    band = np.concatenate(pts_band)
    x = np.concatenate(pts)
    order = np.lexsort((x, band))
    band, x = band[order], x[order]
    same = band[1:] == band[:-1]
    length = np.diff(x)
    keep = same & (length > 1e-12 * width[band[:-1]])
    return np.column_stack([band[:-1][keep], x[:-1][keep], x[1:][keep]])


def band_quadrature(
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    mode_freq_hz: np.ndarray,
    mode_zeta: np.ndarray,
    breakpoints_hz: np.ndarray | Sequence[float] = (),
    *,
    order: int = 8,
) -> BandQuadrature:
    """Quadrature nodes for band integrals of modal FRFs (see the module docstring).

    Parameters
    ----------
    lower_hz, upper_hz : (nb,) band edges, Hz (bands may touch, overlap or leave gaps)
    mode_freq_hz : (m,) natural frequencies, Hz (0 for rigid modes: no breakpoints)
    mode_zeta : (m,) modal damping ratios (> 0 for elastic modes)
    breakpoints_hz : extra breakpoints (spectrum discontinuities and kinks), Hz
    order : Gauss-Legendre points per sub-interval
    """
    lo = np.asarray(lower_hz, float)
    hi = np.asarray(upper_hz, float)
    iv = _band_intervals(
        lo,
        hi,
        np.asarray(mode_freq_hz, float),
        np.asarray(mode_zeta, float),
        np.asarray(breakpoints_hz, float),
    )
    return _gauss_nodes(iv, order, lo.size)


def _split(intervals: np.ndarray, bands: np.ndarray) -> np.ndarray:
    """Halve every interval of the given bands."""
    sel = np.isin(intervals[:, 0].astype(int), bands)
    if not np.any(sel):
        return intervals
    iv = intervals[sel]
    mid = 0.5 * (iv[:, 1] + iv[:, 2])
    left = np.column_stack([iv[:, 0], iv[:, 1], mid])
    right = np.column_stack([iv[:, 0], mid, iv[:, 2]])
    new = np.concatenate([intervals[~sel], left, right])
    return new[np.lexsort((new[:, 1], new[:, 0]))]


def _per_band(values: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Sum the last axis of ``values`` over each band's node range, (..., nb)."""
    nb = start.size - 1
    out = np.zeros(values.shape[:-1] + (nb,))
    nonempty = start[1:] > start[:-1]
    if np.any(nonempty):
        sums = np.add.reduceat(values, start[:-1][nonempty], axis=-1)
        out[..., nonempty] = sums
    return out


def _converged_quadrature(
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    omega_modes: np.ndarray,
    zeta: np.ndarray,
    scale: np.ndarray,
    spectra: Sequence[ForceSpectrum],
    order: int,
    rtol: float,
) -> tuple[BandQuadrature, np.ndarray, int, list[str]]:
    """Nodes that pass the convergence check; per-band relative error; refinements; warnings."""
    bps = [s.breakpoints_hz for s in spectra]
    bp = np.unique(np.concatenate(bps)) if bps else np.zeros(0)
    fm = omega_modes / (2.0 * np.pi)
    iv = _band_intervals(lower_hz, upper_hz, fm, zeta, bp)
    nb = lower_hz.size
    active = scale > 0
    wm, zm, sc2 = omega_modes[active], zeta[active], scale[active] ** 2
    exact = np.array([s.power_n2(lower_hz, upper_hz) for s in spectra]).reshape(-1, nb)
    err = np.zeros(nb)
    refinements = 0
    width = upper_hz - lower_hz
    fa = wm / (2.0 * np.pi)
    # modes whose resonance can shape a band; farther modes are smooth over it
    near = (
        (wm[:, None] > 0)
        & (fa[:, None] > lower_hz - 3 * width)
        & (fa[:, None] < upper_hz + 3 * width)
    )
    todo = np.arange(nb)  # bands to (re)check: all, then only those refined
    for attempt in range(MAX_REFINEMENTS + 1):
        sub = iv[np.isin(iv[:, 0].astype(int), todo)]
        q1 = _gauss_nodes(sub, order, nb)
        e = np.zeros(nb)
        if np.any(near[:, todo]):
            q2 = _gauss_nodes(sub, 2 * order, nb)
            diags = []
            for q in (q1, q2):
                jj, nn = np.nonzero(near[:, q.band])
                re, im = _factor(wm[jj], zm[jj], 2.0 * np.pi * q.freq_hz[nn])
                val = (re * re + im * im) * q.weight_hz[nn] * sc2[jj]
                flat = np.bincount(jj * nb + q.band[nn], weights=val, minlength=wm.size * nb)
                diags.append(flat.reshape(wm.size, nb))
            d1, d2 = diags
            big = near & (d2 >= 1e-13 * np.max(d2, axis=0, keepdims=True))
            with np.errstate(divide="ignore", invalid="ignore"):
                rel = np.where(big & (d2 > 0), np.abs(d1 - d2) / d2, 0.0)
            e = rel.max(axis=0)
        if spectra:
            sp = np.array([s.psd_at(q1.freq_hz) for s in spectra]) * q1.weight_hz[None, :]
            got = _per_band(sp, q1.start)
            top = np.max(exact, axis=1, keepdims=True)
            denom = np.maximum(exact, 1e-13 * top)
            with np.errstate(divide="ignore", invalid="ignore"):
                srel = np.where(denom > 0, np.abs(got - exact) / denom, 0.0)
            e = np.maximum(e, srel.max(axis=0))
        err[todo] = e[todo]
        bad = todo[err[todo] > rtol]
        if bad.size == 0 or attempt == MAX_REFINEMENTS:
            break
        iv = _split(iv, bad)
        refinements += 1
        todo = bad
    warnings = []
    bad = np.flatnonzero(err > rtol)
    if bad.size:
        warnings.append(
            f"band integration converged only to {err[bad].max():.1e} (asked {rtol:.0e}) in "
            f"{bad.size} band(s) near {lower_hz[bad[0]]:.4g} Hz"
        )
    return _gauss_nodes(iv, order, nb), err, refinements, warnings


# ------------------------------------------------------------------------ band mean squares


@dataclass(frozen=True)
class BandArrays:
    """Band mean squares of output rows (pure-array result of :func:`band_mean_squares`).

    All mean squares in (output unit)^2, e.g. (m/s^2)^2; shares are mean squares too (they
    sum to ``total``).

    Attributes
    ----------
    total : (p, nb) band mean square of each output row
    source_alone : (p, s, nb) each source acting alone
    source_share : (p, s, nb) ``sum Re(Y_s conj(Y_g))``; sums over s to ``total``
    group : (p, g, nb) each independent group
    mode_alone : (p, m, nb) each mode's term alone (all sources)
    mode_share : (p, m, nb) ``sum_g Re(Y_gj conj(Y_g))``; sums over modes to ``total``
    quad_nodes : number of quadrature nodes
    quad_error : (nb,) convergence estimate of each band (relative)
    near_modes : (nb,) modes summed node by node in each band (the others, smooth over the
        band, through their Chebyshev interpolant)
    refinements : interval halvings done by the convergence check
    warnings : messages
    """

    total: np.ndarray
    source_alone: np.ndarray
    source_share: np.ndarray
    group: np.ndarray
    mode_alone: np.ndarray
    mode_share: np.ndarray
    quad_nodes: int
    quad_error: np.ndarray
    near_modes: np.ndarray
    refinements: int
    warnings: tuple[str, ...]


def _group_index(groups: Sequence[int] | None, ns: int) -> np.ndarray:
    if groups is None:
        return np.arange(ns)
    g = np.asarray(groups, int)
    if g.shape != (ns,) or np.any(g < 0):
        raise InputError("need one non-negative group index per source", where="groups")
    _, inv = np.unique(g, return_inverse=True)
    return inv.reshape(-1)


#: Chebyshev points of the interpolant of the modes far from a band
_N_CHEB = 16
#: modes within this many band widths of a band are summed node by node from the start
_NEAR_WIDTHS = 2.0
#: relative accuracy a far mode's interpolant must reach, else the mode is summed node by node
_CHEB_TOL = 1e-14


def _cheb_matrix(x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev points (first kind) on [-1, 1] and the barycentric interpolation matrix to x.

    Returns ``xk`` (n,) and ``ell`` (n, len(x)) with ``g(x) ~ g(xk) @ ell`` (Berrut &
    Trefethen, SIAM Review 46 (2004) 501, Eq. 5.1 with the first-kind weights).
    """
    theta = (2 * np.arange(n) + 1) * np.pi / (2 * n)
    xk = np.cos(theta)
    wk = (-1.0) ** np.arange(n) * np.sin(theta)
    d = x[None, :] - xk[:, None]
    hit = d == 0
    t = wk[:, None] / np.where(hit, 1.0, d)
    ell = t / np.sum(t, axis=0, keepdims=True)
    cols = np.any(hit, axis=0)
    if np.any(cols):
        ell[:, cols] = hit[:, cols]
    return xk, ell


@dataclass(frozen=True)
class _BandPart:
    total: np.ndarray  # (p,)
    source_alone: np.ndarray  # (p, L)
    source_share: np.ndarray  # (p, L)
    groups: np.ndarray  # (G,) global group indices
    group: np.ndarray  # (p, G)
    mode_alone: np.ndarray  # (p, m)
    mode_share: np.ndarray  # (p, m)
    n_near: int


def _spectral_band(
    T: np.ndarray,
    F: np.ndarray,
    gl: np.ndarray,
    amp: np.ndarray,
    rre: np.ndarray,
    rim: np.ndarray,
    freq: np.ndarray,
    lo: float,
    hi: float,
    wm: np.ndarray,
    zm: np.ndarray,
    near: np.ndarray,
    contributions: bool = True,
) -> _BandPart:
    """Mean squares in one band from spectral sources (node by node, in amplitude).

    ``amp[s, n] = sqrt(S_s(f_n) w_n)``; the response of each output row and source at the nodes
    is ``H = sum_near c_j r_j + (far-mode sum at Chebyshev points) @ ell``: the modes far from
    the band enter through a 16-point interpolant of their (smooth) sum, each far mode's
    interpolant checked at 49 points across the band to ``_CHEB_TOL`` (a mode that fails is
    summed node by node).  Amplitudes, not squares, are summed, so a response that is small by
    cancellation between modes keeps its relative accuracy.
    """
    p, m = T.shape
    L, nn = amp.shape
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    xk, ell = _cheb_matrix((freq - mid) / half, _N_CHEB)
    far = np.flatnonzero(~near)
    if far.size:
        cre, cim = _factor_parts(wm[far], zm[far], 2.0 * np.pi * (mid + half * xk))
        # check each far mode's interpolant at test points between the Chebyshev points
        xt = np.cos(np.linspace(0.0, np.pi, 3 * _N_CHEB + 1))
        ell_t = _cheb_matrix(xt, _N_CHEB)[1]
        tre, tim = _factor_parts(wm[far], zm[far], 2.0 * np.pi * (mid + half * xt))
        scale = np.maximum(np.max(np.abs(tre) + np.abs(tim), axis=1), 1e-300)
        e = np.abs(cre @ ell_t - tre) + np.abs(cim @ ell_t - tim)
        bad = np.max(e, axis=1) > _CHEB_TOL * scale
        if np.any(bad):
            near = near.copy()
            near[far[bad]] = True
            far = far[~bad]
            cre, cim = cre[~bad], cim[~bad]
    nr = np.flatnonzero(near)
    mn = nr.size
    # responses at the nodes, (L, p, nn), amplitude included: H_s = coef_s @ (basis * amp_s)
    # with the basis [r_near; ell] and the coefficients [c_near, far-mode sum at the points]
    cn = T[None, :, nr] * F[:, None, nr]  # (L, p, mn)
    bre = np.concatenate([rre[nr], ell]) if far.size else rre[nr]  # (K, nn)
    bim = np.concatenate([rim[nr], ell]) if far.size else rim[nr]
    Rre = bre[None] * amp[:, None, :]  # (L, K, nn)
    Rim = bim[None] * amp[:, None, :]
    if far.size:
        Tf = T[:, far]
        hf_re = Tf[None] @ (F[:, far, None] * cre[None])  # (L, p, nc): far sum at the points
        hf_im = Tf[None] @ (F[:, far, None] * cim[None])
        cre_re = np.concatenate([cn, hf_re], axis=2)  # (L, p, K)
        cre_im = np.concatenate([cn, hf_im], axis=2)
    else:
        cre_re = cre_im = cn
    Hre = cre_re @ Rre  # (L, p, nn)
    Him = cre_im @ Rim
    ug, ginv = np.unique(gl, return_inverse=True)
    ginv = ginv.reshape(-1)
    alone = np.einsum("spn,spn->ps", Hre, Hre) + np.einsum("spn,spn->ps", Him, Him)
    # each source's group response: itself when alone in its group
    count = np.bincount(ginv)[ginv]
    share = alone.copy()
    gms = np.zeros((p, ug.size))
    gms[:, ginv[count == 1]] = alone[:, count == 1]
    multi = np.flatnonzero(count > 1)
    Ym_re = Ym_im = np.zeros((0, p, nn))
    if multi.size:
        gm = ginv[multi]
        same = (gm[:, None] == gm[None, :]).astype(float)  # same-group indicator
        Ym_re = np.tensordot(same, Hre[multi], axes=(1, 0))  # (M, p, nn)
        Ym_im = np.tensordot(same, Him[multi], axes=(1, 0))
        share[:, multi] = np.einsum("spn,spn->ps", Hre[multi], Ym_re) + np.einsum(
            "spn,spn->ps", Him[multi], Ym_im
        )
        first = np.unique(gm, return_index=True)[1]
        gms[:, gm[first]] = np.einsum("spn,spn->ps", Ym_re[first], Ym_re[first]) + np.einsum(
            "spn,spn->ps", Ym_im[first], Ym_im[first]
        )
    mode_share = np.zeros((p, m))
    mode_alone = np.zeros((p, m))
    if not contributions:
        return _BandPart(gms.sum(axis=1), alone, share, ug, gms, mode_alone, mode_share, mn)
    # mode shares: T_pj sum_s F_sj Re sum_n r_j(n) amp_s(n) conj(Y_g(s)(n)); the sums over the
    # nodes are products with the amplitude-scaled basis: near columns give the near modes, the
    # Chebyshev columns the far modes through r_j(n) ~ sum_k r_j(x_k) l_k(n)
    RreT, RimT = np.swapaxes(Rre, 1, 2), np.swapaxes(Rim, 1, 2)
    Are = Hre @ RreT  # (L, p, K): sum_n Yre a b, Y = H for a source alone in its group
    Aim = Him @ RimT
    if multi.size:
        Are[multi] = Ym_re @ RreT[multi]
        Aim[multi] = Ym_im @ RimT[multi]
    if mn:
        W = Are[:, :, :mn] + Aim[:, :, :mn]  # Re(conj(Y) a r_j)
        mode_share[:, nr] = T[:, nr] * np.einsum("sj,spj->pj", F[:, nr], W)
    if far.size:
        # sum_s F_sj Re sum_k r_j(x_k) P_sk, P_sk = sum_n a conj(Y) l_k
        Zre = np.tensordot(Are[:, :, mn:], F[:, far], axes=(0, 0))  # (p, nc, mf)
        Zim = np.tensordot(Aim[:, :, mn:], F[:, far], axes=(0, 0))
        Wf = np.einsum("pkj,jk->pj", Zre, cre) + np.einsum("pkj,jk->pj", Zim, cim)
        mode_share[:, far] = T[:, far] * Wf
    # modes alone: T_pj^2 sum_g int |r_j|^2 |sum_{s in g} F_sj a_s|^2
    rr = rre * rre + rim * rim  # (m, nn)
    D = rr @ (amp * amp).T  # (m, L)
    A = np.sum(F.T**2 * D, axis=1)
    if multi.size:
        ia, ib = np.nonzero((ginv[:, None] == ginv[None, :]) & ~np.eye(L, dtype=bool))
        cross = rr @ (amp[ia] * amp[ib]).T  # (m, P)
        A += np.sum(F[ia].T * F[ib].T * cross, axis=1)
    mode_alone = T**2 * A[None, :]
    return _BandPart(
        total=gms.sum(axis=1),
        source_alone=alone,
        source_share=share,
        groups=ug,
        group=gms,
        mode_alone=mode_alone,
        mode_share=mode_share,
        n_near=int(mn),
    )


def band_mean_squares(
    omega_modes: np.ndarray,
    zeta: np.ndarray,
    out_modal: np.ndarray,
    in_modal: np.ndarray,
    spectra: Sequence[ForceSpectrum],
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    *,
    groups: Sequence[int] | None = None,
    order: int = 8,
    rtol: float = 1e-9,
    workers: int | None = None,
    contributions: bool = True,
) -> BandArrays:
    """Band mean squares, their combination over sources and the contributions (pure kernel).

    Parameters
    ----------
    omega_modes : (m,) natural frequencies, rad/s (0: rigid)
    zeta : (m,) modal damping ratios (> 0 for elastic modes)
    out_modal : (p, m) output rows (``T_out @ phi``), m per unit modal coordinate
    in_modal : (s, m) generalized force per newton of each source on each mode
    spectra : s force spectra (:class:`HarmonicLines`, :class:`BandForceSpectrum`,
        :class:`ForcePSD`), N and Hz
    lower_hz, upper_hz : (nb,) band edges, Hz
    groups : (s,) coherent group index per source (default: all independent)
    order : Gauss-Legendre points per sub-interval
    rtol : convergence tolerance of the band integration (relative)
    workers : threads over bands (default the number of CPUs); each uses one BLAS thread
    contributions : compute the per-mode contributions (``mode_alone``, ``mode_share``; zero
        when False, about half the work)

    Returns
    -------
    BandArrays (mean squares in output-unit^2, e.g. (m/s^2)^2 for acceleration rows).
    """
    wm = np.asarray(omega_modes, float)
    zm = np.asarray(zeta, float)
    T = np.asarray(out_modal, float)
    F = np.asarray(in_modal, float)
    lo = np.asarray(lower_hz, float)
    hi = np.asarray(upper_hz, float)
    p, m = T.shape
    ns, nb = F.shape[0], lo.size
    if F.shape != (ns, m) or len(spectra) != ns or zm.shape != (m,) or wm.shape != (m,):
        raise InputError("inconsistent shapes of modes, outputs and sources", where="band")
    if not (np.all(lo > 0) and np.all(hi > lo)):
        raise InputError("bands need 0 < lower < upper", where="bands")
    gidx = _group_index(groups, ns)
    ng = int(gidx.max()) + 1 if ns else 0
    total = np.zeros((p, nb))
    src_alone = np.zeros((p, ns, nb))
    src_share = np.zeros((p, ns, nb))
    grp = np.zeros((p, ng, nb))
    mode_alone = np.zeros((p, m, nb))
    mode_share = np.zeros((p, m, nb))
    warnings: list[str] = []

    # ---------------------------------------------------------------- spectral sources
    spec_idx = np.array(
        [i for i, s in enumerate(spectra) if not isinstance(s, HarmonicLines)], dtype=int
    )
    near_count = np.zeros(nb, int)
    quad_nodes, refinements = 0, 0
    qerr = np.zeros(nb)
    if spec_idx.size:
        Fs = F[spec_idx]
        scale = np.max(np.abs(T), axis=0) * np.max(np.abs(Fs), axis=0)  # (m,) max |c_j|
        spec_list = [spectra[i] for i in spec_idx]
        quad, qerr, refinements, w = _converged_quadrature(
            lo, hi, wm, zm, scale, spec_list, order, rtol
        )
        warnings += w
        quad_nodes = int(quad.freq_hz.size)
        S = np.array([s.psd_at(quad.freq_hz) for s in spec_list])  # (ss, N), N^2/Hz
        re_all, im_all = _factor_parts(wm, zm, 2.0 * np.pi * quad.freq_hz)  # (m, N)
        fm = wm / (2.0 * np.pi)
        elastic = wm > 0
        gs = gidx[spec_idx]

        def one_band(b: int) -> tuple[int, np.ndarray, _BandPart] | None:
            n0, n1 = quad.start[b], quad.start[b + 1]
            if n1 <= n0:
                return None
            live = np.flatnonzero(np.any(S[:, n0:n1] > 0, axis=1))
            if live.size == 0:
                return None
            width = hi[b] - lo[b]
            part = _spectral_band(
                T,
                Fs[live],
                gs[live],
                np.sqrt(S[live, n0:n1] * quad.weight_hz[None, n0:n1]),
                re_all[:, n0:n1],
                im_all[:, n0:n1],
                quad.freq_hz[n0:n1],
                lo[b],
                hi[b],
                wm,
                zm,
                elastic & (fm > lo[b] - _NEAR_WIDTHS * width) & (fm < hi[b] + _NEAR_WIDTHS * width),
            )
            return b, live, part

        # bands in parallel threads, one BLAS thread each (the products are mid-sized:
        # BLAS threads on top of band threads only contend)
        nworkers = max(1, min(int(workers or os.cpu_count() or 1), nb))
        if nworkers == 1:
            results = [one_band(b) for b in range(nb)]
        else:
            with threadpool_limits(limits=1), ThreadPoolExecutor(max_workers=nworkers) as pool:
                results = list(pool.map(one_band, range(nb)))
        for res in results:
            if res is None:
                continue
            b, live, part = res
            near_count[b] = part.n_near
            total[:, b] += part.total
            src = spec_idx[live]
            src_alone[:, src, b] += part.source_alone
            src_share[:, src, b] += part.source_share
            for k, g in enumerate(part.groups):
                grp[:, g, b] += part.group[:, k]
            mode_alone[:, :, b] += part.mode_alone
            mode_share[:, :, b] += part.mode_share

    # ----------------------------------------------------------------- harmonic lines
    harm = [(i, s) for i, s in enumerate(spectra) if isinstance(s, HarmonicLines)]
    if harm:
        src = np.concatenate([np.full(s.freq_hz.size, i) for i, s in harm])
        if src.size > MAX_LINES:
            raise InputError(f"{src.size:,} harmonic lines is more than {MAX_LINES:,}")
        fl = np.concatenate([s.freq_hz for _, s in harm])
        al = np.concatenate(
            [s.amplitude_n * np.exp(1j * np.asarray(s.phase_rad)) for _, s in harm]
        ) / np.sqrt(2.0)  # RMS phasors
        key = _same_frequency_index(fl, gidx[src])
        nu = int(key.max()) + 1
        fu = np.zeros(nu)
        fu[key] = fl
        gu = np.zeros(nu, int)
        gu[key] = gidx[src]
        member = (fu[:, None] >= lo[None, :]) & (fu[:, None] < hi[None, :])
        top = int(np.argmax(hi))
        member[:, top] |= fu == hi[top]  # the top band is closed
        outside = ~np.any(member, axis=1)
        if np.any(outside):
            warnings.append(
                f"{int(outside.sum())} harmonic line(s) lie outside every band (not assessed), "
                f"e.g. at {fu[outside][0]:.4g} Hz"
            )
        re, im = _factor_parts(wm, zm, 2.0 * np.pi * fu)
        r = re + 1j * im  # (m, U)
        B = np.zeros((m, nu), complex)  # sum_s F_sj A_s at each distinct (group, freq)
        np.add.at(B.T, key, F[src] * al[:, None])
        Y = T @ (r * B)  # (p, U) group response phasors (RMS)
        Hs = T @ (r[:, key] * F[src].T * al[None, :])  # (p, lines): each line alone
        # each source's lines at one frequency add first (a source's own phasor sum)
        sk = src * nu + key
        uk, inv = np.unique(sk, return_inverse=True)
        Hsum_t = np.zeros((uk.size, p), complex)
        np.add.at(Hsum_t, inv.reshape(-1), Hs.T)
        Hsum = Hsum_t.T
        us, uu = uk // nu, uk % nu
        Mf = member.astype(float)
        alone = np.abs(Hsum) ** 2
        share = np.real(Hsum * np.conj(Y[:, uu]))
        Ms = np.zeros((uk.size, ns))
        Ms[np.arange(uk.size), us] = 1.0
        src_alone += np.einsum("pk,ks,kb->psb", alone, Ms, Mf[uu])
        src_share += np.einsum("pk,ks,kb->psb", share, Ms, Mf[uu])
        gms = np.abs(Y) ** 2  # (p, U)
        total += gms @ Mf
        Mg = np.zeros((nu, ng))
        Mg[np.arange(nu), gu] = 1.0
        grp += np.einsum("pu,ug,ub->pgb", gms, Mg, Mf)
        for c0 in range(0, nu if contributions else 0, 256):  # chunks keep (p, m, chunk) small
            c1 = min(nu, c0 + 256)
            term = T[:, :, None] * (r[:, c0:c1] * B[:, c0:c1])[None]  # (p, m, u)
            mode_alone += np.abs(term) ** 2 @ Mf[c0:c1]
            mode_share += np.real(term * np.conj(Y[:, None, c0:c1])) @ Mf[c0:c1]

    return BandArrays(
        total=total,
        source_alone=src_alone,
        source_share=src_share,
        group=grp,
        mode_alone=mode_alone,
        mode_share=mode_share,
        quad_nodes=quad_nodes,
        quad_error=qerr,
        near_modes=near_count,
        refinements=refinements,
        warnings=tuple(warnings),
    )


# ------------------------------------------------------------------ band response (Modes)


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
            "center_hz": _clean(self.center_hz),
            "lower_hz": _clean(self.lower_hz),
            "upper_hz": _clean(self.upper_hz),
            "unit": "m/s^2 RMS",
            "points": {
                p: {
                    "rms_mps2_axis": {
                        a: _clean(self.rms_mps2[i, k]) for k, a in enumerate(self.axes)
                    },
                    "sources": {
                        s: {
                            a: _clean(self.source_rms_mps2[i, k, :, j])
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

    def plot(self, point: str | None = None) -> Any:
        """Band RMS per axis at one point (log-log); returns a matplotlib Figure."""
        from microg.plotting.frequency import plot_band_response

        return plot_band_response(self, point=point)


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
    order: int = 8,
    rtol: float = 1e-9,
    workers: int | None = None,
    contributions: bool = True,
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
    )
    warnings = list(arr.warnings)
    uns = getattr(modes, "unstable", None)
    unstable = np.zeros(modes.n_modes, bool) if uns is None else np.asarray(uns, bool)
    if unstable.any():
        rate = getattr(modes, "growth_rate", None)
        g = np.zeros(modes.n_modes) if rate is None else np.asarray(rate, float)
        g = g[unstable]
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
