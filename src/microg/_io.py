"""Output helpers: atomic file and directory writes, JSON encoding of results."""

from __future__ import annotations

import dataclasses
import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "atomic_write_bytes",
    "atomic_write_text",
    "write_output_files",
    "to_jsonable",
    "dumps",
]


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


def write_output_files(directory: str | Path, files: dict[str, bytes | str], *, where: str) -> Path:
    """Write every file of ``files`` into ``directory``, each atomically.

    Everything is rendered before this is called, so an error in the computation leaves
    nothing behind.  Other files already in ``directory`` are left alone (only the named
    files are replaced); a file that cannot be written is an :class:`InputError` naming
    ``where`` (the CLI option), and the files this call already wrote are removed.
    """
    from microg.errors import InputError

    directory = Path(directory)
    created = not directory.exists()
    written: list[Path] = []
    try:
        if directory.exists() and not directory.is_dir():
            raise InputError(f"{str(directory)!r} exists and is not a directory", where=where)
        directory.mkdir(parents=True, exist_ok=True)
        for name, content in files.items():
            target = directory / name
            existed = target.exists()
            data = content.encode("utf-8") if isinstance(content, str) else content
            atomic_write_bytes(target, data)
            if not existed:
                written.append(target)
    except OSError as exc:
        for p in written:
            p.unlink(missing_ok=True)
        if created and directory.exists() and not any(directory.iterdir()):
            directory.rmdir()
        raise InputError(
            f"cannot write {exc.filename or directory}: {exc.strerror or exc}",
            where=where,
            fix="choose a writable directory",
        ) from None
    return directory.resolve()
