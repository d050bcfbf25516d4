"""NASTRAN SOL 103 results as modal models: OP2 (modes and geometry) and OP4 matrices.

:func:`modal_model_from_op2` reads an OP2 with :mod:`microg.models.op2` (a deck beside it,
:func:`microg.models.bdf.grid_geometry`, gives the geometry an OP2 lacks) and converts it
to SI with the user's unit declaration (:func:`microg.models.file_units.parse_units`).

OP4 matrices (MAA, KAA, a mode-shape/recovery matrix) are read by pyyeti's OP4 reader
(numpy 2 ready), imported lazily: without it, one line names the extra.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from microg.errors import InputError
from microg.models.bdf import grid_geometry
from microg.models.file_units import UnitSystem
from microg.models.modal import ModalModel, ModalPoint, build_modal_model, nearest_ids
from microg.models.op2 import Op2File, Op2Modes, read_op2_modes

__all__ = [
    "EXTRA_HINT",
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


@dataclass(frozen=True)
class Op4Model:
    """Matrices read from an OP4 file (file units).

    Attributes
    ----------
    path : str
    matrices : dict of str to ndarray
        Name (upper case) -> dense matrix.
    """

    path: str
    matrices: dict[str, np.ndarray]

    def get(self, name: str) -> np.ndarray:
        """The matrix ``name``; a missing one is an error listing those present."""
        key = name.upper()
        if key not in self.matrices:
            raise InputError(
                f"no matrix {name!r} in the file",
                where=self.path,
                fix=f"matrices present: {', '.join(sorted(self.matrices)) or 'none'}",
            )
        return self.matrices[key]


def _first_line(exc: BaseException) -> str:
    text = str(exc)
    return text.splitlines()[0] if text else ""


def read_op4(path: str | Path) -> Op4Model:
    """Read every matrix of an OP4 (ASCII or binary) with pyyeti's reader (lazy import)."""
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
            mats = op4.read(label, into="dct", sparse=False)
    except Exception as exc:  # pyyeti raises bare errors on corrupt files
        raise InputError(
            f"truncated or corrupt OP4: {type(exc).__name__}: {_first_line(exc)}",
            where=label,
        ) from None
    out = {}
    for k, v in mats.items():
        arr = v[0] if isinstance(v, tuple) else v
        out[str(k).upper()] = np.asarray(arr)
    return Op4Model(label, out)


def modal_model_from_op4(
    path: str | Path,
    units: UnitSystem,
    *,
    dof_map: np.ndarray,
    xyz: np.ndarray,
    grid_ids: np.ndarray,
    mass: str = "MAA",
    stiffness: str = "KAA",
    shapes: str | None = None,
    points: Sequence[ModalPoint] = (),
    n_modes: int | None = None,
) -> ModalModel:
    """A :class:`ModalModel` from OP4 matrices.

    Solves ``KAA phi = lambda MAA phi`` and recovers grid motion through ``shapes`` (rows on
    ``dof_map``) or takes the a-set itself.

    Parameters
    ----------
    path : OP4 file
    units : UnitSystem
    dof_map : ndarray (n, 2) int
        ``[grid, component 1..6]`` of each row of the recovery matrix (or of the a-set
        when ``shapes`` is None).
    xyz : ndarray (g, 3)
        Basic positions of ``grid_ids`` (file length unit).
    grid_ids : ndarray (g,)
    mass, stiffness : str
        Matrix names (a-set).
    shapes : str, optional
        Recovery matrix (rows: ``dof_map``; columns: a-set DOFs) -- e.g. a transformation
        to the grids' DOFs.
    n_modes : int, optional
        Lowest modes kept.
    """
    import scipy.linalg as sla

    op4m = read_op4(path)
    maa = op4m.get(mass).astype(float)
    kaa = op4m.get(stiffness).astype(float)
    if maa.shape != kaa.shape or maa.shape[0] != maa.shape[1]:
        raise InputError(f"{mass} and {stiffness} must be square of one size", where=op4m.path)
    lam, vec = sla.eigh(0.5 * (kaa + kaa.T), 0.5 * (maa + maa.T))
    if n_modes is not None:
        lam, vec = lam[:n_modes], vec[:, :n_modes]
    rec = op4m.get(shapes).astype(float) if shapes else np.eye(maa.shape[0])
    if rec.shape[1] != maa.shape[0]:
        raise InputError(
            f"{shapes} has {rec.shape[1]} columns, the a-set {maa.shape[0]} DOFs", where=op4m.path
        )
    dof_map = np.asarray(dof_map, int)
    if dof_map.shape != (rec.shape[0], 2):
        raise InputError(f"the DOF map must have shape ({rec.shape[0]}, 2)", where="dof_map")
    ids = np.asarray(grid_ids, np.int64)
    pos = {int(g): i for i, g in enumerate(ids)}
    g_shapes = np.zeros((ids.size, 6, lam.size))
    rows = rec @ vec
    for r, (gid, comp) in enumerate(dof_map):
        if int(gid) not in pos:
            raise InputError(f"DOF map row {r}: grid {gid} has no position", where="dof_map")
        if not 1 <= comp <= 6:
            raise InputError(f"DOF map row {r}: component {comp} is not 1..6", where="dof_map")
        g_shapes[pos[int(gid)], comp - 1] = rows[r]
    L, M = units.length_m, units.mass_kg
    phi = g_shapes.copy()
    phi[:, :3] /= np.sqrt(M)
    phi[:, 3:] /= np.sqrt(M) * L
    freq = np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi) / units.time_s
    # mass on the grids' DOFs when the a-set is the grid set (no recovery matrix)
    mg = None
    if shapes is None:
        mg = np.zeros((6 * ids.size, 6 * ids.size))
        idx = np.array([6 * pos[int(g)] + c - 1 for g, c in dof_map])
        sc = np.where(dof_map[:, 1] <= 3, 1.0, L)
        mg[np.ix_(idx, idx)] = maa * M * np.outer(sc, sc)
    return build_modal_model(
        name=Path(path).stem,
        grid_ids=ids,
        xyz_m=np.asarray(xyz, float) * L,
        freq_hz_signed=freq,
        phi=phi,
        units=units,
        source=op4m.path,
        points=points,
        mass_matrix=mg,
        mass_source="MAA" if mg is not None else "",
        meta={"reader": "pyyeti OP4", "mass": mass, "stiffness": stiffness, "shapes": shapes},
    )
