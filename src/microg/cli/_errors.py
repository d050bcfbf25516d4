"""Library errors shown with the command line's words: parameter names become option flags."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from microg.errors import InputError

__all__ = ["flag_errors"]


@contextmanager
def flag_errors(flags: dict[str, str]) -> Iterator[None]:
    """Re-raise library InputErrors with the option's name in place of the parameter's.

    Parameters
    ----------
    flags : dict of str to str
        Library parameter name (``duration``; ``force`` also matches ``force[1]``) -> option
        (``--duration``).
    """
    try:
        yield
    except InputError as exc:
        where = exc.where
        if where:
            head, _, rest = where.partition("[")
            if head in flags:
                where = flags[head] + (f" ({head}[{rest}" if rest else "")
        raise type(exc)(exc.what, where=where, fix=exc.fix) from None
