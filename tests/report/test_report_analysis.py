"""microg.report.analysis: the garbage collector paused while the figures are drawn.

Reference: Python's own gc.isenabled() before, inside and after the block.
"""

from __future__ import annotations

import gc

import pytest

from microg.report.analysis import _collector_paused


@pytest.mark.parametrize("enabled", [True, False])
def test_collector_is_paused_and_restored(enabled):
    was = gc.isenabled()
    try:
        (gc.enable if enabled else gc.disable)()
        with _collector_paused():
            assert not gc.isenabled()
        assert gc.isenabled() is enabled  # as it was, not simply on
        with pytest.raises(ZeroDivisionError), _collector_paused():
            1 / 0  # noqa: B018  (a failing figure)
        assert gc.isenabled() is enabled
    finally:
        (gc.enable if was else gc.disable)()
