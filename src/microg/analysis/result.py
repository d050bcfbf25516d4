"""The main job's results: :class:`Analysis` and the :class:`Observation` at each point.

:func:`microg.analyze` returns one :class:`Analysis`; the CLI (``--json`` is exactly its
``to_dict()``) and the HTML report only read it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from microg._vectors import axis_name
from microg.analysis.contributions import ModeContributions
from microg.analysis.options import REPORT_LIMIT_G, AnalysisOptions, Disturbance
from microg.dynamics.modes import Modes
from microg.dynamics.peaks import PeakResponse
from microg.dynamics.response import PointResponse
from microg.environment.criteria import CriterionVerdict, combine_verdicts
from microg.environment.metrics import Assessment
from microg.environment.requirements import Requirement
from microg.isolation.advise import IsolationAdvice
from microg.structure.structure import Structure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["Analysis", "Observation", "report_criterion"]

#: the seed report's criterion, cited (the ``report-1e-5g`` transient set has the same limit)
REPORT_SOURCE = "seed report, Introduction: experiments require acceleration below 1e-5 g"


def report_criterion(a: Assessment) -> CriterionVerdict:
    """The seed report's 1e-5 g peak as a reported-only criterion (not the one judged).

    Parameters
    ----------
    a : the point's assessment (its ``peak_accel_g``, g)
    """
    peak = float(a.peak_accel_g)
    return CriterionVerdict(
        "report peak 1e-5 g",
        "reported",
        peak <= REPORT_LIMIT_G,
        float("inf") if peak <= 0 else REPORT_LIMIT_G / peak,
        peak,
        REPORT_LIMIT_G,
        "g",
        REPORT_SOURCE,
        f"the seed report's figure, shown for comparison; the verdict is {a.requirement}'s",
    )


@dataclass(frozen=True)
class Observation:
    """The result at one observed point.

    Attributes
    ----------
    name : str
    response : PointResponse
        Displacement, velocity and acceleration (3 axes, SI) at the output times.
    assessment : Assessment
        Peak, RMS, bands, margins, integrated acceleration against the requirement.
    isolation : IsolationAdvice
    contributions : ModeContributions
    interval : dict
        Band margins over consecutive intervals of
        :data:`~microg.analysis.options.REQUIREMENT_INTERVAL_S`.
    peak : PeakResponse
        The certified true maximum of the exact acceleration over the record (between
        samples and at both sides of every force jump); ``assessment.peak_accel_g`` is it.
    """

    name: str
    response: PointResponse
    assessment: Assessment
    isolation: IsolationAdvice
    contributions: ModeContributions
    interval: Mapping[str, Any]
    peak: PeakResponse | None = None

    @property
    def criteria(self) -> tuple[CriterionVerdict, ...]:
        """The assessment's criteria, then the seed report's 1e-5 g (reported only)."""
        return (*self.assessment.criteria, report_criterion(self.assessment))

    @property
    def peak_accel_g(self) -> float:
        """Peak of the acceleration magnitude, g."""
        return float(self.assessment.peak_accel_g)

    @property
    def complies(self) -> bool:
        """The band verdict at this point."""
        return bool(self.assessment.complies)

    @property
    def verdict(self) -> str:
        """``complies``, ``fails`` or ``undecided`` at this point (the assessment's)."""
        return self.assessment.verdict

    def to_dict(self) -> dict[str, Any]:
        """The observation block of ``microg analyze --json``."""
        d = self.assessment.to_dict()
        d["report_criterion"] = {
            "limit_g": REPORT_LIMIT_G,
            "peak_within": bool(self.assessment.peak_accel_g <= REPORT_LIMIT_G),
        }
        d["criteria"] = [c.to_dict() for c in self.criteria]
        d["requirement_interval"] = dict(self.interval)
        if self.peak is not None:
            d["peak"] = self.peak.to_dict()
        d["mode_contributions"] = self.contributions.to_dict()
        d["isolation"] = self.isolation.to_dict()
        return d

    def to_xarray(self) -> Any:
        """The acceleration history as an ``xarray.DataArray`` ``accel_mps2`` (axis, time)."""
        import xarray as xr

        r = self.response
        return xr.DataArray(
            r.acceleration,
            dims=("axis", "time"),
            coords={
                "axis": ["x", "y", "z"],
                "time": ("time", r.timepts, {"units": "s"}),
            },
            name="accel_mps2",
            attrs={"units": "m/s^2", "point": self.name, "long_name": "acceleration"},
        )

    def plot(self, ax: Any = None, *, kind: str | None = None) -> Figure:
        """Acceleration history and 1/3-octave bands against the requirement (a Figure).

        Parameters
        ----------
        ax : matplotlib.axes.Axes or a pair of them, optional
            Where to draw (one axes: the history, or ``kind``; two: both panels).
        kind : {"history", "bands"}, optional
            One panel only (see :func:`microg.plotting.analysis.observation_figure`).
        """
        from microg.plotting.analysis import observation_figure

        return observation_figure(self, ax=ax, kind=kind)

    def plot_interactive(self, kind: str = "bands") -> Any:
        """An interactive chart at this point (a plotly Figure), the live axes only.

        Parameters
        ----------
        kind : {"history", "bands", "psd", "integrated"}
            The acceleration history (micro-g), the 1/3-octave bands against the limit
            (micro-g, judged bands filled), the PSD (g^2/Hz) or the 10-s integrated
            acceleration (micro-g s); see :mod:`microg.plotting.interactive`.
        """
        from microg.plotting.analysis import live_axes
        from microg.plotting.interactive import bands, histories, spectra

        a, r = self.assessment, self.response
        rows = live_axes(r.acceleration)
        axes = tuple("xyz"[i] for i in rows)
        if kind == "history":
            return histories.history_chart(
                r.timepts,
                r.acceleration[rows],
                axes=axes,
                title=f"Acceleration at {self.name} (peak {a.peak_accel_g:.3g} g)",
            )
        if kind == "bands":
            return bands.bands_chart(
                a.third_octave,
                axes=a.axes,
                rows=rows,
                title=f"1/3-octave band RMS at {self.name} vs {a.requirement}",
                verdict_range_hz=a.verdict_range_hz,
            )
        if kind == "psd":
            return spectra.psd_chart(
                a.spectrum, axes=a.axes, rows=rows, title=f"PSD at {self.name}"
            )
        if kind == "integrated":
            integ = a.integrated_sliding
            return histories.integrated_chart(
                integ,
                axes=a.axes,
                rows=rows,
                title=f"{integ.window_s:g}-s integrated acceleration at {self.name}",
            )
        from microg.errors import InputError

        raise InputError(
            f"unknown chart {kind!r}", where="kind", fix="use history, bands, psd or integrated"
        )


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`microg.analyze`.

    Attributes
    ----------
    model : str
        Model name.
    options : AnalysisOptions
    structure : Structure
    modes : Modes
        All computed modes (``used`` marks those in the response).
    used : ndarray of bool
        Modes kept for the response (rigid + elastic up to ``max_freq_hz``).
    observations : dict of str to Observation
    timepts : ndarray
        Output times, s.
    requirement : Requirement
    warnings : list of str
        What makes the verdict shaky; shown in the JSON, the console and the report.
    notes : list of str
    meta : dict
        Provenance: microg version, UTC time, command, model path and sha256.
    frequency_domain : VibratoryAssessment or None
        The vibratory sources' band table per observed point (frequency domain), when sources
        were given.
    """

    model: str
    options: AnalysisOptions
    structure: Structure
    modes: Modes
    used: np.ndarray
    observations: dict[str, Observation]
    timepts: np.ndarray
    requirement: Requirement
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)
    frequency_domain: Any = None

    @property
    def complies(self) -> bool:
        """Every observed point meets the band requirement (transient and vibratory)."""
        ok = all(o.complies for o in self.observations.values())
        if self.frequency_domain is not None:
            ok = ok and bool(np.all(self.frequency_domain.complies))
        return ok

    @property
    def verdict(self) -> str:
        """``complies``, ``fails`` or ``undecided`` over every point (a fail anywhere fails).

        A frequency-domain band table judges every band, so its points comply or fail.
        """
        got = [o.verdict for o in self.observations.values()]
        if self.frequency_domain is not None:
            got += [
                "complies" if c else "fails" for c in np.asarray(self.frequency_domain.complies)
            ]
        return combine_verdicts(got)

    @property
    def responses(self) -> dict[str, PointResponse]:
        """Response of each observed point."""
        return {n: o.response for n, o in self.observations.items()}

    @property
    def assessments(self) -> dict[str, Assessment]:
        """Assessment of each observed point."""
        return {n: o.assessment for n, o in self.observations.items()}

    @property
    def isolation(self) -> dict[str, IsolationAdvice]:
        """Isolation advice of each observed point."""
        return {n: o.isolation for n, o in self.observations.items()}

    def to_dict(self) -> dict[str, Any]:
        """The ``microg analyze --json`` contract (documented in docs/assessment.md)."""
        modes = self.modes.to_dict()
        for row, used in zip(modes["modes"], self.used, strict=True):
            row["used"] = bool(used)
        o = self.options
        return {
            "meta": dict(self.meta),
            "model": self.model,
            "method": self.structure.method,
            "plane": self.structure.plane,
            "modes": modes,
            "disturbances": [_disturbance_dict(d) for d in o.disturbances],
            "damping": o.zeta,
            "requirement": self.requirement.name,
            "requirement_source": self.requirement.source,
            "record": {
                "duration_s": o.duration_s,
                "dt_s": o.dt_s,
                "nyquist_hz": 0.5 / o.dt_s,
                "max_freq_hz": o.max_freq_hz,
            },
            "observations": {n: ob.to_dict() for n, ob in self.observations.items()},
            **self._frequency_dict(),
            "complies": self.complies,
            "verdict": self.verdict,
            "report_criterion": {
                "limit_g": REPORT_LIMIT_G,
                "peak_within": all(
                    ob.assessment.peak_accel_g <= REPORT_LIMIT_G
                    for ob in self.observations.values()
                ),
            }
            if self.observations
            else None,
            "warnings": list(self.warnings),
            "notes": list(self.notes),
        }

    def _frequency_dict(self) -> dict[str, Any]:
        fd = self.frequency_domain
        if fd is None:
            return {}
        return {"frequency_domain": fd.to_dict(), "frequency_domain_basis": fd.info_dict()}

    def to_xarray(self) -> Any:
        """Every observed point's acceleration history in one ``xarray.Dataset``.

        ``accel_mps2`` over (point, axis, time), m/s^2, and the verdict numbers per point
        (``peak_accel_g``, ``complies``); the model, requirement and warnings in the attributes.
        """
        import xarray as xr

        names = list(self.observations)
        obs = [self.observations[n] for n in names]
        acc = (
            np.stack([o.response.acceleration for o in obs])
            if obs
            else np.zeros((0, 3, self.timepts.size))
        )
        return xr.Dataset(
            {
                "accel_mps2": (("point", "axis", "time"), acc, {"units": "m/s^2"}),
                "peak_accel_g": (
                    "point",
                    np.array([o.assessment.peak_accel_g for o in obs], float),
                    {"units": "g"},
                ),
                "complies": (
                    "point",
                    np.array([bool(o.assessment.complies) for o in obs], bool),
                    {"units": "1"},
                ),
            },
            coords={
                "point": names,
                "axis": ["x", "y", "z"],
                "time": ("time", self.timepts, {"units": "s"}),
            },
            attrs={
                "model": self.model,
                "requirement": self.requirement.name,
                "warnings": "\n".join(self.warnings),
            },
        )

    def plot(self, ax: Any = None) -> Figure:
        """The peak at each observed point against the report's 1e-5 g (a Figure).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure).
        """
        from microg.plotting.analysis import analysis_figure

        return analysis_figure(self, ax=ax)

    def plot3d(self) -> Any:
        """The model in 3-D, force and observed points marked, a slider over the elastic modes.

        A plotly Figure (:func:`microg.plotting.interactive.modes_3d`).
        """
        from microg.plotting.interactive import modes_3d

        forces = {d.point: d.unit_direction for d in self.options.disturbances}
        if self.options.sources is not None:
            for src in self.options.sources.sources:
                forces.setdefault(src.at, src.direction)
        return modes_3d(self.modes, force_points=forces, observed=list(self.observations))

    def _repr_html_(self) -> str:
        """The verdict table in a notebook: each point's peak, smallest band margin and verdict."""
        from html import escape

        rows = []
        for name, o in self.observations.items():
            to = o.assessment.third_octave
            judged = np.asarray(to.margin)[:, np.asarray(to.judged, bool)]
            margin = float(judged.min()) if judged.size else float("nan")
            status = {
                "complies": "complies",
                "fails": "fails",
                "undecided": "undecided (the record cannot decide a criterion)",
            }[o.verdict]
            rows.append(
                f"<tr><td>{escape(name)}</td><td>{o.peak_accel_g:.3g}</td>"
                f"<td>{margin:.3g}</td><td>{status}</td></tr>"
            )
        return (
            f"<p><b>{escape(str(self.model))}</b> against {escape(self.requirement.name)}</p>"
            "<table><tr><th>point</th><th>peak (g)</th><th>smallest band margin</th>"
            f"<th>verdict</th></tr>{''.join(rows)}</table>"
        )


def _disturbance_dict(d: Disturbance) -> dict[str, Any]:
    f = d.force
    vec = f.components(d.unit_direction)  # (3, nb), N
    direction = d.unit_direction
    dt = np.diff(f.timepts)
    impulse = np.sum(0.5 * (vec[:, 1:] + vec[:, :-1]) * dt, axis=1)  # trapezoids: exact (N s)
    out: dict[str, Any] = {
        "name": f.name,
        "at": d.point,
        "direction": None if f.is_vector else [float(v) for v in direction],
        "direction_axis": "varies (three components)" if f.is_vector else axis_name(direction),
        "peak_force_N": float(np.max(np.linalg.norm(vec, axis=0))),
        "impulse_Ns": float(np.linalg.norm(impulse)),
        "impulse_Ns_axis": dict(zip("xyz", (float(v) for v in impulse), strict=True)),
        "end_s": float(f.timepts[-1]),
        "final_force_N": float(np.linalg.norm(vec[:, -1])),
    }
    if f.params:
        out["params"] = {k: float(v) for k, v in f.params.items()}
    return out
