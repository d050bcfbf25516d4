"""environment, seed, location, study, units: no import cycle, no module over 1,000 lines.

The import graph is read from the source (AST) with every import form, wherever it is
written: at module level, inside functions, under ``if TYPE_CHECKING:``, relative
(``from . import x``), a submodule taken from its package (``from microg.seed import
errata``) and ``importlib.import_module("microg....")`` with a literal name.  The one edge
left out is the architecture's exception (docs/architecture.md): a result's ``.plot()``
importing ``microg.plotting`` inside the method.  (tests/test_package_layout.py checks the
stage order of the whole package.)
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "microg"

#: the modules held to the rules here (a module or a package's prefix)
SCOPE = (
    "microg.environment",
    "microg.seed",
    "microg.location",
    "microg.study",
    "microg.units",
    "microg._json",
)
#: the most lines of one module (docs/architecture.md: one concept per module)
MAX_LINES = 1000


def _module_name(path: Path, src: Path) -> str:
    parts = list(path.relative_to(src.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _edges(mod: str, is_pkg: bool, tree: ast.AST, known: set[str]) -> set[tuple[str, str]]:
    """(target module, where: module | function | typing) of every import in ``tree``."""
    out: set[tuple[str, str]] = set()

    def add(target: str, where: str) -> None:
        parts = target.split(".")
        while parts and ".".join(parts) not in known:  # a name inside a module: the module
            parts.pop()
        if parts and ".".join(parts) != mod:
            out.add((".".join(parts), where))

    def base_of(node: ast.ImportFrom) -> str:
        if node.level == 0:
            return node.module or ""
        pkg = mod.split(".") if is_pkg else mod.split(".")[:-1]
        pkg = pkg[: len(pkg) - (node.level - 1)]
        return ".".join(pkg + ([node.module] if node.module else []))

    def visit(node: ast.AST, where: str) -> None:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in node.body:
                visit(sub, "typing")
            for sub in node.orelse:
                visit(sub, where)
            return
        if isinstance(node, ast.Import):
            for alias in node.names:
                add(alias.name, where)
        elif isinstance(node, ast.ImportFrom):
            base = base_of(node)
            for alias in node.names:
                full = f"{base}.{alias.name}"
                add(full if full in known else base, where)
        elif (
            isinstance(node, ast.Call)
            and ast.unparse(node.func) in ("importlib.import_module", "import_module")
            and node.args
            and isinstance(node.args[0], ast.Constant)
            and isinstance(node.args[0].value, str)
        ):
            add(node.args[0].value, where)
        inner = where
        if where == "module" and isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            inner = "function"
        for child in ast.iter_child_nodes(node):
            visit(child, inner)

    visit(tree, "module")
    return out


def import_graph(src: Path = SRC) -> dict[str, set[str]]:
    """Module -> the modules it imports, every form counted but the lazy ``.plot()`` one."""
    paths = {_module_name(p, src): p for p in src.rglob("*.py")}
    known = set(paths)
    graph: dict[str, set[str]] = {}
    for mod, path in paths.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        edges = _edges(mod, path.name == "__init__.py", tree, known)
        graph[mod] = {
            t
            for t, where in edges
            if t != src.name and not (where == "function" and t.startswith("microg.plotting"))
        }
    graph.pop(src.name, None)  # the public facade imports lazily from every stage
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def connect(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                connect(w)
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
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            connect(v)
    return sorted(out)


def _in_scope(module: str) -> bool:
    return any(module == s or module.startswith(s + ".") for s in SCOPE)


def test_no_cycle_reaches_the_scope():
    found = [c for c in cycles(import_graph()) if any(_in_scope(m) for m in c)]
    assert found == [], "import cycles: " + "; ".join(" <-> ".join(c) for c in found)


def test_no_module_in_the_scope_is_over_the_limit():
    long = {}
    for path in SRC.rglob("*.py"):
        mod = _module_name(path, SRC)
        n = len(path.read_text(encoding="utf-8").splitlines())
        if _in_scope(mod) and n > MAX_LINES:
            long[mod] = n
    assert long == {}, f"modules over {MAX_LINES} lines: {long}"


FIXTURE = {
    "__init__.py": "",
    "a.py": "from __future__ import annotations\nfrom pkg import b\n",
    "b.py": "def f():\n    from .c import g\n",
    "c.py": (
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    import pkg.d\n"
        "def g():\n    from pkg.plotting import fig\n"
    ),
    "d.py": "import importlib\nimportlib.import_module('pkg.a')\n",
    "plotting.py": "from pkg import c\n",
    "e.py": "from . import a\n",
}


@pytest.fixture
def fixture_pkg(tmp_path: Path) -> Path:
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    for name, text in FIXTURE.items():
        (pkg / name).write_text(text, encoding="utf-8")
    return pkg


def test_the_scanner_sees_every_import_form(fixture_pkg: Path):
    # a known graph: a -> b (from package import submodule), b -> c (relative, in a
    # function), c -> d (TYPE_CHECKING), d -> a (importlib), e -> a (relative from the
    # package); c -> plotting inside a function is the lazy .plot() exception, so
    # plotting -> c closes no cycle.  ("microg.plotting" is the real exception's prefix;
    # the fixture's is "pkg.plotting", so rename it for the check.)
    graph = import_graph(fixture_pkg)
    assert graph["pkg.a"] == {"pkg.b"}
    assert graph["pkg.b"] == {"pkg.c"}
    assert graph["pkg.d"] == {"pkg.a"}
    assert graph["pkg.e"] == {"pkg.a"}
    assert graph["pkg.c"] == {"pkg.d", "pkg.plotting"}  # not microg.plotting: counted
    assert cycles(graph) == [["pkg.a", "pkg.b", "pkg.c", "pkg.d", "pkg.plotting"]]
    graph["pkg.c"].discard("pkg.plotting")  # as the lazy microg.plotting edge is dropped
    assert cycles(graph) == [["pkg.a", "pkg.b", "pkg.c", "pkg.d"]]
    graph["pkg.c"].discard("pkg.d")  # break the TYPE_CHECKING edge: no cycle left
    assert cycles(graph) == []
