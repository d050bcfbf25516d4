"""The seed report's IOC model: its printed values and its four-coordinate reduction.

The shipped model files (``data/ioc.toml``, ``data/ioc-no-orbiter.toml``) describe the
station physically, with the two halves of the solar boom as two beams.  The report's
four coordinates (Eq. 2.21: translation, rotation ``q2 = theta l_k``, keel bending, boom
bending) are the five assumed-modes coordinates with both half-booms tied to one ``q4``:
in the X-Z plane the halves bend together (symmetric), in the Y-Z plane against each
other; the report measures that ``q4`` with the opposite sign (A-6: ``- psi4 q4``).
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import Any

import numpy as np

from microg.defaults import PRESETS
from microg.errors import InputError
from microg.models.station import Station
from microg.structure.ritz import build_ritz
from microg.structure.structure import Structure
from microg.units import FT, LBF, SLUG

__all__ = [
    "PRINTED",
    "CASES",
    "FT",
    "SLUG",
    "LBF",
    "printed",
    "printed_literals",
    "half_unit",
    "ReportMatrices",
    "report_reduction",
    "report_matrices",
    "report_stiffness_us",
]

#: the four cases of Appendix C / Table 4: (plane, orbiter attached)
CASES: dict[str, tuple[str, bool]] = {
    "xz_orbiter": ("xz", True),
    "xz_no_orbiter": ("xz", False),
    "yz_orbiter": ("yz", True),
    "yz_no_orbiter": ("yz", False),
}


@cache
def printed() -> dict[str, Any]:
    """The report's printed values (``data/_seed_printed.toml``)."""
    text = resources.files("microg").joinpath("data/_seed_printed.toml").read_text("utf-8")
    return tomllib.loads(text)


#: a number literal in a value position of the printed-values file
_NUMBER = re.compile(
    r"(?<=[=\[,])(\s*)([+-]?\d[\d_]*(?:\.\d+)?(?:[eE][+-]?\d+)?)(?=\s*(?:[,\]]|$))",
    re.M,
)


@cache
def printed_literals() -> dict[str, Any]:
    """The printed values as their literal text (``"2.730"``, ``"0.254e-8"``), same layout.

    ``tomllib`` turns ``2.730`` into the float 2.73 and loses the printed digit; this reads
    the file with every number literal quoted, so that :func:`half_unit` sees the digits
    as printed.  Comments are dropped first (the file has no ``#`` inside strings).
    """
    text = resources.files("microg").joinpath("data/_seed_printed.toml").read_text("utf-8")
    body = "\n".join(line.split("#", 1)[0] for line in text.splitlines())
    return tomllib.loads(_NUMBER.sub(lambda m: f'{m.group(1)}"{m.group(2)}"', body))


def half_unit(text: str) -> float:
    """Half a unit in the last printed digit of a number literal (the rounding it hides).

    ``"1.0431"`` -> 5e-5, ``"2.730"`` -> 5e-4, ``"0.254e-8"`` -> 5e-12, ``"1096"`` -> 0.5.
    An integer's trailing zeros are ambiguous: they count as significant up to the fourth
    significant digit, the precision the report prints its matrices with (``"18900"``, its
    m11 = 608,600 lb / 32.2 = 18,900.6 slug, -> 5; ``"608600"`` -> 50).

    Parameters
    ----------
    text : str
        A number literal as printed (optional sign, decimals, exponent).
    """
    t = text.strip().lstrip("+-").replace("_", "").lower()
    mant, _, exp = t.partition("e")
    e = int(exp) if exp else 0
    if "." in mant:
        return 0.5 * 10.0 ** (e - len(mant.split(".", 1)[1]))
    digits = mant.lstrip("0") or "0"
    zeros = len(digits) - len(digits.rstrip("0"))
    significant = len(digits) - zeros
    kept = min(zeros, max(0, 4 - significant))  # trailing zeros read as significant
    return 0.5 * 10.0 ** (e + zeros - kept)


class _Printed(dict):
    def __missing__(self, key: str) -> Any:
        self.update(printed())
        return dict.__getitem__(self, key)


#: lazily loaded printed values of the report
PRINTED: dict[str, Any] = _Printed()


@dataclass(frozen=True)
class ReportMatrices:
    """The report's 4x4 matrices of a station in one plane.

    Attributes
    ----------
    plane : str
    mass : ndarray (4, 4)
        Generalized mass, kg (coordinates are lengths, m).
    stiffness : ndarray (4, 4)
        Generalized stiffness, N/m.
    mass_us : ndarray (4, 4)
        The same in slug (as Appendix C prints it).
    stiffness_us : ndarray (4, 4)
        lbf/ft.
    reduction : ndarray (n, 4)
        Map from the report's coordinates to the assumed-modes coordinates.
    """

    plane: str
    mass: np.ndarray
    stiffness: np.ndarray
    mass_us: np.ndarray
    stiffness_us: np.ndarray
    reduction: np.ndarray


def report_reduction(structure: Structure) -> np.ndarray:
    """Map (n, 4) from the report's q1..q4 to a one-function-per-beam IOC structure.

    Needs coordinates ``translation``, ``rotation``, ``keel:1``, ``boom+y:1``, ``boom-y:1``.
    """
    labels = list(structure.dof_labels)
    need = ["translation", "rotation", "keel:1", "boom+y:1", "boom-y:1"]
    missing = [n for n in need if n not in labels]
    if missing:
        raise InputError(
            f"not the report's IOC layout: coordinates {missing} are missing",
            fix="use the shipped 'ioc' model (keel, boom+y, boom-y) with one function per beam",
        )
    t = np.zeros((len(labels), 4))
    t[labels.index("translation"), 0] = 1.0
    t[labels.index("rotation"), 1] = 1.0
    t[labels.index("keel:1"), 2] = 1.0
    sign = 1.0 if structure.plane == "xz" else -1.0
    t[labels.index("boom+y:1"), 3] = sign
    t[labels.index("boom-y:1"), 3] = sign
    return t


def report_matrices(
    station: Station, plane: str, *, gravity_gradient: bool = False
) -> ReportMatrices:
    """The report's 4x4 mass and stiffness of ``station`` (Appendices A and B).

    Parameters
    ----------
    station : Station
        The IOC model (keel and two half-booms).
    plane : {"xz", "yz"}
    gravity_gradient : bool
        Include the gravity-gradient k22 (Appendix B-2 with the 1/l_k^2 factor).
    """
    s = build_ritz(
        station, plane, PRESETS["report"]["functions"], gravity_gradient=gravity_gradient
    )
    t = report_reduction(s)
    m = t.T @ s.mass @ t
    k = t.T @ s.stiffness @ t
    return ReportMatrices(plane, m, k, m / SLUG, k / (LBF / FT), t)


def report_stiffness_us(ei: float, l_k: float, l_s: float) -> np.ndarray:
    """The report's stiffness diag(0, 0, k33, k44), lbf/ft (Appendix B-1).

    ``k33 = 4 EI/(3 l_k^3)``, ``k44 = 4 EI/(3 l_s^3)``: k44 counts one cantilever of the
    boom although the boom's mass counts both halves (see the errata).

    Parameters
    ----------
    ei : float
        Bending stiffness, lbf ft^2.
    l_k, l_s : float
        Keel and boom lengths, ft.
    """
    return np.diag([0.0, 0.0, 4 * ei / (3 * l_k**3), 4 * ei / (3 * l_s**3)])
