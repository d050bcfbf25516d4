"""NASTRAN shell cards -> graph shells: CQUAD4, CTRIA3 with PSHELL and MAT1.

Read field by field as the MSC Nastran Quick Reference Guide lays them out, in the deck's
units, and converted to SI; :mod:`microg.models.bdf` calls :func:`shell_elements` and
:mod:`microg.structure.shells` holds the element (MITC4 and MITC3).

**PSHELL** ``PID MID1 T MID2 12I/T**3 MID3 TS/T NSM Z1 Z2 MID4``:

* membrane ``A = T C(MID1)``, bending ``D = (12I/T^3) T^3 / 12 C(MID2)``, transverse shear
  ``S = (TS/T) T G(MID3)``, with the plane-stress matrix of a MAT1
  ``C = [[E/(1-NU^2), NU E/(1-NU^2), 0], [NU E/(1-NU^2), E/(1-NU^2), 0], [0, 0, G]]``
  (NASTRAN's MAT1 rule fills a blank E, G or NU, :func:`~microg.models.bdf_properties.materials`);
  defaults 12I/T^3 = 1, TS/T = 0.833333.
* MID1 blank: no membrane; MID2 blank: a membrane (no bending, no transverse shear).
  MID3 blank with MID2: NASTRAN neglects transverse shear flexibility (thin-plate theory);
  microg gives ``S`` :data:`KIRCHHOFF_SHEAR` times ``(5/6) T G(MID2)``, which changes a plate
  frequency by about that factor's inverse times ``(T / span)^2`` (below 1e-6 of it for any
  plate thin enough to call thin).
* mass ``(RHO T + NSM) WTMASS`` per area, RHO from MID1 (MID2 when MID1 is blank), as NASTRAN.
* refused: MID2 = -1 (plane strain), MID4 (membrane-bending coupling), T blank.

**CQUAD4 / CTRIA3** ``EID PID G1 G2 G3 [G4] THETA/MCID ZOFFS``, continuation ``TFLAG T1...``:
THETA/MCID orient the material, which changes nothing for MAT1 (ignored); ZOFFS other than
0 and corner thicknesses other than T are refused.

**Drilling**: ``PARAM,K6ROT`` (default :data:`K6ROT_DEFAULT`, NASTRAN's default for linear
solutions, SOL 103 included, since MSC Nastran 2004 and in NX/Simcenter Nastran) scales the
penalty ``1e-6 K6ROT G T`` on the normal rotation.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from microg.models.bdf_cards import Card
from microg.models.bdf_properties import Material, Scales, material
from microg.models.graph_model import ShellElement, ShellSection

__all__ = ["K6ROT_DEFAULT", "KIRCHHOFF_SHEAR", "SHELL_CARDS", "TS_T_DEFAULT", "shell_elements"]

#: the shell cards this module reads
SHELL_CARDS = ("CQUAD4", "CTRIA3", "PSHELL")
#: NASTRAN's default PARAM,K6ROT (MSC Nastran 2004 and later, NX/Simcenter Nastran)
K6ROT_DEFAULT = 100.0
#: NASTRAN's default PSHELL TS/T
TS_T_DEFAULT = 0.833333
#: shear stiffness factor standing for NASTRAN's "no transverse shear flexibility" (MID3 blank)
KIRCHHOFF_SHEAR = 1.0e3

#: (corner grids, THETA/MCID, ZOFFS, TFLAG, first corner thickness) field indices
_LAYOUT = {"CQUAD4": (4, 7, 8, 10, 11), "CTRIA3": (3, 6, 7, 10, 11)}


def _plane_stress(m: Material, c: Card) -> np.ndarray:
    """MAT1's plane-stress matrix, Pa."""
    if not 1.0 - m.nu**2 > 0:
        raise c.error(f"material {m.card.raw(1)}: NU = {m.nu:g} gives no plane-stress matrix")
    q = m.e / (1.0 - m.nu**2)
    return np.array([[q, m.nu * q, 0.0], [m.nu * q, q, 0.0], [0.0, 0.0, m.g]])


def _section(
    c: Card, mats: dict[int, Material], sc: Scales, wt: float, k6rot: float
) -> ShellSection:
    """A PSHELL card as a section, SI."""
    mid1 = c.integer(2, "MID1", None)
    t = c.real(3, "T", None)
    mid2 = c.integer(4, "MID2", None)
    bend = c.real(5, "12I/T**3", 1.0)
    mid3 = c.integer(6, "MID3", None)
    ts = c.real(7, "TS/T", TS_T_DEFAULT)
    nsm = c.real(8, "NSM", 0.0)
    if t is None or not t > 0:
        raise c.error(f"T must be > 0, got {t}", "give the thickness T")
    if mid2 == -1:
        raise c.error("MID2 = -1 (plane strain) is not supported", "give a MID2 or leave it blank")
    if c.raw(11) not in (None, 0):
        raise c.error("MID4 (membrane-bending coupling) is not supported", "leave MID4 blank")
    if mid1 is None and mid2 is None:
        raise c.error("has neither MID1 nor MID2", "give MID1 (membrane) and MID2 (bending)")
    if not (bend >= 0 and ts > 0):
        raise c.error(f"12I/T**3 must be >= 0 and TS/T > 0, got {bend}, {ts}")
    tm = t * sc.length
    m1 = material(mats, mid1, c) if mid1 is not None else None
    m2 = material(mats, mid2, c) if mid2 is not None else None
    a = tm * _plane_stress(m1, c) if m1 is not None else np.zeros((3, 3))
    d = np.zeros((3, 3))
    s = np.zeros((2, 2))
    if m2 is not None:
        d = bend * tm**3 / 12.0 * _plane_stress(m2, c)
        if mid3 is not None:
            g3 = material(mats, mid3, c).g
            s = ts * tm * g3 * np.eye(2)
        else:
            s = KIRCHHOFF_SHEAR * (5.0 / 6.0) * tm * m2.g * np.eye(2)
        if not s[0, 0] > 0:
            raise c.error(
                "the transverse shear modulus G is zero (MAT1 with E only gives G = 0)",
                "give G or NU on the MAT1 card",
            )
    rho_mat = m1 if m1 is not None else m2
    assert rho_mat is not None
    mass = (rho_mat.rho * t + nsm) * wt * sc.mass / sc.length**2
    if mass < 0:
        raise c.error(f"mass per area must be >= 0, got {mass}")
    g = m1.g if m1 is not None else rho_mat.g
    return ShellSection(f"pshell:{c.raw(1)}", a, d, s, mass, 1e-6 * k6rot * g * tm)


def shell_elements(
    elements: dict[int, Card],
    props: dict[int, Card],
    mats: dict[int, Material],
    grid: Callable[[Any, Card, str], str],
    sc: Scales,
    wt: float,
    k6rot: float,
    origin: dict[str, Card],
) -> list[ShellElement]:
    """CQUAD4 and CTRIA3 cards as graph shells.

    Parameters
    ----------
    elements : dict of int to Card
        The deck's CQUAD4 and CTRIA3 cards by element id.
    props : dict of int to Card
        The PSHELL cards by property id.
    mats : dict of int to Material
        The MAT1 materials (SI moduli).
    grid : callable
        ``grid(gid, card, label)``: the node name of a defined grid, else the card's error.
    sc : Scales
        The deck's units.
    wt : float
        WTMASS.
    k6rot : float
        PARAM,K6ROT.
    origin : dict of str to Card
        Filled with each element's card, for messages.
    """
    sections: dict[int, ShellSection] = {}
    out: list[ShellElement] = []
    for eid, c in sorted(elements.items()):
        ng, _theta, zoffs, tflag_at, t_at = _LAYOUT[c.name]
        pid = c.integer(2, "PID", eid)
        if pid not in props:
            raise c.error(f"property {pid} (PSHELL) is not defined", "add it or correct PID")
        if pid not in sections:
            sections[pid] = _section(props[pid], mats, sc, wt, k6rot)
        if c.real(zoffs, "ZOFFS", 0.0) != 0.0:
            raise c.error("ZOFFS (offset of the mid-plane) is not supported", "leave ZOFFS blank")
        t = props[pid].real(3, "T")
        tflag = c.integer(tflag_at, "TFLAG", 0)
        for k in range(ng):
            ti = c.real(t_at + k, f"T{k + 1}", None)
            if ti is not None and abs((ti * t if tflag == 1 else ti) - t) > 1e-9 * t:
                raise c.error(
                    f"corner thickness T{k + 1} = {ti:g} differs from the PSHELL's T = {t:g}",
                    "give the PSHELL's thickness (variable thickness is not supported)",
                )
        ids = [c.raw(3 + k) for k in range(ng)]
        if len(set(ids)) != ng:
            raise c.error(f"corner grids {ids} repeat", "give distinct grids")
        nodes = tuple(grid(g, c, f"G{k + 1}") for k, g in enumerate(ids))
        name = f"{c.name.lower()}:{eid}"
        origin[name] = c
        out.append(ShellElement(name, nodes, sections[pid]))
    return out
