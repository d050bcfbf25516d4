"""A bounded memo of results kept between calls (the least recently used dropped first).

Thread-safe: every read and write holds the memo's lock.  Keys are hashable fingerprints
of everything a result depends on (arrays by value); values are shared with every caller,
so they must not be modified (arrays are kept read-only where they are made).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import Any, Generic, TypeVar

__all__ = ["Kept", "frozen_array", "frozen_state"]

K = TypeVar("K")
V = TypeVar("V")


class Kept(Generic[K, V]):
    """At most ``size`` results by key, and optionally at most ``max_bytes`` of them.

    Parameters
    ----------
    size : largest number of entries (>= 1)
    max_bytes : largest sum of the entries' weights, bytes (None: no limit); an entry
        heavier than a quarter of it is not kept
    weight : an entry's bytes (needed with ``max_bytes``)
    """

    def __init__(
        self,
        size: int,
        max_bytes: int | None = None,
        weight: Callable[[V], int] | None = None,
    ) -> None:
        self._size = max(1, int(size))
        self._max_bytes = max_bytes
        self._weight = weight or (lambda value: 0)
        self._bytes = 0
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
        """Keep ``value`` under ``key`` (unless it is too heavy to) and return it."""
        w = self._weight(value)
        if self._max_bytes is not None and w > self._max_bytes // 4:
            return value
        with self._lock:
            old = self._items.pop(key, None)
            if old is not None:
                self._bytes -= self._weight(old)
            self._items[key] = value
            self._bytes += w
            while len(self._items) > self._size or (
                self._max_bytes is not None and self._bytes > self._max_bytes
            ):
                self._bytes -= self._weight(self._items.popitem(last=False)[1])
        return value

    def clear(self) -> None:
        """Forget every entry."""
        with self._lock:
            self._items.clear()
            self._bytes = 0

    def __len__(self) -> int:
        with self._lock:
            return len(self._items)


def frozen_array(value: Any) -> Any:
    """A read-only float copy of an array (anything else as it is): a frozen object's own."""
    import numpy as np

    if not isinstance(value, np.ndarray):
        return value
    out = np.array(value, float)
    out.setflags(write=False)
    return out


def frozen_state(state: dict[str, Any]) -> dict[str, Any]:
    """The unpickled state of a frozen object: its arrays read-only, its kept results dropped.

    Pickling keeps neither an array's read-only flag nor a reason to trust results kept on
    the instance (``_``-named entries of its ``__dict__``, formed from those arrays), so a
    frozen dataclass whose methods keep results restores itself through this
    (``__setstate__``).
    """
    return {k: frozen_array(v) for k, v in state.items() if not k.startswith("_")}
