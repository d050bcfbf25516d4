"""Absorber tuning: Den Hartog and H2 closed forms, and numerical optima over a band of ``r``.

The report's transmissibility ``U1/U0`` (support acceleration in, package absolute acceleration
out, Eqs. 4.3-4.6) is algebraically the same function as Den Hartog's force-excited main-mass
displacement ratio ``x1/x_st``, with ``g = r`` and the tuning ratio ``f = omega_a/omega_n``:

    f^2 = (k2/m2)/(k1/m1) = 1/(k mu),   zeta_a = c/(2 m2 omega_a) = c/(2 sqrt(m2 k2)) = zeta,

so the classical optima apply in the report's parameters with ``k = 1/(f^2 mu)``:

* Den Hartog (minimise the peak over all ``r``): ``f = 1/(1 + mu)``,
  ``zeta = sqrt(3 mu/(8 (1 + mu)))``; the fixed-point height ``sqrt(1 + 2/mu)`` is a strict lower
  bound of the peak for *any* ``(k, zeta)`` at that ``mu``.
* H2 (minimise ``integral_0^inf M_a^2 dr``, the variance of the package's absolute acceleration
  under white-noise support acceleration): ``f = sqrt(1 + mu/2)/(1 + mu)``,
  ``zeta = sqrt(mu (1 + 3 mu/4)/(4 (1 + mu)(1 + mu/2)))``.

Both are verified numerically in the tests by :func:`tune_absorber`, which minimises the peak of
``M_a`` over a band ``[r_lo, r_hi]`` of the frequency ratio ``r = omega/omega_n`` (not ``r^2``),
or the band-limited H2 integral, with a coarse global grid guarding a Nelder-Mead search.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import NDArray

from microg.errors import InputError, SolverError
from microg.isolation.transmissibility import accel_magnification, spring_ratio_from_tuning

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "AbsorberTuning",
    "PeakResult",
    "Criterion",
    "den_hartog",
    "den_hartog_peak_bound",
    "h2_closed_form",
    "peak_over_band",
    "h2_integral",
    "dimensionless_state_space",
    "tune_absorber",
]

Criterion = Literal["peak", "h2"]

_LOG_F_RANGE = (math.log(0.1), math.log(10.0))
_LOG_ZETA_RANGE = (math.log(1e-3), math.log(2.0))


@dataclass(frozen=True)
class PeakResult:
    """Largest ``M_a`` over a band of ``r`` and where it occurs."""

    peak_Ma: float  # noqa: N815 - the CLI contract name
    r_peak: float

    def to_dict(self) -> dict[str, float]:
        """JSON-ready ``{"peak_Ma", "r_peak"}`` (both dimensionless)."""
        return {"peak_Ma": self.peak_Ma, "r_peak": self.r_peak}


@dataclass(frozen=True)
class AbsorberTuning:
    """An absorber design in the report's parameters (Eq. 4.6) and its figures of merit.

    Attributes
    ----------
    mu : mass ratio ``m2/m1``.
    k : spring ratio ``k1/k2``.
    zeta : absorber damping ratio ``c/(2 sqrt(m2 k2))``.
    f : tuning ratio ``omega_a/omega_n = 1/sqrt(k mu)``.
    peak_Ma : largest ``M_a`` over ``band`` (all ``r`` when ``band`` is None).
    r_peak : frequency ratio of that peak.
    h2 : ``integral M_a^2 dr`` over ``band`` (over ``0..inf`` when ``band`` is None).
    criterion : ``"peak"`` (minimax) or ``"h2"``.
    band : ``(r_lo, r_hi)`` in ``r = omega/omega_n``, or None for all ``r``.
    method : how it was obtained (closed form or numerical).
    """

    mu: float
    k: float
    zeta: float
    f: float
    peak_Ma: float  # noqa: N815 - the CLI contract name
    r_peak: float
    h2: float
    criterion: str
    band: tuple[float, float] | None
    method: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready design: every attribute (all dimensionless), ``band`` as a list or None."""
        return {
            "mu": self.mu,
            "k": self.k,
            "zeta": self.zeta,
            "f": self.f,
            "peak_Ma": self.peak_Ma,
            "r_peak": self.r_peak,
            "h2": self.h2,
            "criterion": self.criterion,
            "band": None if self.band is None else [float(b) for b in self.band],
            "method": self.method,
        }

    def to_xarray(self, r: np.ndarray | None = None) -> Any:
        """``M_a`` (Eq. 4.3 solved) and the package alone over ``r`` as an ``xarray.Dataset``.

        Parameters
        ----------
        r : ndarray, optional
            Frequency ratios ``omega/omega_n`` (default 2,001 from 0 to 3, or to 1.5 times the
            band's upper end, with ``r_peak``).
        """
        import xarray as xr

        from microg.isolation.transmissibility import accel_magnification_no_absorber

        if r is None:
            top = max(3.0, 1.5 * self.band[1]) if self.band is not None else 3.0
            r = np.unique(np.r_[np.linspace(0.0, top, 2001), self.r_peak])
        r = np.asarray(r, float)
        with np.errstate(divide="ignore"):
            alone = accel_magnification_no_absorber(r)
        return xr.Dataset(
            {
                "Ma": ("r", accel_magnification(self.k, self.mu, self.zeta, r), {"units": "1"}),
                "Ma_no_absorber": ("r", alone, {"units": "1"}),
            },
            coords={"r": ("r", r, {"units": "1", "long_name": "omega/omega_n"})},
            attrs={k: v for k, v in self.to_dict().items() if v is not None and k != "band"}
            | ({} if self.band is None else {"band_r": list(self.band)}),
        )

    def plot(self, ax: Any = None) -> Figure:
        """``M_a`` against ``r``, the band and the peak (``plotting.isolation.plot_absorber``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.isolation import plot_absorber

        return plot_absorber(self, ax=ax)

    def contract(self) -> dict[str, float | str]:
        """The CLI contract ``{"k", "zeta", "f", "peak_Ma", "criterion"}``."""
        return {
            "k": self.k,
            "zeta": self.zeta,
            "f": self.f,
            "peak_Ma": self.peak_Ma,
            "criterion": self.criterion,
        }


#: absorber mass ratios m2/m1 accepted: from an absorber of a millionth of the package to one
#: a hundred times heavier (outside it the fixed-point formulas of Eqs. 4.3-4.7 overflow or
#: lose every digit; no design lies there)
MU_RANGE = (1e-6, 100.0)


def _check_mu(mu: float, where: str = "mu") -> float:
    """``mu`` as a float if it is a mass ratio within :data:`MU_RANGE`, else an InputError."""
    try:
        mu = float(mu)
    except (TypeError, ValueError):
        raise InputError(f"mass ratio must be a number, got {mu!r}", where=where) from None
    lo, hi = MU_RANGE
    if not (math.isfinite(mu) and lo <= mu <= hi):
        raise InputError(
            f"mass ratio must be a finite number from {lo:g} to {hi:g}, got {mu!r}",
            where=where,
            fix="give the absorber's mass over the package's, e.g. 0.05",
        )
    return mu


def _check_band(band: tuple[float, float] | None) -> tuple[float, float] | None:
    if band is None:
        return None
    lo, hi = float(band[0]), float(band[1])
    if not (0.0 <= lo < hi < math.inf):
        raise InputError(f"need 0 <= LO < HI < inf, got {band!r}", where="band")
    if hi > MAX_RATIO or 0.0 < lo < 1.0 / MAX_RATIO:
        raise InputError(
            f"frequency ratios must lie from {1 / MAX_RATIO:g} to {MAX_RATIO:g} (or LO = 0), "
            f"got {band!r}",
            where="band",
        )
    return (lo, hi)


#: largest frequency ratio r = omega/omega_2 of a tuning band (six decades either side of
#: the absorber's own frequency hold every band a design can use)
MAX_RATIO = 1e6


def den_hartog_peak_bound(mu: float) -> float:
    """Fixed-point height ``sqrt(1 + 2/mu)``: no ``(k, zeta)`` gives a lower peak of ``M_a``.

    Parameters
    ----------
    mu : float
        Mass ratio ``m2/m1`` (Eq. 4.6), > 0.
    """
    return math.sqrt(1.0 + 2.0 / mu)


def _resonance_candidates(k: float, mu: float) -> list[float]:
    """Frequency ratios where peaks of ``M_a`` can sit (undamped and rigid-absorber poles)."""
    s2 = mu * k
    b = 1.0 + mu + s2
    disc = math.sqrt(max(b * b - 4.0 * s2, 0.0))
    q_minus = (b - disc) / (2.0 * s2)
    q_plus = (b + disc) / (2.0 * s2)
    return [math.sqrt(q_minus), math.sqrt(q_plus), 1.0 / math.sqrt(1.0 + mu)]


def _auto_r_max(k: float, mu: float) -> float:
    return 3.0 * max(1.0, max(_resonance_candidates(k, mu)))


def peak_over_band(
    k: float, mu: float, zeta: float, band: tuple[float, float] | None = None
) -> PeakResult:
    """Largest ``M_a`` over ``r`` in ``band`` (all ``r >= 0`` when None), to about 1e-12 relative.

    A uniform grid plus dense grids around the resonance candidates locate the local maxima;
    each of the best three is refined with a bounded Brent search.

    Parameters
    ----------
    k : float
        Spring ratio ``k1/k2`` (Eq. 4.6).
    mu : float
        Mass ratio ``m2/m1`` (Eq. 4.6).
    zeta : float
        Absorber damping ratio (Eq. 4.6).
    band : (float, float), optional
        ``(r_lo, r_hi)`` in frequency ratio ``r = omega/omega_n``.
    """
    lo, hi = band if band is not None else (0.0, _auto_r_max(k, mu))
    pieces = [np.linspace(lo, hi, 2001)]
    for rc in _resonance_candidates(k, mu):
        a, b = max(lo, rc * 0.8), min(hi, rc * 1.25)
        if a < b:
            pieces.append(np.linspace(a, b, 1001))
    r = np.unique(np.concatenate(pieces))
    m = accel_magnification(k, mu, zeta, r)
    if not np.all(np.isfinite(m)):
        i = int(np.argmax(~np.isfinite(m)))
        return PeakResult(math.inf, float(r[i]))
    # local maxima of the sampled curve (end points included), best three refined
    interior = np.flatnonzero((m[1:-1] >= m[:-2]) & (m[1:-1] >= m[2:])) + 1
    cands = np.concatenate(([0, r.size - 1], interior))
    cands = cands[np.argsort(m[cands])[::-1][:3]]
    best = PeakResult(float(m.max()), float(r[int(np.argmax(m))]))
    for i in cands:
        if i in (0, r.size - 1):
            continue
        from scipy import optimize  # here: scipy.optimize costs ~0.2 s to import

        res = optimize.minimize_scalar(
            lambda x: -float(accel_magnification(k, mu, zeta, x)),
            bounds=(float(r[i - 1]), float(r[i + 1])),
            method="bounded",
            options={"xatol": 1e-13 * max(1.0, float(r[i]))},
        )
        if -res.fun > best.peak_Ma:
            best = PeakResult(float(-res.fun), float(res.x))
    return best


def dimensionless_state_space(
    k: float, mu: float, zeta: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """State space ``(A, B, C)`` from support to package absolute acceleration, time ``omega_n t``.

    States are the relative displacements and velocities ``[z1, z2, z1', z2']`` with
    ``z_i = u_i - u0``; input ``a0 = u0''``; output the package acceleration ``u1''`` (no
    feedthrough).  Its transfer function at ``s = i r`` equals ``U1/U0`` of Eq. 4.3.

    Parameters
    ----------
    k, mu, zeta : float
        Spring ratio, mass ratio and absorber damping ratio (Eq. 4.6).
    """
    kk = 1.0 / k  # k2/k1
    cc = 2.0 * zeta * math.sqrt(mu / k)  # c/(m1 omega_n)
    A = np.array(
        [
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [-(1.0 + kk), kk, -cc, cc],
            [kk / mu, -kk / mu, cc / mu, -cc / mu],
        ]
    )
    B = np.array([[0.0], [0.0], [-1.0], [-1.0]])
    C = A[2:3, :].copy()  # u1'' = z1'' + a0 = (A x)_3
    return A, B, C


def h2_integral(k: float, mu: float, zeta: float, band: tuple[float, float] | None = None) -> float:
    """``integral M_a(r)^2 dr`` over ``band`` (``0..inf`` when None).

    Over all ``r`` it is ``pi C P C^T`` with ``A P + P A^T + B B^T = 0`` (exact; finite because
    ``M_a -> 1`` at ``r = 0`` and ``M_a ~ 1/r^2`` as ``r -> inf``); over a band it is adaptive
    quadrature split at the resonances.  Infinite for ``zeta = 0``.

    Parameters
    ----------
    k, mu, zeta : float
        Spring ratio, mass ratio and absorber damping ratio (Eq. 4.6).
    band : (float, float), optional
        ``(r_lo, r_hi)`` in ``r = omega/omega_n``.
    """
    if zeta <= 0.0:
        return math.inf
    if band is None:
        from scipy import linalg

        A, B, C = dimensionless_state_space(k, mu, zeta)
        P = linalg.solve_continuous_lyapunov(A, -B @ B.T)
        return float(math.pi * (C @ P @ C.T)[0, 0])
    from scipy import integrate  # here: scipy.integrate costs ~0.1 s to import

    lo, hi = band
    pts = sorted({lo, hi, *(x for x in _resonance_candidates(k, mu) if lo < x < hi)})
    total = 0.0
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        val, _ = integrate.quad(
            lambda x: float(accel_magnification(k, mu, zeta, x)) ** 2,
            a,
            b,
            limit=200,
            epsrel=1e-10,
        )
        total += val
    return total


def _make(
    mu: float,
    f: float,
    zeta: float,
    criterion: str,
    band: tuple[float, float] | None,
    method: str,
) -> AbsorberTuning:
    k = float(spring_ratio_from_tuning(f, mu))
    pk = peak_over_band(k, mu, zeta, band)
    return AbsorberTuning(
        mu=mu,
        k=k,
        zeta=zeta,
        f=f,
        peak_Ma=pk.peak_Ma,
        r_peak=pk.r_peak,
        h2=h2_integral(k, mu, zeta, band),
        criterion=criterion,
        band=band,
        method=method,
    )


def den_hartog(mu: float) -> AbsorberTuning:
    """Den Hartog's minimax tuning in the report's parameters, with its actual peak evaluated.

    ``f = 1/(1 + mu)``, ``zeta = sqrt(3 mu/(8 (1 + mu)))``, ``k = 1/(f^2 mu) = (1 + mu)^2/mu``.

    Parameters
    ----------
    mu : float
        Mass ratio ``m2/m1`` (Eq. 4.6), > 0.
    """
    mu = _check_mu(mu)
    f = 1.0 / (1.0 + mu)
    zeta = math.sqrt(3.0 * mu / (8.0 * (1.0 + mu)))
    return _make(mu, f, zeta, "peak", None, "closed form (Den Hartog)")


def h2_closed_form(mu: float) -> AbsorberTuning:
    """H2 tuning ``f = sqrt(1 + mu/2)/(1 + mu)``, ``zeta = sqrt(mu(1 + 3mu/4)/(4(1+mu)(1+mu/2)))``.

    Minimises ``integral_0^inf M_a^2 dr`` (white-noise support acceleration, package absolute
    acceleration variance).

    Parameters
    ----------
    mu : float
        Mass ratio ``m2/m1`` (Eq. 4.6), > 0.
    """
    mu = _check_mu(mu)
    f = math.sqrt(1.0 + mu / 2.0) / (1.0 + mu)
    zeta = math.sqrt(mu * (1.0 + 0.75 * mu) / (4.0 * (1.0 + mu) * (1.0 + mu / 2.0)))
    return _make(mu, f, zeta, "h2", None, "closed form (H2)")


def _objective(
    mu: float, band: tuple[float, float] | None, criterion: str, zeta_fixed: float | None
) -> Callable[[NDArray[np.float64]], float]:
    def fun(x: NDArray[np.float64]) -> float:
        f = math.exp(x[0])
        zeta = zeta_fixed if zeta_fixed is not None else math.exp(x[1])
        k = 1.0 / (f * f * mu)
        if criterion == "peak":
            return peak_over_band(k, mu, zeta, band).peak_Ma
        return h2_integral(k, mu, zeta, band)

    return fun


def _coarse_grid(
    mu: float, band: tuple[float, float] | None, criterion: str, zeta_fixed: float | None
) -> list[tuple[float, float]]:
    """Best few ``(log f, log zeta)`` on a coarse grid (vectorised, sampled peak or H2 sum)."""
    log_f = np.linspace(*_LOG_F_RANGE, 61)
    if zeta_fixed is not None:
        zetas = np.array([zeta_fixed])
    else:
        zetas = np.exp(np.linspace(*_LOG_ZETA_RANGE, 25))
    f = np.exp(log_f)[:, None, None]
    z = zetas[None, :, None]
    lo, hi = band if band is not None else (0.0, 3.0 * max(1.0, float(np.exp(log_f[-1]))))
    r = np.linspace(lo, hi, 1500)[None, None, :]
    m = accel_magnification(1.0 / (f * f * mu), mu, z, r)
    score = (
        m.max(axis=-1) if criterion == "peak" else (m * m).sum(axis=-1) * (r[0, 0, 1] - r[0, 0, 0])
    )
    order = np.argsort(score, axis=None)[:3]
    out = []
    for idx in order:
        i, j = np.unravel_index(idx, score.shape)
        out.append((float(log_f[i]), math.log(max(float(zetas[j]), 1e-300))))
    return out


def tune_absorber(
    mu: float,
    band: tuple[float, float] | None = None,
    criterion: Criterion = "peak",
    *,
    zeta: float | None = None,
    xtol: float = 1e-9,
) -> AbsorberTuning:
    """Numerically optimal ``(k, zeta)`` for mass ratio ``mu``: minimax peak or least H2 of ``M_a``.

    Starts from the closed form (Den Hartog or H2) and from the three best points of a coarse
    ``(f, zeta)`` grid (global guard), polishes each with Nelder-Mead in ``(log f, log zeta)``
    and returns the best.  With ``band`` None the peak is over all ``r`` and H2 is over
    ``0..inf``; the results then agree with :func:`den_hartog` / :func:`h2_closed_form`.

    Parameters
    ----------
    mu : float
        Mass ratio ``m2/m1`` (Eq. 4.6), > 0.
    band : (float, float), optional
        ``(r_lo, r_hi)`` in frequency ratio ``r = omega/omega_n`` (not ``r^2``).
    criterion : {"peak", "h2"}
        Minimise the largest ``M_a`` in the band, or ``integral M_a^2 dr`` over it.
    zeta : float, optional
        Hold the absorber damping ratio fixed and optimise ``k`` only.
    xtol : float
        Final Nelder-Mead tolerance on ``log f`` and ``log zeta``.
    """
    mu = _check_mu(mu)
    band = _check_band(band)
    if criterion not in ("peak", "h2"):
        raise InputError(f"criterion must be 'peak' or 'h2', got {criterion!r}", where="criterion")
    if zeta is not None and not (math.isfinite(zeta) and zeta >= 0):
        raise InputError(f"zeta must be a finite number >= 0, got {zeta!r}", where="zeta")
    if zeta == 0.0 and criterion == "h2":
        raise InputError("H2 of an undamped absorber is infinite", where="zeta", fix="use zeta > 0")
    zeta_fixed = None if zeta is None else float(zeta)
    from scipy import optimize  # here: scipy.optimize costs ~0.2 s to import

    closed = den_hartog(mu) if criterion == "peak" else h2_closed_form(mu)
    starts = [(math.log(closed.f), math.log(closed.zeta))]
    starts += _coarse_grid(mu, band, criterion, zeta_fixed)
    fun = _objective(mu, band, criterion, zeta_fixed)
    best_x: NDArray[np.float64] | None = None
    best_val = math.inf
    for s in dict.fromkeys(starts):  # coarse pass from every start, duplicates dropped
        x0 = np.array([s[0]]) if zeta_fixed is not None else np.array(s)
        res = optimize.minimize(
            fun, x0, method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-8, "maxiter": 2000}
        )
        if res.fun < best_val:
            best_val, best_x = float(res.fun), res.x
    # polish the best, restarting once: Nelder-Mead can stall on the non-smooth minimax ridge
    for _ in range(2):
        if best_x is None or not math.isfinite(best_val):
            break
        res = optimize.minimize(
            fun,
            best_x,
            method="Nelder-Mead",
            options={"xatol": xtol, "fatol": 1e-14, "maxiter": 4000},
        )
        if res.fun <= best_val:
            best_val, best_x = float(res.fun), res.x
    if best_x is None or not math.isfinite(best_val):
        raise SolverError(f"absorber tuning found no finite optimum for mu={mu}, band={band}")
    f = math.exp(best_x[0])
    z = zeta_fixed if zeta_fixed is not None else math.exp(best_x[1])
    return _make(mu, f, z, criterion, band, "numerical (grid + Nelder-Mead)")
