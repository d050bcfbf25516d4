"""The provenance record of a run: microg's version, the time, the command, the model's hash.

The model file is hashed (SHA-256) in a background thread beside the computation
(:class:`Provenance`).
"""

from __future__ import annotations

import datetime as _dt
import hashlib
from pathlib import Path
from typing import Any

__all__ = ["Provenance", "provenance_record", "sha256_file"]


class Provenance:
    """The provenance record of a run, its model file hashed in a background thread.

    A modal model's file can be hundreds of MB (193 MB for 20,000 grids x 200
    modes), a quarter of a second of SHA-256; hashlib and file reads release the GIL, so the
    hash runs beside the computation instead of after it.  :meth:`result` joins the thread
    and re-raises anything it raised.
    """

    def __init__(self, model: Any, command: str | None):
        import threading

        self._out: dict[str, Any] = {}
        self._error: BaseException | None = None

        def work() -> None:
            try:
                self._out = provenance_record(model, command)
            except BaseException as exc:  # re-raised in the caller's thread by result()
                self._error = exc

        self._thread = threading.Thread(target=work, name="microg-provenance", daemon=True)
        self._thread.start()

    def result(self) -> dict[str, Any]:
        """The record (:func:`provenance_record`), once the hash is done."""
        self._thread.join()
        if self._error is not None:
            raise self._error
        return self._out


def sha256_file(path: Path) -> str:
    """SHA-256 of a file (``hashlib.file_digest``: read into one reused buffer)."""
    with path.open("rb") as fh:
        return hashlib.file_digest(fh, "sha256").hexdigest()


def provenance_record(model: Any, command: str | None) -> dict[str, Any]:
    """The record of a run: version, UTC time, command, the model's path and SHA-256.

    A frame (graph) model adds its mass formulation and what chose it (a NASTRAN deck's
    ``PARAM,COUPMASS``, the reader's ``coupled_mass``).

    Parameters
    ----------
    model : a model object; its ``source`` (a file path or a shipped name) is hashed
    command : the command line, or None
    """
    from microg import __version__

    src = getattr(model, "source", "") or ""
    sha = None
    path = None
    if src:
        p = Path(src)
        if p.is_file():
            path = str(p.resolve())
            sha = sha256_file(p)
        else:
            path = src
            try:
                from importlib import resources

                name = Path(src).name
                data = resources.files("microg").joinpath("data").joinpath(name).read_bytes()
                sha = hashlib.sha256(data).hexdigest()
            except (OSError, ValueError):  # FileNotFoundError is an OSError
                sha = None
    out = {
        "microg_version": __version__,
        "created_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "command": command,
        "model_path": path,
        "model_sha256": sha,
    }
    form = getattr(model, "mass_formulation", None)
    if isinstance(form, str):  # a frame (graph) model: its elements' mass and what chose it
        meta = getattr(model, "meta", None) or {}
        out["mass_formulation"] = form
        out["mass_formulation_note"] = meta.get("mass_formulation_note", form)
    return out
