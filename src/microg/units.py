"""Unit parsing at the boundary: strings such as ``"25 lbf"`` become SI floats.

Everything inside microg computes in SI (m, kg, s, N, rad).  This module is the only
place that knows about units; physics kernels never import it.

A quantity is **parsed by a grammar, never evaluated**::

    quantity := number [unit]
    number   := [+|-] (digits [. digits] | . digits) [(e|E) [+|-] digits]
    unit     := factor (("*" | "/") factor)*      e.g.  lbf*ft^2,  kg/m,  N*s/m,  1/s
    factor   := (name | "(" unit ")") [("^" | "**") [+|-] digits]    powers |p| <= 12

One number, then one unit expression, and nothing else: ``"296 ft 2"``, ``"2,96 ft"``,
``"9**9**9 ft"`` and a unit without a number (``"min"``) are errors whose message gives the
accepted form.  The common unit names (m, ft, in, km, kg, lb, slug, N, kN, lbf, s, ms, min,
Hz, rad, ...) come from a built-in table of exact definitions; any other name is looked up
in pint (each once, cached).  pint never sees the number or any arithmetic, and its
registry is built on the first name the table lacks, so ``import microg.units`` (and a
model written in the common units) does not import pint.

Magnitudes: the number must be finite, and so must its value in SI; callers bound each
field further by its physical limits (``docs/model-format.md``, "Limits").
"""

from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from microg.errors import InputError

__all__ = [
    "G0",
    "G0_US",
    "FT",
    "IN",
    "LB",
    "LBF",
    "SLUG",
    "DIMENSIONS",
    "LIMITS",
    "SMALLEST",
    "MAX_TEXT",
    "MAX_POWER",
    "QUANTITY_FORM",
    "registry",
    "parse_quantity",
    "parse_unit",
    "check_limit",
    "is_plain_number",
]

#: standard gravity, m/s^2 (used to express accelerations in g)
G0 = 9.80665
#: the report's weight-to-mass conversion, ft/s^2 (608,600 lb / 32.2 = 18,900 slug, Appendix C-1)
G0_US = 32.2
#: US customary units in SI (exact definitions): foot, inch, pound mass, pound force, slug
FT = 0.3048
IN = 0.0254
LB = 0.45359237
LBF = LB * G0
SLUG = LBF / FT

#: named dimensions accepted by :func:`parse_quantity`, with the SI unit of the float it returns
DIMENSIONS: dict[str, str] = {
    "length": "m",
    "mass": "kg",
    "force": "N",
    "time": "s",
    "frequency": "Hz",
    "angular_frequency": "rad/s",
    "stiffness": "N/m",
    "bending_stiffness": "N*m^2",
    "torsional_stiffness": "N*m^2",
    "axial_stiffness": "N",
    "mass_per_length": "kg/m",
    "rotary_inertia": "kg*m^2",
    "acceleration": "m/s^2",
    "dimensionless": "",
    "damping": "N*s/m",
    "gravitational_parameter": "m^3/s^2",
    "force_per_length": "N/m",
    "angle": "rad",
}

#: physical limits on input magnitudes, SI, by dimension: an input quantity must satisfy
#: ``|value| <= LIMITS[dimension]``.  Generous against any station (the ISS: 4.2e5 kg,
#: 110 m; truss bending stiffness ~1e10 N m^2), small enough that the products formed by the
#: structure (m L^2, EI / L^3) stay far from overflow.  Documented in docs/model-format.md.
LIMITS: dict[str, float] = {
    "length": 1e5,  # m: 100 km
    "mass": 1e9,  # kg
    "force": 1e7,  # N: the largest rocket engines
    "time": 1e7,  # s: 116 days
    "frequency": 1e6,  # Hz
    "angular_frequency": 2e6 * math.pi,  # rad/s
    "stiffness": 1e12,  # N/m
    "bending_stiffness": 1e16,  # N m^2
    "torsional_stiffness": 1e16,  # N m^2
    "axial_stiffness": 1e16,  # N
    "mass_per_length": 1e6,  # kg/m
    "rotary_inertia": 1e18,  # kg m^2
    "acceleration": 1e3,  # m/s^2: 100 g
    "dimensionless": math.inf,
    "damping": 1e12,  # N s/m
    "gravitational_parameter": 1e18,  # m^3/s^2 (the Earth: 3.986e14)
    "force_per_length": 1e7,  # N/m
    "angle": 1e3,  # rad: an orbit element or attitude angle is within a few turns
}

#: the smallest non-zero magnitude accepted, per dimension where one matters: a frequency
#: below 1e-9 Hz (a period of 32 years) is no vibration of a station, and its reciprocal
#: powers overflow
SMALLEST: dict[str, float] = {
    "frequency": 1e-9,  # Hz
    "angular_frequency": 2e-9 * math.pi,  # rad/s
}

#: longest quantity text accepted, characters
MAX_TEXT = 128
#: largest |power| in a unit expression (``m^3``, ``s^-2``)
MAX_POWER = 12
#: deepest nesting of parentheses in a unit expression
MAX_PARENS = 3
#: the accepted form, for error messages
QUANTITY_FORM = (
    "write one number and one unit, e.g. '296 ft', '-1.5e3 N', '1.31e9 lbf*ft^2' "
    "(number: optional sign, digits, decimal point, exponent; unit: names joined by * and /, "
    "integer powers with ^)"
)

_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_NON_FINITE = re.compile(r"[+-]?(?:nan|inf|infinity)(?![A-Za-z_])", re.IGNORECASE)
_TOKEN = re.compile(r"\s*(?:(\*\*|[*/^()])|([^\W\d]\w*|%)|([+-]?[0-9]+))")
_NAME_START = re.compile(r"[^\W\d]|%")


def is_plain_number(text: str) -> bool:
    """Whether ``text`` is one number of the quantity grammar (ASCII digits; nan/inf named).

    Python's ``float`` also reads other scripts' digits and underscores; this does not.
    """
    t = text.strip()
    return _NUMBER.fullmatch(t) is not None or _NON_FINITE.fullmatch(t) is not None


# ------------------------------------------------------------------------------- registry

_REGISTRY: Any = None


def registry() -> Any:
    """The pint unit registry, built on first use (about 0.4 s; pint is imported then)."""
    global _REGISTRY
    if _REGISTRY is None:
        import pint

        reg: Any = pint.UnitRegistry()
        reg.define("micro_g = 1e-6 * standard_gravity = ug")
        reg.define("milli_g = 1e-3 * standard_gravity = mg_accel")
        _REGISTRY = reg
    return _REGISTRY


def __getattr__(name: str) -> Any:
    if name == "ureg":  # the registry under its old name, still lazy
        return registry()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# -------------------------------------------------------------------------------- grammar


class _BadQuantityError(Exception):
    """A parse failure: ``what`` and ``fix``, without ``where`` (added by the caller)."""

    def __init__(self, what: str, fix: str | None = None):
        super().__init__(what)
        self.what = what
        self.fix = fix


def _tokens(expr: str) -> list[tuple[str, str]]:
    """(kind, text) tokens of a unit expression: op, name or int."""
    out: list[tuple[str, str]] = []
    pos = 0
    end = len(expr.rstrip())
    while pos < end:
        m = _TOKEN.match(expr, pos)
        if m is None or m.end() == pos:
            raise _BadQuantityError(
                f"has an unexpected {expr[pos:].strip()[:1]!r} in its unit", QUANTITY_FORM
            )
        kind = "op" if m.group(1) else "name" if m.group(2) else "int"
        out.append((kind, m.group(m.lastindex or 0)))
        pos = m.end()
    return out


class _UnitParser:
    """Recursive descent over the unit grammar; yields ``{name: power}``."""

    def __init__(self, tokens: list[tuple[str, str]]):
        self.tokens = tokens
        self.i = 0

    def peek(self) -> tuple[str, str] | None:
        return self.tokens[self.i] if self.i < len(self.tokens) else None

    def take(self) -> tuple[str, str]:
        tok = self.tokens[self.i]
        self.i += 1
        return tok

    def parse(self) -> dict[str, int]:
        powers = self.expr(0, first=True)
        tok = self.peek()
        if tok is not None:
            what = tok[1]
            if tok[0] == "int":
                raise _BadQuantityError(
                    f"has a number {what!r} after its unit", "give one number, then the unit"
                )
            if tok[0] == "name":
                raise _BadQuantityError(
                    f"has unit names not joined by * or / (at {what!r})", "write e.g. lbf*ft^2"
                )
            raise _BadQuantityError(f"has an unexpected {what!r} in its unit", QUANTITY_FORM)
        return powers

    def expr(self, depth: int, first: bool = False) -> dict[str, int]:
        powers: dict[str, int] = {}
        tok = self.peek()
        if first and tok == ("int", "1") and self.i + 1 < len(self.tokens):
            if self.tokens[self.i + 1] == ("op", "/"):  # "1/s"
                self.take()
                sign = 0
            else:
                sign = 1
        else:
            sign = 1
        if sign:
            _merge(powers, self.factor(depth), 1)
        while True:
            tok = self.peek()
            if tok is None or tok not in (("op", "*"), ("op", "/")):
                return powers
            self.take()
            _merge(powers, self.factor(depth), 1 if tok[1] == "*" else -1)

    def factor(self, depth: int) -> dict[str, int]:
        if self.peek() is None:
            raise _BadQuantityError("ends where a unit name is expected", QUANTITY_FORM)
        kind, text = self.take()
        if kind == "name":
            base = {text: 1}
        elif text == "(":
            if depth >= MAX_PARENS:
                raise _BadQuantityError(
                    f"has more than {MAX_PARENS} levels of parentheses", QUANTITY_FORM
                )
            base = self.expr(depth + 1)
            if self.peek() != ("op", ")"):
                raise _BadQuantityError("has an unbalanced parenthesis", QUANTITY_FORM)
            self.take()
        elif kind == "int":
            raise _BadQuantityError(
                f"has a number {text!r} where a unit name is expected", QUANTITY_FORM
            )
        else:
            raise _BadQuantityError(f"has {text!r} where a unit name is expected", QUANTITY_FORM)
        tok = self.peek()
        if tok in (("op", "^"), ("op", "**")):
            self.take()
            nxt = self.peek()
            if nxt is None or nxt[0] != "int":
                raise _BadQuantityError(
                    "has a power that is not an integer", "write e.g. m^2 or s^-1"
                )
            self.take()
            p = int(nxt[1])
            if abs(p) > MAX_POWER:
                raise _BadQuantityError(
                    f"has a power {p} out of range", f"powers are integers, |power| <= {MAX_POWER}"
                )
            base = {k: v * p for k, v in base.items()}
            nxt = self.peek()
            if nxt in (("op", "^"), ("op", "**")):
                raise _BadQuantityError(
                    "has a repeated power (a^b^c)", "write one integer power, e.g. m^3"
                )
        return base


def _merge(into: dict[str, int], part: dict[str, int], sign: int) -> None:
    for k, v in part.items():
        into[k] = into.get(k, 0) + sign * v


def _canonical(powers: dict[str, int]) -> str:
    """A stable text of the unit expression, for the cache (names keep their order)."""
    return "*".join(f"{k}^{v}" for k, v in powers.items() if v != 0)


@dataclass(frozen=True)
class _Conversion:
    factor: float  # SI value of one unit


class _WrongDimensionError(_BadQuantityError):
    """The unit is fine but not of the dimension asked for."""


@lru_cache(maxsize=1024)
def _lookup(name: str) -> Any:
    """The pint Unit of one unit name (a single word, never an expression; cached)."""
    reg = registry()
    try:
        return reg.Unit(name)
    except Exception:  # pint raises several kinds for an unknown name
        raise _BadQuantityError(
            f"has an unknown unit {name!r}", "use a unit such as m, ft, kg, slug, N, lbf, s"
        ) from None


def _si_unit(dimension: str) -> Any:
    reg = registry()
    si = DIMENSIONS[dimension]
    return reg.Unit(si.replace("^", "**")) if si else reg.dimensionless


# The common units, exactly defined (NIST SP 811), so that a model in ft, slug, lbf or SI
# never needs pint's registry (about 1 s to import and build): name -> (SI factor, exponents
# of (m, kg, s), radian (an angle), hertz (a cycle rate)).  Any other name goes to pint.  The
# tests check every entry against pint.
_L, _M, _T = (1, 0, 0), (0, 1, 0), (0, 0, 1)
_BUILTIN: dict[str, tuple[float, tuple[int, int, int], bool, bool]] = {
    "m": (1.0, _L, False, False),
    "mm": (1e-3, _L, False, False),
    "cm": (1e-2, _L, False, False),
    "km": (1e3, _L, False, False),
    "ft": (FT, _L, False, False),
    "in": (IN, _L, False, False),
    "yd": (3 * FT, _L, False, False),
    "kg": (1.0, _M, False, False),
    "g": (1e-3, _M, False, False),
    "t": (1e3, _M, False, False),
    "lb": (LB, _M, False, False),
    "slug": (SLUG, _M, False, False),
    "N": (1.0, (1, 1, -2), False, False),
    "kN": (1e3, (1, 1, -2), False, False),
    "MN": (1e6, (1, 1, -2), False, False),
    "lbf": (LBF, (1, 1, -2), False, False),
    "kip": (1e3 * LBF, (1, 1, -2), False, False),
    "s": (1.0, _T, False, False),
    "ms": (1e-3, _T, False, False),
    "min": (60.0, _T, False, False),
    "h": (3600.0, _T, False, False),
    "Hz": (1.0, (0, 0, -1), False, True),
    "kHz": (1e3, (0, 0, -1), False, True),
    "rad": (1.0, (0, 0, 0), True, False),
    "deg": (math.pi / 180.0, (0, 0, 0), True, False),
    "rpm": (2.0 * math.pi / 60.0, (0, 0, -1), True, False),
    "percent": (1e-2, (0, 0, 0), False, False),
    "%": (1e-2, (0, 0, 0), False, False),
}
#: exponents of (m, kg, s) of each dimension
_DIMENSION_EXPONENTS: dict[str, tuple[int, int, int]] = {
    "length": _L,
    "mass": _M,
    "force": (1, 1, -2),
    "time": _T,
    "frequency": (0, 0, -1),
    "angular_frequency": (0, 0, -1),
    "stiffness": (0, 1, -2),
    "bending_stiffness": (3, 1, -2),
    "torsional_stiffness": (3, 1, -2),
    "axial_stiffness": (1, 1, -2),
    "mass_per_length": (-1, 1, 0),
    "rotary_inertia": (2, 1, 0),
    "acceleration": (1, 0, -2),
    "dimensionless": (0, 0, 0),
    "damping": (0, 1, -1),
    "gravitational_parameter": (3, 0, -2),
    "force_per_length": (0, 1, -2),
    "angle": (0, 0, 0),
}


def _builtin_conversion(canonical: str, dimension: str) -> _Conversion | None:
    """The conversion from the built-in table, or None when a name is not in it."""
    factor, dims, radian, hertz = 1.0, [0, 0, 0], 0, False
    for item in canonical.split("*") if canonical else ():
        name, _, power_text = item.rpartition("^")
        entry = _BUILTIN.get(name)
        if entry is None:
            return None
        power = int(power_text)
        factor *= entry[0] ** power
        dims = [d + power * e for d, e in zip(dims, entry[1], strict=True)]
        radian += power * entry[2]
        hertz = hertz or entry[3]
    nice = dimension.replace("_", " ")
    if tuple(dims) != _DIMENSION_EXPONENTS[dimension]:
        article = "an" if nice[0] in "aeiou" else "a"
        paren = "its unit {unit} is dimensionless" if not any(dims) else "its unit is {unit}"
        raise _WrongDimensionError(
            f"is not {article} {nice} ({paren})",
            f"use a unit of {nice}, e.g. {DIMENSIONS[dimension] or 'a plain number'}",
        )
    if dimension == "angle" and radian != 1:
        raise _WrongDimensionError("is not an angle", "use deg or rad, e.g. '51.6 deg'")
    if dimension == "angular_frequency" and not radian and hertz:
        factor *= 2.0 * math.pi
    elif dimension == "frequency" and radian:
        factor /= 2.0 * math.pi
    if not math.isfinite(factor) or factor == 0.0:
        raise _BadQuantityError("has a unit out of range", "use a unit of ordinary size")
    return _Conversion(factor)


@lru_cache(maxsize=4096)
def _conversion(canonical: str, dimension: str) -> _Conversion:
    """Scale from the unit ``canonical`` (see :func:`_canonical`) to SI ``dimension`` (cached)."""
    builtin = _builtin_conversion(canonical, dimension)
    if builtin is not None:
        return builtin
    return _pint_conversion(canonical, dimension)


def _pint_conversion(canonical: str, dimension: str) -> _Conversion:
    """The conversion by pint (any unit pint knows)."""
    reg = registry()
    unit: Any = reg.dimensionless
    names: list[str] = []
    if canonical:
        for item in canonical.split("*"):
            name, _, power = item.rpartition("^")
            u = _lookup(name)
            names.append(str(u))
            unit = unit * u ** int(power)
    target = _si_unit(dimension)
    q1 = reg.Quantity(1.0, unit)
    nice = dimension.replace("_", " ")
    try:
        zero = float(reg.Quantity(0.0, unit).to(target).magnitude)
        value = float(q1.to(target).magnitude)
    except Exception as exc:
        if type(exc).__name__ == "DimensionalityError":
            article = "an" if nice[0] in "aeiou" else "a"
            paren = "its unit {unit} is dimensionless" if q1.dimensionless else "its unit is {unit}"
            raise _WrongDimensionError(
                f"is not {article} {nice} ({paren})",
                f"use a unit of {nice}, e.g. {DIMENSIONS[dimension] or 'a plain number'}",
            ) from None
        raise _BadQuantityError(
            "has a unit that cannot be converted", "use a plain multiplicative unit"
        ) from None
    if zero != 0.0:
        raise _BadQuantityError(
            "has a unit with an offset (a temperature scale)", "use a plain unit"
        )
    if dimension == "angle" and dict(q1.to_root_units().unit_items()).get("radian", 0) != 1:
        raise _WrongDimensionError("is not an angle", "use deg or rad, e.g. '51.6 deg'")
    # pint treats the radian as dimensionless, so Hz and rad/s would convert 1:1: convert
    # between cycles and radians explicitly (pint's revolution, rpm and cycle carry 2 pi)
    if dimension in ("angular_frequency", "frequency"):
        radian = dict(q1.to_root_units().unit_items()).get("radian", 0)
        if dimension == "angular_frequency" and not radian and any("hertz" in n for n in names):
            value *= 2.0 * math.pi
        elif dimension == "frequency" and radian:
            value /= 2.0 * math.pi
    if not math.isfinite(value) or value == 0.0:
        raise _BadQuantityError("has a unit out of range", "use a unit of ordinary size")
    return _Conversion(value)


def _unit_factor(unit_text: str, dimension: str) -> float:
    """SI factor of a unit expression; the message of a wrong dimension names the unit."""
    powers = _UnitParser(_tokens(unit_text)).parse()
    try:
        return _conversion(_canonical(powers), dimension).factor
    except _WrongDimensionError as bad:
        raise _BadQuantityError(bad.what.replace("{unit}", unit_text.strip()), bad.fix) from None


@lru_cache(maxsize=65536)
def _parse_text(text: str, dimension: str, default_unit: str | None) -> float:
    """SI value of a quantity string (cached; raises :class:`_BadQuantityError`)."""
    if len(text) > MAX_TEXT:
        raise _BadQuantityError(f"is longer than {MAX_TEXT} characters", QUANTITY_FORM)
    s = text.strip()
    if not s:
        raise _BadQuantityError("is empty", QUANTITY_FORM)
    m = _NUMBER.match(s)
    if m is None:
        if _NON_FINITE.match(s):
            raise _BadQuantityError("is not a finite number", "give a finite value")
        if _NAME_START.match(s):
            raise _BadQuantityError("has a unit but no number", QUANTITY_FORM)
        raise _BadQuantityError("does not start with a number", QUANTITY_FORM)
    number_text = m.group(0)
    rest = s[m.end() :]
    if re.match(r",[0-9]", rest):
        raise _BadQuantityError(
            "has a comma in its number", "write the decimal point as '.', e.g. '2.96 ft'"
        )
    unit_text = rest.strip()
    glued = bool(rest) and not rest[0].isspace()  # "40lbf" is fine, "2**9" or "5(" is not
    if (glued and not _NAME_START.match(rest)) or (
        unit_text and not (_NAME_START.match(unit_text) or re.match(r"\(|1\s*/", unit_text))
    ):
        raise _BadQuantityError(
            "holds arithmetic or punctuation: only one number is accepted", QUANTITY_FORM
        )
    number = float(number_text)
    if not math.isfinite(number):
        raise _BadQuantityError(
            "is not a finite number (beyond the floating-point range)", "give a finite value"
        )
    if not unit_text:
        if dimension == "dimensionless":
            return number
        if default_unit is None:
            raise _BadQuantityError(
                "has no unit",
                f"write it with a unit of {dimension.replace('_', ' ')}, e.g. "
                f"'{number_text} {DIMENSIONS[dimension]}', or declare a unit system",
            )
        unit_text = default_unit
    value = number * _unit_factor(unit_text, dimension)
    if not math.isfinite(value):
        raise _BadQuantityError(
            "is out of range (its SI value overflows)", "give a value of physical size"
        )
    return value


def _bad_type(text: object, dimension: str, where: str) -> InputError:
    si = DIMENSIONS[dimension]
    return InputError(
        f"expected a {dimension.replace('_', ' ')} such as '1 {si}', got {type(text).__name__}",
        where=where,
        fix=QUANTITY_FORM,
    )


def parse_quantity(
    text: str | float | int,
    dimension: str,
    *,
    where: str,
    default_unit: str | None = None,
) -> float:
    """Parse ``text`` as a quantity of ``dimension`` and return its value in SI.

    Parameters
    ----------
    text : str or number
        ``"296 ft"``, ``"1.31e9 lbf*ft^2"``, ``"25 lbf"`` (see the module's grammar); a bare
        number (a float, or a string holding only a number) takes ``default_unit``.
    dimension : str
        A key of :data:`DIMENSIONS`.
    where : str
        Where the value came from (parameter name, ``file: field``), for the error message.
    default_unit : str, optional
        Unit of a bare number.  Without it a bare number is an error (except dimensionless).

    Returns
    -------
    float
        The value in the SI unit of ``DIMENSIONS[dimension]``; finite.

    Raises
    ------
    InputError
        One line naming ``where``, saying what is wrong and giving the accepted form.
    """
    if dimension not in DIMENSIONS:
        raise InputError(f"unknown dimension {dimension!r}", where=where)
    if isinstance(text, bool) or not isinstance(text, str | numbers.Real):
        raise _bad_type(text, dimension, where)
    try:
        if isinstance(text, str):
            return _parse_text(text, dimension, default_unit)
        try:
            number = float(text)
        except OverflowError:
            raise _BadQuantityError(
                "is out of the floating-point range", "give a finite value"
            ) from None
        if not math.isfinite(number):
            raise _BadQuantityError("is not a finite number", "give a finite value")
        if dimension == "dimensionless":
            return number
        if default_unit is None:
            raise _BadQuantityError(
                f"bare number {text!r} has no unit",
                f"write it with a unit, e.g. '{text} {DIMENSIONS[dimension]}', "
                "or declare a unit system",
            )
        value = number * _unit_factor(default_unit, dimension)
        if not math.isfinite(value):
            raise _BadQuantityError(
                "is out of range (its SI value overflows)", "give a value of physical size"
            )
        return value
    except _BadQuantityError as bad:
        shown = text if not isinstance(text, str) or len(text) <= 40 else text[:37] + "..."
        raise InputError(f"{shown!r} {bad.what}", where=where, fix=bad.fix) from None


def parse_unit(text: str, dimension: str, *, where: str) -> float:
    """SI value of one ``text`` unit of ``dimension`` (a unit alone, e.g. a CSV header's).

    Parameters
    ----------
    text : str
        A unit expression (``"lbf"``, ``"ms"``, ``"kN"``), the grammar of the module.
    dimension : str
        A key of :data:`DIMENSIONS`.
    where : str
        Where the unit came from, for the error message.

    Returns
    -------
    float
        The factor to SI, finite and non-zero.
    """
    if not isinstance(text, str) or not text.strip() or len(text) > MAX_TEXT:
        raise InputError("expected a unit", where=where, fix=QUANTITY_FORM)
    try:
        return _unit_factor(text.strip(), dimension)
    except _BadQuantityError as bad:
        raise InputError(f"unit {text.strip()!r} {bad.what}", where=where, fix=bad.fix) from None


def _article(word: str) -> str:
    return "an" if word[:1] in "aeiou" else "a"


def check_limit(value: float, dimension: str, *, where: str) -> float:
    """``value`` (SI) if ``|value| <= LIMITS[dimension]``, else a one-line :class:`InputError`.

    Parameters
    ----------
    value : float
        The SI value (unit of ``DIMENSIONS[dimension]``).
    dimension : str
        A key of :data:`LIMITS`.
    where : str
        Parameter or ``file: field`` named by the error.
    """
    limit = LIMITS[dimension]
    if not math.isfinite(value):
        raise InputError(
            f"{value!r} is not a finite number", where=where, fix="give a finite value"
        )
    if abs(value) > limit:
        si = DIMENSIONS[dimension]
        raise InputError(
            f"{value:.6g} {si} is beyond the physical limit of {limit:.6g} {si} for "
            f"{_article(dimension)} {dimension.replace('_', ' ')}",
            where=where,
            fix="check the value and its unit (limits: docs/model-format.md)",
        )
    small = SMALLEST.get(dimension, 0.0)
    if 0.0 < abs(value) < small:
        si = DIMENSIONS[dimension]
        raise InputError(
            f"{value:.6g} {si} is below the smallest {dimension.replace('_', ' ')} accepted, "
            f"{small:.6g} {si}",
            where=where,
            fix="check the value and its unit (limits: docs/model-format.md)",
        )
    return value
