"""The result of an active-isolation design: :class:`ActiveIsolation`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.environment.metrics import json_number
from microg.isolation.active.controller import GM_MIN, PM_MIN_DEG, Controller
from microg.isolation.active.plant import DOF_NAMES, ActivePlant
from microg.isolation.active.sourcecheck import SourcesCheck
from microg.isolation.active.target import Target
from microg.isolation.active.verify import LoopMargin
from microg.units import G0

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from microg.environment.metrics import Assessment

__all__ = ["ActiveIsolation", "TimeCheck", "BINDING_LIMITS"]

#: what can bind a design, in the order they are checked
BINDING_LIMITS = ("umbilical", "rattlespace", "actuator_force", "sensor_noise")
_AXES = ("x", "y", "z")


def _nums(a: np.ndarray) -> list[float | str | None]:
    return [json_number(v) for v in np.asarray(a, float).ravel()]


@dataclass(frozen=True)
class TimeCheck:
    """The station's own response at the mount point pushed through the closed loop.

    Attributes
    ----------
    point : the mount point's name
    timepts : (nt,) s
    base_accel : (3, nt) the mount point's acceleration, m/s^2
    platform_accel : (3, nt) the platform's, m/s^2
    stroke : (6, nt) relative motion, m and rad
    force : (6, nt) actuator force and torque, N and N m
    base : Assessment of the base acceleration
    isolated : Assessment of the platform acceleration (time domain)
    spectral_rms_g : (3, nb) band RMS of the frequency-domain path (``sum_j |T_ij|^2 S_j`` of
        the record's periodogram), g, on the isolated assessment's bands
    noise_rms_g : (3, nb) the sensors' noise floor per band, g
    combined_margin : (nb,) limit / sqrt(time-domain^2 + noise^2), worst axis
    complies : every resolved band within its limit with the noise added, and the time-domain
        verdict's other criteria met
    """

    point: str
    timepts: np.ndarray
    base_accel: np.ndarray
    platform_accel: np.ndarray
    stroke: np.ndarray
    force: np.ndarray
    base: Assessment = field(repr=False)
    isolated: Assessment = field(repr=False)
    spectral_rms_g: np.ndarray
    noise_rms_g: np.ndarray
    combined_margin: np.ndarray
    complies: bool

    @property
    def peak_stroke(self) -> np.ndarray:
        """Largest |relative motion| per DOF, (6,), m and rad."""
        return np.max(np.abs(self.stroke), axis=1)

    @property
    def peak_force(self) -> np.ndarray:
        """Largest |actuator force/torque| per DOF, (6,), N and N m."""
        return np.max(np.abs(self.force), axis=1)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (no histories; ``to_xarray`` has them)."""
        to = self.isolated.third_octave
        wb = self.isolated.worst_band
        return {
            "point": self.point,
            "record_s": float(self.timepts[-1] - self.timepts[0]),
            "samples": int(self.timepts.size),
            "base_peak_accel_g": self.base.peak_accel_g,
            "platform_peak_accel_g": self.isolated.peak_accel_g,
            "base_complies": bool(self.base.complies),
            "time_domain_complies": bool(self.isolated.complies),
            "complies": bool(self.complies),
            "worst_band": None if wb is None else wb.to_dict(),
            "peak_stroke": dict(zip(DOF_NAMES, map(float, self.peak_stroke), strict=True)),
            "peak_force": dict(zip(DOF_NAMES, map(float, self.peak_force), strict=True)),
            "third_octave": {
                "center_hz": _nums(to.center_hz),
                "limit_g": _nums(to.limit_g),
                "resolved": [bool(v) for v in to.resolved],
                "base_rms_g_axis": {
                    a: _nums(self.base.third_octave.rms_g[i]) for i, a in enumerate(_AXES)
                },
                "time_domain_rms_g_axis": {a: _nums(to.rms_g[i]) for i, a in enumerate(_AXES)},
                "frequency_domain_rms_g_axis": {
                    a: _nums(self.spectral_rms_g[i]) for i, a in enumerate(_AXES)
                },
                "noise_rms_g_axis": {a: _nums(self.noise_rms_g[i]) for i, a in enumerate(_AXES)},
                "combined_margin": _nums(self.combined_margin),
            },
        }


@dataclass(frozen=True)
class ActiveIsolation:
    """An actively isolated payload, designed and verified (``design_active``).

    Attributes
    ----------
    plant, controller, target : what was designed, and to what
    stable : every pole of the continuous (Pade delay) and of the sampled closed loop stable
    pole_margin : (continuous: largest real part, 1/s; discrete: largest |z| - 1)
    margins : per loop, both models
    loop_response : (6, nf) each loop's ``L_i`` (continuous model) at ``freq_hz``, complex
    freq_hz : (nf,) frequencies of the curves, Hz
    transmissibility : (3, 3, nf) base to platform acceleration, complex
    passive : (3, 3, nf) the same with the controller off
    disturbance : (6, nf) direct response |a_i / d_i| closed loop, SI per N (N m)
    disturbance_passive : (6, nf) the same with the controller off
    noise_psd : (3, nf) the sensors' noise floor on the platform, (m/s^2)^2/Hz
    noise_center_hz, noise_limit_g : (nb,) the requirement's bands and limits, Hz and g
    noise_band_rms_g : (3, nb) the noise floor's band RMS, g
    target_ratio : (3,) largest |T_ii| / allowed over the target's check frequencies
    passes_quasi_steady : |T_ii| >= the pass level a decade below the target's corner
        (None when the target has no quasi-steady corner)
    time : the time-domain check, or None without a station response
    sources : the station's vibratory sources at the mount point through the closed loop
        (band table and verdict), or None without sources
    meets_target : stable, margins kept, the target met, and (with a time check) stroke and
        force within their limits and the noise floor below the requirement
    binding_limit : the first of :data:`BINDING_LIMITS` that is exceeded, or None
    limits_exceeded : every one exceeded
    notes : the design's and the checks' findings
    """

    plant: ActivePlant
    controller: Controller
    target: Target
    stable: bool
    pole_margin: tuple[float, float]
    margins: tuple[LoopMargin, ...]
    loop_response: np.ndarray
    freq_hz: np.ndarray
    transmissibility: np.ndarray
    passive: np.ndarray
    disturbance: np.ndarray
    disturbance_passive: np.ndarray
    noise_psd: np.ndarray
    noise_center_hz: np.ndarray
    noise_limit_g: np.ndarray
    noise_band_rms_g: np.ndarray
    target_ratio: np.ndarray
    passes_quasi_steady: bool | None
    time: TimeCheck | None
    sources: SourcesCheck | None
    meets_target: bool
    binding_limit: str | None
    limits_exceeded: tuple[str, ...]
    notes: tuple[str, ...] = ()

    # ------------------------------------------------------------------ derived

    @property
    def margins_kept(self) -> bool:
        """Every loop keeps the design minima (phase and gain margin), both models."""
        return all(
            m.phase_margin_deg >= PM_MIN_DEG and m.gain_margin_factor >= GM_MIN
            for m in self.margins
        )

    def transmissibility_axis(self) -> np.ndarray:
        """``|T_ii|`` per axis, (3, nf)."""
        return np.abs(np.array([self.transmissibility[i, i] for i in range(3)]))

    def attenuation_at(self, freq_hz: float) -> np.ndarray:
        """``1 / |T_ii|`` per axis at one frequency (log-log interpolation), (3,)."""
        t = self.transmissibility_axis()
        lf = np.log(self.freq_hz)
        return np.array(
            [1.0 / math.exp(np.interp(math.log(freq_hz), lf, np.log(t[i]))) for i in range(3)]
        )

    @property
    def complies(self) -> bool:
        """The platform meets the requirement at the mount point, every limit kept.

        The time check (noise included) complies, the design is stable with its margins kept,
        the stroke and force stay within their limits, and, when the sources were checked,
        their band verdict on the platform (noise included) complies too.
        """
        if self.time is None or not self.stable or not self.margins_kept:
            return False
        if self.sources is not None and not self.sources.complies:
            return False
        stroke, force = self.plant.limits()
        return (
            bool(self.time.complies)
            and bool(np.all(self.time.peak_stroke <= stroke))
            and bool(np.all(self.time.peak_force <= force))
        )

    # ------------------------------------------------------------------ output

    def margins_dict(self) -> dict[str, Any]:
        """Per loop: ``{"x": {"continuous": {...}, "discrete": {...}}, ...}``."""
        out: dict[str, Any] = {n: {} for n in DOF_NAMES}
        for m in self.margins:
            out[m.loop][m.model] = m.to_dict()
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready result (the ``microg isolate active --json`` contract); strict JSON."""
        stroke_lim, force_lim = self.plant.limits()
        tm = self.time
        t_axis = self.transmissibility_axis()
        out: dict[str, Any] = {
            "stable": bool(self.stable),
            "pole_margin": {
                "continuous_max_real_per_s": json_number(self.pole_margin[0]),
                "discrete_max_abs_minus_1": json_number(self.pole_margin[1]),
            },
            "margins": self.margins_dict(),
            "margins_kept": self.margins_kept,
            "margin_minima": {"phase_deg": PM_MIN_DEG, "gain_factor": GM_MIN},
            "frequency_hz": _nums(self.freq_hz),
            "transmissibility": {a: _nums(t_axis[i]) for i, a in enumerate(_AXES)},
            "passive_transmissibility": {
                a: _nums(np.abs(self.passive[i, i])) for i, a in enumerate(_AXES)
            },
            "disturbance_accel_per_N": {
                n: _nums(self.disturbance[i]) for i, n in enumerate(DOF_NAMES[:3])
            },
            "disturbance_accel_per_N_passive": {
                n: _nums(self.disturbance_passive[i]) for i, n in enumerate(DOF_NAMES[:3])
            },
            "noise_floor_g_per_rthz": {
                a: _nums(np.sqrt(self.noise_psd[i]) / G0) for i, a in enumerate(_AXES)
            },
            "noise_floor_bands": {
                "center_hz": _nums(self.noise_center_hz),
                "limit_g": _nums(self.noise_limit_g),
                "rms_g_axis": {a: _nums(self.noise_band_rms_g[i]) for i, a in enumerate(_AXES)},
                "worst_margin": json_number(
                    float(
                        np.min(
                            self.noise_limit_g
                            / np.maximum(self.noise_band_rms_g.max(axis=0), 1e-300)
                        )
                    )
                ),
            },
            "attenuation_at_0_1_hz": dict(
                zip(_AXES, map(float, self.attenuation_at(0.1)), strict=True)
            ),
            "plant": self.plant.to_dict(),
            "controller": self.controller.to_dict(),
            "target": {
                **self.target.to_dict(),
                "limit": _nums(self.target.limit(self.freq_hz)),
                "worst_ratio_axis": dict(
                    zip(_AXES, map(json_number, self.target_ratio), strict=True)
                ),
                "passes_quasi_steady": self.passes_quasi_steady,
            },
            "meets_target": bool(self.meets_target),
            "binding_limit": self.binding_limit,
            "limits_exceeded": list(self.limits_exceeded),
            "complies": bool(self.complies),
            "stroke_m": None if tm is None else float(tm.peak_stroke[:3].max()),
            "stroke_rad": None if tm is None else float(tm.peak_stroke[3:].max()),
            "force_N": None if tm is None else float(tm.peak_force[:3].max()),
            "torque_N_m": None if tm is None else float(tm.peak_force[3:].max()),
            "stroke_limit_m": float(stroke_lim[0]),
            "force_limit_N": float(force_lim[0]),
            "time_check": None if tm is None else tm.to_dict(),
            "sources": None if self.sources is None else self.sources.to_dict(),
            "notes": list(self.notes),
        }
        return out

    def to_xarray(self) -> Any:
        """Curves on ``freq_hz``, histories on ``time_s`` (with a record), ``xarray.Dataset``."""
        import xarray as xr

        t_axis = self.transmissibility_axis()
        data: dict[str, Any] = {
            "transmissibility": (("axis", "freq_hz"), t_axis, {"units": "1"}),
            "passive_transmissibility": (
                ("axis", "freq_hz"),
                np.abs(np.array([self.passive[i, i] for i in range(3)])),
                {"units": "1"},
            ),
            "target_limit": ("freq_hz", self.target.limit(self.freq_hz), {"units": "1"}),
            "noise_psd_g2_per_hz": (
                ("axis", "freq_hz"),
                self.noise_psd / G0**2,
                {"units": "g^2/Hz"},
            ),
            "disturbance_accel_per_N": (
                ("axis", "freq_hz"),
                self.disturbance[:3],
                {"units": "m/s^2/N"},
            ),
        }
        coords: dict[str, Any] = {
            "axis": list(_AXES),
            "freq_hz": ("freq_hz", self.freq_hz, {"units": "Hz"}),
        }
        tm = self.time
        if tm is not None:
            coords["time_s"] = ("time_s", tm.timepts, {"units": "s"})
            coords["dof"] = list(DOF_NAMES)
            data["base_accel_g"] = (("axis", "time_s"), tm.base_accel / G0, {"units": "g"})
            data["platform_accel_g"] = (("axis", "time_s"), tm.platform_accel / G0, {"units": "g"})
            data["stroke"] = (
                ("dof", "time_s"),
                tm.stroke,
                {"units": "m (x, y, z); rad (rx, ry, rz)"},
            )
            data["force"] = (
                ("dof", "time_s"),
                tm.force,
                {"units": "N (x, y, z); N m (rx, ry, rz)"},
            )
        sc = self.sources
        if sc is not None:
            coords["band_center_hz"] = ("band_center_hz", sc.platform.center_hz, {"units": "Hz"})
            for name, values in (
                ("sources_base_rms_g", sc.base.rms_g[0]),
                ("sources_platform_rms_g", sc.platform.rms_g[0]),
                ("sources_combined_rms_g", sc.combined_rms_g),
            ):
                data[name] = (("axis", "band_center_hz"), values, {"units": "g"})
            data["sources_limit_g"] = ("band_center_hz", sc.platform.limit_g, {"units": "g"})
        return xr.Dataset(
            data,
            coords=coords,
            attrs={
                "plant": self.plant.name,
                "controller": self.controller.kind,
                "target": self.target.name,
                "stable": int(self.stable),
                "meets_target": int(self.meets_target),
                "binding_limit": self.binding_limit or "",
            },
        )

    def plot(self, ax: Any = None, kind: str = "transmissibility") -> Figure:
        """A figure of the design (``plotting.active``), on ``ax`` when given.

        ``kind``: ``transmissibility`` (with the target), ``noise``, ``time`` (the time-domain
        check), ``margins`` (Nyquist of each loop) or ``bands``.
        """
        from microg.plotting.active import plot_active

        return plot_active(self, kind=kind, ax=ax)
