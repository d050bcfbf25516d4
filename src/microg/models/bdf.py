"""NASTRAN bulk data (BDF/DAT) import: a deck's cards become a graph model.

``load_bdf(path, units="in, lbf, s")`` reads a deck with microg's own card reader (no
pyNastran: its 1.4 releases pin numpy < 2, and the bulk data format is small and documented)
and converts it to SI at the boundary.  The reader is checked against pyNastran's parse of
the same decks in the ``nastran`` extra's environment (``tests/models/test_bdf.py``).

**Format read** by :mod:`microg.models.bdf_cards` (small-, large- and free-field entries,
continuations, ``INCLUDE``); the case control's ``SPC = n`` is noted.  This module turns
the cards into the graph; :mod:`microg.models.bdf_properties` reads the property and
material cards.

**Cards converted:** GRID (CP, CD), CORD2R/C/S, CBAR, CBEAM, BAROR, BEAMOR, PBAR, PBARL,
PBEAM (uniform), PBEAML (uniform), CROD, PROD, CONROD, CQUAD4, CTRIA3 + PSHELL
(:mod:`microg.models.bdf_shells`), CBUSH + PBUSH (K, B, GE), CONM2,
CONM1 (a rigid body's 6x6 mass), MAT1, PARAM (WTMASS, COUPMASS, K6ROT); and through
:mod:`microg.models.bdf_constraints`: SPOINT, CELAS1 + PELAS, CELAS2, CMASS1 + PMASS, CMASS2,
CDAMP1 + PDAMP, CDAMP2, RBE2, RBE3 (rotations, UM), MPC, MPCADD (``MPC = n`` applied), SPC,
SPC1, SPCADD (noted as constraints).

**Cards ignored by name** (they change no stiffness or mass: loads, solution and output
control) are counted in ``meta["ignored_cards"]`` and named in ``meta["warnings"]``; every
other card is *unsupported* and the whole deck is refused with one :class:`InputError` listing
each unsupported card with its count.  Nothing is dropped silently.

**Units.**  NASTRAN decks declare none: ``units="LENGTH, FORCE, TIME"`` is required (e.g.
``"in, lbf, s"``, ``"mm, N, s"``, ``"m, N, s"``; :func:`microg.models.file_units.parse_units`);
the mass unit is FORCE TIME^2 / LENGTH.  Mass input (densities, non-structural mass, CONM2)
is multiplied by WTMASS (``PARAM,WTMASS``, or the ``wtmass`` argument; both given and
different is an error).

**Element formulation** follows NASTRAN: lumped mass unless ``PARAM,COUPMASS`` > 0, then
NASTRAN's coupled CBAR mass as Simcenter Nastran 2020.2 forms it (``coupled_mass="coupled"``,
the default) or NX Nastran 9.1 (``"coupled-nx9"``), stated in ``meta["mass_formulation_note"]``;
shear
flexibility from PBAR/PBEAM K1, K2 (PBAR blank: none; PBEAM default 1.0; 0.0: none) and from
the PBARL/PBEAML section (:data:`~microg.models.bdf_properties.SECTION_SHEAR_FACTORS`);
see :mod:`microg.structure.elements`.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from microg import defaults
from microg.errors import InputError
from microg.models import bdf_constraints
from microg.models.bdf_cards import MAX_CARDS, MAX_INCLUDE_DEPTH, Card, read_cards
from microg.models.bdf_properties import (
    SECTION_SHEAR_FACTORS,
    BeamProperty,
    Material,
    Scales,
    beam_properties,
    beam_section,
    bush_properties,
    material,
    materials,
)
from microg.models.bdf_shells import K6ROT_DEFAULT, SHELL_CARDS, shell_elements
from microg.models.coords import (
    NASTRAN_KINDS,
    CoordinateFrame,
    Cord2,
    chain_cord2,
    nastran_coordinates,
)
from microg.models.file_units import UnitSystem, parse_units
from microg.models.graph_check import validate_graph
from microg.models.graph_model import (
    MASS_NOTES,
    NASTRAN_COUPLED_FORMS,
    BeamElement,
    BeamSection,
    ConcentratedMass,
    Constraint,
    GraphModel,
    GraphPoint,
    Node,
    RodElement,
    Spring,
    parse_components,
    spring_axes,
)
from microg.models.modal import ModalPoint

__all__ = [
    "ANALYSIS_SET_CARDS",
    "IGNORED_CARDS",
    "MAX_CARDS",
    "MAX_INCLUDE_DEPTH",
    "SECTION_SHEAR_FACTORS",
    "SUPPORTED_CARDS",
    "Card",
    "grid_geometry",
    "load_bdf",
    "read_cards",
]

# fmt: off
#: cards converted into the graph
SUPPORTED_CARDS = (
    "GRID", "CORD2R", "CORD2C", "CORD2S", "CBAR", "CBEAM", "BAROR", "BEAMOR", "PBAR", "PBARL",
    "PBEAM", "PBEAML", "CROD", "PROD", "CONROD", "CBUSH", "PBUSH", "CELAS1", "CELAS2", "PELAS",
    "CONM2", "CONM1", "RBE2", "RBE3", "MAT1", "PARAM", "SPC", "SPC1", "SPCADD",
    "SPOINT", "CMASS1", "CMASS2", "PMASS", "CDAMP1", "CDAMP2", "PDAMP", "MPC", "MPCADD",
    *SHELL_CARDS,
)
# fmt: on
# fmt: off
#: cards read and ignored: they change neither stiffness nor mass (loads, solution control,
#: output requests, analysis sets, thermal cards, tables); listed once in the warnings and
#: counted in meta["ignored_cards"]
IGNORED_CARDS = (
    "ENDDATA", "EIGRL", "EIGR", "EIGB", "EIGC", "USET", "USET1", "PLOTEL", "FORCE", "FORCE1",
    "FORCE2", "MOMENT", "MOMENT1", "MOMENT2", "LOAD", "GRAV", "RFORCE", "PLOAD", "PLOAD1",
    "PLOAD2", "PLOAD4", "DAREA", "DLOAD", "TLOAD1", "TLOAD2", "RLOAD1", "RLOAD2", "DELAY",
    "DPHASE", "FREQ", "FREQ1", "FREQ2", "FREQ3", "FREQ4", "FREQ5", "TABLED1", "TABLED2",
    "TABLED3", "TABLED4", "TABDMP1", "TSTEP", "TEMP", "TEMPD", "SPCD", "NLPARM", "ASET",
    "ASET1", "OMIT", "OMIT1", "QSET", "QSET1", "BSET", "BSET1", "CSET", "CSET1", "SUPORT",
    "SUPORT1", "MONPNT1", "DTI",
    # thermal materials, boundary conditions and loads (no structural stiffness or mass)
    "MAT4", "MAT5", "MATT4", "MATT5", "CONV", "PCONV", "RADBC", "RADM", "CHBDYE", "CHBDYG",
    "CHBDYP", "PHBDY", "QBDY1", "QBDY2", "QBDY3", "QVOL", "QHBDY", "TEMPP1", "TEMPRB",
    # material and load tables, sets, design optimisation, initial conditions
    "TABLEM1", "TABLEM2", "TABLEM3", "TABLEM4", "TABLES1", "TABLEST", "SET1", "SET3",
    "DESVAR", "DRESP1", "DRESP2", "DCONSTR", "DVPREL1", "DOPTPRM", "TIC", "DCONADD", "DSCREEN",
    "DVGRID",
)
# fmt: on

#: the ignored cards that define NASTRAN's analysis sets (a reduction or a fixed boundary): a
#: run that uses them prints other eigenvalues than the structure's, so their presence is said
ANALYSIS_SET_CARDS = frozenset(
    ("ASET", "ASET1", "OMIT", "OMIT1", "QSET", "QSET1", "BSET", "BSET1", "CSET", "CSET1")
)


# --------------------------------------------------------------------------- deck -> graph


def _same_card(a: Card, b: Card) -> bool:
    """Whether two cards say the same.

    Fields equal as parsed values, trailing blanks and zeros aside (a blank GRID CD/PS/SEID
    or CORD2 coordinate is 0).
    """

    def norm(c: Card) -> tuple[Any, ...]:
        f = list(c.fields)
        while f and (f[-1] is None or f[-1] == "" or (not isinstance(f[-1], str) and f[-1] == 0)):
            f.pop()
        return tuple(f)

    return norm(a) == norm(b)


#: the form of a NASTRAN card name (at most 8 characters, a letter first)
_CARD_NAME = re.compile(r"^[A-Z][A-Z0-9]{0,7}$")


class _Deck:
    """Converts cards to a GraphModel (private)."""

    def __init__(
        self,
        cards: list[Card],
        case: list[str],
        path: str,
        sc: Scales,
        wtmass: float | None,
        spc: int | None,
        mpc: int | None = None,
    ):
        self.cards = cards
        self.case = case
        self.path = path
        self.sc = sc
        self.user_wtmass = wtmass
        self.user_spc = spc
        self.user_mpc = mpc
        self.spoint_ids: set[int] = set()
        self.mpc_sets: list[int] = []
        self.warnings: list[str] = []
        self.origin: dict[str, Card] = {}
        self.grid_cards: dict[int, Card] = {}
        self.grid_ps: list[tuple[str, str]] = []
        self.spc_sets: list[int] = []
        self.coupled_form = defaults.NASTRAN_COUPLED_MASS

    def by_id(self, names: tuple[str, ...], what: str) -> dict[int, Card]:
        out: dict[int, Card] = {}
        for c in self.cards:
            if c.name in names:
                i = c.integer(1, f"{what} id")
                if i in out:
                    if _same_card(out[i], c):
                        continue  # an identical repeat (an INCLUDEd file repeating a card)
                    raise c.error(f"duplicate {what} id {i} (also at {out[i].file}:{out[i].line})")
                out[i] = c
        return out

    def build(self) -> GraphModel:
        counts = Counter(c.name for c in self.cards)
        unsupported = {
            k: v for k, v in counts.items() if k not in SUPPORTED_CARDS and k not in IGNORED_CARDS
        }
        if unsupported:
            # a name is quoted only when it has the form of a NASTRAN card name: the lines of
            # a file that is not a deck (an INCLUDEd /etc/passwd) are counted, never echoed
            # (and nothing of a file that holds such a line: it is not a deck)
            bad = [c for c in self.cards if c.name in unsupported]
            foreign = {c.file for c in bad if not _CARD_NAME.match(c.name)}
            junk = [c for c in bad if c.file in foreign]
            named = Counter(c.name for c in bad if c.file not in foreign)
            parts = [f"{k} ({v})" for k, v in sorted(named.items())]
            if junk:
                parts.append(
                    f"{len(junk)} line(s) that are not NASTRAN cards (first at "
                    f"{junk[0].file}:{junk[0].line})"
                )
            raise InputError(
                f"unsupported cards: {', '.join(parts)}",
                where=self.path,
                fix="microg's frame elements read "
                + " ".join(SUPPORTED_CARDS)
                + "; remove the others or replace them by supported elements",
            )
        ignored = {k: v for k, v in counts.items() if k in IGNORED_CARDS and k != "ENDDATA"}
        if ignored:
            self.warnings.append(
                "cards ignored (no stiffness or mass): "
                + ", ".join(f"{k} ({v})" for k, v in sorted(ignored.items()))
            )
        sets = sorted(k for k in ignored if k in ANALYSIS_SET_CARDS)
        if sets:
            self.warnings.append(
                f"analysis sets ({', '.join(sets)}) are not applied: these are the modes of the "
                "whole structure (free-free, or with its SPC under constrained=True); a NASTRAN "
                "run that reduces to these sets (ASET/OMIT, Craig-Bampton BSET/QSET, EXTSEOUT) "
                "prints the modes of its reduced or fixed-boundary model instead"
            )
        params = self.params()
        wt = self.wtmass(params)
        coupmass = params.get("COUPMASS")
        lumped = not (
            coupmass is not None
            and isinstance(coupmass.raw(2), int | float)
            and coupmass.raw(2) > 0
        )
        formulation = "lumped" if lumped else self.coupled_form
        chosen_by = (
            "no PARAM,COUPMASS > 0 in the deck: NASTRAN's default"
            if lumped
            else f"PARAM,COUPMASS,{coupmass.raw(2) if coupmass else ''} in the deck"
        )
        k6 = params["K6ROT"].real(2, "K6ROT", K6ROT_DEFAULT) if "K6ROT" in params else None
        frames = self.frames()
        nodes, grid_pos, grid_axes = self.grids(frames)
        nodes = self.with_scalar_points(nodes)
        mats = materials(self.by_id(("MAT1",), "material"), self.sc)
        beam_props = beam_properties(
            self.by_id(("PBAR", "PBARL", "PBEAM", "PBEAML"), "beam property"), self.warnings
        )
        beams = self.beams(beam_props, mats, grid_pos, grid_axes, wt)
        rods = self.rods(mats, grid_pos, wt)
        shell_cards = self.by_id(("CQUAD4", "CTRIA3"), "element")
        shells = shell_elements(
            shell_cards, self.by_id(("PSHELL",), "shell property"), mats,
            lambda g, c, lab: self.grid(g, c, grid_pos, lab), self.sc, wt,
            K6ROT_DEFAULT if k6 is None else k6, self.origin,
        )  # fmt: skip
        if k6 is not None and not shells:
            self.warnings.append("PARAM K6ROT noted: it stiffens shell drilling rotations only")
        springs = self.bushes(grid_pos, grid_axes, frames)
        scalars = bdf_constraints.scalar_springs(self) + bdf_constraints.scalar_dampers(self)
        masses = self.conm2(grid_pos, frames, wt) + self.conm1(grid_pos, frames, wt)
        links, interps = bdf_constraints.rigid(self, grid_pos)
        mpcs = bdf_constraints.mpcs(self)
        constraints = bdf_constraints.constraints(self, grid_pos)
        for ps_node, comps in self.grid_ps:
            constraints.append(Constraint(ps_node, comps))
        ignored_params = sorted(k for k in params if k not in ("WTMASS", "COUPMASS", "K6ROT"))
        meta = {
            "format": "nastran-bdf",
            "units": {"length_m": self.sc.length, "force_N": self.sc.force, "time_s": self.sc.time},
            "wtmass": wt,
            "mass_formulation": formulation,
            "mass_formulation_note": f"{formulation} ({chosen_by}; {MASS_NOTES[formulation]})",
            "k6rot": (K6ROT_DEFAULT if k6 is None else k6) if shells else None,
            "ignored_cards": ignored,
            "params_ignored": ignored_params,
            "card_counts": dict(counts),
            "spc_sets": self.spc_sets,
            "mpc_sets": self.mpc_sets,
            "scalar_points": len(self.spoint_ids),
            "warnings": tuple(self.warnings),
        }
        graph = GraphModel(
            name=Path(self.path).stem,
            nodes=tuple(nodes),
            beams=tuple(beams),
            rods=tuple(rods),
            shells=tuple(shells),
            springs=tuple(springs),
            scalar_springs=tuple(scalars),
            masses=tuple(masses),
            rigid_links=tuple(links),
            interpolations=tuple(interps),
            scalar_masses=tuple(bdf_constraints.scalar_masses(self, wt)),
            mpcs=tuple(mpcs),
            frames=tuple(f for k, f in frames.items() if k != 0),
            mass_formulation=formulation,
            constraints=tuple(constraints),
            source=self.path,
            meta=meta,
        )
        try:
            validate_graph(graph)
        except InputError as exc:
            where = exc.where or ""
            card = self.origin.get(where.split(": ", 1)[1]) if ": " in where else None
            if card is not None:
                raise InputError(exc.what, where=card.where, fix=exc.fix) from None
            raise
        return graph

    # ---- parameters and units

    def params(self) -> dict[str, Card]:
        out: dict[str, Card] = {}
        for c in self.cards:
            if c.name == "PARAM":
                out[c.text(1, "parameter name").upper()] = c
        return out

    def wtmass(self, params: dict[str, Card]) -> float:
        c = params.get("WTMASS")
        deck = c.real(2, "WTMASS") if c is not None else None
        if deck is not None and not deck > 0:
            assert c is not None
            raise c.error(f"WTMASS must be > 0, got {deck}")
        if self.user_wtmass is not None:
            if not (isinstance(self.user_wtmass, int | float) and self.user_wtmass > 0):
                raise InputError(f"wtmass must be > 0, got {self.user_wtmass!r}", where="wtmass")
            if deck is not None and not math.isclose(deck, self.user_wtmass, rel_tol=1e-9):
                assert c is not None
                raise InputError(
                    f"the deck's PARAM WTMASS {deck:g} contradicts wtmass = {self.user_wtmass:g}",
                    where=c.where,
                    fix="give the deck's value or omit wtmass",
                )
            return float(self.user_wtmass)
        return 1.0 if deck is None else deck

    # ---- geometry

    def frames(self) -> dict[int, CoordinateFrame]:
        raw = self.by_id(("CORD2R", "CORD2C", "CORD2S"), "coordinate system")
        defs = [
            Cord2(
                cid,
                NASTRAN_KINDS[c.name[-1]],
                c.integer(2, "RID", 0),
                np.array(
                    [
                        [
                            c.real(k + m, f"point {'ABC'[(k - 3) // 3]}{m + 1}", 0.0)
                            for m in range(3)
                        ]
                        for k in (3, 6, 9)
                    ]
                ),
                c.where,
            )
            for cid, c in raw.items()
        ]
        return chain_cord2(defs, length=self.sc.length)

    def frame(self, frames: dict[int, CoordinateFrame], cid: int, c: Card) -> CoordinateFrame:
        if cid not in frames:
            raise c.error(f"coordinate system {cid} is not defined", "add its CORD2R/C/S card")
        return frames[cid]

    def grids(
        self, frames: dict[int, CoordinateFrame]
    ) -> tuple[list[Node], dict[int, np.ndarray], dict[int, np.ndarray]]:
        grids = self.by_id(("GRID",), "grid")
        self.grid_cards = grids
        if not grids:
            raise InputError(
                "the deck has no GRID", where=self.path, fix="give the bulk data with its grids"
            )
        nodes: list[Node] = []
        pos: dict[int, np.ndarray] = {}
        axes: dict[int, np.ndarray] = {}
        self.grid_ps = []
        for gid, c in sorted(grids.items()):
            cp = c.integer(2, "CP", 0)
            cd = c.integer(6, "CD", 0)
            if c.raw(8) not in (None, 0):
                raise c.error(
                    "superelement grids (SEID) are not supported", "give the residual structure"
                )
            if cd == -1:
                raise c.error("fluid grids (CD = -1) are not supported")
            fr = self.frame(frames, cp, c)
            x = np.array([c.real(3 + k, f"X{k + 1}", 0.0) for k in range(3)])
            p = fr.to_basic(nastran_coordinates(fr.kind, x, self.sc.length))
            fd = self.frame(frames, cd, c)
            ax = fd.axes_at(p)
            name = f"grid:{gid}"
            nodes.append(Node(name, p, ax, "basic" if cd == 0 else f"cs:{cd}"))
            pos[gid] = p
            axes[gid] = ax
            ps = c.raw(7)
            if ps not in (None, 0):
                self.grid_ps.append((name, self.components(ps, c, "PS")))
            self.origin[name] = c
        return nodes, pos, axes

    def with_scalar_points(self, nodes: list[Node]) -> list[Node]:
        """The grids' nodes and the SPOINTs' (one DOF each), ordered by id as NASTRAN's g-set."""
        ids = bdf_constraints.scalar_points(self)
        clash = [i for i in ids if i in self.grid_cards]
        if clash:
            raise self.grid_cards[clash[0]].error(
                f"id {clash[0]} is both a GRID and an SPOINT", "give each point its own id"
            )
        self.spoint_ids = set(ids)
        if not ids:
            return nodes
        spoints = [Node(f"spoint:{i}", np.zeros(3), np.eye(3), "scalar", True) for i in ids]
        return sorted(nodes + spoints, key=lambda nd: int(nd.name.split(":")[1]))

    def components(self, value: Any, c: Card, label: str, allowed: str = "123456") -> str:
        try:
            return parse_components(value, where=c.where, allowed=allowed)
        except InputError as exc:
            raise c.error(f"{label}: {exc.what}", exc.fix) from None

    def grid(self, gid: Any, c: Card, pos: dict[int, np.ndarray], label: str) -> str:
        if not isinstance(gid, int) or gid not in pos:
            known = sorted(pos)
            near = sorted(known, key=lambda k: abs(k - gid) if isinstance(gid, int) else k)[:5]
            raise c.error(
                f"{label} grid {gid} is not defined",
                f"add GRID {gid} or correct the id (nearest: {', '.join(map(str, near))})",
            )
        return f"grid:{gid}"

    # ---- elements

    def orientation(
        self,
        c: Card,
        defaults: Card | None,
        pos: dict[int, np.ndarray],
        axes: dict[int, np.ndarray],
        ga: int,
    ) -> tuple[np.ndarray, str]:
        """Orientation vector (basic) and OFFT of a CBAR/CBEAM (BAROR/BEAMOR defaults)."""
        src = c
        x1 = c.raw(5)
        if x1 is None and defaults is not None:
            src = defaults
            x1 = defaults.raw(5)
        offt = c.raw(8)
        if isinstance(offt, float):  # CBEAM BIT (p-elements only)
            self.warnings.append(f"{c.where}: BIT ignored")
            offt = None
        if offt is None and defaults is not None and isinstance(defaults.raw(8), str):
            offt = defaults.raw(8)
        offt = str(offt or "GGG")
        if len(offt) != 3 or offt[0] not in "GB" or offt[1] not in "GO" or offt[2] not in "GO":
            raise c.error(
                f"OFFT {offt!r} is not valid", "use GGG, BGG, GGO, ... (offsets in O not supported)"
            )
        if "O" in offt[1:]:
            raise c.error(
                f"OFFT {offt!r}: offsets in the element system are not supported",
                "give offsets in G",
            )
        if x1 is None:
            raise c.error(
                "has no orientation vector (X1-X3 or G0) and no BAROR/BEAMOR default",
                "give X1, X2, X3 or G0",
            )
        if isinstance(x1, int):
            self.grid(x1, src, pos, "G0")  # G0 must exist
            return pos[x1] - pos[ga], offt
        v = np.array([src.real(5 + k, f"X{k + 1}", 0.0) for k in range(3)])
        if offt[0] == "G":
            v = v @ axes[ga]
        return v, offt

    def beams(
        self,
        props: dict[int, BeamProperty],
        mats: dict[int, Material],
        pos: dict[int, np.ndarray],
        axes: dict[int, np.ndarray],
        wt: float,
    ) -> list[BeamElement]:
        out: list[BeamElement] = []
        sections: dict[int, BeamSection] = {}
        orient = {
            n: next((c for c in self.cards if c.name == n), None) for n in ("BAROR", "BEAMOR")
        }
        for name in ("CBAR", "CBEAM"):
            defaults = orient["BAROR" if name == "CBAR" else "BEAMOR"]
            for eid, c in self.by_id((name,), "element").items():
                pid = c.integer(2, "PID", None)
                if pid is None and defaults is not None:
                    pid = defaults.integer(2, "PID", None)
                pid = eid if pid is None else pid
                if pid not in props:
                    raise c.error(
                        f"property {pid} ({'PBAR/PBARL' if name == 'CBAR' else 'PBEAM/PBEAML'})"
                        " is not defined",
                        "add the property card or correct PID",
                    )
                prop = props[pid]
                if name == "CBAR" and prop.card.name not in ("PBAR", "PBARL"):
                    raise c.error(
                        f"property {pid} is a {prop.card.name}; a CBAR needs a PBAR or PBARL"
                    )
                if name == "CBEAM" and prop.card.name not in ("PBEAM", "PBEAML"):
                    raise c.error(
                        f"property {pid} is a {prop.card.name}; a CBEAM needs a PBEAM or PBEAML"
                    )
                if pid not in sections:
                    sections[pid] = beam_section(
                        prop, material(mats, prop.mid, prop.card), wt, self.sc
                    )
                ga_id, gb_id = c.raw(3), c.raw(4)
                ga = self.grid(ga_id, c, pos, "GA")
                gb = self.grid(gb_id, c, pos, "GB")
                if ga_id == gb_id:
                    raise c.error("GA and GB are the same grid", "connect two distinct grids")
                v, offt = self.orientation(c, defaults, pos, axes, ga_id)
                wa = (
                    np.array([c.real(11 + k, f"W{k + 1}A", 0.0) for k in range(3)]) * self.sc.length
                )
                wb = (
                    np.array([c.real(14 + k, f"W{k + 1}B", 0.0) for k in range(3)]) * self.sc.length
                )
                wa = wa @ axes[ga_id]
                wb = wb @ axes[gb_id]
                releases = tuple(
                    "" if c.raw(k) in (None, 0) else self.components(c.raw(k), c, lab)
                    for k, lab in ((9, "PA"), (10, "PB"))
                )
                if name == "CBEAM" and (c.raw(17) or c.raw(18)):
                    raise c.error("warping scalar points SA/SB are not supported")
                ename = f"{name.lower()}:{eid}"
                self.origin[ename] = c
                # a zero length is found by validate_graph and reported at this card
                out.append(
                    BeamElement(
                        ename,
                        (ga, gb),
                        sections[pid],
                        v,
                        np.stack([wa, wb]),
                        "bar" if name == "CBAR" else "beam",
                        (releases[0], releases[1]),
                    )
                )
        return out

    def rods(
        self, mats: dict[int, Material], pos: dict[int, np.ndarray], wt: float
    ) -> list[RodElement]:
        sc = self.sc
        props = self.by_id(("PROD",), "rod property")
        out: list[RodElement] = []
        for eid, c in self.by_id(("CROD", "CONROD"), "element").items():
            if c.name == "CROD":
                pid = c.integer(2, "PID", eid)
                if pid not in props:
                    raise c.error(
                        f"property {pid} (PROD) is not defined", "add the PROD card or correct PID"
                    )
                p = props[pid]
                mid, a, j, nsm = (
                    p.integer(2, "MID"),
                    p.real(3, "A"),
                    p.real(4, "J", 0.0),
                    p.real(6, "NSM", 0.0),
                )
                g1, g2 = c.raw(3), c.raw(4)
                mat = material(mats, mid, p)
            else:
                g1, g2 = c.raw(2), c.raw(3)
                mat = material(mats, c.integer(4, "MID"), c)
                a, j, nsm = c.real(5, "A"), c.real(6, "J", 0.0), c.real(8, "NSM", 0.0)
            n1 = self.grid(g1, c, pos, "G1")
            n2 = self.grid(g2, c, pos, "G2")
            if not a > 0:
                raise c.error(f"rod area must be > 0, got {a}")
            A = a * sc.length**2
            rho = mat.rho * wt * sc.mass / sc.length**3
            ename = f"{c.name.lower()}:{eid}"
            self.origin[ename] = c
            out.append(
                RodElement(
                    ename,
                    (n1, n2),
                    mat.e * A,
                    mat.g * j * sc.length**4,
                    rho * A + nsm * wt * sc.mass / sc.length,
                )
            )
        return out

    def bushes(
        self,
        pos: dict[int, np.ndarray],
        axes: dict[int, np.ndarray],
        frames: dict[int, CoordinateFrame],
    ) -> list[Spring]:
        sc = self.sc
        props = bush_properties(self.by_id(("PBUSH",), "bush property"), sc)
        out: list[Spring] = []
        for eid, c in self.by_id(("CBUSH",), "element").items():
            pid = c.integer(2, "PID", eid)
            if pid not in props:
                raise c.error(
                    f"property {pid} (PBUSH) is not defined", "add the PBUSH card or correct PID"
                )
            k6, b6, ge = props[pid]
            ga_id = c.raw(3)
            ga = self.grid(ga_id, c, pos, "GA")
            gb_id = c.raw(4)
            gb = None if gb_id in (None, 0) else self.grid(gb_id, c, pos, "GB")
            pa = pos[ga_id]
            pb = pa if gb is None else pos[gb_id]
            ocid = c.integer(10, "OCID", -1)
            if ocid == -1:
                s = c.real(9, "S", 0.5)
                loc = pa + s * (pb - pa)
            else:
                fr = self.frame(frames, ocid, c)
                soff = np.array([c.real(11 + m, f"S{m + 1}", 0.0) for m in range(3)]) * sc.length
                loc = pa + fr.vector_to_basic(soff, pa)
            cid = c.raw(8)
            where = c.where
            if cid is not None:
                if not isinstance(cid, int):
                    raise c.error(f"CID must be an integer, got {cid!r}")
                ax = self.frame(frames, cid, c).axes_at(loc)
            else:
                x1 = c.raw(5)
                v: np.ndarray | None
                if x1 is None:
                    v = None
                elif isinstance(x1, int):
                    self.grid(x1, c, pos, "G0")
                    v = pos[x1] - pa
                else:
                    v = np.array([c.real(5 + m, f"X{m + 1}", 0.0) for m in range(3)]) @ axes[ga_id]
                try:
                    ax = spring_axes(pa, pb, v, k6, b6, where=where)
                except InputError as exc:
                    raise InputError(exc.what, where=where, fix=exc.fix) from None
            ename = f"cbush:{eid}"
            self.origin[ename] = c
            out.append(Spring(ename, (ga, gb), k6, b6, ax, loc, ge))
        return out

    def conm2(
        self, pos: dict[int, np.ndarray], frames: dict[int, CoordinateFrame], wt: float
    ) -> list[ConcentratedMass]:
        sc = self.sc
        out: list[ConcentratedMass] = []
        for eid, c in self.by_id(("CONM2",), "element").items():
            gid = c.raw(2)
            node = self.grid(gid, c, pos, "G")
            cid = c.integer(3, "CID", 0)
            m = c.real(4, "M", 0.0) * wt * sc.mass
            x = np.array([c.real(5 + k, f"X{k + 1}", 0.0) for k in range(3)]) * sc.length
            i11, i21, i22, i31, i32, i33 = (
                c.real(k, lab, 0.0)
                for k, lab in zip(
                    range(9, 15), ("I11", "I21", "I22", "I31", "I32", "I33"), strict=True
                )
            )
            # QRG CONM2 remark: the inertia matrix is
            # [[I11, -I21, -I31], [-I21, I22, -I32], [-I31, -I32, I33]]
            j = (
                np.array([[i11, -i21, -i31], [-i21, i22, -i32], [-i31, -i32, i33]])
                * wt
                * sc.mass
                * sc.length**2
            )
            if cid == -1:
                off = x - pos[gid]
            else:
                fr = self.frame(frames, cid, c)
                ax = fr.axes_at(pos[gid])
                off = x @ ax
                j = ax.T @ j @ ax
            if m < 0:
                raise c.error(f"mass must be >= 0, got {m}")
            ename = f"conm2:{eid}"
            self.origin[ename] = c
            out.append(ConcentratedMass(ename, node, m, off, j))
        return out

    def conm1(
        self, pos: dict[int, np.ndarray], frames: dict[int, CoordinateFrame], wt: float
    ) -> list[ConcentratedMass]:
        """CONM1: a 6x6 mass at a grid (lower triangle, in CID at the grid), as a rigid body.

        The matrix must be a rigid body's, ``[[m I, -m S(d)], [m S(d), J + m S(d)^T S(d)]]``
        with ``S(d) x = d x x`` (mass m at offset d, inertia J about its centre): one mass in
        the three directions and an antisymmetric coupling, to 1e-9.  Anything else
        (different masses per direction) is refused.
        """
        sc = self.sc
        out: list[ConcentratedMass] = []
        for eid, c in self.by_id(("CONM1",), "element").items():
            gid = c.raw(2)
            node = self.grid(gid, c, pos, "G")
            cid = c.integer(3, "CID", 0)
            mm = np.zeros((6, 6))
            k = 4
            for i in range(6):
                for j in range(i + 1):
                    mm[i, j] = mm[j, i] = c.real(k, f"M{i + 1}{j + 1}", 0.0)
                    k += 1
            scale = np.ones(6)
            scale[3:] = sc.length
            mm = mm * np.outer(scale, scale) * wt * sc.mass
            if cid != 0:
                ax = self.frame(frames, cid, c).axes_at(pos[gid])
                t = np.zeros((6, 6))
                t[:3, :3] = t[3:, 3:] = ax.T  # columns: the system's axes in basic
                mm = t @ mm @ t.T
            m = float(mm[0, 0])
            big = max(abs(m), float(np.abs(mm).max()), 1e-300)
            if (
                m < 0
                or np.abs(mm[:3, :3] - m * np.eye(3)).max() > 1e-9 * big
                or np.abs(mm[:3, 3:] + mm[:3, 3:].T).max() > 1e-9 * big
                or (m == 0 and np.abs(mm[:3, 3:]).max() > 0)
            ):
                raise c.error(
                    "only the mass of a rigid body is supported (M11 = M22 = M33 >= 0, no "
                    "translational cross terms, an antisymmetric translation-rotation block)",
                    fix="give the mass as CONM2 (mass, offset, inertia)",
                )
            sd = -mm[:3, 3:] / m if m > 0 else np.zeros((3, 3))
            d = np.array([sd[2, 1], sd[0, 2], sd[1, 0]])
            jc = mm[3:, 3:] - m * (sd.T @ sd)
            jc = 0.5 * (jc + jc.T)
            if np.linalg.eigvalsh(jc).min() < -1e-9 * max(float(np.abs(jc).max()), 1e-300):
                raise c.error("the rotational block is not a positive semidefinite inertia")
            ename = f"conm1:{eid}"
            self.origin[ename] = c
            out.append(ConcentratedMass(ename, node, m, d, jc))
        return out


def grid_geometry(
    path: str | Path, ids: np.ndarray, *, missing_ok: bool = False
) -> tuple[np.ndarray, np.ndarray, dict[int, CoordinateFrame]]:
    """Positions of grids in the basic system, their output systems, and the deck's systems.

    For an OP2 without geometry tables: only GRID and CORD2R/C/S cards (and INCLUDEs) are
    read, in the deck's own length unit (the OP2 reader scales them with the rest).

    Parameters
    ----------
    path : str or Path
        The BDF deck beside the OP2.
    ids : ndarray of int
        The grids wanted (the OP2's), in order.
    missing_ok : bool
        Give NaN positions (CD 0) for grids the deck lacks, instead of an error.

    Returns
    -------
    xyz : ndarray (g, 3)
        Basic coordinates, in the deck's length unit.
    cd : ndarray (g,) of int
        Each grid's output (displacement) coordinate system.
    systems : dict of int to CoordinateFrame
        Every CORD2R/C/S by id (basic excluded), origin in the deck's length unit.
    """
    cards, case = read_cards(path)
    keep = [c for c in cards if c.name in ("GRID", "CORD2R", "CORD2C", "CORD2S")]
    deck = _Deck(keep, case, str(path), Scales(1.0, 1.0, 1.0), None, None)
    frames = deck.frames()
    _, pos, _ = deck.grids(frames)
    missing = [int(g) for g in ids if int(g) not in pos]
    if missing and not missing_ok:
        raise InputError(
            f"{len(missing)} grid(s) of the OP2 are not in the deck (first: {missing[0]})",
            where=str(path),
            fix="give the deck the OP2 was run from",
        )
    cd = {gid: c.integer(6, "CD", 0) for gid, c in deck.by_id(("GRID",), "grid").items()}
    systems = {cid: f for cid, f in frames.items() if cid != 0}
    nowhere = np.full(3, np.nan)
    xyz = np.array([pos.get(int(g), nowhere) for g in ids], float).reshape(-1, 3)
    return xyz, np.array([cd.get(int(g), 0) for g in ids], int), systems


def load_bdf(
    path: str | Path,
    units: str | UnitSystem | None = None,
    *,
    wtmass: float | None = None,
    spc: int | None = None,
    mpc: int | None = None,
    points: Sequence[ModalPoint] | None = None,
    coupled_mass: str | None = None,
) -> GraphModel:
    """Read a NASTRAN bulk data deck into a graph model, SI.

    Parameters
    ----------
    path : str or Path
        The deck; INCLUDE files are read relative to it.
    units : str or UnitSystem
        ``"LENGTH, FORCE, TIME"`` of the deck, e.g. ``"in, lbf, s"``
        (:func:`microg.models.file_units.parse_units`); required: NASTRAN files declare none.
    wtmass : float, optional
        Factor from the deck's mass input to FORCE TIME^2/LENGTH (NASTRAN ``PARAM,WTMASS``);
        default the deck's, else 1.  Contradicting the deck's is an error.  (A UnitSystem's
        ``wtmass`` counts as given when it was declared, ``wtmass_given``, 1 included.)
    spc : int, optional
        SPC set noted as the model's constraints; default the case control's ``SPC = n``.
    mpc : int, optional
        MPC set applied (eliminated exactly); default the case control's ``MPC = n`` (none
        selected: no MPC, as in NASTRAN).
    points : sequence of ModalPoint, optional
        Named points on grids (a points file, :func:`microg.models.modal.read_options`).
    coupled_mass : {"coupled", "coupled-nx9", "consistent"}, optional
        The mass of a deck with ``PARAM,COUPMASS`` > 0: NASTRAN's coupled CBAR mass as
        Simcenter Nastran 2020.2 forms it (``"coupled"``, default
        :data:`microg.defaults.NASTRAN_COUPLED_MASS`) or as NX Nastran 9.1 (2014) does
        (``"coupled-nx9"``), or microg's consistent mass (``"consistent"``: with torsional
        inertia, which NASTRAN's CBAR has not; a straight line of CBARs then keeps the
        inertia of its rotation about its axis); see :mod:`microg.structure.elements`.  A
        deck without COUPMASS is lumped whatever this says.

    Returns
    -------
    GraphModel
        Mass formulation lumped unless ``PARAM,COUPMASS`` > 0, else ``coupled_mass``;
        ``constraints`` the SPC set (not applied unless
        :func:`~microg.structure.frame.build_frame` is asked to); ``meta`` the units, WTMASS,
        the mass formulation and what chose it (``mass_formulation_note``), ignored cards and
        parameters, and ``warnings``.
    """
    form = defaults.NASTRAN_COUPLED_MASS if coupled_mass is None else coupled_mass
    if form not in NASTRAN_COUPLED_FORMS:
        raise InputError(
            f"unknown coupled mass {coupled_mass!r}",
            where="coupled_mass",
            fix="use " + ", ".join(NASTRAN_COUPLED_FORMS),
        )
    if isinstance(units, UnitSystem):
        system = units
        if wtmass is None and units.wtmass_given:
            wtmass = units.wtmass
    elif units is None or not str(units).strip():
        raise InputError(
            "NASTRAN files declare no units and none were given",
            where=str(path),
            fix='state them as "LENGTH, FORCE, TIME", e.g. units="in, lbf, s" '
            "(and wtmass if the deck's masses are weights)",
        )
    else:
        system = parse_units(str(units), where="units")
    notes: list[str] = []
    cards, case = read_cards(path, notes)
    sc = Scales(system.length_m, system.force_N, system.time_s)
    deck = _Deck(cards, case, str(path), sc, wtmass, spc, mpc)
    deck.coupled_form = form
    deck.warnings.extend(notes)
    graph = deck.build()
    if not points:
        return graph
    out = []
    for p in points:
        node = f"grid:{p.grid}"
        if p.grid in deck.spoint_ids:
            raise InputError(
                f"point {p.name!r}: {p.grid} is a scalar point (SPOINT), not a point in space",
                where=str(path),
                fix="name a grid",
            )
        try:
            pos = graph.node(node).position
        except InputError as exc:
            raise InputError(
                f"point {p.name!r}: grid {p.grid} is not in the deck", where=str(path), fix=exc.fix
            ) from None
        out.append(
            GraphPoint(p.name, node, pos + np.asarray(p.offset_m, float), p.kind, p.description)
        )
    return dataclasses.replace(graph, points=tuple(out))
