"""Passive mount search against a measured (or computed) acceleration spectrum.

The report's design rule (Section 4.2, :func:`microg.isolation.design.design_mount`) bounds
M_a over the band where a requirement is exceeded; it ignores the mount's own resonance,
which a broadband transient (a crew push-off) excites below that band, where the ISS limit is
strictest.  :func:`search_mount` screens spring-damper mounts on the whole spectrum: the
package's PSD is ``|T(f)|^2`` times the mount's (linear, time-invariant system), band RMS per
1/3-octave band against the limit, and returns the stiffest mount that complies.  The caller
verifies the choice with the exact time-domain response
(:func:`microg.isolation.timedomain.package_response`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.environment.metrics import Spectrum, json_number
from microg.environment.requirements import BandTable, Requirement
from microg.units import G0, IN, LBF

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["mount_transmissibility", "MountChoice", "screen_margins", "search_mount"]


def mount_transmissibility(
    k1: np.ndarray | float, c1: np.ndarray | float, m1: float, omega: np.ndarray
) -> np.ndarray:
    """Absolute transmissibility U1/U0 of a spring-damper mount (no absorber), complex.

    ``T = (k1 + i c1 w) / (k1 - m1 w^2 + i c1 w)``; with ``c1 = 0`` this is Eq. 4.3 with
    ``m2 = 0``.

    Parameters
    ----------
    k1 : float or ndarray
        Mount stiffness, N/m.
    c1 : float or ndarray
        Mount damping, N s/m.
    m1 : float
        Package mass, kg.
    omega : ndarray
        Circular frequency, rad/s.
    """
    num = k1 + 1j * c1 * omega
    return num / (k1 - m1 * omega**2 + 1j * c1 * omega)


@dataclass(frozen=True)
class MountChoice:
    """Result of :func:`search_mount`.

    Attributes
    ----------
    found : bool
        A screened mount complies in every band.
    k1 : float
        Stiffness of the chosen mount (the stiffest compliant one, else the best), N/m.
    zeta1 : float
        Its damping ratio ``c1 / (2 sqrt(k1 m1))``.
    c1 : float
        N s/m.
    min_margin : float
        Smallest limit / band RMS over axes and bands (>= 1 means compliance).
    freq_hz_n : float
        Mount natural frequency, Hz.
    screened : int
        Number of (k1, zeta1) pairs screened.
    """

    found: bool
    k1: float
    zeta1: float
    c1: float
    min_margin: float
    freq_hz_n: float
    screened: int

    @property
    def mass_kg(self) -> float:
        """Package mass ``k1 / (2 pi f_n)^2``, kg."""
        return self.k1 / (2 * np.pi * self.freq_hz_n) ** 2

    def transmissibility(self, freq_hz: np.ndarray) -> np.ndarray:
        """``|U1/U0|`` of this mount at support frequencies ``freq_hz`` (Hz)."""
        w = 2 * np.pi * np.asarray(freq_hz, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.abs(mount_transmissibility(self.k1, self.c1, self.mass_kg, w))

    def default_freq_hz(self) -> np.ndarray:
        """801 log-spaced frequencies from f_n / 20 to 50 f_n, Hz."""
        return np.geomspace(self.freq_hz_n / 20, 50 * self.freq_hz_n, 801)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready choice; keys carry units (the ``screened_mount`` of the advice)."""
        return {
            "found": bool(self.found),
            "k1_N_per_m": self.k1,
            "k1_lbf_per_in": self.k1 * IN / LBF,
            "zeta1": self.zeta1,
            "c1_N_s_per_m": self.c1,
            "natural_freq_hz": self.freq_hz_n,
            "screen_min_margin": json_number(self.min_margin),
            "screened": self.screened,
        }

    def to_xarray(self, freq_hz: np.ndarray | None = None) -> Any:
        """``|U1/U0|`` over support frequency as an ``xarray.Dataset`` (dim ``freq_hz``)."""
        import xarray as xr

        f = self.default_freq_hz() if freq_hz is None else np.asarray(freq_hz, float)
        return xr.Dataset(
            {"transmissibility": ("freq_hz", self.transmissibility(f), {"units": "1"})},
            coords={"freq_hz": ("freq_hz", f, {"units": "Hz"})},
            attrs=self.to_dict() | {"found": int(self.found), "mass_kg": self.mass_kg},
        )

    def plot(self) -> Figure:
        """``|U1/U0|`` against frequency (``plotting.isolation.plot_mount_choice``)."""
        from microg.plotting.isolation import plot_mount_choice

        return plot_mount_choice(self)


def screen_margins(
    spectrum: Spectrum,
    requirement: Requirement,
    mass: float,
    k_max: float,
    zetas: tuple[float, ...],
    decades: float,
    n_k: int,
) -> np.ndarray:
    """Smallest band margin of the package on each screened mount, ``(len(zetas), n_k)``.

    The package's PSD is ``|T(omega)|^2`` times the mount's, with
    ``|T|^2 = (k^2 + (c omega)^2) / ((k - m omega^2)^2 + (c omega)^2)`` (the modulus of
    :func:`mount_transmissibility`), and a band's power is linear in the PSD
    (:func:`~microg.environment.metrics.band_weights`, the integration of
    :func:`~microg.environment.metrics.band_rms`): all candidates of one damping ratio are one
    sparse-dense product per axis.  The margin is ``min limit / band RMS`` over the bands
    below Nyquist and the axes (``inf`` where no band has power); 0 for an undamped mount
    resonant exactly on a bin carrying power (an unbounded response).

    Parameters
    ----------
    spectrum : Spectrum
        One-sided PSD of the mount acceleration, per axis ((m/s^2)^2/Hz).
    requirement : Requirement
        Band limits (g).
    mass : float
        Package mass, kg.
    k_max : float
        Stiffest mount, N/m; the stiffnesses are ``k_max * logspace(-decades, 0, n_k)``.
    zetas : tuple of float
        Mount damping ratios.
    decades : float
        Width of the log-spaced stiffness range.
    n_k : int
        Number of stiffness values.
    """
    from microg.environment.metrics import band_weights

    omega = 2 * np.pi * spectrum.freq_hz
    keep = requirement.bands.lower_hz < spectrum.nyquist_hz
    limit = requirement.limit_g[keep]
    kept = BandTable(
        requirement.bands.center_hz[keep],
        requirement.bands.lower_hz[keep],
        requirement.bands.upper_hz[keep],
    )
    w = band_weights(spectrum.freq_hz, spectrum.df_hz, spectrum.nyquist_hz, kept)
    psd = np.atleast_2d(spectrum.psd)
    weighted = [w.multiply(p[None, :]).tocsr() for p in psd]  # (nb, nf) per axis
    power_bins = np.any(psd > 0, axis=0)
    k_grid = k_max * np.logspace(-decades, 0.0, n_k)
    w2 = omega**2
    out = np.empty((len(zetas), n_k))
    for iz, zeta1 in enumerate(zetas):
        c1 = 2 * zeta1 * np.sqrt(k_grid * mass)
        cw2 = (c1[:, None] ** 2) * w2[None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            t2 = (k_grid[:, None] ** 2 + cw2) / ((k_grid[:, None] - mass * w2[None, :]) ** 2 + cw2)
        unbounded = ~np.all(np.isfinite(t2[:, power_bins]), axis=1)
        t2 = np.where(np.isfinite(t2), t2, 0.0)  # bins without power
        rms_g = np.stack([np.sqrt(np.maximum(wa @ t2.T, 0.0)).T for wa in weighted]) / G0
        with np.errstate(divide="ignore"):
            ratio = np.where(rms_g > 0, limit / np.maximum(rms_g, 1e-300), np.inf)
        m = np.min(ratio, axis=(0, 2)) if ratio.size else np.full(n_k, np.inf)
        out[iz] = np.where(unbounded, 0.0, m)
    return out


def search_mount(
    spectrum: Spectrum,
    requirement: Requirement,
    mass: float,
    k_max: float,
    *,
    zetas: tuple[float, ...] = (0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0),
    decades: float = 4.0,
    n_k: int = 81,
) -> MountChoice:
    """Stiffest spring-damper mount whose package spectrum meets ``requirement`` everywhere.

    Parameters
    ----------
    spectrum : Spectrum
        One-sided PSD of the mount acceleration, per axis ((m/s^2)^2/Hz).
    requirement : Requirement
        Band limits (g).
    mass : float
        Package mass, kg.
    k_max : float
        Stiffest mount to consider, N/m (e.g. the report's rule's answer); the search spans
        ``decades`` below it.
    zetas : tuple of float
        Mount damping ratios to screen.
    decades : float
        Width of the log-spaced stiffness range.
    n_k : int
        Number of stiffness values.
    """
    margins = screen_margins(spectrum, requirement, mass, k_max, zetas, decades, n_k)
    k_grid = k_max * np.logspace(-decades, 0.0, n_k)
    best = None
    for iz, zeta1 in enumerate(zetas):  # the first of equal candidates wins, as screened
        for ik, k1 in enumerate(k_grid):
            c1 = 2 * zeta1 * np.sqrt(k1 * mass)
            margin = float(margins[iz, ik])
            cand = (margin >= 1.0, k1 if margin >= 1.0 else margin, k1, zeta1, c1, margin)
            if best is None or cand[:2] > best[:2]:
                best = cand
    assert best is not None
    found, _, k1, zeta1, c1, margin = best
    return MountChoice(
        found=bool(found),
        k1=float(k1),
        zeta1=float(zeta1),
        c1=float(c1),
        min_margin=margin,
        freq_hz_n=float(np.sqrt(k1 / mass) / (2 * np.pi)),
        screened=len(zetas) * n_k,
    )
