"""Unit parsing at the boundary: strings such as ``"25 lbf"`` become SI floats.

Everything inside microg computes in SI (m, kg, s, N, rad).  This module is the only
place that knows about units; physics kernels never import it.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pint

from microg.errors import InputError

__all__ = [
    "G0",
    "G0_US",
    "FT",
    "IN",
    "LB",
    "LBF",
    "SLUG",
    "ureg",
    "parse_quantity",
    "to_si",
    "format_quantity",
    "DIMENSIONS",
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

ureg: pint.UnitRegistry = pint.UnitRegistry()
ureg.define("micro_g = 1e-6 * standard_gravity = ug")
ureg.define("milli_g = 1e-3 * standard_gravity = mg_accel")

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
}


@lru_cache(maxsize=64)
def _unit(name: str) -> pint.Unit:
    return ureg.Unit(name)


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
        ``"296 ft"``, ``"1.31e9 lbf*ft^2"``, ``"25 lbf"``; a bare number takes ``default_unit``.
    dimension : str
        A key of :data:`DIMENSIONS`.
    where : str
        Where the value came from (option name, ``file: field``), for the error message.
    default_unit : str, optional
        Unit of a bare number.  Without it a bare number is an error (except dimensionless).

    Returns
    -------
    float
        The value in the SI unit of ``DIMENSIONS[dimension]``.
    """
    si = DIMENSIONS[dimension]
    if isinstance(text, bool):
        raise InputError(
            f"expected a {dimension} such as '1 {si or ''}', got {text!r}", where=where
        )
    if isinstance(text, int | float):
        if dimension == "dimensionless":
            return float(text)
        if default_unit is None:
            raise InputError(
                f"bare number {text!r} has no unit",
                where=where,
                fix=f"write it with a unit, e.g. '{text} {si}', or declare a unit system",
            )
        text = f"{text} {default_unit}"
    try:
        q: pint.Quantity = ureg.Quantity(str(text).strip())
    except (pint.errors.PintError, ValueError, TypeError, AttributeError, SyntaxError) as exc:
        raise InputError(
            f"cannot read {text!r} as a {dimension}: {exc}".replace("\n", " "),
            where=where,
            fix=f"write a number and a unit, e.g. '1 {si}'",
        ) from None
    if not isinstance(q, pint.Quantity):
        q = ureg.Quantity(float(q), default_unit or "")
    if q.dimensionless and dimension != "dimensionless":
        if default_unit is None:
            raise InputError(
                f"{text!r} has no unit",
                where=where,
                fix=f"write it with a unit of {dimension}, e.g. '{q.magnitude} {si}'",
            )
        q = ureg.Quantity(q.magnitude, default_unit)
    if not np.isfinite(q.magnitude):
        raise InputError(f"{text!r} is not a finite number", where=where, fix="give a finite value")
    try:
        value = q.to(_unit(si) if si else ureg.dimensionless).magnitude
    except pint.errors.DimensionalityError:
        raise InputError(
            f"{text!r} is not a {dimension} (its unit is {q.units:~})",
            where=where,
            fix=f"use a unit of {dimension}, e.g. {si or 'a plain number'}",
        ) from None
    # pint treats the radian as dimensionless, so Hz and rad/s would convert 1:1; convert
    # between cycles and radians explicitly (pint's revolution and rpm already carry 2 pi)
    unit_text = str(q.units)
    cyclic = "hertz" in unit_text
    if dimension == "angular_frequency" and cyclic:
        value *= 2.0 * np.pi
    elif dimension == "frequency" and any(
        w in unit_text for w in ("radian", "revolution", "turn", "cycle")
    ):
        value /= 2.0 * np.pi
    if not np.isfinite(value):
        raise InputError(f"{text!r} is out of range", where=where, fix="give a finite value")
    return float(value)


def to_si(value: float, unit: str) -> float:
    """Convert ``value`` in ``unit`` to SI base units."""
    return float(ureg.Quantity(value, unit).to_base_units().magnitude)


def from_si(value: float, si_unit: str, unit: str) -> float:
    """Convert ``value`` from ``si_unit`` to ``unit``."""
    return float(ureg.Quantity(value, si_unit).to(unit).magnitude)


def format_quantity(value: float, si_unit: str, unit: str | None = None, digits: int = 4) -> str:
    """Format an SI value for output, optionally converted to ``unit``."""
    if unit is None:
        return f"{value:.{digits}g} {si_unit}"
    return f"{from_si(value, si_unit, unit):.{digits}g} {unit}"
