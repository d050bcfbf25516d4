"""The package's layout keeps the data flow one way (the rule of docs/architecture.md).

Every ``import microg.X`` statement in ``src/microg`` is read from the source (AST), at module
level and inside functions alike; only ``if TYPE_CHECKING:`` blocks are skipped.  A module may
import its own stage or a lower one, never a higher one.  The one exception is the view
layer: a result's ``.plot()`` may import ``microg.plotting`` lazily, inside the method.  The
test also checks that the module-level import graph has no cycle, and that ``import microg``
loads neither scipy, pint nor matplotlib.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "microg"

#: stage of each top-level module or package, bottom (0) to top
STAGES: dict[str, int] = {
    "errors": 0,
    "units": 0,
    "_io": 0,
    "_json": 0,
    "_vectors": 0,
    "_scan": 0,
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


def _module_name(path: Path) -> str:
    rel = path.relative_to(SRC.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _stage(module: str) -> int | None:
    parts = module.split(".")
    if parts[0] != "microg" or len(parts) < 2:
        return None
    return STAGES.get(parts[1])


def _imports(tree: ast.AST) -> list[tuple[str, bool]]:
    """(imported microg module, at module level?) for every import outside TYPE_CHECKING."""
    out: list[tuple[str, bool]] = []

    def visit(node: ast.AST, top: bool) -> None:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in node.orelse:
                visit(sub, top)
            return
        if isinstance(node, ast.Import):
            out.extend((a.name, top) for a in node.names if a.name.startswith("microg"))
        elif (
            isinstance(node, ast.ImportFrom)
            and node.module
            and node.level == 0
            and node.module.startswith("microg")
        ):
            out.append((node.module, top))
        inner = top and not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda)
        for child in ast.iter_child_nodes(node):
            visit(child, inner)

    visit(tree, True)
    return out


def _all_modules() -> dict[str, list[tuple[str, bool]]]:
    mods = {}
    for path in SRC.rglob("*.py"):
        mods[_module_name(path)] = _imports(ast.parse(path.read_text(encoding="utf-8")))
    return mods


def test_every_module_has_a_stage() -> None:
    missing = sorted({m for m in _all_modules() if m != "microg" and _stage(m) is None})
    assert missing == [], f"add these to STAGES (and docs/architecture.md): {missing}"


def test_no_lower_stage_imports_a_higher_one() -> None:
    bad = []
    for mod, imports in _all_modules().items():
        if mod == "microg":  # the public facade imports lazily from every stage
            continue
        own = _stage(mod)
        assert own is not None
        for target, top in imports:
            stage = _stage(target)
            if stage is None or stage <= own:
                continue
            if not top and target.startswith("microg.plotting"):
                continue  # a result's .plot() draws through the view layer, lazily
            bad.append(f"{mod} (stage {own}) imports {target} (stage {stage})")
    assert bad == [], "\n".join(bad)


def test_no_import_cycle() -> None:
    mods = _all_modules()
    graph = {
        m: {
            t
            for t, top in imps
            if t in mods and t != m and (top or not t.startswith("microg.plotting"))
        }
        for m, imps in mods.items()
        if m != "microg"
    }
    state: dict[str, int] = {}
    cycle: list[str] = []

    def dfs(node: str, path: list[str]) -> bool:
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if nxt == "microg":
                continue
            if state.get(nxt) == 1:
                cycle.extend([*path, node, nxt])
                return True
            if state.get(nxt) is None and dfs(nxt, [*path, node]):
                return True
        state[node] = 2
        return False

    for node in sorted(graph):
        if state.get(node) is None and dfs(node, []):
            break
    assert cycle == [], " -> ".join(cycle)


@pytest.mark.parametrize("heavy", ["scipy", "pint", "matplotlib"])
def test_import_microg_is_light(heavy: str) -> None:
    code = f"import sys, microg; print({heavy!r} in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("heavy", ["scipy", "pydantic", "pint", "matplotlib"])
def test_the_classes_of_an_analysis_import_light(heavy: str) -> None:
    # the result classes and the report module import lazily: scipy and pydantic load on
    # first use (a reader of a pickled Analysis of a frame model needs none of them)
    mods = "microg.analysis, microg.structure.fem, microg.report.analysis"
    code = f"import sys, {mods}; print({heavy!r} in sys.modules)"
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
