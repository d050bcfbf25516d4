"""Imported modal models: frequencies and mode shapes at named grids, in SI.

A :class:`ModalModel` is what a NASTRAN SOL 103 run (:mod:`microg.models.nastran`), a UFF
file (:mod:`microg.models.uff`) or microg's own modal-model file gives: natural
frequencies, mass-normalised mode shapes at grids (6 DOF each, in the basic frame), the
grid geometry, optional modal damping, named points and the provenance of its units.
:mod:`microg.structure.modal` turns it into a :class:`~microg.structure.Structure` in
modal coordinates, so every solver and response path of microg works on it unchanged.

Conventions (SI inside, as everywhere in microg)
------------------------------------------------
* ``phi[g, :, j]`` is mode ``j`` at grid ``g``: translations (x, y, z) and rotations
  (about x, y, z) of the basic frame, mass-normalised (``phi^T M phi = I``).  With the
  modal coordinate ``eta`` in m sqrt(kg) (kinetic energy ``eta'^2 / 2``), translations are
  in m per (m sqrt(kg)) = 1/sqrt(kg) and rotations in rad per (m sqrt(kg)).
* Converting a source in units (L, F, T): :mod:`microg.models.file_units`.
* Rigid-body modes of a free-free run are replaced by exact ones
  (:mod:`microg.models.rigid_modes`, :func:`build_modal_model`).

Own file format (``.npz``, numpy's zip of ``.npy`` arrays, read without pickle)
--------------------------------------------------------------------------------
``format`` = ``"microg-modal-model"``, ``version`` = 1, and the arrays ``grid_ids`` (g,)
int64, ``xyz_m`` (g, 3), ``omega`` (m,) rad/s, ``phi`` (g, 6, m), ``rigid`` (m,) bool,
``zeta`` (m,) (NaN: not given), ``generalized_mass_kg_m2`` (m,), ``rigid_mass`` (6, 6)
about the basic origin (NaN: unknown); ``name``; ``points_json`` (a JSON list of
``{"name", "grid", "offset_m", "kind", "description"}``) and ``meta_json`` (JSON object:
source, units, replaced_rigid, warnings).  All values SI.

Points/options file (TOML)
--------------------------
::

    units = "in, lbf, s"        # length, force, time of the source file (NASTRAN: required)
    wtmass = 0.00259            # NASTRAN PARAM,WTMASS of the run (default: from the OP2, else 1)

    [points]
    lab = "grid:2001"
    crew = { grid = "grid:55", kind = "crew", offset = ["0 in", "0 in", "12 in"] }

``kind`` is ``"crew"``, ``"experiment"`` or ``"point"`` (default); ``offset`` is the
point's position minus the grid's, in the basic frame (a rigid offset: the point moves as
``u + theta x offset``).
"""

from __future__ import annotations

import io
import json
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from microg._io import loads_toml
from microg.errors import InputError, ModelError
from microg.models.file_units import SI_UNITS, UnitSystem, check_positive, parse_units
from microg.models.rigid_modes import (
    MIN_RIGID_GRIDS,
    RIGID_GAP,
    RIGID_MAX_HZ,
    RIGID_TOL,
    ReplacedRigid,
    replace_rigid_modes,
    rigid_basis_at,
    shift_rigid_mass,
)
from microg.units import parse_quantity

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "POINT_KINDS",
    "RIGID_GAP",
    "RIGID_TOL",
    "SI_UNITS",
    "MAX_GRIDS",
    "MAX_MODES",
    "MIN_RIGID_GRIDS",
    "RIGID_MAX_HZ",
    "ModalModel",
    "ModalPoint",
    "ModelOptions",
    "ReplacedRigid",
    "UnitSystem",
    "parse_units",
    "parse_grid",
    "read_options",
    "rigid_basis_at",
    "replace_rigid_modes",
    "shift_rigid_mass",
    "nearest_ids",
    "save_modal_model",
    "load_modal_model",
]

FORMAT = "microg-modal-model"
FORMAT_VERSION = 1
POINT_KINDS = ("crew", "experiment", "point")
#: size limits of a modal model (memory: 48 bytes per grid and mode)
MAX_GRIDS = 2_000_000
MAX_MODES = 20_000


# --------------------------------------------------------------------------- points


@dataclass(frozen=True)
class ModalPoint:
    """A named point riding rigidly on a grid.

    Attributes
    ----------
    name : str
    grid : int
        Grid ID.
    offset_m : ndarray (3,)
        Point position minus grid position, basic frame, m.
    kind : str
        ``"crew"``, ``"experiment"`` or ``"point"``.
    description : str
    """

    name: str
    grid: int
    offset_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    kind: str = "point"
    description: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (the own file's ``points_json`` rows)."""
        return {
            "name": self.name,
            "grid": int(self.grid),
            "offset_m": [float(v) for v in self.offset_m],
            "kind": self.kind,
            "description": self.description,
        }


def parse_grid(text: Any, *, where: str) -> int:
    """Grid ID of ``"grid:1001"`` (or a bare positive integer)."""
    if isinstance(text, bool):
        raise InputError(f"expected 'grid:N', got {text!r}", where=where)
    if isinstance(text, int):
        value = text
    elif isinstance(text, str) and text.strip().lower().startswith("grid:"):
        body = text.strip()[5:]
        if not body.isdigit():
            raise InputError(f"{text!r} is not 'grid:N' with N a positive integer", where=where)
        value = int(body)
    else:
        raise InputError(
            f"expected a grid such as 'grid:1001', got {text!r}",
            where=where,
            fix='write e.g. lab = "grid:2001"',
        )
    if value <= 0 or value >= 2**31:
        raise InputError(f"grid ID {value} is out of range 1..2^31-1", where=where)
    return int(value)


@dataclass(frozen=True)
class ModelOptions:
    """What a points/options file says about a modal model.

    Attributes
    ----------
    units : str or None
        The unit declaration (``"in, lbf, s"``).
    wtmass : float or None
    points : tuple of ModalPoint
    source : str
        The file it was read from.
    """

    units: str | None = None
    wtmass: float | None = None
    points: tuple[ModalPoint, ...] = ()
    source: str = ""


def read_options(path: str | Path) -> ModelOptions:
    """Read a points/options TOML file (see the module docstring for its format)."""
    label = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ModelError("no such file", where=label, fix="give the points file's path") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"cannot read: {exc}", where=label) from None
    doc = loads_toml(text, label, ModelError)
    known = {"units", "wtmass", "points"}
    extra = sorted(set(doc) - known)
    if extra:
        raise ModelError(
            f"unknown key {extra[0]!r}",
            where=f"{label}: {extra[0]}",
            fix="use units, wtmass, points",
        )
    units = doc.get("units")
    if units is not None and not isinstance(units, str):
        raise ModelError("units must be a string such as 'in, lbf, s'", where=f"{label}: units")
    wtmass = doc.get("wtmass")
    if wtmass is not None:
        wtmass = check_positive(wtmass, f"{label}: wtmass")
    table = doc.get("points", {})
    if not isinstance(table, dict):
        raise ModelError("[points] must be a table of name = 'grid:N'", where=f"{label}: points")
    length_unit = None
    if units is not None:
        length_unit = units.split(",")[0].strip() or None
    points = []
    for name, spec in table.items():
        w = f"{label}: points.{name}"
        if isinstance(spec, dict):
            bad = sorted(set(spec) - {"grid", "kind", "offset", "description"})
            if bad:
                raise ModelError(
                    f"unknown key {bad[0]!r}",
                    where=f"{w}.{bad[0]}",
                    fix="use grid, kind, offset, description",
                )
            if "grid" not in spec:
                raise ModelError("missing grid", where=w, fix='add grid = "grid:N"')
            grid = parse_grid(spec["grid"], where=f"{w}.grid")
            kind = spec.get("kind", "point")
            if kind not in POINT_KINDS:
                raise ModelError(
                    f"unknown kind {kind!r}", where=f"{w}.kind", fix="use crew, experiment, point"
                )
            offset = np.zeros(3)
            if "offset" in spec:
                off = spec["offset"]
                if not isinstance(off, list) or len(off) != 3:
                    raise ModelError("offset must be 3 lengths", where=f"{w}.offset")
                offset = np.array(
                    [
                        parse_quantity(v, "length", where=f"{w}.offset", default_unit=length_unit)
                        for v in off
                    ]
                )
            desc = spec.get("description", "")
            if not isinstance(desc, str):
                raise ModelError("description must be a string", where=f"{w}.description")
            points.append(ModalPoint(name, grid, offset, kind, desc))
        else:
            points.append(ModalPoint(name, parse_grid(spec, where=w)))
    return ModelOptions(units=units, wtmass=wtmass, points=tuple(points), source=label)


def nearest_ids(ids: np.ndarray, wanted: int, count: int = 5) -> list[int]:
    """The ``count`` IDs of ``ids`` nearest to ``wanted`` (for 'not in the file' errors)."""
    ids = np.asarray(ids, dtype=np.int64)
    if ids.size == 0:
        return []
    order = np.argsort(np.abs(ids - wanted), kind="stable")[:count]
    return sorted(int(v) for v in ids[order])


# --------------------------------------------------------------------------- the model


@dataclass(frozen=True)
class ModalModel:
    """Modes of a structure at grids, SI, basic frame (see the module docstring).

    Attributes
    ----------
    name : str
    grid_ids : ndarray (g,) int64
        Grid IDs, ascending, unique.
    xyz_m : ndarray (g, 3)
        Grid positions in the basic frame, m.
    omega : ndarray (m,)
        Natural frequencies, rad/s, ascending; exactly 0 for the rigid-body modes.
    phi : ndarray (g, 6, m)
        Mass-normalised shapes (translations 1/sqrt(kg), rotations rad/(m sqrt(kg))).
    rigid : ndarray (m,) bool
        The exact rigid-body modes.
    zeta : ndarray (m,) or None
        Modal damping ratios where the source gives them.
    generalized_mass_kg_m2 : ndarray (m,)
        The source's generalized masses (its own normalisation of the shapes, with a
        dimensionless modal coordinate), kg m^2; 1 for mass-normalised sources.
    points : tuple of ModalPoint
        Named points (from the points file).
    rigid_mass : ndarray (6, 6) or None
        Rigid-body mass about the basic origin, SI (kg, kg m, kg m^2), when known.
    units : UnitSystem
        The source's units (provenance; values here are SI).
    source : str
        File read.
    replaced_rigid : ReplacedRigid or None
    warnings : tuple of str
    meta : mapping
    """

    name: str
    grid_ids: np.ndarray
    xyz_m: np.ndarray
    omega: np.ndarray
    phi: np.ndarray
    rigid: np.ndarray
    zeta: np.ndarray | None = None
    generalized_mass_kg_m2: np.ndarray | None = None
    points: tuple[ModalPoint, ...] = ()
    rigid_mass: np.ndarray | None = None
    units: UnitSystem = SI_UNITS
    source: str = ""
    replaced_rigid: ReplacedRigid | None = None
    warnings: tuple[str, ...] = ()
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        g, m = self.grid_ids.shape[0], self.omega.shape[0]
        where = self.source or "modal model"
        checks = [
            (self.grid_ids.ndim == 1, "grid_ids must be 1-D"),
            (self.xyz_m.shape == (g, 3), f"xyz_m must have shape ({g}, 3)"),
            (self.phi.shape == (g, 6, m), f"phi must have shape ({g}, 6, {m})"),
            (self.rigid.shape == (m,), f"rigid must have shape ({m},)"),
            (g <= MAX_GRIDS, f"more than {MAX_GRIDS:,} grids"),
            (m <= MAX_MODES, f"more than {MAX_MODES:,} modes"),
            (bool(np.all(np.diff(self.grid_ids) > 0)), "grid IDs must be ascending and unique"),
            (bool(np.all(np.isfinite(self.omega)) and np.all(self.omega >= 0)), "bad omega"),
            (bool(np.all(np.isfinite(self.phi))), "mode shapes must be finite"),
            (bool(np.all(np.isfinite(self.xyz_m))), "grid positions must be finite"),
        ]
        for ok, msg in checks:
            if not ok:
                raise ModelError(msg, where=where)
        if self.zeta is not None and (
            self.zeta.shape != (m,) or not np.all((self.zeta >= 0) & (self.zeta < 1))
        ):
            raise ModelError("zeta must have one value 0 <= zeta < 1 per mode", where=where)
        for p in self.points:
            self.grid_index(p.grid, where=f"{where}: points.{p.name}")

    @property
    def freq_hz(self) -> np.ndarray:
        """Natural frequencies, Hz."""
        return self.omega / (2.0 * np.pi)

    @property
    def n_modes(self) -> int:
        """Number of modes."""
        return int(self.omega.size)

    @property
    def n_grids(self) -> int:
        """Number of grids."""
        return int(self.grid_ids.size)

    def grid_index(self, grid: int, *, where: str = "grid") -> int:
        """Row of ``grid``; a grid not in the model is an error listing the nearest IDs."""
        i = int(np.searchsorted(self.grid_ids, grid))
        if i < self.grid_ids.size and self.grid_ids[i] == grid:
            return i
        left_out = self.meta.get("grids_left_out") or {}
        if str(grid) in left_out:
            raise InputError(
                f"grid {grid} {left_out[str(grid)]}",
                where=where,
                fix="give the deck with its GRID card (bdf=...), or name another grid",
            )
        near = ", ".join(f"grid:{v}" for v in nearest_ids(self.grid_ids, grid))
        raise InputError(
            f"grid {grid} is not in {self.source or 'the model'}",
            where=where,
            fix=f"nearest grids: {near}",
        )

    def point(self, name: str) -> ModalPoint:
        """A named point, or ``grid:N`` as a point at that grid."""
        for p in self.points:
            if p.name == name:
                return p
        if isinstance(name, str) and name.lower().startswith("grid:"):
            gid = parse_grid(name, where=name)
            self.grid_index(gid, where=name)
            return ModalPoint(f"grid:{gid}", gid)
        known = ", ".join(p.name for p in self.points) or "(none)"
        raise InputError(
            f"unknown point {name!r}", where=name, fix=f"named points: {known}; or grid:N"
        )

    def with_points(self, points: Sequence[ModalPoint]) -> ModalModel:
        """The same model with ``points`` added (a later name replaces an earlier one)."""
        merged = {p.name: p for p in self.points}
        merged.update({p.name: p for p in points})
        return replace(self, points=tuple(merged.values()))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (no shapes)."""
        return {
            "name": self.name,
            "source": self.source,
            "n_grids": self.n_grids,
            "n_modes": self.n_modes,
            "omega": self.omega,
            "freq_hz": self.freq_hz,
            "rigid": self.rigid,
            "zeta": self.zeta,
            "units": self.units.to_dict(),
            "replaced_rigid": None
            if self.replaced_rigid is None
            else self.replaced_rigid.to_dict(),
            "points": [p.to_dict() for p in self.points],
            "warnings": list(self.warnings),
        }

    def to_xarray(self) -> Any:
        """The shapes as an ``xarray.Dataset`` (dims grid, dof, mode; units in attrs)."""
        import xarray as xr

        return xr.Dataset(
            {
                "phi": (("grid", "dof", "mode"), self.phi, {"units": "mass-normalised, SI"}),
                "xyz_m": (("grid", "axis"), self.xyz_m, {"units": "m"}),
                "omega": (("mode",), self.omega, {"units": "rad/s"}),
                "rigid": (("mode",), self.rigid),
            },
            coords={
                "grid": self.grid_ids,
                "dof": ["x", "y", "z", "rx", "ry", "rz"],
                "mode": np.arange(1, self.n_modes + 1),
                "axis": ["x", "y", "z"],
            },
            attrs={"name": self.name, "source": self.source, "units_declared": self.units.text},
        )


def build_modal_model(
    *,
    name: str,
    grid_ids: np.ndarray,
    xyz_m: np.ndarray,
    freq_hz_signed: np.ndarray,
    phi: np.ndarray,
    units: UnitSystem,
    source: str,
    generalized_mass_kg_m2: np.ndarray | None = None,
    zeta: np.ndarray | None = None,
    points: Sequence[ModalPoint] = (),
    rigid_mass: np.ndarray | None = None,
    rigid_mass_ref_m: np.ndarray | None = None,
    mass_matrix: Any = None,
    mass_source: str = "",
    replace_rigid: bool = True,
    warnings: Sequence[str] = (),
    meta: Mapping[str, Any] | None = None,
    dof_axes: np.ndarray | None = None,
) -> ModalModel:
    """Assemble a :class:`ModalModel` from SI data, replacing free-free rigid modes.

    Parameters are those of :class:`ModalModel` (SI, mass-normalised ``phi`` in the basic
    frame, grids in any order) plus the signed file frequencies, the optional mass
    sources and the grids' output systems ``dof_axes`` (g, 3, 3) of
    :func:`replace_rigid_modes`.
    """
    ids = np.asarray(grid_ids, dtype=np.int64)
    order = np.argsort(ids, kind="stable")
    ids, xyz, phi = ids[order], np.asarray(xyz_m, float)[order], np.asarray(phi, float)[order]
    axes = None if dof_axes is None else np.asarray(dof_axes, float)[order]
    if ids.size and np.any(np.diff(ids) == 0):
        dup = int(ids[np.flatnonzero(np.diff(ids) == 0)[0]])
        raise ModelError(f"grid {dup} appears twice", where=source)
    f = np.asarray(freq_hz_signed, float)
    gm = np.ones(f.size) if generalized_mass_kg_m2 is None else np.asarray(generalized_mass_kg_m2)
    z = None if zeta is None else np.asarray(zeta, float)
    warn = list(warnings)
    if mass_matrix is not None:
        # grid order changed: permute the mass matrix's grid blocks the same way
        perm = (6 * order[:, None] + np.arange(6)).ravel()
        mass_matrix = mass_matrix[perm][:, perm]
    replaced = None
    if replace_rigid:
        omega, phi2, rigid, replaced, w2 = replace_rigid_modes(
            f,
            phi,
            xyz,
            rigid_mass=rigid_mass,
            rigid_mass_ref_m=rigid_mass_ref_m,
            mass_matrix=mass_matrix,
            mass_source=mass_source,
            grid_ids=ids,
            dof_axes=axes,
        )
        mode_order = np.argsort(np.abs(f), kind="stable")
        gm, z = gm[mode_order], (None if z is None else z[mode_order])
        if replaced is not None:
            gm = gm.copy()
            gm[: replaced.count] = 1.0
            if z is not None:
                z = z.copy()
                z[: replaced.count] = 0.0
        warn += w2
    else:
        mode_order = np.argsort(np.abs(f), kind="stable")
        omega = 2.0 * np.pi * np.abs(f[mode_order])
        phi2 = phi[:, :, mode_order]
        rigid = omega == 0.0
        gm, z = gm[mode_order], (None if z is None else z[mode_order])
    rm = None
    if rigid_mass is not None:
        ref = np.zeros(3) if rigid_mass_ref_m is None else rigid_mass_ref_m
        rm = shift_rigid_mass(np.asarray(rigid_mass, float), ref, np.zeros(3))
    elif mass_matrix is not None:
        rf = rigid_basis_at(xyz).reshape(-1, 6)
        rm = rf.T @ np.asarray(mass_matrix @ rf)
    return ModalModel(
        name=name,
        grid_ids=ids,
        xyz_m=xyz,
        omega=np.asarray(omega, float),
        phi=np.ascontiguousarray(phi2),
        rigid=np.asarray(rigid, bool),
        zeta=z,
        generalized_mass_kg_m2=np.asarray(gm, float),
        points=tuple(points),
        rigid_mass=rm,
        units=units,
        source=source,
        replaced_rigid=replaced,
        warnings=tuple(warn),
        meta=dict(meta or {}),
    )


# --------------------------------------------------------------------------- own file


def save_modal_model(model: ModalModel, path: str | Path) -> Path:
    """Write ``model`` as microg's own modal-model file (``.npz``, schema above), atomically."""
    from microg._io import atomic_write_bytes

    nan_m = np.full(model.n_modes, np.nan)
    meta = {
        "source": model.source,
        "units": model.units.to_dict(),
        "replaced_rigid": None if model.replaced_rigid is None else model.replaced_rigid.to_dict(),
        "warnings": list(model.warnings),
        "meta": {k: v for k, v in model.meta.items() if _jsonable(v)},
    }
    arrays: dict[str, Any] = {
        "format": np.array(FORMAT),
        "version": np.array(FORMAT_VERSION),
        "name": np.array(model.name),
        "grid_ids": model.grid_ids.astype(np.int64),
        "xyz_m": model.xyz_m,
        "omega": model.omega,
        "phi": model.phi,
        "rigid": model.rigid,
        "zeta": nan_m if model.zeta is None else model.zeta,
        "generalized_mass_kg_m2": (
            np.ones(model.n_modes)
            if model.generalized_mass_kg_m2 is None
            else model.generalized_mass_kg_m2
        ),
        "rigid_mass": np.full((6, 6), np.nan) if model.rigid_mass is None else model.rigid_mass,
        "points_json": np.array(json.dumps([p.to_dict() for p in model.points])),
        "meta_json": np.array(json.dumps(meta)),
    }
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    out = Path(path)
    atomic_write_bytes(out, buf.getvalue())
    return out


def _jsonable(v: Any) -> bool:
    try:
        json.dumps(v)
    except (TypeError, ValueError):
        return False
    return True


def load_modal_model(path: str | Path, *, points: Sequence[ModalPoint] = ()) -> ModalModel:
    """Read microg's own modal-model file (see :func:`save_modal_model`)."""
    label = str(path)
    try:
        with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise InputError("no such file", where=label) from None
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise InputError(
            f"not a readable microg modal-model file (truncated or corrupt): {exc}",
            where=label,
        ) from None
    need = ("format", "version", "grid_ids", "xyz_m", "omega", "phi", "rigid")
    missing = [k for k in need if k not in data]
    if missing or str(data.get("format", "")) != FORMAT:
        raise InputError(
            f"not a microg modal-model file (missing {', '.join(missing) or 'format tag'})",
            where=label,
        )
    if int(data["version"]) > FORMAT_VERSION:
        raise InputError(
            f"file version {int(data['version'])} is newer than this microg reads "
            f"({FORMAT_VERSION})",
            where=label,
            fix="upgrade microg",
        )
    try:
        meta = json.loads(str(data.get("meta_json", "{}")))
        pts = json.loads(str(data.get("points_json", "[]")))
    except json.JSONDecodeError as exc:
        raise InputError(f"corrupt metadata: {exc}", where=label) from None
    zeta = data.get("zeta")
    if zeta is not None and np.all(np.isnan(zeta)):
        zeta = None
    rm = data.get("rigid_mass")
    if rm is not None and np.any(np.isnan(rm)):
        rm = None
    rr = meta.get("replaced_rigid")
    replaced = None
    if rr:
        replaced = ReplacedRigid(
            count=int(rr["count"]),
            max_file_freq_hz=float(rr["max_file_freq_hz"]),
            file_freq_hz=tuple(rr.get("file_freq_hz", ())),
            max_rigid_residual=float(rr.get("max_rigid_residual", 0.0)),
            first_elastic_hz=rr.get("first_elastic_hz"),
            mass_source=str(rr.get("mass_source", "")),
            rule=str(rr.get("rule", "")),
            fit_grids=int(rr.get("fit_grids", 0)),
            excluded_grids=tuple(int(v) for v in rr.get("excluded_grids", ())),
        )
    u = meta.get("units") or {}
    units = UnitSystem(
        str(u.get("declared", "m, N, s")),
        float(u.get("length_m", 1.0)),
        float(u.get("force_N", 1.0)),
        float(u.get("time_s", 1.0)),
        float(u.get("mass_kg", 1.0)),
        float(u.get("wtmass", 1.0)),
        bool(u.get("wtmass_given", False)),
    )
    file_points = tuple(
        ModalPoint(
            p["name"],
            int(p["grid"]),
            np.asarray(p["offset_m"], float),
            p["kind"],
            p.get("description", ""),
        )
        for p in pts
    )
    model = ModalModel(
        name=str(data.get("name", Path(label).stem)),
        grid_ids=np.asarray(data["grid_ids"], np.int64),
        xyz_m=np.asarray(data["xyz_m"], float),
        omega=np.asarray(data["omega"], float),
        phi=np.asarray(data["phi"], float),
        rigid=np.asarray(data["rigid"], bool),
        zeta=zeta,
        generalized_mass_kg_m2=data.get("generalized_mass_kg_m2"),
        points=file_points,
        rigid_mass=rm,
        units=units,
        source=label,
        replaced_rigid=replaced,
        warnings=tuple(meta.get("warnings", ())),
        meta=meta.get("meta", {}),
    )
    return model.with_points(points) if points else model
