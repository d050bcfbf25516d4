"""Test configuration: BLAS threads as the command starts them, reproducible property tests."""

from __future__ import annotations

import os

from hypothesis import settings

from microg.cli import BLAS_ENV


def _one_blas_thread() -> None:
    """BLAS on one thread for the suite, as ``microg`` starts it, unless the user set a count.

    ``OPENBLAS_NUM_THREADS=2 pytest`` runs the suite on two.  The variables reach the
    processes the tests start; this process has loaded numpy already (a pytest plugin imports
    it), so its BLAS libraries are set by threadpoolctl, here, by the test harness (microg's
    library code never changes them: tests/test_blas_threads.py).
    """
    if any(os.environ.get(v) for v in BLAS_ENV):
        return
    for name in BLAS_ENV[1:]:
        os.environ[name] = "1"
    import scipy.linalg  # noqa: F401  (scipy's own BLAS, loaded now so that the limit reaches it)
    from threadpoolctl import threadpool_limits

    threadpool_limits(1, user_api="blas")


_one_blas_thread()

# CI (CI=true) replays the same examples every run, so a red build is reproducible; locally
# hypothesis explores new examples each run.
settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
settings.load_profile("ci" if os.environ.get("CI") else "dev")
