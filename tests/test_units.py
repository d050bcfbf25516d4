"""Units at the boundary: the quantity grammar, SI conversion, Hz against rad/s, limits.

References: the exact definitions of the US units (NIST SP 811: 1 ft = 0.3048 m,
1 lb = 0.45359237 kg, g0 = 9.80665 m/s^2, so 1 lbf = 4.4482216152605 N) and 2 pi rad per
cycle, written out here, never read back from pint.  The reproductions of bad strings are
named after the string they feed.
"""

from __future__ import annotations

import math
import subprocess
import sys
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import microg.units as units_module
from microg.errors import InputError
from microg.units import LIMITS, QUANTITY_FORM, check_limit, parse_quantity, parse_unit

FT = 0.3048
LB = 0.45359237
LBF = LB * 9.80665
REL = 1e-12  # one or two roundings in pint's factors (~1e-16); 1e-12 leaves margin


@pytest.mark.parametrize(
    ("text", "dimension", "expected"),
    [
        ("296 ft", "length", 296 * FT),  # exact foot
        ("25 lbf", "force", 25 * LBF),  # exact pound-force
        ("40lbf", "force", 40 * LBF),  # number glued to the unit, as in f0=40lbf
        ("1 slug*ft^2", "rotary_inertia", LBF / FT * FT**2),
        ("1.31e9 lbf*ft**2", "bending_stiffness", 1.31e9 * LBF * FT**2),
        ("0.25 slug/ft", "mass_per_length", 0.25 * LBF / FT / FT),
        ("3 N*s/m", "damping", 3.0),
        ("5 1/s", "frequency", 5.0),
        ("2 (lbf*ft)/ft", "force", 2 * LBF),
        ("-.5e-3 m", "length", -0.5e-3),
        ("+7 ms", "time", 7e-3),
        ("1 Hz", "angular_frequency", 2 * math.pi),  # pint alone would give 1 rad/s
        ("1 rad/s", "angular_frequency", 1.0),
        ("60 rpm", "angular_frequency", 2 * math.pi),
        ("2 Hz", "frequency", 2.0),
        ("1 rad/s", "frequency", 1 / (2 * math.pi)),
        ("60 rpm", "frequency", 1.0),
        ("360 deg/s", "frequency", 1.0),  # a degree is 1/360 cycle
        ("100 kg/lb", "dimensionless", 100 / LB),  # the scale is kept, not dropped
        ("60 percent", "dimensionless", 0.6),
        ("296", "length", 296 * FT),  # a bare number takes the default unit (ft here)
    ],
)
def test_conversions(text: str, dimension: str, expected: float) -> None:
    value = parse_quantity(text, dimension, where="t", default_unit="ft")
    assert value == pytest.approx(expected, rel=REL)


def _error(text: str, dimension: str = "length", default_unit: str | None = None) -> str:
    with pytest.raises(InputError) as exc:
        parse_quantity(text, dimension, where="w", default_unit=default_unit)
    msg = str(exc.value)
    assert msg.startswith("w: ") and "\n" not in msg
    return msg


def test_9_pow_9_pow_9_ft_does_not_hang() -> None:
    # the units library evaluated this: 9**(9**9) has 370 million digits
    start = time.perf_counter()
    msg = _error("9**9**9 ft")
    assert time.perf_counter() - start < 0.5  # parsing is a regex and a table lookup
    assert "only one number" in msg and QUANTITY_FORM in msg


@pytest.mark.parametrize(
    ("text", "dimension"),
    [("2**1000 ft", "length"), ("(296 ft", "length"), ("2**5000 lbf", "force")],
)
def test_arithmetic_and_parentheses_are_clean_errors(text: str, dimension: str) -> None:
    msg = _error(text, dimension)
    assert "number" in msg and "write one number and one unit" in msg


def test_import_os_ft_is_not_evaluated() -> None:
    msg = _error("__import__('os').system('touch /tmp/microg-pwned') ft")
    assert "no number" in msg


@pytest.mark.parametrize(("text", "dimension"), [("296 ft 2", "length"), ("30 s 2", "time")])
def test_trailing_number_is_not_multiplied(text: str, dimension: str) -> None:
    # was read as 592 ft and 60 s
    assert "a number '2' after its unit" in _error(text, dimension)


@pytest.mark.parametrize(("text", "dimension"), [("2,96 ft", "length"), ("1,5 min", "time")])
def test_decimal_comma_is_an_error(text: str, dimension: str) -> None:
    # was read as 296 ft and 900 s
    assert "comma" in _error(text, dimension)


def test_296_m_per_m_is_not_296_ft_in_a_us_model() -> None:
    msg = _error("296 m/m", "length", default_unit="ft")
    assert "is not a length" in msg and "dimensionless" in msg


@pytest.mark.parametrize(
    ("text", "dimension", "unit"), [("min", "time", "s"), ("lbf", "force", "lbf")]
)
def test_bare_unit_without_number(text: str, dimension: str, unit: str) -> None:
    # "min" meant 60 s and f0=lbf meant 1 lbf
    assert "has a unit but no number" in _error(text, dimension, default_unit=unit)


@pytest.mark.parametrize("text", ["100 kg/lb", "60 percent"])
def test_dimensionless_is_not_a_time(text: str) -> None:
    # "100 kg/lb" became 100 s and "60 percent" 60 s
    assert "is not a time" in _error(text, "time", default_unit="s")


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("5 m^2^3", "repeated power"),
        ("5 m^99", "power 99 out of range"),
        ("5 ((((m))))", "levels of parentheses"),
        ("5 m)", "unexpected ')'"),
        ("5 m*", "ends where a unit name"),
        ("5*m", "only one number"),
        ("1.5.3 m", "only one number"),
        ("5 N m", "not joined by * or /"),
        ("5 foo", "unknown unit 'foo'"),
        ("5 degC", "is not a length"),
        ("", "is empty"),
        ("x" * 200, "longer than"),
    ],
)
def test_grammar_errors_say_what(text: str, needle: str) -> None:
    assert needle in _error(text)


@pytest.mark.parametrize("text", ["nan s", "inf s", "-inf s", "1e400 s"])
def test_non_finite_rejected(text: str) -> None:
    with pytest.raises(InputError, match="finite"):
        parse_quantity(text, "time", where="--dt")


def test_overflowing_si_value_rejected() -> None:
    # 1e308 km is a finite number whose SI value (1e311 m) overflows
    assert "out of range" in _error("1e308 km")
    with pytest.raises(InputError, match="floating-point range"):
        parse_quantity(10**400, "length", where="w", default_unit="m")


def test_wrong_dimension_names_the_field() -> None:
    with pytest.raises(InputError) as exc:
        parse_quantity("3 m", "force", where="f0")
    assert str(exc.value).startswith("f0:") and "not a force (its unit is m)" in str(exc.value)


def test_bare_number_needs_default_unit() -> None:
    with pytest.raises(InputError, match="no unit"):
        parse_quantity(3.0, "length", where="beam.length")
    assert parse_quantity(3.0, "length", where="x", default_unit="ft") == pytest.approx(3 * FT)
    with pytest.raises(InputError, match="no unit"):
        parse_quantity("3", "length", where="x")


def test_non_string_non_number_is_an_error() -> None:
    for bad in (True, None, [1], {"a": 1}, b"1 m"):
        with pytest.raises(InputError, match="expected a length"):
            parse_quantity(bad, "length", where="x")  # type: ignore[arg-type]


def test_parse_unit_for_headers() -> None:
    assert parse_unit("ms", "time", where="h") == pytest.approx(1e-3, rel=REL)
    assert parse_unit("kip", "force", where="h") == pytest.approx(1000 * LBF, rel=REL)
    with pytest.raises(InputError, match="not a force"):
        parse_unit("kg", "force", where="h")


def test_physical_limits() -> None:
    assert check_limit(1e7, "force", where="f0") == 1e7
    with pytest.raises(InputError, match="physical limit of 1e\\+07 N"):
        check_limit(1e300 * LBF, "force", where="f0")
    assert LIMITS["length"] == 1e5 and math.isinf(LIMITS["dimensionless"])


def test_import_does_not_load_pint() -> None:
    # `import microg.units` must not import pint (about 1 s with its registry); the
    # common units come from the built-in table, and pint only for another name
    code = (
        "import sys, microg.units as u; assert 'pint' not in sys.modules; "
        "u.parse_quantity('1.31e9 lbf*ft^2', 'bending_stiffness', where='x'); "
        "u.parse_quantity('25 slug/ft', 'mass_per_length', where='x'); "
        "assert 'pint' not in sys.modules; "
        "u.parse_quantity('1 furlong', 'length', where='x'); assert 'pint' in sys.modules"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize("name", sorted(units_module._BUILTIN))
def test_builtin_units_agree_with_pint(name: str) -> None:
    # the independent reference for the built-in table is pint itself: the same factor (to
    # pint's rounding, 1e-15) in every dimension the unit belongs to, 2 pi rules included
    entry = units_module._BUILTIN[name]
    for dimension, dims in units_module._DIMENSION_EXPONENTS.items():
        if dims != entry[1] or (dimension == "angle" and entry[2] != 1):
            continue  # a plain ratio (%, ppm) is no angle: refused by design, tested below
        mine = units_module._builtin_conversion(f"{name}^1", dimension)
        theirs = units_module._pint_conversion(f"{name}^1", dimension)
        assert mine is not None
        assert mine.factor == pytest.approx(theirs.factor, rel=1e-15), dimension


@pytest.mark.parametrize(
    ("unit", "dimension"),
    [
        ("lbf*ft^2", "bending_stiffness"),
        ("slug/ft", "mass_per_length"),
        ("slug*ft^2", "rotary_inertia"),
        ("lbf*s/ft", "damping"),
        ("ft^3/s^2", "gravitational_parameter"),
        ("kip/in", "stiffness"),
        ("rad/s", "frequency"),
        ("1/min", "angular_frequency"),
        ("kg/lb", "dimensionless"),
    ],
)
def test_builtin_compounds_agree_with_pint(unit: str, dimension: str) -> None:
    powers = units_module._UnitParser(units_module._tokens(unit)).parse()
    canonical = units_module._canonical(powers)
    mine = units_module._builtin_conversion(canonical, dimension)
    theirs = units_module._pint_conversion(canonical, dimension)
    assert mine is not None and mine.factor == pytest.approx(theirs.factor, rel=1e-14)


@pytest.mark.parametrize("canonical", ["lbf^1", "", "Hz^1", "kg^1*m^-1"])
def test_builtin_and_pint_refuse_the_same_dimensions(canonical: str) -> None:
    # "" is a unit whose powers cancel (m/m): dimensionless, not a length
    for path in (units_module._builtin_conversion, units_module._pint_conversion):
        with pytest.raises(units_module._WrongDimensionError):
            path(canonical, "length")


def test_parsing_is_fast_and_cached() -> None:
    # was about 1 ms a value through pint; now a regex and a cached factor
    parse_quantity("1 ft", "length", where="x")  # builds the registry
    texts = [f"{i}.25 ft" for i in range(20000)]
    start = time.perf_counter()
    for t in texts:
        parse_quantity(t, "length", where="x")
    per_value = (time.perf_counter() - start) / len(texts)
    assert per_value < 2e-4  # 200 us: five times slower than measured (~9 us) on a busy box


# hypothesis: the grammar against an independent evaluator over a table of exact units
_UNITS = {"m": 1.0, "ft": FT, "in": 0.0254, "km": 1e3, "mm": 1e-3, "yd": 3 * FT}


@given(
    number=st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False),
    unit=st.sampled_from(sorted(_UNITS)),
    space=st.sampled_from(["", " ", "  ", "\t"]),
    fmt=st.sampled_from(["{!r}", "{:.6e}", "{:.3f}", "{:g}"]),
)
@settings(max_examples=300, deadline=None)
def test_number_then_unit_is_exact(number: float, unit: str, space: str, fmt: str) -> None:
    text = fmt.format(number)
    if "inf" in text or "nan" in text:
        return
    got = parse_quantity(f"{text}{space}{unit}", "length", where="x")
    assert got == pytest.approx(float(text) * _UNITS[unit], rel=REL, abs=1e-300)


@given(st.text(max_size=40))
@settings(max_examples=500, deadline=None)
def test_any_text_is_a_value_or_a_one_line_error(text: str) -> None:
    # never an exception other than InputError, never a hang, never a non-finite value
    try:
        value = parse_quantity(text, "length", where="x", default_unit="m")
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    assert math.isfinite(value)


def test_angles_take_deg_or_rad_and_refuse_ratios() -> None:
    # quasi-steady's --inclination took a bare number of degrees; an angle is now a quantity
    from microg.units import parse_quantity

    deg = math.pi / 180.0  # the definition of the degree
    assert parse_quantity("51.6 deg", "angle", where="x") == pytest.approx(51.6 * deg, rel=1e-15)
    assert parse_quantity("51.6", "angle", where="x", default_unit="deg") == pytest.approx(
        51.6 * deg, rel=1e-15
    )
    assert parse_quantity("1 arcminute", "angle", where="x") == pytest.approx(deg / 60, rel=1e-12)
    for bad in ("5 %", "5 percent", "3 m/m", "2 rad/s", "51.6 m"):
        with pytest.raises(InputError):
            parse_quantity(bad, "angle", where="x")
