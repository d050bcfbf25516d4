"""NASTRAN SOL 103 results as modal models: OP2 (modes and geometry) and OP4 matrices.

:func:`modal_model_from_op2` reads an OP2 with :mod:`microg.models.op2` (a deck beside it,
:func:`microg.models.bdf.grid_geometry`, gives the geometry an OP2 lacks) and converts it
to SI with the user's unit declaration (:func:`microg.models.file_units.parse_units`).

OP4 matrices (MAA, KAA or EXTSEOUT's MXX, KXX, a recovery matrix) are read by pyyeti's OP4
reader (numpy 2 ready), imported lazily: without it, one line names the extra.  Every
matrix is kept, duplicated names included (:class:`Op4Model`: ``NAME#k``, nas2cam's
SE_START blocks by superelement); the rows' DOFs come from :mod:`microg.models.dofmap`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from microg.errors import InputError
from microg.models.bdf import grid_geometry
from microg.models.dofmap import DofMap
from microg.models.file_units import UnitSystem
from microg.models.modal import ModalModel, ModalPoint, build_modal_model, nearest_ids
from microg.models.op2 import Op2File, Op2Modes, read_op2_modes

__all__ = [
    "EXTRA_HINT",
    "OP4_MASS_NAMES",
    "OP4_STIFFNESS_NAMES",
    "Op2File",
    "Op2Modes",
    "Op4Model",
    "modal_model_from_op2",
    "modal_model_from_op4",
    "read_op2_modes",
    "read_op4",
]

EXTRA_HINT = 'pip install "microg[nastran]"'


def modal_model_from_op2(
    path: str | Path,
    units: UnitSystem,
    *,
    points: Sequence[ModalPoint] = (),
    bdf: str | Path | Sequence[str | Path] | None = None,
    rigid_mass: np.ndarray | None = None,
    rigid_mass_ref_m: np.ndarray | None = None,
    replace_rigid: bool = True,
    subcase: int | None = None,
) -> ModalModel:
    """A :class:`ModalModel` (SI, basic frame, mass-normalised) from a SOL 103 OP2.

    Parameters
    ----------
    path : str or Path
    units : UnitSystem
        The run's units (``parse_units("in, lbf, s", wtmass=...)``).
    points : sequence of ModalPoint
        Named points (each grid must be in the file).
    bdf : path or sequence of paths, optional
        Decks for the positions of grids the OP2 does not place (no geometry tables, or the
        interior grids of an external superelement); default: ``<stem>.bdf``/``.dat`` beside.
        Grids placed nowhere are left out with a warning, and naming one says why.
    rigid_mass : ndarray (6, 6), optional
        Rigid-body mass, SI, about ``rigid_mass_ref_m`` (default: the OP2's OGPWG, if any).
    replace_rigid : bool
        Replace free-free rigid modes by exact ones
        (:func:`~microg.models.modal.replace_rigid_modes`).
    subcase : int, optional
        The subcase to read (required when the file has modes of several).
    """
    op2 = read_op2_modes(path, subcase=subcase)
    where = op2.path
    wtmass = _run_wtmass(op2, units)
    warnings: list[str] = []
    if op2.eigenvalue_source != "LAMA":
        warnings.append(
            "no LAMA table: eigenvalues from the OUGV1 record headers, generalized masses 1 "
            "(the vectors taken as mass-normalised, EIGRL NORM=MASS)"
        )
    xyz, cd = op2.xyz_basic, op2.cd
    coords = dict(op2.coords)
    basic_out = op2.table.startswith("B") or str(op2.params.get("OUGCORD", "")).upper() == "BASIC"
    unplaced = np.ones(op2.grid_ids.size, bool) if xyz is None else np.isnan(xyz).any(axis=1)
    if unplaced.any():
        decks = _decks(path, bdf)
        if xyz is None and not decks:
            raise InputError(
                "the OP2 has no grid geometry (no GEOM1 or BGPDT table) and no BDF is beside it",
                where=where,
                fix="rerun with PARAM,POST,-1/-2 (geometry written), or put the deck beside it",
            )
        xyz = np.full((op2.grid_ids.size, 3), np.nan) if xyz is None else xyz.copy()
        cd = cd.copy()
        for deck in decks:
            if not unplaced.any():
                break
            d_xyz, d_cd, d_sys = grid_geometry(deck, op2.grid_ids[unplaced], missing_ok=True)
            found = ~np.isnan(d_xyz).any(axis=1)
            rows = np.flatnonzero(unplaced)[found]
            xyz[rows] = d_xyz[found]
            if not basic_out:
                cd[rows] = d_cd[found]
            for cid, frame in d_sys.items():
                coords.setdefault(cid, frame)
            unplaced[rows] = False
    left_out: dict[str, str] = {}
    for gid, ses in op2.ambiguous.items():
        left_out[str(gid)] = (
            f"is in superelements {', '.join(str(v) for v in ses)} with different positions "
            "or motions (microg names a grid by its ID alone), so it was left out"
        )
    if unplaced.any():
        se_of = op2.grid_se if op2.grid_se is not None else np.zeros(op2.grid_ids.size, int)
        by_se: dict[int, list[int]] = {}
        for gid, se in zip(op2.grid_ids[unplaced], se_of[unplaced], strict=True):
            by_se.setdefault(int(se), []).append(int(gid))
            left_out[str(int(gid))] = (
                f"is in superelement {int(se)}'s displacement table, but neither the OP2 nor a "
                "deck gives its position, so it was left out"
            )
        for se, gids in sorted(by_se.items()):
            warnings.append(
                f"{len(gids)} grid(s) of superelement {se} (first: {gids[0]}) have no position in "
                "the OP2 or a deck: left out (give the superelement's deck, bdf=[...])"
            )
        keep = ~unplaced
        assert xyz is not None  # filled above
        op2 = Op2Modes(
            **{
                **op2.__dict__,
                "grid_ids": op2.grid_ids[keep],
                "shapes": op2.shapes[keep],
                "grid_se": None if op2.grid_se is None else op2.grid_se[keep],
            }
        )
        xyz, cd = xyz[keep], cd[keep]
    if op2.ambiguous:
        amb = sorted(op2.ambiguous)
        warnings.append(
            f"{len(amb)} grid ID(s) (first: {amb[0]}) are in several superelements with "
            "different positions or motions: left out"
        )
    assert xyz is not None  # from the OP2 or the decks
    data = Op2Modes(**{**op2.__dict__, "xyz_basic": xyz, "cd": cd, "coords": coords})
    shapes = data.shapes_basic()
    axes = data.output_axes()
    gm = op2.generalized_mass.astype(float)
    if np.any(gm <= 0) or not np.all(np.isfinite(gm)):
        raise InputError("LAMA has a non-positive generalized mass", where=where)
    L, M = units.length_m, units.mass_kg
    phi = shapes / np.sqrt(gm)[None, None, :]
    phi[:, :3] /= np.sqrt(M)
    phi[:, 3:] /= np.sqrt(M) * L
    freq = op2.freq_hz_signed / units.time_s
    rm, ref = None, None
    src = ""
    if rigid_mass is not None:
        rm, ref, src = np.asarray(rigid_mass, float), rigid_mass_ref_m, "given"
    elif op2.rigid_mass is not None and op2.rigid_mass_ref is not None:
        scale = np.ones((6, 6))
        scale[:3, 3:] = L
        scale[3:, :3] = L
        scale[3:, 3:] = L * L
        rm = op2.rigid_mass * wtmass * M * scale
        ref = op2.rigid_mass_ref * L
        src = "OGPWG"
    if op2.n_scalar:
        warnings.append(f"{op2.n_scalar} scalar points dropped (no position)")
    for p in points:
        if str(p.grid) in left_out:
            raise InputError(
                f"grid {p.grid} (point {p.name!r}) {left_out[str(p.grid)]}", where=where
            )
        if p.grid not in set(op2.grid_ids.tolist()):
            near = ", ".join(f"grid:{v}" for v in nearest_ids(op2.grid_ids, p.grid))
            raise InputError(
                f"grid {p.grid} (point {p.name!r}) is not in the file",
                where=where,
                fix=f"nearest grids: {near}",
            )
    return build_modal_model(
        name=Path(path).stem,
        grid_ids=op2.grid_ids,
        xyz_m=xyz * L,
        freq_hz_signed=freq,
        phi=phi,
        units=UnitSystem(
            units.text, units.length_m, units.force_N, units.time_s, M, wtmass, units.wtmass_given
        ),
        source=where,
        generalized_mass_kg_m2=gm * M * L * L,
        points=points,
        rigid_mass=rm,
        rigid_mass_ref_m=ref,
        mass_source=src,
        replace_rigid=replace_rigid,
        warnings=warnings,
        meta={
            "table": op2.table,
            "sort": op2.sort,
            "reader": "microg OP2",
            "tables": list(op2.tables),
            "subcase": op2.subcase,
            "eigenvalues": op2.eigenvalue_source,
            "grids_left_out": left_out,
        },
        dof_axes=axes,
    )


def _decks(path: str | Path, bdf: str | Path | Sequence[str | Path] | None) -> list[Path]:
    if bdf is None:
        return [c for c in (Path(path).with_suffix(x) for x in (".bdf", ".dat")) if c.is_file()][:1]
    if isinstance(bdf, str | Path):
        return [Path(bdf)]
    return [Path(b) for b in bdf]


def _run_wtmass(op2: Op2Modes, units: UnitSystem) -> float:
    """The run's WTMASS: the OP2's PVT0 (absent there: 1, the default), else the declared one.

    A declared WTMASS that contradicts the file is an error (``units.wtmass_given``).
    """
    if not op2.params:  # no PVT0: the file does not say
        return units.wtmass
    wt_file = float(op2.params.get("WTMASS", 1.0))
    if units.wtmass_given and abs(units.wtmass - wt_file) > 1e-6 * wt_file:
        said = "PARAM,WTMASS," + f"{wt_file:g}" if "WTMASS" in op2.params else "no PARAM,WTMASS (1)"
        raise InputError(
            f"WTMASS {units.wtmass:g} declared, but the run used {said}",
            where="wtmass",
            fix="declare the run's WTMASS or omit it",
        )
    return wt_file


# --------------------------------------------------------------------------- OP4


#: the a-set mass and stiffness names tried, in order: the nas2cam DMAP's and EXTSEOUT's
OP4_MASS_NAMES = ("MAA", "MXX")
OP4_STIFFNESS_NAMES = ("KAA", "KXX")
#: the most entries of one OP4 matrix read (dense, 8 bytes each: 400 MB; an a-set of 7,000)
MAX_OP4_ENTRIES = 50_000_000
#: the marker matrix that starts each superelement's matrices (pyyeti's nas2cam DMAP)
SE_START = "SE_START"


@dataclass(frozen=True)
class Op4Model:
    """Matrices read from an OP4 file (file units).

    Attributes
    ----------
    path : str
    matrices : dict of str to ndarray
        Name (upper case) -> dense matrix, for the names the file holds once.
    entries : tuple of (str, ndarray)
        Every matrix in file order, duplicated names included.
    """

    path: str
    matrices: dict[str, np.ndarray]
    entries: tuple[tuple[str, np.ndarray], ...] = ()

    def occurrences(self, name: str) -> list[np.ndarray]:
        """Every matrix named ``name`` (upper or lower case), in file order."""
        key = name.upper()
        found = [a for n, a in self.entries if n == key]
        return found or ([self.matrices[key]] if key in self.matrices else [])

    def get(self, name: str) -> np.ndarray:
        """The matrix ``name``, or ``NAME#k`` the k-th of a name the file holds several times.

        A missing name is an error listing those present; a duplicated name without ``#k``
        is an error listing its occurrences (never silently the last).
        """
        key, _, nth = name.upper().partition("#")
        found = self.occurrences(key)
        if not found:
            raise InputError(
                f"no matrix {key!r} in the file",
                where=self.path,
                fix=f"matrices present: {', '.join(self.names()) or 'none'}",
            )
        if nth:
            if not nth.isdigit() or not 1 <= int(nth) <= len(found):
                raise InputError(
                    f"{name!r}: the file holds {len(found)} matrices named {key}",
                    where=self.path,
                    fix=f"give {key}#1 to {key}#{len(found)}",
                )
            return found[int(nth) - 1]
        if len(found) > 1:
            listed = ", ".join(
                f"{key}#{k + 1} ({a.shape[0]}x{a.shape[1] if a.ndim > 1 else 1})"
                for k, a in enumerate(found)
            )
            raise InputError(
                f"the file holds {len(found)} matrices named {key}: {listed}",
                where=self.path,
                fix="choose one: NAME#k, or --superelement N when the file marks its "
                "superelements (SE_START)",
            )
        return found[0]

    def names(self) -> list[str]:
        """Names present, each once, in file order."""
        seen: dict[str, None] = {}
        for n, _ in self.entries or tuple(self.matrices.items()):
            seen.setdefault(n, None)
        return list(seen)

    def blocks(self) -> list[Op4Model]:
        """The superelement blocks of a nas2cam OP4 (each starts at an SE_START matrix).

        Empty when the file has no SE_START marker.  The blocks follow the superelements'
        order of the run's SLIST (pyyeti's ``rdnas2cam``); LOOP_END ends the last.
        """
        out: list[list[tuple[str, np.ndarray]]] = []
        for n, a in self.entries:
            if n == SE_START:
                out.append([])
            elif n == "LOOP_END":
                break
            elif out:
                out[-1].append((n, a))
        return [
            Op4Model(
                f"{self.path} (block {k + 1})",
                {n: a for n, a in b if sum(m == n for m, _ in b) == 1},
                tuple(b),
            )
            for k, b in enumerate(out)
        ]


def _first_line(exc: BaseException) -> str:
    text = str(exc)
    return text.splitlines()[0] if text else ""


def read_op4(path: str | Path) -> Op4Model:
    """Read every matrix of an OP4 (ASCII or binary) with pyyeti's reader (lazy import).

    Matrices of one name several times (one per superelement) are all kept, in file order.
    """
    label = str(path)
    if not Path(path).is_file():
        raise InputError("no such file", where=label)
    try:
        from pyyeti.nastran import op4
    except ImportError:
        raise InputError("reading OP4 needs pyyeti", where=label, fix=EXTRA_HINT) from None
    import warnings as _w

    try:
        with _w.catch_warnings():
            _w.simplefilter("ignore")
            # sizes first (headers only): a corrupt header must not allocate a huge matrix
            heads = op4.dir(label, verbose=False)
            for name, dims in zip(heads[0], heads[1], strict=True):
                r, c = (int(v) for v in dims)
                if r < 0 or c < 0 or r * c > MAX_OP4_ENTRIES:
                    raise InputError(
                        f"matrix {str(name).upper()} is {r} x {c}: more than "
                        f"{MAX_OP4_ENTRIES:.0e} entries (a corrupt header?)",
                        where=label,
                        fix="give the a-set matrices of the run",
                    )
            names, mats, *_ = op4.read(label, into="list", sparse=False)
    except InputError:
        raise
    except Exception as exc:  # pyyeti raises bare errors on corrupt files
        raise InputError(
            f"truncated or corrupt OP4: {type(exc).__name__}: {_first_line(exc)}",
            where=label,
        ) from None
    entries = []
    for k, v in zip(names, mats, strict=True):
        arr = np.asarray(v[0] if isinstance(v, tuple) else v)
        if arr.dtype.kind not in "fiuc" or (arr.size and not np.all(np.isfinite(arr))):
            raise InputError(
                f"matrix {str(k).upper()} holds values that are not finite numbers",
                where=label,
            )
        entries.append((str(k).upper(), arr))
    once = {n: a for n, a in entries if sum(m == n for m, _ in entries) == 1}
    return Op4Model(label, once, tuple(entries))


def _op4_scope(op4m: Op4Model, superelement: int | None) -> tuple[Op4Model, str]:
    """The matrices of the chosen superelement (a nas2cam OP4's blocks), or the whole file."""
    blocks = op4m.blocks()
    if not blocks:
        return op4m, ""
    from microg.models.op2 import read_op2_dof_tables

    side = Path(op4m.path).with_suffix(".op2")
    ses = (
        [t.superelement for t in read_op2_dof_tables(side) if t.uset is not None]
        if side.is_file()
        else []
    )
    if len(ses) != len(blocks):
        raise InputError(
            f"the file holds {len(blocks)} superelement blocks (SE_START), and "
            + (f"{side.name} lists {len(ses)} superelements" if ses else f"no {side.name} with "
               "USET tables is beside it to say which they are"),
            where=op4m.path,
            fix="put the run's nas2cam OP2 beside the OP4",
        )  # fmt: skip
    if superelement is None:
        if len(blocks) == 1:
            return blocks[0], f"superelement {ses[0]}"
        raise InputError(
            f"the file holds the matrices of superelements {', '.join(map(str, ses))}",
            where=op4m.path,
            fix="choose one with superelement=N",
        )
    if superelement not in ses:
        raise InputError(
            f"no superelement {superelement} in the file (superelements: "
            f"{', '.join(map(str, ses))})",
            where="superelement",
        )
    k = ses.index(superelement)
    return Op4Model(
        op4m.path, blocks[k].matrices, blocks[k].entries
    ), f"superelement {superelement}"


def _pick(op4m: Op4Model, name: str | None, tried: tuple[str, ...], what: str) -> str:
    if name is not None:
        return name
    for n in tried:
        if op4m.occurrences(n):
            return n
    raise InputError(
        f"no {what} matrix ({' or '.join(tried)}) in the file",
        where=op4m.path,
        fix=f"matrices present: {', '.join(op4m.names()) or 'none'}; name it (mass=, stiffness=)",
    )


def modal_model_from_op4(
    path: str | Path,
    units: UnitSystem,
    *,
    dof_map: DofMap | np.ndarray | None = None,
    xyz: np.ndarray | None = None,
    grid_ids: np.ndarray | None = None,
    mass: str | None = None,
    stiffness: str | None = None,
    shapes: str | None = None,
    points: Sequence[ModalPoint] = (),
    n_modes: int | None = None,
    superelement: int | None = None,
) -> ModalModel:
    """A :class:`ModalModel` from OP4 matrices.

    Solves ``KAA phi = lambda MAA phi`` (dense, :func:`scipy.linalg.eigh`) and recovers
    grid motion through ``shapes`` (rows on the DOF map) or takes the a-set itself.  Each
    grid's components are rotated from its output system (CD) to basic.  Scalar points
    (component 0: the modal coordinates of a Craig-Bampton reduction) are coordinates of
    the eigenproblem without a position: they are zero in rigid-body motion, so the
    rigid-body mass is ``R^T M_gg R`` over the grid rows.

    Parameters
    ----------
    path : OP4 file
    units : UnitSystem
    dof_map : DofMap or ndarray (n, 2) int, optional
        What each row of the recovery matrix (or of the a-set when ``shapes`` is None) is;
        default: from the run's files beside the OP4
        (:func:`microg.models.dofmap.dof_map_for_op4`: ``<stem>.op2`` USET/EQEXIN,
        ``<stem>.pch`` EXTRN, ``<stem>.dofmap.csv``).  An array ``[grid, component]``
        needs ``xyz`` and ``grid_ids``.
    xyz : ndarray (g, 3), optional
        Basic positions of ``grid_ids`` (file length unit), with an array ``dof_map``.
    grid_ids : ndarray (g,), optional
    mass, stiffness : str, optional
        Matrix names (a-set); ``NAME#k`` for the k-th of a duplicated name.  Default: the
        first present of MAA, MXX and of KAA, KXX.
    shapes : str, optional
        Recovery matrix (rows: the DOF map; columns: a-set DOFs).
    n_modes : int, optional
        Lowest modes kept.
    superelement : int, optional
        The superelement of an OP4 holding several (nas2cam's SE_START blocks, named by
        the OP2's SLIST beside it) and of an OP2 DOF map holding several.
    """
    from microg.models.dofmap import DofMap, dof_map_for_op4

    op4m, scope = _op4_scope(read_op4(path), superelement)
    mass = _pick(op4m, mass, OP4_MASS_NAMES, "mass")
    stiffness = _pick(op4m, stiffness, OP4_STIFFNESS_NAMES, "stiffness")
    maa = op4m.get(mass).astype(float)
    kaa = op4m.get(stiffness).astype(float)
    if maa.shape != kaa.shape or maa.ndim != 2 or maa.shape[0] != maa.shape[1]:
        raise InputError(f"{mass} and {stiffness} must be square of one size", where=op4m.path)
    for name, a in ((mass, maa), (stiffness, kaa)):
        top = float(np.abs(a).max()) if a.size else 0.0
        if top and float(np.abs(a - a.T).max()) > SYMMETRY_TOL * top:
            raise InputError(
                f"{name} is not symmetric (largest |A - A^T| is "
                f"{float(np.abs(a - a.T).max()) / top:.2g} of its largest entry)",
                where=op4m.path,
                fix="give the a-set mass and stiffness of the run (is the file corrupt?)",
            )
    rec = op4m.get(shapes).astype(float) if shapes else np.eye(maa.shape[0])
    if rec.ndim != 2 or rec.shape[1] != maa.shape[0]:
        raise InputError(
            f"{shapes} has {rec.shape[1]} columns, the a-set {maa.shape[0]} DOFs", where=op4m.path
        )
    if dof_map is None:
        dm = dof_map_for_op4(path, rec.shape[0], superelement)
    elif isinstance(dof_map, DofMap):
        dm = dof_map
    else:
        dm = _array_dof_map(dof_map, xyz, grid_ids, rec.shape[0])
    if dm.n != rec.shape[0]:
        raise InputError(
            f"the DOF map ({dm.source}) has {dm.n} rows, "
            + (f"{shapes} {rec.shape[0]}" if shapes else f"{mass} {rec.shape[0]}"),
            where="dof_map",
        )
    lam, vec, solve_notes = _solve_aset(kaa, maa, mass, stiffness, op4m.path)
    if n_modes is not None:
        lam, vec = lam[:n_modes], vec[:, :n_modes]
    ids = dm.grid_ids
    pos = {int(g): i for i, g in enumerate(ids)}
    g_shapes = np.zeros((ids.size, 6, lam.size))
    rows = rec @ vec
    grid_rows = np.flatnonzero(dm.components > 0)
    gi = np.array([pos[int(dm.ids[r])] for r in grid_rows], int)
    ci = dm.components[grid_rows] - 1
    g_shapes[gi, ci] = rows[grid_rows]
    # output systems (CD) to basic: u_basic = A u_cd, columns of A the system's axes
    g_shapes[:, :3] = np.einsum("gab,gbm->gam", dm.axes, g_shapes[:, :3])
    g_shapes[:, 3:] = np.einsum("gab,gbm->gam", dm.axes, g_shapes[:, 3:])
    L, M = units.length_m, units.mass_kg
    phi = g_shapes.copy()
    phi[:, :3] /= np.sqrt(M)
    phi[:, 3:] /= np.sqrt(M) * L
    freq = np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi) / units.time_s
    warnings: list[str] = [f"DOF map from {dm.source}", *solve_notes]
    n_sp = int(np.count_nonzero(dm.components == 0))
    mg = rm = None
    if shapes is None:
        # the a-set's grid rows: their mass, in basic, SI (M = A^T-rotated blocks)
        idx = 6 * gi + ci
        sc = np.where(ci < 3, 1.0, L)
        m_cd = np.zeros((6 * ids.size, 6 * ids.size))
        m_cd[np.ix_(idx, idx)] = maa[np.ix_(grid_rows, grid_rows)] * M * np.outer(sc, sc)
        rot = np.zeros((6 * ids.size, 6 * ids.size))
        for g in range(ids.size):
            rot[6 * g : 6 * g + 3, 6 * g : 6 * g + 3] = dm.axes[g]
            rot[6 * g + 3 : 6 * g + 6, 6 * g + 3 : 6 * g + 6] = dm.axes[g]
        m_basic = rot @ m_cd @ rot.T
        if n_sp:
            # scalar points are zero in rigid motion: the 6x6 R^T M R, not M itself (the
            # grid rows alone would M-orthogonalise the elastic modes without M_bq)
            from microg.models.rigid_modes import rigid_basis_at

            r = rigid_basis_at(np.asarray(dm.xyz, float) * L).reshape(6 * ids.size, 6)
            rm = r.T @ m_basic @ r
        else:
            mg = m_basic
    if n_sp:
        warnings.append(
            f"{n_sp} scalar point(s) (SPOINT, first {int(dm.scalar_points[0])}) are modal "
            "coordinates without a position: in the eigenproblem, not observable"
        )
    return build_modal_model(
        name=Path(path).stem,
        grid_ids=ids,
        xyz_m=np.asarray(dm.xyz, float) * L,
        freq_hz_signed=freq,
        phi=phi,
        units=units,
        source=op4m.path,
        points=points,
        mass_matrix=mg,
        rigid_mass=rm,
        rigid_mass_ref_m=np.zeros(3) if rm is not None else None,
        mass_source="MAA" if (mg is not None or rm is not None) else "",
        warnings=warnings,
        meta={
            "reader": "pyyeti OP4",
            "mass": mass,
            "stiffness": stiffness,
            "shapes": shapes,
            "superelement": scope or None,
            "dof_map": dm.source,
            "scalar_points": [int(v) for v in dm.scalar_points],
        },
        dof_axes=dm.axes,
    )


#: MAA/KAA asymmetry accepted, relative to the largest entry (NASTRAN's round-off: 6e-16 in
#: the real files of tests/data/nastran); more is a corrupt or foreign matrix, never averaged
SYMMETRY_TOL = 1e-9
#: a direction of the a-set whose mass is below this fraction of the largest is massless
MASSLESS_TOL = 1e-12


def _solve_aset(
    kaa: np.ndarray, maa: np.ndarray, mass: str, stiffness: str, where: str
) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Eigenpairs of ``K phi = lambda M phi`` with M only positive semi-definite.

    DOFs with neither mass nor stiffness (the unused modal coordinates NASTRAN leaves
    null) are zero in every mode.  The rest: ``M = V diag(d) V^T``; directions with
    ``d <= MASSLESS_TOL max(d)`` are massless and condensed statically (exact: a massless
    coordinate carries no inertia force, ``K_00 y_0 + K_0m y_m = 0``), the others solved
    with ``M* = diag(d_m)``, ``K* = K_mm - K_m0 K_00^-1 K_0m``.  Returns the eigenvalues,
    the a-set vectors (M-normalised) and notes for the output.
    """
    import scipy.linalg as sla

    k = 0.5 * (kaa + kaa.T)
    m = 0.5 * (maa + maa.T)
    n = m.shape[0]
    notes: list[str] = []
    null = ~(np.any(k != 0, axis=0) | np.any(m != 0, axis=0))
    live = np.flatnonzero(~null)
    if null.any():
        notes.append(
            f"{int(null.sum())} DOF(s) of {mass}/{stiffness} (rows "
            f"{', '.join(str(int(r) + 1) for r in np.flatnonzero(null)[:5])}"
            f"{', ...' if null.sum() > 5 else ''}) have neither mass nor stiffness: "
            "zero in every mode"
        )
    kl, ml = k[np.ix_(live, live)], m[np.ix_(live, live)]
    d, v = np.linalg.eigh(ml)
    top = float(np.abs(d).max()) if d.size else 0.0
    if top == 0.0 or d.min() < -MASSLESS_TOL * top:
        raise InputError(
            f"{mass} is not positive semi-definite (eigenvalue {d.min():.3g} of largest {top:.3g})",
            where=where,
            fix="give the a-set mass and stiffness of the run",
        )
    massive = d > MASSLESS_TOL * top
    vm, v0 = v[:, massive], v[:, ~massive]
    kt_mm, kt_m0, kt_00 = vm.T @ kl @ vm, vm.T @ kl @ v0, v0.T @ kl @ v0
    cond = np.zeros((v0.shape[1], vm.shape[1]))
    if v0.shape[1]:
        try:
            cho = sla.cho_factor(kt_00)
        except np.linalg.LinAlgError:
            raise InputError(
                f"{mass} has {v0.shape[1]} massless direction(s) that {stiffness} does not "
                "restrain (a massless mechanism)",
                where=where,
            ) from None
        cond = -sla.cho_solve(cho, kt_m0.T)
        notes.append(f"{v0.shape[1]} massless direction(s) of {mass} condensed statically (exact)")
    kstar = kt_mm + kt_m0 @ cond
    dm = d[massive]
    scale = 1.0 / np.sqrt(dm)
    lam, w = np.linalg.eigh(0.5 * (kstar + kstar.T) * np.outer(scale, scale))
    ym = w * scale[:, None]  # M*-normalised: ym^T diag(dm) ym = I
    vec = np.zeros((n, lam.size))
    vec[live] = vm @ ym + v0 @ (cond @ ym)
    return lam, vec, notes


def _array_dof_map(
    dof_map: np.ndarray, xyz: np.ndarray | None, grid_ids: np.ndarray | None, n: int
) -> DofMap:
    """A ``[grid, component]`` array with positions as a :class:`DofMap` (basic outputs)."""
    from microg.models.dofmap import DofMap

    dm = np.asarray(dof_map)
    if dm.ndim != 2 or dm.shape != (n, 2):
        raise InputError(f"the DOF map must have shape ({n}, 2)", where="dof_map")
    dm = dm.astype(int)
    if xyz is None or grid_ids is None:
        raise InputError("an array DOF map needs xyz and grid_ids", where="dof_map")
    ids = np.asarray(grid_ids, np.int64)
    pos = {int(g): i for i, g in enumerate(ids)}
    for r, (gid, comp) in enumerate(dm):
        if not 0 <= comp <= 6:
            raise InputError(f"DOF map row {r}: component {comp} is not 0..6", where="dof_map")
        if comp and int(gid) not in pos:
            raise InputError(f"DOF map row {r}: grid {gid} has no position", where="dof_map")
    used = np.unique(dm[dm[:, 1] > 0, 0])
    keep = np.array([pos[int(g)] for g in used], int)
    return DofMap(
        dm[:, 0].astype(np.int64),
        dm[:, 1],
        used.astype(np.int64),
        np.asarray(xyz, float).reshape(-1, 3)[keep],
        np.broadcast_to(np.eye(3), (used.size, 3, 3)).copy(),
        "dof_map",
    )
