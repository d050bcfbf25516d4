"""The commands' progress bar: tqdm on a terminal, a silent stand-in otherwise.

tqdm hides its bar when its stream (stderr) is not a terminal (``disable=None``); the same
rule is applied here *before* tqdm is imported, so a run whose bar is never shown (a pipe,
``--json`` into a file, ``--no-progress``, the tests) does not load it.
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = ["NullBar", "progress_bar"]


class NullBar:
    """The part of tqdm's bar the commands use, doing nothing: ``n``, ``update``, ``close``."""

    def __init__(self, total: int | None = None) -> None:
        self.total = total
        self.n = 0

    def update(self, n: int = 1) -> None:
        """Count ``n`` more steps."""
        self.n += n

    def set_postfix_str(self, s: str = "") -> None:
        """Ignore the stage name."""

    def close(self) -> None:
        """Nothing to clear."""


def progress_bar(total: int, desc: str, *, hide: bool, unit: str = "it") -> Any:
    """A transient tqdm bar on stderr, or a :class:`NullBar` when it would not be shown.

    Parameters
    ----------
    total : int
        Number of steps.
    desc : str
        Label before the bar.
    hide : bool
        The user asked for no bar (``--no-progress``).
    unit : str
        Name of one step.
    """
    stream = sys.stderr
    if hide or stream is None or (hasattr(stream, "isatty") and not stream.isatty()):
        return NullBar(total)
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, disable=None, leave=False)
