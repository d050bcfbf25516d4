"""NASTRAN property and material cards -> SI sections, springs and materials.

The cards that give elements their stiffness and mass: MAT1, PBAR, PBARL, PBEAM, PBEAML
(uniform), PBUSH and PELAS, read field by field as the MSC Nastran Quick Reference Guide
lays them out, in the deck's units (:class:`Scales`), and converted to SI.
:mod:`microg.models.bdf` attaches them to the elements.

**Shear flexibility** follows NASTRAN: PBAR K1, K2 (blank or 0: none), PBEAM K1, K2 (default
1.0; 0.0: none) and the PBARL/PBEAML section's own factor (:data:`SECTION_SHEAR_FACTORS`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from microg.models.bdf_cards import Card
from microg.models.graph_model import BeamSection

__all__ = [
    "SECTION_SHEAR_FACTORS",
    "BeamProperty",
    "Material",
    "Scales",
    "beam_properties",
    "beam_section",
    "bush_properties",
    "material",
    "materials",
    "scalar_spring_properties",
    "section_values",
]

#: transverse shear factors (K1, K2) NASTRAN gives PBARL/PBEAML sections.  ROD's 0.9 is
#: the value Simcenter Nastran prints for the beam_modes fixture (IFP9A echo); the others
#: are the textbook factors (thin tube 1/2, rectangle 5/6), not checked against NASTRAN
SECTION_SHEAR_FACTORS = {"ROD": 0.9, "TUBE": 0.5, "TUBE2": 0.5, "BAR": 5.0 / 6.0}
#: dimensions per PBARL/PBEAML type supported
_SECTION_DIMS = {"ROD": 1, "TUBE": 2, "TUBE2": 2, "BAR": 2}
_STRESS_SO = ("YES", "YESA", "NO")


@dataclass(frozen=True)
class Scales:
    """The deck's units in SI.

    Attributes
    ----------
    length : float
        One length unit, m.
    force : float
        One force unit, N.
    time : float
        One time unit, s.
    """

    length: float
    force: float
    time: float

    @property
    def mass(self) -> float:
        """The consistent mass unit FORCE TIME^2 / LENGTH, kg."""
        return self.force * self.time**2 / self.length


@dataclass(frozen=True)
class Material:
    """A MAT1 material: ``e``, ``g`` in Pa, ``nu``; ``rho`` and ``ge`` as written (deck units)."""

    e: float
    g: float
    nu: float
    rho: float
    ge: float
    card: Card


@dataclass(frozen=True)
class BeamProperty:
    """A PBAR/PBARL/PBEAM/PBEAML section in deck units (A, I1, I2, I12, J, NSM, K1, K2, MID)."""

    a: float
    i1: float
    i2: float
    i12: float
    j: float
    nsm: float
    k1: float | None
    k2: float | None
    mid: int
    card: Card


def section_values(
    kind: str, dims: list[float], card: Card
) -> tuple[float, float, float, float, float]:
    """A, I1, I2, J and the shear factor of a PBARL/PBEAML section (deck units).

    ROD and TUBE: the circle's ``pi r^2``, ``pi r^4 / 4`` and ``J = 2 I``; BAR (DIM1 x DIM2):
    ``I1 = DIM1 DIM2^3 / 12`` (pyNastran's convention) and Roark's torsion constant of a
    rectangle.

    Parameters
    ----------
    kind : {"ROD", "TUBE", "TUBE2", "BAR"}
    dims : list of float
        DIM1, DIM2 (deck length unit).
    card : Card
        The property card, for errors.
    """
    if any(not d > 0 for d in dims):
        raise card.error(f"section {kind} dimensions must be > 0, got {dims}")
    k = SECTION_SHEAR_FACTORS[kind]
    if kind == "ROD":
        r = dims[0]
        a = math.pi * r**2
        i = math.pi * r**4 / 4.0
        return a, i, i, 2.0 * i, k
    if kind in ("TUBE", "TUBE2"):
        ro = dims[0]
        ri = dims[1] if kind == "TUBE" else dims[0] - dims[1]
        if not 0 <= ri < ro:
            raise card.error(f"{kind} needs an inner radius between 0 and the outer, got {dims}")
        a = math.pi * (ro**2 - ri**2)
        i = math.pi * (ro**4 - ri**4) / 4.0
        return a, i, i, 2.0 * i, k
    # BAR: DIM1 x DIM2, I1 = DIM1 DIM2^3 / 12 (pyNastran's convention), Roark's J
    b, h = dims
    long_, short = max(b, h), min(b, h)
    j = long_ * short**3 * (1.0 / 3.0 - 0.21 * short / long_ * (1.0 - short**4 / (12.0 * long_**4)))
    return b * h, b * h**3 / 12.0, h * b**3 / 12.0, j, k


def materials(cards: dict[int, Card], sc: Scales) -> dict[int, Material]:
    """MAT1 cards as materials, E and G in Pa.

    A blank E or G follows from the other and NU (``G = E / (2 (1 + NU))``); a blank NU
    from E and G.

    Parameters
    ----------
    cards : dict of int to Card
        The deck's MAT1 cards by material id.
    sc : Scales
        The deck's units.
    """
    out: dict[int, Material] = {}
    for mid, c in cards.items():
        e = c.real(2, "E", None)
        g = c.real(3, "G", None)
        nu = c.real(4, "NU", None)
        if not e and not g:
            raise c.error("E and G are both blank or zero", "give E (and NU or G)")
        if e and g is None:
            g = e / (2.0 * (1.0 + nu)) if nu is not None else 0.0
        elif g and e is None:
            e = 2.0 * (1.0 + nu) * g if nu is not None else 0.0
        if nu is None:
            nu = e / (2.0 * g) - 1.0 if e and g else 0.0
        rho = c.real(5, "RHO", 0.0)
        ge = c.real(8, "GE", 0.0)
        assert e is not None and g is not None
        if e < 0 or g < 0 or rho < 0:
            raise c.error("E, G and RHO must be >= 0")
        out[mid] = Material(
            e * sc.force / sc.length**2, g * sc.force / sc.length**2, nu, rho, ge, c
        )
    return out


def material(mats: dict[int, Material], mid: int, c: Card) -> Material:
    """Material ``mid``, or an error at card ``c`` that refers to it.

    Parameters
    ----------
    mats : dict of int to Material
    mid : int
        The material id ``c`` names.
    c : Card
        The referring card.
    """
    if mid not in mats:
        raise c.error(f"material {mid} (MAT1) is not defined", "add the MAT1 card or correct MID")
    return mats[mid]


def beam_properties(cards: dict[int, Card], warnings: list[str]) -> dict[int, BeamProperty]:
    """PBAR, PBARL, PBEAM and PBEAML cards as sections (deck units).

    Parameters
    ----------
    cards : dict of int to Card
        The property cards by id.
    warnings : list of str
        Appended to: what is read and ignored (PBEAM warping coefficients).
    """
    out: dict[int, BeamProperty] = {}
    for pid, c in cards.items():
        mid = c.integer(2, "MID")
        if c.name == "PBAR":
            k1 = c.real(17, "K1", None)
            k2 = c.real(18, "K2", None)
            prop = BeamProperty(
                c.real(3, "A", 0.0),
                c.real(4, "I1", 0.0),
                c.real(5, "I2", 0.0),
                c.real(19, "I12", 0.0),
                c.real(6, "J", 0.0),
                c.real(7, "NSM", 0.0),
                k1 if k1 else None,
                k2 if k2 else None,
                mid,
                c,
            )
        elif c.name == "PBEAM":
            prop = _pbeam(c, mid, warnings)
        else:
            prop = _pbarl(c, mid)
        out[pid] = prop
    return out


def _pbarl(c: Card, mid: int) -> BeamProperty:
    group = c.text(3, "GROUP", "MSCBML0")
    kind = c.text(4, "TYPE")
    if group != "MSCBML0":
        raise c.error(f"section group {group!r} is not supported", "use the MSCBML0 library")
    if kind not in _SECTION_DIMS:
        raise c.error(
            f"section type {kind!r} is not supported (microg knows {', '.join(_SECTION_DIMS)})",
            "give the section as PBAR/PBEAM with A, I1, I2, J, K1, K2",
        )
    n = _SECTION_DIMS[kind]
    dims = [c.real(9 + k, f"DIM{k + 1}") for k in range(n)]
    nsm = c.real(9 + n, "NSM", 0.0)
    if c.name == "PBEAML":
        i = 10 + n
        while i < len(c):  # further stations: SO, X/XB, dims, NSM; uniform only
            sd = [c.real(i + 2 + k, f"DIM{k + 1}", dims[k]) for k in range(n)]
            snsm = c.real(i + 2 + n, "NSM", nsm)
            if not np.allclose(sd, dims, rtol=1e-9) or not math.isclose(snsm, nsm, rel_tol=1e-9):
                raise c.error(
                    "tapered sections are not supported", "give a uniform section (one station)"
                )
            i += 3 + n
    elif len(c) > 10 + n:
        raise c.error("has fields beyond DIMs and NSM")
    a, i1, i2, j, k = section_values(kind, dims, c)
    return BeamProperty(a, i1, i2, 0.0, j, nsm, k, k, mid, c)


def _pbeam(c: Card, mid: int, warnings: list[str]) -> BeamProperty:
    a = c.real(3, "A")
    i1 = c.real(4, "I1", 0.0)
    i2 = c.real(5, "I2", 0.0)
    i12 = c.real(6, "I12", 0.0)
    j = c.real(7, "J", 0.0)
    nsm = c.real(8, "NSM", 0.0)
    i = 9
    if i < len(c) and not isinstance(c.raw(9), str):
        i = 17  # stress recovery points at end A
    end_a = (a, i1, i2, i12, j, nsm)
    while i < len(c) and isinstance(c.raw(i), str):
        so = c.text(i, "SO")
        if so not in _STRESS_SO:
            raise c.error(f"SO {so!r} must be YES, YESA or NO")
        vals = tuple(c.real(i + 2 + k, "station value", end_a[k]) for k in range(6))
        if not np.allclose(vals, end_a, rtol=1e-9, atol=0.0):
            raise c.error("tapered beams are not supported", "give a uniform PBEAM (end B = end A)")
        i += 16 if so == "YES" else 8
    k1 = c.real(i, "K1", 1.0)
    k2 = c.real(i + 1, "K2", 1.0)
    extra = [c.real(i + k, "field", 0.0) for k in range(4, 16)]
    nsi = extra[0:2]
    cw = extra[2:4]
    mn = extra[4:12]
    if any(mn) or any(nsi):
        raise c.error(
            "non-structural mass inertia or offsets (NSI, M1-N2) are not supported",
            "remove them or model the offset mass with CONM2",
        )
    if any(cw):
        warnings.append(f"{c.where}: warping coefficients CW ignored (no warping DOFs)")
    return BeamProperty(a, i1, i2, i12, j, nsm, k1 or None, k2 or None, mid, c)


def beam_section(prop: BeamProperty, mat: Material, wt: float, sc: Scales) -> BeamSection:
    """The SI section of a beam property and its material.

    ``EA``, ``E I2`` (about local y), ``E I1`` (about local z), ``GJ``; mass per length
    ``rho A + NSM`` and polar mass moment ``rho (I1 + I2)`` (input mass times ``wt``);
    shear stiffness ``K G A`` per plane; ``E I12``.

    Parameters
    ----------
    prop : BeamProperty
    mat : Material
    wt : float
        WTMASS: input mass to FORCE TIME^2 / LENGTH.
    sc : Scales
        The deck's units.
    """
    L2, L4 = sc.length**2, sc.length**4
    a, i1, i2, j = prop.a * L2, prop.i1 * L4, prop.i2 * L4, prop.j * L4
    c = prop.card
    if not (a > 0 and i1 > 0 and i2 > 0 and j > 0):
        raise c.error(
            f"A, I1, I2 and J must be > 0 for a beam, got {prop.a}, {prop.i1}, {prop.i2}, {prop.j}"
        )
    if mat.g <= 0:
        raise mat.card.error(
            "G is zero: the beams using it have no torsional stiffness", "give G or NU"
        )
    rho = mat.rho * wt * sc.mass / sc.length**3
    nsm = prop.nsm * wt * sc.mass / sc.length
    mpl = rho * a + nsm
    shear = [None if k is None else k * mat.g * a for k in (prop.k1, prop.k2)]
    return BeamSection(
        f"{c.name.lower()}:{c.raw(1)}",
        mat.e * a,
        mat.e * i2,
        mat.e * i1,
        mat.g * j,
        mpl,
        rho * (i1 + i2),
        shear[0],
        shear[1],
        0.0,
        0.0,
        mat.e * prop.i12 * L4,
    )


def bush_properties(
    cards: dict[int, Card], sc: Scales
) -> dict[int, tuple[np.ndarray, np.ndarray, float]]:
    """PBUSH cards as (stiffness 6x6, damping 6x6, GE), SI, diagonal in the bush axes.

    Parameters
    ----------
    cards : dict of int to Card
        The PBUSH cards by id (K, B, GE and RCV lines).
    sc : Scales
        The deck's units: K in F/L and F L/rad, B in F T/L and F L T/rad.
    """
    props: dict[int, tuple[np.ndarray, np.ndarray, float]] = {}
    for pid, c in cards.items():
        k = np.zeros(6)
        b = np.zeros(6)
        ge = 0.0
        i = 2
        while i < len(c):
            kw = c.raw(i)
            vals = [c.real(i + 1 + m, f"{kw}{m + 1}", 0.0) for m in range(6)]
            if kw == "K":
                k = np.array(vals)
            elif kw == "B":
                b = np.array(vals)
            elif kw == "GE":
                ge = vals[0]
                if any(v not in (0.0, ge) for v in vals[1:]):
                    raise c.error("GE per direction is not supported", "give one GE1")
            elif kw not in ("RCV", None):
                raise c.error(f"PBUSH line {kw!r} is not supported (K, B, GE, RCV are)")
            i += 8
        if np.any(k < 0) or np.any(b < 0):
            raise c.error("negative stiffness or damping")
        kscale = np.array([sc.force / sc.length] * 3 + [sc.force * sc.length] * 3)
        props[pid] = (np.diag(k * kscale), np.diag(b * kscale * sc.time), ge)
    return props


def scalar_spring_properties(cards: list[Card]) -> dict[int, tuple[float, float, Card]]:
    """PELAS cards (two properties per card) as (K, GE, card) by id, deck units.

    Parameters
    ----------
    cards : list of Card
        The deck's PELAS cards.
    """
    pelas: dict[int, tuple[float, float, Card]] = {}
    for c in cards:
        for base in (1, 5):
            pid = c.raw(base)
            if pid is None:
                continue
            if not isinstance(pid, int) or pid in pelas:
                raise c.error(f"PELAS id {pid!r} is invalid or duplicate")
            pelas[pid] = (c.real(base + 1, "K"), c.real(base + 2, "GE", 0.0), c)
    return pelas
