"""Output helpers: run directories written atomically as a whole, single files, JSON of results.

A command's output (report, figures, JSON) is a **run directory**, written all at once by
:func:`write_run_directory`:

* the whole run is written into a hidden temporary sibling directory, then swapped in with one
  rename (Linux ``renameat2(RENAME_EXCHANGE)``; elsewhere two renames), so the target always
  holds one complete run, the previous one until the swap and the new one after it;
* a run directory carries a marker file :data:`RUN_MARKER`, the manifest of the files the run
  wrote with their SHA-256.  A directory is replaced only when it is empty or holds exactly
  the files of its manifest, unchanged; anything else (a file added or edited, a marker that
  is not microg's manifest) is refused, naming what is there;
* the previous run is then deleted file by file from its manifest (a file changed since is
  kept), so a run never deletes a file it did not write;
* on any error (disk full, permissions) or on SIGINT/SIGTERM, the temporary directory is
  removed and the previous run is left as it was.  A SIGKILL can leave only a hidden
  temporary sibling (``.NAME.microg-tmp-PID-TOKEN``) and its lock file, which the next run
  into the same place removes once the lock shows that their run is over;
* a symbolic link as the output is followed only to an existing directory.

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


#: version of the marker's manifest (file name -> SHA-256 of its bytes)
_MANIFEST_VERSION = 2


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _manifest(path: Path) -> dict[str, str] | None:
    """The files a microg run wrote in ``path`` (name -> SHA-256), or None if not a run."""
    try:
        data = json.loads((path / RUN_MARKER).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("microg_run") != _MANIFEST_VERSION:
        return None
    files = data.get("files")
    if not isinstance(files, dict):
        return None
    if not all(isinstance(k, str) and isinstance(v, str) for k, v in files.items()):
        return None
    return files


def _entries(path: Path) -> tuple[set[str], set[str]]:
    """(files, other entries) below ``path``, relative POSIX names; links are never followed.

    A directory counts as an entry of its own only when it is empty; symbolic links and
    special files are "other" entries.
    """
    files: set[str] = set()
    other: set[str] = set()
    for root, dirs, names in os.walk(path, followlinks=False):
        rel = Path(root).relative_to(path)
        for name in dirs:
            full = Path(root) / name
            if full.is_symlink():
                other.add((rel / name).as_posix())
            elif _is_empty_dir(full):
                other.add((rel / name).as_posix() + "/")
        for name in names:
            full = Path(root) / name
            key = (rel / name).as_posix()
            if full.is_symlink() or not full.is_file():
                other.add(key)
            elif key != RUN_MARKER:
                files.add(key)
    return files, other


def _foreign(path: Path) -> list[str] | None:
    """What in ``path`` microg did not write there (sorted), or None if it is not a run.

    A run directory holds exactly the files its marker lists, each with the SHA-256 the
    marker records; anything else (a file added, a file changed, a link, an empty directory)
    is foreign.
    """
    manifest = _manifest(path)
    if manifest is None:
        return None
    files, other = _entries(path)
    changed = sorted(n for n in files & set(manifest) if _sha256(path / n) != manifest[n])
    return sorted(files - set(manifest)) + changed + sorted(other)


def _is_empty_dir(path: Path) -> bool:
    with os.scandir(path) as it:
        return next(it, None) is None


def _resolve_target(path: str | Path | None, where: str) -> Path:
    """The absolute output directory, checked: not empty text, not cwd, not a dangling link."""
    if path is None or not str(path).strip():
        raise InputError(
            "is empty", where=where, fix="name an output directory, e.g. 'microg-results'"
        )
    text = str(path)
    if "\x00" in text:
        raise InputError("holds a NUL character", where=where, fix="name a plain directory")
    target = Path(os.path.abspath(text))
    try:
        if target.is_symlink():
            dest = target.resolve()
            if not dest.is_dir():
                raise InputError(
                    f"{text!r} is a symbolic link to {str(dest)!r}, which is not an existing "
                    "directory; microg follows a link only to an existing directory",
                    where=where,
                    fix="create the directory it points to, or name another output directory",
                )
            target = dest
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


def _listed(names: list[str], limit: int = 3) -> str:
    shown = ", ".join(repr(n) for n in names[:limit])
    return shown + (f" and {len(names) - limit} more" if len(names) > limit else "")


def _check_replaceable(target: Path, text: str, where: str, *, resumable: bool = False) -> None:
    """Refuse a target that holds anything an earlier microg run did not write there."""
    try:
        if target.exists() and not target.is_dir():
            raise InputError(
                f"{text!r} exists and is not a directory", where=where, fix="name a directory"
            )
        if not target.is_dir() or _is_empty_dir(target):
            return
        if resumable and _is_sweep(target):
            return
        foreign = _foreign(target)
        if foreign is None:
            raise InputError(
                f"{text!r} is a non-empty directory that microg did not write (it has no "
                f"{RUN_MARKER} manifest of microg's files); microg replaces its output "
                "directory as a whole",
                where=where,
                fix="choose a new or empty directory, or one that microg wrote",
            )
        if foreign:
            raise InputError(
                f"{text!r} holds what the earlier microg run there did not write: "
                f"{_listed(foreign)}; microg replaces a run directory only when it holds "
                "exactly that run's files",
                where=where,
                fix="move those out, or choose another directory",
            )
    except OSError as exc:
        raise InputError(f"cannot use {text!r}: {exc.strerror or exc}", where=where) from None


def _is_sweep(path: Path) -> bool:
    """A sweep's output directory (resumed in place, never replaced whole)."""
    try:
        data = json.loads((path / RUN_MARKER).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return False
    return isinstance(data, dict) and data.get("command") == "sweep"


def _existing_ancestor(path: Path) -> Path:
    for p in (path, *path.parents):
        if p.exists():
            return p
    return Path(path.anchor)


def check_writable(
    path: str | Path | None, where: str, *, directory: bool = True, resumable: bool = False
) -> Path:
    """Check, before computing anything, that output can be written to ``path``.

    Parameters
    ----------
    path : the output directory (``directory=True``) or file
    where : parameter named in the error
    directory : True for a run directory (:func:`write_run_directory`), False for one file
    resumable : a sweep's directory, resumed in place: one that a sweep marked is accepted too

    Returns
    -------
    Path
        The absolute path that will be written (a symbolic link to an existing directory
        resolved).

    Raises
    ------
    InputError
        The path is empty, is the current directory, is a symbolic link to anything but an
        existing directory, is a file where a directory is needed (or the reverse), holds
        anything that an earlier microg run did not write there, or its parent cannot be
        written (probed by creating and removing a temporary entry).
    """
    text = "" if path is None else str(path)
    if directory:
        target = _resolve_target(path, where)
        _check_replaceable(target, text, where, resumable=resumable)
    else:
        if not text.strip() or "\x00" in text:
            raise InputError("is empty or holds a NUL", where=where, fix="name an output file")
        target = Path(os.path.abspath(text))
        if target.is_dir():
            raise InputError(f"{text!r} is a directory", where=where, fix="name a file")
        if target.is_symlink() and not target.exists():
            raise InputError(
                f"{text!r} is a symbolic link to nothing", where=where, fix="name a plain file"
            )
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


# ------------------------------------------------------------ who is writing (lock files)
#
# A run holds an exclusive lock on its own lock file (``.NAME.microg-tmp-PID-TOKEN.lock``, an
# empty sibling of its temporary directories) from before it creates them until after it has
# removed them.  The operating system drops the lock when the process dies, however it dies,
# so a temporary entry whose lock file exists and can be locked belongs to a run that is
# over.  An entry without its lock file is not microg's and is left alone.  No process is
# signalled or looked up by number.


def _try_lock(fd: int) -> bool:
    """Take an exclusive lock on an open file without waiting; False if another holds it."""
    try:
        if sys.platform == "win32":  # pragma: no cover - Windows
            import msvcrt

            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        else:
            import fcntl

            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


class _Lock:
    """The lock file of one run into ``target``, held while the run writes."""

    def __init__(self, target: Path, holder: list[_Lock]) -> None:
        token = f"{os.getpid()}-{secrets.token_hex(4)}"
        self.stem = f".{target.name}{_TMP_TAG}{token}"
        self.path = target.parent / f"{self.stem}.lock"
        self.fd = -1
        self.ours = True  # the name is this run's (random token) unless creating it failed
        # in the caller's hands before the file exists: a SIGTERM raised at any bytecode from
        # here on still finds the lock file to remove (an assignment after return would not)
        holder.append(self)
        try:
            self.fd = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_RDWR, 0o600)
        except FileExistsError:  # pragma: no cover - another run drew the same token
            self.ours = False
            raise
        if not _try_lock(self.fd):  # pragma: no cover - a file only this process created
            raise OSError(errno.EAGAIN, "cannot lock", str(self.path))

    def release(self) -> None:
        """Drop the lock and remove its file (again: nothing)."""
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1
        if self.ours:
            self.ours = False
            with contextlib.suppress(OSError):
                self.path.unlink()


def _writer_gone(lock: Path) -> bool:
    """Whether ``lock`` is the lock file of a run that is over (an empty file, lock free)."""
    try:
        if lock.is_symlink() or not lock.is_file() or lock.stat().st_size:
            return False
        fd = os.open(lock, os.O_RDWR)
    except OSError:
        return False
    try:
        return _try_lock(fd)
    finally:
        os.close(fd)


def _remove_stale(target: Path) -> None:
    """Remove the temporary siblings (and lock files) of runs into ``target`` that are over.

    Only entries named as microg names its temporaries are touched: a temporary directory
    is entirely microg's (it was created empty by the run and filled by it).
    """
    prefix = f".{target.name}{_TMP_TAG}"
    try:
        entries = [e for e in os.scandir(target.parent) if e.name.startswith(prefix)]
    except OSError:
        return
    for entry in entries:
        if entry.name.endswith(".lock") or not entry.is_dir(follow_symlinks=False):
            continue
        token = "-".join(entry.name[len(prefix) :].split("-")[:2])
        lock = target.parent / f"{prefix}{token}.lock"
        if _writer_gone(lock):
            path = Path(entry.path)
            if (path / RUN_MARKER).exists():  # a complete run, new or previous: its files
                _remove_previous(path, target)
            else:  # filled by the run before its marker: entirely microg's
                shutil.rmtree(path, ignore_errors=True)
    for entry in entries:
        if entry.name.endswith(".lock") and entry.is_file(follow_symlinks=False):
            path = Path(entry.path)
            if _writer_gone(path):
                with contextlib.suppress(OSError):
                    path.unlink()


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
    previous: Path | None = None
    lock: _Lock | None = None
    held: list[_Lock] = []
    with _sigterm_as_exception():
        try:
            parent.mkdir(parents=True, exist_ok=True)
            _remove_stale(target)
            _Lock(target, held)
            lock = held[0]
            # the name is held before the directory exists: a SIGTERM between the two (an
            # exception at any bytecode) still finds it to remove (mkdtemp's return would not)
            tmp = parent / lock.stem
            os.mkdir(tmp, 0o700)
            manifest: dict[str, str] = {}
            for name, content in files.items():
                data = content.encode("utf-8") if isinstance(content, str) else bytes(content)
                dest = tmp / name
                dest.parent.mkdir(parents=True, exist_ok=True)
                with open(dest, "xb") as fh:
                    fh.write(data)
                manifest[Path(name).as_posix()] = hashlib.sha256(data).hexdigest()
            marker = {"microg_run": _MANIFEST_VERSION, "files": dict(sorted(manifest.items()))}
            # the marker appears whole or not at all (a kill while writing it leaves a part
            # file, and the temporary is then entirely microg's for the next run to remove)
            part = tmp / f"{RUN_MARKER}.part"
            part.write_text(json.dumps(marker, indent=1) + "\n", encoding="utf-8")
            os.rename(part, tmp / RUN_MARKER)
            os.chmod(tmp, 0o777 & ~_umask())
            if target.exists():
                _check_replaceable(target, text, where)  # again, just before the swap
                previous = _swap(tmp, target, lock.stem)
                tmp = None  # the new run is in place; what is at `previous` was the old one
                _remove_previous(previous, target)
                previous = None
            else:
                os.rename(tmp, target)
                tmp = None
        except OSError as exc:
            _cleanup(tmp, previous, target, created, lock)
            raise InputError(
                f"cannot write {exc.filename or target}: {exc.strerror or exc}",
                where=where,
                fix="choose a writable directory with free space",
            ) from None
        except BaseException:
            _cleanup(tmp, previous, target, created, lock)
            raise
        finally:
            for each in held:
                each.release()
    return target


def _swap(new: Path, target: Path, stem: str) -> Path:
    """Put directory ``new`` at ``target``; return where the previous ``target`` now is."""
    if _exchange(new, target):
        return new
    aside = target.parent / f"{stem}-old"
    os.rename(target, aside)
    try:
        os.rename(new, target)
    except BaseException:
        os.rename(aside, target)  # put the previous run back
        raise
    return aside


def _remove_previous(path: Path, target: Path) -> None:
    """Delete the previous run, now at ``path``: only the files its manifest lists.

    Each listed file is removed only if it still has the recorded SHA-256, then the
    directories left empty, the marker last.  Anything else (a file a user put there after
    the check, a moment ago) is kept: the directory is then renamed to a visible sibling of
    the target, ``NAME.microg-kept-TOKEN``, with it inside.
    """
    manifest = _manifest(path) or {}
    for name, digest in manifest.items():
        file = path / name
        with contextlib.suppress(OSError):
            if not file.is_symlink() and file.is_file() and _sha256(file) == digest:
                file.unlink()
    for root, dirs, _names in os.walk(path, topdown=False):
        for name in dirs:
            with contextlib.suppress(OSError):
                os.rmdir(os.path.join(root, name))  # only if empty
    files, other = _entries(path)
    if not files and not other:
        with contextlib.suppress(OSError):
            (path / RUN_MARKER).unlink()
        with contextlib.suppress(OSError):
            path.rmdir()
        return
    with contextlib.suppress(OSError):
        os.rename(path, target.parent / f"{target.name}.microg-kept-{secrets.token_hex(4)}")


def _cleanup(
    tmp: Path | None, previous: Path | None, target: Path, created: list[Path], lock: _Lock | None
) -> None:
    """After an error or a signal: the run's temporaries gone, the previous run's files too."""
    if tmp is not None:
        shutil.rmtree(tmp, ignore_errors=True)  # a temporary directory is entirely the run's
    if previous is not None:  # interrupted while removing the replaced run
        _remove_previous(previous, target)
    if lock is not None:
        lock.release()
    for p in created:  # deepest first
        with contextlib.suppress(OSError):
            p.rmdir()


#: the former name of :func:`write_run_directory` (same signature), kept for the commands
write_output_files = write_run_directory
