"""The station models shipped with microg (``microg/data/NAME.toml``).

A shipped model is a file ``microg/data/NAME.toml`` whose name does not start with ``_`` and
which has a ``[station]`` table (other TOML data files live there too).
"""

from __future__ import annotations

import re
from importlib import resources

__all__ = ["shipped_models", "shipped_model_text"]

_DATA_PACKAGE = "microg"
_DATA_DIR = "data"
_STATION_TABLE = re.compile(r"^[ \t]*\[[ \t]*station[ \t]*\][ \t]*(#.*)?$", re.MULTILINE)


def shipped_models() -> list[str]:
    """Names of the station models shipped in ``microg/data``, sorted."""
    root = resources.files(_DATA_PACKAGE).joinpath(_DATA_DIR)
    if not root.is_dir():
        return []
    names = []
    for entry in root.iterdir():
        if entry.is_file() and entry.name.endswith(".toml") and not entry.name.startswith("_"):
            try:
                text = entry.read_text(encoding="utf-8")
            except (OSError, UnicodeDecodeError):
                continue
            if _STATION_TABLE.search(text):
                names.append(entry.name[: -len(".toml")])
    return sorted(names)


def shipped_model_text(name: str) -> tuple[str, str, str] | None:
    """``(text, file name, source)`` of the shipped model ``name``, or None if there is none.

    Parameters
    ----------
    name : a name of :func:`shipped_models`, e.g. ``"ioc"``
    """
    if name not in shipped_models():
        return None
    fname = f"{name}.toml"
    res = resources.files(_DATA_PACKAGE).joinpath(_DATA_DIR).joinpath(fname)
    return res.read_text(encoding="utf-8"), fname, f"microg/data/{fname}"
