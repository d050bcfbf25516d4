"""Tests of microg.cli._progress: tqdm on a terminal only, and not even imported otherwise."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from microg.cli._progress import NullBar, progress_bar


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_hidden_bar_is_the_null_bar_and_counts():
    bar = progress_bar(3, "x", hide=True)
    assert isinstance(bar, NullBar)
    bar.update(2)
    bar.set_postfix_str("stage")
    bar.update()
    bar.close()
    # reference: the counting the commands rely on (update(done - bar.n) in sweep/optimize)
    assert bar.n == 3


def test_no_terminal_gives_the_null_bar(monkeypatch: pytest.MonkeyPatch):
    # tqdm's own rule (disable=None): no bar when stderr is not a terminal
    monkeypatch.setattr(sys, "stderr", io.StringIO())
    assert isinstance(progress_bar(3, "x", hide=False), NullBar)


def test_terminal_gives_a_tqdm_bar(monkeypatch: pytest.MonkeyPatch):
    from tqdm import tqdm

    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    bar = progress_bar(2, "microg test", hide=False)
    assert isinstance(bar, tqdm)
    bar.update(2)
    bar.close()
    assert "microg test" in term.getvalue()


def test_a_run_without_a_terminal_does_not_import_tqdm():
    # the command's module and a hidden bar, in a fresh interpreter whose stderr is a pipe
    code = (
        "import sys; from microg.cli._progress import progress_bar; "
        "import microg.cli.analyze; progress_bar(1, 'x', hide=False).close(); "
        "print('tqdm' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == "False"
