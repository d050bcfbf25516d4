"""Output helpers: run directories written atomically as a whole, single files, JSON of results.

A command's output (report, figures, JSON) is a **run directory**, written all at once by
:func:`write_run_directory`:

* the whole run is written into a hidden temporary sibling directory, then swapped in with one
  rename (Linux ``renameat2(RENAME_EXCHANGE)``; elsewhere two renames), so the target always
  holds one complete run, the previous one until the swap and the new one after it; the
  previous run is then removed;
* a run directory carries a small marker file :data:`RUN_MARKER`; a non-empty directory
  without it is never replaced or deleted (it is not microg's);
* on any error (disk full, permissions) or on SIGINT/SIGTERM, the temporary directory is
  removed and the previous run is left as it was.  A SIGKILL can leave only a hidden
  temporary sibling (``.NAME.microg-tmp-PID-*``), which the next run into the same place
  removes;
* files of an earlier run that the new run does not write (stale figures) disappear with it.

:func:`check_writable` checks an output path before any computation, and
:func:`safe_filenames` gives unique, stable file names for arbitrary point names.
"""

from __future__ import annotations

import contextlib
import ctypes
import dataclasses
import errno
import hashlib
import json
import os
import re
import secrets
import shutil
import signal
import sys
import tempfile
import threading
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = [
    "RUN_MARKER",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_writable",
    "dumps",
    "safe_filenames",
    "loads_toml",
    "sigterm_raises",
    "to_jsonable",
    "write_output_files",
    "write_run_directory",
]

#: name of the marker file of a run directory
RUN_MARKER = ".microg-run"
_TMP_TAG = ".microg-tmp-"


_TOML_POS = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")


def loads_toml(text: str, filename: str, error: type[InputError] = InputError) -> dict[str, Any]:
    """``tomllib.loads``, a syntax error as one line naming ``filename: line L, column C``.

    Parameters
    ----------
    text : the TOML text
    filename : the file named in the error
    error : the error type raised (``ModelError`` for model files)
    """
    import tomllib

    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = _TOML_POS.search(msg)
        where = f"{filename}: line {m.group(1)}, column {m.group(2)}" if m else filename
        raise error(
            f"invalid TOML: {' '.join(_TOML_POS.sub('', msg).split())}",
            where=where,
            fix="fix the TOML syntax there",
        ) from None


def to_jsonable(obj: Any) -> Any:
    """Convert dataclasses, numpy arrays and scalars to plain JSON types (NaN -> None)."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.bool_ | bool):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating | float):
        value = float(obj)
        return value if np.isfinite(value) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def dumps(obj: Any, indent: int | None = 2) -> str:
    """JSON text of ``obj`` after :func:`to_jsonable`."""
    return json.dumps(to_jsonable(obj), indent=indent, allow_nan=False)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


# ------------------------------------------------------------------------------ single files


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same directory and a rename.

    The file gets the usual permissions (0666 less the umask), not mkstemp's 0600.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (see :func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode("utf-8"))


# ----------------------------------------------------------------------------- file names

_UNSAFE = re.compile(r"[^A-Za-z0-9_-]+")
_MAX_STEM = 64


def _digest(name: str) -> str:
    return hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:8]


def safe_filenames(names: Iterable[str]) -> dict[str, str]:
    """A file-name stem for each name: unique, stable, safe on every file system.

    A name made only of ``A-Z a-z 0-9 _ -`` (at most 64 characters, not starting with ``-``)
    is its own stem.  Any other name is sanitised (runs of other characters become ``_``)
    and gets ``-`` plus 8 hex digits of the SHA-256 of the name, so that ``"a/b"`` and
    ``"a_b"`` never share a file.  Stems that would still coincide, compared without case
    (macOS and Windows), all get the suffix.  A name's stem depends only on the name and on
    which other names collide with it.

    Parameters
    ----------
    names : point (or other) names, any text

    Returns
    -------
    dict
        name -> stem (add the extension and any prefix yourself).
    """
    stems: dict[str, str] = {}
    for name in dict.fromkeys(names):
        clean = _UNSAFE.sub("_", name).strip("_")[:_MAX_STEM]
        if clean != name or not clean or clean.startswith("-"):
            clean = f"{clean.lstrip('-') or 'x'}-{_digest(name)}"
        stems[name] = clean
    groups: dict[str, list[str]] = {}
    for name, stem in stems.items():
        groups.setdefault(stem.lower(), []).append(name)
    for members in groups.values():
        if len(members) > 1:
            for name in members:
                if not stems[name].endswith(_digest(name)):
                    stems[name] = f"{stems[name]}-{_digest(name)}"
    if len({s.lower() for s in stems.values()}) != len(stems):  # pragma: no cover - sha collision
        raise InputError("names collide after sanitising", where="names")
    return stems


# --------------------------------------------------------------------------- run directories


def _has_marker(path: Path) -> bool:
    return (path / RUN_MARKER).is_file()


def _is_empty_dir(path: Path) -> bool:
    with os.scandir(path) as it:
        return next(it, None) is None


def _resolve_target(path: str | Path | None, where: str) -> Path:
    """The absolute output directory, checked: not empty text, not cwd, not a file."""
    if path is None or not str(path).strip():
        raise InputError(
            "is empty", where=where, fix="name an output directory, e.g. 'microg-results'"
        )
    text = str(path)
    if "\x00" in text:
        raise InputError("holds a NUL character", where=where)
    target = Path(os.path.abspath(text))
    try:
        if target.is_symlink():
            target = target.resolve()
        cwd = Path.cwd().resolve()
    except OSError as exc:
        raise InputError(f"cannot use {text!r}: {exc.strerror or exc}", where=where) from None
    if target == Path(target.anchor) or target.resolve() in (cwd, *cwd.parents):
        raise InputError(
            f"{text!r} is the current directory or one above it; microg replaces its output "
            "directory as a whole",
            where=where,
            fix="name a new subdirectory, e.g. 'microg-results'",
        )
    return target


def _check_replaceable(target: Path, text: str, where: str) -> None:
    try:
        if target.exists() and not target.is_dir():
            raise InputError(f"{text!r} exists and is not a directory", where=where)
        if target.is_dir() and not _has_marker(target) and not _is_empty_dir(target):
            raise InputError(
                f"{text!r} is a non-empty directory that microg did not write (it has no "
                f"{RUN_MARKER} marker); microg replaces its output directory as a whole",
                where=where,
                fix="choose a new or empty directory, or one that microg wrote",
            )
    except OSError as exc:
        raise InputError(f"cannot use {text!r}: {exc.strerror or exc}", where=where) from None


def _existing_ancestor(path: Path) -> Path:
    for p in (path, *path.parents):
        if p.exists():
            return p
    return Path(path.anchor)


def check_writable(path: str | Path | None, where: str, *, directory: bool = True) -> Path:
    """Check, before computing anything, that output can be written to ``path``.

    Parameters
    ----------
    path : the output directory (``directory=True``) or file
    where : parameter named in the error
    directory : True for a run directory (:func:`write_run_directory`), False for one file

    Returns
    -------
    Path
        The absolute path that will be written.

    Raises
    ------
    InputError
        The path is empty, is the current directory, is a file where a directory is needed
        (or the reverse), is a non-empty directory microg did not write, or its parent
        cannot be written (probed by creating and removing a temporary entry).
    """
    text = "" if path is None else str(path)
    if directory:
        target = _resolve_target(path, where)
        _check_replaceable(target, text, where)
    else:
        if not text.strip() or "\x00" in text:
            raise InputError("is empty", where=where, fix="name an output file")
        target = Path(os.path.abspath(text))
        if target.is_dir():
            raise InputError(f"{text!r} is a directory", where=where, fix="name a file")
    probe_in = _existing_ancestor(target.parent)
    try:
        if not probe_in.is_dir():
            raise InputError(f"{str(probe_in)!r} is not a directory", where=where)
        os.rmdir(tempfile.mkdtemp(prefix=".microg-probe-", dir=probe_in))
    except OSError as exc:
        raise InputError(
            f"cannot write in {str(probe_in)!r}: {exc.strerror or exc}",
            where=where,
            fix="choose a writable location",
        ) from None
    return target


_RENAMEAT2: Any = None


def _renameat2() -> Any:
    global _RENAMEAT2
    if _RENAMEAT2 is None:
        fn: Any = False
        if sys.platform.startswith("linux"):
            try:
                libc = ctypes.CDLL(None, use_errno=True)
                fn = getattr(libc, "renameat2", False)
                if fn:
                    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                                   ctypes.c_uint]  # fmt: skip
                    fn.restype = ctypes.c_int
            except OSError:  # pragma: no cover - no libc
                fn = False
        _RENAMEAT2 = fn
    return _RENAMEAT2


def _exchange(a: Path, b: Path) -> bool:
    """Swap two directories atomically; False where the system cannot."""
    fn = _renameat2()
    if not fn:
        return False
    at_fdcwd, rename_exchange = -100, 2
    if fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP, errno.EPERM):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _remove_stale(target: Path) -> None:
    """Remove temporary siblings left by killed runs into ``target`` (dead process, marked)."""
    prefix = f".{target.name}{_TMP_TAG}"
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return
    for entry in entries:
        if not entry.name.startswith(prefix) or not entry.is_dir(follow_symlinks=False):
            continue
        pid_text = entry.name[len(prefix) :].split("-", 1)[0]
        if not pid_text.isdigit() or _pid_alive(int(pid_text)):
            continue
        path = Path(entry.path)
        with contextlib.suppress(OSError):
            if _has_marker(path) or _is_empty_dir(path) or _only_partial(path):
                _remove_run(path)


def _only_partial(path: Path) -> bool:
    """A temporary directory killed before its marker was written: it has a pending tag."""
    return (path / f"{RUN_MARKER}.pending").is_file()


class _Terminated(BaseException):
    """SIGTERM arrived while a run directory was being written."""


@contextlib.contextmanager
def sigterm_raises(exc_type: type[BaseException]) -> Iterator[Any]:
    """Inside the block, SIGTERM raises ``exc_type`` (main thread only); restored after.

    Yields the handler the block replaced (``signal.SIG_DFL`` if none), for a caller that
    re-delivers the signal once it has cleaned up.
    """
    if threading.current_thread() is not threading.main_thread():
        yield signal.getsignal(signal.SIGTERM) or signal.SIG_DFL
        return

    def handler(signum: int, frame: Any) -> None:
        raise exc_type

    previous = signal.signal(signal.SIGTERM, handler) or signal.SIG_DFL
    try:
        yield previous
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def _sigterm_as_exception() -> Iterator[None]:
    """Turn SIGTERM into an exception inside the block (main thread only), then re-deliver it."""
    with sigterm_raises(_Terminated) as previous:
        try:
            yield
        except _Terminated:
            signal.signal(signal.SIGTERM, previous)
            signal.raise_signal(signal.SIGTERM)  # the previous handler (default: terminate)
            raise KeyboardInterrupt from None  # pragma: no cover - a handler that returned


def _check_names(files: Mapping[str, bytes | str], where: str) -> None:
    for name in files:
        parts = Path(name).parts
        if (
            not name
            or Path(name).is_absolute()
            or any(p in ("", ".", "..") for p in parts)
            or parts[0].startswith(RUN_MARKER)
        ):
            raise InputError(f"bad output file name {name!r}", where=where)


def write_run_directory(
    directory: str | Path, files: Mapping[str, bytes | str], *, where: str
) -> Path:
    """Write a whole run (``files``: name -> content) as the directory ``directory``.

    Everything is rendered before this is called.  The run is written into a temporary
    sibling, marked with :data:`RUN_MARKER`, and swapped in with one rename; the previous
    run (a directory that has the marker, or an empty one) is kept until the swap and then
    removed.  See the module docstring for what happens on errors and kills.

    Parameters
    ----------
    directory : the output directory
    files : file name (relative, may contain ``/`` for subdirectories) -> bytes or text
        (UTF-8)
    where : parameter named in errors

    Returns
    -------
    Path
        The absolute output directory.

    Raises
    ------
    InputError
        One line naming ``where``: a bad path (see :func:`check_writable`), or an OS error
        while writing (disk full, permissions).  Nothing is left behind.
    """
    text = str(directory)
    target = _resolve_target(directory, where)
    _check_names(files, where)
    _check_replaceable(target, text, where)
    parent = target.parent
    created: list[Path] = [p for p in (parent, *parent.parents) if not p.exists()]
    tmp: Path | None = None
    with _sigterm_as_exception():
        try:
            parent.mkdir(parents=True, exist_ok=True)
            _remove_stale(target)
            # the name is held before the directory exists: a SIGTERM between the two (an
            # exception at any bytecode) still finds it to remove (mkdtemp's return would not)
            while True:
                tmp = parent / f".{target.name}{_TMP_TAG}{os.getpid()}-{secrets.token_hex(4)}"
                try:
                    os.mkdir(tmp, 0o700)
                    break
                except FileExistsError:
                    continue
            (tmp / f"{RUN_MARKER}.pending").write_bytes(b"")
            for name, content in files.items():
                data = content.encode("utf-8") if isinstance(content, str) else bytes(content)
                dest = tmp / name
                dest.parent.mkdir(parents=True, exist_ok=True)
                with open(dest, "xb") as fh:
                    fh.write(data)
            marker = {"microg_run": 1, "files": sorted(files)}
            (tmp / RUN_MARKER).write_text(json.dumps(marker) + "\n", encoding="utf-8")
            (tmp / f"{RUN_MARKER}.pending").unlink()
            os.chmod(tmp, 0o777 & ~_umask())
            if target.exists():
                _check_replaceable(target, text, where)  # again, just before the swap
                tmp = _swap(tmp, target)  # now holds the previous run (marked or empty)
                _remove_run(tmp)
            else:
                os.rename(tmp, target)
            tmp = None
        except OSError as exc:
            _cleanup(tmp, created)
            raise InputError(
                f"cannot write {exc.filename or target}: {exc.strerror or exc}",
                where=where,
                fix="choose a writable directory with free space",
            ) from None
        except BaseException:
            _cleanup(tmp, created)
            raise
    return target


def _swap(new: Path, target: Path) -> Path:
    """Put directory ``new`` at ``target``; return where the previous ``target`` now is."""
    if _exchange(new, target):
        return new
    aside = Path(tempfile.mkdtemp(prefix=f".{target.name}{_TMP_TAG}{os.getpid()}-old-",
                                  dir=target.parent))  # fmt: skip
    os.rmdir(aside)
    os.rename(target, aside)
    try:
        os.rename(new, target)
    except BaseException:
        os.rename(aside, target)  # put the previous run back
        raise
    return aside


def _remove_run(path: Path) -> None:
    """Delete a run directory, its marker last: a kill midway leaves it marked (removable)."""
    tags = (RUN_MARKER, f"{RUN_MARKER}.pending")
    for root, dirs, names in os.walk(path, topdown=False):
        for name in names:
            if not (root == str(path) and name in tags):
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(os.path.join(root, name))
        for name in dirs:
            full = os.path.join(root, name)
            with contextlib.suppress(FileNotFoundError):
                if os.path.islink(full):
                    os.unlink(full)
                else:
                    os.rmdir(full)
    for tag in tags:
        with contextlib.suppress(FileNotFoundError):
            (path / tag).unlink()
    with contextlib.suppress(OSError):
        path.rmdir()
    if path.exists():  # anything unexpected: plain removal
        shutil.rmtree(path, ignore_errors=True)


def _cleanup(tmp: Path | None, created: list[Path]) -> None:
    if tmp is not None:
        _remove_run(tmp)
    for p in created:  # deepest first
        with contextlib.suppress(OSError):
            p.rmdir()


#: the former name of :func:`write_run_directory` (same signature), kept for the commands
write_output_files = write_run_directory
