"""A circular orbit: its inputs, and one orbit sampled in the station frame (with geodesy).

The CM moves on a circle of radius ``R``; one orbit is sampled uniformly in time, giving the
radius and relative-wind directions in the station frame, the LVLH axes, and the geodetic
position (WGS84) that the atmosphere needs (see :mod:`microg.environment.quasisteady`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from microg.environment._inputs import finite_number
from microg.environment.attitude import Attitude, rodrigues
from microg.errors import InputError

__all__ = [
    "EARTH_EQUATORIAL_RADIUS_M",
    "EARTH_ROTATION_RAD_S",
    "INCLINATION_DEG",
    "MAX_SAMPLES",
    "OrbitInputs",
    "OrbitSamples",
    "geodetic",
    "orbit_samples",
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
#: largest number of orbit samples
MAX_SAMPLES = 100_000


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


#: the ISS orbit's inclination, degrees
INCLINATION_DEG = 51.6


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
    inclination_deg: float = INCLINATION_DEG
    raan_deg: float = 0.0
    arg_latitude_deg: float = 0.0
    n_samples: int = 180

    def __post_init__(self) -> None:
        r = finite_number(self.radius_m, "radius", positive=True)
        if r < EARTH_EQUATORIAL_RADIUS_M + MIN_ALTITUDE_M:
            raise InputError(
                f"{r:.6g} m is inside the Earth or below {MIN_ALTITUDE_M / 1e3:g} km altitude "
                f"(the equatorial radius is {EARTH_EQUATORIAL_RADIUS_M:.0f} m)",
                where="radius",
                fix="give the orbit radius from the Earth's centre, e.g. 6778 km",
            )
        if r > MAX_RADIUS_M:
            raise InputError(f"must be <= {MAX_RADIUS_M:g} m, got {r:.6g} m", where="radius")
        finite_number(self.mu_m3_per_s2, "mu", positive=True)
        inc = finite_number(self.inclination_deg, "inclination")
        if not 0.0 <= inc <= 180.0:
            raise InputError(f"must be in [0, 180] degrees, got {inc:g}", where="inclination")
        finite_number(self.raan_deg, "raan")
        finite_number(self.arg_latitude_deg, "arg_latitude")
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
        C = rodrigues(w_body / rate, rate * t)  # body -> inertial
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
