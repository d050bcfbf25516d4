"""Drag: the atmosphere's density along the orbit and the drag specific force.

``a_drag = -(1/2) rho_atm |v_rel| v_rel / B`` with the ballistic coefficient
``B = m / (C_d A)`` (kg/m^2) and the velocity relative to the co-rotating atmosphere
``v_rel``.  The density comes from NRLMSIS 2.1 through ``pymsis`` (inputs F10.7, its 81-day
mean F10.7a, the daily Ap, the date and the position; no network needed when they are given)
or, when pymsis is missing or asked for, the exponential atmosphere of Vallado (2013, Table
8-4), which ignores solar activity.  The result says which was used.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg.environment._inputs import finite_number
from microg.environment.orbit import OrbitSamples
from microg.errors import InputError

__all__ = [
    "AP_DEFAULT",
    "ATMOSPHERES",
    "CD_DEFAULT",
    "DATE_DEFAULT",
    "EXPONENTIAL_ATMOSPHERE",
    "F107_DEFAULT",
    "AtmosphereInputs",
    "Drag",
    "density",
    "drag_accel",
    "exponential_density",
]

#: drag coefficient used with an area when none is given (free-molecular flow, Vallado 2013)
CD_DEFAULT = 2.2
#: solar and geomagnetic inputs used when none are given: moderate activity (assumed)
F107_DEFAULT = 150.0
AP_DEFAULT = 15.0
#: date used when none is given (UTC, an equinox)
DATE_DEFAULT = "2024-03-20T12:00:00"
ATMOSPHERES = ("msis", "exponential")

#: exponential atmosphere, Vallado (2013) Fundamentals of Astrodynamics and Applications, 4th
#: ed., Table 8-4: base altitude km, nominal density kg/m^3, scale height km (CIRA-72 based)
EXPONENTIAL_ATMOSPHERE = np.array(
    [
        (0, 1.225, 7.249),
        (25, 3.899e-2, 6.349),
        (30, 1.774e-2, 6.682),
        (40, 3.972e-3, 7.554),
        (50, 1.057e-3, 8.382),
        (60, 3.206e-4, 7.714),
        (70, 8.770e-5, 6.549),
        (80, 1.905e-5, 5.799),
        (90, 3.396e-6, 5.382),
        (100, 5.297e-7, 5.877),
        (110, 9.661e-8, 7.263),
        (120, 2.438e-8, 9.473),
        (130, 8.484e-9, 12.636),
        (140, 3.845e-9, 16.149),
        (150, 2.070e-9, 22.523),
        (180, 5.464e-10, 29.740),
        (200, 2.789e-10, 37.105),
        (250, 7.248e-11, 45.546),
        (300, 2.418e-11, 53.628),
        (350, 9.518e-12, 53.298),
        (400, 3.725e-12, 58.515),
        (450, 1.585e-12, 60.828),
        (500, 6.967e-13, 63.822),
        (600, 1.454e-13, 71.835),
        (700, 3.614e-14, 88.667),
        (800, 1.170e-14, 124.64),
        (900, 5.245e-15, 181.05),
        (1000, 3.019e-15, 268.00),
    ]
)


def drag_accel(
    density_kg_per_m3: np.ndarray, v_rel_mps: np.ndarray, ballistic_coefficient_kg_per_m2: float
) -> np.ndarray:
    """Drag specific force ``-(1/2) rho |v| v / B``, m/s^2 (against the relative wind).

    Parameters
    ----------
    density_kg_per_m3 : (...,) atmospheric density, kg/m^3
    v_rel_mps : (..., 3) velocity relative to the atmosphere, m/s
    ballistic_coefficient_kg_per_m2 : ``B = m / (C_d A)``, kg/m^2
    """
    v = np.asarray(v_rel_mps, dtype=float)
    speed = np.sqrt(np.sum(v * v, axis=-1))
    rho = np.asarray(density_kg_per_m3, dtype=float)
    return -(0.5 * rho * speed / ballistic_coefficient_kg_per_m2)[..., None] * v


def exponential_density(altitude_m: np.ndarray) -> np.ndarray:
    """Density of the exponential atmosphere (Vallado 2013, Table 8-4), kg/m^3.

    ``rho = rho_0 exp(-(h - h_0) / H)`` with the band of the table holding ``h``.

    Parameters
    ----------
    altitude_m : altitude above the ellipsoid, m (>= 0)
    """
    h_km = np.asarray(altitude_m, dtype=float) / 1e3
    tab = EXPONENTIAL_ATMOSPHERE
    i = np.clip(np.searchsorted(tab[:, 0], h_km, side="right") - 1, 0, tab.shape[0] - 1)
    return tab[i, 1] * np.exp(-(h_km - tab[i, 0]) / tab[i, 2])


@dataclass(frozen=True)
class Drag:
    """Drag inputs: a ballistic coefficient, or an area with a drag coefficient.

    Attributes
    ----------
    ballistic_coefficient_kg_per_m2 : ``B = m / (C_d A)``, kg/m^2
    area_m2 : reference (projected) area, m^2 (instead of ``B``)
    cd : drag coefficient (with ``area_m2``; default :data:`CD_DEFAULT`)
    mass_kg : station mass for ``B`` from the area, kg (default: the model's mass)
    """

    ballistic_coefficient_kg_per_m2: float | None = None
    area_m2: float | None = None
    cd: float | None = None
    mass_kg: float | None = None

    def __post_init__(self) -> None:
        if self.ballistic_coefficient_kg_per_m2 is not None:
            finite_number(
                self.ballistic_coefficient_kg_per_m2, "ballistic_coefficient", positive=True
            )
            if self.area_m2 is not None or self.cd is not None:
                raise InputError(
                    "give a ballistic coefficient, or an area and Cd, not both",
                    where="ballistic_coefficient",
                )
        if self.area_m2 is not None:
            finite_number(self.area_m2, "area", positive=True)
        if self.cd is not None:
            finite_number(self.cd, "cd", positive=True)
            if self.area_m2 is None:
                raise InputError("a drag coefficient needs an area", where="cd", fix="give area")
        if self.mass_kg is not None:
            finite_number(self.mass_kg, "mass", positive=True)

    @property
    def given(self) -> bool:
        """True when there is a drag input."""
        return self.ballistic_coefficient_kg_per_m2 is not None or self.area_m2 is not None

    def beta(self, model_mass_kg: float) -> float | None:
        """Ballistic coefficient, kg/m^2 (None without a drag input)."""
        if self.ballistic_coefficient_kg_per_m2 is not None:
            return float(self.ballistic_coefficient_kg_per_m2)
        if self.area_m2 is None:
            return None
        mass = self.mass_kg if self.mass_kg is not None else model_mass_kg
        return float(mass / ((self.cd if self.cd is not None else CD_DEFAULT) * self.area_m2))

    def to_dict(self, model_mass_kg: float) -> dict[str, Any]:
        """JSON-ready echo."""
        return {
            "given": self.given,
            "ballistic_coefficient_kg_per_m2": self.beta(model_mass_kg),
            "area_m2": self.area_m2,
            "cd": (self.cd if self.cd is not None else CD_DEFAULT) if self.area_m2 else None,
            "mass_kg": (self.mass_kg or model_mass_kg) if self.area_m2 else None,
        }


@dataclass(frozen=True)
class AtmosphereInputs:
    """Atmosphere model and its inputs.

    Attributes
    ----------
    model : ``"msis"`` (NRLMSIS 2.1 through pymsis; the exponential model if pymsis is
        missing) or ``"exponential"`` (Vallado 2013 Table 8-4)
    date_utc : ISO date and time of the first orbit sample, UTC
    f107_sfu : daily F10.7 solar radio flux of the previous day, solar flux units (1e-22 W/m^2/Hz)
    f107a_sfu : its 81-day centred mean, sfu
    ap : daily geomagnetic Ap index
    defaulted : names of the inputs left at their defaults (reported)
    """

    model: str = "msis"
    date_utc: str = DATE_DEFAULT
    f107_sfu: float = F107_DEFAULT
    f107a_sfu: float = F107_DEFAULT
    ap: float = AP_DEFAULT
    defaulted: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.model not in ATMOSPHERES:
            raise InputError(
                f"unknown atmosphere model {self.model!r}",
                where="atmosphere",
                fix="use msis or exponential",
            )
        finite_number(self.f107_sfu, "f107", positive=True)
        finite_number(self.f107a_sfu, "f107a", positive=True)
        finite_number(self.ap, "ap", nonneg=True)
        for name, v, hi in (("f107", self.f107_sfu, 1000.0), ("f107a", self.f107a_sfu, 1000.0)):
            if v > hi:
                raise InputError(f"must be <= {hi:g} sfu, got {v:g}", where=name)
        if self.ap > 400:
            raise InputError(f"must be <= 400, got {self.ap:g}", where="ap")
        self.date64()

    def date64(self) -> np.datetime64:
        """The date as numpy datetime64 (ms); an unreadable date is an InputError."""
        try:
            d = np.datetime64(str(self.date_utc).replace("Z", ""), "ms")
        except ValueError:
            raise InputError(
                f"not an ISO date and time: {self.date_utc!r}",
                where="date",
                fix="write e.g. 2024-03-20T12:00:00",
            ) from None
        year = d.astype("datetime64[Y]").astype(int) + 1970
        if not 1961 <= year <= 2100:
            raise InputError(f"year {year} is outside 1961-2100", where="date")
        return d


def density(samples: OrbitSamples, atm: AtmosphereInputs) -> tuple[np.ndarray, str, str | None]:
    """Density at the samples (kg/m^3), the model used and why the fallback was taken (or None).

    Parameters
    ----------
    samples : OrbitSamples
        The orbit's dates and geodetic positions (deg, m).
    atm : AtmosphereInputs
        The model asked for and its solar and geomagnetic inputs.
    """
    reason = None
    if atm.model == "msis":
        try:
            from pymsis import msis
        except ImportError:
            reason = "pymsis is not installed (pip install 'microg[atmosphere]')"
        else:
            S = samples.time_s.size
            try:
                out = msis.calculate(
                    samples.date.astype("datetime64[s]"),
                    samples.longitude_deg,
                    samples.latitude_deg,
                    samples.altitude_m / 1e3,
                    f107s=np.full(S, atm.f107_sfu),
                    f107as=np.full(S, atm.f107a_sfu),
                    aps=np.full((S, 7), atm.ap),
                    version=2.1,
                )
            except Exception as exc:  # noqa: BLE001 - any pymsis failure falls back, with reason
                reason = f"pymsis failed ({type(exc).__name__}: {exc})"
            else:
                rho = np.asarray(out, float).reshape(S, -1)[:, 0]
                if np.all(np.isfinite(rho)) and np.all(rho >= 0):
                    return rho, "NRLMSIS 2.1 (pymsis)", None
                reason = "pymsis returned non-finite densities"
    rho = exponential_density(samples.altitude_m)
    return rho, "exponential (Vallado 2013, Table 8-4; no solar-activity dependence)", reason
