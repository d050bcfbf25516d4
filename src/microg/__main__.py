"""``python -m microg``."""

from microg.cli import _entry

_entry()
