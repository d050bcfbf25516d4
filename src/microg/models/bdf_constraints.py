"""NASTRAN deck cards of scalar points, scalar elements, rigid elements and constraints.

The conversions :mod:`microg.models.bdf` delegates for these cards (each function takes the
deck converter, ``deck``, for its cards, scales, warnings and id look-ups):

* **SPOINT** (``id ... `` or ``id1 THRU id2``): scalar points, one DOF each, nodes named
  ``"spoint:ID"`` (:attr:`~microg.models.graph_model.Node.scalar`); their ids share the
  grids' id space (a clash is an error) and the nodes are ordered by id, grids and scalar
  points together, as NASTRAN numbers its g-set.  A scalar point's component is 0 or blank;
  it is scaled as a translation (the deck's length unit), so that a spring and a mass on it
  keep their ratio.  ESPOINT (extra points) is refused as an unsupported card.
* **Scalar elements** on grid components or scalar points: CELAS1 (+ PELAS), CELAS2,
  CMASS1 (+ PMASS), CMASS2, CDAMP1 (+ PDAMP), CDAMP2.  Units by the two components: both
  translations (or scalar points) F/L (mass F T^2/L, damping F T/L), both rotations F L
  (mass F T^2 L, damping F L T), mixed F (F T^2, F T).  Masses are multiplied by WTMASS.
* **RBE2** (GN, CM, GMi; ALPHA ignored) and **RBE3** (REFGRID, REFC, WTi/Ci/Gi,j with any
  of components 1-6, ``UM`` with GMi/CMi as the dependent components instead, ``ALPHA``
  and what follows ignored: thermal).  The fit is NASTRAN's
  (:func:`microg.structure.elements.interpolation_matrix`).
* **MPC** / **MPCADD**: ``sum_j A_j u_j = 0``, first term dependent; the set applied is the
  case control's ``MPC = n`` (or ``load_bdf(mpc=n)``).  As in NASTRAN, a set not selected is
  not applied (noted), and a selected set the bulk data does not define is a warning
  (NX's USER WARNING 2047).  Coefficients become SI per component unit (per m, per rad).
* **SPC**, **SPC1**, **SPCADD**: the SPC set noted as the model's constraints (``SPC = n``
  or ``load_bdf(spc=n)``), on grids and scalar points.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from microg.errors import InputError
from microg.models.bdf_cards import Card
from microg.models.bdf_properties import scalar_spring_properties
from microg.models.graph_model import (
    Constraint,
    Interpolation,
    MultiPointConstraint,
    RigidLink,
    ScalarMass,
    ScalarSpring,
)

__all__ = [
    "constraints",
    "mpcs",
    "point_dof",
    "rigid",
    "scalar_dampers",
    "scalar_masses",
    "scalar_points",
    "scalar_springs",
]


def scalar_points(deck: Any) -> list[int]:
    """The SPOINT ids of the deck, sorted (``THRU`` ranges expanded).

    Parameters
    ----------
    deck : the deck converter (``microg.models.bdf``'s), for its cards.
    """
    ids: set[int] = set()
    for c in deck.cards:
        if c.name != "SPOINT":
            continue
        vals = [v for v in c.fields[1:] if v is not None]
        k = 0
        while k < len(vals):
            v = vals[k]
            if k + 2 < len(vals) and vals[k + 1] == "THRU":
                lo, hi = v, vals[k + 2]
                if not (isinstance(lo, int) and isinstance(hi, int) and 0 < lo <= hi):
                    raise c.error(f"SPOINT range {lo!r} THRU {hi!r} is not valid")
                if hi - lo >= 10_000_000:
                    raise c.error(f"SPOINT range {lo} THRU {hi} is too large")
                ids.update(range(lo, hi + 1))
                k += 3
                continue
            if not (isinstance(v, int) and v > 0):
                raise c.error(f"SPOINT id {v!r} must be a positive integer")
            ids.add(v)
            k += 1
    return sorted(ids)


def point_dof(deck: Any, gid: Any, comp: Any, c: Card, label: str) -> tuple[str, int]:
    """(node, component 1-6) of a grid component, or (scalar point, 1) of a scalar point.

    Parameters
    ----------
    deck : the deck converter.
    gid : the id field.
    comp : the component field (1-6 for a grid; 0 or blank for a scalar point).
    c : Card
        The card, for errors.
    label : str
        The field's name (``G1``).
    """
    if isinstance(gid, int) and gid in deck.spoint_ids:
        if comp not in (None, 0):
            raise c.error(
                f"{label} {gid} is a scalar point: its component is 0 or blank, got {comp!r}"
            )
        return f"spoint:{gid}", 1
    if not isinstance(gid, int) or gid not in deck.grid_cards:
        raise c.error(
            f"{label} {gid!r} is neither a GRID nor an SPOINT", "add the GRID or SPOINT card"
        )
    if not isinstance(comp, int) or comp not in range(1, 7):
        raise c.error(f"component {comp!r} of grid {gid} must be 1-6")
    return f"grid:{gid}", comp


def _scale(dofs: list[tuple[str, int]], trans: float, mixed: float, rot: float) -> float:
    """The SI factor of a scalar element by the kinds of its components."""
    kinds = [comp > 3 for _, comp in dofs]
    n_rot = sum(kinds)
    return trans if n_rot == 0 else rot if n_rot == len(kinds) else mixed


def _ends(deck: Any, c: Card, fields: tuple[tuple[int, int], ...]) -> list[tuple[str, int] | None]:
    out: list[tuple[str, int] | None] = []
    for gi, ci in fields:
        g = c.raw(gi)
        if g in (None, 0):
            out.append(None)
            continue
        out.append(point_dof(deck, g, c.raw(ci), c, f"G{len(out) + 1}"))
    if all(d is None for d in out):
        raise c.error("connects no grid or scalar point")
    return out


def _pairs(cards: list[Card], what: str) -> dict[int, float]:
    """PMASS/PDAMP: up to four (PID, value) pairs per card, by id (deck units)."""
    out: dict[int, float] = {}
    for c in cards:
        for base in (1, 3, 5, 7):
            pid = c.raw(base)
            if pid is None:
                continue
            if not isinstance(pid, int) or pid in out:
                raise c.error(f"{what} id {pid!r} is invalid or duplicate")
            out[pid] = c.real(base + 1, "value")
    return out


def scalar_springs(deck: Any) -> list[ScalarSpring]:
    """CELAS1 (PELAS) and CELAS2 as scalar springs, SI (GE kept, S ignored).

    Parameters
    ----------
    deck : the deck converter.
    """
    sc = deck.sc
    pelas = scalar_spring_properties([c for c in deck.cards if c.name == "PELAS"])
    out: list[ScalarSpring] = []
    for eid, c in deck.by_id(("CELAS1", "CELAS2"), "element").items():
        if c.name == "CELAS1":
            pid = c.integer(2, "PID", eid)
            if pid not in pelas:
                raise c.error(
                    f"property {pid} (PELAS) is not defined", "add the PELAS card or correct PID"
                )
            k, ge, _ = pelas[pid]
        else:
            k, ge = c.real(2, "K"), c.real(7, "GE", 0.0)
        ends = _ends(deck, c, ((3, 4), (5, 6)))
        scale = _scale(
            [d for d in ends if d is not None],
            sc.force / sc.length,
            sc.force,
            sc.force * sc.length,
        )
        ename = f"{c.name.lower()}:{eid}"
        deck.origin[ename] = c
        out.append(ScalarSpring(ename, (ends[0], ends[1]), k * scale, 0.0, ge))
    return out


def scalar_dampers(deck: Any) -> list[ScalarSpring]:
    """CDAMP1 (PDAMP) and CDAMP2 as scalar springs of no stiffness (viscous damping), SI.

    Parameters
    ----------
    deck : the deck converter.
    """
    sc = deck.sc
    pdamp = _pairs([c for c in deck.cards if c.name == "PDAMP"], "PDAMP")
    out: list[ScalarSpring] = []
    for eid, c in deck.by_id(("CDAMP1", "CDAMP2"), "element").items():
        if c.name == "CDAMP1":
            pid = c.integer(2, "PID", eid)
            if pid not in pdamp:
                raise c.error(
                    f"property {pid} (PDAMP) is not defined", "add the PDAMP card or correct PID"
                )
            b = pdamp[pid]
        else:
            b = c.real(2, "B")
        ends = _ends(deck, c, ((3, 4), (5, 6)))
        scale = _scale(
            [d for d in ends if d is not None],
            sc.force * sc.time / sc.length,
            sc.force * sc.time,
            sc.force * sc.length * sc.time,
        )
        ename = f"{c.name.lower()}:{eid}"
        deck.origin[ename] = c
        out.append(ScalarSpring(ename, (ends[0], ends[1]), 0.0, b * scale, 0.0))
    return out


def scalar_masses(deck: Any, wt: float) -> list[ScalarMass]:
    """CMASS1 (PMASS) and CMASS2 as scalar masses, SI, multiplied by WTMASS ``wt``.

    Parameters
    ----------
    deck : the deck converter.
    wt : float
        WTMASS.
    """
    sc = deck.sc
    pmass = _pairs([c for c in deck.cards if c.name == "PMASS"], "PMASS")
    out: list[ScalarMass] = []
    for eid, c in deck.by_id(("CMASS1", "CMASS2"), "element").items():
        if c.name == "CMASS1":
            pid = c.integer(2, "PID", eid)
            if pid not in pmass:
                raise c.error(
                    f"property {pid} (PMASS) is not defined", "add the PMASS card or correct PID"
                )
            m = pmass[pid]
        else:
            m = c.real(2, "M")
        if not m >= 0:
            raise c.error(f"mass must be >= 0, got {m}")
        ends = _ends(deck, c, ((3, 4), (5, 6)))
        scale = _scale(
            [d for d in ends if d is not None],
            sc.mass,
            sc.mass * sc.length,
            sc.mass * sc.length**2,
        )
        ename = f"{c.name.lower()}:{eid}"
        deck.origin[ename] = c
        out.append(ScalarMass(ename, (ends[0], ends[1]), m * wt * scale))
    return out


def rigid(deck: Any, pos: dict[int, np.ndarray]) -> tuple[list[RigidLink], list[Interpolation]]:
    """RBE2 as rigid links, RBE3 as interpolations (rotations among Ci, UM; ALPHA ignored).

    Parameters
    ----------
    deck : the deck converter.
    pos : dict of int to ndarray
        Grid positions, for the id checks.
    """
    links: list[RigidLink] = []
    interps: list[Interpolation] = []
    for eid, c in deck.by_id(("RBE2",), "element").items():
        gn = deck.grid(c.raw(2), c, pos, "GN")
        cm = deck.components(c.raw(3), c, "CM")
        deps = []
        for k in range(4, len(c)):
            v = c.raw(k)
            if v is None:
                continue
            if isinstance(v, float) and k == len(c) - 1:
                break  # ALPHA (thermal expansion)
            if not isinstance(v, int):
                raise c.error(f"field {k + 1}: expected a grid id, got {v!r}")
            deps.append(deck.grid(v, c, pos, "GM"))
        if not deps:
            raise c.error("has no dependent grid")
        ename = f"rbe2:{eid}"
        deck.origin[ename] = c
        links.append(RigidLink(ename, gn, tuple(deps), cm))
    for eid, c in deck.by_id(("RBE3",), "element").items():
        interps.append(_rbe3(deck, eid, c, pos))
    return links, interps


def _rbe3(deck: Any, eid: int, c: Card, pos: dict[int, np.ndarray]) -> Interpolation:
    ref = deck.grid(c.raw(3), c, pos, "REFGRID")
    refc = deck.components(c.raw(4), c, "REFC")
    srcs: list[tuple[str, str, float]] = []
    moved: list[tuple[str, str]] = []
    k = 5
    n = len(c)
    while k < n:
        v = c.raw(k)
        if v is None:
            k += 1
            continue
        if v == "ALPHA":
            break  # ALPHA (and TREF): thermal, no stiffness or mass
        if v == "UM":
            k += 1
            while k < n and c.raw(k) != "ALPHA":
                g = c.raw(k)
                if g is None:
                    k += 1
                    continue
                node = deck.grid(g, c, pos, "GM")
                moved.append((node, deck.components(c.raw(k + 1), c, "CM")))
                k += 2
            break
        if isinstance(v, str):
            raise c.error(f"field {k + 1}: {v!r} is not a weight, UM or ALPHA")
        w = float(v)
        if not w > 0:
            raise c.error(f"weight WT {w:g} must be > 0")
        comps = deck.components(c.raw(k + 1), c, "C")
        k += 2
        gids = []
        while k < n and isinstance(c.raw(k), int | type(None)):
            if c.raw(k) is not None:
                gids.append(c.raw(k))
            k += 1
        if not gids:
            raise c.error(f"weight {w:g} has no grid")
        srcs += [(deck.grid(g, c, pos, "G"), comps, w) for g in gids]
    if not srcs:
        raise c.error("has no independent grid")
    ename = f"rbe3:{eid}"
    deck.origin[ename] = c
    return Interpolation(ename, ref, refc, tuple(srcs), tuple(moved))


def _selected(deck: Any, kind: str, defined: list[int], user: int | None) -> int | None:
    """The set the case control (or the caller) selects for ``kind`` (SPC, MPC)."""
    if user is not None:
        return user
    picks = sorted(
        {int(m.group(1)) for ln in deck.case if (m := re.match(rf"{kind}\s*=\s*(\d+)", ln))}
    )
    if len(picks) > 1:
        what = "constraints" if kind == "SPC" else "MPCs"
        deck.warnings.append(f"case control selects {kind} sets {picks}; {what} from {picks[0]}")
    if picks:
        return picks[0]
    if kind == "SPC" and len(defined) == 1:
        return defined[0]
    return None


def mpcs(deck: Any) -> list[MultiPointConstraint]:
    """The selected MPC set (MPCADD resolved) as multipoint constraints, SI coefficients.

    Parameters
    ----------
    deck : the deck converter (``user_mpc``: the set asked for, or None).
    """
    sc = deck.sc
    sets: dict[int, list[tuple[Card, list[tuple[str, int, float]]]]] = {}
    adds: dict[int, list[int]] = {}
    for c in deck.cards:
        if c.name == "MPC":
            sid = c.integer(1, "SID")
            terms: list[tuple[str, int, float]] = []
            for base in range(2, len(c), 8):
                for off in (0, 3):
                    g = c.raw(base + off)
                    if (
                        g is None
                        and c.raw(base + off + 1) is None
                        and c.raw(base + off + 2) is None
                    ):
                        continue
                    node, comp = point_dof(deck, g, c.raw(base + off + 1), c, "G")
                    a = c.real(base + off + 2, "A")
                    # sum A u = 0 in deck units: a translation's u_deck = u_SI / L
                    unit = 1.0 if comp > 3 and node.startswith("grid:") else sc.length
                    terms.append((node, comp, a / unit))
            if not terms:
                raise c.error("has no term")
            if terms[0][2] == 0:
                raise c.error("the first (dependent) coefficient A1 is zero")
            sets.setdefault(sid, []).append((c, terms))
        elif c.name == "MPCADD":
            sid = c.integer(1, "SID")
            adds[sid] = [v for v in c.fields[2:] if isinstance(v, int)]
    defined = sorted(set(sets) | set(adds))
    deck.mpc_sets = defined
    chosen = _selected(deck, "MPC", defined, deck.user_mpc)
    if chosen is None:
        if defined:
            deck.warnings.append(
                f"MPC sets {defined} present, none selected (case control MPC = n): not "
                "applied, as in NASTRAN"
            )
        return []
    if chosen not in defined:
        if deck.user_mpc is not None:
            raise InputError(
                f"MPC set {chosen} is not defined", where=deck.path, fix=f"defined: {defined}"
            )
        deck.warnings.append(
            f"case control selects MPC set {chosen}, which the bulk data does not define: no "
            "MPC applied (NASTRAN's USER WARNING 2047)"
        )
        return []
    out: list[MultiPointConstraint] = []
    for sid in adds.get(chosen, [chosen]):
        if sid not in sets:
            raise InputError(
                f"MPCADD {chosen} names MPC set {sid}, which is not defined",
                where=deck.path,
                fix=f"defined: {sorted(sets)}",
            )
        for k, (c, terms) in enumerate(sets[sid]):
            name = f"mpc:{sid}#{k + 1}"
            deck.origin[name] = c
            out.append(MultiPointConstraint(name, tuple(terms)))
    return out


def constraints(deck: Any, pos: dict[int, np.ndarray]) -> list[Constraint]:
    """The selected SPC set (SPC, SPC1, SPCADD) as constraints on grids and scalar points.

    Parameters
    ----------
    deck : the deck converter (``user_spc``: the set asked for, or None).
    pos : dict of int to ndarray
        Grid positions (``THRU`` ranges take the grids and scalar points that exist).
    """
    sets: dict[int, list[tuple[str, str]]] = {}
    adds: dict[int, list[int]] = {}

    def entry(g: Any, comps: Any, c: Card) -> tuple[str, str]:
        if isinstance(g, int) and g in deck.spoint_ids:
            if comps not in (None, 0):
                raise c.error(f"scalar point {g}: component is 0 or blank, got {comps!r}")
            return f"spoint:{g}", "1"
        return deck.grid(g, c, pos, "G"), deck.components(comps, c, "C")

    for c in deck.cards:
        if c.name == "SPC":
            sid = c.integer(1, "SID")
            for base in (2, 5):
                g = c.raw(base)
                if g is None:
                    continue
                node, comps = entry(g, c.raw(base + 1), c)
                if c.real(base + 2, "D", 0.0):
                    deck.warnings.append(f"{c.where}: enforced displacement ignored")
                sets.setdefault(sid, []).append((node, comps))
        elif c.name == "SPC1":
            sid = c.integer(1, "SID")
            ids = list(c.fields[3:])
            if len(ids) == 3 and ids[1] == "THRU":
                lo, hi = ids[0], ids[2]
                ids = [
                    g
                    for g in sorted(set(pos) | set(deck.spoint_ids))
                    if isinstance(lo, int) and isinstance(hi, int) and lo <= g <= hi
                ]
            for g in ids:
                if g is not None:
                    sets.setdefault(sid, []).append(entry(g, c.raw(2), c))
        elif c.name == "SPCADD":
            adds[c.integer(1, "SID")] = [v for v in c.fields[2:] if isinstance(v, int)]
    deck.spc_sets = sorted(set(sets) | set(adds))
    chosen = _selected(deck, "SPC", deck.spc_sets, deck.user_spc)
    if chosen is None:
        if deck.spc_sets:
            deck.warnings.append(
                f"SPC sets {deck.spc_sets} present, none selected: no constraints noted"
            )
        return []
    if chosen not in sets and chosen not in adds:
        raise InputError(
            f"SPC set {chosen} is not defined", where=deck.path, fix=f"defined: {deck.spc_sets}"
        )
    out: list[Constraint] = []
    for sid in adds.get(chosen, [chosen]):
        out += [Constraint(n, comp) for n, comp in sets.get(sid, [])]
    return out
