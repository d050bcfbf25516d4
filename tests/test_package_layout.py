"""The package's layout keeps the data flow one way (the rule of docs/architecture.md).

Every import of a microg module in ``src/microg`` is read from the source (AST) in every form:
``import microg.a.b``, ``from microg.a import b`` (``b`` a submodule or a name), relative
imports, at module level, inside functions and under ``if TYPE_CHECKING:``.  A module may import
its own stage or a lower one, never a higher one.  The one exception is the view layer: a
result's ``plot*()`` method may import ``microg.plotting`` lazily, inside that method.  The
graph of all these imports has no cycle, no module is longer than 1,000 lines, and
``import microg`` loads neither scipy, pint nor matplotlib.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "microg"

#: stage of each top-level module or package, bottom (0) to top
STAGES: dict[str, int] = {
    "errors": 0,
    "units": 0,
    "defaults": 0,
    "_io": 0,
    "_json": 0,
    "_vectors": 0,
    "_scan": 0,
    "_kept": 0,
    "_args": 0,
    "models": 1,
    "structure": 2,
    "dynamics": 3,
    "environment": 4,
    "location": 4,
    "isolation": 4,
    "seed": 4,
    "analysis": 5,
    "study": 5,
    "plotting": 6,
    "report": 6,
    "cli": 7,
    "__main__": 7,
}

#: the longest a module may be (lines of its file); longer is a sign of several concepts
MAX_LINES = 1000


@dataclass(frozen=True)
class Edge:
    """One import found in a module's source."""

    target: str  # the microg module imported (a submodule when the name is one)
    function: str | None  # the innermost enclosing function, None at module level
    line: int


def _module_name(path: Path) -> str:
    rel = path.relative_to(SRC.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _is_package(module: str) -> bool:
    return (SRC.parent / Path(*module.split(".")) / "__init__.py").is_file()


MODULES: set[str] = {_module_name(p) for p in SRC.rglob("*.py")}


def _resolve(module: str, node: ast.ImportFrom) -> str | None:
    """The absolute module an ``ImportFrom`` names (relative levels resolved)."""
    if node.level == 0:
        return node.module
    base = module.split(".") if _is_package(module) else module.split(".")[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join([*base, node.module] if node.module else base)


def _edges(module: str, tree: ast.AST) -> list[Edge]:
    out: list[Edge] = []

    def add(target: str | None, function: str | None, line: int) -> None:
        if target and (target == "microg" or target.startswith("microg.")):
            out.append(Edge(target, function, line))

    def visit(node: ast.AST, function: str | None) -> None:
        if isinstance(node, ast.Import):
            for alias in node.names:
                add(alias.name, function, node.lineno)
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(module, node)
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                # ``from microg.models import bdf`` imports the submodule microg.models.bdf
                add(sub if sub in MODULES else base, function, node.lineno)
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            function = node.name
        for child in ast.iter_child_nodes(node):
            visit(child, function)

    visit(tree, None)
    return out


def _all_edges() -> dict[str, list[Edge]]:
    return {
        _module_name(p): _edges(_module_name(p), ast.parse(p.read_text(encoding="utf-8")))
        for p in SRC.rglob("*.py")
    }


def _stage(module: str) -> int | None:
    parts = module.split(".")
    if parts[0] != "microg" or len(parts) < 2:
        return None
    return STAGES.get(parts[1])


def _is_view_edge(edge: Edge) -> bool:
    """A result's ``plot*()`` drawing through ``microg.plotting``, imported in the method."""
    return (
        edge.function is not None
        and edge.function.startswith("plot")
        and (edge.target == "microg.plotting" or edge.target.startswith("microg.plotting."))
    )


def _graph() -> dict[str, set[str]]:
    """module -> the microg modules it imports (the facade and the view edges left out)."""
    graph: dict[str, set[str]] = {}
    for mod, edges in _all_edges().items():
        if mod == "microg":  # the public facade imports lazily from every stage
            continue
        graph[mod] = {
            e.target
            for e in edges
            if e.target != mod and e.target != "microg" and not _is_view_edge(e)
        }
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found: list[list[str]] = []
    counter = 0

    def strong(v: str) -> None:
        nonlocal counter
        index[v] = low[v] = counter
        counter += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return found


def test_every_import_form_is_seen() -> None:
    # the reader itself: each form yields the module it loads (a test that cannot see an
    # import could not fail on it)
    code = (
        "import microg.models.bdf\n"
        "from microg.models import nastran\n"
        "from . import graph\n"
        "from .modal import ModalModel\n"
        "from ..errors import InputError\n"
        "def plot_x():\n"
        "    from microg.plotting import modes\n"
        "if TYPE_CHECKING:\n"
        "    from microg.dynamics.modes import Modes\n"
    )
    edges = _edges("microg.models.load", ast.parse(code))
    assert [(e.target, e.function) for e in edges] == [
        ("microg.models.bdf", None),
        ("microg.models.nastran", None),
        ("microg.models.graph", None),
        ("microg.models.modal", None),
        ("microg.errors", None),
        ("microg.plotting.modes", "plot_x"),
        ("microg.dynamics.modes", None),
    ]
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_every_module_has_a_stage() -> None:
    missing = sorted({m for m in _all_edges() if m != "microg" and _stage(m) is None})
    assert missing == [], f"add these to STAGES (and docs/architecture.md): {missing}"


def test_no_lower_stage_imports_a_higher_one() -> None:
    bad = []
    for mod, edges in _all_edges().items():
        if mod == "microg":
            continue
        own = _stage(mod)
        assert own is not None
        for e in edges:
            stage = _stage(e.target)
            if stage is None or stage <= own or _is_view_edge(e):
                continue
            bad.append(f"{mod}:{e.line} (stage {own}) imports {e.target} (stage {stage})")
    assert bad == [], "\n".join(bad)


def test_no_import_cycle() -> None:
    assert _cycles(_graph()) == []


def test_no_module_is_longer_than_a_concept() -> None:
    long = {
        _module_name(p): n
        for p in SRC.rglob("*.py")
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES
    }
    assert long == {}, f"split these into one concept each: {long}"


@pytest.mark.parametrize("heavy", ["scipy", "pint", "matplotlib"])
def test_import_microg_is_light(heavy: str) -> None:
    code = f"import sys, microg; print({heavy!r} in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_plot_leaves_the_backend_alone() -> None:
    # a notebook user's backend must survive microg: pick one, run and plot, read it back
    code = (
        "import matplotlib; matplotlib.use('svg'); import microg;"
        "r = microg.analyze('ioc', observe=['lab'], duration=40, dt=0.02, isolation=False);"
        "r.observations['lab'].plot(); r.modes.structure;"
        "import microg.report.analysis, microg.plotting.analysis;"
        "print(matplotlib.get_backend())"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "svg"


def test_the_package_declares_its_types():
    # PEP 561: a py.typed marker shipped as package data (mypy runs with
    # disallow_untyped_defs on src/, so every function is annotated)
    import tomllib

    assert (SRC / "py.typed").is_file()
    conf = tomllib.loads((SRC.parents[1] / "pyproject.toml").read_text(encoding="utf-8"))
    assert "py.typed" in conf["tool"]["setuptools"]["package-data"]["microg"]
    assert conf["tool"]["mypy"]["disallow_untyped_defs"] is True
