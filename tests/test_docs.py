"""The documentation runs as written: the API page as doctests, and every README command."""

from __future__ import annotations

import doctest
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_api_page_doctests() -> None:
    result = doctest.testfile(
        str(ROOT / "docs" / "api.md"),
        module_relative=False,
        optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
    )
    assert result.attempted > 10 and result.failed == 0


def test_package_docstring_doctest() -> None:
    import microg

    result = doctest.testmod(microg, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 4 and result.failed == 0


def _readme_commands() -> list[str]:
    """The `microg ...` lines of README.md's shell blocks (continuations joined)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    cmds = []
    for block in re.findall(r"```sh\n(.*?)```", text, flags=re.S):
        joined = block.replace("\\\n", " ")
        for line in joined.splitlines():
            line = line.strip()
            if line.startswith("microg "):
                cmds.append(line)
    return cmds


def test_readme_has_examples() -> None:
    assert len(_readme_commands()) >= 10


@pytest.mark.slow
@pytest.mark.parametrize("command", _readme_commands())
def test_readme_example_runs_as_written(command: str, tmp_path: Path) -> None:
    # run in a scratch directory laid out like a clone (examples/ and tests/), so that outputs
    # land in the scratch directory, as a user's would; nothing outside the clone is reachable
    work = tmp_path / "clone"
    work.mkdir()
    for name in ("examples", "tests"):
        (work / name).symlink_to(ROOT / name)
    args = shlex.split(command)
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run(
        [sys.executable, "-m", "microg", *args[1:], *(["--no-progress"] * _progress(args))],
        cwd=work,
        capture_output=True,
        text=True,
        timeout=600,
        env=env,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr


def _progress(args: list[str]) -> bool:
    return len(args) > 1 and args[1] in ("analyze",) and "--no-progress" not in args


def test_api_page_studies_block_runs_and_hands_out_numbers(tmp_path: Path, monkeypatch) -> None:
    # the "Studies" block of docs/api.md, run as written (in a directory holding the
    # repository's examples/): every expression it shows evaluates to computed values (numpy
    # arrays, not an uncomputed Dask graph), so what a user copies prints numbers
    import ast
    import shutil

    import numpy as np

    text = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    block = text.split("## Studies", 1)[1].split("```python", 1)[1].split("```", 1)[0]
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    shown = []
    for stmt in ast.parse(block).body:
        if isinstance(stmt, ast.Expr):
            shown.append(eval(compile(ast.Expression(stmt.value), "api.md", "eval"), scope))
        else:
            exec(compile(ast.Module([stmt], []), "api.md", "exec"), scope)
    assert len(shown) == 2
    margin, summary = shown
    assert isinstance(margin.data, np.ndarray) and np.all(np.isfinite(margin.data))
    assert isinstance(summary, dict) and 0.0 <= summary["complying_fraction"] <= 1.0


def test_api_page_computes_what_it_shows_of_a_lazy_dataset() -> None:
    # a study's dataset is opened lazily (Dask arrays over zarr): an expression on it printed
    # as written shows an uncomputed array, so the page computes each one it shows
    text = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    shown = [ln for ln in text.splitlines() if ln.startswith("result.dataset")]
    assert shown and all(".compute()" in ln for ln in shown)
