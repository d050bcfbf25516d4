"""Exception hierarchy of microg.

::

    MicrogError
     +-- InputError        bad user input: one line, exit status 2 at the CLI
     +-- ModelError        (InputError) a model file that is wrong, names file and field
     +-- SolverError       a numerical failure that is not the user's fault
"""

from __future__ import annotations

__all__ = ["InputError", "MicrogError", "ModelError", "SolverError"]


class MicrogError(Exception):
    """Base class of every error microg raises on purpose."""


class InputError(MicrogError, ValueError):
    """Bad input: the message says what is wrong, where, and how to fix it (one line)."""

    def __init__(self, message: str, *, where: str | None = None, fix: str | None = None):
        self.what = message
        self.where = where
        self.fix = fix
        text = f"{where}: {message}" if where else message
        if fix:
            text = f"{text} ({fix})"
        super().__init__(text)


class ModelError(InputError):
    """An invalid station model; ``where`` is ``file: field.path``."""


class SolverError(MicrogError, RuntimeError):
    """A numerical procedure failed on input that passed validation."""
