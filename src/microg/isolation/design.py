"""Mount design in physical units and the check of the report's Section 4.2 claims.

:func:`design_mount` returns the stiffest mount spring ``k1`` (largest natural frequency) that
keeps ``M_a`` at or below a target over a disturbance band, with or without an absorber.
:func:`check_section42_claims` recomputes every quantitative statement of Section 4.2 (and
conclusion 5) of the report and says which hold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.errors import InputError
from microg.isolation.absorber import AbsorberTuning, _check_mu, tune_absorber
from microg.isolation.transmissibility import (
    accel_magnification,
    accel_magnification_no_absorber,
)
from microg.units import G0, G0_US, IN, LBF, check_limit

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "MountDesign",
    "ClaimCheck",
    "Section42Claims",
    "FIGURE8_CURVES",
    "max_stiffness_no_absorber",
    "design_mount",
    "check_section42_claims",
]

#: lbf/in per N/m
_N_PER_M_TO_LBF_PER_IN = IN / LBF

#: Figure 8 of the report (zeta = 0.2): the k values drawn for fixed mu, the mu values for fixed k
#: (the figure itself is lost from the scan; these are the report's panel parameters with a
#: representative set of the "various" values)
FIGURE8_CURVES: dict[str, tuple[float, ...]] = {
    "mu_panels": (0.01, 0.025, 0.05),
    "k_values": (5.0, 10.0, 15.0, 20.0),
    "k_panels": (10.0, 15.0, 20.0),
    "mu_values": (0.01, 0.025, 0.05),
}


def max_stiffness_no_absorber(mass: float, omega: float, target: float = 1.0) -> float:
    """Largest ``k1`` (N/m) with ``M_a = 1/(r^2 - 1) <= target`` at ``omega`` and above.

    ``r^2 = m1 omega^2/k1 >= 1 + 1/target``, so ``k1 <= m1 omega^2 target/(1 + target)``;
    ``target = 1`` gives the report's ``r^2 > 2`` boundary, ``k1 < m1 omega^2/2``.

    Parameters
    ----------
    mass : float
        Package mass ``m1``, kg.
    omega : float
        Lowest disturbance angular frequency, rad/s.
    target : float
        Largest acceptable ``M_a`` (0 < target <= 1).
    """
    return mass * omega * omega * target / (1.0 + target)


@dataclass(frozen=True)
class MountDesign:
    """Mount (and absorber) meeting ``M_a <= target`` over a disturbance band.

    Attributes
    ----------
    mass : package mass ``m1``, kg.
    omega_band : ``(lo, hi)`` disturbance angular frequencies, rad/s.
    target : required largest ``M_a`` over the band.
    k1 : largest mount stiffness meeting the target, N/m.
    k1_lbf_per_in : the same in lbf/in.
    omega_n : mount natural frequency ``sqrt(k1/m1)``, rad/s.
    freq_hz_n : ``omega_n/(2 pi)``, Hz.
    r_band : the band as frequency ratios ``omega/omega_n``.
    achieved_Ma : largest ``M_a`` over the band for this design.
    sag_1g : static deflection ``m1 g0/k1`` under 1 g (ground test), m.
    mu, k, zeta, f : absorber ratios (Eq. 4.6) or None.
    m2, k2, c : absorber mass (kg), stiffness (N/m), damping (N s/m) or None.
    """

    mass: float
    omega_band: tuple[float, float]
    target: float
    k1: float
    k1_lbf_per_in: float
    omega_n: float
    freq_hz_n: float
    r_band: tuple[float, float]
    achieved_Ma: float  # noqa: N815 - report symbol M_a
    sag_1g: float
    mu: float | None = None
    k: float | None = None
    zeta: float | None = None
    f: float | None = None
    m2: float | None = None
    k2: float | None = None
    c: float | None = None

    @property
    def band_hz(self) -> tuple[float, float]:
        """The disturbance band, Hz."""
        return self.omega_band[0] / (2 * math.pi), self.omega_band[1] / (2 * math.pi)

    def magnification(self, freq_hz: np.ndarray) -> np.ndarray:
        """``M_a`` of this design at support frequencies ``freq_hz`` (Hz), with its absorber."""
        r = np.asarray(freq_hz, float) / self.freq_hz_n
        if self.mu is None or self.k is None or self.zeta is None:
            with np.errstate(divide="ignore"):
                return accel_magnification_no_absorber(r)
        return accel_magnification(self.k, self.mu, self.zeta, r)

    def default_freq_hz(self) -> np.ndarray:
        """801 log-spaced frequencies from f_n / 20 to 5 times the band's top, Hz.

        The band edges are included.
        """
        lo, hi = self.band_hz
        grid = np.geomspace(self.freq_hz_n / 20, max(5 * hi, 20 * self.freq_hz_n), 801)
        return np.unique(np.r_[grid, lo, hi])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready design; keys carry units (``k1_N_per_m``, ``sag_1g_m``, ``mass_kg``)."""
        return {
            "mass_kg": self.mass,
            "omega_band": [float(w) for w in self.omega_band],
            "band_hz": list(self.band_hz),
            "target_Ma": self.target,
            "k1_N_per_m": self.k1,
            "k1_lbf_per_in": self.k1_lbf_per_in,
            "omega_n": self.omega_n,
            "natural_freq_hz": self.freq_hz_n,
            "r_band": [float(r) for r in self.r_band],
            "achieved_Ma": self.achieved_Ma,
            "sag_1g_m": self.sag_1g,
            "mu": self.mu,
            "absorber_k": self.k,
            "absorber_zeta": self.zeta,
            "absorber_f": self.f,
            "m2_kg": self.m2,
            "k2_N_per_m": self.k2,
            "c_N_s_per_m": self.c,
        }

    def to_xarray(self, freq_hz: np.ndarray | None = None) -> Any:
        """``M_a`` over support frequency as an ``xarray.Dataset`` (dim ``freq_hz``).

        Parameters
        ----------
        freq_hz : ndarray, optional
            Frequencies, Hz (default :meth:`default_freq_hz`).
        """
        import xarray as xr

        f = self.default_freq_hz() if freq_hz is None else np.asarray(freq_hz, float)
        return xr.Dataset(
            {"Ma": ("freq_hz", self.magnification(f), {"units": "1", "long_name": "M_a"})},
            coords={"freq_hz": ("freq_hz", f, {"units": "Hz"})},
            attrs={k: v for k, v in self.to_dict().items() if v is not None}
            | {"omega_band_units": "rad/s", "omega_n_units": "rad/s"},
        )

    def plot(self, ax: Any = None) -> Figure:
        """``M_a`` against frequency, the band and the target (``plotting.isolation``).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.isolation import plot_mount_design

        return plot_mount_design(self, ax=ax)


def _validate_design(mass: float, band: tuple[float, float], target: float) -> None:
    if not (math.isfinite(mass) and mass > 0):
        raise InputError(f"must be a finite number > 0, got {mass!r}", where="mass")
    lo, hi = band
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
        raise InputError(f"need 0 < LO <= HI < inf, got {band!r}", where="omega band")
    for value in (lo, hi):  # one documented range for every frequency (microg.units)
        check_limit(value, "angular_frequency", where="omega band")
    if not (math.isfinite(target) and 0 < target <= 1):
        raise InputError(
            f"must be in (0, 1], got {target!r}",
            where="target",
            fix="a rigid mount already gives M_a = 1",
        )


def design_mount(
    mass: float,
    omega_band: tuple[float, float],
    target: float = 0.5,
    *,
    mu: float | None = None,
    zeta: float | None = None,
) -> MountDesign:
    """Stiffest mount meeting ``M_a <= target`` for every disturbance frequency in a band.

    Without absorber: ``k1 = m1 omega_lo^2 target/(1 + target)`` (closed form).  With absorber
    mass ratio ``mu``: the smallest lower frequency ratio ``r_lo`` for which the minimax-tuned
    absorber (:func:`~microg.isolation.absorber.tune_absorber` over ``[r_lo, r_lo hi/lo]``)
    meets the target, found by a coarse scan then bisection; ``k1 = m1 (omega_lo/r_lo)^2``.

    Parameters
    ----------
    mass : float
        Package mass ``m1``, kg.
    omega_band : (float, float)
        Lowest and highest disturbance angular frequency, rad/s (equal for one frequency).
    target : float
        Largest acceptable ``M_a`` over the band, in (0, 1].
    mu : float, optional
        Absorber mass ratio ``m2/m1`` (Eq. 4.6); needs a band of nonzero width.
    zeta : float, optional
        Hold the absorber damping ratio fixed (default: optimised).
    """
    lo, hi = float(omega_band[0]), float(omega_band[1])
    _validate_design(mass, (lo, hi), target)
    if mu is None:
        k1 = max_stiffness_no_absorber(mass, lo, target)
        wn = math.sqrt(k1 / mass)
        achieved = float(accel_magnification_no_absorber(lo / wn))
        return _finish(mass, (lo, hi), target, k1, achieved)
    mu = _check_mu(mu)
    if hi <= lo:
        raise InputError(
            "an absorber design needs a band of frequencies",
            where="omega band",
            fix="give LO < HI: at one frequency an undamped absorber tuned to it gives M_a = 0",
        )
    ratio = hi / lo

    def tuned(r_lo: float) -> AbsorberTuning:
        return tune_absorber(mu, (r_lo, r_lo * ratio), "peak", zeta=zeta, xtol=1e-6)

    # coarse scan of r_lo from the no-absorber value downwards; keep the last feasible point
    r_noabs = math.sqrt(1.0 + 1.0 / target)
    grid = r_noabs * np.geomspace(1.0, 0.25, 9)
    feasible, infeasible = None, None
    best = None
    for r_lo in grid:
        t = tuned(float(r_lo))
        if t.peak_Ma <= target:
            feasible, best = float(r_lo), t
        else:
            infeasible = float(r_lo)
            if feasible is not None:
                break
    if feasible is None:
        # the absorber cannot meet the target in the scanned range: fall back to no absorber
        # at the same band (a rigid absorber adds mass, so this is conservative)
        k1 = max_stiffness_no_absorber(mass, lo, target)
        return _finish(
            mass,
            (lo, hi),
            target,
            k1,
            float(accel_magnification_no_absorber(lo / math.sqrt(k1 / mass))),
        )
    if infeasible is not None and infeasible < feasible:
        a, b = infeasible, feasible
        while b / a - 1.0 > 1e-4:
            mid = math.sqrt(a * b)
            t = tuned(mid)
            if t.peak_Ma <= target:
                b, best = mid, t
            else:
                a = mid
        feasible = b
    assert best is not None
    wn = lo / feasible
    k1 = mass * wn * wn
    m2 = mu * mass
    k2 = k1 / best.k
    return _finish(
        mass,
        (lo, hi),
        target,
        k1,
        best.peak_Ma,
        mu=mu,
        k=best.k,
        zeta=best.zeta,
        f=best.f,
        m2=m2,
        k2=k2,
        c=2.0 * best.zeta * math.sqrt(m2 * k2),
    )


def _finish(
    mass: float,
    band: tuple[float, float],
    target: float,
    k1: float,
    achieved: float,
    **absorber: float,
) -> MountDesign:
    wn = math.sqrt(k1 / mass)
    return MountDesign(
        mass=mass,
        omega_band=band,
        target=target,
        k1=k1,
        k1_lbf_per_in=k1 * _N_PER_M_TO_LBF_PER_IN,
        omega_n=wn,
        freq_hz_n=wn / (2.0 * math.pi),
        r_band=(band[0] / wn, band[1] / wn),
        achieved_Ma=achieved,
        sag_1g=mass * G0 / k1,
        **absorber,
    )


# ----------------------------------------------------------------------------- Section 4.2


@dataclass(frozen=True)
class ClaimCheck:
    """One statement of the report, what it says, what recomputation gives, and the verdict.

    Attributes
    ----------
    id : short label ("a" ... "e").
    statement : the report's words.
    holds : True when the recomputation supports the statement.
    printed : the report's number or condition.
    recomputed : the recomputed number or condition, in words.
    values : the numbers behind ``recomputed``.
    note : explanation of any difference.
    """

    id: str
    statement: str
    holds: bool
    printed: str
    recomputed: str
    values: dict[str, float] = field(default_factory=dict)
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready check (``values`` keep their unit-suffixed names)."""
        return {
            "id": self.id,
            "statement": self.statement,
            "holds": bool(self.holds),
            "printed": self.printed,
            "recomputed": self.recomputed,
            "values": {k: float(v) for k, v in self.values.items()},
            "note": self.note,
        }


@dataclass(frozen=True)
class Section42Claims:
    """All checks of Section 4.2 and conclusion 5, with the inputs used."""

    weight_lbf: float
    omega: float
    omega_fundamental: float
    omega_lowest_bending: float
    zeta: float
    mu_max: float
    checks: tuple[ClaimCheck, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready inputs (``omega*`` in rad/s) and every check."""
        return {
            "weight_lbf": self.weight_lbf,
            "omega": self.omega,
            "omega_fundamental": self.omega_fundamental,
            "omega_lowest_bending": self.omega_lowest_bending,
            "zeta": self.zeta,
            "mu_max": self.mu_max,
            "checks": [c.to_dict() for c in self.checks],
        }

    def by_id(self, claim_id: str) -> ClaimCheck:
        """The check labelled ``claim_id``."""
        for c in self.checks:
            if c.id == claim_id:
                return c
        raise KeyError(claim_id)


def _lbf_per_in(k_lb_per_ft: float) -> float:
    return k_lb_per_ft / 12.0


def _claim_a(zeta: float) -> ClaimCheck:
    r2 = np.linspace(0.0, 12.0, 240001)
    r = np.sqrt(r2)
    crossings, max_above = [], []
    for mu in FIGURE8_CURVES["mu_panels"]:
        for k in FIGURE8_CURVES["k_values"]:
            m = accel_magnification(k, mu, zeta, r)
            crossings.append(float(r2[np.flatnonzero(m >= 1.0)[-1]]))
            max_above.append(float(m[r2 > 2.0].max()))
    for k in FIGURE8_CURVES["k_panels"]:
        for mu in FIGURE8_CURVES["mu_values"]:
            m = accel_magnification(k, mu, zeta, r)
            crossings.append(float(r2[np.flatnonzero(m >= 1.0)[-1]]))
            max_above.append(float(m[r2 > 2.0].max()))
    # r^2 above which M_a <= 0.5 without absorber: 1/(r^2 - 1) = 0.5 -> r^2 = 3
    values = {
        "no_absorber_Ma_below_1_for_r2_above": 2.0,
        "figure8_crossing_r2_min": min(crossings),
        "figure8_crossing_r2_max": max(crossings),
        "figure8_max_Ma_for_r2_above_2": max(max_above),
        "no_absorber_Ma_at_r2_3": float(accel_magnification_no_absorber(math.sqrt(3.0))),
    }
    return ClaimCheck(
        id="a",
        statement="M_a can be effectively reduced for r^2 > 2 (all Figure 8 curves)",
        holds=True,
        printed="M_a reduced for r^2 > 2",
        recomputed=(
            f"no absorber: M_a = 1/(r^2 - 1) < 1 exactly for r^2 > 2; Figure 8 curves "
            f"(zeta = {zeta}) cross M_a = 1 at r^2 = {min(crossings):.3f}..{max(crossings):.3f}"
        ),
        values=values,
        note=(
            "holds as the M_a < 1 boundary, to within 2.5%; just above r^2 = 2 the curves are "
            f"still up to M_a = {max(max_above):.3f}, and M_a <= 0.5 needs r^2 >= 3"
        ),
    )


def check_section42_claims(
    *,
    weight_lbf: float = 1000.0,
    omega: float = 1.0,
    omega_fundamental: float = 1.021,
    omega_lowest_bending: float = 0.656,
    zeta: float = 0.2,
    mu_max: float = 0.25,
) -> Section42Claims:
    """Recompute the quantitative claims of Section 4.2 and conclusion 5 of the report.

    Weights convert to mass with the report's g = 32.2 ft/s^2.

    Parameters
    ----------
    weight_lbf : float
        Package weight, lbf (the report's 1,000 lb).
    omega : float
        "Frequency of the IOC space station in elastic vibration", rad/s (the report's 1).
    omega_fundamental : float
        Fundamental bending frequency with orbiter, X-Z plane (Table 4: 1.021 rad/s).
    omega_lowest_bending : float
        Lowest bending frequency of Table 4 (0.656 rad/s, Y-Z without orbiter).
    zeta : float
        Absorber damping ratio of Figure 8 (0.2).
    mu_max : float
        Largest practical absorber mass ratio searched for claim (d).
    """
    mu_max = _check_mu(mu_max, where="mu_max")
    m1 = weight_lbf / G0_US  # slug
    k_max = {w: m1 * w * w / 2.0 for w in (omega, omega_fundamental, omega_lowest_bending)}  # lb/ft
    k_printed_lb_ft = 5.0 * 12.0
    r2_printed = m1 * omega**2 / k_printed_lb_ft
    two_w_over_g = 2.0 * weight_lbf / G0_US  # lb/ft when omega = 1 rad/s (units of k1 hidden)

    a = _claim_a(zeta)

    b = ClaimCheck(
        id="b",
        statement="since the elastic frequency is about 1 rad/s, it requires that k1 > 2 W1/g",
        holds=False,
        printed="k1 > 2 W1/g",
        recomputed="k1 < m1 omega^2/2 = W1 omega^2/(2 g), i.e. k1 < W1/(2 g) at 1 rad/s",
        values={
            "printed_bound_lb_per_ft": two_w_over_g,
            "correct_bound_lb_per_ft": k_max[omega],
            "ratio_printed_to_correct": two_w_over_g / k_max[omega],
            "r2_at_printed_bound": m1 * omega**2 / two_w_over_g,
        },
        note=(
            "r^2 = m1 omega^2/k1 > 2 needs k1 < m1 omega^2/2: the printed inequality has the "
            "wrong direction and a factor 4 (2 for 1/2); k1 = 2 W1/g gives r^2 = 0.5, "
            f"where M_a = {float(accel_magnification_no_absorber(math.sqrt(0.5))):.2f} (amplified)"
        ),
    )

    c = ClaimCheck(
        id="c",
        statement="for a 1,000 lb package the spring constant must be less than 5 lb/in",
        holds=False,
        printed="k1 < 5 lb/in",
        recomputed=(
            f"k1 < {_lbf_per_in(k_max[omega]):.3f} lb/in at {omega} rad/s, "
            f"{_lbf_per_in(k_max[omega_fundamental]):.3f} lb/in at {omega_fundamental} rad/s, "
            f"{_lbf_per_in(k_max[omega_lowest_bending]):.3f} lb/in to cover "
            f"{omega_lowest_bending} rad/s"
        ),
        values={
            "mass_slug": m1,
            "k1_max_lbf_per_in_at_omega": _lbf_per_in(k_max[omega]),
            "k1_max_lbf_per_in_at_fundamental": _lbf_per_in(k_max[omega_fundamental]),
            "k1_max_lbf_per_in_at_lowest_bending": _lbf_per_in(k_max[omega_lowest_bending]),
            "two_w_over_g_lbf_per_in": _lbf_per_in(two_w_over_g),
            "r2_with_5_lbf_per_in": r2_printed,
            "Ma_with_5_lbf_per_in": float(accel_magnification_no_absorber(math.sqrt(r2_printed))),
            "sag_1g_in_at_bound": weight_lbf / _lbf_per_in(k_max[omega]),
        },
        note=(
            f"5 lb/in is 2 W/g = {_lbf_per_in(two_w_over_g):.2f} lb/in rounded, i.e. it follows "
            f"from the wrong inequality (b); with 5 lb/in, r^2 = {r2_printed:.3f} at 1 rad/s and "
            "the mount amplifies (M_a > 2)"
        ),
    )

    # (d) band-wide: minimax over 0.5 < r^2 < 2 (r in [sqrt 0.5, sqrt 2])
    band = (math.sqrt(0.5), math.sqrt(2.0))
    d_values: dict[str, float] = {}
    best_free = tune_absorber(mu_max, band, "peak", xtol=1e-6)
    d_values["best_peak_Ma_mu_max_zeta_free"] = best_free.peak_Ma
    d_values["best_k_mu_max_zeta_free"] = best_free.k
    d_values["best_zeta_mu_max_zeta_free"] = best_free.zeta
    for mu in (0.05, mu_max):
        t = tune_absorber(mu, band, "peak", zeta=zeta, xtol=1e-6)
        d_values[f"best_peak_Ma_mu_{mu:g}_zeta_{zeta:g}"] = t.peak_Ma
    d_values["den_hartog_bound_mu_max"] = math.sqrt(1.0 + 2.0 / mu_max)
    # pointwise: at each single r^2 in the range, the smallest M_a any k gives (zeta fixed)
    r2 = np.linspace(0.5, 2.0, 151)
    ks = np.geomspace(0.05, 1e4, 4000)[:, None]
    best_pointwise = {}
    for mu in (0.05, mu_max):
        m = accel_magnification(ks, mu, zeta, np.sqrt(r2)[None, :]).min(axis=0)
        best_pointwise[mu] = m
        d_values[f"pointwise_min_Ma_mu_{mu:g}_zeta_{zeta:g}_worst_r2"] = float(m.max())
        d_values[f"pointwise_min_Ma_mu_{mu:g}_zeta_{zeta:g}_best_r2"] = float(m.min())
    frac = float(np.mean(best_pointwise[mu_max] < 0.5))
    d_values["fraction_of_range_pointwise_below_half_mu_max"] = frac
    d = ClaimCheck(
        id="d",
        statement=(
            "for 0.5 < r^2 < 2, M_a can be made less than 0.5 by a proper combination of mu and k"
        ),
        holds=False,
        printed="M_a < 0.5 over 0.5 < r^2 < 2",
        recomputed=(
            f"best largest M_a over the band: {best_free.peak_Ma:.3f} (mu = {mu_max}, k and zeta "
            f"optimised), {d_values[f'best_peak_Ma_mu_{mu_max:g}_zeta_{zeta:g}']:.3f} at zeta = "
            f"{zeta}; even one frequency at a time (zeta = {zeta}, mu <= {mu_max}) M_a < 0.5 is "
            f"reachable on {100 * frac:.0f}% of the range"
        ),
        values=d_values,
        note=(
            "the band contains the package resonance; Den Hartog's fixed points bound the peak "
            f"below by sqrt(1 + 2/mu) = {math.sqrt(1 + 2 / mu_max):.2f} at mu = {mu_max}, so no "
            "passive absorber of practical mass gets M_a < 1 over this band, let alone 0.5"
        ),
    )

    # (e) conclusion 5: "can reduce the acceleration to 1/4 of its magnitude, at most"
    e_values: dict[str, float] = {}
    for frac_target in (0.25, 0.1, 0.01):
        r2_needed = 1.0 + 1.0 / frac_target
        k_lb_ft = m1 * omega**2 / r2_needed
        e_values[f"r2_for_Ma_{frac_target:g}"] = r2_needed
        e_values[f"k1_lbf_per_in_for_Ma_{frac_target:g}_at_omega"] = _lbf_per_in(k_lb_ft)
        e_values[f"sag_1g_ft_for_Ma_{frac_target:g}"] = weight_lbf / k_lb_ft
        k_lb_ft_low = m1 * omega_lowest_bending**2 / r2_needed
        e_values[f"k1_lbf_per_in_for_Ma_{frac_target:g}_at_lowest_bending"] = _lbf_per_in(
            k_lb_ft_low
        )
    e = ClaimCheck(
        id="e",
        statement=(
            "an effective suspension system can reduce the acceleration to 1/4 of its "
            "magnitude, at most"
        ),
        holds=False,
        printed="M_a >= 1/4",
        recomputed=(
            "M_a = 1/(r^2 - 1) has no lower limit: 1/4 needs r^2 = 5 "
            f"(k1 = {e_values['k1_lbf_per_in_for_Ma_0.25_at_omega']:.3f} lb/in at {omega} rad/s), "
            f"1/10 needs r^2 = 11 ({e_values['k1_lbf_per_in_for_Ma_0.1_at_omega']:.3f} lb/in), "
            f"1/100 needs r^2 = 101 ({e_values['k1_lbf_per_in_for_Ma_0.01_at_omega']:.4f} lb/in)"
        ),
        values=e_values,
        note=(
            "1/4 is a practical limit of spring softness, not a physical one: the 1 g sag of the "
            f"1/4 design is {e_values['sag_1g_ft_for_Ma_0.25']:.0f} ft, so such mounts cannot be "
            "ground tested and need large rattle space; more reduction needs active isolation"
        ),
    )
    return Section42Claims(
        weight_lbf=weight_lbf,
        omega=omega,
        omega_fundamental=omega_fundamental,
        omega_lowest_bending=omega_lowest_bending,
        zeta=zeta,
        mu_max=mu_max,
        checks=(a, b, c, d, e),
    )
