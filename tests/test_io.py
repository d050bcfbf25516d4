"""Output helpers: atomic writes, output directories, JSON of results."""

from __future__ import annotations

import json
import os
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from microg._io import atomic_write_text, dumps, write_output_files
from microg.errors import InputError


def test_atomic_write_replaces_and_leaves_no_temporaries(tmp_path: Path) -> None:
    p = tmp_path / "a.txt"
    atomic_write_text(p, "one")
    atomic_write_text(p, "two")
    assert p.read_text() == "two"
    assert [q.name for q in tmp_path.iterdir()] == ["a.txt"]
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~umask  # not mkstemp's 0600


def test_output_files_keep_other_content(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("mine")
    write_output_files(tmp_path, {"r.json": "{}", "f.png": b"\x89PNG"}, where="--out")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png", "notes.txt", "r.json"]
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_output_path_that_is_a_file(tmp_path: Path) -> None:
    f = tmp_path / "x"
    f.write_text("file")
    with pytest.raises(InputError, match="not a directory") as exc:
        write_output_files(f, {"r.json": "{}"}, where="--out")
    assert exc.value.where == "--out"
    assert f.read_text() == "file"


def test_unwritable_directory_is_one_line_and_cleans_up(tmp_path: Path) -> None:
    if os.geteuid() == 0:
        target = Path("/proc/microg-cannot-write/out")  # root ignores permissions
    else:  # pragma: no cover - CI runs as root
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        target = locked / "out"
    with pytest.raises(InputError) as exc:
        write_output_files(target, {"a.txt": "x"}, where="--out")
    assert "\n" not in str(exc.value) and exc.value.where == "--out"


def test_dumps_handles_dataclasses_arrays_and_nan() -> None:
    @dataclass
    class R:
        a: np.ndarray
        b: float
        c: np.bool_

    text = dumps(R(np.array([1.0, np.nan]), np.float64(2.5), np.bool_(True)))
    assert json.loads(text) == {"a": [1.0, None], "b": 2.5, "c": True}
