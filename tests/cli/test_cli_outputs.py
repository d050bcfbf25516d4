"""Every command that writes a run directory never deletes what it did not write there.

Reference: the directory's own listing and contents, read before and after the run.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from microg.cli import main

ROOT = Path(__file__).resolve().parents[2]

#: a command and its cheapest arguments, each writing a run directory with --out
COMMANDS = {
    "analyze": ["analyze", "ioc", "--duration", "40 s", "--no-progress"],
    "locate": ["locate", "ioc"],
    "quasi-steady": ["quasi-steady", "ioc", "--atmosphere", "exponential"],
    "assess": ["assess", str(ROOT / "examples" / "measured.csv"), "--interval", "60s"],
    "reproduce": ["reproduce"],
}


def _snapshot(path: Path) -> dict[str, bytes]:
    return {str(p.relative_to(path)): p.read_bytes() for p in path.rglob("*") if p.is_file()}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_an_empty_marker_beside_a_users_files_is_refused(command, tmp_path, capsys) -> None:
    # an empty .microg-run next to a user's notes and data once let every command wipe them
    out = tmp_path / "mine"
    (out / "data").mkdir(parents=True)
    (out / ".microg-run").write_text("")
    (out / "notes.txt").write_text("keep me")
    (out / "data" / "x.csv").write_text("1,2\n")
    before = _snapshot(out)
    rc = main([*COMMANDS[command], "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "--out" in err
    assert _snapshot(out) == before


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_file_added_to_an_earlier_run_is_never_deleted(command, tmp_path, capsys) -> None:
    out = tmp_path / "run"
    assert main([*COMMANDS[command], "--out", str(out)]) == 0
    (out / "my-remarks.txt").write_text("mine")
    capsys.readouterr()
    rc = main([*COMMANDS[command], "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and "my-remarks.txt" in err and err.count("\n") == 1
    assert (out / "my-remarks.txt").read_text() == "mine"
    (out / "my-remarks.txt").unlink()  # without it, the run replaces its own directory
    assert main([*COMMANDS[command], "--out", str(out)]) == 0
