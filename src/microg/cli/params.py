"""Click parameter types that parse physical quantities and ranges at the boundary.

Quantities follow the grammar of :mod:`microg.units` (one number, one unit) and the
physical limits of :data:`microg.units.LIMITS`.
"""

from __future__ import annotations

import math
import re
from typing import Any

import click

from microg.errors import InputError
from microg.units import G0, LIMITS, check_limit, is_plain_number, parse_quantity

__all__ = [
    "QuantityType",
    "MassOrWeightType",
    "RangeType",
    "BandType",
    "PositiveFloat",
    "PathType",
    "Integer",
    "Number",
]

#: a plain number as written in ASCII: Python's own parsing also takes other scripts' digits
#: ("\u0661\u0660" is 10) and underscores ("1_0" is 10), which the unit grammar refuses
_ASCII_INT = re.compile(r"[+-]?[0-9]+")


def _ascii(value: Any, pattern: re.Pattern[str] | None, kind: str, param: Any, ctx: Any) -> None:
    """Fail unless a text ``value`` is a plain ASCII number.

    ``pattern`` is the integer form; None means a number of the quantity grammar
    (:func:`microg.units.is_plain_number`).
    """
    if not isinstance(value, str):
        return
    ok = is_plain_number(value) if pattern is None else pattern.fullmatch(value.strip())
    if not ok:
        shown = value if len(value) <= 40 else value[:40] + "..."
        raise click.BadParameter(f"expected {kind} in ASCII digits, got {shown!r}", ctx, param)


class QuantityType(click.ParamType):
    """A physical quantity: ``"25 lbf"``, ``"111 N"``; a bare number takes ``default_unit``.

    Converts to an SI float within the physical limit of its dimension
    (:data:`microg.units.LIMITS`).  ``minimum``/``strict`` bound the SI value from below,
    ``maximum`` from above.
    """

    name = "quantity"

    def __init__(
        self,
        dimension: str,
        default_unit: str | None,
        *,
        minimum: float | None = None,
        strict: bool = False,
        maximum: float | None = None,
    ):
        self.dimension = dimension
        self.default_unit = default_unit
        self.minimum = minimum
        self.strict = strict
        self.maximum = LIMITS[dimension] if maximum is None else maximum

    def get_metavar(self, param: click.Parameter, ctx: click.Context | None = None) -> str:
        """The help's placeholder: ``Q``, or ``Q[unit]`` with the default unit."""
        return "Q" if self.default_unit is None else f"Q[{self.default_unit}]"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The SI value of ``value`` (a float passes through), checked against the bounds."""
        if isinstance(value, float):
            return value
        try:
            si = parse_quantity(
                value, self.dimension, where="value", default_unit=self.default_unit
            )
            check_limit(si, self.dimension, where="value")
        except InputError as exc:
            self.fail(f"{exc.what}" + (f" ({exc.fix})" if exc.fix else ""), param, ctx)
        if self.minimum is not None:
            bad = si <= self.minimum if self.strict else si < self.minimum
            if bad:
                op = ">" if self.strict else ">="
                self.fail(f"must be {op} {self.minimum:g}, got {value!r}", param, ctx)
        if abs(si) > self.maximum:
            self.fail(f"must be at most {self.maximum:g} (SI), got {value!r}", param, ctx)
        return si


class MassOrWeightType(click.ParamType):
    """A mass (``"200 kg"``, ``"14 slug"``) or an Earth weight (``"441 lbf"``) -> kg.

    A weight W is turned into the mass W / g0 (standard gravity 9.80665 m/s^2).  A bare
    number takes ``default_unit`` (a mass or a force unit).  The result is > 0 and within
    the physical limit on masses.
    """

    name = "mass"

    def __init__(self, default_unit: str):
        self.default_unit = default_unit

    def get_metavar(self, param: click.Parameter, ctx: click.Context | None = None) -> str:
        """The help's placeholder, ``Q[unit]`` with the default unit."""
        return f"Q[{self.default_unit}]"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The mass of ``value``, kg (a weight divided by g0; a float passes through)."""
        if isinstance(value, float):
            return value
        errors = []
        for dimension, scale in (("mass", 1.0), ("force", 1.0 / G0)):
            default = self.default_unit
            try:
                si = parse_quantity(value, dimension, where="value", default_unit=default)
            except InputError as exc:
                errors.append(exc)
                continue
            mass = si * scale
            if not mass > 0:
                self.fail(f"must be > 0, got {value!r}", param, ctx)
            try:
                check_limit(mass, "mass", where="value")
            except InputError as exc:
                self.fail(exc.what, param, ctx)
            return mass
        first = next((e for e in errors if "is not a" not in e.what), errors[0])
        what = first.what
        if "is not a" in what:
            what = f"{value!r} is neither a mass (kg, slug, lb) nor a weight (N, lbf)"
        self.fail(
            what + (f" ({first.fix})" if first.fix and "is not a" not in first.what else ""),
            param,
            ctx,
        )


class PositiveFloat(click.ParamType):
    """A plain float with an optional lower bound (strict or not)."""

    name = "float"

    def __init__(self, minimum: float = 0.0, strict: bool = True):
        self.minimum = minimum
        self.strict = strict

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The finite float of ``value``, checked against the lower bound."""
        _ascii(value, None, "a number", param, ctx)
        try:
            x = float(value)
        except (TypeError, ValueError):
            self.fail(f"expected a number, got {value!r}", param, ctx)
        if x != x or x in (float("inf"), float("-inf")):
            self.fail(f"expected a finite number, got {value!r}", param, ctx)
        bad = x <= self.minimum if self.strict else x < self.minimum
        if bad:
            op = ">" if self.strict else ">="
            self.fail(f"must be {op} {self.minimum:g}, got {value!r}", param, ctx)
        return x


class RangeType(click.ParamType):
    """``START:STOP:N`` -> ``(start, stop, n)``, N >= 2 integer, START < STOP."""

    name = "START:STOP:N"

    def __init__(self, max_points: int = 1_000_000):
        self.max_points = max_points

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """``(start, stop, n)`` of ``START:STOP:N``, in the option's unit; a tuple passes."""
        if isinstance(value, tuple):
            return value
        parts = str(value).split(":")
        if len(parts) != 3:
            self.fail(f"expected START:STOP:N, got {value!r}", param, ctx)
        for part, pattern in zip(parts, (None, None, _ASCII_INT), strict=True):
            _ascii(part, pattern, "START:STOP:N", param, ctx)
        try:
            start, stop = float(parts[0]), float(parts[1])
        except ValueError:
            self.fail(f"START and STOP must be numbers, got {value!r}", param, ctx)
        try:
            n = int(parts[2])
        except ValueError:
            self.fail(f"N must be an integer, got {parts[2]!r}", param, ctx)
        if not (math.isfinite(start) and math.isfinite(stop)):
            self.fail(f"START and STOP must be finite, got {value!r}", param, ctx)
        if not (start < stop) or n < 2:
            self.fail(f"need START < STOP and N >= 2, got {value!r}", param, ctx)
        if n > self.max_points:
            self.fail(f"N must be <= {self.max_points:,}, got {n:,}", param, ctx)
        return (start, stop, n)


class BandType(click.ParamType):
    """``LO:HI`` -> ``(lo, hi)`` with 0 <= LO < HI."""

    name = "LO:HI"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """``(lo, hi)`` of ``LO:HI``, in the option's unit (Hz, rad/s); a tuple passes through."""
        if isinstance(value, tuple):
            return value
        parts = str(value).split(":")
        if len(parts) != 2:
            self.fail(f"expected LO:HI, got {value!r}", param, ctx)
        for part in parts:
            _ascii(part, None, "LO:HI numbers", param, ctx)
        try:
            lo, hi = float(parts[0]), float(parts[1])
        except ValueError:
            self.fail(f"expected numbers in LO:HI, got {value!r}", param, ctx)
        if not (0 <= lo < hi) or not math.isfinite(hi):
            self.fail(f"need 0 <= LO < HI < inf, got {value!r}", param, ctx)
        return (lo, hi)


class PathType(click.Path):
    """click's path type, refusing first what the operating system cannot take.

    An empty name or one holding a NUL character is refused in one line (``os.stat`` raises
    ``ValueError`` on a NUL, which click does not catch); everything else is click's own check.
    """

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The path of ``value``, after the empty-name and NUL checks."""
        text = value if isinstance(value, str) else str(value)
        if not text.strip():
            self.fail("is empty: name a file or directory", param, ctx)
        if "\x00" in text:
            self.fail("holds a NUL character: name a plain file or directory", param, ctx)
        return super().convert(value, param, ctx)


def _range_text(rng: click.types._NumberRangeBase) -> str:
    """The range text of click for the help, empty when the range has no bound."""
    if rng.min is None and rng.max is None:
        return ""
    return click.types._NumberRangeBase._describe_range(rng)


class Integer(click.IntRange):
    """click's integer range, in ASCII digits only (no ``"1_0"``, no other scripts' digits)."""

    def _describe_range(self) -> str:
        return _range_text(self)

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The integer of ``value``, after the ASCII check, within the range."""
        _ascii(value, _ASCII_INT, "an integer", param, ctx)
        return super().convert(value, param, ctx)


class Number(click.FloatRange):
    """click's float range, in ASCII digits only, finite unless a bound says otherwise."""

    def _describe_range(self) -> str:
        return _range_text(self)

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The float of ``value``, after the ASCII and finiteness checks, within the range."""
        _ascii(value, None, "a number", param, ctx)
        x = super().convert(value, param, ctx)
        if not math.isfinite(x):
            self.fail(f"expected a finite number, got {value!r}", param, ctx)
        return x
