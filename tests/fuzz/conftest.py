"""The fuzzers' outcome counts, printed at the end of the run (and in CI's log)."""

from __future__ import annotations

from typing import Any


def pytest_terminal_summary(terminalreporter: Any) -> None:
    from test_fuzz_support import CATEGORIES, COUNTS

    if not COUNTS:
        return
    tr = terminalreporter
    tr.section("fuzz outcome counts")
    total = {c: 0 for c in CATEGORIES}
    for group in sorted(COUNTS):
        counts = COUNTS[group]
        tr.write_line(f"{group:<24} " + ", ".join(f"{c} {counts.get(c, 0)}" for c in CATEGORIES))
        for c in CATEGORIES:
            total[c] += counts.get(c, 0)
    tr.write_line(f"{'all':<24} " + ", ".join(f"{c} {total[c]}" for c in CATEGORIES))
    tr.write_line(f"{'cases':<24} {sum(total.values())}")
