"""NASTRAN OP2 files: the OUTPUT2 records and the tables of a SOL 103 run, file units.

microg's own reader (pure numpy; no third-party reader works on numpy 2 for every table
needed here):

* the OUTPUT2 record structure, little- or big-endian, 32- or 64-bit words, with or
  without the "NASTRAN FORT TAPE ID CODE" header (MSC and Simcenter/NX files);
* ``LAMA``: mode number, extraction order, eigenvalue, radians, cycles, generalized mass
  and stiffness of each real mode;
* ``OUGV1`` / ``BOUGV1`` real eigenvectors (approach code 2, table code 7) in SORT1 (one
  record per mode) and SORT2 (one record per grid), grids and scalar points;
* geometry: ``GEOM1``/``GEOM1S`` GRID and CORD2R/C/S records (coordinate systems chained
  through their reference systems, :func:`microg.models.coords.chain_cord2`), else
  ``BGPDT``/``BGPDTS`` + ``EQEXIN``/``EQEXINS``; eigenvectors in a grid's output system
  (CD) are rotated to the basic frame (cylindrical and spherical systems at the grid's own
  angles, :meth:`Op2Modes.shapes_basic`), unless the table is BOUGV1 or PARAM OUGCORD is
  BASIC;
* ``OGPWG``: the grid point weight generator's 6x6 rigid-body mass about its reference
  point (input mass units, so times WTMASS), used for exact rigid-body modes;
* ``PVT0``: the run's PARAMs (WTMASS, OUGCORD, GRDPNT).

:func:`microg.models.nastran.modal_model_from_op2` converts what is read to SI.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from microg.errors import InputError
from microg.models.coords import (
    NASTRAN_KINDS,
    CoordinateFrame,
    Cord2,
    chain_cord2,
    nastran_coordinates,
)

__all__ = ["Op2DofTables", "Op2File", "Op2Modes", "read_op2_dof_tables", "read_op2_modes"]


# --------------------------------------------------------------------------- records


class Op2File:
    """The data blocks of an OP2 file: name -> list of tables, each a list of records.

    Attributes
    ----------
    path : str
    endian : str
        ``"<"`` or ``">"``.
    word : int
        4 (32-bit) or 8 (64-bit) bytes.
    tables : list of (name, trailer, records)
        In file order; ``records`` are the logical records' bytes (record 0 is the
        header record holding the name).
    """

    def __init__(self, path: str | Path):
        self.path = str(path)
        try:
            data = Path(path).read_bytes()
        except FileNotFoundError:
            raise InputError("no such file", where=self.path) from None
        except OSError as exc:
            raise InputError(f"cannot read: {exc.strerror or exc}", where=self.path) from None
        if len(data) < 8:
            raise InputError("not an OP2 file (shorter than one record)", where=self.path)
        first_le = struct.unpack("<i", data[:4])[0]
        first_be = struct.unpack(">i", data[:4])[0]
        if first_le in (4, 8):
            self.endian, self.word = "<", first_le
        elif first_be in (4, 8):
            self.endian, self.word = ">", first_be
        else:
            raise InputError(
                "not an OP2 file (the first Fortran record marker is not 4 or 8)",
                where=self.path,
            )
        self._data = data
        self._records = self._scan(data)
        self.tables = self._split()

    def _fail(self, what: str) -> InputError:
        return InputError(f"truncated or corrupt OP2: {what}", where=self.path)

    def _scan(self, data: bytes) -> list[tuple[int, int]]:
        n = len(data)
        fmt = self.endian + "i"
        out = []
        i = 0
        while i < n:
            if i + 4 > n:
                raise self._fail(f"a record marker is cut at byte {i}")
            length = struct.unpack_from(fmt, data, i)[0]
            end = i + 4 + length
            if length < 0 or end + 4 > n:
                raise self._fail(f"the record at byte {i} runs past the end of the file")
            if struct.unpack_from(fmt, data, end)[0] != length:
                raise self._fail(f"the record at byte {i} has mismatched length markers")
            out.append((i + 4, end))
            i = end + 4
        return out

    def _key(self, k: int) -> int | None:
        if k >= len(self._records):
            return None
        a, b = self._records[k]
        if b - a != self.word:
            return None
        return int(
            struct.unpack_from(self.endian + ("i" if self.word == 4 else "q"), self._data, a)[0]
        )

    def _bytes(self, k: int) -> bytes:
        a, b = self._records[k]
        return self._data[a:b]

    def _split(self) -> list[tuple[str, np.ndarray, list[bytes]]]:
        recs = self._records
        k = 0
        if self._key(0) == 3 and len(recs) > 1 and recs[1][1] - recs[1][0] == 3 * self.word:
            # MSC header: date, "NASTRAN FORT TAPE ID CODE", label, then -1, 0
            while k < len(recs) and self._key(k) != 0:
                k += 1
            k += 1
        tables = []
        while k < len(recs):
            n = self._key(k)
            if n is None:
                raise self._fail(f"expected a data block name at record {k}")
            if n == 0:
                break
            if k + 8 > len(recs):
                raise self._fail("a data block header is cut")
            name = self.name8(self._bytes(k + 1))
            trailer = np.frombuffer(
                self._bytes(k + 4), self.endian + ("i4" if self.word == 4 else "i8")
            )
            k += 8
            logical: list[bytes] = []
            while True:
                n = self._key(k)
                if n is None:
                    raise self._fail(f"data block {name} ends without its end marker")
                if n == 0:
                    k += 1
                    break
                if n > 0:
                    parts = []
                    while n is not None and n > 0:
                        if k + 1 >= len(recs):
                            raise self._fail(f"data block {name} is cut")
                        parts.append(self._bytes(k + 1))
                        k += 2
                        n = self._key(k)
                    logical.append(b"".join(parts))
                if n is None or n >= 0:
                    raise self._fail(f"data block {name}: bad record marker at record {k}")
                k += 3  # -r, 1, 0
            tables.append((name, trailer, logical))
        return tables

    def name8(self, raw: bytes) -> str:
        """An 8-character name in two words (a 64-bit word holds 4 characters and 4 blanks)."""
        if self.word == 8:
            raw = raw[:4] + raw[8:12]
        return raw[:8].decode("latin1").replace("\x00", " ").strip()

    def ints(self, rec: bytes) -> np.ndarray:
        """Record as integers."""
        return np.frombuffer(rec, self.endian + ("i4" if self.word == 4 else "i8"))

    def floats(self, rec: bytes) -> np.ndarray:
        """Record as reals."""
        return np.frombuffer(rec, self.endian + ("f4" if self.word == 4 else "f8"))

    def named(self, *names: str) -> list[tuple[str, np.ndarray, list[bytes]]]:
        """Tables whose name is one of ``names``, in file order."""
        return [t for t in self.tables if t[0] in names]


# --------------------------------------------------------------------------- OP2 tables


@dataclass(frozen=True)
class Op2Modes:
    """Real modes read from an OP2, in the file's units and output systems.

    Attributes
    ----------
    path : str
    table : str
        ``"OUGV1"`` or ``"BOUGV1"``.
    sort : str
        ``"SORT1"`` or ``"SORT2"``.
    mode : ndarray (m,) int
    eigenvalue : ndarray (m,)
        omega^2 in 1/time^2 (LAMA).
    generalized_mass : ndarray (m,)
        LAMA's generalized masses (mass x length^2 in consistent units).
    grid_ids : ndarray (g,) int
        Grids (scalar points excluded).
    shapes : ndarray (g, 6, m)
        Eigenvector components T1..R3 as in the file (each grid's output system).
    cd : ndarray (g,) int
        Output system of each grid's components (0 when the table is in basic).
    xyz_basic : ndarray (g, 3) or None
        Grid positions in basic (file length unit); NaN for a grid the OP2 does not place.
    coords : dict of int to CoordinateFrame
        Coordinate systems by id, origins in the file's length unit.
    rigid_mass : ndarray (6, 6) or None
        OGPWG's MO about ``rigid_mass_ref`` (input mass units: multiply by WTMASS).
    rigid_mass_ref : ndarray (3,) or None
        Basic coordinates of the OGPWG reference point.
    params : dict
        PARAMs from PVT0.
    n_scalar : int
        Scalar points dropped.
    superelements : tuple of int
        The superelements whose displacement tables were read (0: the residual).
    ambiguous : dict of int to tuple of int
        Grid IDs that several superelements give with different positions or motions, and
        those superelements; such grids are left out (a grid is named by its ID alone).
    eigenvalue_source : str
        ``"LAMA"``, or ``"OUGV1 headers"`` when the file has no LAMA (generalized masses are
        then 1: the vectors are taken as mass-normalised, EIGRL's default NORM=MASS).
    subcase : int
        The subcase read.
    tables : tuple of str
        The displacement tables read, ``"OUGV1 (SE 101)"``.
    grid_se : ndarray (g,) int
        The (first) superelement whose table gives each grid.
    """

    path: str
    table: str
    sort: str
    mode: np.ndarray
    eigenvalue: np.ndarray
    generalized_mass: np.ndarray
    grid_ids: np.ndarray
    shapes: np.ndarray
    cd: np.ndarray
    xyz_basic: np.ndarray | None
    coords: dict[int, CoordinateFrame] = field(default_factory=dict)
    rigid_mass: np.ndarray | None = None
    rigid_mass_ref: np.ndarray | None = None
    params: dict[str, Any] = field(default_factory=dict)
    n_scalar: int = 0
    superelements: tuple[int, ...] = (0,)
    ambiguous: dict[int, tuple[int, ...]] = field(default_factory=dict)
    eigenvalue_source: str = "LAMA"
    subcase: int = 1
    tables: tuple[str, ...] = ()
    grid_se: np.ndarray | None = None

    @property
    def freq_hz_signed(self) -> np.ndarray:
        """sign(eigenvalue) sqrt(|eigenvalue|) / 2 pi, Hz (file time unit)."""
        lam = self.eigenvalue
        return np.sign(lam) * np.sqrt(np.abs(lam)) / (2.0 * np.pi)

    def output_axes(self) -> np.ndarray:
        """Each grid's output system at the grid: columns its axes in basic, (g, 3, 3)."""
        out = np.broadcast_to(np.eye(3), (self.grid_ids.size, 3, 3)).copy()
        for cid in np.unique(self.cd):
            if cid == 0:
                continue
            sel = np.flatnonzero(self.cd == cid)
            cs = self.coords.get(int(cid))
            if cs is None or self.xyz_basic is None:
                self.shapes_basic()  # the error naming what is missing
                continue
            out[sel] = np.swapaxes(cs.axes_at(self.xyz_basic[sel]), -1, -2)
        return out

    def shapes_basic(self) -> np.ndarray:
        """Eigenvectors rotated from each grid's output system to basic, (g, 6, m)."""
        out = np.array(self.shapes, dtype=float)
        for cid in np.unique(self.cd):
            if cid == 0:
                continue
            sel = np.flatnonzero(self.cd == cid)
            cs = self.coords.get(int(cid))
            if cs is None:
                raise InputError(
                    f"grids {', '.join(str(g) for g in self.grid_ids[sel[:5]])} give output in "
                    f"coordinate system {cid}, which the file does not define",
                    where=self.path,
                    fix="give the BDF (with its CORD2 cards) beside the OP2",
                )
            if self.xyz_basic is None:
                raise InputError("no grid geometry to rotate output systems", where=self.path)
            t = np.swapaxes(cs.axes_at(self.xyz_basic[sel]), -1, -2)  # columns: axes
            out[sel, :3] = np.einsum("nab,nbm->nam", t, out[sel, :3])
            out[sel, 3:] = np.einsum("nab,nbm->nam", t, out[sel, 3:])
        return out


def _pvt0(f: Op2File) -> dict[str, Any]:
    params: dict[str, Any] = {}
    for _, _, recs in f.named("PVT0"):
        if len(recs) < 2:
            continue
        ints, flts = f.ints(recs[1]), f.floats(recs[1])
        raw = recs[1]
        w = f.word
        i = 0
        try:
            while i + 3 <= ints.size:
                name = f.name8(raw[i * w : (i + 2) * w])
                kind = int(ints[i + 2])
                i += 3
                if kind == 1:
                    params[name] = int(ints[i])
                    i += 1
                elif kind == 2:
                    params[name] = float(flts[i])
                    i += 1
                elif kind == 3:
                    params[name] = f.name8(raw[i * w : (i + 2) * w])
                    i += 2
                elif kind == 4:
                    params[name] = (
                        float(np.frombuffer(raw[i * w : (i + 2) * w], f.endian + "f8")[0])
                        if w == 4
                        else float(flts[i])
                    )
                    i += 2 if w == 4 else 1
                elif kind == 5:
                    i += 2
                elif kind == 6:
                    i += 4 if w == 4 else 2
                else:
                    break
        except (IndexError, UnicodeDecodeError, ValueError):
            pass
    return params


def _lama(f: Op2File) -> np.ndarray | None:
    """(m, 7): mode, order, eigenvalue, radians, cycles, genmass, genstiff."""
    for _, _, recs in f.named("LAMA"):
        if len(recs) < 3:
            continue
        data = recs[2]
        n = len(data) // (7 * f.word)
        if n * 7 * f.word != len(data):
            raise InputError("LAMA record length is not 7 words per mode", where=f.path)
        ints = f.ints(data).reshape(n, 7)
        flt = f.floats(data).reshape(n, 7)
        out = np.empty((n, 7))
        out[:, :2] = ints[:, :2]
        out[:, 2:] = flt[:, 2:]
        return out
    return None


def _geometry(
    f: Op2File,
) -> tuple[dict[int, tuple[int, np.ndarray, int]], dict[int, CoordinateFrame], set[int]]:
    """Grids and coordinate systems from GEOM1/GEOM1S.

    Returns grid id -> (cp, x in cp, cd), the systems, and the grid IDs that several
    GEOM1/GEOM1S tables (superelements) define differently.
    """
    grids: dict[int, tuple[int, np.ndarray, int]] = {}
    clash: set[int] = set()
    cords: dict[int, Cord2] = {}
    kinds = {(2101, 21, 8): "R", (2001, 20, 9): "C", (2201, 22, 10): "S"}
    for _, _, recs in f.named("GEOM1", "GEOM1S"):
        for rec in recs[1:]:
            ints = f.ints(rec)
            if ints.size < 3:
                continue
            head = tuple(int(v) for v in ints[:3])
            body_i, body_f = ints[3:], f.floats(rec)[3:]
            if head == (4501, 45, 1):
                n = body_i.size // 8
                bi, bf = body_i[: 8 * n].reshape(n, 8), body_f[: 8 * n].reshape(n, 8)
                for r in range(n):
                    gid = int(bi[r, 0])
                    new = (int(bi[r, 1]), bf[r, 2:5].astype(float), int(bi[r, 5]))
                    old = grids.setdefault(gid, new)
                    if old is not new and (
                        old[0] != new[0] or old[2] != new[2] or not np.array_equal(old[1], new[1])
                    ):
                        clash.add(gid)
            elif head in kinds:
                n = body_i.size // 13
                bi, bf = body_i[: 13 * n].reshape(n, 13), body_f[: 13 * n].reshape(n, 13)
                for r in range(n):
                    cid = int(bi[r, 0])
                    letter = kinds[head]
                    cords.setdefault(
                        cid,
                        Cord2(
                            cid,
                            NASTRAN_KINDS[letter],
                            int(bi[r, 3]),
                            bf[r, 4:13].astype(float).reshape(3, 3),
                            f"{f.path}: CORD2{letter} {cid}",
                        ),
                    )
            elif head[:2] in ((1701, 17), (1801, 18), (1901, 19)):
                raise InputError(
                    "CORD1R/C/S systems (defined by grids) are not supported in the OP2 geometry",
                    where=f.path,
                    fix="use CORD2R/C/S, or output in basic (PARAM,OUGCORD,BASIC)",
                )
    systems = chain_cord2(list(cords.values()))
    return grids, systems, clash


def _bgpdt(f: Op2File) -> dict[int, tuple[int, np.ndarray]]:
    """Grid id -> (cd, basic xyz) from BGPDT(S) + EQEXIN(S) (older 4-word layout)."""
    out: dict[int, tuple[int, np.ndarray]] = {}
    bg = f.named("BGPDT", "BGPDTS")
    eq = f.named("EQEXIN", "EQEXINS")
    for (_, _, brecs), (_, _, erecs) in zip(bg, eq, strict=False):
        if len(brecs) < 2 or len(erecs) < 2:
            continue
        e1 = f.ints(erecs[1]).reshape(-1, 2)  # external id, internal id
        rec = brecs[1]
        n = e1.shape[0]
        nw = len(rec) // f.word
        if nw != 4 * n:
            continue  # newer layouts: GEOM1 carries the geometry instead
        bi, bf = f.ints(rec).reshape(n, 4), f.floats(rec).reshape(n, 4)
        internal = {int(i): int(e) for e, i in e1}
        for row in range(n):
            ext = internal.get(row + 1)
            if ext is not None and bi[row, 0] >= 0:
                out.setdefault(ext, (int(bi[row, 0]), bf[row, 1:4].astype(float)))
    return out


def _ogpwg(f: Op2File) -> tuple[np.ndarray, int] | None:
    for _, _, recs in f.named("OGPWG"):
        if len(recs) < 3:
            continue
        ident = f.ints(recs[1])
        data = f.floats(recs[2]).astype(float)
        if data.size < 36:
            continue
        return data[:36].reshape(6, 6), int(ident[2]) if ident.size > 2 else 0
    return None


@dataclass(frozen=True)
class _Table:
    name: str
    recs: list[bytes]
    se: int
    subcase: int


def _eigenvector_tables(f: Op2File) -> tuple[list[_Table], list[str]]:
    """The real-mode displacement tables, and the others of those names, described."""
    out, other = [], []
    for name, _, recs in f.named("OUGV1", "BOUGV1", "OUGV2", "BOUGV2"):
        ident = f.ints(recs[1]) if len(recs) >= 2 else np.zeros(0, int)
        if len(recs) >= 3 and ident.size >= 10 and ident[0] // 10 == 2 and ident[1] % 1000 == 7:
            sub = recs[1][82 * f.word : 114 * f.word]
            if f.word == 8:
                sub = b"".join(sub[i : i + 4] for i in range(0, len(sub), 8))
            m = re.search(rb"SUPERELEMENT\s+(\d+)", sub)
            out.append(_Table(name, recs, int(m.group(1)) if m else 0, int(ident[3])))
        elif ident.size >= 2:
            other.append(
                f"{name} (approach code {int(ident[0]) // 10}, table code {int(ident[1])}: "
                "not real modes)"
            )
        else:
            other.append(f"{name} (empty)")
    return out, other


def _read_ougv(
    f: Op2File, name: str, recs: list[bytes], lama: np.ndarray | None
) -> tuple[str, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """(sort, mode numbers, eigenvalues from the records, grid ids, shapes (g, 6, m), n_scalar)."""
    w = f.word
    pairs = [(recs[i], recs[i + 1]) for i in range(1, len(recs) - 1, 2)]
    first = f.ints(pairs[0][0])
    tcode = int(first[1])
    sort2 = bool((tcode // 1000) & 2)
    if (tcode // 1000) & 1 or int(first[8]) not in (0, 1) or int(first[9]) != 8:
        raise InputError(
            f"{name} holds complex or non-standard eigenvectors (format {int(first[8])}, "
            f"{int(first[9])} words per entry); only real modes are read",
            where=f.path,
        )
    if not sort2:
        modes, eig, data = [], [], []
        for ident, rec in pairs:
            ii = f.ints(ident)
            modes.append(int(ii[4]))
            eig.append(float(f.floats(ident)[5]))
            data.append(rec)
        n = len(data[0]) // (8 * w)
        if any(len(d) != n * 8 * w for d in data):
            raise InputError(f"{name}: modes have different numbers of points", where=f.path)
        ints = f.ints(data[0]).reshape(n, 8)
        ids, types = ints[:, 0] // 10, ints[:, 1]
        vals = np.stack([f.floats(d).reshape(n, 8)[:, 2:] for d in data], axis=-1)
    else:
        ids_l, types_l, cols = [], [], []
        modes_arr = None
        for ident, rec in pairs:
            ii = f.ints(ident)
            nrow = len(rec) // (8 * w)
            ri, rf = f.ints(rec).reshape(nrow, 8), f.floats(rec).reshape(nrow, 8)
            ids_l.append(int(ii[4]) // 10)
            types_l.append(int(ri[0, 1]))
            cols.append(rf[:, 2:].T)  # (6, m)
            if modes_arr is None:
                key_i = ri[:, 0]
                if lama is not None and np.all((key_i >= 1) & (key_i <= 10**7)):
                    modes_arr = key_i.astype(int)
                elif lama is not None:
                    lam = lama[:, 2]
                    key_f = rf[:, 0].astype(float)
                    modes_arr = np.array([int(lama[np.argmin(np.abs(lam - v)), 0]) for v in key_f])
                else:
                    modes_arr = np.arange(1, nrow + 1)
        ids, types = np.array(ids_l), np.array(types_l)
        vals = np.stack(cols, axis=0)  # (n, 6, m)
        modes = list(modes_arr) if modes_arr is not None else []
        eig = [float("nan")] * len(modes)
    scalar = types != 1
    keep = ~scalar
    return (
        "SORT2" if sort2 else "SORT1",
        np.asarray(modes, int),
        np.asarray(eig, float),
        np.asarray(ids[keep], np.int64),
        np.asarray(vals[keep], float),
        int(np.count_nonzero(scalar)),
    )


def _merge(
    parts: list[tuple[_Table, tuple[Any, ...]]], clash: set[int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[int, tuple[int, ...]]]:
    """Grids of every superelement's table: (ids, shapes, in basic, SE, ambiguous ids)."""
    ids = np.concatenate([r[3] for _, r in parts])
    shp = np.concatenate([r[4] for _, r in parts], axis=0)
    se = np.concatenate([np.full(r[3].size, t.se) for t, r in parts])
    basic = np.concatenate([np.full(r[3].size, t.name.startswith("B")) for t, r in parts])
    order = np.argsort(ids, kind="stable")
    ids, shp, se, basic = ids[order], shp[order], se[order], basic[order]
    uniq, first, counts = np.unique(ids, return_index=True, return_counts=True)
    bad = np.isin(uniq, np.fromiter(clash, np.int64, len(clash)))
    ambiguous: dict[int, tuple[int, ...]] = {}
    for u in np.flatnonzero((counts > 1) | bad):
        a, n = first[u], counts[u]
        ref = shp[a]
        tol = 1e-6 * max(float(np.abs(ref).max()), 1e-30)
        same = all(
            basic[a + j] == basic[a] and float(np.abs(shp[a + j] - ref).max()) <= tol
            for j in range(1, n)
        )
        if bad[u] or not same:
            ambiguous[int(uniq[u])] = tuple(sorted({int(v) for v in se[a : a + n]}))
    keep = ~np.isin(uniq, np.fromiter(ambiguous, np.int64, len(ambiguous)))
    k = first[keep]
    return uniq[keep], shp[k], basic[k], se[k], ambiguous


def read_op2_modes(path: str | Path, *, subcase: int | None = None) -> Op2Modes:
    """Read the real modes of a SOL 103 OP2 (see the module docstring).

    Every superelement's displacement table of the subcase is read; a grid several
    superelements give alike (a boundary grid) is one grid, one they give differently is
    left out and listed in :attr:`Op2Modes.ambiguous`.  Without LAMA, the eigenvalues come
    from the OUGV1 record headers and the generalized masses are 1 (mass-normalised
    vectors); vectors normalised to a unit largest component are then refused.

    Parameters
    ----------
    path : str or Path
    subcase : int, optional
        The subcase to read (required when the file has modes of several).

    Raises
    ------
    InputError
        Not an OP2, truncated or corrupt, no eigenvectors or no eigenvalues, an unknown or
        unchosen subcase (one line naming the file).
    """
    f = Op2File(path)
    tables, other = _eigenvector_tables(f)
    lama = _lama(f)
    if not tables:
        names = ", ".join(sorted({t[0] for t in f.tables})) or "none"
        unusable = f"; unusable: {'; '.join(other)}" if other else ""
        raise InputError(
            "no real eigenvectors (no OUGV1/BOUGV1 table of SOL 103 modes; data blocks: "
            f"{names}{unusable})",
            where=f.path,
            fix="rerun with DISPLACEMENT(PLOT) = ALL and PARAM,POST,-1 or -2",
        )
    subs = sorted({t.subcase for t in tables})
    if subcase is None:
        if len(subs) > 1:
            raise InputError(
                f"the file holds modes of subcases {', '.join(str(v) for v in subs)}",
                where=f.path,
                fix="choose one with subcase=N",
            )
        subcase = subs[0]
    elif subcase not in subs:
        raise InputError(
            f"no modes of subcase {subcase} in the file (subcases: "
            f"{', '.join(str(v) for v in subs)})",
            where="subcase",
        )
    chosen: dict[int, _Table] = {}
    for t in tables:
        if t.subcase == subcase:
            chosen.setdefault(t.se, t)
    parts = [(t, _read_ougv(f, t.name, t.recs, lama)) for t in chosen.values()]
    t0, (sort, modes, eig_id, _, _, _) = parts[0]
    for t, r in parts[1:]:
        if not np.array_equal(r[1], modes):
            raise InputError(
                f"{t.name} of superelement {t.se} holds other modes than {t0.name} of "
                f"superelement {t0.se}",
                where=f.path,
            )
    if lama is not None:
        row = {int(mn): r for r, mn in enumerate(lama[:, 0].astype(int))}
        missing = [int(mn) for mn in modes if int(mn) not in row]
        if missing:
            raise InputError(
                f"{t0.name} mode {missing[0]} has no LAMA entry", where=f.path, fix="check the file"
            )
        sel = np.array([row[int(mn)] for mn in modes])
        eigenvalue, gm, eig_src = lama[sel, 2], lama[sel, 5], "LAMA"
    elif sort == "SORT1" and np.all(np.isfinite(eig_id)):
        eigenvalue, gm, eig_src = eig_id, np.ones(modes.size), "OUGV1 headers"
    else:
        raise InputError(
            "no LAMA table (eigenvalues and generalized masses), and SORT2 eigenvectors carry "
            "no eigenvalues",
            where=f.path,
            fix="rerun SOL 103 with PARAM,POST so that LAMA is written",
        )
    params = _pvt0(f)
    grids, systems, clash = _geometry(f)
    ids, shapes, in_basic, grid_se, ambiguous = _merge(parts, clash)
    n_scalar = sum(int(r[5]) for _, r in parts)
    if eig_src != "LAMA" and shapes.size:
        peak = np.abs(shapes).max(axis=(0, 1))
        if np.all(np.abs(peak - 1.0) <= 1e-6):
            raise InputError(
                "no LAMA table, and the eigenvectors are scaled to a unit largest component "
                "(EIGRL NORM=MAX): their generalized masses are unknown",
                where=f.path,
                fix="rerun with PARAM,POST so that LAMA is written, or with NORM=MASS",
            )
    name = t0.name
    xyz = None
    cd = np.zeros(ids.size, int)
    if grids:
        # grids the OP2 does not place (interior grids of an external superelement) are NaN
        nowhere = (-1, np.full(3, np.nan), 0)
        cps = np.array([grids.get(int(g), nowhere)[0] for g in ids], int)
        local = np.array([grids.get(int(g), nowhere)[1] for g in ids], float).reshape(-1, 3)
        cd = np.array([grids.get(int(g), nowhere)[2] for g in ids], int)
        xyz = np.full((ids.size, 3), np.nan)
        for cp in np.unique(cps[cps >= 0]):
            cs = systems.get(int(cp))
            if cs is None:
                raise InputError(
                    f"grids refer to coordinate system {cp}, not defined in the OP2", where=f.path
                )
            m = cps == cp
            xyz[m] = cs.to_basic(nastran_coordinates(cs.kind, local[m]))
    else:
        bg = _bgpdt(f)
        if bg and all(int(g) in bg for g in ids):
            cd = np.array([bg[int(g)][0] for g in ids])
            xyz = np.array([bg[int(g)][1] for g in ids])
    if str(params.get("OUGCORD", "")).upper() == "BASIC":
        in_basic = np.ones(ids.size, bool)
    cd = np.where(in_basic, 0, cd)
    gp = _ogpwg(f)
    rm = ref = None
    if gp is not None:
        rm, ref_grid = gp
        ref = np.zeros(3)
        if ref_grid > 0 and xyz is not None and ref_grid in set(ids.tolist()):
            ref = xyz[int(np.flatnonzero(ids == ref_grid)[0])]
        elif ref_grid > 0:
            rm = None  # reference grid unknown: do not guess its position
    return Op2Modes(
        path=f.path,
        table=name,
        sort=sort,
        mode=modes,
        eigenvalue=np.asarray(eigenvalue, float),
        generalized_mass=np.asarray(gm, float),
        grid_ids=ids,
        shapes=shapes,
        cd=cd,
        xyz_basic=xyz,
        coords=systems,
        rigid_mass=rm,
        rigid_mass_ref=ref,
        params=params,
        n_scalar=n_scalar,
        superelements=tuple(sorted(chosen)),
        ambiguous=ambiguous,
        eigenvalue_source=eig_src,
        subcase=int(subcase),
        tables=tuple(f"{t.name} (SE {t.se})" for t in chosen.values()),
        grid_se=grid_se,
    )


# --------------------------------------------------------------------------- DOF tables

#: USET bits (NASTRAN's NDDL, as pyyeti's ``n2p.mkusetmask`` lists them): the a-set is any
#: DOF with the A bit or one of its subsets' bits (Q, R, B, C); bit 1 is the B set's second
#: bit, which some writers also set on the S set, so it is cleared where an S bit (SG, SB) is
USET_A_MASK = (1 << 22) | 8 | (2 | (1 << 21)) | (1 << 20) | (1 << 7)
USET_S_MASK = (1 << 9) | (1 << 10)


@dataclass(frozen=True)
class Op2DofTables:
    """One superelement's DOF tables from an OP2 (USET, EQEXIN(S), BGPDT(S), CSTM(S)).

    Attributes
    ----------
    superelement : int
        From SLIST (its order of the superelements), 0 without one.
    uset : ndarray (n,) uint64 or None
        The USET word of each g-set DOF, internal order (bit 1 cleared on the S set).
    ids : ndarray (p,) int
        External ids of the points (grids and scalar points), internal order.
    kinds : ndarray (p,) int
        EQEXIN's point type: 1 grid (6 DOFs), 2 scalar point, 3 extra point (1 DOF).
    xyz : ndarray (p, 3)
        Basic positions (BGPDT; zero for scalar points), file length unit.
    cd : ndarray (p,) int
        Output (displacement) system of each point (-1 for scalar points).
    coords : dict of int to CoordinateFrame
        CSTM's systems (origin and axes resolved to basic by NASTRAN).
    tables : tuple of str
        The data blocks read, by their whole names.
    """

    superelement: int
    uset: np.ndarray | None
    ids: np.ndarray
    kinds: np.ndarray
    xyz: np.ndarray
    cd: np.ndarray
    coords: dict[int, CoordinateFrame]
    tables: tuple[str, ...]

    @property
    def dof_ids(self) -> np.ndarray:
        """The point id of each g-set DOF, internal order."""
        return np.repeat(self.ids, np.where(self.kinds == 1, 6, 1))

    @property
    def dof_components(self) -> np.ndarray:
        """The component of each g-set DOF: 1..6 on a grid, 0 on a scalar or extra point."""
        parts = [np.arange(1, 7) if k == 1 else np.zeros(1, int) for k in self.kinds]
        return np.concatenate(parts) if parts else np.zeros(0, int)

    def a_set(self) -> np.ndarray:
        """Boolean over the g-set DOFs: those in the a-set (from USET's bits)."""
        if self.uset is None:
            raise InputError(
                f"superelement {self.superelement} has no USET table", where=", ".join(self.tables)
            )
        u = self.uset.copy()
        s = (u & USET_S_MASK) != 0
        u[s] &= ~np.uint64(2)
        return (u & USET_A_MASK) != 0


def _eqexin(f: Op2File, recs: list[bytes], name: str) -> tuple[np.ndarray, np.ndarray]:
    """(external ids, internal ids, SIL*10 + type) from EQEXIN(S), sorted to internal order."""
    if len(recs) < 3:
        raise f._fail(f"{name} has {len(recs) - 1} records, not 2")
    r1, r2 = f.ints(recs[1]), f.ints(recs[2])
    if r1.size % 2 or r1.size != r2.size or not np.array_equal(r1[::2], r2[::2]):
        raise f._fail(f"{name}'s two records do not list the same points")
    order = np.argsort(r1[1::2], kind="stable")
    if not np.array_equal(np.sort(r1[1::2]), np.arange(1, r1.size // 2 + 1)):
        raise f._fail(f"{name}'s internal ids are not 1..{r1.size // 2}")
    return r1[::2][order].astype(np.int64), r2[1::2][order].astype(np.int64)


def _bgpdt_points(f: Op2File, recs: list[bytes], n: int, name: str) -> tuple[Any, Any]:
    """(cd, basic xyz) of ``n`` points in internal order from BGPDT(S), either layout."""
    if len(recs) < 2:
        raise f._fail(f"{name} has no data record")
    rec = recs[1]
    words = len(rec) // f.word
    if n and words == 4 * n:  # the older layout: cd, x, y, z (reals)
        bi, bf = f.ints(rec).reshape(n, 4), f.floats(rec).reshape(n, 4)
        return bi[:, 0].astype(int), bf[:, 1:4].astype(float)
    per = 6 + (6 if f.word == 4 else 3)  # cd, internal, external, type, set, boundary; xyz f8
    if n == 0 or words != per * n:
        raise f._fail(f"{name} holds {words} words, not {per} (or 4) for each of {n} points")
    dt = np.dtype([("i", f.endian + ("i4" if f.word == 4 else "i8"), 6), ("x", f.endian + "f8", 3)])
    data = np.frombuffer(rec, dt)
    return data["i"][:, 0].astype(int), data["x"].astype(float)


def _cstm(f: Op2File, recs: list[bytes], name: str) -> dict[int, CoordinateFrame]:
    """CSTM(S): id, type, origin and axes of each system (NASTRAN resolves them to basic)."""
    if len(recs) < 3:
        raise f._fail(f"{name} has {len(recs) - 1} records, not 2")
    r1 = f.ints(recs[1])
    vals = np.frombuffer(recs[2], f.endian + "f8")
    if r1.size % 4:
        raise f._fail(f"{name}'s first record is not 4 words per system")
    kinds = {1: "rectangular", 2: "cylindrical", 3: "spherical"}
    out = {}
    for cid, kind, _, at in r1.reshape(-1, 4):
        if int(kind) not in kinds or at < 1 or at - 1 + 12 > vals.size:
            raise f._fail(f"{name}: system {int(cid)} has type {int(kind)} or offset {int(at)}")
        v = vals[at - 1 : at + 11].astype(float)
        t = v[3:].reshape(3, 3)  # basic = T local + origin: T's columns are the axes
        out[int(cid)] = CoordinateFrame(f"cs:{int(cid)}", kinds[int(kind)], v[:3], t.T.copy())
    return out


def read_op2_dof_tables(path: str | Path) -> list[Op2DofTables]:
    """Every superelement's USET/EQEXIN(S)/BGPDT(S)/CSTM(S) of an OP2 (nas2cam's DMAP writes them).

    Layouts as pyyeti's ``nastran.op2.OP2.rdn2cop2`` and pyNastran read them: SLIST (7 words
    per superelement, the first its id) orders the superelements; each USET* table starts
    one superelement's group, EQEXIN(S) (record 1: external and internal ids, record 2:
    external id and 10 SIL + type, both in external order), CSTM(S) (record 1: id, type,
    -, offset into record 2's reals: origin and the 3x3 transformation to basic) and BGPDT(S)
    (each point's output system, 6 integers, basic x, y, z in 8-byte reals; or 4 words) follow.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    list of Op2DofTables
        One per superelement, in file order (empty when the file has no EQEXIN).
    """
    f = Op2File(path)
    selist: list[int] = []
    for _, _, recs in f.named("SLIST"):
        if len(recs) >= 2:
            r = f.ints(recs[1])
            if r.size % 7:
                raise f._fail("SLIST is not 7 words per superelement")
            selist = [int(v) for v in r[::7]]
    groups: list[dict[str, tuple[str, list[bytes]]]] = []
    for name, _, recs in f.tables:
        kind = next((k for k in ("USET", "EQEXIN", "BGPDT", "CSTM") if name.startswith(k)), None)
        if kind is None or name.startswith(("BGPDTOLD", "CSTMA")):
            continue
        if kind == "USET" or not groups or kind in groups[-1]:
            groups.append({})
        groups[-1][kind] = (name, recs)
    out = []
    for k, g in enumerate(groups):
        if "EQEXIN" not in g:
            continue
        se = selist[k] if k < len(selist) and len(selist) == len(groups) else (0 if k == 0 else k)
        ids, code = _eqexin(f, g["EQEXIN"][1], g["EQEXIN"][0])
        kinds = code % 10
        if np.any((kinds < 1) | (kinds > 3)):
            raise f._fail(f"{g['EQEXIN'][0]}: point types other than 1, 2, 3")
        n_dof = int(np.where(kinds == 1, 6, 1).sum())
        sil = code // 10
        first = np.concatenate([[1], 1 + np.cumsum(np.where(kinds == 1, 6, 1))[:-1]])
        if ids.size and not np.array_equal(sil, first):
            raise f._fail(f"{g['EQEXIN'][0]}: scalar index list out of internal order")
        xyz = np.zeros((ids.size, 3))
        cd = np.where(kinds == 1, 0, -1)
        if "BGPDT" in g:
            cd_b, xyz = _bgpdt_points(f, g["BGPDT"][1], ids.size, g["BGPDT"][0])
            cd = np.where(kinds == 1, cd_b, -1)
        coords = _cstm(f, g["CSTM"][1], g["CSTM"][0]) if "CSTM" in g else {}
        uset = None
        if "USET" in g:
            urecs = g["USET"][1]
            if len(urecs) < 2:
                raise f._fail(f"{g['USET'][0]} has no data record")
            uset = f.ints(urecs[1]).astype(np.int64).astype(np.uint64) & np.uint64(0xFFFFFFFF)
            if uset.size != n_dof:
                raise InputError(
                    f"{g['USET'][0]} of superelement {se} has {uset.size} DOFs, "
                    f"{g['EQEXIN'][0]} {n_dof}",
                    where=f.path,
                )
        out.append(
            Op2DofTables(
                superelement=se,
                uset=uset,
                ids=ids,
                kinds=kinds.astype(int),
                xyz=np.asarray(xyz, float),
                cd=np.asarray(cd, int),
                coords=coords,
                tables=tuple(v[0] for v in g.values()),
            )
        )
    return out
