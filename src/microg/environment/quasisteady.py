"""The quasi-steady acceleration environment (below 0.01 Hz): gravity gradient, rotation, drag.

What is computed
----------------
The acceleration an accelerometer fixed to the structure at a point ``P`` reads (the specific
force: inertial acceleration of the point minus the gravitational acceleration there, the
convention of the SAMS/MAMS/OARE measurements and of the vibratory predictions), for a rigid
station whose centre of mass (CM) is in a circular orbit of radius ``R``::

    a(P) = [g(R_cm) - g(R_cm + rho)]  +  [alpha x rho + omega x (omega x rho)]  +  a_drag
           gravity gradient (tidal)      rotation (attitude rate and acceleration)  drag

with ``rho = P - CM``, ``g(r) = -mu r / |r|^3`` (two-body gravity), ``omega`` and ``alpha`` the
body's inertial angular velocity and acceleration (station frame), and
``a_drag = -(1/2) rho_atm |v_rel| v_rel / B`` the drag specific force of ballistic coefficient
``B = m / (C_d A)`` (kg/m^2) in the atmosphere of density ``rho_atm``, with the velocity
relative to the co-rotating atmosphere ``v_rel``.  The apparent acceleration of a free particle
released at ``P`` relative to the structure is the negative of ``a(P)`` (SMAD, Wertz & Larson,
Table 8-2 lists that form).

* Gravity gradient: the full 3-D two-body difference, not its linearisation, evaluated without
  cancellation (:func:`gravity_gradient_accel`).  To first order in ``rho/R`` it is
  ``-n^2 (3 r_hat (r_hat . rho) - rho)``, ``n = sqrt(mu / R^3)`` the mean motion.
* Rotation: ``alpha x rho + omega x (omega x rho)`` (:func:`rotation_accel`); no Coriolis term
  (the point is fixed in the structure).  In LVLH hold ``omega = n`` about the orbit normal and
  the sum of the two terms is the classic ``(0, n^2 y, -3 n^2 z)`` in the station frame.
* Drag: :func:`drag_accel`, with the density from NRLMSIS 2.1 through ``pymsis`` (inputs F10.7,
  its 81-day mean F10.7a, the daily Ap, the date and the position; no network needed when they
  are given) or, when pymsis is missing or asked for, the exponential atmosphere of Vallado
  (2013, Table 8-4), which ignores solar activity.  The output says which was used.

Frames
------
Station frame (the models' frame, the seed report's): x along the flight direction, y along the
solar boom (the orbit normal, pitch axis), z along the keel.  In the seed report the main body
and the orbiter hang below the keel ("Z is measured from the bottom end of the keel
extension"), so in LVLH hold +z points away from the Earth (zenith).  The station frame is then
(velocity, orbit normal, zenith).  LVLH (the ISS convention): X_LVLH along the velocity,
Z_LVLH to nadir, Y_LVLH = Z x X (against the orbit normal).  Hence, in LVLH hold,
``a_lvlh = LVLH_FROM_STATION @ a_station`` with ``LVLH_FROM_STATION = diag(1, -1, -1)`` (a
180-degree rotation about x); another mounting is the ``lvlh_from_station`` of
:class:`Attitude`.

Attitudes (:class:`Attitude`): ``"lvlh"`` (LVLH hold: the body turns once per orbit about the
orbit normal), ``"inertial"`` (fixed in inertial space; aligned with LVLH at the first sample),
``"rate"`` (a constant body rate ``omega`` and an angular acceleration ``alpha`` given in the
station frame; aligned with LVLH at the first sample).  The orbit (inclination, node, argument
of latitude) matters for drag only (density and co-rotation); one orbit is sampled uniformly
in time, giving orbital averages (of each vector, in the station and the LVLH frame) and peaks
(of the magnitude).

Compliance is judged against the ISS quasi-steady requirement, 1 micro-g at internal payload
locations (NASA-CR-205357; ``microg/data/quasi_steady_requirement.toml``), on the peak
magnitude over the orbit.  Without a drag input (ballistic coefficient, or area and C_d) the
verdict is withheld (``complies`` None) and a warning says so.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.errors import InputError
from microg.units import G0, parse_quantity

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "AP_DEFAULT",
    "ATTITUDES",
    "Attitude",
    "AtmosphereInputs",
    "CD_DEFAULT",
    "DATE_DEFAULT",
    "Drag",
    "EARTH_EQUATORIAL_RADIUS_M",
    "EARTH_ROTATION_RAD_S",
    "EXPONENTIAL_ATMOSPHERE",
    "F107_DEFAULT",
    "LVLH_FROM_STATION",
    "OrbitInputs",
    "PointQuasiSteady",
    "QuasiSteadyMap",
    "QuasiSteadyRequirement",
    "QuasiSteadyResult",
    "drag_accel",
    "exponential_density",
    "geodetic",
    "gravity_gradient_accel",
    "gravity_gradient_linear",
    "orbit_samples",
    "peak_magnitude",
    "quasi_steady",
    "quasi_steady_requirement",
    "rotation_accel",
]

#: WGS84 equatorial radius, m, and flattening
EARTH_EQUATORIAL_RADIUS_M = 6378137.0
EARTH_FLATTENING = 1.0 / 298.257223563
#: Earth rotation rate, rad/s (IERS, the rate of the Earth rotation angle)
EARTH_ROTATION_RAD_S = 7.292115146706979e-5
#: lowest and highest orbit altitudes accepted, m (below 100 km there is no orbit)
MIN_ALTITUDE_M = 100e3
MAX_RADIUS_M = 1e8
#: station frame -> LVLH in LVLH hold (x velocity, y orbit normal, z zenith -> X, -Y, -Z)
LVLH_FROM_STATION = np.diag([1.0, -1.0, -1.0])
#: drag coefficient used with an area when none is given (free-molecular flow, Vallado 2013)
CD_DEFAULT = 2.2
#: solar and geomagnetic inputs used when none are given: moderate activity (assumed)
F107_DEFAULT = 150.0
AP_DEFAULT = 15.0
#: date used when none is given (UTC, an equinox)
DATE_DEFAULT = "2024-03-20T12:00:00"
ATTITUDES = ("lvlh", "inertial", "rate")
ATMOSPHERES = ("msis", "exponential")
#: largest number of orbit samples
MAX_SAMPLES = 100_000
#: points per vectorised block of the map (bounds the (points, samples) scratch memory)
_MAP_BLOCK = 8192

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


# ------------------------------------------------------------------------------- kernels


def gravity_gradient_accel(rho_m: np.ndarray, r_cm_m: np.ndarray, mu: float) -> np.ndarray:
    """Tidal specific force ``g(R) - g(R + rho)`` at offsets ``rho`` from the CM, m/s^2.

    The full two-body difference (no linearisation), written without cancellation: with
    ``s = R + rho``, ``g(R) - g(s) = mu [rho / S^3 + R (1/S^3 - 1/R^3)]`` and
    ``1/S^3 - 1/R^3 = (R - S)(R^2 + R S + S^2) / (R^3 S^3)``,
    ``R - S = -(2 R . rho + rho . rho) / (R + S)``.

    Parameters
    ----------
    rho_m : (..., 3) offsets of the points from the centre of mass, m
    r_cm_m : (..., 3) position of the centre of mass from the Earth's centre, m (broadcasts)
    mu : gravitational parameter, m^3/s^2

    Returns
    -------
    (..., 3) m/s^2, in the frame of the inputs.
    """
    rho = np.asarray(rho_m, dtype=float)
    rc = np.asarray(r_cm_m, dtype=float)
    s = rc + rho
    R2 = np.einsum("...i,...i->...", rc, rc)[..., None]
    S2 = np.einsum("...i,...i->...", s, s)[..., None]
    R, S = np.sqrt(R2), np.sqrt(S2)
    two_r_rho = 2.0 * np.einsum("...i,...i->...", rho, rc)[..., None]
    r_minus_s = -(two_r_rho + np.einsum("...i,...i->...", rho, rho)[..., None]) / (R + S)
    S3 = S2 * S
    inv_diff = r_minus_s * (R2 + R * S + S2) / (R2 * R * S3)
    return mu * (rho / S3 + rc * inv_diff)


def gravity_gradient_linear(rho_m: np.ndarray, r_hat: np.ndarray, mean_motion: float) -> np.ndarray:
    """First-order tidal specific force ``-n^2 (3 r_hat (r_hat . rho) - rho)``, m/s^2.

    Parameters
    ----------
    rho_m : (..., 3) offsets from the centre of mass, m
    r_hat : (..., 3) unit vector from the Earth's centre to the CM (broadcasts)
    mean_motion : ``n = sqrt(mu / R^3)``, rad/s
    """
    rho = np.asarray(rho_m, dtype=float)
    rh = np.asarray(r_hat, dtype=float)
    return -(mean_motion**2) * (3.0 * rh * np.sum(rh * rho, axis=-1)[..., None] - rho)


def rotation_accel(
    rho_m: np.ndarray, omega_rad_s: np.ndarray, alpha_rad_per_s2: np.ndarray | None = None
) -> np.ndarray:
    """Acceleration of a point fixed in a rotating body: ``alpha x rho + omega x (omega x rho)``.

    Parameters
    ----------
    rho_m : (..., 3) offsets from the centre of mass, m
    omega_rad_s : (3,) inertial angular velocity of the body, rad/s (same frame)
    alpha_rad_per_s2 : (3,) angular acceleration, rad/s^2 (zero by default)

    Returns
    -------
    (..., 3) m/s^2 (centripetal: toward the rotation axis).
    """
    rho = np.asarray(rho_m, dtype=float)
    w = np.asarray(omega_rad_s, dtype=float)
    # omega x (omega x rho) = (omega omega^T - |omega|^2 I) rho; alpha x rho = [alpha]x rho
    m = np.outer(w, w) - float(w @ w) * np.eye(3)
    if alpha_rad_per_s2 is not None:
        a = np.asarray(alpha_rad_per_s2, dtype=float)
        m = m + np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return rho @ m.T


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


def geodetic(r_ecef_m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """WGS84 geodetic latitude and longitude (degrees) and altitude (m) of ECEF positions.

    Bowring's formula with two refinements (sub-millimetre at orbital altitudes).

    Parameters
    ----------
    r_ecef_m : (..., 3) Earth-fixed positions, m
    """
    r = np.asarray(r_ecef_m, dtype=float)
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    a = EARTH_EQUATORIAL_RADIUS_M
    f = EARTH_FLATTENING
    b = a * (1.0 - f)
    e2 = f * (2.0 - f)
    ep2 = e2 / (1.0 - e2)
    p = np.hypot(x, y)
    lat = np.arctan2(z, p * (1.0 - e2))
    for _ in range(3):
        beta = np.arctan2((1.0 - f) * np.sin(lat), np.cos(lat))
        lat = np.arctan2(z + ep2 * b * np.sin(beta) ** 3, p - e2 * a * np.cos(beta) ** 3)
    sin_lat = np.sin(lat)
    n_rad = a / np.sqrt(1.0 - e2 * sin_lat * sin_lat)
    cos_lat = np.cos(lat)
    # altitude along the normal, well conditioned at every latitude
    alt = p * cos_lat + z * sin_lat - n_rad * (1.0 - e2 * sin_lat * sin_lat)
    return np.degrees(lat), np.degrees(np.arctan2(y, x)), alt


def _rodrigues(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) about the unit ``axis`` by ``angle`` (n,), rad."""
    k = np.asarray(axis, float)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    a = np.asarray(angle, float)[:, None, None]
    return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * (K @ K)


# ------------------------------------------------------------------------------- inputs


def _finite(value: float, where: str, *, positive: bool = False, nonneg: bool = False) -> float:
    v = float(value)
    if not math.isfinite(v):
        raise InputError(f"must be a finite number, got {value!r}", where=where)
    if positive and not v > 0:
        raise InputError(f"must be > 0, got {value!r}", where=where)
    if nonneg and v < 0:
        raise InputError(f"must be >= 0, got {value!r}", where=where)
    return v


def _vector3(value: Any, where: str) -> np.ndarray:
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InputError(f"must be three finite numbers, got {value!r}", where=where)
    return v


@dataclass(frozen=True)
class Attitude:
    """The station's attitude for the quasi-steady environment.

    Attributes
    ----------
    kind : ``"lvlh"`` (LVLH hold, default), ``"inertial"`` (fixed in inertial space) or
        ``"rate"`` (a constant body rate ``omega_rad_s``)
    omega_rad_s : (3,) body rate in the station frame, rad/s (``"rate"`` only)
    alpha_rad_per_s2 : (3,) angular acceleration in the station frame, rad/s^2 (``"rate"``
        only; enters the ``alpha x rho`` term, not the attitude history)
    lvlh_from_station : (3, 3) rotation from station to LVLH axes in LVLH hold (and at the
        first sample for the other kinds); default :data:`LVLH_FROM_STATION`
    """

    kind: str = "lvlh"
    omega_rad_s: np.ndarray | Sequence[float] | None = None
    alpha_rad_per_s2: np.ndarray | Sequence[float] | None = None
    lvlh_from_station: np.ndarray = field(default_factory=lambda: LVLH_FROM_STATION.copy())

    def __post_init__(self) -> None:
        if self.kind not in ATTITUDES:
            raise InputError(
                f"unknown attitude {self.kind!r}",
                where="attitude",
                fix="use lvlh, inertial or rate",
            )
        if self.kind == "rate":
            if self.omega_rad_s is None:
                raise InputError("a rate attitude needs the body rate", where="omega")
            object.__setattr__(self, "omega_rad_s", _vector3(self.omega_rad_s, "omega"))
            if self.alpha_rad_per_s2 is not None:
                alpha = _vector3(self.alpha_rad_per_s2, "alpha")
                object.__setattr__(self, "alpha_rad_per_s2", alpha)
        elif self.omega_rad_s is not None or self.alpha_rad_per_s2 is not None:
            raise InputError(
                f"a rate is given only with attitude 'rate', not {self.kind!r}",
                where="omega",
                fix="choose attitude 'rate' or leave the rate out",
            )
        m = np.asarray(self.lvlh_from_station, dtype=float)
        if (
            m.shape != (3, 3)
            or not np.allclose(m @ m.T, np.eye(3), atol=1e-12)
            or np.linalg.det(m) < 0
        ):
            raise InputError("must be a proper rotation matrix", where="lvlh_from_station")
        object.__setattr__(self, "lvlh_from_station", m)

    def to_dict(self, mean_motion: float) -> dict[str, Any]:
        """JSON-ready echo, with the body rate actually used (rad/s, station frame)."""
        w, a = self.rates(mean_motion)
        return {
            "kind": self.kind,
            "omega_rad_s": w.tolist(),
            "alpha_rad_per_s2": a.tolist(),
            "lvlh_from_station": self.lvlh_from_station.tolist(),
        }

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Velocity, orbit-normal and zenith unit vectors in the station frame at the start."""
        m = self.lvlh_from_station  # rows: LVLH axes in station coordinates
        return m[0], -m[1], -m[2]

    def rates(self, mean_motion: float) -> tuple[np.ndarray, np.ndarray]:
        """Body rate and angular acceleration in the station frame, rad/s and rad/s^2."""
        if self.kind == "lvlh":
            return mean_motion * self.axes()[1], np.zeros(3)
        if self.kind == "inertial":
            return np.zeros(3), np.zeros(3)
        assert self.omega_rad_s is not None
        alpha = np.zeros(3) if self.alpha_rad_per_s2 is None else self.alpha_rad_per_s2
        return np.asarray(self.omega_rad_s, float), np.asarray(alpha, float)


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
            _finite(self.ballistic_coefficient_kg_per_m2, "ballistic_coefficient", positive=True)
            if self.area_m2 is not None or self.cd is not None:
                raise InputError(
                    "give a ballistic coefficient, or an area and Cd, not both",
                    where="ballistic_coefficient",
                )
        if self.area_m2 is not None:
            _finite(self.area_m2, "area", positive=True)
        if self.cd is not None:
            _finite(self.cd, "cd", positive=True)
            if self.area_m2 is None:
                raise InputError("a drag coefficient needs an area", where="cd", fix="give area")
        if self.mass_kg is not None:
            _finite(self.mass_kg, "mass", positive=True)

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
        _finite(self.f107_sfu, "f107", positive=True)
        _finite(self.f107a_sfu, "f107a", positive=True)
        _finite(self.ap, "ap", nonneg=True)
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


@dataclass(frozen=True)
class OrbitInputs:
    """A circular orbit.

    Attributes
    ----------
    radius_m : orbit radius, m (Earth centre to the CM)
    mu_m3_per_s2 : gravitational parameter, m^3/s^2
    inclination_deg : inclination, degrees (ISS: 51.6)
    raan_deg : right ascension of the ascending node, degrees
    arg_latitude_deg : argument of latitude at the first sample, degrees
    n_samples : samples over one orbit period
    """

    radius_m: float
    mu_m3_per_s2: float = 3.986004418e14
    inclination_deg: float = 51.6
    raan_deg: float = 0.0
    arg_latitude_deg: float = 0.0
    n_samples: int = 180

    def __post_init__(self) -> None:
        r = _finite(self.radius_m, "radius", positive=True)
        if r < EARTH_EQUATORIAL_RADIUS_M + MIN_ALTITUDE_M:
            raise InputError(
                f"{r:.6g} m is inside the Earth or below {MIN_ALTITUDE_M / 1e3:g} km altitude "
                f"(the equatorial radius is {EARTH_EQUATORIAL_RADIUS_M:.0f} m)",
                where="radius",
                fix="give the orbit radius from the Earth's centre, e.g. 6778 km",
            )
        if r > MAX_RADIUS_M:
            raise InputError(f"must be <= {MAX_RADIUS_M:g} m, got {r:.6g} m", where="radius")
        _finite(self.mu_m3_per_s2, "mu", positive=True)
        inc = _finite(self.inclination_deg, "inclination")
        if not 0.0 <= inc <= 180.0:
            raise InputError(f"must be in [0, 180] degrees, got {inc:g}", where="inclination")
        _finite(self.raan_deg, "raan")
        _finite(self.arg_latitude_deg, "arg_latitude")
        n = self.n_samples
        if not (isinstance(n, int | np.integer) and 4 <= n <= MAX_SAMPLES):
            raise InputError(f"must be an integer in 4..{MAX_SAMPLES}, got {n!r}", where="samples")

    @property
    def mean_motion_rad_s(self) -> float:
        """``n = sqrt(mu / R^3)``, rad/s."""
        return math.sqrt(self.mu_m3_per_s2 / self.radius_m**3)

    @property
    def period_s(self) -> float:
        """Orbit period, s."""
        return 2.0 * math.pi / self.mean_motion_rad_s


@dataclass(frozen=True)
class QuasiSteadyRequirement:
    """The quasi-steady limit with its source (``microg/data/quasi_steady_requirement.toml``)."""

    name: str
    limit_g: float
    applies_to: str
    statistic: str
    duration: str
    source: str
    verified: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready echo (limit in g and micro-g)."""
        return {
            "name": self.name,
            "limit_g": self.limit_g,
            "limit_ug": self.limit_g * 1e6,
            "applies_to": self.applies_to,
            "statistic": self.statistic,
            "duration": self.duration,
            "source": self.source,
            "verified": self.verified,
        }


@lru_cache(maxsize=1)
def quasi_steady_requirement() -> QuasiSteadyRequirement:
    """The ISS quasi-steady limit, 1 micro-g at internal payload locations (NASA-CR-205357)."""
    path = "data/quasi_steady_requirement.toml"
    data = tomllib.loads(resources.files("microg").joinpath(path).read_text("utf-8"))
    req = data["requirement"]
    limit = parse_quantity(req["limit"], "acceleration", where=f"{path}: requirement.limit")
    return QuasiSteadyRequirement(
        name=req["name"],
        limit_g=limit / G0,
        applies_to=req["applies_to"],
        statistic=req["statistic"],
        duration=req["duration"],
        source=req["source"],
        verified=bool(req["verified"]),
    )


# ------------------------------------------------------------------------------- the orbit


@dataclass(frozen=True)
class OrbitSamples:
    """One orbit sampled uniformly in time, in the station (body) frame.

    Attributes
    ----------
    time_s : (S,) time from the first sample, s
    r_hat : (S, 3) unit vector Earth centre -> CM, station frame
    v_rel_mps : (S, 3) velocity relative to the co-rotating atmosphere, station frame, m/s
    lvlh_from_station : (S, 3, 3) station -> LVLH components at each sample
    latitude_deg, longitude_deg, altitude_m : (S,) geodetic position of the CM (WGS84)
    date : (S,) datetime64 of each sample (UTC)
    """

    time_s: np.ndarray
    r_hat: np.ndarray
    v_rel_mps: np.ndarray
    lvlh_from_station: np.ndarray
    latitude_deg: np.ndarray
    longitude_deg: np.ndarray
    altitude_m: np.ndarray
    date: np.ndarray


def _earth_rotation_angle(date: np.ndarray) -> np.ndarray:
    """Earth rotation angle (IERS 2003), rad, of datetime64 values (UTC taken as UT1)."""
    j2000 = np.datetime64("2000-01-01T12:00:00", "ms")
    days = (date - j2000).astype("timedelta64[ms]").astype(float) / 86_400_000.0
    frac = (0.7790572732640 + 1.00273781191135448 * days) % 1.0
    return 2.0 * np.pi * frac


def orbit_samples(orbit: OrbitInputs, attitude: Attitude, date: np.datetime64) -> OrbitSamples:
    """Geometry of one orbit in the station frame: radius and relative-wind directions.

    The inertial reference frame is the station frame at the first sample, where the body is
    aligned with LVLH (``attitude.lvlh_from_station``).  The CM moves on the circle
    ``r_hat(theta) = cos(theta) r_hat_0 + sin(theta) v_hat_0``, theta = n t; the body turns by
    the constant body rate about a fixed axis (Rodrigues), so a vector's station components are
    ``C(t)^T`` times its inertial ones.  For drag, the orbit in the Earth-centred inertial
    frame (inclination, node, argument of latitude) gives the geodetic position (for density)
    and the co-rotating atmosphere's wind: ``v_rel = (v - w_E R cos i) v_hat +
    w_E R cos(u) sin(i) h_hat``.

    Parameters
    ----------
    orbit : OrbitInputs
    attitude : Attitude
    date : datetime64 of the first sample (UTC)
    """
    n = orbit.mean_motion_rad_s
    S = int(orbit.n_samples)
    t = np.arange(S) * (orbit.period_s / S)
    theta = n * t
    v0, h0, r0 = attitude.axes()
    r_in = np.cos(theta)[:, None] * r0 + np.sin(theta)[:, None] * v0
    v_in = np.cos(theta)[:, None] * v0 - np.sin(theta)[:, None] * r0
    h_in = np.broadcast_to(h0, r_in.shape)
    w_body, _ = attitude.rates(n)
    rate = float(np.linalg.norm(w_body))
    if rate > 0:
        C = _rodrigues(w_body / rate, rate * t)  # body -> inertial
        Ct = np.swapaxes(C, 1, 2)
        r_b = np.einsum("sij,sj->si", Ct, r_in)
        v_b = np.einsum("sij,sj->si", Ct, v_in)
        h_b = np.einsum("sij,sj->si", Ct, h_in)
    else:
        r_b, v_b, h_b = r_in, v_in, np.array(h_in)
    # Earth-centred inertial position for density and co-rotation
    inc = math.radians(orbit.inclination_deg)
    raan = math.radians(orbit.raan_deg)
    u = math.radians(orbit.arg_latitude_deg) + theta
    R = orbit.radius_m
    eci = R * np.column_stack(
        [
            math.cos(raan) * np.cos(u) - math.sin(raan) * np.sin(u) * math.cos(inc),
            math.sin(raan) * np.cos(u) + math.cos(raan) * np.sin(u) * math.cos(inc),
            np.sin(u) * math.sin(inc),
        ]
    )
    dates = date + (t * 1000.0).astype("timedelta64[ms]")
    era = _earth_rotation_angle(dates)
    ecef = np.column_stack(
        [
            np.cos(era) * eci[:, 0] + np.sin(era) * eci[:, 1],
            -np.sin(era) * eci[:, 0] + np.cos(era) * eci[:, 1],
            eci[:, 2],
        ]
    )
    lat, lon, alt = geodetic(ecef)
    speed = math.sqrt(orbit.mu_m3_per_s2 / R)
    wr = EARTH_ROTATION_RAD_S * R
    along = speed - wr * math.cos(inc)
    cross = wr * np.cos(u) * math.sin(inc)
    v_rel = along * v_b + cross[:, None] * h_b
    lvlh = np.stack([v_b, -h_b, -r_b], axis=1)  # rows: LVLH axes in station components
    return OrbitSamples(t, r_b, v_rel, lvlh, lat, lon, alt, dates)


def _density(samples: OrbitSamples, atm: AtmosphereInputs) -> tuple[np.ndarray, str, str | None]:
    """Density at the samples, the model used and why the fallback was taken (or None)."""
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


# ------------------------------------------------------------------------------- results


@dataclass(frozen=True)
class PointQuasiSteady:
    """The quasi-steady acceleration at one point (orbital averages and the peak), m/s^2.

    Vectors are orbital averages in the station frame, with ``*_lvlh`` the same in LVLH.
    ``magnitude_mps2`` is the magnitude of the average vector, ``peak_magnitude_mps2`` the
    largest magnitude over the orbit (what the requirement judges), ``complies`` the verdict
    (None when withheld: no drag input).
    """

    name: str
    kind: str
    position_m: np.ndarray
    accel_mps2: np.ndarray
    gravity_gradient_mps2: np.ndarray
    rotation_mps2: np.ndarray
    drag_mps2: np.ndarray
    accel_lvlh_mps2: np.ndarray
    gravity_gradient_lvlh_mps2: np.ndarray
    rotation_lvlh_mps2: np.ndarray
    drag_lvlh_mps2: np.ndarray
    magnitude_mps2: float
    peak_magnitude_mps2: float
    complies: bool | None

    def to_dict(self) -> dict[str, Any]:
        """The contract's entry (vectors in g, station frame and LVLH)."""
        g = 1.0 / G0
        return {
            "kind": self.kind,
            "position_m": self.position_m.tolist(),
            "accel_g": (self.accel_mps2 * g).tolist(),
            "gravity_gradient_g": (self.gravity_gradient_mps2 * g).tolist(),
            "rotation_g": (self.rotation_mps2 * g).tolist(),
            "drag_g": (self.drag_mps2 * g).tolist(),
            "magnitude_g": self.magnitude_mps2 * g,
            "peak_magnitude_g": self.peak_magnitude_mps2 * g,
            "lvlh": {
                "accel_g": (self.accel_lvlh_mps2 * g).tolist(),
                "gravity_gradient_g": (self.gravity_gradient_lvlh_mps2 * g).tolist(),
                "rotation_g": (self.rotation_lvlh_mps2 * g).tolist(),
                "drag_g": (self.drag_lvlh_mps2 * g).tolist(),
            },
            "complies": self.complies,
        }


@dataclass(frozen=True)
class QuasiSteadyMap:
    """Peak quasi-steady magnitude over the structure's sample points and the 1 micro-g zone.

    Attributes
    ----------
    positions_m : (p, 3) sample positions, station frame, m
    labels : (p,) sample labels
    peak_magnitude_mps2 : (p,) peak magnitude over the orbit, m/s^2
    limit_mps2 : the requirement's limit, m/s^2
    within : (p,) peak magnitude within the limit (the 1 micro-g zone's samples)
    zone_half_width_m : for LVLH hold, the half-widths of the ideal zone about the CM in the
        orbit-normal (y) and radial (z) directions, ``L / n^2`` and ``L / (3 n^2)`` reduced by
        the drag, ``sqrt(L^2 - d^2)`` for the largest drag d (None otherwise, or when the drag
        alone exceeds L)
    """

    positions_m: np.ndarray
    labels: tuple[str, ...]
    peak_magnitude_mps2: np.ndarray
    limit_mps2: float
    within: np.ndarray
    zone_half_width_m: dict[str, float] | None

    def to_dict(self) -> dict[str, Any]:
        """Summary (the full map goes to the CSV of ``--out``)."""
        g = 1.0 / G0
        inside = self.positions_m[self.within]
        return {
            "n_samples": int(self.within.size),
            "n_within_limit": int(self.within.sum()),
            "fraction_within_limit": float(self.within.mean()) if self.within.size else None,
            "peak_magnitude_g_min": float(self.peak_magnitude_mps2.min() * g)
            if self.within.size
            else None,
            "peak_magnitude_g_max": float(self.peak_magnitude_mps2.max() * g)
            if self.within.size
            else None,
            "zone_extent_m": {
                "min": inside.min(axis=0).tolist(),
                "max": inside.max(axis=0).tolist(),
            }
            if inside.size
            else None,
            "zone_half_width_m": self.zone_half_width_m,
        }

    def to_csv(self) -> str:
        """The map as CSV: label, x, y, z (m), peak magnitude (micro-g), within the limit."""
        lines = ["label,x [m],y [m],z [m],peak [ug],within_limit"]
        for lab, p, a, w in zip(
            self.labels, self.positions_m, self.peak_magnitude_mps2, self.within, strict=True
        ):
            lines.append(
                f"{lab},{p[0]:.6g},{p[1]:.6g},{p[2]:.6g},{a / G0 * 1e6:.6g},{str(bool(w)).lower()}"
            )
        return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class QuasiSteadyResult:
    """The quasi-steady environment of a station (see the module docstring)."""

    model: str
    mass_kg: float
    center_of_mass_m: np.ndarray
    mean_motion_rad_s: float
    orbit: OrbitInputs
    attitude: Attitude
    atmosphere: AtmosphereInputs
    atmosphere_model: str
    atmosphere_fallback: str | None
    drag: Drag
    density_kg_per_m3: np.ndarray
    drag_samples_mps2: np.ndarray
    samples: OrbitSamples
    requirement: QuasiSteadyRequirement
    points: Mapping[str, PointQuasiSteady]
    map: QuasiSteadyMap | None
    complies: bool | None
    warnings: tuple[str, ...]

    def to_dict(self) -> dict[str, Any]:
        """The ``microg quasi-steady --json`` contract."""
        rho = self.density_kg_per_m3
        orbit = self.orbit
        alt = self.samples.altitude_m
        return {
            "model": self.model,
            "mass_kg": self.mass_kg,
            "center_of_mass_m": self.center_of_mass_m.tolist(),
            "mean_motion_rad_s": self.mean_motion_rad_s,
            "orbit": {
                "radius_m": orbit.radius_m,
                "mu_m3_per_s2": orbit.mu_m3_per_s2,
                "period_s": orbit.period_s,
                "inclination_deg": orbit.inclination_deg,
                "raan_deg": orbit.raan_deg,
                "arg_latitude_deg": orbit.arg_latitude_deg,
                "n_samples": int(orbit.n_samples),
                "altitude_m": {
                    "mean": float(alt.mean()),
                    "min": float(alt.min()),
                    "max": float(alt.max()),
                },
            },
            "attitude": self.attitude.to_dict(self.mean_motion_rad_s),
            "atmosphere": {
                "model": self.atmosphere_model,
                "requested": self.atmosphere.model,
                "fallback_reason": self.atmosphere_fallback,
                "date_utc": str(self.samples.date[0].astype("datetime64[s]")),
                "f107_sfu": self.atmosphere.f107_sfu,
                "f107a_sfu": self.atmosphere.f107a_sfu,
                "ap": self.atmosphere.ap,
                "defaulted": list(self.atmosphere.defaulted),
                "density_kg_per_m3": {
                    "mean": float(rho.mean()),
                    "min": float(rho.min()),
                    "max": float(rho.max()),
                },
            },
            "drag": self.drag.to_dict(self.mass_kg),
            "frames": {
                "station": "x along the flight direction, y along the solar boom (orbit normal), "
                "z along the keel (zenith in LVLH hold)",
                "lvlh": "X along the velocity, Y against the orbit normal, Z to nadir",
                "convention": "accelerometer reading (specific force); a free particle's "
                "apparent acceleration relative to the structure is the negative",
            },
            "requirement": self.requirement.to_dict(),
            "points": {name: p.to_dict() for name, p in self.points.items()},
            "map": None if self.map is None else self.map.to_dict(),
            "complies": self.complies,
            "warnings": list(self.warnings),
        }

    def peak_at(self, positions_m: np.ndarray) -> np.ndarray:
        """Peak magnitude over the orbit at any positions (p, 3) in the station frame, m/s^2."""
        omega, alpha = self.attitude.rates(self.mean_motion_rad_s)
        pos = np.asarray(positions_m, float).reshape(-1, 3)
        return _map_peaks(
            pos,
            self.center_of_mass_m,
            self.samples,
            self.orbit,
            omega,
            alpha,
            self.drag_samples_mps2,
            self.attitude.kind == "lvlh",
        )

    def plot(self, ax: Any = None) -> Figure:
        """The map of the peak magnitude with the 1 micro-g zone (see microg.plotting).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.quasisteady import plot_quasi_steady_map

        return plot_quasi_steady_map(self, ax=ax)

    def to_xarray(self) -> Any:
        """Per-point vectors (orbital averages, m/s^2) as an xarray Dataset."""
        import xarray as xr

        names = list(self.points)
        pts = [self.points[n] for n in names]

        def stack(attr: str) -> np.ndarray:
            return np.array([getattr(p, attr) for p in pts]).reshape(len(pts), 3)

        coords = {"point": names, "axis": ["x", "y", "z"]}
        data: dict[str, Any] = {
            key: (("point", "axis"), stack(attr), {"units": "m/s^2", "frame": frame})
            for key, attr, frame in (
                ("accel", "accel_mps2", "station"),
                ("gravity_gradient", "gravity_gradient_mps2", "station"),
                ("rotation", "rotation_mps2", "station"),
                ("drag", "drag_mps2", "station"),
                ("accel_lvlh", "accel_lvlh_mps2", "lvlh"),
            )
        }
        data["peak_magnitude"] = (
            ("point",),
            np.array([p.peak_magnitude_mps2 for p in pts]),
            {"units": "m/s^2"},
        )
        data["position"] = (("point", "axis"), stack("position_m"), {"units": "m"})
        return xr.Dataset(
            data, coords=coords, attrs={"model": self.model, "limit_g": self.requirement.limit_g}
        )


# ------------------------------------------------------------------------------- the job


def _point_terms(
    rho: np.ndarray,
    samples: OrbitSamples,
    orbit: OrbitInputs,
    omega: np.ndarray,
    alpha: np.ndarray,
    constant_geometry: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """Gravity gradient (P, S or 1, 3) and rotation (P, 3) terms at offsets ``rho`` (P, 3)."""
    R = orbit.radius_m
    mu = orbit.mu_m3_per_s2
    if constant_geometry:
        gg = gravity_gradient_accel(rho, R * samples.r_hat[0], mu)[:, None, :]
    else:
        gg = gravity_gradient_accel(rho[:, None, :], R * samples.r_hat[None, :, :], mu)
    return gg, rotation_accel(rho, omega, alpha)


def _hull_vertices(d: np.ndarray) -> np.ndarray:
    """Indices of the samples that can be farthest from any point: the convex hull's vertices.

    ``|q + d|`` is convex in ``d``, so its maximum over a finite set is at a vertex of the set's
    convex hull.  Degenerate sets (drag in LVLH hold lies in a plane) are hulled in the affine
    subspace they span (found by SVD; directions below 1e-12 of the spread are dropped, which
    changes the maximum by at most that much).
    """
    from scipy.spatial import ConvexHull, QhullError

    if d.shape[0] <= 8:
        return np.arange(d.shape[0])
    c = d.mean(axis=0)
    _, sv, vt = np.linalg.svd(d - c, full_matrices=False)
    k = int(np.sum(sv > 1e-12 * max(float(sv[0]), 1e-300))) if sv.size else 0
    if k == 0:
        return np.array([0])
    y = (d - c) @ vt[:k].T
    if k == 1:
        return np.unique([int(np.argmin(y[:, 0])), int(np.argmax(y[:, 0]))])
    try:
        return np.asarray(ConvexHull(y).vertices, dtype=np.intp)
    except QhullError:  # pragma: no cover - a hull qhull cannot build: keep every sample
        return np.arange(d.shape[0])


def peak_magnitude(static: np.ndarray, varying: np.ndarray) -> np.ndarray:
    """``max_s |static_p + varying_s|`` for every point p, vectorised without a (P, S, 3) array.

    Only the convex-hull vertices of the ``varying`` samples can give the maximum
    (:func:`_hull_vertices`); then ``|q + d_s|^2 = |q|^2 + (|d_s|^2 + 2 q . d_s)`` is one matrix
    product ``Q D^T`` per block of points and a maximum over s.  Rounding: absolute ~1e-16
    (|q|^2 + |d|^2), negligible against a micro-g limit.

    Parameters
    ----------
    static : (P, 3) the part constant over the orbit (gravity gradient and rotation in LVLH
        hold), m/s^2
    varying : (S, 3) the part common to all points that varies over the orbit (drag), m/s^2
    """
    q = np.asarray(static, float)
    d = np.asarray(varying, float)
    d = d[_hull_vertices(d)]
    d2 = np.sum(d * d, axis=1)
    dT = 2.0 * d.T
    out = np.empty(q.shape[0])
    block = max(64, 2**17 // max(d.shape[0], 1))  # (block, vertices) scratch stays in cache
    for c0 in range(0, q.shape[0], block):
        qb = q[c0 : c0 + block]
        inner = qb @ dT
        inner += d2
        out[c0 : c0 + block] = np.sum(qb * qb, axis=1) + inner.max(axis=1)
    return np.sqrt(np.maximum(out, 0.0))


def _map_peaks(
    positions: np.ndarray,
    cm: np.ndarray,
    samples: OrbitSamples,
    orbit: OrbitInputs,
    omega: np.ndarray,
    alpha: np.ndarray,
    drag: np.ndarray,
    constant_geometry: bool,
) -> np.ndarray:
    """Peak magnitude over the orbit at every position (P,), m/s^2 (vectorised, blocked)."""
    rho = np.asarray(positions, float) - cm
    if constant_geometry:
        gg, rot = _point_terms(rho, samples, orbit, omega, alpha, True)
        return peak_magnitude(gg[:, 0, :] + rot, drag)
    # the gradient varies over the orbit: exact two-body terms written as
    # alpha(c, |rho|^2) r_hat_s + beta(c, |rho|^2) rho with c = rho . r_hat_s, so |a|^2 comes
    # from matrix products and (points, samples) scalar fields, never a (P, S, 3) array
    R, mu = orbit.radius_m, orbit.mu_m3_per_s2
    rh = samples.r_hat
    rot = rotation_accel(rho, omega, alpha)
    rd = np.sum(rh * drag, axis=1)  # (S,)
    dd = np.sum(drag * drag, axis=1)
    out = np.empty(rho.shape[0])
    block = max(1, 2**18 // max(rh.shape[0], 1))
    for c0 in range(0, rho.shape[0], block):
        r = rho[c0 : c0 + block]
        e = rot[c0 : c0 + block]
        rr = np.sum(r * r, axis=1)[:, None]
        c = r @ rh.T
        q = 2.0 * R * c + rr
        S2 = R * R + q
        Sd = np.sqrt(S2)
        beta = mu / (S2 * Sd)
        alph = mu * R * (-q / (R + Sd)) * (R * R + R * Sd + S2) / (R**3 * S2 * Sd)
        ee = np.sum(e * e, axis=1)[:, None]
        re = e @ rh.T
        ed = e @ drag.T
        pd = r @ drag.T
        pe = np.sum(r * e, axis=1)[:, None]
        a2 = (
            alph * alph
            + beta * beta * rr
            + (ee + 2.0 * ed + dd)
            + 2.0 * alph * beta * c
            + 2.0 * alph * (re + rd)
            + 2.0 * beta * (pe + pd)
        )
        out[c0 : c0 + block] = np.sqrt(np.maximum(a2.max(axis=1), 0.0))
    return out


def _model_geometry(
    model: Any, elements: int | None
) -> tuple[str, float, np.ndarray, list[tuple[str, str, np.ndarray]], Any]:
    """Name, mass (kg), CM (m), named points (name, kind, position) and map samples of a model."""
    from microg.models.station import Station

    if isinstance(model, Station):
        mass, cm, _ = model.mass_properties()
        named = [(p.name, p.kind, np.asarray(p.position, float)) for p in model.points]
        return model.name, float(mass), np.asarray(cm, float), named, ("station", elements)
    from microg.structure.discretize import discretize

    structure = discretize(model)
    named = [(n, "point", np.asarray(p.position, float)) for n, p in structure.points.items()]
    name = str(getattr(structure, "meta", {}).get("model", getattr(model, "name", "model")))
    return (
        name,
        float(structure.total_mass),
        np.asarray(structure.center_of_mass, float),
        named,
        ("structure", structure),
    )


def _sample_positions(source: Any, model: Any) -> tuple[np.ndarray, tuple[str, ...]] | None:
    kind, payload = source
    if kind == "station":
        from microg.structure.discretize import discretize

        s = discretize(model, n=payload).samples
    else:
        s = payload.samples
    if s is None:
        return None
    pos = np.asarray(s.position, float).reshape(-1, 3)
    labels = tuple(getattr(s, "labels", None) or [f"s{i}" for i in range(pos.shape[0])])
    return pos, labels


def quasi_steady(
    model: Any,
    *,
    orbit: OrbitInputs | None = None,
    attitude: Attitude | None = None,
    drag: Drag | None = None,
    atmosphere: AtmosphereInputs | None = None,
    points: Sequence[str] | None = None,
    with_map: bool = True,
    map_positions_m: np.ndarray | None = None,
    elements: int | None = 20,
) -> QuasiSteadyResult:
    """The quasi-steady environment of a model: every named point, the CM, and a map.

    Parameters
    ----------
    model : Station (its mass properties give the CM), a Structure, or any model
        :func:`~microg.structure.discretize.discretize` takes (the structure's
        ``center_of_mass`` and ``total_mass``)
    orbit : circular orbit (default: the model's orbit radius and mu, ISS inclination 51.6 deg)
    attitude : default LVLH hold
    drag : default none (drag omitted, verdict withheld)
    atmosphere : default NRLMSIS 2.1 with the default date and moderate solar activity
    points : named points to report (default: all); the CM is always reported as ``cm``
    with_map : compute the map over the structure's sample points
    map_positions_m : (p, 3) positions for the map instead of the structure's samples, m
    elements : frame elements per beam of the sampling mesh (Station models)

    Returns
    -------
    QuasiSteadyResult
    """
    name, mass, cm, named, source = _model_geometry(model, elements)
    if orbit is None:
        st_orbit = getattr(model, "orbit", None)
        if st_orbit is None:
            raise InputError("the model has no orbit", where="orbit", fix="give the orbit radius")
        orbit = OrbitInputs(radius_m=st_orbit.radius, mu_m3_per_s2=st_orbit.mu)
    attitude = attitude or Attitude()
    drag = drag or Drag()
    atmosphere = atmosphere or AtmosphereInputs(defaulted=("date", "f107", "f107a", "ap"))
    warnings: list[str] = []
    n = orbit.mean_motion_rad_s
    samples = orbit_samples(orbit, attitude, atmosphere.date64())
    rho_atm, atm_model, fallback = _density(samples, atmosphere)
    if fallback:
        warnings.append(f"atmosphere: the exponential model is used because {fallback}")
    beta = drag.beta(mass)
    if beta is None:
        drag_s = np.zeros((samples.time_s.size, 3))
        warnings.append(
            "no drag input (ballistic coefficient, or area and Cd): drag is left out and the "
            "verdict is withheld (complies = null)"
        )
    else:
        drag_s = drag_accel(rho_atm, samples.v_rel_mps, beta)
        if atmosphere.defaulted and atm_model.startswith("NRLMSIS"):
            warnings.append(
                "drag uses assumed inputs for "
                + ", ".join(atmosphere.defaulted)
                + f" (F10.7 = F10.7a = {F107_DEFAULT:g} sfu, Ap = {AP_DEFAULT:g}, "
                f"{DATE_DEFAULT} UTC): give the date and solar activity of the case"
            )
    omega, alpha = attitude.rates(n)
    constant = attitude.kind == "lvlh"
    req = quasi_steady_requirement()
    limit = req.limit_g * G0
    wanted = list(points) if points is not None else [p[0] for p in named]
    by_name = {p[0]: p for p in named}
    unknown = [p for p in wanted if p not in by_name]
    if unknown:
        known = ", ".join(sorted(by_name)) or "(none)"
        raise InputError(f"unknown point {unknown[0]!r}", where="points", fix=f"known: {known}")
    chosen = [("cm", "cm", cm.copy())] + [by_name[p] for p in wanted if p != "cm"]
    pos = np.array([c[2] for c in chosen]).reshape(-1, 3)
    rho = pos - cm
    gg, rot = _point_terms(rho, samples, orbit, omega, alpha, constant)
    S = samples.time_s.size
    gg_s = np.broadcast_to(gg, (rho.shape[0], S, 3))
    rot_s = np.broadcast_to(rot[:, None, :], gg_s.shape)
    drag_p = np.broadcast_to(drag_s[None, :, :], gg_s.shape)
    total = gg_s + rot_s + drag_p
    L = samples.lvlh_from_station  # (S, 3, 3)

    def lvlh(v: np.ndarray) -> np.ndarray:
        return np.einsum("sij,psj->pi", L, v) / S

    peaks = np.sqrt(np.max(np.sum(total * total, axis=-1), axis=1))
    out_points: dict[str, PointQuasiSteady] = {}
    for i, (pname, kind, p) in enumerate(chosen):
        mean = total[i].mean(axis=0)
        verdict = None if beta is None else bool(peaks[i] <= limit)
        out_points[pname] = PointQuasiSteady(
            name=pname,
            kind=kind,
            position_m=p,
            accel_mps2=mean,
            gravity_gradient_mps2=gg_s[i].mean(axis=0),
            rotation_mps2=rot[i].copy(),
            drag_mps2=drag_s.mean(axis=0),
            accel_lvlh_mps2=lvlh(total[i : i + 1])[0],
            gravity_gradient_lvlh_mps2=lvlh(gg_s[i : i + 1])[0],
            rotation_lvlh_mps2=lvlh(rot_s[i : i + 1])[0],
            drag_lvlh_mps2=lvlh(drag_p[i : i + 1])[0],
            magnitude_mps2=float(np.linalg.norm(mean)),
            peak_magnitude_mps2=float(peaks[i]),
            complies=verdict,
        )
    # the verdict: payload (experiment) points if the model names any, else every named point
    judged = [c[0] for c in chosen if c[1] == "experiment"] or [c[0] for c in chosen[1:]]
    if not judged:
        judged = ["cm"]
        warnings.append("the model names no points: only the centre of mass is judged")
    if beta is None:
        overall: bool | None = None
    else:
        overall = all(out_points[n_].complies for n_ in judged)
    qmap = None
    if with_map:
        got = (
            (np.asarray(map_positions_m, float).reshape(-1, 3), None)
            if map_positions_m is not None
            else _sample_positions(source, model)
        )
        if got is not None:
            mpos, labels = got
            if not np.all(np.isfinite(mpos)):
                raise InputError("map positions must be finite", where="map_positions")
            labs = labels or tuple(f"p{i}" for i in range(mpos.shape[0]))
            mpk = _map_peaks(mpos, cm, samples, orbit, omega, alpha, drag_s, constant)
            half = None
            if constant:
                d_max = float(np.max(np.linalg.norm(drag_s, axis=1)))
                if d_max < limit:
                    reach = math.sqrt(limit * limit - d_max * d_max)
                    half = {"y": reach / n**2, "z": reach / (3.0 * n**2)}
            qmap = QuasiSteadyMap(mpos, labs, mpk, limit, mpk <= limit, half)
    return QuasiSteadyResult(
        model=name,
        mass_kg=mass,
        center_of_mass_m=cm,
        mean_motion_rad_s=n,
        orbit=orbit,
        attitude=attitude,
        atmosphere=atmosphere,
        atmosphere_model=atm_model,
        atmosphere_fallback=fallback,
        drag=drag,
        density_kg_per_m3=rho_atm,
        drag_samples_mps2=drag_s,
        samples=samples,
        requirement=req,
        points=out_points,
        map=qmap,
        complies=overall,
        warnings=tuple(warnings),
    )
