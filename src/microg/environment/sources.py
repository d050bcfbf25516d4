"""Catalogue of vibratory disturbance sources: TOML reader, units, validation, Source objects.

File format (the contract; other tools read it)::

    [catalogue]                      # optional
    name = "example"
    description = "..."
    illustrative = true              # the numbers are examples, not data (echoed as a warning)

    [[source]]
    name = "cabin fan"               # unique
    at = "lab"                       # a named point of the model
    direction = "x"                  # "x", "-z", "1 0 0" or [1, 0, 0]
    harmonic = { amplitude = "2 N", frequency = "0.5 Hz", phase = "30 deg" }
    # or a list of lines: harmonic = [{ amplitude = ..., frequency = ... }, ...]
    # or bands = { center_hz = [...], rms = [...], unit = "N" }
    # or psd = { frequency_hz = [...], value = [...], unit = "N^2/Hz" }
    coherent_group = "fan"           # optional: sources of one group are one machine
    duty = 0.5                       # optional: fraction of the time it runs, 0 < duty <= 1
    state = "on"                     # optional: "on" (default) or "off" (left out)
    source = "where the numbers come from"
    description = "..."              # optional

Meaning of the spectra (see :mod:`microg.dynamics.frequency` for the conventions):

* ``harmonic``: ``amplitude`` is the **peak** force of ``A cos(2 pi f t + phase)``; ``phase``
  (optional, default 0) matters only between lines of one coherent group at one frequency.
* ``bands``: the force RMS in each 1/3-octave band, flat (constant PSD) inside the band.  Each
  centre must be a 1/3-octave centre (base-10 ``10^(n/10)`` with the IEC nominal values such as
  0.125 or 0.315, or base-2 ``2^(k/3)``), within 6 % of a band step.  When the analysis runs,
  a centre that matches a band of the requirement's table (within that tolerance) takes that
  band's edges; any other centre takes the exact edges of its own series.
* ``psd``: a one-sided force PSD table, interpolated log-log (power law between points), zero
  outside its range.

Limits: at most :data:`MAX_SOURCES` sources, :data:`MAX_POINTS` values per spectrum,
frequencies in (0, :data:`MAX_FREQ_HZ`] Hz.  Every error is one line naming the file, the
source and the field, with the fix (:class:`~microg.errors.InputError`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from microg._io import loads_toml
from microg._vectors import DIRECTION_FIX, parse_direction
from microg.dynamics.frequency import (
    BandForceSpectrum,
    ForcePSD,
    ForceSpectrum,
    HarmonicLines,
    Load,
)
from microg.environment.requirements import BandTable
from microg.errors import InputError
from microg.units import parse_quantity, parse_unit

__all__ = [
    "MAX_SOURCES",
    "MAX_POINTS",
    "MAX_FREQ_HZ",
    "CENTER_TOL",
    "BandLevels",
    "Source",
    "SourceCatalogue",
    "load_sources",
    "loads_sources",
    "example_sources",
    "validate_source_points",
    "third_octave_edges",
    "as_sources",
]

#: largest number of sources in one catalogue
MAX_SOURCES = 10_000
#: largest number of lines, bands or PSD points of one source
MAX_POINTS = 10_000
#: highest frequency accepted in a catalogue, Hz
MAX_FREQ_HZ = 1.0e5
#: tolerance on a 1/3-octave centre, in band steps (6 % of a step is about 1.4 % in frequency)
CENTER_TOL = 0.06

_SOURCE_KEYS = {
    "name",
    "at",
    "direction",
    "harmonic",
    "bands",
    "psd",
    "coherent_group",
    "duty",
    "state",
    "source",
    "description",
}
_SPECTRUM_KEYS = ("harmonic", "bands", "psd")
_STATES = ("on", "off")
_EXAMPLE = "example_sources.toml"
#: a force-PSD unit: force unit, power 2, "/", frequency unit (``N^2/Hz``, ``(lbf)**2 / Hz``)
_PSD_UNIT = re.compile(r"^\s*\(?\s*([^()^*/\s]+)\s*\)?\s*(?:\^|\*\*)\s*2\s*/\s*([^()^*/\s]+)\s*$")


# ---------------------------------------------------------------------------- band centres


#: IEC 61260-1 nominal (preferred-number) mantissas of the base-10 1/3-octave centres
_NOMINAL = np.array([1.0, 1.25, 1.6, 2.0, 2.5, 3.15, 4.0, 5.0, 6.3, 8.0])


def _dev10(center_hz: np.ndarray) -> np.ndarray:
    """Distance, in band steps, to the nearest base-10 centre, exact 10^(n/10) or nominal."""
    x10 = 10.0 * np.log10(center_hz)
    n = np.round(x10)
    nominal = _NOMINAL[(n % 10).astype(int)] * 10.0 ** np.floor(n / 10)
    return np.minimum(np.abs(x10 - n), np.abs(10.0 * np.log10(center_hz / nominal)))


def _series_index(center_hz: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nearest base-10 and base-2 band indices and the smaller deviation (in band steps)."""
    x10 = 10.0 * np.log10(center_hz)
    x2 = 3.0 * np.log2(center_hz)
    n10, n2 = np.round(x10), np.round(x2)
    d10, d2 = _dev10(center_hz), np.abs(x2 - n2)
    base2 = d2 < d10
    return np.where(base2, n2, n10), base2, np.minimum(d10, d2)


def third_octave_edges(
    center_hz: np.ndarray, table: BandTable | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Edges of 1/3-octave bands given by their centres, Hz.

    * A centre within :data:`CENTER_TOL` band steps of a centre of ``table`` takes that band's
      edges (a spectrum given on the requirement's bands is integrated band for band).
    * Otherwise the exact edges of its series (IEC 61260-1): base 10 ``10^((n -+ 1/2)/10)``,
      base 2 ``2^((k -+ 1/2)/3)``; one series for the whole spectrum when all its centres fit
      it (the one that fits closer; base 10, measured from its exact or nominal centres, on a
      tie), else each centre's nearer series.
    * Adjacent bands from different series that overlap (by at most a few per cent) meet at
      the geometric mean of the two edges.

    Parameters
    ----------
    center_hz : (nb,) band centres, Hz, increasing
    table : optional band table (e.g. the requirement's)
    """
    c = np.asarray(center_hz, float)
    x10, x2 = 10.0 * np.log10(c), 3.0 * np.log2(c)
    d10, d2 = _dev10(c), np.abs(x2 - np.round(x2))
    fit10, fit2 = bool(np.all(d10 <= CENTER_TOL)), bool(np.all(d2 <= CENTER_TOL))
    if fit10 and (not fit2 or d10.max() <= d2.max()):
        base2 = np.zeros(c.size, bool)
    elif fit2:
        base2 = np.ones(c.size, bool)
    else:
        base2 = d2 < d10
    idx = np.where(base2, np.round(x2), np.round(x10))
    lo = np.where(base2, 2.0 ** ((idx - 0.5) / 3.0), 10.0 ** ((idx - 0.5) / 10.0))
    hi = np.where(base2, 2.0 ** ((idx + 0.5) / 3.0), 10.0 ** ((idx + 0.5) / 10.0))
    if table is not None and table.center_hz.size:
        step = math.log(2.0) / 3.0
        dist = np.abs(np.log(c[:, None] / table.center_hz[None, :])) / step
        j = np.argmin(dist, axis=1)
        hit = dist[np.arange(c.size), j] <= CENTER_TOL
        lo = np.where(hit, table.lower_hz[j], lo)
        hi = np.where(hit, table.upper_hz[j], hi)
    over = np.flatnonzero(hi[:-1] > lo[1:])
    if over.size:
        meet = np.sqrt(hi[over] * lo[over + 1])
        hi[over] = meet
        lo[over + 1] = meet
    return lo, hi


@dataclass(frozen=True, eq=False)
class BandLevels:
    """Force RMS per 1/3-octave band, the bands given by their centres.

    Attributes
    ----------
    center_hz : (nb,) 1/3-octave centres, Hz, increasing
    rms_n : (nb,) RMS force in each band, N (>= 0)
    """

    center_hz: np.ndarray
    rms_n: np.ndarray

    kind = "bands"

    def __post_init__(self) -> None:
        c = np.atleast_1d(np.asarray(self.center_hz, float))
        r = np.atleast_1d(np.asarray(self.rms_n, float))
        if c.ndim != 1 or c.shape != r.shape or c.size < 1:
            raise InputError("need one RMS value per band centre", where="bands")
        object.__setattr__(self, "center_hz", c)
        object.__setattr__(self, "rms_n", r)

    def resolve(self, table: BandTable | None = None) -> BandForceSpectrum:
        """The flat-in-band spectrum with edges from ``table`` or the series."""
        lo, hi = third_octave_edges(self.center_hz, table)
        return BandForceSpectrum(lo, hi, self.rms_n, center_hz=self.center_hz)


SourceSpectrum = HarmonicLines | BandLevels | ForcePSD


@dataclass(frozen=True, eq=False)
class Source:
    """One disturbance source of a catalogue.

    Attributes
    ----------
    name : unique name
    at : name of the model point where it acts
    direction : (3,) unit direction of the force, station frame
    spectrum : :class:`~microg.dynamics.frequency.HarmonicLines`, :class:`BandLevels` or
        :class:`~microg.dynamics.frequency.ForcePSD` (N, Hz)
    coherent_group : sources of one group add coherently (one machine); None: independent
    duty : fraction of the time it runs (0, 1], or None when not given
    state : "on" or "off" (an off source is left out of the assessment)
    source : where the numbers come from
    description : free text
    origin : where it was read (``FILE: source[i]``), for messages
    """

    name: str
    at: str
    direction: np.ndarray
    spectrum: SourceSpectrum
    coherent_group: str | None = None
    duty: float | None = None
    state: str = "on"
    source: str | None = None
    description: str | None = None
    origin: str = "source"

    def __post_init__(self) -> None:
        d = parse_direction(self.direction, where=f"{self.origin}.direction")
        object.__setattr__(self, "direction", d)
        if self.state not in _STATES:
            raise InputError(
                f"unknown state {self.state!r}", where=f"{self.origin}.state", fix="use on or off"
            )
        if self.duty is not None and not (0.0 < self.duty <= 1.0):
            raise InputError(
                f"duty {self.duty!r} is not in (0, 1]",
                where=f"{self.origin}.duty",
                fix="give the fraction of the time the source runs, e.g. 0.5",
            )

    @property
    def kind(self) -> str:
        """``harmonic``, ``bands`` or ``psd``."""
        return str(self.spectrum.kind)

    def force_spectrum(self, table: BandTable | None = None) -> ForceSpectrum:
        """The kernel spectrum (band edges resolved against ``table``, see the module doc)."""
        if isinstance(self.spectrum, BandLevels):
            try:
                return self.spectrum.resolve(table)
            except InputError as exc:
                raise InputError(
                    exc.what,
                    where=f"{self.origin}.bands.center_hz",
                    fix="list each 1/3-octave band once, in increasing order",
                ) from None
        return self.spectrum

    def load(self, table: BandTable | None = None, *, mean_square_scale: float = 1.0) -> Load:
        """A :class:`~microg.dynamics.frequency.Load` for the kernel.

        ``mean_square_scale`` multiplies the force mean square (e.g. the duty).
        """
        spec = self.force_spectrum(table)
        if mean_square_scale != 1.0:
            spec = _scaled(spec, mean_square_scale)
        return Load(self.name, self.at, self.direction, spec, group=self.coherent_group)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready echo of the source (SI: N, Hz, N^2/Hz)."""
        sp = self.spectrum
        spec: dict[str, Any]
        if isinstance(sp, HarmonicLines):
            spec = {
                "amplitude_n": [float(v) for v in sp.amplitude_n],
                "freq_hz": [float(v) for v in sp.freq_hz],
                "phase_rad": [float(v) for v in np.asarray(sp.phase_rad)],
            }
        elif isinstance(sp, BandLevels):
            spec = {
                "center_hz": [float(v) for v in sp.center_hz],
                "rms_n": [float(v) for v in sp.rms_n],
            }
        else:
            spec = {
                "frequency_hz": [float(v) for v in sp.freq_hz],
                "value_n2_per_hz": [float(v) for v in sp.value_n2_per_hz],
                "interpolation": "log-log",
            }
        return {
            "name": self.name,
            "at": self.at,
            "direction": [float(v) for v in self.direction],
            "kind": self.kind,
            self.kind: spec,
            "coherent_group": self.coherent_group,
            "duty": self.duty,
            "state": self.state,
            "source": self.source,
        }


def _scaled(spec: ForceSpectrum, ms: float) -> ForceSpectrum:
    a = math.sqrt(ms)
    if isinstance(spec, HarmonicLines):
        return HarmonicLines(spec.amplitude_n * a, spec.freq_hz, spec.phase_rad)
    if isinstance(spec, BandForceSpectrum):
        return BandForceSpectrum(spec.lower_hz, spec.upper_hz, spec.rms_n * a, spec.center_hz)
    return ForcePSD(spec.freq_hz, spec.value_n2_per_hz * ms)


@dataclass(frozen=True)
class SourceCatalogue:
    """The sources of one catalogue file.

    Attributes
    ----------
    sources : the sources, in file order
    file : the file they came from (for messages)
    name, description : from the optional ``[catalogue]`` table
    illustrative : the file declares its numbers are examples, not data
    """

    sources: tuple[Source, ...]
    file: str = "<sources>"
    name: str | None = None
    description: str | None = None
    illustrative: bool = False
    notes: tuple[str, ...] = field(default=())

    def __len__(self) -> int:
        return len(self.sources)

    def __iter__(self) -> Any:
        return iter(self.sources)

    @property
    def names(self) -> tuple[str, ...]:
        """Source names, in file order."""
        return tuple(s.name for s in self.sources)

    def validate_points(self, point_names: Iterable[str]) -> None:
        """Raise :class:`InputError` (naming file and source) for a source at an unknown point."""
        validate_source_points(self.sources, point_names)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready echo of the catalogue."""
        return {
            "file": self.file,
            "name": self.name,
            "illustrative": self.illustrative,
            "sources": [s.to_dict() for s in self.sources],
        }


def validate_source_points(sources: Iterable[Source], point_names: Iterable[str]) -> None:
    """Check that every source acts at a known point; one-line error naming file and source.

    Parameters
    ----------
    sources : the sources (each knows where it was read)
    point_names : the model's point names
    """
    known = set(point_names)
    for s in sources:
        if s.at not in known:
            listed = ", ".join(sorted(known)) or "(none)"
            raise InputError(
                f"source {s.name!r} is at unknown point {s.at!r}",
                where=f"{s.origin}.at",
                fix=f"use a point of the model: {listed}",
            )


# ----------------------------------------------------------------------------- reading


class _Reader:
    def __init__(self, file: str):
        self.file = file

    def err(self, path: str, what: str, fix: str | None = None) -> InputError:
        return InputError(what, where=f"{self.file}: {path}" if path else self.file, fix=fix)

    def text(self, value: Any, path: str, *, required: bool = True) -> str | None:
        if value is None:
            if required:
                raise self.err(path, "is missing", "give a non-empty string")
            return None
        if not isinstance(value, str) or not value.strip():
            raise self.err(path, f"expected a non-empty string, got {value!r}")
        return value.strip()

    def quantity(self, value: Any, dimension: str, path: str, example: str) -> float:
        if isinstance(value, bool) or not isinstance(value, str | int | float):
            raise self.err(path, f"expected a quantity such as {example!r}, got {value!r}")
        if not isinstance(value, str):
            raise self.err(path, f"bare number {value!r} has no unit", f"write e.g. {example!r}")
        return parse_quantity(value, dimension, where=f"{self.file}: {path}")

    def numbers(self, value: Any, path: str) -> np.ndarray:
        if not isinstance(value, list) or not value:
            raise self.err(path, "expected a non-empty list of numbers")
        if len(value) > MAX_POINTS:
            raise self.err(path, f"{len(value):,} values is more than {MAX_POINTS:,}")
        out = np.empty(len(value))
        for i, v in enumerate(value):
            if isinstance(v, bool) or not isinstance(v, int | float):
                raise self.err(f"{path}[{i}]", f"expected a number, got {v!r}")
            if not math.isfinite(v):
                raise self.err(f"{path}[{i}]", f"{v!r} is not a finite number", "give a number")
            out[i] = float(v)
        return out

    def force_unit(self, unit: Any, path: str) -> float:
        """SI factor of a force unit (``N``, ``lbf``, ``kN``)."""
        if not isinstance(unit, str) or not unit.strip():
            raise self.err(path, "is missing", 'give the unit of the values, e.g. unit = "N"')
        try:
            return parse_unit(unit.strip(), "force", where=f"{self.file}: {path}")
        except InputError as exc:
            raise self.err(
                path, f"{unit!r} is not a unit of force: {exc.what}", 'use e.g. "N" or "lbf"'
            ) from None

    def psd_unit(self, unit: Any, path: str) -> float:
        """SI factor (to N^2/Hz) of a force-PSD unit ``F^2/f``: ``N^2/Hz``, ``lbf^2/Hz``."""
        fix = 'write a force squared per frequency, e.g. "N^2/Hz" or "lbf^2/Hz"'
        if not isinstance(unit, str) or not unit.strip():
            raise self.err(path, "is missing", f"give the unit of the values: {fix}")
        m = _PSD_UNIT.match(unit)
        if not m:
            raise self.err(path, f"{unit!r} is not a unit of force^2/frequency", fix)
        where = f"{self.file}: {path}"
        try:
            force = parse_unit(m.group(1), "force", where=where)
            freq = parse_unit(m.group(2), "frequency", where=where)
        except InputError as exc:
            raise self.err(path, f"{unit!r}: {exc.what}", fix) from None
        return force * force / freq

    def frequencies(self, f: np.ndarray, path: str) -> None:
        bad = np.flatnonzero(~((f > 0) & (f <= MAX_FREQ_HZ)))
        if bad.size:
            i = int(bad[0])
            raise self.err(
                f"{path}[{i}]",
                f"frequency {f[i]!r} Hz is not in (0, {MAX_FREQ_HZ:g}] Hz",
                "give a positive frequency in Hz",
            )

    def nonnegative(self, v: np.ndarray, path: str) -> None:
        bad = np.flatnonzero(v < 0)
        if bad.size:
            i = int(bad[0])
            raise self.err(f"{path}[{i}]", f"{v[i]!r} is negative", "spectrum values are >= 0")

    # ------------------------------------------------------------------ spectra
    def harmonic(self, raw: Any, path: str) -> HarmonicLines:
        lines = raw if isinstance(raw, list) else [raw]
        if not lines:
            raise self.err(path, "has no lines", "give { amplitude = '2 N', frequency = '1 Hz' }")
        if len(lines) > MAX_POINTS:
            raise self.err(path, f"{len(lines):,} lines is more than {MAX_POINTS:,}")
        amp, freq, phase = [], [], []
        for k, line in enumerate(lines):
            p = f"{path}[{k}]" if isinstance(raw, list) else path
            if not isinstance(line, dict):
                raise self.err(p, "expected a table { amplitude = ..., frequency = ... }")
            extra = set(line) - {"amplitude", "frequency", "phase"}
            if extra:
                raise self.err(
                    f"{p}.{sorted(extra)[0]}", "unknown field", "use amplitude, frequency, phase"
                )
            for key in ("amplitude", "frequency"):
                if key not in line:
                    raise self.err(
                        f"{p}.{key}",
                        "is missing",
                        f"give {key}, e.g. " + ("'2 N'" if key == "amplitude" else "'0.5 Hz'"),
                    )
            a = self.quantity(line["amplitude"], "force", f"{p}.amplitude", "2 N")
            f = self.quantity(line["frequency"], "frequency", f"{p}.frequency", "0.5 Hz")
            if a < 0:
                raise self.err(
                    f"{p}.amplitude",
                    f"{line['amplitude']!r} is negative",
                    "give the peak amplitude, >= 0",
                )
            if not 0 < f <= MAX_FREQ_HZ:
                raise self.err(
                    f"{p}.frequency",
                    f"{line['frequency']!r} is not in (0, {MAX_FREQ_HZ:g}] Hz",
                    "give a positive frequency",
                )
            ph = 0.0
            if "phase" in line:
                raw_ph = line["phase"]
                if not (isinstance(raw_ph, str) and any(ch.isalpha() for ch in raw_ph)):
                    raise self.err(
                        f"{p}.phase", f"phase {raw_ph!r} has no unit", "write e.g. '30 deg'"
                    )
                ph = self.quantity(raw_ph, "dimensionless", f"{p}.phase", "30 deg")
            amp.append(a)
            freq.append(f)
            phase.append(ph)
        return HarmonicLines(np.array(amp), np.array(freq), np.array(phase))

    def bands(self, raw: Any, path: str) -> BandLevels:
        if not isinstance(raw, dict):
            raise self.err(path, "expected a table { center_hz = [...], rms = [...], unit = 'N' }")
        extra = set(raw) - {"center_hz", "rms", "unit"}
        if extra:
            raise self.err(
                f"{path}.{sorted(extra)[0]}", "unknown field", "use center_hz, rms, unit"
            )
        for key in ("center_hz", "rms"):
            if key not in raw:
                raise self.err(f"{path}.{key}", "is missing", "give a list of numbers")
        c = self.numbers(raw["center_hz"], f"{path}.center_hz")
        r = self.numbers(raw["rms"], f"{path}.rms")
        scale = self.force_unit(raw.get("unit"), f"{path}.unit")
        if c.size != r.size:
            raise self.err(
                f"{path}.rms",
                f"{r.size} values for {c.size} band centres",
                "give one RMS value per centre",
            )
        self.frequencies(c, f"{path}.center_hz")
        self.nonnegative(r, f"{path}.rms")
        _, _, dev = _series_index(c)
        bad = np.flatnonzero(dev > CENTER_TOL)
        if bad.size:
            i = int(bad[0])
            raise self.err(
                f"{path}.center_hz[{i}]",
                f"{c[i]:g} Hz is not a 1/3-octave band centre",
                "use 1/3-octave centres such as 0.1, 0.125, 0.16, 0.2, 0.25, 0.315, 0.4, 0.5, "
                "0.63, 0.8, 1 Hz (or the base-2 centres 2^(k/3) Hz)",
            )
        if np.any(np.diff(c) <= 0):
            i = int(np.flatnonzero(np.diff(c) <= 0)[0]) + 1
            raise self.err(
                f"{path}.center_hz[{i}]",
                "band centres must increase",
                "list each band once, in order",
            )
        close = np.flatnonzero(3.0 * np.log2(c[1:] / c[:-1]) < 0.5)
        if close.size:
            i = int(close[0]) + 1
            raise self.err(
                f"{path}.center_hz[{i}]",
                f"{c[i]:g} Hz and {c[i - 1]:g} Hz are centres of one 1/3-octave band",
                "list each 1/3-octave band once",
            )
        return BandLevels(c, r * scale)

    def psd(self, raw: Any, path: str) -> ForcePSD:
        if not isinstance(raw, dict):
            raise self.err(
                path, "expected a table { frequency_hz = [...], value = [...], unit = 'N^2/Hz' }"
            )
        extra = set(raw) - {"frequency_hz", "value", "unit"}
        if extra:
            raise self.err(
                f"{path}.{sorted(extra)[0]}", "unknown field", "use frequency_hz, value, unit"
            )
        for key in ("frequency_hz", "value"):
            if key not in raw:
                raise self.err(f"{path}.{key}", "is missing", "give a list of numbers")
        f = self.numbers(raw["frequency_hz"], f"{path}.frequency_hz")
        v = self.numbers(raw["value"], f"{path}.value")
        scale = self.psd_unit(raw.get("unit"), f"{path}.unit")
        if f.size != v.size:
            raise self.err(
                f"{path}.value",
                f"{v.size} values for {f.size} frequencies",
                "give one value per frequency",
            )
        if f.size < 2:
            raise self.err(f"{path}.frequency_hz", "needs at least 2 points")
        self.frequencies(f, f"{path}.frequency_hz")
        if np.any(np.diff(f) <= 0):
            i = int(np.flatnonzero(np.diff(f) <= 0)[0]) + 1
            raise self.err(
                f"{path}.frequency_hz[{i}]",
                "frequencies must increase strictly",
                "sort the table and remove repeated frequencies",
            )
        self.nonnegative(v, f"{path}.value")
        return ForcePSD(f, v * scale)

    # ------------------------------------------------------------------ one source
    def source(self, raw: Any, i: int) -> Source:
        path = f"source[{i}]"
        if not isinstance(raw, dict):
            raise self.err(path, "expected a [[source]] table")
        extra = set(raw) - _SOURCE_KEYS
        if extra:
            key = sorted(extra)[0]
            raise self.err(
                f"{path}.{key}", "unknown field", "fields: " + ", ".join(sorted(_SOURCE_KEYS))
            )
        name = self.text(raw.get("name"), f"{path}.name")
        at = self.text(raw.get("at"), f"{path}.at")
        if "direction" not in raw:
            raise self.err(f"{path}.direction", "is missing", DIRECTION_FIX)
        direction = parse_direction(raw["direction"], where=f"{self.file}: {path}.direction")
        given = [k for k in _SPECTRUM_KEYS if k in raw]
        if len(given) != 1:
            what = "has no spectrum" if not given else f"has {' and '.join(given)}"
            raise self.err(path, what, "give exactly one of harmonic, bands or psd")
        kind = given[0]
        spectrum: SourceSpectrum
        if kind == "harmonic":
            spectrum = self.harmonic(raw["harmonic"], f"{path}.harmonic")
        elif kind == "bands":
            spectrum = self.bands(raw["bands"], f"{path}.bands")
        else:
            spectrum = self.psd(raw["psd"], f"{path}.psd")
        group = self.text(raw.get("coherent_group"), f"{path}.coherent_group", required=False)
        duty = raw.get("duty")
        if duty is not None:
            if isinstance(duty, bool) or not isinstance(duty, int | float):
                raise self.err(f"{path}.duty", f"expected a number in (0, 1], got {duty!r}")
            if not 0 < duty <= 1:
                raise self.err(
                    f"{path}.duty", f"{duty!r} is not in (0, 1]", "give the fraction of time on"
                )
            duty = float(duty)
        state = raw.get("state", "on")
        if state not in _STATES:
            raise self.err(f"{path}.state", f"unknown state {state!r}", "use on or off")
        return Source(
            name=str(name),
            at=str(at),
            direction=direction,
            spectrum=spectrum,
            coherent_group=group,
            duty=duty,
            state=state,
            source=self.text(raw.get("source"), f"{path}.source", required=False),
            description=self.text(raw.get("description"), f"{path}.description", required=False),
            origin=f"{self.file}: {path}",
        )

    def catalogue(self, data: Mapping[str, Any]) -> SourceCatalogue:
        extra = set(data) - {"catalogue", "source"}
        if extra:
            raise self.err(
                sorted(extra)[0], "unknown table", "a catalogue has [catalogue] and [[source]]"
            )
        head = data.get("catalogue", {})
        if not isinstance(head, dict):
            raise self.err("catalogue", "expected a table")
        extra = set(head) - {"name", "description", "illustrative"}
        if extra:
            raise self.err(
                f"catalogue.{sorted(extra)[0]}",
                "unknown field",
                "use name, description, illustrative",
            )
        illustrative = head.get("illustrative", False)
        if not isinstance(illustrative, bool):
            raise self.err("catalogue.illustrative", "expected true or false")
        raw = data.get("source")
        if not isinstance(raw, list) or not raw:
            raise self.err("source", "no [[source]] table", "add at least one [[source]]")
        if len(raw) > MAX_SOURCES:
            raise self.err("source", f"{len(raw):,} sources is more than {MAX_SOURCES:,}")
        sources = [self.source(r, i) for i, r in enumerate(raw)]
        seen: dict[str, int] = {}
        for i, s in enumerate(sources):
            if s.name in seen:
                raise self.err(
                    f"source[{i}].name",
                    f"name {s.name!r} is also source[{seen[s.name]}]",
                    "give each source its own name",
                )
            seen[s.name] = i
        for i, s in enumerate(sources):
            g = s.coherent_group
            if g is not None and g in seen and sources[seen[g]].coherent_group != g:
                raise self.err(
                    f"source[{i}].coherent_group",
                    f"group {g!r} is the name of an independent source",
                    "name coherent groups differently from sources",
                )
        return SourceCatalogue(
            sources=tuple(sources),
            file=self.file,
            name=self.text(head.get("name"), "catalogue.name", required=False),
            description=self.text(head.get("description"), "catalogue.description", required=False),
            illustrative=illustrative,
        )


def loads_sources(text: str, filename: str = "<sources>") -> SourceCatalogue:
    """Read a source catalogue from TOML text (see the module docstring for the format).

    Parameters
    ----------
    text : the TOML text
    filename : name used in error messages

    Raises
    ------
    InputError
        One line naming ``filename``, the source and field, and the fix.
    """
    data = loads_toml(text, filename)
    return _Reader(filename).catalogue(data)


def load_sources(path: str | Path) -> SourceCatalogue:
    """Read a source catalogue file (TOML; the module docstring gives the format).

    ``"example"`` names the shipped illustrative catalogue (:func:`example_sources`).
    """
    if isinstance(path, str) and path == "example":
        return example_sources()
    p = Path(path)
    if not p.is_file():
        raise InputError(
            "is a directory, not a source file" if p.is_dir() else "no such file",
            where=str(path),
            fix="give the path of a TOML source catalogue",
        )
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the file: {exc}", where=str(path)) from None
    return loads_sources(text, filename=str(path))


def example_sources() -> SourceCatalogue:
    """The shipped example catalogue for the IOC model (ILLUSTRATIVE values, not ISS data)."""
    text = resources.files("microg").joinpath(f"data/{_EXAMPLE}").read_text("utf-8")
    return loads_sources(text, filename=f"microg/data/{_EXAMPLE}")


def as_sources(sources: SourceCatalogue | Sequence[Source]) -> tuple[Source, ...]:
    """The sources of a catalogue or a sequence, checked for unique names."""
    out = tuple(sources.sources if isinstance(sources, SourceCatalogue) else sources)
    names = [s.name for s in out]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise InputError(f"source name {dup!r} is used twice", where="sources")
    return out
