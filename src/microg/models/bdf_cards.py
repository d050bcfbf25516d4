"""NASTRAN bulk data cards: a deck's text -> :class:`Card` records (the tokenizer).

``read_cards(path)`` reads executive and case control up to ``BEGIN BULK`` (the case
control lines are returned), then bulk data to ``ENDDATA``: small-field (8 columns),
large-field (``NAME*``, 16 columns, ``*`` continuations) and free-field (commas) entries;
continuation lines (``+``/``*`` in column 1, or a blank first field); ``$`` comments; tabs
as 8-column stops; ``INCLUDE 'file'`` anywhere (relative to the including file, nested to
:data:`MAX_INCLUDE_DEPTH`).  Real numbers in NASTRAN's forms (``1.5``, ``1.5E-3``,
``1.5-3``, ``1.5D-3``, ``.5``).  The layout is the MSC Nastran Quick Reference Guide's
("Bulk Data Entry format"); fields are numbered as pyNastran numbers them.
:mod:`microg.models.bdf` turns the cards into a graph model.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from microg.errors import InputError

__all__ = ["MAX_CARDS", "MAX_INCLUDE_DEPTH", "Card", "read_cards"]

#: the deepest nesting of INCLUDE files
MAX_INCLUDE_DEPTH = 20
#: the most cards read from one deck (documented limit)
MAX_CARDS = 5_000_000


@dataclass(frozen=True)
class Card:
    """One bulk data entry: its name and fields, where it was read.

    ``fields[0]`` is the name; ``fields[i]`` the i-th data field counting across
    continuations (8 per small-field line), pyNastran's numbering.  Each field is an int,
    a float, an upper-case str or None (blank).
    """

    fields: tuple[Any, ...]
    file: str
    line: int

    @property
    def name(self) -> str:
        """Card name, upper case (``GRID``)."""
        return str(self.fields[0])

    def __len__(self) -> int:
        return len(self.fields)

    def raw(self, i: int) -> Any:
        """Field ``i`` or None beyond the end."""
        return self.fields[i] if i < len(self.fields) else None

    @property
    def where(self) -> str:
        """``FILE:LINE: NAME ID`` of the card, for error messages."""
        ident = self.raw(1)
        return f"{self.file}:{self.line}: {self.name}" + (f" {ident}" if ident is not None else "")

    def error(self, what: str, fix: str | None = None) -> InputError:
        """An :class:`~microg.errors.InputError` at this card (:attr:`where`)."""
        return InputError(what, where=self.where, fix=fix)

    def integer(self, i: int, label: str, default: Any = ...) -> int:
        """Integer field ``i`` (``label`` in messages); blank: ``default`` or an error."""
        v = self.raw(i)
        if v is None:
            if default is ...:
                raise self.error(f"field {i + 1} ({label}) is blank", f"give {label}")
            return default
        if not isinstance(v, int):
            raise self.error(f"field {i + 1} ({label}) must be an integer, got {v!r}")
        return v

    def real(self, i: int, label: str, default: Any = ...) -> float:
        """Real field ``i`` as written (an integer is accepted); blank: ``default`` or an error."""
        v = self.raw(i)
        if v is None:
            if default is ...:
                raise self.error(f"field {i + 1} ({label}) is blank", f"give {label}")
            return default
        if isinstance(v, str):
            raise self.error(f"field {i + 1} ({label}) must be a number, got {v!r}")
        return float(v)

    def text(self, i: int, label: str, default: Any = ...) -> str:
        """Field ``i`` as text (``label`` in messages); blank: ``default`` or an error."""
        v = self.raw(i)
        if v is None:
            if default is ...:
                raise self.error(f"field {i + 1} ({label}) is blank", f"give {label}")
            return default
        return str(v)


_INT = re.compile(r"[+-]?\d+$")
_REAL = re.compile(r"([+-]?(?:\d+\.\d*|\.\d+|\d+))(?:([EeDd])?([+-]?\d+))?$")


def _value(text: str) -> Any:
    """A field's value: None, int, float or an upper-case string."""
    s = text.strip()
    if not s:
        return None
    if _INT.match(s):
        return int(s)
    m = _REAL.match(s)
    if m and ("." in m.group(1) or m.group(2)):
        mant, letter, exp = m.group(1), m.group(2), m.group(3)
        if exp is not None and letter is None and not exp.startswith(("+", "-")):
            return s.upper()  # "1.5 3" and the like: not a number
        try:
            v = float(mant) * 10.0 ** int(exp) if exp is not None else float(mant)
        except OverflowError:
            return s.upper()
        return v if math.isfinite(v) else s.upper()
    return s.upper()


@dataclass
class _Line:
    text: str
    file: str
    number: int


def _read_lines(
    path: Path,
    shown: str,
    depth: int,
    stack: tuple[Path, ...],
    notes: list[str] | None = None,
    state: dict[str, bool] | None = None,
) -> Iterator[_Line]:
    """Lines of ``path`` with INCLUDEs expanded (file name and line number kept).

    An INCLUDE before ``BEGIN BULK`` (executive or case control: DMAP alters, output
    requests) that does not exist is skipped with a note in ``notes``; a bulk-data INCLUDE
    must exist.
    """
    state = {"bulk": False} if state is None else state
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read the file: {exc.strerror or exc}", where=shown) from None
    text = raw.decode("latin-1")
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i].expandtabs(8)
        number = i + 1
        i += 1
        head = line.lstrip()[:7].upper()
        if head == "INCLUDE" and not line.lstrip().startswith("$"):
            spec = line.lstrip()[7:]
            while spec.count("'") == 1 and i < len(lines):  # a quoted path continued
                spec += lines[i].strip()
                i += 1
            m = re.match(r"\s*'([^']*)'\s*(\$.*)?$", spec) or re.match(r"\s*(\S+)\s*(\$.*)?$", spec)
            if not m:
                raise InputError(
                    "INCLUDE needs a file name",
                    where=f"{shown}:{number}",
                    fix="write INCLUDE 'file.bdf'",
                )
            name = m.group(1).strip()
            if any(ord(ch) < 32 for ch in name):  # a NUL is no path (os raises ValueError)
                raise InputError(
                    "INCLUDE file name holds a control character",
                    where=f"{shown}:{number}",
                    fix="write INCLUDE 'file.bdf'",
                )
            target = Path(name) if Path(name).is_absolute() else path.parent / name
            target_shown = str(Path(shown).parent / name) if not Path(name).is_absolute() else name
            if depth >= MAX_INCLUDE_DEPTH or target.resolve() in stack:
                raise InputError(
                    f"INCLUDE {name!r} nests deeper than {MAX_INCLUDE_DEPTH} or includes itself",
                    where=f"{shown}:{number}",
                    fix="remove the circular INCLUDE",
                )
            if not target.is_file() and not state["bulk"] and notes is not None:
                notes.append(
                    f"{shown}:{number}: INCLUDE {name[-60:]!r} before BEGIN BULK not found: "
                    "skipped (executive and case control do not change the model)"
                )
                continue
            if not target.is_file():
                raise InputError(
                    f"INCLUDE {name!r}: file not found",
                    where=f"{shown}:{number}",
                    fix="give the path relative to the including file",
                )
            yield from _read_lines(
                target, target_shown, depth + 1, (*stack, target.resolve()), notes, state
            )
            continue
        if not state["bulk"] and re.match(r"\s*BEGIN\s+(BULK|SUPER)", line, re.I):
            state["bulk"] = True
        yield _Line(line, shown, number)


def _free(parts: list[str], large: bool, where: str) -> list[str]:
    """Data fields of a free-field line (after its first field): 8 (4 large), then a marker.

    A short line is padded with blank fields to its 8 (4): each line of a free-field card
    stands for one fixed-format line, so a continuation's first data field is field 2 of the
    next line whatever the line before it held (MSC/NX Quick Reference Guide, "Free Field
    Format").
    """
    per = 4 if large else 8
    data = parts[1:]
    if len(data) > per + 1 or (len(data) == per + 1 and isinstance(_value(data[per]), int | float)):
        raise InputError(
            f"a free-field line holds {per} data fields and a continuation marker, "
            f"this one has {len(data)} fields",
            where=where,
            fix="continue the card on a new line starting with '+' (or ',')",
        )
    return data[:per] + [""] * (per - len(data[:per]))


def _fields_of(line: str, where: str) -> tuple[str, list[str]]:
    """(name, data fields) of the first line of a card."""
    if "," in line:
        parts = line.split(",")
        head = parts[0].strip()
        return head.rstrip("*"), _free(parts, head.endswith("*"), where)
    head = line[:8]
    if head.strip().endswith("*"):
        data = [line[8 + 16 * k : 24 + 16 * k] for k in range(4)]
    else:
        data = [line[8 + 8 * k : 16 + 8 * k] for k in range(8)]
    return head.strip().rstrip("*"), data


def _is_continuation(line: str) -> bool:
    s = line.rstrip()
    if not s:
        return False
    if s[0] in "+*" or s.startswith(","):
        return True
    if "," in s:
        return not s.split(",")[0].strip()
    return not line[:8].strip()


def read_cards(
    path: str | Path, notes: list[str] | None = None, *, superelements: bool = False
) -> tuple[list[Card], list[str]]:
    """Bulk data cards of a deck and its case control lines.

    Parameters
    ----------
    path : str or Path
        The deck (``.bdf``, ``.dat``, ``.blk``, ``.nas``); INCLUDEs relative to it.
    notes : list of str, optional
        Receives a note per executive/case-control INCLUDE that does not exist (skipped);
        without it such an INCLUDE is an error, as a bulk-data one always is.
    superelements : bool
        Read the cards of ``BEGIN SUPER`` sections too, joined with the main bulk data's
        (the punch file of an external superelement, for its DOF list); otherwise such a
        section is an error.

    Returns
    -------
    cards : list of Card
    case_control : list of str
        Upper-case case control lines (empty for a bulk-only file).
    """
    p = Path(path)
    shown = str(path)
    if not p.is_file():
        raise InputError("file not found", where=shown, fix="check the path")
    try:
        top = p.read_bytes().decode("latin-1")
    except OSError as exc:
        raise InputError(f"cannot read the file: {exc.strerror or exc}", where=shown) from None
    # a file without CEND or BEGIN BULK is bulk data throughout
    bulk_only = not re.search(r"^\s*(CEND\b|BEGIN\s+(BULK|SUPER))", top, re.I | re.M)
    state = {"bulk": bulk_only}
    lines = list(_read_lines(p, shown, 0, (p.resolve(),), notes, state))
    begin = next(
        (k for k, ln in enumerate(lines) if re.match(r"\s*BEGIN\s+(BULK|SUPER)", ln.text, re.I)),
        None,
    )
    case: list[str] = []
    if begin is not None:
        if not superelements and re.match(r"\s*BEGIN\s+SUPER", lines[begin].text, re.I):
            raise InputError(
                "superelement bulk data (BEGIN SUPER) is not supported",
                where=f"{lines[begin].file}:{lines[begin].number}",
                fix="give the residual structure only",
            )
        cend = next(
            (k for k, ln in enumerate(lines[:begin]) if re.match(r"\s*CEND\b", ln.text, re.I)), -1
        )
        case = [ln.text.split("$")[0].strip().upper() for ln in lines[cend + 1 : begin]]
        lines = lines[begin + 1 :]
    cards: list[Card] = []
    cur: list[Any] | None = None
    cur_at: tuple[str, int] = ("", 0)
    pattern: list[str] | None = None
    ended = False
    for ln in lines:
        text = ln.text.split("$", 1)[0] if "$" in ln.text else ln.text
        if not text.strip():
            continue
        if re.match(r"\s*ENDDATA\b", text, re.I):
            ended = True
            break
        if superelements and re.match(r"\s*BEGIN\s+(BULK|SUPER)", text, re.I):
            if cur is not None:
                cards.append(_card(cur, cur_at))
                cur = None
            continue
        where = f"{ln.file}:{ln.number}"
        if cur is not None and _is_continuation(text):
            if "," in text:
                parts = text.split(",")
                data = _free(parts, parts[0].strip().startswith("*"), where)
            else:
                large = text.startswith("*")
                data = (
                    [text[8 + 16 * k : 24 + 16 * k] for k in range(4)]
                    if large
                    else [text[8 + 8 * k : 16 + 8 * k] for k in range(8)]
                )
            cur.extend(_value(f) for f in data)
            continue
        if cur is not None:
            cards.append(_card(cur, cur_at))
            cur = None
        if len(cards) >= MAX_CARDS:
            raise InputError(f"more than {MAX_CARDS} cards", where=shown, fix="split the model")
        head = text.strip()
        if head.startswith("="):
            # replication (QRG "Bulk Data Entry Replication"): "=,..." one card from the
            # previous one by a pattern, "=N" N more cards by the last pattern
            if not cards:
                raise InputError("a replication line before any card", where=where)
            count = head.split(",")[0].strip()
            if count == "=":
                pattern = [f.strip() for f in text.split(",")[1:]]
                times = 1
            elif re.fullmatch(r"=\(?\d+\)?", count):
                if pattern is None:
                    raise InputError(f"{count!r} repeats no replication pattern", where=where)
                times = int(count.strip("=()"))
            else:
                raise InputError(f"{count[:8]!r} is not a replication line", where=where)
            if len(cards) + times > MAX_CARDS:
                raise InputError(f"more than {MAX_CARDS} cards", where=shown, fix="split the model")
            for _ in range(times):
                cards.append(
                    _card(_replicate(cards[-1].fields, pattern, where), (ln.file, ln.number))
                )
            continue
        pattern = None  # "=N" repeats only a replication that directly precedes it
        name, data = _fields_of(text, where)
        cur = [name.strip().upper(), *(_value(f) for f in data)]
        cur_at = (ln.file, ln.number)
    if begin is not None and not ended and not superelements:
        # a complete input file's bulk data runs from BEGIN BULK to ENDDATA (QRG, "Bulk
        # Data Entries"); without it a file cut at a line boundary would read as a
        # shorter model
        raise InputError(
            "the bulk data has no ENDDATA: the file may be cut short",
            where=shown,
            fix="if the deck is complete, end it with an ENDDATA line",
        )
    if cur is not None:
        cards.append(_card(cur, cur_at))
    return cards, case


def _replicate(prev: tuple[Any, ...], pattern: list[str], where: str) -> list[Any]:
    """The card a replication pattern makes of ``prev``.

    ``=`` copies a field, ``==`` all remaining ones, ``*x`` / ``*(x)`` adds ``x`` to it, a
    blank is blank, anything else is the new value (MSC/NX QRG, "Bulk Data Entry
    Replication").
    """
    out: list[Any] = [prev[0]]
    for k, tok in enumerate(pattern, start=1):
        old = prev[k] if k < len(prev) else None
        if tok == "==":
            out.extend(prev[k:])
            return out
        if tok == "=":
            out.append(old)
        elif tok.startswith("*"):
            inc = _value(tok[1:].strip("()"))
            if not isinstance(inc, int | float) or not isinstance(old, int | float):
                raise InputError(
                    f"replication {tok[:10]!r} increments a field that is not a number",
                    where=where,
                )
            out.append(old + inc)
        else:
            out.append(_value(tok))
    return out


def _card(fields: list[Any], at: tuple[str, int]) -> Card:
    while len(fields) > 1 and fields[-1] is None:
        fields.pop()
    return Card(tuple(fields), at[0], at[1])
