"""Library calls never change the process's BLAS threads; the CLI sets them only at its start.

References: threadpoolctl's own report of every loaded BLAS library's thread count
(``threadpool_info``) before and after the calls; threadpoolctl's own entry points (every
``set_num_threads`` of its library controllers, ``threadpool_limits``,
``ThreadpoolController.limit``) replaced by recorders, which must record nothing; for the CLI,
the BLAS library's own report in a fresh ``microg`` process.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
import threadpoolctl

from microg.cli import BLAS_ENV


def _threads() -> list[tuple[str, int]]:
    return sorted((i["filepath"], i["num_threads"]) for i in threadpoolctl.threadpool_info())


@pytest.fixture
def no_thread_changes(monkeypatch):
    """Every way threadpoolctl changes a thread count, replaced by a recorder."""
    import scipy.linalg  # noqa: F401  (its own BLAS, loaded before the first report)

    calls: list[str] = []

    def recorder(name: str):
        def record(*args, **kwargs):
            calls.append(name)
            raise AssertionError(f"library code called threadpoolctl's {name}")

        return record

    monkeypatch.setattr(threadpoolctl, "threadpool_limits", recorder("threadpool_limits"))
    monkeypatch.setattr(threadpoolctl.ThreadpoolController, "limit", recorder("limit"))
    controllers = [threadpoolctl.LibController, *threadpoolctl.LibController.__subclasses__()]
    for cls in controllers:
        if "set_num_threads" in vars(cls):
            monkeypatch.setattr(cls, "set_num_threads", recorder(f"{cls.__name__}.set_num_threads"))
    before = _threads()
    assert before  # a BLAS is loaded: the report is not vacuous
    yield calls
    assert calls == []
    assert _threads() == before


def test_solve_modes_and_analyze_leave_the_blas_threads_alone(no_thread_changes):
    import microg

    for method in ("fem", "ritz"):  # a sparse and a dense eigensolve
        modes = microg.solve_modes("ioc", method=method)
        assert modes.n_rigid == 6
    result = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02)
    assert result.observations["lab"].peak_accel_g > 0
    # the frequency domain's band integration runs its bands in threads
    vib = microg.analyze("ioc", sources="example", observe=["lab"])
    assert vib.frequency_domain is not None


def test_the_recorders_catch_a_thread_limit(no_thread_changes):
    # the fixture's recorders are live: threadpoolctl's own limit is caught (then cleared,
    # so the fixture's final check passes)
    with pytest.raises(AssertionError, match="threadpool_limits"):
        threadpoolctl.threadpool_limits(limits=1)
    assert no_thread_changes == ["threadpool_limits"]
    no_thread_changes.clear()


def _cli_threads(**env: str) -> list[int]:
    """BLAS thread counts inside a fresh process started as ``microg`` starts."""
    code = (
        "import json, sys\n"
        "import microg.cli\n"
        "microg.cli.one_blas_thread()\n"
        "import numpy, scipy.linalg, threadpoolctl\n"
        "print(json.dumps([i['num_threads'] for i in threadpoolctl.threadpool_info()]))\n"
    )
    base = {k: v for k, v in os.environ.items() if k not in BLAS_ENV}
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={**base, **env},
        check=True,
        timeout=300,
    )
    return json.loads(out.stdout)


def test_the_cli_starts_blas_on_one_thread_unless_the_user_chose():
    assert set(_cli_threads()) == {1}
    assert set(_cli_threads(OPENBLAS_NUM_THREADS="2")) == {2}  # the user's setting wins
    assert set(_cli_threads(OMP_NUM_THREADS="2")) == {2}


def test_the_cli_sets_nothing_once_numpy_is_loaded(monkeypatch):
    # numpy is loaded in this test process: its BLAS read its variables already
    import numpy  # noqa: F401

    for name in BLAS_ENV:
        monkeypatch.delenv(name, raising=False)
    from microg.cli import one_blas_thread

    assert one_blas_thread() is False
    assert not any(os.environ.get(v) for v in BLAS_ENV)
