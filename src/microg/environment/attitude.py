"""The station's attitude and the acceleration of a point fixed in the rotating body.

Attitudes (:class:`Attitude`): ``"lvlh"`` (LVLH hold: the body turns once per orbit about the
orbit normal), ``"inertial"`` (fixed in inertial space; aligned with LVLH at the first sample),
``"rate"`` (a constant body rate ``omega`` and an angular acceleration ``alpha`` given in the
station frame; aligned with LVLH at the first sample).  Station frame: x along the flight
direction, y along the solar boom (the orbit normal), z along the keel (zenith in LVLH hold);
``a_lvlh = LVLH_FROM_STATION @ a_station`` in LVLH hold (see
:mod:`microg.environment.quasisteady`).

Rotation: ``alpha x rho + omega x (omega x rho)`` (:func:`rotation_accel`); no Coriolis term
(the point is fixed in the structure).  In LVLH hold ``omega = n`` about the orbit normal.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg.environment._inputs import vector3
from microg.errors import InputError

__all__ = ["ATTITUDES", "LVLH_FROM_STATION", "Attitude", "rodrigues", "rotation_accel"]

LVLH_FROM_STATION = np.diag([1.0, -1.0, -1.0])

ATTITUDES = ("lvlh", "inertial", "rate")


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


def rodrigues(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) about the unit ``axis`` by ``angle`` (Rodrigues' formula).

    Parameters
    ----------
    axis : ndarray (3,)
        Unit rotation axis.
    angle : ndarray (n,)
        Angles, rad.
    """
    k = np.asarray(axis, float)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    a = np.asarray(angle, float)[:, None, None]
    return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * (K @ K)


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
            object.__setattr__(self, "omega_rad_s", vector3(self.omega_rad_s, "omega"))
            if self.alpha_rad_per_s2 is not None:
                alpha = vector3(self.alpha_rad_per_s2, "alpha")
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
