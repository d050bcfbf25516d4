"""Error messages of model files: one line, ``FILE: field.path: what is wrong (how to fix)``.

:func:`structure_error` turns the first error of a pydantic validation into a
:class:`~microg.errors.ModelError`; :func:`fail` is how the schema's own validators report
(a message and a fix carried through pydantic).  Values are quoted as written in TOML, cut
to a few dozen characters.
"""

from __future__ import annotations

import types
import typing
from collections.abc import Mapping, Sequence
from typing import Any

from pydantic import BaseModel, ValidationError
from pydantic_core import PydanticCustomError

from microg.errors import ModelError

__all__ = [
    "EXAMPLES",
    "fail",
    "loc_path",
    "short",
    "structure_error",
    "toml_repr",
    "toml_string",
]

#: example values for "add it" hints, by key
EXAMPLES: dict[str, str] = {
    "station": '[station] with name = "my station"',
    "orbit": '[orbit] with altitude = "500 km"',
    "body": '[[body]] with name = "core" (the root body)',
    "name": 'name = "keel"',
    "parent": 'parent = "core"',
    "root": 'root = ["0 m", "0 m", "0 m"]',
    "direction": 'direction = "+z" or [0, 0, 1]',
    "length": 'length = "90 m"',
    "gj": 'gj = "1e9 N*m^2"',
    "mass_per_length": 'mass_per_length = "50 kg/m"',
    "at": 'at = ["0 m", "0 m", "-5 m"]',
    "on": 'on = "core"',
}

_TOML_ESCAPES = {
    '"': '\\"',
    "\\": "\\\\",
    "\b": "\\b",
    "\t": "\\t",
    "\n": "\\n",
    "\f": "\\f",
    "\r": "\\r",
}


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string (quoted, escaped)."""
    out = []
    for ch in text:
        if ch in _TOML_ESCAPES:
            out.append(_TOML_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def toml_repr(value: Any, limit: int = 200) -> str:
    """``value`` written as in a TOML file (for messages), at most about ``limit`` characters."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return toml_string(value[:limit])
    if isinstance(value, list | tuple):
        parts: list[str] = []
        for v in value[:8]:
            parts.append(toml_repr(v, limit))
            if sum(map(len, parts)) > limit:
                break
        more = ", ..." if len(parts) < len(value) else ""
        return "[" + ", ".join(parts) + more + "]"
    if isinstance(value, dict):
        items = list(value.items())[:8]
        body = ", ".join(f"{k} = {toml_repr(v, limit)}" for k, v in items)
        return "{ " + body + (", ..." if len(value) > len(items) else "") + " }"
    return str(value)[:limit]


def short(value: Any, limit: int = 60) -> str:
    """:func:`toml_repr` cut to ``limit`` characters."""
    text = toml_repr(value, limit)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def fail(kind: str, what: str, fix: str, value: Any) -> PydanticCustomError:
    """A schema error whose message is ``what`` and whose ``ctx["fix"]`` says how to fix."""
    return PydanticCustomError(kind, what + ", got {v}", {"v": short(value), "fix": fix})


def loc_path(loc: Sequence[str | int]) -> str:
    """``beam[1].mass[0].weight`` from pydantic's location tuple."""
    out = ""
    for el in loc:
        if isinstance(el, int):
            out += f"[{el}]"
        else:
            out += f".{el}" if out else str(el)
    return out


def _model_of(annotation: Any) -> type[BaseModel] | None:
    """The pydantic model inside ``annotation`` (through Annotated, Optional, list)."""
    for _ in range(8):
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            return annotation
        origin = typing.get_origin(annotation)
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if origin is None or not args:
            return None
        if origin in (typing.Union, types.UnionType):
            models = [m for m in (_model_of(a) for a in args) if m is not None]
            return models[0] if models else None
        annotation = args[0]
    return None


def _model_at(root: type[BaseModel], loc: Sequence[str | int]) -> type[BaseModel] | None:
    model: type[BaseModel] | None = root
    for el in loc:
        if isinstance(el, int):
            continue
        if model is None or el not in model.model_fields:
            return None
        model = _model_of(model.model_fields[el].annotation)
    return model


def structure_error(
    exc: ValidationError,
    file: str,
    root: type[BaseModel],
    examples: Mapping[str, str] = EXAMPLES,
) -> ModelError:
    """The first error of a pydantic ValidationError as a one-line ModelError.

    Parameters
    ----------
    exc : the validation error of ``root.model_validate``
    file : the file's name for the message
    root : the schema's root model (to list the keys allowed where a key is unknown)
    examples : example values by key, for "add it" hints (default: the station format's)
    """
    errors = exc.errors(include_url=False)
    # a misspelt key also makes the right one "missing": report the misspelling
    err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = tuple(err["loc"])
    path = loc_path(loc)
    where = f"{file}: {path}" if path else file
    kind = err["type"]
    key = loc[-1] if loc else ""
    if kind == "missing":
        example = examples.get(str(key))
        fix = f"add it, e.g. {example}" if example else "add it"
        table = isinstance(key, str) and _model_at(root, loc) is not None
        what = "required table is missing" if table else "required key is missing"
        if key == "body":
            what = "the model has no [[body]]: it needs at least the root body"
        return ModelError(what, where=where, fix=fix)
    if kind == "extra_forbidden":
        parent = _model_at(root, loc[:-1])
        allowed = ", ".join(parent.model_fields) if parent is not None else ""
        fix = f"allowed keys here: {allowed}" if allowed else "remove it"
        return ModelError("unknown key", where=where, fix=f"check its spelling; {fix}")
    if kind == "too_short" and key == "body":
        return ModelError(
            "the model has no [[body]]: it needs at least the root body",
            where=where,
            fix=f"add {EXAMPLES['body']}",
        )
    if kind == "too_short":
        example = examples.get(str(key))
        return ModelError(
            "expected a non-empty array",
            where=where,
            fix=f"give at least one, e.g. {example}" if example else "give at least one",
        )
    if kind == "too_long":
        limit = (err.get("ctx") or {}).get("max_length")
        return ModelError(
            f"has more than {limit} entries (the limit of the format)",
            where=where,
            fix="split or simplify the model (limits: docs/model-format.md)",
        )
    header = ".".join(str(x) for x in loc if isinstance(x, str))  # beam.mass for beam[0].mass
    if kind in ("model_type", "dict_type"):
        if loc and isinstance(loc[-1], int):
            fix = f"write each item as a [[{header}]] table"
        elif len(loc) == 1:
            fix = f"write it as a [{header}] table"
        else:
            fix = f'write it as an inline table, e.g. {key} = {{ xx = "1 kg*m^2", ... }}'
        return ModelError(f"expected a table, got {short(err.get('input'))}", where=where, fix=fix)
    if kind == "list_type":
        return ModelError(
            f"expected an array of tables, got {short(err.get('input'))}",
            where=where,
            fix=f"write each item as a [[{header}]] table",
        )
    simple = {
        "string_type": ("expected a string", f'write it in double quotes, e.g. {key} = "text"'),
        "bool_type": ("expected true or false", "write true or false, without quotes"),
        "literal_error": (
            str(err["msg"]).replace("Input should be", "expected"),
            "use one of the listed values; case matters",
        ),
        "string_too_short": ("expected a non-empty string", "give a name"),
        "string_too_long": ("is too long", "keep names and texts short (limits: docs)"),
    }
    if kind in simple:
        what, fix = simple[kind]
        return ModelError(f"{what}, got {short(err.get('input'))}", where=where, fix=fix)
    # the schema's own validators (quantity, vector, direction, range) carry a message and fix
    ctx = err.get("ctx") or {}
    fix_text = ctx.get("fix")
    return ModelError(
        " ".join(str(err["msg"]).split()),
        where=where,
        fix=str(fix_text) if fix_text is not None else "see docs/model-format.md",
    )
