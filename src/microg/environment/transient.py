"""Transient criteria as data (peak and integrated acceleration limits) and their verdict.

A criterion set lives in a TOML file (the shipped one: ``microg/data/transient_criteria.toml``)
as ``[[set]]`` tables of ``[[set.criterion]]``; each criterion has a ``name``, a ``quantity``
(:data:`QUANTITIES`), a limit with its unit in its key (``limit_ug`` for peaks, ``limit_ug_s``
for integrals), ``window_s`` for integrals, a ``source`` and ``verified``.

A criterion the project cannot trace to a public source has ``verified = false``: it is judged
and reported, flagged unverified, but it does not decide ``complies`` (see
:attr:`TransientVerdict.complies_verified`).  This module only judges numbers that
:func:`microg.environment.metrics.assess` computed; it computes no signal quantity itself.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from microg.errors import InputError
from microg.units import G0

__all__ = [
    "QUANTITIES",
    "TransientCriterion",
    "TransientCriteria",
    "TransientCheck",
    "TransientVerdict",
    "transient_criteria",
    "load_transient_criteria",
    "judge_transient",
]

#: the quantities a criterion may limit
QUANTITIES = ("peak_axis", "peak_magnitude", "integrated_axis", "integrated_magnitude")
#: largest criteria file read, bytes
MAX_FILE_BYTES = 1_000_000


@dataclass(frozen=True)
class TransientCriterion:
    """One transient limit, SI.

    Attributes
    ----------
    name : short name
    quantity : one of :data:`QUANTITIES`
    limit : the limit, m/s^2 for a peak, m/s for an integral
    window_s : integration window, s (None for a peak)
    source : citation
    verified : the value is traced to a public source
    """

    name: str
    quantity: str
    limit: float
    window_s: float | None
    source: str
    verified: bool

    @property
    def is_integral(self) -> bool:
        """True for the integrated-acceleration quantities."""
        return self.quantity.startswith("integrated")


@dataclass(frozen=True)
class TransientCriteria:
    """A named set of transient criteria."""

    name: str
    description: str
    criteria: tuple[TransientCriterion, ...]

    @property
    def windows_s(self) -> tuple[float, ...]:
        """The distinct integration windows the set needs, s."""
        return tuple(sorted({c.window_s for c in self.criteria if c.window_s is not None}))


@dataclass(frozen=True)
class TransientCheck:
    """One criterion judged.

    Attributes
    ----------
    criterion : the criterion
    value_axis : (naxes,) per-axis value (NaN for a magnitude criterion), SI
    value : the judged value (max over axes, or the magnitude), SI
    complies : value <= limit
    basis : how the integral was taken (``sliding`` or ``pims``), or ``peak``
    """

    criterion: TransientCriterion
    value_axis: np.ndarray
    value: float
    complies: bool
    basis: str

    def to_dict(self, axes: tuple[str, ...]) -> dict[str, Any]:
        """JSON-ready; keys carry units (``_g`` for peaks, ``_mps`` and ``_ug_s`` for integrals)."""
        c = self.criterion
        out: dict[str, Any] = {"name": c.name, "quantity": c.quantity, "basis": self.basis}
        per_axis = c.quantity.endswith("_axis")
        if c.is_integral:
            out["window_s"] = c.window_s
            if per_axis:
                out["value_mps_axis"] = dict(zip(axes, map(float, self.value_axis), strict=True))
            out["value_mps"] = self.value
            out["limit_mps"] = c.limit
            out["value_ug_s"] = self.value / G0 * 1e6
            out["limit_ug_s"] = c.limit / G0 * 1e6
        else:
            if per_axis:
                out["value_g_axis"] = dict(
                    zip(axes, (float(v) / G0 for v in self.value_axis), strict=True)
                )
            out["value_g"] = self.value / G0
            out["limit_g"] = c.limit / G0
        out["complies"] = bool(self.complies)
        out["source"] = c.source
        out["verified"] = bool(c.verified)
        out["enters_verdict"] = bool(c.verified)
        return out


@dataclass(frozen=True)
class TransientVerdict:
    """The transient criteria judged at one point.

    Attributes
    ----------
    criteria : name of the criteria set
    checks : every criterion judged
    """

    criteria: str
    checks: tuple[TransientCheck, ...]

    @property
    def complies(self) -> bool:
        """Every criterion (verified or not) is met."""
        return all(c.complies for c in self.checks)

    @property
    def complies_verified(self) -> bool:
        """Every *verified* criterion is met (what enters the overall verdict)."""
        return all(c.complies for c in self.checks if c.criterion.verified)

    @property
    def verified(self) -> bool:
        """Every criterion of the set is traced to a public source."""
        return all(c.criterion.verified for c in self.checks)

    def to_dict(self, axes: tuple[str, ...]) -> dict[str, Any]:
        """JSON-ready summary."""
        return {
            "criteria": self.criteria,
            "complies": self.complies,
            "complies_verified": self.complies_verified,
            "verified": self.verified,
            "checks": [c.to_dict(axes) for c in self.checks],
        }


def _bad(where: str, what: str, fix: str) -> InputError:
    return InputError(what, where=where, fix=fix)


def _parse_sets(data: Mapping[str, Any], origin: str) -> dict[str, TransientCriteria]:
    sets = data.get("set")
    if not isinstance(sets, list) or not sets:
        raise _bad(f"{origin}: set", "no [[set]] tables", "add [[set]] with [[set.criterion]]")
    out: dict[str, TransientCriteria] = {}
    for i, s in enumerate(sets):
        w = f"{origin}: set[{i}]"
        if not isinstance(s, dict):
            raise _bad(w, "is not a table", "write [[set]]")
        name = s.get("name")
        if not isinstance(name, str) or not name.strip():
            raise _bad(f"{w}.name", "missing or empty", 'give name = "..."')
        crits = s.get("criterion")
        if not isinstance(crits, list) or not crits:
            raise _bad(f"{w}.criterion", "no [[set.criterion]]", "add at least one criterion")
        parsed = []
        for j, c in enumerate(crits):
            wc = f"{w}.criterion[{j}]"
            if not isinstance(c, dict):
                raise _bad(wc, "is not a table", "write [[set.criterion]]")
            cname = c.get("name")
            if not isinstance(cname, str) or not cname.strip():
                raise _bad(f"{wc}.name", "missing or empty", 'give name = "..."')
            q = c.get("quantity")
            if q not in QUANTITIES:
                raise _bad(f"{wc}.quantity", f"unknown quantity {q!r}", f"use one of {QUANTITIES}")
            integral = str(q).startswith("integrated")
            key = "limit_ug_s" if integral else "limit_ug"
            lim = c.get(key)
            if isinstance(lim, bool) or not isinstance(lim, int | float):
                raise _bad(f"{wc}.{key}", "missing or not a number", f"give {key} = <number>")
            if not (math.isfinite(lim) and 0 < lim <= 1e9):
                raise _bad(f"{wc}.{key}", f"{lim!r} is out of range", "give 0 < limit <= 1e9")
            window = None
            if integral:
                window = c.get("window_s")
                if isinstance(window, bool) or not isinstance(window, int | float):
                    raise _bad(f"{wc}.window_s", "missing or not a number", "give window_s = 10")
                if not (math.isfinite(window) and 0 < window <= 86400):
                    raise _bad(f"{wc}.window_s", f"{window!r} is out of range", "0 < window <= 1 d")
                window = float(window)
            src = c.get("source")
            if not isinstance(src, str) or not src.strip():
                raise _bad(f"{wc}.source", "missing", "every limit needs its source")
            ver = c.get("verified")
            if not isinstance(ver, bool):
                raise _bad(f"{wc}.verified", "missing or not true/false", "give verified = false")
            parsed.append(
                TransientCriterion(
                    name=cname.strip(),
                    quantity=str(q),
                    limit=float(lim) * 1e-6 * G0,  # ug -> m/s^2, or ug s -> m/s
                    window_s=window,
                    source=src.strip(),
                    verified=ver,
                )
            )
        out[name.strip()] = TransientCriteria(
            name.strip(), str(s.get("description", "")), tuple(parsed)
        )
    return out


@lru_cache(maxsize=1)
def _shipped() -> dict[str, TransientCriteria]:
    text = resources.files("microg").joinpath("data/transient_criteria.toml").read_text("utf-8")
    return _parse_sets(tomllib.loads(text), "microg/data/transient_criteria.toml")


def transient_criteria(name: str | TransientCriteria = "iss") -> TransientCriteria:
    """A shipped criteria set by name (``iss``: unverified ISS limits; ``report-1e-5g``).

    Parameters
    ----------
    name : set name, or a :class:`TransientCriteria` (returned as is)
    """
    if isinstance(name, TransientCriteria):
        return name
    sets = _shipped()
    if name not in sets:
        raise InputError(
            f"unknown transient criteria {name!r}",
            where="transient",
            fix=f"use one of: {', '.join(sets)}, or a criteria file",
        )
    return sets[name]


def load_transient_criteria(path: str | Path, name: str | None = None) -> TransientCriteria:
    """Read a criteria set from a TOML file of the shipped layout.

    Parameters
    ----------
    path : the TOML file
    name : the set to take (default: the file's first set)
    """
    p = Path(path)
    try:
        if p.stat().st_size > MAX_FILE_BYTES:
            raise InputError(f"larger than {MAX_FILE_BYTES} bytes", where=str(p))
        data = tomllib.loads(p.read_text("utf-8"))
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", where=str(p)) from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"not valid TOML: {exc}", where=str(p)) from None
    sets = _parse_sets(data, str(p))
    if name is None:
        return next(iter(sets.values()))
    if name not in sets:
        raise InputError(f"no set {name!r}", where=str(p), fix=f"sets: {', '.join(sets)}")
    return sets[name]


def judge_transient(
    criteria: TransientCriteria,
    *,
    peak_axis: np.ndarray,
    peak_magnitude: float,
    integrated: Mapping[float, tuple[np.ndarray, float]],
    basis: str,
) -> TransientVerdict:
    """Judge each criterion of ``criteria`` on precomputed peaks and integrals.

    Parameters
    ----------
    criteria : the criteria set
    peak_axis : (naxes,) max |a| per axis, m/s^2
    peak_magnitude : max |a| of the vector, m/s^2
    integrated : window_s -> ((naxes,) max |integral| per axis, m/s; max vector norm, m/s),
        for every window of ``criteria.windows_s``
    basis : ``sliding`` or ``pims`` (how ``integrated`` was taken; reported)
    """
    checks = []
    n = np.asarray(peak_axis).size
    for c in criteria.criteria:
        if c.is_integral:
            assert c.window_s is not None
            ax_vals, mag = integrated[c.window_s]
            kind = basis
        else:
            ax_vals, mag = np.asarray(peak_axis, float), float(peak_magnitude)
            kind = "peak"
        if c.quantity.endswith("_axis"):
            vals = np.asarray(ax_vals, float)
            value = float(np.max(vals)) if vals.size else 0.0
        else:
            vals = np.full(n, np.nan)
            value = float(mag)
        checks.append(TransientCheck(c, vals, value, bool(value <= c.limit), kind))
    return TransientVerdict(criteria.name, tuple(checks))
