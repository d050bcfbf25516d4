"""The actively isolated payload: a rigid platform on umbilicals, with actuators and sensors.

The platform (mass ``m``, inertia ``J`` about its centre of mass) is a rigid body on the
station's mount point, which moves in translation only (the station's point response carries
three translations; the base's rotation is neglected).  In relative coordinates at the centre
of mass, ``q = [x, y, z, rx, ry, rz]`` of the platform minus the base (m, rad),

    M q'' + C q' + K q = -M E a0 + f + d,        a = q'' + E a0,

with ``M = diag(m, m, m, J)``, ``E = [I3; 0]`` (the base acceleration ``a0`` acts on the
translations), ``f`` the actuator forces and torques, ``d`` a force or torque applied directly
to the platform (a payload's own fan, a crew touch), and ``a`` the platform's absolute linear
and angular acceleration (m/s^2, rad/s^2).  The umbilicals are a spring and a dashpot per axis
at their attachment point (diagonal there, plus an optional full 6x6 coupling matrix); the
centre of mass sits at ``cm_offset_m`` from that point, so at the centre of mass

    K = T^T K_a T,   C = T^T C_a T,   T = [[I, [r]x], [0, I]],   r = cm_offset_m

(the attachment point's displacement is ``u + theta x (-r)``), which couples translation and
rotation.  This is the linearised rigid-platform model of the ARIS and g-LIMIT design papers
(Hampton et al.; Beech & Hampton, AIAA 2001-1138), with the actuators lumped into one force
and one torque per axis at the centre of mass and the sensors blended into the six rigid-body
measurements (the geometry of the eight pushrods or three Lorentz actuators, and of the
accelerometer heads, is not modelled).

Sensors: accelerometers measure ``a`` through a second-order Butterworth low-pass of
bandwidth ``accel_bandwidth_hz`` (infinite: ideal), with white noise of one-sided PSD
``(accel_noise_ug_per_rthz * 1e-6 g)^2`` per axis added before the filter; relative-position
sensors measure ``q`` with white noise ``position_noise_m_per_rthz``.  Actuators apply the
commanded force after the computation delay; the digital controller's zero-order hold adds half
a sample, so the continuous model delays by ``delay_s + 0.5 / sample_rate_hz`` (Pade
approximant, :func:`control.pade`), and the discrete model (:func:`control.c2d`, ZOH at
``sample_rate_hz``) by ``round(delay_s * sample_rate_hz)`` samples.

:meth:`ActivePlant.generalized` builds, with python-control, the plant of every verification:
inputs ``[a0 (3), d (6), n_a (6), n_p (6), u (6)]``, outputs ``[a (6), q (6), f (6), a_m (6),
q_m (6)]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from functools import cached_property
from typing import Any

import numpy as np

from microg._kept import Kept, frozen_array, frozen_state
from microg.errors import InputError
from microg.units import G0

__all__ = ["ActivePlant", "DOF_NAMES", "N_EXO", "gain", "plant_key", "rigid_transform"]

#: names of the six rigid-body coordinates (and of the six control loops)
DOF_NAMES = ("x", "y", "z", "rx", "ry", "rz")
#: exogenous inputs of the generalized plant: a0 (3), d (6), n_a (6), n_p (6)
N_EXO = 21


def _skew(r: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def rigid_transform(r: np.ndarray) -> np.ndarray:
    """``T`` mapping centre-of-mass motion to the motion of a point at ``-r`` from it.

    Parameters
    ----------
    r : (3,) position of the centre of mass relative to the point, m.

    The point's small displacement is ``u + theta x (-r) = u + [r]x theta``.
    """
    t = np.eye(6)
    t[:3, 3:] = _skew(np.asarray(r, float))
    return t


def gain(matrix: np.ndarray, dt: float | None = None) -> Any:
    """A static gain as a ``control.StateSpace`` (no states); ``dt`` for a sampled one."""
    import control as ct

    d = np.atleast_2d(np.asarray(matrix, float))
    kw = {} if dt is None else {"dt": dt}
    return ct.ss(np.zeros((0, 0)), np.zeros((0, d.shape[1])), np.zeros((d.shape[0], 0)), d, **kw)


def _vec3(value: Any, where: str, *, positive: bool, allow_inf: bool = False) -> np.ndarray:
    v = np.asarray(value, float)
    if v.ndim == 0:
        v = np.full(3, float(v))
    if v.shape != (3,):
        raise InputError(f"needs 3 values (x, y, z), got shape {v.shape}", where=where)
    bad = ~np.isfinite(v) if not allow_inf else np.isnan(v)
    if np.any(bad) or (np.any(v <= 0) if positive else np.any(v < 0)):
        need = "> 0" if positive else ">= 0"
        raise InputError(f"must be finite numbers {need}, got {v.tolist()}", where=where)
    return v


def _scalar(
    value: float, where: str, *, allow_zero: bool = False, allow_inf: bool = False
) -> float:
    v = float(value)
    ok = (v >= 0 if allow_zero else v > 0) and not math.isnan(v) and (allow_inf or math.isfinite(v))
    if not ok:
        need = ">= 0" if allow_zero else "> 0"
        raise InputError(f"must be a finite number {need}, got {value!r}", where=where)
    return v


#: generalized plants already built (by plant, Pade order, model) (the 32 most recent)
_GEN_CACHE: Kept[tuple[Any, ...], Any] = Kept(32)


def plant_key(plant: ActivePlant) -> tuple[Any, ...]:
    """A hashable fingerprint of every physical parameter of ``plant`` (arrays by value)."""
    return plant._fingerprint


@dataclass(frozen=True)
class ActivePlant:
    """An actively isolated payload (module docstring).

    Attributes
    ----------
    mass_kg : platform mass, kg
    inertia_kg_m2 : (3, 3) inertia about the centre of mass, kg m^2 (3 values: diagonal)
    cm_offset_m : (3,) centre of mass relative to the umbilical attachment point, m
    umbilical_k_N_per_m, umbilical_c_N_s_per_m : (3,) translational stiffness (N/m) and
        damping (N s/m) per axis at the attachment point
    umbilical_k_N_m_per_rad, umbilical_c_N_m_s_per_rad : (3,) rotational stiffness
        (N m/rad) and damping (N m s/rad) per axis
    umbilical_k_coupling, umbilical_c_coupling : (6, 6) symmetric terms added at the
        attachment point (SI per entry: N/m, N/rad, N m/rad; and the damping's), or None
    rattlespace_m : largest relative translation allowed, m (> 0)
    rattlespace_rad : largest relative rotation allowed, rad (> 0)
    actuator_force_N : force available per axis, N
    actuator_torque_N_m : torque available per axis, N m
    accel_noise_ug_per_rthz : accelerometer noise, micro-g per sqrt(Hz) (white)
    accel_bandwidth_hz : accelerometer bandwidth (2nd-order Butterworth), Hz (inf: ideal)
    position_noise_m_per_rthz : relative-position sensor noise, m per sqrt(Hz) (white)
    position_range_m : relative-position sensor range, m
    sample_rate_hz : controller sampling rate, Hz
    delay_s : computation delay, s
    max_loop_hz : highest acceleration-loop gain the platform allows, Hz (its flexible modes,
        not modelled, bound the bandwidth; inf: only the sensors and the delay do)
    name : preset or user label
    sources : parameter -> where its value comes from
    """

    mass_kg: float
    inertia_kg_m2: np.ndarray
    cm_offset_m: np.ndarray
    umbilical_k_N_per_m: np.ndarray  # noqa: N815
    umbilical_c_N_s_per_m: np.ndarray  # noqa: N815
    umbilical_k_N_m_per_rad: np.ndarray  # noqa: N815
    umbilical_c_N_m_s_per_rad: np.ndarray  # noqa: N815
    rattlespace_m: float
    rattlespace_rad: float
    actuator_force_N: float  # noqa: N815
    actuator_torque_N_m: float  # noqa: N815
    accel_noise_ug_per_rthz: float = 0.0
    accel_bandwidth_hz: float = math.inf
    position_noise_m_per_rthz: float = 0.0
    position_range_m: float = math.inf
    sample_rate_hz: float = 1000.0
    delay_s: float = 0.0
    max_loop_hz: float = math.inf
    umbilical_k_coupling: np.ndarray | None = None
    umbilical_c_coupling: np.ndarray | None = None
    name: str = "custom"
    sources: dict[str, str] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "mass_kg", _scalar(self.mass_kg, "mass"))
        j = np.asarray(self.inertia_kg_m2, float)
        if j.ndim == 0 or j.shape == (3,):
            j = np.diag(_vec3(j, "inertia", positive=True))
        if j.shape != (3, 3) or not np.all(np.isfinite(j)) or not np.allclose(j, j.T):
            raise InputError("must be 3 values or a symmetric 3x3 matrix", where="inertia")
        if np.linalg.eigvalsh(j).min() <= 0:
            raise InputError("must be positive definite", where="inertia")
        s(self, "inertia_kg_m2", j)
        off = np.asarray(self.cm_offset_m, float).reshape(-1)
        if off.shape != (3,) or not np.all(np.isfinite(off)):
            raise InputError("needs 3 finite values (x, y, z), m", where="cm-offset")
        s(self, "cm_offset_m", off)
        for name, where in (
            ("umbilical_k_N_per_m", "umbilical-stiffness"),
            ("umbilical_c_N_s_per_m", "umbilical-damping"),
            ("umbilical_k_N_m_per_rad", "umbilical-rot-stiffness"),
            ("umbilical_c_N_m_s_per_rad", "umbilical-rot-damping"),
        ):
            s(self, name, _vec3(getattr(self, name), where, positive=False))
        for name, where in (
            ("umbilical_k_coupling", "k-coupling"),
            ("umbilical_c_coupling", "c-coupling"),
        ):
            v = getattr(self, name)
            if v is not None:
                v = np.asarray(v, float)
                if v.shape != (6, 6) or not np.all(np.isfinite(v)) or not np.allclose(v, v.T):
                    raise InputError("must be a symmetric 6x6 matrix", where=where)
                s(self, name, v)
        for name, where in (
            ("rattlespace_m", "rattlespace"),
            ("rattlespace_rad", "rattlespace-rot"),
            ("actuator_force_N", "actuator-force"),
            ("actuator_torque_N_m", "actuator-torque"),
            ("sample_rate_hz", "sample-rate"),
        ):
            s(self, name, _scalar(getattr(self, name), where))
        s(
            self,
            "accel_noise_ug_per_rthz",
            _scalar(self.accel_noise_ug_per_rthz, "accel-noise", allow_zero=True),
        )
        s(
            self,
            "position_noise_m_per_rthz",
            _scalar(self.position_noise_m_per_rthz, "position-noise", allow_zero=True),
        )
        s(
            self,
            "accel_bandwidth_hz",
            _scalar(self.accel_bandwidth_hz, "accel-bandwidth", allow_inf=True),
        )
        s(
            self,
            "position_range_m",
            _scalar(self.position_range_m, "position-range", allow_inf=True),
        )
        s(self, "delay_s", _scalar(self.delay_s, "delay", allow_zero=True))
        s(self, "max_loop_hz", _scalar(self.max_loop_hz, "max-loop", allow_inf=True))
        if self.delay_s * self.sample_rate_hz > 100:
            raise InputError(
                f"{self.delay_s:g} s is more than 100 samples at {self.sample_rate_hz:g} Hz",
                where="delay",
            )
        for axis in ("k", "c"):
            mat = self.umbilical_matrix(axis)
            if np.linalg.eigvalsh(0.5 * (mat + mat.T)).min() < -1e-9 * max(1.0, np.abs(mat).max()):
                raise InputError(
                    "the umbilical matrix with its coupling is not positive semi-definite",
                    where="k-coupling" if axis == "k" else "c-coupling",
                )
        for f in fields(self):  # the arrays are the plant's own, read-only (it is frozen)
            s(self, f.name, frozen_array(getattr(self, f.name)))

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(frozen_state(state))

    # ------------------------------------------------------------------ matrices

    def with_(self, **changes: Any) -> ActivePlant:
        """A copy with ``changes`` (validated again)."""
        return replace(self, **changes)

    def mass_matrix(self) -> np.ndarray:
        """``M = diag(m, m, m, J)`` at the centre of mass, (6, 6), kg and kg m^2."""
        mm = np.zeros((6, 6))
        mm[:3, :3] = self.mass_kg * np.eye(3)
        mm[3:, 3:] = self.inertia_kg_m2
        return mm

    def umbilical_matrix(self, which: str, at: str = "cm") -> np.ndarray:
        """Umbilical stiffness (``which="k"``) or damping (``"c"``), (6, 6), SI.

        Parameters
        ----------
        which : ``"k"`` or ``"c"``
        at : ``"attachment"`` (diagonal plus coupling) or ``"cm"`` (``T^T K_a T``)
        """
        if which == "k":
            diag = np.concatenate([self.umbilical_k_N_per_m, self.umbilical_k_N_m_per_rad])
            extra = self.umbilical_k_coupling
        else:
            diag = np.concatenate([self.umbilical_c_N_s_per_m, self.umbilical_c_N_m_s_per_rad])
            extra = self.umbilical_c_coupling
        ka = np.diag(diag) + (extra if extra is not None else 0.0)
        if at == "attachment":
            return ka
        t = rigid_transform(self.cm_offset_m)
        return t.T @ ka @ t

    @property
    def effective_delay_s(self) -> float:
        """Delay of the continuous model: computation plus half a ZOH sample, s."""
        return self.delay_s + 0.5 / self.sample_rate_hz

    @property
    def delay_samples(self) -> int:
        """Computation delay of the discrete model, whole samples."""
        return int(round(self.delay_s * self.sample_rate_hz))

    @property
    def accel_noise_psd(self) -> float:
        """Accelerometer noise, one-sided PSD, (m/s^2)^2/Hz."""
        return (self.accel_noise_ug_per_rthz * 1e-6 * G0) ** 2

    @property
    def position_noise_psd(self) -> float:
        """Position sensor noise, one-sided PSD, m^2/Hz."""
        return self.position_noise_m_per_rthz**2

    def limits(self) -> tuple[np.ndarray, np.ndarray]:
        """(stroke limit per DOF: m, m, m, rad, rad, rad; force limit per DOF: N, N m)."""
        stroke_t = min(self.rattlespace_m, self.position_range_m)
        stroke = np.array([stroke_t] * 3 + [self.rattlespace_rad] * 3)
        force = np.array([self.actuator_force_N] * 3 + [self.actuator_torque_N_m] * 3)
        return stroke, force

    def channel(self, i: int) -> tuple[float, float]:
        """Decoupled channel ``i``: ``((M^-1 K)_ii, (M^-1 C)_ii)``, 1/s^2 and 1/s."""
        k, c = self._channels
        return float(k[i]), float(c[i])

    @cached_property
    def _fingerprint(self) -> tuple[Any, ...]:
        """:func:`plant_key`'s value, formed once (the plant and its arrays are read-only)."""
        out: list[Any] = []
        for f in fields(self):
            if f.name in ("sources", "name"):
                continue
            v = getattr(self, f.name)
            out.append(None if v is None else np.asarray(v, float).tobytes())
        return tuple(out)

    @cached_property
    def _channels(self) -> tuple[np.ndarray, np.ndarray]:
        """Every channel's ``(M^-1 K)_ii`` and ``(M^-1 C)_ii``, (6,) each (formed once)."""
        minv = np.linalg.inv(self.mass_matrix())
        return (
            np.diag(minv @ self.umbilical_matrix("k")).copy(),
            np.diag(minv @ self.umbilical_matrix("c")).copy(),
        )

    # ---------------------------------------------------------------- state space

    def physical(self) -> Any:
        """Rigid platform on umbilicals, ``control.StateSpace``.

        States ``[q (6), q' (6)]``; inputs ``[a0 (3), d (6), f (6)]``; outputs
        ``[a (6), q (6), f (6)]`` (the applied force passed through, for the limits).
        """
        import control as ct

        mm = self.mass_matrix()
        minv = np.linalg.inv(mm)
        kk, cc = self.umbilical_matrix("k"), self.umbilical_matrix("c")
        z6, i6 = np.zeros((6, 6)), np.eye(6)
        e = np.vstack([np.eye(3), np.zeros((3, 3))])
        a = np.block([[z6, i6], [-minv @ kk, -minv @ cc]])
        b = np.block([[np.zeros((6, 3)), z6, z6], [-e, minv, minv]])
        c = np.block([[-minv @ kk, -minv @ cc], [i6, z6], [z6, z6]])
        d = np.block(
            [[np.zeros((6, 3)), minv, minv], [np.zeros((6, 3)), z6, z6], [np.zeros((6, 9)), i6]]
        )
        return ct.ss(a, b, c, d)

    def accelerometer(self) -> Any:
        """Six accelerometer channels: 2nd-order Butterworth at the bandwidth (or unity)."""
        import control as ct

        if not math.isfinite(self.accel_bandwidth_hz):
            return gain(np.eye(6))
        wb = 2 * math.pi * self.accel_bandwidth_hz
        one = ct.ss(ct.tf([wb**2], [1.0, math.sqrt(2.0) * wb, wb**2]))
        return ct.append(*([one] * 6))

    def actuator_delay(self, pade_order: int = 3, *, discrete: bool = False) -> Any:
        """Delay of the six actuator channels: Pade (continuous) or ``z^-n`` (discrete)."""
        import control as ct

        if discrete:
            n = self.delay_samples
            dt = 1.0 / self.sample_rate_hz
            if n == 0:
                return gain(np.eye(6), dt)
            a1 = np.eye(n, k=-1)
            one = ct.ss(a1, np.eye(n, 1), np.eye(1, n, n - 1), [[0.0]], dt)
            return ct.append(*([one] * 6))
        tau = self.effective_delay_s
        if tau <= 0 or pade_order == 0:
            return gain(np.eye(6))
        num, den = ct.pade(tau, pade_order)
        one = ct.ss(ct.tf(num, den))
        return ct.append(*([one] * 6))

    def generalized(self, pade_order: int = 3, *, discrete: bool = False) -> Any:
        """The generalized plant of the module docstring, ``control.StateSpace``.

        Built once per plant (by value, :func:`plant_key`), Pade order and model, and shared:
        callers must not modify it.

        Parameters
        ----------
        pade_order : order of the Pade approximant of the actuator delay (continuous model)
        discrete : the sampled model instead: ZOH at ``sample_rate_hz`` (:func:`control.c2d`)
            and the computation delay in whole samples
        """
        key = (plant_key(self), pade_order, discrete)
        hit = _GEN_CACHE.get(key)
        if hit is None:
            hit = _GEN_CACHE.put(key, self._generalized(pade_order, discrete))
        return hit

    def _generalized(self, pade_order: int, discrete: bool) -> Any:
        import control as ct

        phys = self.physical()  # [a0, d, f] -> [a, q, f]
        # the sensors see [a, q] and the noises: a_m = H (a + n_a), q_m = q + n_p
        acc = self.accelerometer()
        sel = np.zeros((12, 30))  # [a, q, f, n_a, n_p] -> [a + n_a, q + n_p]
        sel[:6, :6] = np.eye(6)
        sel[:6, 18:24] = np.eye(6)
        sel[6:, 6:12] = np.eye(6)
        sel[6:, 24:30] = np.eye(6)
        ident6 = gain(np.eye(6))
        meas = ct.series(gain(sel), ct.append(acc, ident6))  # 30 -> 12
        fan = np.vstack([np.hstack([np.eye(18), np.zeros((18, 12))]), np.eye(30)])  # 30 -> 48
        outs = ct.series(gain(fan), ct.append(gain(np.eye(18)), meas))
        if discrete:
            dt = 1.0 / self.sample_rate_hz
            body = ct.series(ct.append(phys, gain(np.eye(12))), outs)
            body = ct.c2d(body, dt, "zoh")
            dly = self.actuator_delay(discrete=True)
            ident = gain(np.eye(21), dt)
        else:
            body = ct.series(ct.append(phys, gain(np.eye(12))), outs)
            dly = self.actuator_delay(pade_order)
            ident = gain(np.eye(21))
        # body inputs: [a0, d, f, n_a, n_p]; reorder to [a0, d, n_a, n_p, u] with f = delay(u)
        perm = np.zeros((27, 27))
        perm[0:9, 0:9] = np.eye(9)  # a0, d
        perm[9:15, 21:27] = np.eye(6)  # f <- delayed u
        perm[15:27, 9:21] = np.eye(12)  # n_a, n_p
        reorder = gain(perm, 1.0 / self.sample_rate_hz if discrete else None)
        head = ct.series(ct.append(ident, dly), reorder)  # [a0,d,n_a,n_p,u] -> body inputs
        return ct.series(head, body)

    # ---------------------------------------------------------------------- output

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready parameters (the contract's ``plant`` block), SI with units in the names."""

        def axes3(v: np.ndarray) -> dict[str, float]:
            return dict(zip(("x", "y", "z"), (float(x) for x in v), strict=True))

        def mat(v: np.ndarray | None) -> list[list[float]] | None:
            return None if v is None else [[float(x) for x in row] for row in v]

        def num(v: float) -> float | str:
            return float(v) if math.isfinite(v) else "inf"

        return {
            "name": self.name,
            "mass_kg": self.mass_kg,
            "inertia_kg_m2": mat(self.inertia_kg_m2),
            "cm_offset_m": axes3(self.cm_offset_m),
            "umbilical": {
                "k_N_per_m": axes3(self.umbilical_k_N_per_m),
                "c_N_s_per_m": axes3(self.umbilical_c_N_s_per_m),
                "k_N_m_per_rad": axes3(self.umbilical_k_N_m_per_rad),
                "c_N_m_s_per_rad": axes3(self.umbilical_c_N_m_s_per_rad),
                "k_coupling": mat(self.umbilical_k_coupling),
                "c_coupling": mat(self.umbilical_c_coupling),
                "natural_freq_hz": {
                    n: math.sqrt(max(self.channel(i)[0], 0.0)) / (2 * math.pi)
                    for i, n in enumerate(DOF_NAMES)
                },
            },
            "rattlespace_m": self.rattlespace_m,
            "rattlespace_rad": self.rattlespace_rad,
            "actuator_force_N": self.actuator_force_N,
            "actuator_torque_N_m": self.actuator_torque_N_m,
            "accel_noise_ug_per_rthz": self.accel_noise_ug_per_rthz,
            "accel_bandwidth_hz": num(self.accel_bandwidth_hz),
            "position_noise_m_per_rthz": self.position_noise_m_per_rthz,
            "position_range_m": num(self.position_range_m),
            "sample_rate_hz": self.sample_rate_hz,
            "delay_s": self.delay_s,
            "max_loop_hz": num(self.max_loop_hz),
            "sources": dict(self.sources),
        }
