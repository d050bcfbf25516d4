"""Universal File Format (UFF): nodes (15, 2411), modes (55), units (164), time histories (58).

microg's own reader and writer, vectorised (numbers parsed and formatted by numpy, not node
by node).  pyuff is not used: it writes dataset 55 only as ``E13.5`` (6 significant digits)
and reads it in fixed 13-column fields, so it can neither write nor read the lossless
``precision="double"`` files below; it is the tests' independent reader of the standard
single-precision files.

Precision.  The standard writes dataset 55 values as ``6E13.5`` (6 significant digits)
and dataset 15 coordinates as ``3E13.5``; ``precision="single"`` (the default) writes
exactly that, readable by every UFF tool (pyuff included).  ``precision="double"`` writes
nodes as 2411 (``3D25.16``) and 55 with data type 4 (double) in ``E25.16`` fields, lossless
(a round trip equals the original to rounding), for readers that parse numbers by
whitespace (microg does).

Units.  Dataset 164 states the file's units as factors: SI value = file value / factor
(length, force, temperature, offset).  microg writes SI (code 1, factors 1).  A file read
without a 164 needs a unit declaration.

Shapes.  Dataset 55 (analysis type 2, normal modes) holds each mode's frequency (Hz),
modal mass, viscous damping ratio and the 6 (or 3) components per node in the global
frame.  A modal mass of 0 means "not given": the shapes are taken as mass-normalised, with
a warning.
"""

from __future__ import annotations

import io
import json
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from microg.errors import InputError
from microg.models.file_units import UnitSystem
from microg.models.modal import ModalModel, ModalPoint, build_modal_model

__all__ = [
    "UffDataset",
    "data_values",
    "dataset_units",
    "read_uff",
    "modal_model_from_uff",
    "write_uff_modes",
    "write_uff_time",
]

_PRECISIONS = ("single", "double")
#: a NASTRAN grid's sample label (its id kept in the export)
_GRID_LABEL = re.compile(r"grid:(\d+)")


@dataclass(frozen=True)
class UffDataset:
    """One dataset: its number, header lines and the numeric data section's text."""

    number: int
    lines: list[str] = field(repr=False)
    start_line: int = 0


def read_uff(path: str | Path) -> list[UffDataset]:
    """Split a UFF file into datasets (delimited by ``-1`` lines)."""
    label = str(path)
    try:
        text = Path(path).read_text(encoding="latin-1")
    except FileNotFoundError:
        raise InputError("no such file", where=label) from None
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror or exc}", where=label) from None
    binary = re.search(r"^\s*-1[ \t]*\r?\n[ \t]*(\d+)[bB]", text, re.MULTILINE)
    if binary:
        line = text.count("\n", 0, binary.start(1)) + 1
        raise InputError(
            f"line {line}: dataset {binary.group(1)}b is binary UFF, which microg does not read",
            where=label,
            fix="write the file as ASCII UFF (pyuff: binary=0)",
        )
    lines = text.splitlines()
    marks = [i for i, ln in enumerate(lines) if ln.strip() == "-1"]
    if len(marks) < 2:
        raise InputError("not a UFF file (no '-1' dataset delimiters)", where=label)
    if len(marks) % 2:
        raise InputError(
            f"truncated UFF: the dataset starting at line {marks[-1] + 1} has no closing -1",
            where=label,
        )
    out = []
    for a, b in zip(marks[::2], marks[1::2], strict=True):
        head = lines[a + 1].split() if a + 1 < b else []
        if not head or not head[0].lstrip("-").isdigit():
            raise InputError(f"line {a + 2}: no dataset number", where=label)
        out.append(UffDataset(int(head[0]), lines[a + 2 : b], a + 2))
    return out


def _numbers(lines: Sequence[str], where: str) -> np.ndarray:
    text = " ".join(lines).replace("D", "E").replace("d", "e")
    try:
        return np.array(text.split(), dtype=float)
    except ValueError:
        raise InputError("non-numeric data", where=where) from None


def _fixed(lines: Sequence[str], width: int) -> np.ndarray:
    vals: list[float] = []
    for ln in lines:
        s = ln.rstrip()
        vals.extend(float(s[i : i + width].replace("D", "E")) for i in range(0, len(s), width))
    return np.array(vals)


def data_values(lines: Sequence[str], where: str, width: int) -> np.ndarray:
    """Numbers of a data section: whitespace-separated, or ``width``-wide fields that touch."""
    try:
        return _numbers(lines, where)
    except InputError:
        pass
    try:
        return _fixed(lines, width)
    except ValueError:
        raise InputError("non-numeric data", where=where) from None


def dataset_units(ds: UffDataset, where: str) -> UnitSystem:
    """The unit system of a dataset 164 (SI value = file value / factor).

    Parameters
    ----------
    ds : UffDataset
        A dataset 164.
    where : str
        The file, for errors.
    """
    rec1 = ds.lines[0]
    nums = _numbers(ds.lines[1:], where)
    if nums.size < 2:
        raise InputError("dataset 164 has no unit factors", where=where)
    f_len, f_force = nums[0], nums[1]
    if f_len <= 0 or f_force <= 0:
        raise InputError("dataset 164: non-positive unit factors", where=where)
    length, force = 1.0 / f_len, 1.0 / f_force
    desc = rec1[10:30].strip() or "UFF 164"
    return UnitSystem(f"{desc} (UFF 164)", length, force, 1.0, force / length)


def _nodes(ds: UffDataset, where: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    nums = _numbers(ds.lines, where)
    if nums.size % 7:
        raise InputError(f"dataset {ds.number}: node records are not 7 values each", where=where)
    rows = nums.reshape(-1, 7)
    return rows[:, 0].astype(np.int64), rows[:, 4:7], rows[:, 1:3].astype(int)


def _mode55(ds: UffDataset, where: str) -> dict[str, Any]:
    ln = ds.lines
    if len(ln) < 8:
        raise InputError(f"line {ds.start_line}: dataset 55 header is cut", where=where)
    rec6 = ln[5].split()
    if len(rec6) < 6:
        raise InputError(f"line {ds.start_line + 5}: dataset 55 record 6 is cut", where=where)
    analysis, data_type, ndv = int(rec6[1]), int(rec6[4]), int(rec6[5])
    if analysis != 2:
        raise InputError(
            f"line {ds.start_line}: dataset 55 of analysis type {analysis}; only normal modes (2)",
            where=where,
        )
    if data_type not in (2, 4) or ndv not in (3, 6):
        raise InputError(
            f"line {ds.start_line}: dataset 55 data type {data_type} with {ndv} values per node "
            "(only real 3- or 6-DOF modes)",
            where=where,
        )
    rec7 = ln[6].split()
    nreal = int(rec7[1])
    mode_n = int(rec7[3]) if len(rec7) > 3 else 0
    nreal_lines = (nreal + 5) // 6
    reals = _numbers(ln[7 : 7 + nreal_lines], where)
    body = ln[7 + nreal_lines :]
    nums = _numbers(body, where)
    if nums.size % (ndv + 1):
        try:  # fixed-width fields that touch (I-DEAS style E13.5 without separating blanks)
            ids = np.array([int(x) for x in body[::2]])
            vals = _fixed(body[1::2], 13).reshape(ids.size, ndv)
        except (ValueError, IndexError):
            raise InputError(
                f"line {ds.start_line}: dataset 55 node data is cut or malformed", where=where
            ) from None
    else:
        rows = nums.reshape(-1, ndv + 1)
        ids, vals = rows[:, 0].astype(np.int64), rows[:, 1:]
    return {
        "mode": mode_n,
        "freq_hz": float(reals[0]),
        "modal_mass": float(reals[1]) if reals.size > 1 else 0.0,
        "zeta": float(reals[2]) if reals.size > 2 else 0.0,
        "ids": ids,
        "values": vals,
        "ndv": ndv,
    }


def modal_model_from_uff(
    path: str | Path,
    *,
    units: UnitSystem | None = None,
    points: Sequence[ModalPoint] = (),
    rigid_mass: np.ndarray | None = None,
    replace_rigid: bool = True,
) -> ModalModel:
    """A :class:`ModalModel` from a UFF file with nodes (15 or 2411) and modes (55).

    Parameters
    ----------
    path : str or Path
    units : UnitSystem, optional
        Needed when the file has no dataset 164 (and then must agree with it if both).
    points : sequence of ModalPoint
    rigid_mass : ndarray (6, 6), optional
        Rigid-body mass about the origin, SI, for exact rigid-mode normalisation.
    replace_rigid : bool
    """
    where = str(path)
    sets = read_uff(path)
    u164 = [d for d in sets if d.number == 164]
    file_units = dataset_units(u164[0], where) if u164 else None
    if file_units is None and units is None:
        raise InputError(
            "no units: the file has no dataset 164 and no unit declaration was given",
            where=where,
            fix='declare the units, e.g. units = "m, N, s"',
        )
    if units is not None and units.wtmass_given:
        raise InputError(
            "applies to NASTRAN files only: a UFF file's masses are in its declared units",
            where="wtmass",
            fix="leave it out",
        )
    if file_units is not None and units is not None:
        for a, b, what in (
            (file_units.length_m, units.length_m, "length"),
            (file_units.force_N, units.force_N, "force"),
            (file_units.time_s, units.time_s, "time"),
        ):
            if abs(a - b) > 1e-6 * b:
                raise InputError(
                    f"declared {what} unit disagrees with the file's dataset 164",
                    where=where,
                    fix="omit the declaration (the file states its units)",
                )
    u = file_units or units
    assert u is not None
    node_sets = [d for d in sets if d.number in (15, 2411)]
    if not node_sets:
        raise InputError("no node dataset (15 or 2411)", where=where)
    ids_l, xyz_l = [], []
    for d in node_sets:
        i, x, cs = _nodes(d, where)
        if np.any(cs > 1):  # 0 or 1: the global (part) system
            raise InputError(
                f"dataset {d.number}: nodes in local coordinate systems are not supported",
                where=where,
                fix="export nodes and shapes in the global frame",
            )
        ids_l.append(i)
        xyz_l.append(x)
    ids = np.concatenate(ids_l)
    xyz = np.concatenate(xyz_l)
    ids, first = np.unique(ids, return_index=True)
    xyz = xyz[first]
    modes = [_mode55(d, where) for d in sets if d.number == 55]
    if not modes:
        raise InputError("no mode shapes (dataset 55)", where=where)
    pos = np.searchsorted(ids, np.concatenate([md["ids"] for md in modes]))
    if np.any(pos >= ids.size) or np.any(
        ids[np.minimum(pos, ids.size - 1)] != np.concatenate([md["ids"] for md in modes])
    ):
        raise InputError("dataset 55 refers to a node not in the node datasets", where=where)
    g, m = ids.size, len(modes)
    phi = np.zeros((g, 6, m))
    warnings: list[str] = []
    gm = np.ones(m)
    for j, md in enumerate(modes):
        rows = np.searchsorted(ids, md["ids"])
        phi[rows, : md["ndv"], j] = md["values"]
        if md["modal_mass"] > 0:
            gm[j] = md["modal_mass"]
    if any(md["modal_mass"] <= 0 for md in modes):
        warnings.append("dataset 55 gives no modal mass for some modes: taken as mass-normalised")
    if any(md["ndv"] == 3 for md in modes):
        warnings.append("3-DOF shapes: rotations are zero (offset points move with the grid)")
    L, M = u.length_m, u.mass_kg
    phi = phi / np.sqrt(gm)[None, None, :]
    phi[:, :3] /= np.sqrt(M)
    phi[:, 3:] /= np.sqrt(M) * L
    freq = np.array([md["freq_hz"] for md in modes])
    zeta = np.array([md["zeta"] for md in modes])
    return build_modal_model(
        name=Path(path).stem,
        grid_ids=ids,
        xyz_m=xyz * L,
        freq_hz_signed=freq,
        phi=phi,
        units=u,
        source=where,
        generalized_mass_kg_m2=np.ones(m) if np.all(gm == 1) else gm * M * L * L,
        zeta=zeta if np.any(zeta > 0) else None,
        points=points,
        rigid_mass=rigid_mass,
        mass_source="given" if rigid_mass is not None else "",
        replace_rigid=replace_rigid,
        warnings=warnings,
        meta={"reader": "microg UFF"},
    )


# --------------------------------------------------------------------------- writing


def _block(number: int, body: str) -> str:
    return f"{-1:6d}\n{number:6d}\n{body}{-1:6d}\n"


def _fmt_rows(values: np.ndarray, fmt: str) -> str:
    """Rows of ``values`` formatted with ``fmt`` (one line each)."""
    if values.size == 0:
        return ""
    buf = io.StringIO()
    np.savetxt(buf, values, fmt=fmt, delimiter="")
    return buf.getvalue()


def _clip(a: np.ndarray) -> np.ndarray:
    """Values below 1e-99 in magnitude written as 0 (E13.5 has room for 2 exponent digits)."""
    a = np.asarray(a, float)
    return np.where(np.abs(a) < 1e-99, 0.0, a)


def _units_block() -> str:
    head = f"{1:10d}{'SI: meter (newton)':>20s}{2:10d}\n"
    body = f"{1.0:25.16E}{1.0:25.16E}{1.0:25.16E}\n{273.15:25.16E}\n"
    return _block(164, head + body)


def _nodes_block(ids: np.ndarray, xyz: np.ndarray, precision: str) -> str:
    n = ids.size
    if precision == "single":
        arr = np.column_stack([ids, np.zeros(n), np.zeros(n), np.full(n, 11), _clip(xyz)])
        return _block(15, _fmt_rows(arr, "%10d%10d%10d%10d%13.5E%13.5E%13.5E"))
    ints = np.column_stack([ids, np.zeros(n), np.zeros(n), np.full(n, 11)]).astype(np.int64)
    lines1 = _fmt_rows(ints, "%10d%10d%10d%10d").splitlines()
    lines2 = _fmt_rows(xyz, "%25.16E%25.16E%25.16E").splitlines()
    body = "".join(f"{a}\n{b}\n" for a, b in zip(lines1, lines2, strict=True))
    return _block(2411, body)


def _mode_block(
    ids: np.ndarray,
    values: np.ndarray,
    j: int,
    freq_hz: float,
    zeta: float,
    name: str,
    precision: str,
) -> str:
    dtype = 2 if precision == "single" else 4
    head = (
        f"{name[:80]:<80s}\nmicrog mass-normalised mode shapes (SI)\nNONE\n"
        f"{'mode ' + str(j + 1):<80s}\n"
        f"{'Mode ' + str(j + 1) + ', ' + format(freq_hz, '.6g') + ' Hz':<80s}\n"
        f"{1:10d}{2:10d}{3:10d}{8:10d}{dtype:10d}{6:10d}\n"
        f"{2:10d}{4:10d}{1:10d}{j + 1:10d}\n"
    )
    if precision == "single":
        head += f"{freq_hz:13.5E}{1.0:13.5E}{zeta:13.5E}{0.0:13.5E}\n"
        vals = _fmt_rows(_clip(values), "%13.5E" * 6).splitlines()
    else:
        head += f"{freq_hz:25.16E}{1.0:25.16E}{zeta:25.16E}{0.0:25.16E}\n"
        vals = _fmt_rows(values, "%25.16E" * 6).splitlines()
    idl = [f"{int(i):10d}" for i in ids]
    body = "".join(f"{a}\n{b}\n" for a, b in zip(idl, vals, strict=True))
    return _block(55, head + body)


def _from_modes(
    modes: Any,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, int], str]:
    """(ids, xyz_m, omega, shapes (g, 6, m), named point -> node, name) of a Modes object.

    Nodes: the structure's samples (frame nodes and body masses, rotations of their node),
    then one node per named point (its own translation map, offsets included).
    """
    st = modes.structure
    phi = np.asarray(modes.phi)
    samples = st.samples
    tr_l, rot_l, xyz_l = [], [], []
    if samples is not None and hasattr(samples, "phi_t"):
        raise TypeError("modes of a modal model: pass the ModalModel itself")
    grid_ids: list[int] | None = None
    if samples is not None and hasattr(samples, "rot_index"):
        tr_l.append(np.asarray(samples.displacement(phi)))  # (p, 3, m), offsets included
        rot_l.append(phi[np.asarray(samples.rot_index)])
        xyz_l.append(np.asarray(samples.position, float))
    elif samples is not None and hasattr(samples, "rows") and len(samples):
        # a frame model's samples (microg.structure.frame.FrameSamples): the 6 DOFs of each
        # sample's node from the coordinates, translations carried to the sample's offset
        p = len(samples)
        u6 = np.asarray(samples.rows @ samples.expand(phi)).reshape(p, 6, -1)
        tr_l.append(np.asarray(samples.displacement(phi)).reshape(p, 3, -1))
        rot_l.append(u6[:, 3:])
        xyz_l.append(np.asarray(samples.position, float))
        # a NASTRAN deck's grids keep their ids when every sample is a grid
        got = [_GRID_LABEL.fullmatch(str(lab)) for lab in samples.labels]
        if all(got) and len({int(g.group(1)) for g in got if g}) == p:
            grid_ids = [int(g.group(1)) for g in got if g]
    maps = list(st.points.values())
    if maps:
        tr_l.append(np.stack([p.translation @ phi for p in maps]))
        rot_l.append(np.stack([p.rotation @ phi for p in maps]))
        xyz_l.append(np.stack([np.asarray(p.position, float) for p in maps]))
    if not xyz_l:
        raise InputError("the structure has no points or samples to export", where="modes")
    shapes = np.concatenate([np.concatenate(tr_l), np.concatenate(rot_l)], axis=1)
    xyz = np.concatenate(xyz_l)
    ids = np.arange(1, xyz.shape[0] + 1, dtype=np.int64)
    if grid_ids is not None:
        # grids by their own ids, the named points after the largest
        top = max(grid_ids)
        ids = np.array(grid_ids + [top + 1 + i for i in range(len(maps))], dtype=np.int64)
    first_point = int(ids[xyz.shape[0] - len(maps)]) if maps else int(ids[-1]) + 1
    named = {p.name: first_point + i for i, p in enumerate(maps)}
    name = str(st.meta.get("model", "microg")) if st.meta else "microg"
    return ids, xyz, np.asarray(modes.omega), shapes, named, name


def write_uff_modes(
    modes_or_model: Any,
    path: str | Path,
    *,
    precision: str = "single",
    name: str | None = None,
    points_path: str | Path | None = None,
) -> Path:
    """Write modes as UFF 164 (SI units) + 15 or 2411 (nodes) + 55 (one per mode), atomically.

    Parameters
    ----------
    modes_or_model : ModalModel or microg.dynamics.modes.Modes
        A modal model (its grids and shapes), or the modes of a microg structure (nodes:
        the structure's samples -- frame nodes and body masses, or a deck's grids and the
        masses off them -- numbered 1.., a deck's grids by their own ids when every sample is
        a grid; then its named points).
    path : str or Path
        Output file (``.unv``/``.uff``).
    precision : {"single", "double"}
        ``single``: the standard 15 + 55 with E13.5 (6 digits, any UFF tool);
        ``double``: 2411 + 55 with data type 4 in E25.16 (lossless; whitespace-parsing
        readers).
    name : str, optional
        ID line 1 of each mode (default the model's name).
    points_path : str or Path, optional
        Also write a points TOML file naming the nodes of the named points
        (``lab = "grid:N"``), for reading the file back with names.

    Returns
    -------
    Path
    """
    from microg._io import atomic_write_text

    if precision not in _PRECISIONS:
        raise InputError(
            f"unknown precision {precision!r}", where="precision", fix="single or double"
        )
    if isinstance(modes_or_model, ModalModel):
        mm = modes_or_model
        ids, xyz, omega, shapes = mm.grid_ids, mm.xyz_m, mm.omega, mm.phi
        zeta = mm.zeta
        label = name or mm.name
        named = {p.name: int(p.grid) for p in mm.points if not np.any(p.offset_m)}
    else:
        ids, xyz, omega, shapes, named, label0 = _from_modes(modes_or_model)
        zeta = None
        label = name or label0
    freq = np.asarray(omega) / (2.0 * np.pi)
    parts = [_units_block(), _nodes_block(ids, xyz, precision)]
    z = np.zeros(freq.size) if zeta is None else np.asarray(zeta)
    for j in range(freq.size):
        parts.append(
            _mode_block(ids, shapes[:, :, j], j, float(freq[j]), float(z[j]), label, precision)
        )
    out = Path(path)
    atomic_write_text(out, "".join(parts))
    if points_path is not None:
        lines = ['units = "m, N, s"', "", "[points]"]
        lines += [f'{json.dumps(k)} = "grid:{v}"' for k, v in named.items()]
        atomic_write_text(points_path, "\n".join(lines) + "\n")
    return out


def write_uff_time(
    responses: Mapping[str, Any],
    path: str | Path,
    *,
    quantity: str = "acceleration",
    precision: str = "single",
    nodes: Mapping[str, int] | None = None,
) -> Path:
    """Write time histories as UFF 58 (one dataset per point and axis), SI, atomically.

    Parameters
    ----------
    responses : mapping of name to PointResponse
        :class:`microg.dynamics.response.PointResponse` objects (uniform ``timepts``).
    path : str or Path
    quantity : {"acceleration", "velocity", "displacement"}
    precision : {"single", "double"}
        Ordinate data type 2 (E13.5) or 4 (E20.12).
    nodes : mapping of name to int, optional
        Node number of each point (default 1, 2, ... in order).
    """
    from microg._io import atomic_write_text

    spec = {
        "acceleration": (12, "m/s^2", 1),
        "velocity": (11, "m/s", 1),
        "displacement": (8, "m", 1),
    }
    if quantity not in spec:
        raise InputError(f"unknown quantity {quantity!r}", where="quantity", fix=", ".join(spec))
    if precision not in _PRECISIONS:
        raise InputError(
            f"unknown precision {precision!r}", where="precision", fix="single or double"
        )
    code, unit, len_exp = spec[quantity]
    parts = [_units_block()]
    for k, (pname, r) in enumerate(responses.items()):
        t = np.asarray(r.timepts, float)
        data = np.asarray(getattr(r, quantity), float)
        if t.size < 2:
            raise InputError("need at least 2 samples", where=f"responses: {pname}")
        dt = (t[-1] - t[0]) / (t.size - 1)
        if np.max(np.abs(np.diff(t) - dt)) > 1e-9 * max(abs(dt), 1e-300):
            raise InputError("time samples are not uniform", where=f"responses: {pname}")
        node = (nodes or {}).get(pname, k + 1)
        for axis in range(3):
            y = data[axis]
            dtype = 2 if precision == "single" else 4
            head = (
                f"{pname[:80]:<80s}\n{(quantity + ' ' + 'xyz'[axis])[:80]:<80s}\nNONE\n"
                f"{'microg response':<80s}\nNONE\n"
                f"{1:5d}{k * 3 + axis + 1:10d}{1:5d}{0:10d} {'microg':>10s}{node:10d}{axis + 1:4d} "
                f"{'NONE':>10s}{0:10d}{0:4d}\n"
                f"{dtype:10d}{t.size:10d}{1:10d}{t[0]:13.5E}{dt:13.5E}{0.0:13.5E}\n"
                f"{17:10d}{0:5d}{0:5d}{0:5d} {'Time':<20s} {'s':<20s}\n"
                f"{code:10d}{len_exp:5d}{0:5d}{0:5d} {quantity.capitalize():<20s} {unit:<20s}\n"
                f"{0:10d}{0:5d}{0:5d}{0:5d} {'NONE':<20s} {'NONE':<20s}\n"
                f"{0:10d}{0:5d}{0:5d}{0:5d} {'NONE':<20s} {'NONE':<20s}\n"
            )
            per, fmt = (6, "%13.5E") if precision == "single" else (4, "%20.12E")
            yv = _clip(y) if precision == "single" else y
            full = (yv.size // per) * per
            body = _fmt_rows(yv[:full].reshape(-1, per), fmt * per) if full else ""
            if yv.size > full:
                body += "".join(fmt % v for v in yv[full:]) + "\n"
            parts.append(_block(58, head + body))
    out = Path(path)
    atomic_write_text(out, "".join(parts))
    return out
