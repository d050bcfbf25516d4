"""A bounded memo of results kept between calls (the least recently used dropped first).

Thread-safe: every read and write holds the memo's lock.  Keys are hashable fingerprints
of everything a result depends on (arrays by value); values are shared with every caller,
so they must not be modified (arrays are kept read-only where they are made).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Any, Generic, TypeVar

__all__ = ["Kept", "frozen_state"]

K = TypeVar("K")
V = TypeVar("V")


class Kept(Generic[K, V]):
    """At most ``size`` results by key.

    Parameters
    ----------
    size : largest number of entries (>= 1)
    """

    def __init__(self, size: int) -> None:
        self._size = max(1, int(size))
        self._items: OrderedDict[K, V] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: K) -> V | None:
        """The value kept under ``key`` (now the most recently used), or None."""
        with self._lock:
            value = self._items.get(key)
            if value is not None:
                self._items.move_to_end(key)
            return value

    def put(self, key: K, value: V) -> V:
        """Keep ``value`` under ``key`` and return it."""
        with self._lock:
            self._items[key] = value
            self._items.move_to_end(key)
            while len(self._items) > self._size:
                self._items.popitem(last=False)
        return value

    def clear(self) -> None:
        """Forget every entry."""
        with self._lock:
            self._items.clear()

    def __len__(self) -> int:
        with self._lock:
            return len(self._items)


def frozen_state(state: dict[str, Any]) -> dict[str, Any]:
    """The unpickled state of a frozen object: its arrays read-only, its kept results dropped.

    Pickling keeps neither an array's read-only flag nor a reason to trust results kept on
    the instance (``_``-named entries of its ``__dict__``, formed from those arrays), so a
    frozen dataclass whose methods keep results restores itself through this
    (``__setstate__``).
    """
    import numpy as np

    out: dict[str, Any] = {}
    for name, value in state.items():
        if name.startswith("_"):
            continue
        if isinstance(value, np.ndarray):
            value = np.array(value)
            value.setflags(write=False)
        out[name] = value
    return out
