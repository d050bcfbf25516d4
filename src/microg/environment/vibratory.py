"""The vibratory regime in the frequency domain: band RMS at observed points against a requirement.

:func:`assess_sources` is the frequency-domain analysis of ISS practice: the force spectrum of
each source at its location, the acceleration FRFs of the modal model with modal damping
(rigid modes and rotation at offset points included), band RMS by converged integration, RSS
over independent sources and coherent sums within a ``coherent_group``, compared band by band
and axis by axis with the requirement (``margin = limit / rms``; a band passes when
``rms <= limit``).  Bands and limits come from the :class:`~microg.environment.requirements.
Requirement` object, never recomputed here.

The result's :meth:`VibratoryAssessment.to_dict` is the ``frequency_domain`` block of
``microg analyze --sources FILE --json``: one entry per observed point with ``third_octave``
(``center_hz``, ``lower_hz``, ``upper_hz``, ``rms_g`` and ``margin`` of the governing axis,
``limit_g``, ``rms_g_axis``), ``complies``, ``worst_band`` and ``contributions`` (per band: the
governing axis, each source alone and each mode alone in g RMS, with their signed shares of the
band mean square; see :mod:`microg.dynamics.frequency` for how a coherent sum is attributed).

Operating state: a source with ``state = "off"`` is left out (and listed).  ``duty`` is echoed;
by default a running source is assessed at its full level (PIMS judges per-interval band RMS,
and an interval in which the source runs sees its full level); ``duty_weighted=True`` scales
each source's mean square by its duty instead (a long-term average, not a compliance check).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg import defaults
from microg._json import finite_list, finite_or_none, json_numbers
from microg._vectors import AXIS_NAMES
from microg.dynamics.frequency import BandResponse, band_response, damping_ratios
from microg.dynamics.modes import Modes
from microg.environment.requirements import Requirement, iss_requirement
from microg.environment.sources import Source, SourceCatalogue, as_sources, validate_source_points
from microg.errors import InputError
from microg.units import G0

__all__ = ["VibratoryAssessment", "assess_sources"]

#: default number of modes listed per band in ``contributions``
MAX_MODES_LISTED = 10


@dataclass(frozen=True)
class VibratoryAssessment:
    """Frequency-domain vibratory assessment of observed points.

    Attributes
    ----------
    requirement : requirement name; ``requirement_source`` its citation
    points, axes : observed points; ("x", "y", "z")
    center_hz, lower_hz, upper_hz : (nb,) the requirement's bands, Hz
    limit_g : (nb,) band-RMS limit per axis, g
    rms_g : (npt, 3, nb) band RMS acceleration, g
    margin : (npt, 3, nb) ``limit / rms`` (inf where the response is zero)
    complies : (npt,) every band and axis within its limit
    response : the band response in SI with the contributions (m/s^2)
    sources : the sources assessed (state on); ``excluded`` the names left out (state off)
    zeta : (m,) damping ratio per mode
    duty_weighted : mean squares scaled by duty
    illustrative : the catalogue says its numbers are examples
    warnings : what the numbers rest on that the user should know
    max_modes : modes listed per band in :meth:`to_dict`
    """

    requirement: str
    requirement_source: str
    points: tuple[str, ...]
    axes: tuple[str, ...]
    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray
    limit_g: np.ndarray
    rms_g: np.ndarray
    margin: np.ndarray
    complies: np.ndarray
    response: BandResponse = field(repr=False)
    sources: tuple[Source, ...] = field(repr=False)
    excluded: tuple[str, ...] = ()
    zeta: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    duty_weighted: bool = False
    illustrative: bool = False
    warnings: tuple[str, ...] = ()
    max_modes: int = MAX_MODES_LISTED

    # ------------------------------------------------------------------ per point
    def _index(self, point: str | None) -> int:
        if point is None:
            return 0
        if point not in self.points:
            raise InputError(
                f"{point!r} is not an observed point", fix=f"use one of {', '.join(self.points)}"
            )
        return self.points.index(point)

    def governing_axis(self, point: str | None = None) -> np.ndarray:
        """(nb,) index of the axis with the largest band RMS at ``point``."""
        return np.argmax(self.rms_g[self._index(point)], axis=0)

    def point_dict(self, point: str) -> dict[str, Any]:
        """The JSON entry of one observed point (see the module docstring)."""
        i = self._index(point)
        rms, mar = self.rms_g[i], self.margin[i]
        gov = np.argmax(rms, axis=0)
        nb = self.center_hz.size
        worst_rms = rms[gov, np.arange(nb)]
        worst_margin = np.min(mar, axis=0)
        k = int(np.argmin(worst_margin)) if nb else 0
        worst = None
        if nb and np.isfinite(worst_margin[k]):
            worst = {
                "center_hz": float(self.center_hz[k]),
                "axis": self.axes[int(gov[k])],
                "rms_g": float(worst_rms[k]),
                "limit_g": float(self.limit_g[k]),
                "margin": float(worst_margin[k]),
            }
        return {
            "third_octave": {
                "center_hz": finite_list(self.center_hz),
                "lower_hz": finite_list(self.lower_hz),
                "upper_hz": finite_list(self.upper_hz),
                "rms_g": finite_list(worst_rms),
                "limit_g": finite_list(self.limit_g),
                "margin": json_numbers(worst_margin),  # "inf": a band without power
                "rms_g_axis": {a: finite_list(rms[j]) for j, a in enumerate(self.axes)},
                "axis": [self.axes[int(j)] for j in gov],
            },
            "complies": bool(self.complies[i]),
            "worst_band": worst,
            "contributions": self._contributions(i, gov),
        }

    def _contributions(self, i: int, gov: np.ndarray) -> dict[str, Any]:
        r = self.response
        bands = []
        for b in range(self.center_hz.size):
            a = int(gov[b])
            total = float(r.rms_mps2[i, a, b]) / G0
            if total <= 0:
                continue
            s_rms = r.source_rms_mps2[i, a, b] / G0
            s_share = r.source_share[i, a, b]
            order = np.argsort(-s_share)
            srcs = [
                {"name": r.sources[j], "rms_g": float(s_rms[j]), "share": float(s_share[j])}
                for j in order
                if s_rms[j] > 0
            ]
            m_rms = r.mode_rms_mps2[i, a, b] / G0
            m_share = r.mode_share[i, a, b]
            top = np.argsort(-np.abs(m_share))[: self.max_modes]
            modes = [
                {
                    "mode": int(j) + 1,  # numbered as in the modes table (1-based)
                    "freq_hz": float(r.mode_freq_hz[j]),
                    "rms_g": float(m_rms[j]),
                    "share": float(m_share[j]),
                }
                for j in top
                if m_rms[j] > 0
            ]
            rest = float(np.sum(m_share) - np.sum(m_share[top]))
            bands.append(
                {
                    "center_hz": float(self.center_hz[b]),
                    "axis": self.axes[a],
                    "rms_g": total,
                    "sources": srcs,
                    "modes": modes,
                    "other_modes_share": rest,
                }
            )
        return {
            "unit": "g RMS",
            "definition": (
                "rms_g: the source (or mode) acting alone; share: its signed part of the band "
                "mean square (sums to 1; a coherent group's members and the modes are "
                "attributed by projection on the complex total)"
            ),
            "bands": bands,
        }

    def to_dict(self) -> dict[str, Any]:
        """``{point: {...}}``: the ``frequency_domain`` block of ``microg analyze --json``."""
        return {p: self.point_dict(p) for p in self.points}

    def info_dict(self) -> dict[str, Any]:
        """What the assessment rests on: requirement, damping, sources, diagnostics, warnings."""
        r = self.response
        el = self.zeta[self.zeta > 0]
        return {
            "requirement": self.requirement,
            "requirement_source": self.requirement_source,
            "zeta": float(el[0]) if el.size and np.all(el == el[0]) else finite_list(self.zeta),
            "duty_weighted": self.duty_weighted,
            "illustrative_sources": self.illustrative,
            "sources": [s.to_dict() for s in self.sources],
            "excluded_sources": list(self.excluded),
            "modes": {
                "count": int(r.mode_freq_hz.size),
                "highest_hz": finite_or_none(float(np.max(r.mode_freq_hz, initial=0.0))),
            },
            "band_integration": {
                "method": "composite Gauss-Legendre, graded at every natural frequency, "
                "convergence-checked",
                "nodes": r.quad_nodes,
                "max_error": float(np.max(r.quad_error, initial=0.0)),
                "refinements": r.refinements,
            },
            "warnings": list(self.warnings),
        }

    def to_xarray(self) -> Any:
        """xarray.Dataset (point, axis, band, source, group, mode), accelerations in g."""
        ds = self.response.to_xarray()
        out = ds.assign(
            rms_g=(("point", "axis", "band"), self.rms_g, {"units": "g"}),
            limit_g=(("band",), self.limit_g, {"units": "g"}),
            margin=(("point", "axis", "band"), self.margin, {"units": "1"}),
            complies=(("point",), self.complies),
            source_rms_g=(
                ("point", "axis", "band", "source"),
                self.response.source_rms_mps2 / G0,
                {"units": "g"},
            ),
            mode_rms_g=(
                ("point", "axis", "band", "mode"),
                self.response.mode_rms_mps2 / G0,
                {"units": "g"},
            ),
        )
        out.attrs.update(
            {
                "requirement": self.requirement,
                "requirement_source": self.requirement_source,
                "warnings": "; ".join(self.warnings),
            }
        )
        return out

    def plot(self, point: str | None = None, kind: str = "bands", ax: Any = None) -> Any:
        """Figure: ``bands`` or ``contributions``.

        ``bands``: band RMS per axis against the limit; ``contributions``: each source's
        share of the governing axis per band.

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.frequency import plot_contributions, plot_vibratory

        if kind == "bands":
            return plot_vibratory(self, point=point, ax=ax)
        if kind == "contributions":
            return plot_contributions(self, point=point, ax=ax)
        raise InputError(f"unknown plot {kind!r}", where="kind", fix="use bands or contributions")


def assess_sources(
    modes: Modes,
    sources: SourceCatalogue | Sequence[Source],
    observe: Sequence[str],
    requirement: Requirement | None = None,
    zeta: float | np.ndarray = defaults.DAMPING,
    *,
    duty_weighted: bool = False,
    max_modes: int = MAX_MODES_LISTED,
    workers: int | None = None,
    weight: Any = None,
    weight_breakpoints_hz: Sequence[float] | np.ndarray = (),
) -> VibratoryAssessment:
    """Frequency-domain vibratory assessment of ``observe`` under the catalogue's sources.

    Parameters
    ----------
    modes : Modes of the station (mass-normalised; rigid modes included).  Keep modes to at
        least 1.5 times the highest band edge (a warning says so otherwise).
    sources : a :class:`SourceCatalogue` (from :func:`~microg.environment.sources.load_sources`)
        or a sequence of :class:`Source`
    observe : observed point names
    requirement : band limits (default :func:`~microg.environment.requirements.iss_requirement`)
    zeta : modal damping ratio of the elastic modes, scalar or one per mode (0 < zeta < 1)
    duty_weighted : scale each source's mean square by its ``duty`` (default: full level)
    max_modes : modes listed per band in the contributions of :meth:`VibratoryAssessment.to_dict`
    workers : threads over bands (default the CPU count)
    weight, weight_breakpoints_hz : a real weight per output row (x, y, z of each observed
        point) on the band integrand, and its breakpoints, Hz
        (:func:`~microg.dynamics.bands.band_mean_squares`): ``|T_axis(f)|^2`` of an isolator
        assesses its platform instead of the point

    Returns
    -------
    VibratoryAssessment
    """
    req = requirement or iss_requirement()
    srcs = as_sources(sources)
    cat = sources if isinstance(sources, SourceCatalogue) else None
    obs = [observe] if isinstance(observe, str) else list(observe)
    if not obs:
        raise InputError("no observed point", where="observe", fix="name at least one point")
    validate_source_points(srcs, modes.structure.points)
    z = damping_ratios(modes, zeta)
    on = tuple(s for s in srcs if s.state == "on")
    excluded = tuple(s.name for s in srcs if s.state != "on")
    warnings: list[str] = []
    if cat is not None and cat.illustrative:
        warnings.append(
            f"source catalogue {cat.file} declares its values ILLUSTRATIVE (not measured or "
            "specified data): the verdict only shows what such sources would do"
        )
    if excluded:
        warnings.append(f"sources switched off and left out: {', '.join(excluded)}")
    no_cite = [s.name for s in on if not s.source]
    if no_cite:
        warnings.append(f"sources without a stated origin of their numbers: {', '.join(no_cite)}")
    if duty_weighted:
        warnings.append(
            "mean squares scaled by duty: a long-term average, not an interval compliance check"
        )
    loads = [
        s.load(req.bands, mean_square_scale=(s.duty or 1.0) if duty_weighted else 1.0) for s in on
    ]
    bands = req.bands
    if not loads:
        raise InputError(
            "no source is on", where="sources", fix='set state = "on" for at least one source'
        )
    resp = band_response(
        modes,
        z,
        obs,
        loads,
        bands.lower_hz,
        bands.upper_hz,
        center_hz=bands.center_hz,
        workers=workers,
        weight=weight,
        weight_breakpoints_hz=weight_breakpoints_hz,
    )
    warnings += list(resp.warnings)
    out_of_band = _outside_bands(on, req)
    warnings += out_of_band
    rms_g = resp.rms_mps2 / G0
    limit = np.asarray(req.limit_g, float)
    with np.errstate(divide="ignore"):
        margin = np.where(rms_g > 0, limit / np.where(rms_g > 0, rms_g, 1.0), np.inf)
    complies = np.all(rms_g <= limit, axis=(1, 2))
    return VibratoryAssessment(
        requirement=req.name,
        requirement_source=req.source,
        points=tuple(obs),
        axes=AXIS_NAMES,
        center_hz=np.asarray(bands.center_hz, float),
        lower_hz=np.asarray(bands.lower_hz, float),
        upper_hz=np.asarray(bands.upper_hz, float),
        limit_g=limit,
        rms_g=rms_g,
        margin=margin,
        complies=complies,
        response=resp,
        sources=on,
        excluded=excluded,
        zeta=z,
        duty_weighted=duty_weighted,
        illustrative=bool(cat is not None and cat.illustrative),
        warnings=tuple(warnings),
        max_modes=max_modes,
    )


def _outside_bands(sources: Sequence[Source], req: Requirement) -> list[str]:
    """Warnings for sources with force power outside the requirement's bands (not assessed)."""
    lo, hi = req.bands.lower_hz, req.bands.upper_hz
    out = []
    for s in sources:
        spec = s.force_spectrum(req.bands)
        total = float(spec.power_n2(np.array([1e-300]), np.array([np.inf]))[0])
        inside = float(np.sum(spec.power_n2(lo, hi)))
        if total > 0 and inside < total * (1 - 1e-6):
            out.append(
                f"source {s.name!r}: {100 * (1 - inside / total):.3g} % of its force mean "
                "square lies outside the requirement's bands (not assessed)"
            )
    return out
