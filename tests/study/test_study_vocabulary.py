"""Study files take the commands' words: ``functions`` (assumed modes), ``elements`` (frames)."""

from __future__ import annotations

import pytest

from microg.errors import InputError
from microg.study.plan import loads_study

BASE = """
[study]
model = "ioc"
{extra}
[axes]
observe = ["lab"]
"""


def _disc(extra: str):
    return loads_study(BASE.format(extra=extra)).discretisation


@pytest.mark.parametrize(
    ("extra", "method", "n"),
    [
        ("", "fem", None),
        ("elements = 4", "fem", 4),
        ('method = "ritz"\nplane = "xz"\nfunctions = 2', "ritz", 2),
        ('method = "ritz"\nn = 3', "ritz", 3),  # the old key, still read
        ("n = 5", "fem", 5),
    ],
)
def test_functions_and_elements_keys(extra: str, method: str, n: int | None) -> None:
    d = _disc(extra)
    assert (d.method, d.n) == (method, n)


@pytest.mark.parametrize(
    ("extra", "where"),
    [
        ("functions = 2", "study.functions"),  # fem is the default method
        ('method = "ritz"\nelements = 2', "study.elements"),
        ("elements = 2\nn = 2", "study.n"),
    ],
)
def test_a_count_of_the_other_method_is_refused(extra: str, where: str) -> None:
    with pytest.raises(InputError) as exc:
        _disc(extra)
    assert where in str(exc.value)
