"""Fuzzer of model files: mutated shipped and test models.

Strategy: start from the shipped models (``ioc``, ``ioc-no-orbiter``), the test models
(``small_si``, ``small_us``) and ``examples/station.toml``; mutate values (numbers, units,
grammar breakers), keys (deleted, misspelt, unknown), nesting (scalars in
arrays, tables as scalars, deep arrays, duplicated tables) or the text itself (characters,
lines, BOM); or rewrite quantities in equivalent units.

Invariant: loading gives a one-line ``ModelError`` naming the file, or a ``Station``; an
equivalent rewrite gives the same ``Station`` (else a silent misreading).  A station then
solves (FEM, 2 elements per beam) to exactly 6 rigid modes (a free 3-D model) with shapes
M- and K-orthogonal to 1e-9, or is refused with one line.  Any other exception while loading
is a traceback; past the hard time limit, a hang.  Failures of the solver on a valid model
belong to the solver stage: they are counted as known, and with ``MICROG_FUZZ_SAVE=1``
written to ``tests/data/fuzz_found/`` for it.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
import os
import re
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_fuzz_support import (
    Hang,
    dump_toml,
    fuzz_settings,
    one_line,
    record,
    time_limit,
)

from microg.errors import InputError, ModelError
from microg.models.catalog import shipped_model_text
from microg.models.toml import loads_station

ROOT = Path(__file__).resolve().parents[2]
FOUND = ROOT / "tests" / "data" / "fuzz_found"
FT, LB = 0.3048, 0.45359237
LBF = LB * 9.80665
SLUG = LBF / FT


def _seeds() -> dict[str, str]:
    seeds = {}
    for name in ("ioc", "ioc-no-orbiter"):
        shipped = shipped_model_text(name)
        assert shipped is not None
        seeds[name] = shipped[0]
    for path in (
        ROOT / "tests" / "data" / "models" / "small_si.toml",
        ROOT / "tests" / "data" / "models" / "small_us.toml",
        ROOT / "examples" / "station.toml",
    ):
        seeds[path.stem] = path.read_text(encoding="utf-8")
    return seeds


SEEDS = _seeds()
DOCS = {name: tomllib.loads(text) for name, text in SEEDS.items()}
BASE = {name: loads_station(text, filename=f"{name}.toml") for name, text in SEEDS.items()}

#: units of equal dimension with their exact SI factor, for equivalent rewrites
EQUIVALENT: list[dict[str, float]] = [
    {"m": 1.0, "ft": FT, "in": 0.0254, "km": 1e3, "mm": 1e-3},
    {"kg": 1.0, "lb": LB, "slug": SLUG, "g": 1e-3},
    {"N": 1.0, "lbf": LBF, "kN": 1e3},
    {"N*m^2": 1.0, "lbf*ft^2": LBF * FT**2, "kN*m^2": 1e3},
    {"kg*m^2": 1.0, "slug*ft^2": SLUG * FT**2},
    {"kg/m": 1.0, "slug/ft": SLUG / FT, "lb/ft": LB / FT},
    {"N/m": 1.0, "lbf/ft": LBF / FT},
    {"m/s^2": 1.0, "ft/s^2": FT},
]
_UNIT_GROUP = {u: g for g in EQUIVALENT for u in g}
_QUANTITY = re.compile(r"^\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(\S+)\s*$")

#: values that broke or fooled the old reader and other trouble
NASTY: list[Any] = [
    "9**9**9 ft",
    "2**1000 ft",
    "(296 ft",
    "2**5000 lbf",
    "__import__('os').system('true') ft",
    "296 ft 2",
    "30 s 2",
    "2,96 ft",
    "1,5 min",
    "296 m/m",
    "min",
    "lbf",
    "100 kg/lb",
    "60 percent",
    "1e300 ft",
    "-1e300 ft",
    "1e-300 m",
    "nan m",
    "inf kg",
    "1e400 m",
    "0 m",
    "-5 kg",
    "1 km",
    "5 degC",
    "5 N m",
    "5 m^99",
    "",
    " ",
    "\x00",
    "é ft",
    "+-x",
    "x",
    "-z",
    "[0, 0, 0]",
    0,
    -1,
    1e308,
    -1e308,
    math.inf,
    math.nan,
    10**18,
    -(2**63),
    True,
    [],
    [1, 2],
    [0, 0, 0],
    [1e308, 1e308, 0],
    ["1 m", "2 m", "3 m", "4 m"],
    {},
    {"xx": "1 kg*m^2"},
    "a" * 300,
]
UNITS = ["m", "ft", "kg", "slug", "lbf", "N", "s", "Hz", "rad", "lbf*ft^2", "m/m", "foo", "%"]
KEYS = ["lenght", "mas", "ei_x", "parent ", "Name", "x" * 50, "inertia", "s", "at", "units"]


def _paths(node: Any, prefix: tuple = ()) -> list[tuple]:
    """Every (container path, key) under ``node``."""
    out: list[tuple] = []
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for key, value in items:
        out.append((*prefix, key))
        if isinstance(value, dict | list):
            out.extend(_paths(value, (*prefix, key)))
    return out


def _get(doc: Any, path: tuple) -> Any:
    for key in path:
        doc = doc[key]
    return doc


@st.composite
def mutated_models(draw: st.DrawFn) -> tuple[str, str, str]:
    """(seed name, kind of mutation, TOML text)."""
    name = draw(st.sampled_from(sorted(SEEDS)))
    doc = copy.deepcopy(DOCS[name])
    kind = draw(st.sampled_from(["value", "value", "key", "nesting", "text", "equivalent"]))
    if kind == "text":
        return name, kind, _mutate_text(draw, SEEDS[name])
    if kind == "equivalent":
        return name, kind, _equivalent(draw, doc)
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        path = draw(st.sampled_from(paths))
        parent, key = _get(doc, path[:-1]), path[-1]
        value = parent[key]
        if kind == "value":
            parent[key] = _mutate_value(draw, value)
        elif kind == "key" and isinstance(parent, dict):
            op = draw(st.sampled_from(["delete", "rename", "add"]))
            if op == "delete":
                del parent[key]
            elif op == "rename":
                parent[draw(st.sampled_from(KEYS))] = parent.pop(key)
            else:
                parent[draw(st.sampled_from(KEYS))] = copy.deepcopy(draw(st.sampled_from(NASTY)))
        elif kind == "nesting":
            op = draw(st.sampled_from(["wrap", "deep", "scalar", "dup", "drop", "dict"]))
            if op == "wrap":
                parent[key] = [value]
            elif op == "deep":
                for _ in range(draw(st.integers(2, 12))):
                    value = [value]
                parent[key] = value
            elif op == "scalar":
                parent[key] = "x"
            elif op == "dict":
                parent[key] = {"value": value}
            elif op == "dup" and isinstance(parent, list):
                parent.append(copy.deepcopy(value))
            elif op == "drop" and isinstance(parent, list):
                parent.pop(key)
    return name, kind, dump_toml(doc)


def _mutate_value(draw: st.DrawFn, value: Any) -> Any:
    op = draw(st.sampled_from(["nasty", "number", "unit", "scale"]))
    if op == "nasty" or not isinstance(value, str):
        return copy.deepcopy(draw(st.sampled_from(NASTY)))  # (a copy: NASTY is shared)
    m = _QUANTITY.match(value)
    if m is None:
        return copy.deepcopy(draw(st.sampled_from(NASTY)))
    number, unit = m.groups()
    if op == "number":
        new = draw(
            st.sampled_from(["0", "-1", "1e300", "1e-300", "nan", "1e6", "-0", "5e", "1.5.2"])
            | st.floats(allow_nan=True, allow_infinity=True).map(repr)
        )
        return f"{new} {unit}"
    if op == "unit":
        return f"{number} {draw(st.sampled_from(UNITS))}"
    factor = draw(st.sampled_from([1e-9, 1e-3, 10.0, 1e6, 1e12, -1.0]))
    return f"{float(number) * factor!r} {unit}"


def _mutate_text(draw: st.DrawFn, text: str) -> str:
    lines = text.split("\n")
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["char", "delete", "dup", "digit", "bom", "cut", "bracket"]))
        i = draw(st.integers(0, len(lines) - 1))
        if op == "char":
            line = lines[i]
            j = draw(st.integers(0, len(line)))
            ch = draw(st.sampled_from(list("[]{}=\".,#\\'\x00\t") + ["\u00e9", "\ufeff"]))
            lines[i] = line[:j] + ch + line[j:]
        elif op == "delete" and len(lines) > 1:
            lines.pop(i)
        elif op == "dup":
            lines.insert(i, lines[i])
        elif op == "digit":
            lines[i] = re.sub(r"[0-9]", lambda _m: draw(st.sampled_from("0123456789")), lines[i])
        elif op == "bom":
            lines[0] = "\ufeff" + lines[0]
        elif op == "cut":
            lines = lines[: max(1, i)]
        elif op == "bracket":
            lines.insert(i, "x = " + "[" * draw(st.integers(1, 20)) + "]" * 3)
    return "\n".join(lines)


def _equivalent(draw: st.DrawFn, doc: dict) -> str:
    """Rewrite some quantities in equivalent units: the station must not change."""
    leaves = [p for p in _paths(doc) if isinstance(_get(doc, p), str)]
    quantities = [p for p in leaves if (m := _QUANTITY.match(_get(doc, p))) and m[2] in _UNIT_GROUP]
    if not quantities:
        return dump_toml(doc)
    for path in draw(st.lists(st.sampled_from(quantities), min_size=1, max_size=6, unique=True)):
        parent, key = _get(doc, path[:-1]), path[-1]
        number, unit = _QUANTITY.match(parent[key]).groups()  # type: ignore[union-attr]
        group = _UNIT_GROUP[unit]
        new_unit = draw(st.sampled_from(sorted(group)))
        value = float(number) * group[unit] / group[new_unit]
        space = draw(st.sampled_from([" ", "", "   "]))
        parent[key] = f"{value!r}{space}{new_unit}"
    return dump_toml(doc)


def _same(a: Any, b: Any, scale: float, path: str = "station") -> None:
    """Equal stations: strings exactly, numbers to 1e-9 relative (rounding of two units)."""
    if dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            if f.name != "source":
                _same(getattr(a, f.name), getattr(b, f.name), scale, f"{path}.{f.name}")
    elif isinstance(a, tuple | list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, scale, f"{path}[{i}]")
    elif isinstance(a, np.ndarray | float | int) and not isinstance(a, bool):
        x, y = np.asarray(a, float), np.asarray(b, float)
        tol = 1e-9 * np.maximum(np.abs(x), np.abs(y)) + 1e-9 * scale
        assert x.shape == y.shape and np.all(np.abs(x - y) <= tol), f"misread at {path}: {a} {b}"
    else:
        assert a == b, f"misread at {path}: {a!r} != {b!r}"


def _scale(station: Any) -> float:
    coords = [np.abs(p.position).max() for p in station.all_masses()] + [1.0]
    return float(max(coords))


def _save(text: str, what: str) -> None:  # pragma: no cover - only with MICROG_FUZZ_SAVE
    if not os.environ.get("MICROG_FUZZ_SAVE"):
        return
    FOUND.mkdir(parents=True, exist_ok=True)
    digest = hashlib.sha256(text.encode("utf-8", "replace")).hexdigest()[:10]
    head = "".join(f"# {line}\n" for line in what.splitlines()[:3])
    (FOUND / f"model-{digest}.toml").write_text(
        "# found by tests/fuzz/test_fuzz_models.py: a valid model the solver fails on\n"
        + head
        + text.removeprefix("\ufeff"),
        encoding="utf-8",
    )


def check_model(seed: str, kind: str, text: str, *, solve: bool = True) -> str:
    """Run one model through the invariant; returns the outcome category."""
    from microg.dynamics.modes import solve_modes
    from microg.structure.discretize import discretize

    try:
        with time_limit(30):
            try:
                station = loads_station(text, filename="fuzz.toml")
            except ModelError as exc:
                assert one_line(str(exc)) and str(exc).startswith("fuzz.toml"), str(exc)
                assert kind != "equivalent", f"an equivalent rewrite was refused: {exc}"
                return "clean error"
            if kind == "equivalent":
                try:
                    _same(station, BASE[seed], _scale(BASE[seed]))
                except AssertionError:
                    record("models", "misread")
                    raise
            if not solve:
                return "valid result"
            try:
                structure = discretize(station, "fem", n=2)
                modes = solve_modes(structure)
            except InputError as exc:  # refused by the structure stage, with one line
                assert one_line(str(exc)), str(exc)
                return "clean error"
            except Exception as exc:  # the solver's, on a valid model: known, saved
                _save(text, f"{type(exc).__name__}: {exc}")
                return "known solver"
            problem = _physics_problem(structure, modes)
            if problem:
                _save(text, problem)
                return "known solver"
            return "valid result"
    except Hang:
        record("models", "hang")
        raise
    except AssertionError:
        raise
    except Exception:
        record("models", "traceback")
        raise


def _physics_problem(structure: Any, modes: Any) -> str | None:
    """Why the modes break the invariants of a free 3-D model, or None."""
    if modes.n_rigid != 6:
        return f"{modes.n_rigid} rigid modes, expected 6"
    if np.any(modes.omega[modes.rigid] != 0.0):
        return "rigid modes with non-zero frequency"
    phi = np.asarray(modes.phi, float)
    if phi.shape[0] != structure.mass.shape[0]:
        return None  # reduced coordinates: orthogonality is the solver's own check
    mm = phi.T @ (structure.mass @ phi)
    kk = phi.T @ (structure.stiffness @ phi)
    w2 = np.asarray(modes.omega, float) ** 2
    if not np.all(np.isfinite(mm)) or np.max(np.abs(mm - np.eye(mm.shape[0]))) > 1e-9:
        return "shapes not M-orthonormal to 1e-9"
    if np.max(np.abs(kk - np.diag(w2))) > 1e-9 * max(float(w2.max()), 1.0):
        return "shapes not K-orthogonal to 1e-9"
    return None


@given(mutated_models())
@fuzz_settings(n_ci=700, n_long=5_000, deadline_s=20)
def test_fuzz_mutated_model_files(case: tuple[str, str, str]) -> None:
    seed, kind, text = case
    record("models", check_model(seed, kind, text))


@pytest.mark.parametrize("seed", sorted(SEEDS))
def test_seed_models_are_valid(seed: str) -> None:
    # the starting points pass the invariant themselves (a mutation-free control)
    assert check_model(seed, "equivalent", SEEDS[seed]) == "valid result"


@pytest.mark.parametrize("path", sorted(FOUND.glob("model-*.toml")), ids=lambda p: p.name)
def test_fuzz_found_models_are_valid_inputs(path: Path) -> None:
    # the solver failures the fuzzer found are valid models: the boundary accepts them (the
    # solver stage owns the failure; see the report)
    loads_station(path.read_text(encoding="utf-8"), filename=path.name)
