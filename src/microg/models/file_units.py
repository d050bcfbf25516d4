"""The units of a file that declares none (NASTRAN, UFF without dataset 164), as SI factors.

A declaration ``"LENGTH, FORCE, TIME"`` (``"in, lbf, s"``) fixes the consistent mass unit
``M = F T^2 / L`` (the slinch for in, lbf, s); NASTRAN's ``PARAM,WTMASS`` turns input mass
into that unit.  Converting a source: positions scale by L, eigenvalues by 1/T^2,
mass-normalised translations by 1/sqrt(M), rotations by 1/(sqrt(M) L), mass-matrix blocks
by M, M L, M L^2 (translation, coupling, rotation).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg.errors import InputError
from microg.units import parse_quantity

__all__ = ["SI_UNITS", "UnitSystem", "WTMASS_RANGE", "check_positive", "parse_units"]


@dataclass(frozen=True)
class UnitSystem:
    """The units of a source file that declares none (NASTRAN), as SI factors.

    Attributes
    ----------
    text : str
        The declaration as the user wrote it (``"in, lbf, s"``).
    length_m, force_N, time_s : float
        One length, force and time unit in SI.
    mass_kg : float
        The consistent mass unit ``F T^2 / L``, kg (the slinch for in, lbf, s).
    wtmass : float
        NASTRAN's PARAM,WTMASS of the run (input mass times WTMASS = consistent mass).
    wtmass_given : bool
        Whether the user declared ``wtmass`` (1 is then a declaration, not the default).
    """

    text: str
    length_m: float
    force_N: float  # noqa: N815 (unit suffix, as SI writes it)
    time_s: float
    mass_kg: float
    wtmass: float = 1.0
    wtmass_given: bool = False

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready provenance."""
        return {
            "declared": self.text,
            "length_m": self.length_m,
            "force_N": self.force_N,
            "time_s": self.time_s,
            "mass_kg": self.mass_kg,
            "wtmass": self.wtmass,
            "wtmass_given": self.wtmass_given,
        }


#: accepted NASTRAN WTMASS values: 1e-6 (mg to kg) to 1e3 (a run whose input mass unit is
#: a thousand of the consistent one); 1/386.09 = 0.00259 and 1/9.80665 = 0.102 lie inside
WTMASS_RANGE = (1e-6, 1e3)

#: the SI system (UFF files in SI, microg's own files)
SI_UNITS = UnitSystem("m, N, s", 1.0, 1.0, 1.0, 1.0)


def parse_units(text: str, *, where: str = "units", wtmass: float | None = None) -> UnitSystem:
    """Parse a unit declaration ``"LENGTH, FORCE, TIME[, MASS]"`` (e.g. ``"in, lbf, s"``).

    Parameters
    ----------
    text : str
        Length, force and time units, comma-separated; an optional fourth entry, the mass
        unit, must equal the consistent ``F T^2 / L`` (else the declaration is inconsistent).
    where : str
        Where the declaration came from, for errors.
    wtmass : float, optional
        NASTRAN WTMASS (dimensionless, :data:`WTMASS_RANGE`; default 1, not a declaration).

    Returns
    -------
    UnitSystem
    """
    if not isinstance(text, str) or not text.strip():
        raise InputError(
            "no unit declaration",
            where=where,
            fix='state the units of the file, e.g. units = "in, lbf, s"',
        )
    parts = [p.strip() for p in text.split(",")]
    if len(parts) not in (3, 4) or not all(parts):
        raise InputError(
            f"{text!r} is not 'LENGTH, FORCE, TIME'",
            where=where,
            fix='write three units, e.g. "in, lbf, s" or "m, N, s"',
        )
    dims = ("length", "force", "time")
    factors = []
    for unit, dim in zip(parts[:3], dims, strict=True):
        try:
            factors.append(parse_quantity(f"1 {unit}", dim, where=where))
        except InputError as exc:
            raise InputError(
                f"{unit!r} is not a unit of {dim}: the mass unit cannot be derived",
                where=where,
                fix=f'give {dim} as the {dims.index(dim) + 1}. entry, e.g. "in, lbf, s"',
            ) from exc
    length, force, time = factors
    mass = force * time**2 / length
    if len(parts) == 4:
        declared = parse_quantity(f"1 {parts[3]}", "mass", where=where)
        if abs(declared - mass) > 1e-9 * mass:
            raise InputError(
                f"inconsistent units: {parts[3]!r} ({declared:.6g} kg) is not "
                f"{parts[1]}*{parts[2]}^2/{parts[0]} ({mass:.6g} kg)",
                where=where,
                fix="drop the mass unit (it is derived) or make it force*time^2/length",
            )
    w = 1.0
    if wtmass is not None:
        w = check_positive(wtmass, "wtmass")
        lo, hi = WTMASS_RANGE
        if not lo <= w <= hi:
            raise InputError(
                f"WTMASS {w:g} is outside {lo:g} to {hi:g}",
                where="wtmass",
                fix="give the run's PARAM,WTMASS (e.g. 0.00259 for lbf-s^2/in from lbm)",
            )
    return UnitSystem(text.strip(), length, force, time, mass, w, wtmass is not None)


def check_positive(value: Any, where: str) -> float:
    """``value`` as a float, or an InputError at ``where`` unless it is a finite number > 0.

    Parameters
    ----------
    value : Any
        The value as given (a bool is not a number).
    where : str
        The parameter or ``file: key``, for the error.
    """
    if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
        raise InputError(f"expected a positive number, got {value!r}", where=where)
    if value <= 0:
        raise InputError(f"must be > 0, got {value!r}", where=where)
    return float(value)
