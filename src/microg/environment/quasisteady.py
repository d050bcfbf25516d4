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
magnitude over the orbit.  Without a drag input (ballistic coefficient, or area and C_d) a
point fails when the smallest peak any drag could give (:func:`peak_lower_bound`: drag along
its known direction, of any size) already exceeds the limit; otherwise its verdict is withheld
(``complies`` None), and a warning says which.

Modules, one concept each: :mod:`~microg.environment.gravity_gradient` (the tidal term),
:mod:`~microg.environment.attitude` (attitudes and the rotation term),
:mod:`~microg.environment.orbit` (the orbit, its samples, geodesy),
:mod:`~microg.environment.drag` (the atmosphere and the drag term); this module assembles
them at the named points and over the structure (:func:`quasi_steady`, its result, the
requirement) and keeps their names importable from here.
"""

from __future__ import annotations

import csv
import io
import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.environment._inputs import points3
from microg.environment.attitude import ATTITUDES, LVLH_FROM_STATION, Attitude, rotation_accel
from microg.environment.drag import (
    AP_DEFAULT,
    ATMOSPHERES,
    CD_DEFAULT,
    DATE_DEFAULT,
    EXPONENTIAL_ATMOSPHERE,
    F107_DEFAULT,
    AtmosphereInputs,
    Drag,
    density,
    drag_accel,
    exponential_density,
)
from microg.environment.gravity_gradient import gravity_gradient_accel
from microg.environment.orbit import (
    EARTH_EQUATORIAL_RADIUS_M,
    EARTH_FLATTENING,
    EARTH_ROTATION_RAD_S,
    MAX_SAMPLES,
    OrbitInputs,
    OrbitSamples,
    geodetic,
    orbit_samples,
)
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
    "ATMOSPHERES",
    "EARTH_EQUATORIAL_RADIUS_M",
    "EARTH_FLATTENING",
    "EARTH_ROTATION_RAD_S",
    "EXPONENTIAL_ATMOSPHERE",
    "F107_DEFAULT",
    "LVLH_FROM_STATION",
    "MAX_SAMPLES",
    "OrbitInputs",
    "OrbitSamples",
    "PointQuasiSteady",
    "QuasiSteadyMap",
    "QuasiSteadyRequirement",
    "QuasiSteadyResult",
    "drag_accel",
    "exponential_density",
    "geodetic",
    "gravity_gradient_accel",
    "orbit_samples",
    "peak_lower_bound",
    "peak_magnitude",
    "quasi_steady",
    "quasi_steady_requirement",
    "rotation_accel",
]


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


# ------------------------------------------------------------------------------- results


@dataclass(frozen=True)
class PointQuasiSteady:
    """The quasi-steady acceleration at one point (orbital averages and the peak), m/s^2.

    Vectors are orbital averages in the station frame, with ``*_lvlh`` the same in LVLH.
    ``magnitude_mps2`` is the magnitude of the average vector, ``peak_magnitude_mps2`` the
    largest magnitude over the orbit (what the requirement judges), ``complies`` the verdict.
    Without a drag input ``peak_lower_bound_mps2`` is the smallest peak any drag could give
    (:func:`peak_lower_bound`): above the limit the point fails whatever the drag, else its
    verdict is withheld (None).
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
    peak_lower_bound_mps2: float | None = None

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
            "peak_lower_bound_g": None
            if self.peak_lower_bound_mps2 is None
            else self.peak_lower_bound_mps2 * g,
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
        """The map as CSV: label, x, y, z (m), peak magnitude (micro-g), within the limit.

        Written by the :mod:`csv` module, so a label holding a comma or a quote is quoted.
        """
        buf = io.StringIO()
        out = csv.writer(buf, lineterminator="\n")
        out.writerow(["label", "x [m]", "y [m]", "z [m]", "peak [ug]", "within_limit"])
        for lab, p, a, w in zip(
            self.labels, self.positions_m, self.peak_magnitude_mps2, self.within, strict=True
        ):
            out.writerow(
                [lab, f"{p[0]:.6g}", f"{p[1]:.6g}", f"{p[2]:.6g}", f"{a / G0 * 1e6:.6g}",
                 str(bool(w)).lower()]
            )  # fmt: skip
        return buf.getvalue()


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
        """Peak magnitude over the orbit at any positions (p, 3) in the station frame, m/s^2.

        ``positions_m``: (p, 3) points (or one as (3,)) in the model's frame, m.
        """
        omega, alpha = self.attitude.rates(self.mean_motion_rad_s)
        pos = points3(positions_m, "positions_m")
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

    def plot3d(self) -> Any:
        """The peak magnitude at the structure's samples in 3-D (a plotly Figure, micro-g)."""
        from microg.plotting.interactive.maps import quasi_steady_3d

        return quasi_steady_3d(self)

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
    (:func:`_hull_vertices`); then ``|q + d_s|^2 = |q|^2 + (|d_s|^2 + 2 q . d_s)`` and the
    bracket is one matrix product of the rows ``(2 d_s, |d_s|^2)`` with the columns ``(q, 1)``
    per block of points, whose largest entry down each column is taken (the vertices along the
    rows: the maximum runs over contiguous rows).  Rounding: absolute ~1e-16 (|q|^2 + |d|^2),
    negligible against a micro-g limit.

    Parameters
    ----------
    static : (P, 3) the part constant over the orbit (gravity gradient and rotation in LVLH
        hold), m/s^2
    varying : (S, 3) the part common to all points that varies over the orbit (drag), m/s^2
    """
    q = np.asarray(static, float)
    d = np.asarray(varying, float)
    d = d[_hull_vertices(d)]
    rows = np.empty((d.shape[0], 4))
    rows[:, :3] = 2.0 * d
    rows[:, 3] = np.sum(d * d, axis=1)
    out = np.einsum("ij,ij->i", q, q)
    block = min(4096, max(64, 2**17 // max(d.shape[0], 1)))  # the scratch stays in cache
    cols = np.empty((4, min(block, q.shape[0])))
    cols[3] = 1.0
    for c0 in range(0, q.shape[0], block):
        qb = q[c0 : c0 + block]
        n = qb.shape[0]
        cols[:3, :n] = qb.T
        out[c0 : c0 + n] += (rows @ cols[:, :n]).max(axis=0)
    return np.sqrt(np.maximum(out, 0.0))


def peak_lower_bound(static: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """The smallest peak magnitude over the orbit that any drag can give, m/s^2, (P,).

    Drag acts along a known direction ``u_s`` (against the wind relative to the co-rotating
    atmosphere) with an unknown size ``k_s >= 0`` at each sample (ballistic coefficient,
    density and solar activity unknown).  At one sample ``min_{k >= 0} |q + k u| = |q|`` when
    ``q . u >= 0`` (drag can only add), else ``|q - (q . u) u|`` (drag cancels the along-wind
    part at best).  Each sample's minimum is reached by its own ``k_s``, so the bound is the
    largest over the samples: ``max_s min_k |q_s + k u_s|`` <= the peak for every drag.

    Parameters
    ----------
    static : (P, S, 3) or (P, 3) the drag-free acceleration (gravity gradient and rotation) at
        each point and sample, m/s^2
    direction : (S, 3) unit vectors of the drag at each sample (rows of zeros: no drag there)
    """
    u = np.asarray(direction, float)
    q = np.asarray(static, float)
    if q.ndim == 2:
        q = q[:, None, :]
    q = np.broadcast_to(q, (q.shape[0], u.shape[0], 3))
    qu = np.einsum("psi,si->ps", q, u)
    q2 = np.sum(q * q, axis=-1)
    low2 = np.where(qu >= 0.0, q2, q2 - qu * qu)
    return np.sqrt(np.maximum(low2, 0.0).max(axis=1))


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
    rho_atm, atm_model, fallback = density(samples, atmosphere)
    if fallback:
        warnings.append(f"atmosphere: the exponential model is used because {fallback}")
    beta = drag.beta(mass)
    if beta is None:
        drag_s = np.zeros((samples.time_s.size, 3))
        warnings.append(
            "no drag input (ballistic coefficient, or area and Cd): drag is left out; a point "
            "fails only if it exceeds the limit whatever the drag, else its verdict is "
            "withheld (complies = null)"
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
    lower = None
    if beta is None:  # drag unknown: the smallest peak any drag could give
        d_dir = drag_accel(rho_atm, samples.v_rel_mps, 1.0)
        d_len = np.linalg.norm(d_dir, axis=1, keepdims=True)
        d_dir = np.divide(d_dir, d_len, out=np.zeros_like(d_dir), where=d_len > 0)
        lower = peak_lower_bound(gg_s + rot_s, d_dir)
    out_points: dict[str, PointQuasiSteady] = {}
    for i, (pname, kind, p) in enumerate(chosen):
        mean = total[i].mean(axis=0)
        if lower is None:
            verdict: bool | None = bool(peaks[i] <= limit)
        else:
            verdict = False if lower[i] > limit else None
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
            peak_lower_bound_mps2=None if lower is None else float(lower[i]),
        )
    # the verdict: payload (experiment) points if the model names any, else every named point
    judged = [c[0] for c in chosen if c[1] == "experiment"] or [c[0] for c in chosen[1:]]
    if not judged:
        judged = ["cm"]
        warnings.append("the model names no points: only the centre of mass is judged")
    if beta is None:
        fails = [n_ for n_ in judged if out_points[n_].complies is False]
        ug = 1e6 / G0
        overall: bool | None = False if fails else None
        if fails:
            warnings.append(
                "without drag input the verdict is a fail: at "
                + ", ".join(
                    f"{n_} (>= {(out_points[n_].peak_lower_bound_mps2 or 0.0) * ug:.3g} micro-g)"
                    for n_ in fails
                )
                + f" gravity gradient and rotation exceed {req.limit_g * 1e6:.3g} micro-g "
                "whatever the drag (no ballistic coefficient, area, Cd, density or solar "
                "activity changes it)"
            )
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
