"""Output helpers: run directories written as a whole, single files, file names, JSON.

The run-directory tests check that a kill mid-run leaves the previous
run or the new one, never a mix; disk full and errors leave the previous run; stale figures
disappear; a directory microg did not write is never replaced; point names that collide
after sanitising get distinct files.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import random
import signal
import stat
import subprocess
import sys
import textwrap
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import microg._io as io_mod
from microg._io import (
    RUN_MARKER,
    atomic_write_text,
    check_writable,
    dumps,
    safe_filenames,
    write_output_files,
    write_run_directory,
)
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


def _listing(path: Path) -> list[str]:
    return sorted(p.name for p in path.iterdir())


def test_run_directory_is_replaced_whole_and_stale_figures_go(tmp_path: Path) -> None:
    out = tmp_path / "run"
    write_run_directory(out, {"report.html": "old", "lab-isolated.png": b"old"}, where="out")
    assert _listing(out) == [RUN_MARKER, "lab-isolated.png", "report.html"]
    # the next run needs no isolation: its directory has no lab-isolated.png
    write_run_directory(out, {"report.html": "new", "results.json": "{}"}, where="out")
    assert _listing(out) == [RUN_MARKER, "report.html", "results.json"]
    assert (out / "report.html").read_text() == "new"
    assert _listing(tmp_path) == ["run"]  # no temporary sibling left
    marker = json.loads((out / RUN_MARKER).read_text())
    # the manifest: every file the run wrote with the SHA-256 of its bytes (hashlib directly)
    assert marker["files"] == {
        "report.html": hashlib.sha256(b"new").hexdigest(),
        "results.json": hashlib.sha256(b"{}").hexdigest(),
    }
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(out.stat().st_mode) == 0o777 & ~umask  # not mkdtemp's 0700


def test_write_output_files_is_the_run_writer(tmp_path: Path) -> None:
    assert write_output_files is write_run_directory  # the name the commands use
    write_output_files(tmp_path / "o", {"a/b.txt": "x"}, where="out")  # subdirectories too
    assert (tmp_path / "o" / "a" / "b.txt").read_text() == "x"


def test_refuses_a_non_empty_directory_microg_did_not_write(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match=f"no {RUN_MARKER} manifest") as exc:
        write_run_directory(tmp_path, {"r.json": "{}"}, where="--out")
    assert exc.value.where == "--out"
    assert _listing(tmp_path) == ["notes.txt"] and (tmp_path / "notes.txt").read_text() == "mine"
    with pytest.raises(InputError, match="manifest"):
        check_writable(tmp_path, "--out")  # the same answer before any computation


def test_an_empty_directory_is_taken(tmp_path: Path) -> None:
    out = tmp_path / "empty"
    out.mkdir()
    write_run_directory(out, {"r.json": "{}"}, where="out")
    assert _listing(out) == [RUN_MARKER, "r.json"]


def test_output_path_that_is_a_file(tmp_path: Path) -> None:
    f = tmp_path / "x"
    f.write_text("file")
    with pytest.raises(InputError, match="not a directory") as exc:
        write_run_directory(f, {"r.json": "{}"}, where="--out")
    assert exc.value.where == "--out"
    assert f.read_text() == "file"


@pytest.mark.parametrize("bad", ["", "   ", ".", ".."])
def test_out_empty_or_current_directory_is_an_error(bad: str, tmp_path: Path, monkeypatch) -> None:
    # `--out ''` wrote into the current directory
    monkeypatch.chdir(tmp_path)
    (tmp_path / "keep").write_text("x")
    for call in (
        lambda: check_writable(bad, "--out"),
        lambda: write_run_directory(bad, {"r.json": "{}"}, where="--out"),
    ):
        with pytest.raises(InputError) as exc:
            call()
        assert exc.value.where == "--out"
    assert _listing(tmp_path) == ["keep"]


def test_check_writable_proc_fails_at_once() -> None:
    # `--out /proc/x` failed only after the computation
    with pytest.raises(InputError, match="cannot write in '/proc'") as exc:
        check_writable("/proc/x", "--out")
    assert "\n" not in str(exc.value)
    with pytest.raises(InputError):
        check_writable("/proc/x.png", "--out", directory=False)


def test_check_writable_creates_nothing(tmp_path: Path) -> None:
    target = tmp_path / "a" / "b" / "run"
    assert check_writable(target, "out") == target
    assert _listing(tmp_path) == []  # the probe is removed, no parent is created
    with pytest.raises(InputError, match="is a directory"):
        check_writable(tmp_path, "out", directory=False)


def test_unwritable_directory_is_one_line_and_cleans_up(tmp_path: Path) -> None:
    if os.geteuid() == 0:
        target = Path("/proc/microg-cannot-write/out")  # root ignores permissions
    else:  # pragma: no cover - CI runs as root
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        target = locked / "out"
    with pytest.raises(InputError) as exc:
        write_run_directory(target, {"a.txt": "x"}, where="--out")
    assert "\n" not in str(exc.value) and exc.value.where == "--out"


def test_disk_full_keeps_the_previous_run(tmp_path: Path, monkeypatch) -> None:
    out = tmp_path / "run"
    write_run_directory(out, {"a.png": b"old-a", "report.html": "old"}, where="out")
    real_open = open
    calls = {"n": 0}

    def full_disk(file, mode="r", *args, **kwargs):  # the second file finds the disk full
        if "x" in mode:
            calls["n"] += 1
            if calls["n"] == 2:
                raise OSError(errno.ENOSPC, "No space left on device", str(file))
        return real_open(file, mode, *args, **kwargs)

    monkeypatch.setattr(io_mod, "open", full_disk, raising=False)
    with pytest.raises(InputError, match="No space left on device") as exc:
        write_run_directory(out, {"a.png": b"new-a", "report.html": "new"}, where="--out")
    assert exc.value.where == "--out" and "\n" not in str(exc.value)
    assert (out / "a.png").read_bytes() == b"old-a" and (out / "report.html").read_text() == "old"
    assert _listing(tmp_path) == ["run"]  # the temporary directory is gone


def test_disk_full_on_a_first_run_leaves_nothing(tmp_path: Path, monkeypatch) -> None:
    def full_disk(file, mode="r", *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(file))

    monkeypatch.setattr(io_mod, "open", full_disk, raising=False)
    with pytest.raises(InputError, match="No space"):
        write_run_directory(tmp_path / "deep" / "run", {"a": "x"}, where="out")
    assert _listing(tmp_path) == []  # not even the parent it created


def test_without_atomic_exchange_the_fallback_works(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(io_mod, "_exchange", lambda a, b: False)  # non-Linux systems
    out = tmp_path / "run"
    write_run_directory(out, {"a": "1", "b": "1"}, where="out")
    write_run_directory(out, {"a": "2"}, where="out")
    assert _listing(out) == [RUN_MARKER, "a"] and (out / "a").read_text() == "2"
    assert _listing(tmp_path) == ["run"]


_CHILD = textwrap.dedent(
    """
    import sys
    from microg._io import write_run_directory
    out, start = sys.argv[1], int(sys.argv[2])
    payload = 400_000
    for k in range(start, start + 10_000):
        files = {f"fig{i}.png": (f"{k:08d}".encode() * (payload // 8)) for i in range(6)}
        files["report.html"] = f"{k:08d}" * (payload // 8)
        write_run_directory(out, files, where="out")
        print(k, flush=True)
    """
)


def _check_complete(out: Path) -> int | None:
    """The run id of ``out`` when it is one complete run (all files from the same run)."""
    if not out.exists():
        return None
    names = set(_listing(out))
    marker = json.loads((out / RUN_MARKER).read_text())
    assert names == {RUN_MARKER, *marker["files"]}  # exactly the files of its run
    ids = {(out / n).read_bytes()[:8] for n in marker["files"]}
    assert len(ids) == 1, f"mixed runs: {ids}"  # never new figures beside an old report
    return int(ids.pop())


@pytest.mark.slow
def test_killed_at_random_points_leaves_one_complete_run(tmp_path: Path) -> None:
    # kills mixed runs (8 of 20 trials) and left temporaries (33 of 76)
    out = tmp_path / "run"
    rng = random.Random(20261201)  # fixed seed: reproducible kill times
    last = None
    for trial in range(12):
        sig = signal.SIGKILL if trial % 3 else signal.SIGTERM
        proc = subprocess.Popen(
            [sys.executable, "-c", _CHILD, str(out), str(trial * 10_000)],
            stdout=subprocess.PIPE,
            text=True,
        )
        assert proc.stdout is not None
        proc.stdout.readline()  # at least one run written, so a previous run exists
        time.sleep(rng.uniform(0.0, 0.15))
        proc.send_signal(sig)
        proc.wait(timeout=30)
        proc.stdout.close()
        run_id = _check_complete(out)
        assert run_id is not None and run_id >= trial * 10_000
        leftovers = [n for n in _listing(tmp_path) if n != "run"]
        if sig == signal.SIGTERM:
            assert leftovers == []  # cleaned up on the way out
        last = run_id
    assert last is not None
    # a SIGKILL can leave one hidden temporary; the next run into the same place removes it
    write_run_directory(out, {"report.html": "final"}, where="out")
    assert _listing(tmp_path) == ["run"]
    assert _listing(out) == [RUN_MARKER, "report.html"]


_KILLED_IN_MARKER = textwrap.dedent(
    """
    import os, pathlib, sys
    from microg._io import RUN_MARKER, write_run_directory
    out = sys.argv[1]
    write_run_directory(out, {"a.txt": "first"}, where="out")
    real = pathlib.Path.write_text
    def half(self, data, *args, **kwargs):
        if self.name.startswith(RUN_MARKER):  # killed halfway through writing the marker
            real(self, data[: len(data) // 2], *args, **kwargs)
            os._exit(9)
        return real(self, data, *args, **kwargs)
    pathlib.Path.write_text = half
    write_run_directory(out, {"a.txt": "second", "b.txt": "x"}, where="out")
    """
)


def test_a_kill_while_the_marker_is_written_leaves_nothing_for_the_next_run(tmp_path: Path):
    # the random-kill test found it: a run killed while writing its marker left a temporary
    # with every file and half a marker, which the next run could not read as a run and so
    # moved aside as "kept" (a user's files would be): the marker is now written whole or not
    # at all, and the next run removes the temporary entirely
    out = tmp_path / "run"
    proc = subprocess.run([sys.executable, "-c", _KILLED_IN_MARKER, str(out)], timeout=60)
    assert proc.returncode == 9
    assert (out / "a.txt").read_text() == "first"  # the first run, untouched
    write_run_directory(out, {"a.txt": "third"}, where="out")
    assert _listing(tmp_path) == ["run"]  # no temporary, nothing kept aside
    assert (out / "a.txt").read_text() == "third"


def _locked(path: Path) -> int:
    """An open, locked lock file at ``path`` (a run that is still writing): its descriptor."""
    import fcntl

    fd = os.open(path, os.O_CREAT | os.O_RDWR, 0o600)
    fcntl.flock(fd, fcntl.LOCK_EX)
    return fd


@pytest.mark.skipif(os.name == "nt", reason="the test holds its lock with fcntl")
def test_stale_temporaries_are_removed_only_when_their_run_is_over(tmp_path: Path) -> None:
    out = tmp_path / "run"
    live = tmp_path / ".run.microg-tmp-1-aaaa"  # a concurrent run: its lock is held
    live.mkdir()
    (live / "fig.png").write_bytes(b"x")
    fd = _locked(tmp_path / ".run.microg-tmp-1-aaaa.lock")
    dead = tmp_path / ".run.microg-tmp-2-bbbb"  # killed before its marker: lock file, free
    dead.mkdir()
    (dead / "fig.png").write_bytes(b"x")
    (tmp_path / ".run.microg-tmp-2-bbbb.lock").write_bytes(b"")
    notours = tmp_path / ".run.microg-tmp-3-cccc"  # named like one, but no lock file
    notours.mkdir()
    (notours / "data.txt").write_text("not a run")
    try:
        write_run_directory(out, {"a": "1"}, where="out")
    finally:
        os.close(fd)
    assert live.exists() and (live / "fig.png").exists()
    assert not dead.exists() and not (tmp_path / ".run.microg-tmp-2-bbbb.lock").exists()
    assert (notours / "data.txt").read_text() == "not a run"  # never deleted


def test_stale_detection_never_signals_a_process(tmp_path: Path, monkeypatch) -> None:
    # os.kill(pid, 0) terminates the process on Windows: no process is ever signalled
    def no_kill(*args):
        raise AssertionError("os.kill called")

    monkeypatch.setattr(os, "kill", no_kill)
    dead = tmp_path / f".run.microg-tmp-{os.getpid()}-dddd"
    dead.mkdir()
    (tmp_path / f".run.microg-tmp-{os.getpid()}-dddd.lock").write_bytes(b"")
    write_run_directory(tmp_path / "run", {"a": "1"}, where="out")
    assert _listing(tmp_path) == ["run"]


# -------------------------------------------- a run deletes only what an earlier run wrote


def test_an_empty_marker_does_not_make_a_directory_microgs(tmp_path: Path) -> None:
    # an empty .microg-run beside a user's files used to let a run wipe them (exit 0)
    out = tmp_path / "mine"
    out.mkdir()
    (out / RUN_MARKER).write_text("")
    (out / "notes.txt").write_text("keep me")
    (out / "data").mkdir()
    (out / "data" / "x.csv").write_text("1,2")
    with pytest.raises(InputError, match="microg did not write"):
        check_writable(out, "--out")
    with pytest.raises(InputError, match="microg did not write"):
        write_run_directory(out, {"r.json": "{}"}, where="--out")
    assert (out / "notes.txt").read_text() == "keep me"
    assert (out / "data" / "x.csv").read_text() == "1,2"


@pytest.mark.parametrize("marker", ['{"microg_run": 1, "files": ["r.json"]}', "{}", "[1]", "x"])
def test_a_marker_without_microgs_manifest_is_refused(tmp_path: Path, marker: str) -> None:
    # a manifest of names without hashes (microg 0.2) cannot show that nothing was changed
    out = tmp_path / "old"
    out.mkdir()
    (out / RUN_MARKER).write_text(marker)
    (out / "r.json").write_text("{}")
    with pytest.raises(InputError, match="manifest"):
        write_run_directory(out, {"r.json": "{}"}, where="--out")
    assert (out / "r.json").read_text() == "{}"


def test_a_file_added_to_an_earlier_run_is_kept_and_named(tmp_path: Path) -> None:
    out = tmp_path / "run"
    write_run_directory(out, {"report.html": "old", "figs/a.png": b"a"}, where="out")
    (out / "my-notes.txt").write_text("mine")
    (out / "figs" / "annotated.png").write_bytes(b"mine")
    with pytest.raises(InputError, match="did not write") as exc:
        write_run_directory(out, {"report.html": "new"}, where="--out")
    msg = str(exc.value)
    assert "my-notes.txt" in msg and "figs/annotated.png" in msg and "\n" not in msg
    assert exc.value.where == "--out"
    assert (out / "my-notes.txt").read_text() == "mine"
    assert (out / "report.html").read_text() == "old"  # the earlier run is untouched


def test_a_file_edited_in_an_earlier_run_is_kept_and_named(tmp_path: Path) -> None:
    out = tmp_path / "run"
    write_run_directory(out, {"report.html": "old", "results.json": "{}"}, where="out")
    (out / "report.html").write_text("old, with my remarks")
    with pytest.raises(InputError, match="report.html"):
        check_writable(out, "--out")
    assert (out / "report.html").read_text() == "old, with my remarks"


@pytest.mark.parametrize("extra", ["link", "emptydir"])
def test_links_and_empty_directories_are_not_microgs(tmp_path: Path, extra: str) -> None:
    out = tmp_path / "run"
    write_run_directory(out, {"a.txt": "1"}, where="out")
    if extra == "link":
        (tmp_path / "elsewhere.txt").write_text("precious")
        (out / "ln").symlink_to(tmp_path / "elsewhere.txt")
    else:
        (out / "empty").mkdir()
    with pytest.raises(InputError, match="did not write"):
        write_run_directory(out, {"a.txt": "2"}, where="out")
    if extra == "link":
        assert (tmp_path / "elsewhere.txt").read_text() == "precious"


def test_a_file_added_after_the_check_survives_the_replacement(tmp_path: Path, monkeypatch):
    # the race between the last check and the removal of the previous run: whatever appeared
    # in it is kept, in a visible sibling (NAME.microg-kept-TOKEN), never deleted
    out = tmp_path / "run"
    write_run_directory(out, {"report.html": "old"}, where="out")
    real_swap = io_mod._swap

    def swap_then_user_writes(new, target, stem):
        previous = real_swap(new, target, stem)
        (previous / "late.txt").write_text("written during the swap")
        return previous

    monkeypatch.setattr(io_mod, "_swap", swap_then_user_writes)
    write_run_directory(out, {"report.html": "new"}, where="out")
    assert (out / "report.html").read_text() == "new"
    kept = [p for p in tmp_path.iterdir() if p.name.startswith("run.microg-kept-")]
    assert len(kept) == 1 and (kept[0] / "late.txt").read_text() == "written during the swap"
    assert not (kept[0] / "report.html").exists()  # the old run's own file is gone


def test_a_link_to_an_existing_directory_is_followed(tmp_path: Path) -> None:
    real = tmp_path / "real"
    real.mkdir()
    link = tmp_path / "out"
    link.symlink_to(real)
    write_run_directory(link, {"a.txt": "1"}, where="--out")
    write_run_directory(link, {"a.txt": "2"}, where="--out")  # and replaced there again
    assert link.is_symlink() and (real / "a.txt").read_text() == "2"


@pytest.mark.parametrize("kind", ["dangling", "to-file"])
def test_a_link_to_anything_else_is_refused(tmp_path: Path, kind: str) -> None:
    dest = tmp_path / "no" / "such" / "dir" if kind == "dangling" else tmp_path / "f.txt"
    if kind == "to-file":
        dest.write_text("file")
    link = tmp_path / "out"
    link.symlink_to(dest)
    for call in (
        lambda: check_writable(link, "--out"),
        lambda: write_run_directory(link, {"a.txt": "1"}, where="--out"),
    ):
        with pytest.raises(InputError, match="symbolic link") as exc:
            call()
        assert exc.value.where == "--out"
    assert not (tmp_path / "no").exists()  # the link's target's parents are not created
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["out"] + (["f.txt"] if kind == "to-file" else [])
    )


def test_safe_filenames_a_slash_b_and_a_underscore_b() -> None:
    # points "a/b" and "a_b" both wrote a_b-*.png, and the report showed one figure for both
    names = safe_filenames(["a/b", "a_b", "lab", "crew site", "Lab", "..", ""])
    stems = list(names.values())
    assert len({s.lower() for s in stems}) == len(stems)  # unique, also without case
    assert names["a_b"] == "a_b" and names["a/b"].startswith("a_b-")
    assert all(s and s[0] not in ".-" and len(s) <= 80 for s in stems)
    assert all(set(s) <= set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-")
               for s in stems)  # fmt: skip
    # stable: the same names in another order give the same files
    again = safe_filenames(["", "..", "Lab", "crew site", "lab", "a_b", "a/b"])
    assert again == names
    assert safe_filenames(["lab"]) == {"lab": "lab"}  # a safe name is its own file


def test_dumps_handles_dataclasses_arrays_and_nan() -> None:
    @dataclass
    class R:
        a: np.ndarray
        b: float
        c: np.bool_

    text = dumps(R(np.array([1.0, np.nan]), np.float64(2.5), np.bool_(True)))
    assert json.loads(text) == {"a": [1.0, None], "b": 2.5, "c": True}
