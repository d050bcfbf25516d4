"""Station model files: a TOML file (or a shipped model name) -> ``Station``, and back.

The format is specified in ``docs/model-format.md``.  Reading goes in four steps, one module
each:

1. a cheap pre-scan here rejects what would make the TOML parser recurse or crawl (nesting
   deeper than :data:`MAX_NESTING`, dotted keys longer than :data:`MAX_KEY_PARTS`, files
   larger than :data:`MAX_FILE_BYTES`); then :mod:`tomllib` parses the text (a syntax error
   names the file, line and column; a UTF-8 byte-order mark is accepted);
2. :mod:`microg.models.schema` (pydantic) checks the structure: known keys, required keys,
   the kind of each value, counts;
3. :mod:`microg.models.build` converts every quantity to SI (dimension and limits checked)
   and checks the physics and the tree;
4. :mod:`microg.models.messages` words every error as one line,
   ``FILE: field.path: what is wrong (how to fix)``, a :class:`~microg.errors.ModelError`.

Shipped models are listed by :mod:`microg.models.catalog`.  :func:`dump_station` writes a
station back as TOML in SI units, such that ``loads_station(dump_station(st))`` reproduces
``st``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from microg import _args
from microg._io import loads_toml
from microg.errors import ModelError
from microg.models.build import build_station
from microg.models.catalog import shipped_model_text, shipped_models
from microg.models.messages import structure_error
from microg.models.messages import toml_string as _tstr
from microg.models.schema import EARTH_RADIUS, MAX_COUNTS, ON_AXIS_TOL, UNIT_SYSTEMS, FileIn
from microg.models.station import Beam, PointMass, Station

__all__ = [
    "EARTH_RADIUS",
    "MAX_FILE_BYTES",
    "MAX_KEY_PARTS",
    "MAX_NESTING",
    "ON_AXIS_TOL",
    "UNIT_SYSTEMS",
    "dump_station",
    "load_station",
    "loads_station",
    "shipped_models",
]

#: largest model file, bytes: Python's TOML parser reads about 1 MB a second, and 20,000 point
#: masses (the limit, :data:`~microg.models.schema.MAX_COUNTS`) take about 1.6 MB
MAX_FILE_BYTES = 4 * 2**20
#: deepest nesting of arrays and inline tables (the format needs 2)
MAX_NESTING = 8
#: most parts of a dotted key or table name (``body.mass`` has 2)
MAX_KEY_PARTS = 8

# strings and comments (their brackets and dots do not count); multi-line forms first
_STRINGS = re.compile(
    r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*'
)
# nine or more parts: a dot, then eight times "part ." (a float has one dot, 1.5)
_LONG_KEY = re.compile(r"\.(?:[ \t]*[A-Za-z0-9_\-s]+[ \t]*\.){" + str(MAX_KEY_PARTS - 1) + "}")
_MASS_HEADER = re.compile(r"^[ \t]*\[\[[ \t]*(?:body|beam)[ \t]*\.[ \t]*mass[ \t]*\]\]", re.M)


def _line_of(text: str, pos: int) -> int:
    return text.count("\n", 0, pos) + 1


def _prescan(text: str, filename: str) -> None:
    """Reject, in linear time, input that would make tomllib recurse deeply or crawl."""
    if len(text) > MAX_FILE_BYTES:
        raise ModelError(
            f"the file is larger than {MAX_FILE_BYTES // 2**20} MB",
            where=filename,
            fix="simplify the model (limits: docs/model-format.md)",
        )
    # strings and comments become "s"; line numbers are found again only for a message
    bare = _STRINGS.sub("s", text)
    if _LONG_KEY.search(bare) is not None:
        kept = _keep_lines(text)
        found = _LONG_KEY.search(kept)
        raise ModelError(
            f"a dotted key or table name of more than {MAX_KEY_PARTS} parts",
            where=f"{filename}: line {_line_of(kept, found.start() if found else 0)}",
            fix="the format nests tables at most two deep, e.g. [[body.mass]]",
        )
    n_masses = sum(1 for _ in _MASS_HEADER.finditer(bare))
    if n_masses > MAX_COUNTS["mass"]:
        raise ModelError(
            f"{n_masses:,} point masses, more than the limit of {MAX_COUNTS['mass']:,}",
            where=filename,
            fix="merge point masses (limits: docs/model-format.md)",
        )
    depth = _depth(bare)
    if depth.size and int(depth.max()) > MAX_NESTING:
        kept = _keep_lines(text)
        at = int(np.argmax(_depth(kept) > MAX_NESTING))
        raise ModelError(
            f"arrays or inline tables nested more than {MAX_NESTING} deep",
            where=f"{filename}: line {_line_of(kept, at)}",
            fix="the format needs at most two levels, e.g. inertia = { xx = ... }",
        )


def _keep_lines(text: str) -> str:
    """``text`` with strings and comments replaced by "s", line breaks kept."""
    return _STRINGS.sub(lambda m: "s" + "\n" * m.group(0).count("\n"), text)


def _depth(bare: str) -> np.ndarray:
    """Nesting depth of brackets and braces after each character of ASCII-safe ``bare``."""
    code = np.frombuffer(bare.encode("ascii", "replace"), dtype=np.uint8)
    step = (code == ord("[")).astype(np.int32) + (code == ord("{"))
    step -= (code == ord("]")).astype(np.int32) + (code == ord("}"))
    return np.cumsum(step)


def loads_station(text: str, *, filename: str = "<string>", source: str = "") -> Station:
    """Build a station from the text of a model file.

    Parameters
    ----------
    text : str
        TOML text in the format of ``docs/model-format.md`` (a leading byte-order mark is
        dropped).
    filename : str
        Name used for the file in error messages.
    source : str
        Stored as :attr:`Station.source` (the file it was read from).

    Returns
    -------
    Station
        SI units; beams parent-first, the root body first.

    Raises
    ------
    ModelError
        One line: ``FILE: field.path: what is wrong (how to fix)``.
    """
    if not isinstance(text, str):
        raise ModelError(f"expected the text of a model, got {type(text).__name__}", where=filename)
    if text.startswith("\ufeff"):
        text = text[1:]
    _prescan(text, filename)
    try:
        data = loads_toml(text, filename, ModelError)
    except ModelError:  # a syntax error, already one line (ModelError is a ValueError too)
        raise
    except RecursionError:
        raise ModelError(
            "nested too deeply", where=filename, fix="the format nests at most two levels"
        ) from None
    except ValueError as exc:  # an integer of more than 4300 digits
        what = "an integer has too many digits" if "digits" in str(exc) else "an invalid value"
        raise ModelError(
            f"invalid TOML: {what}", where=filename, fix="write numbers of ordinary size"
        ) from None
    try:
        doc = FileIn.model_validate(data)
    except ValidationError as exc:
        raise structure_error(exc, filename, FileIn) from None
    except RecursionError:
        raise ModelError(
            "nested too deeply", where=filename, fix="the format nests at most two levels"
        ) from None
    return build_station(doc, filename, source)


def load_station(path_or_name: str | Path) -> Station:
    """Read a station model from a TOML file or by the name of a shipped model.

    Parameters
    ----------
    path_or_name : str or Path
        A shipped model name (see :func:`shipped_models`, e.g. ``"ioc"``), or the path of a
        ``.toml`` file.  A string that is a shipped name means the shipped model even if a
        file of that name exists in the working directory (write ``./ioc`` for the file);
        a :class:`~pathlib.Path` is always a file.

    Returns
    -------
    Station
        In SI units, with :attr:`Station.source` set to the file read.

    Raises
    ------
    ModelError
        Unknown name or unreadable file, or an invalid model (one line naming file and field).
    """
    _args.path(path_or_name, "path_or_name")
    if isinstance(path_or_name, str):
        shipped = shipped_model_text(path_or_name)
        if shipped is not None:
            text, fname, source = shipped
            return loads_station(text, filename=fname, source=source)
    path = Path(path_or_name)
    label = str(path_or_name)
    try:
        is_file = path.is_file()
        is_dir = path.is_dir()
    except (OSError, ValueError):  # a name too long, or with a NUL character
        is_file = is_dir = False
    if not is_file:
        names = ", ".join(shipped_models()) or "none"
        what = "is a directory, not a model file" if is_dir else "no such file"
        shown = label if len(label) <= 200 else label[:197] + "..."
        raise ModelError(
            f"{what}, and not the name of a shipped model",
            where=shown,
            fix=f"give the path of a .toml model file or a shipped model: {names}",
        )
    try:
        with path.open("rb") as fh:
            data = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ModelError(
            f"cannot read: {exc.strerror or exc}", where=label, fix="check the path and permissions"
        ) from None
    if len(data) > MAX_FILE_BYTES:
        raise ModelError(
            f"the file is larger than {MAX_FILE_BYTES // 2**20} MB",
            where=label,
            fix="simplify the model (limits: docs/model-format.md)",
        )
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ModelError(
            f"not UTF-8 text (byte {exc.start})", where=label, fix="save the file as UTF-8"
        ) from None
    return loads_station(text, filename=label, source=str(path))


# --------------------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------------------


def _tq(value: float, unit: str) -> str:
    return _tstr(f"{float(value)!r} {unit}")


def _tvec(v: np.ndarray, unit: str | None = "m") -> str:
    if unit is None:
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"
    return "[" + ", ".join(_tq(x, unit) for x in v) + "]"


def _dump_mass(lines: list[str], table: str, pm: PointMass, beam: Beam | None) -> None:
    lines.append(f"[[{table}.mass]]")
    lines.append(f"name = {_tstr(pm.name)}")
    lines.append(f"mass = {_tq(pm.mass, 'kg')}")
    if beam is None:
        lines.append(f"at = {_tvec(pm.position)}")
    else:
        lines.append(f"s = {_tq(beam.arc_length(pm.position), 'm')}")
    if pm.source:
        lines.append(f"source = {_tstr(pm.source)}")
    if pm.fitted:
        lines.append("fitted = true")
    if pm.movable is not None:
        lines.append(f"movable = [{_tq(pm.movable[0], 'm')}, {_tq(pm.movable[1], 'm')}]")
    inertia = np.asarray(pm.inertia, float)
    if np.any(inertia != 0.0):
        keys = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
        body = ", ".join(f"{k} = {_tq(inertia[ij], 'kg*m^2')}" for k, ij in keys.items())
        lines.append(f"inertia = {{ {body} }}")


def dump_station(station: Station) -> str:
    """The TOML text of a station model, in SI units with a unit on every value.

    Parameters
    ----------
    station : Station
        Any station (beam masses are written by their arc length along the beam).

    Returns
    -------
    str
        A model file such that ``loads_station(dump_station(station))`` equals ``station``
        to rounding (about 1e-15 relative).
    """
    lines = ["# station model written by microg.models.toml.dump_station (SI units)", ""]
    lines.append("[station]")
    lines.append(f"name = {_tstr(station.name)}")
    if station.description:
        lines.append(f"description = {_tstr(station.description)}")
    lines.append(f"reference_length = {_tq(station.reference_length, 'm')}")
    lines += ["", "[orbit]"]
    lines.append(f"radius = {_tq(station.orbit.radius, 'm')}")
    lines.append(f"mu = {_tq(station.orbit.mu, 'm^3/s^2')}")
    for body in station.bodies:
        lines += ["", "[[body]]", f"name = {_tstr(body.name)}"]
        if body.parent is not None:
            lines.append(f"parent = {_tstr(body.parent)}")
        if body.attach is not None:
            lines.append(f"at = {_tvec(body.attach)}")
        for pm in body.masses:
            _dump_mass(lines, "body", pm, None)
    for beam in station.beams:
        lines += ["", "[[beam]]", f"name = {_tstr(beam.name)}", f"parent = {_tstr(beam.parent)}"]
        lines.append(f"root = {_tvec(beam.root)}")
        lines.append(f"direction = {_tvec(beam.direction, None)}")
        lines.append(f"length = {_tq(beam.length, 'm')}")
        lines.append(f"orientation = {_tvec(beam.orientation, None)}")
        lines.append(f"ei_y = {_tq(beam.ei_y, 'N*m^2')}")
        lines.append(f"ei_z = {_tq(beam.ei_z, 'N*m^2')}")
        lines.append(f"gj = {_tq(beam.gj, 'N*m^2')}")
        if beam.ea is not None:
            lines.append(f"ea = {_tq(beam.ea, 'N')}")
        lines.append(f"mass_per_length = {_tq(beam.mass_per_length, 'kg/m')}")
        for pm in beam.masses:
            _dump_mass(lines, "beam", pm, beam)
    for pt in station.points:
        lines += ["", "[[point]]", f"name = {_tstr(pt.name)}", f"on = {_tstr(pt.on)}"]
        lines.append(f"at = {_tvec(pt.position)}")
        lines.append(f"kind = {_tstr(pt.kind)}")
        if pt.description:
            lines.append(f"description = {_tstr(pt.description)}")
    return "\n".join(lines) + "\n"
