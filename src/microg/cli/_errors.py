"""Library errors shown with the command line's words: parameter names become option flags."""

from __future__ import annotations

import re
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
                where = flags[head] + (f" ({head}[{rest})" if rest else "")
        raise type(exc)(exc.what, where=where, fix=_fix_flags(exc.fix, flags)) from None


def _fix_flags(fix: str | None, flags: dict[str, str]) -> str | None:
    """A fix written for the API (``restart=True``, ``workers=N``) as the command's options."""
    if not fix:
        return fix
    for param, flag in flags.items():
        fix = re.sub(rf"(?<![\w.-]){re.escape(param)}=True\b", flag, fix)
        fix = re.sub(rf"(?<![\w.-]){re.escape(param)}=(?=\S)", flag + " ", fix)
    return fix
