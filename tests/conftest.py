"""Test configuration: reproducible property tests in CI."""

from __future__ import annotations

import os

from hypothesis import settings

# CI (CI=true) replays the same examples every run, so a red build is reproducible; locally
# hypothesis explores new examples each run.
settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
settings.load_profile("ci" if os.environ.get("CI") else "dev")
