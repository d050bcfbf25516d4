"""Tests of microg.cli._errors: library errors shown with the command line's words."""

from __future__ import annotations

import pytest

from microg.cli._errors import flag_errors
from microg.errors import InputError


def test_parameter_names_become_flags_in_where_and_fix():
    # reference: the same message written by hand for the command line
    flags = {"restart": "--restart", "workers": "--workers", "units": "--units"}
    with pytest.raises(InputError) as err, flag_errors(flags):
        raise InputError(
            "out holds another study",
            where="workers",
            fix='restart=True to discard them, workers=N, or units="in, lbf, s"; '
            "my_restart=True and x.units=1 stay",
        )
    assert err.value.where == "--workers"
    assert err.value.fix == (
        '--restart to discard them, --workers N, or --units "in, lbf, s"; '
        "my_restart=True and x.units=1 stay"
    )


def test_indexed_parameters_keep_their_index():
    with pytest.raises(InputError) as err, flag_errors({"force": "--force"}):
        raise InputError("bad", where="force[1]")
    assert err.value.where == "--force (force[1])" and err.value.fix is None
