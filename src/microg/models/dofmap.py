"""The DOFs of an OP4's matrix rows: grid components and scalar points, and where they are.

An OP4 holds bare matrices; what each row is comes from the run that wrote them:

* an OP2 beside it with the superelement's USET, EQEXIN(S), BGPDT(S) and CSTM(S) tables
  (pyyeti's nas2cam DMAP writes them; :func:`microg.models.op2.read_op2_dof_tables`): the
  a-set is the DOFs whose USET bits say so, in NASTRAN's internal order;
* the punch file of an external superelement (``EXTSEOUT(ASMBULK)``, ``<stem>.pch``): its
  ``EXTRN`` entry lists the boundary and modal DOFs in the matrices' order, its GRID,
  CORD2R/C/S and SPOINT entries place them;
* as a fallback, microg's own ``<stem>.dofmap.csv`` (``grid, component, x, y, z`` per row).

A scalar point (SPOINT: the modal coordinate of a Craig-Bampton reduction, say) is a row of
component 0, as NASTRAN writes it on EXTRN and in USET; it has no position and no motion of
its own to observe, but it is a coordinate of the eigenproblem.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from microg.errors import InputError
from microg.models.coords import (
    NASTRAN_KINDS,
    Cord2,
    chain_cord2,
    nastran_coordinates,
)

__all__ = ["DofMap", "dof_map_for_op4", "dof_map_from_csv", "dof_map_from_op2", "dof_map_from_pch"]


@dataclass(frozen=True)
class DofMap:
    """What each row of a matrix is, and where its grid is.

    Attributes
    ----------
    ids : ndarray (n,) int
        Grid or scalar-point id of each row.
    components : ndarray (n,) int
        1..6 (T1..R3 in the grid's output system) on a grid, 0 on a scalar point.
    grid_ids : ndarray (g,) int
        The grids of the rows, sorted.
    xyz : ndarray (g, 3)
        Their basic positions, file length unit.
    axes : ndarray (g, 3, 3)
        Their output systems' axes at the grid, columns in basic (identity: basic).
    source : str
        Where the map was read (file and tables or cards).
    """

    ids: np.ndarray
    components: np.ndarray
    grid_ids: np.ndarray
    xyz: np.ndarray
    axes: np.ndarray
    source: str

    @property
    def n(self) -> int:
        """Number of rows."""
        return int(self.ids.size)

    @property
    def scalar_points(self) -> np.ndarray:
        """The scalar points' ids (rows of component 0), in row order."""
        return self.ids[self.components == 0]


def _build(
    ids: np.ndarray,
    comps: np.ndarray,
    pos: dict[int, np.ndarray],
    axes: dict[int, np.ndarray],
    source: str,
) -> DofMap:
    grids = np.unique(ids[comps > 0]).astype(np.int64)
    missing = [int(g) for g in grids if int(g) not in pos]
    if missing:
        raise InputError(
            f"{len(missing)} grid(s) of the DOF map have no position (first: {missing[0]})",
            where=source,
        )
    xyz = np.array([pos[int(g)] for g in grids], float).reshape(-1, 3)
    ax = np.array([axes.get(int(g), np.eye(3)) for g in grids], float).reshape(-1, 3, 3)
    return DofMap(np.asarray(ids, np.int64), np.asarray(comps, int), grids, xyz, ax, source)


def dof_map_from_op2(path: str | Path, superelement: int | None = None) -> DofMap:
    """The a-set of a superelement from an OP2's USET/EQEXIN(S)/BGPDT(S)/CSTM(S).

    Parameters
    ----------
    path : str or Path
        An OP2 with USET tables (the nas2cam DMAP's).
    superelement : int, optional
        Its id (SLIST); required when the file has several.
    """
    from microg.models.op2 import read_op2_dof_tables

    label = str(path)
    tabs = [t for t in read_op2_dof_tables(path) if t.uset is not None]
    if not tabs:
        raise InputError("no USET table (the a-set is not in the file)", where=label)
    ses = [t.superelement for t in tabs]
    if superelement is None:
        if len(tabs) > 1:
            raise InputError(
                f"the file holds the DOFs of superelements {', '.join(map(str, ses))}",
                where=label,
                fix="choose one with superelement=N",
            )
        t = tabs[0]
    elif superelement in ses:
        t = tabs[ses.index(superelement)]
    else:
        raise InputError(
            f"no superelement {superelement} in the file (superelements: "
            f"{', '.join(map(str, ses))})",
            where="superelement",
        )
    a = t.a_set()
    pos, axes = {}, {}
    for k in np.flatnonzero(t.kinds == 1):
        gid, cd = int(t.ids[k]), int(t.cd[k])
        pos[gid] = t.xyz[k]
        if cd > 0:
            frame = t.coords.get(cd)
            if frame is None:
                raise InputError(
                    f"grid {gid} gives its DOFs in coordinate system {cd}, which no CSTM "
                    "of the file defines",
                    where=label,
                )
            axes[gid] = np.swapaxes(frame.axes_at(t.xyz[k]), -1, -2)
    tables = ", ".join(t.tables)
    return _build(
        t.dof_ids[a],
        t.dof_components[a],
        pos,
        axes,
        f"{label} ({tables} of superelement {t.superelement})",
    )


def _expand_list(card_fields: tuple[object, ...], where: str) -> list[int]:
    """SPOINT ids: a list, or ``A THRU B`` ranges."""
    vals = [v for v in card_fields[1:] if v is not None]
    out: list[int] = []
    k = 0
    while k < len(vals):
        if k + 1 < len(vals) and vals[k + 1] == "THRU":
            lo = vals[k]
            hi = vals[k + 2] if k + 2 < len(vals) else None
            if not isinstance(lo, int) or not isinstance(hi, int) or not 0 < lo <= hi:
                raise InputError("SPOINT: a THRU range is not two increasing ids", where=where)
            if hi - lo > 10**6:
                raise InputError("SPOINT: a THRU range of more than 10^6 points", where=where)
            out.extend(range(lo, hi + 1))
            k += 3
            continue
        v = vals[k]
        if not isinstance(v, int) or v < 1:
            raise InputError(f"SPOINT: {v!r} is not a positive id", where=where)
        out.append(v)
        k += 1
    return out


def dof_map_from_pch(path: str | Path) -> DofMap:
    """An external superelement's DOFs from its punch file (EXTSEOUT's ASMBULK).

    ``EXTRN`` lists ``id, components`` pairs in the matrices' row order (components 0: a
    scalar point); GRID (with CP and CD systems, CORD2R/C/S) places the grids.

    Parameters
    ----------
    path : str or Path
        The ``.pch`` file.
    """
    from microg.models.bdf_cards import read_cards

    label = str(path)
    cards, _ = read_cards(path, superelements=True)
    extrn = [c for c in cards if c.name == "EXTRN"]
    if not extrn:
        raise InputError("no EXTRN entry (the superelement's DOF list)", where=label)
    if len({c.fields for c in extrn}) > 1:
        raise InputError("several different EXTRN entries", where=label)
    e = extrn[0]
    vals = list(e.fields[1:])
    while vals and vals[-1] is None:
        vals.pop()
    if len(vals) % 2:
        raise e.error("EXTRN fields are not id, component pairs")
    spoints: set[int] = set()
    for c in cards:
        if c.name == "SPOINT":
            spoints.update(_expand_list(c.fields, c.where))
    ids: list[int] = []
    comps: list[int] = []
    for k in range(0, len(vals), 2):
        gid, c = vals[k], vals[k + 1]
        if not isinstance(gid, int) or gid < 1 or not isinstance(c, int) or c < 0:
            raise e.error(f"pair {k // 2 + 1}: {gid!r}, {c!r} is not an id and components")
        digits = sorted({int(d) for d in str(c)}) if c else [0]
        if any(d > 6 for d in digits) or (c and 0 in digits):
            raise e.error(f"pair {k // 2 + 1}: components {c} are not digits 1-6 (or 0)")
        if (c == 0) != (gid in spoints):
            kind = "a scalar point (SPOINT)" if gid in spoints else "not an SPOINT"
            raise e.error(f"pair {k // 2 + 1}: id {gid} is {kind} but has components {c}")
        ids.extend([gid] * len(digits))
        comps.extend(digits)
    cords: list[Cord2] = []
    grids: dict[int, tuple[int, tuple[float, ...], int]] = {}
    for c in cards:
        if c.name in ("CORD2R", "CORD2C", "CORD2S"):
            pts = np.array([c.real(k, f"point {k}", 0.0) for k in range(3, 12)]).reshape(3, 3)
            cords.append(
                Cord2(
                    c.integer(1, "CID"),
                    NASTRAN_KINDS[c.name[-1]],
                    c.integer(2, "RID", 0),
                    pts,
                    c.where,
                )  # fmt: skip
            )
        elif c.name == "GRID":
            gid = c.integer(1, "ID")
            new = (c.integer(2, "CP", 0), tuple(c.real(k, "X", 0.0) for k in (3, 4, 5)),
                   c.integer(6, "CD", 0))  # fmt: skip
            if grids.setdefault(gid, new) != new:
                raise c.error(f"grid {gid} is given twice with different fields")
    unique = {d.cid: d for d in cords}
    systems = chain_cord2(list(unique.values()))
    pos: dict[int, np.ndarray] = {}
    axes: dict[int, np.ndarray] = {}
    for gid, (cp, x, cd) in grids.items():
        for cid in (cp, cd):
            if cid and cid not in systems:
                raise InputError(
                    f"grid {gid} refers to coordinate system {cid}, not defined", where=label
                )
        frame = systems.get(cp)
        pos[gid] = (
            np.array(x, float)
            if frame is None
            else frame.to_basic(nastran_coordinates(frame.kind, np.array(x, float)))
        )
    for gid, (_, _, cd) in grids.items():
        if cd:
            axes[gid] = np.swapaxes(systems[cd].axes_at(pos[gid]), -1, -2)
    return _build(np.array(ids), np.array(comps), pos, axes, f"{label} (EXTRN, GRID, SPOINT)")


def dof_map_from_csv(path: str | Path) -> DofMap:
    """A DOF map file of microg's own: ``grid, component, x, y, z`` per row.

    Positions basic, the file's length unit; a scalar point's row has component 0 (its
    position is not used).

    Parameters
    ----------
    path : str or Path
        The ``.dofmap.csv`` file.
    """
    label = str(path)
    try:
        rows = np.loadtxt(path, delimiter=",", ndmin=2, comments="#")
    except (ValueError, OSError) as exc:
        text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputError(f"cannot read the DOF map: {text}", where=label) from None
    if rows.shape[1] != 5 or not np.all(np.isfinite(rows)):
        raise InputError("DOF map rows must be grid, component, x, y, z (numbers)", where=label)
    ids, comps = rows[:, 0], rows[:, 1]
    if np.any(ids != np.round(ids)) or np.any(ids < 1) or np.any(ids > 2**31):
        raise InputError("DOF map ids must be positive integers", where=label)
    if np.any(comps != np.round(comps)) or np.any((comps < 0) | (comps > 6)):
        raise InputError("DOF map components must be 1..6 (0: a scalar point)", where=label)
    pos: dict[int, np.ndarray] = {}
    for r in rows[comps > 0]:
        old = pos.setdefault(int(r[0]), r[2:5])
        if not np.array_equal(old, r[2:5]):
            raise InputError(f"grid {int(r[0])} has two positions", where=label)
    return _build(ids.astype(np.int64), comps.astype(int), pos, {}, f"{label} (DOF map file)")


def dof_map_for_op4(op4: str | Path, n_rows: int, superelement: int | None = None) -> DofMap:
    """The DOF map of an OP4's a-set matrices from the files beside it.

    The first found of ``<stem>.op2`` with USET tables, ``<stem>.pch`` with an EXTRN entry,
    ``<stem>.dofmap.csv``.  A map whose size is not the matrices' is an error naming both.

    Parameters
    ----------
    op4 : str or Path
        The OP4 file.
    n_rows : int
        The matrices' size (a-set DOFs).
    superelement : int, optional
        The superelement (an OP2 holding several).
    """
    p = Path(op4)
    tried: list[str] = []
    for suffix, reader in ((".op2", "op2"), (".pch", "pch"), (".dofmap.csv", "csv")):
        side = p.with_suffix(suffix)
        if not side.is_file():
            tried.append(f"{side.name} (absent)")
            continue
        if reader == "op2":
            from microg.models.op2 import read_op2_dof_tables

            if not any(t.uset is not None for t in read_op2_dof_tables(side)):
                tried.append(f"{side.name} (no USET table)")
                continue
            m = dof_map_from_op2(side, superelement)
        elif reader == "pch":
            m = dof_map_from_pch(side)
        else:
            m = dof_map_from_csv(side)
        if m.n != n_rows:
            raise InputError(
                f"the DOF map from {m.source} has {m.n} DOFs, the matrices {n_rows}",
                where=str(op4),
                fix="give the files of the run that wrote the OP4",
            )
        return m
    raise InputError(
        "an OP4 needs the DOFs of its rows: none of " + ", ".join(tried),
        where=str(op4),
        fix="put the run's OP2 (with USET, EQEXIN) or .pch beside it, or a "
        f"{p.with_suffix('.dofmap.csv').name} (grid, component, x, y, z per row)",
    )
