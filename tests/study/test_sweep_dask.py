"""The distributed path: the same bits as the serial one, retried tasks, a worker that dies."""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

from microg.errors import InputError  # noqa: E402
from microg.study import loads_study, sweep  # noqa: E402
from microg.study.kernel import run_blocks  # noqa: E402

TEXT = """
[study]
name = "dask-test"
model = "ioc"
[axes]
force = ["foot-pushoff-max", "hand-pushoff-mean"]
at = ["crew", "vertical-lab"]
direction = ["x", "y", "z"]
observe = ["lab", "keel-tip"]
damping = [0.002, 0.01]
isolator = [{ name = "none" }, { name = "soft", f_n = "0.1 Hz", zeta1 = 0.1 }]
variant = [
  { name = "base" },
  { name = "dock-fwd", move = "main/Orbiter", to = ["0 ft", "0 ft", "-60 ft"] },
]
[record]
duration = "40 s"
dt = "0.1 s"
max_freq = "2 Hz"
"""

#: the task functions below must travel to the workers by value (tests are not a package)
import cloudpickle  # noqa: E402

cloudpickle.register_pickle_by_value(sys.modules[__name__])


def _study():
    return loads_study(TEXT, filename="study.toml")


#: a distributed test that has not finished in this time fails instead of hanging CI (each
#: takes 2-10 s on the 2-core machine)
HANG_S = 180


@pytest.fixture(autouse=True)
def _no_hang():
    def hung(signum, frame):
        raise TimeoutError(f"a distributed test ran past {HANG_S} s (a hang)")

    old = signal.signal(signal.SIGALRM, hung)
    signal.alarm(HANG_S)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


@pytest.fixture(scope="module")
def serial():
    return sweep(_study()).dataset.load()


def _assert_identical(ds, ref) -> None:
    for name in ref.data_vars:
        assert np.array_equal(ds[name].values, ref[name].values, equal_nan=True), name


def test_two_local_workers_give_the_serial_bits(serial, monkeypatch) -> None:
    monkeypatch.setattr("microg.study.run.TASK_CASES", 12)  # several tasks per variant
    r = sweep(_study(), workers=2)
    _assert_identical(r.dataset.load(), serial)
    assert r.computed_blocks == len(list(r.study.blocks()))


@pytest.fixture
def cluster():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
        silence_logs=50,
    ) as c:  # fmt: skip
        yield c


def _fail_once(marker: str):
    def task(basis, plan, works, threads):
        path = Path(marker) / f"{works[0].id}"
        if not path.exists():
            path.write_text("failed once")
            raise RuntimeError("transient failure")
        return run_blocks(basis, plan, works, threads)

    return task


def test_a_task_that_fails_is_retried(serial, cluster, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr("microg.study.run.TASK_CASES", 12)
    r = sweep(_study(), scheduler=cluster.scheduler_address, _task_fn=_fail_once(str(tmp_path)))
    _assert_identical(r.dataset.load(), serial)
    assert len(list(tmp_path.iterdir())) > 1  # every task failed once and was rerun


def _die_once(marker: str):
    def task(basis, plan, works, threads):
        path = Path(marker) / "died"
        if not path.exists():
            path.write_text(str(os.getpid()))
            os.kill(os.getpid(), signal.SIGKILL)  # the worker process dies mid-task
        return run_blocks(basis, plan, works, threads)

    return task


def test_a_worker_that_dies_loses_only_its_batch(serial, cluster, tmp_path, monkeypatch) -> None:
    monkeypatch.setattr("microg.study.run.TASK_CASES", 12)
    r = sweep(_study(), scheduler=cluster.scheduler_address, _task_fn=_die_once(str(tmp_path)))
    assert (tmp_path / "died").exists()  # a worker was killed during the sweep
    _assert_identical(r.dataset.load(), serial)


def _die_holding_a_basis(marker: str):
    """A task that kills its worker once, with the variant's basis in its memory."""

    def task(basis, plan, works, threads):
        from distributed import get_worker

        path = Path(marker) / "died"
        held = [k for k in get_worker().data if str(k).startswith("solve_basis-")]
        if held and not path.exists():
            path.write_text(str(held))
            os.kill(os.getpid(), signal.SIGKILL)
        return run_blocks(basis, plan, works, threads)

    return task


def test_a_worker_that_dies_with_a_basis_loses_nothing(serial, cluster, tmp_path, monkeypatch):
    # the basis is a task's result: recomputed by the scheduler, or (its scattered model
    # already released) solved again by the sweep before its blocks are resubmitted
    monkeypatch.setattr("microg.study.run.TASK_CASES", 12)
    r = sweep(
        _study(), scheduler=cluster.scheduler_address, _task_fn=_die_holding_a_basis(str(tmp_path))
    )
    assert (tmp_path / "died").exists()  # a worker holding a basis was killed
    _assert_identical(r.dataset.load(), serial)


def _always_die(marker: str):
    """A task that kills its worker every time (a crash in native code, say)."""

    def task(basis, plan, works, threads):
        with open(Path(marker) / "deaths", "a") as fh:
            fh.write("x")
        os.kill(os.getpid(), signal.SIGKILL)

    return task


def test_a_block_that_kills_every_worker_stops_the_sweep(cluster, tmp_path, monkeypatch):
    # each death loses the basis with the worker (its scattered model is released once it is
    # solved): the variant is solved again and the block resubmitted, counted to RESUBMIT, so
    # the sweep stops with the failure instead of solving and dying without end
    from microg.study.run import SweepIncompleteError

    monkeypatch.setattr("microg.study.run.TASK_CASES", 10**6)  # one task
    with pytest.raises(SweepIncompleteError):
        sweep(_study(), scheduler=cluster.scheduler_address, _task_fn=_always_die(str(tmp_path)))
    assert 1 <= len((tmp_path / "deaths").read_text()) <= 30


def test_a_resumed_sweep_on_dask_solves_only_the_variants_left(serial, cluster, tmp_path):
    # the variants' solves start before the store is made; on a resume a variant whose blocks
    # are all written has its solve cancelled, and the others' blocks are computed once
    import zarr

    out = tmp_path / "out"
    addr = cluster.scheduler_address
    study = _study()
    sweep(study, out, scheduler=addr)
    # the "dock-fwd" variant's blocks marked not written, as a sweep stopped part-way leaves
    left = [b.id for b in study.blocks() if study.variants[b.index[1]].label == "dock-fwd"]
    grp = zarr.open_group(
        str(out / "results.zarr"), mode="r+", zarr_format=2, use_consolidated=False
    )
    done = grp["sweep/done"]
    done[left] = False
    watcher = distributed.Client(addr, set_as_default=False)
    try:
        r = sweep(_study(), out, scheduler=addr)
        assert r.computed_blocks == len(left) and r.resumed_blocks > 0
        _assert_identical(r.dataset.load(), serial)
        r3 = sweep(_study(), out, scheduler=addr)  # every block written: nothing is computed
        assert r3.computed_blocks == 0
        _assert_identical(r3.dataset.load(), serial)
        # nothing of the sweeps is left on the cluster (every future released or cancelled)
        names = ("solve_basis", "_identity", "run_blocks", "Station")
        held = [k for keys in watcher.has_what().values() for k in keys]
        assert not [k for k in held if str(k).startswith(names)], held
    finally:
        watcher.close()


def test_a_scheduler_that_does_not_answer_is_one_line() -> None:
    with pytest.raises(InputError) as info:
        sweep(_study(), scheduler="tcp://127.0.0.1:9", timeout_s=1.0)
    assert info.value.where == "scheduler"
    assert "no Dask scheduler answered" in str(info.value) and "\n" not in str(info.value)


def test_workers_and_scheduler_are_exclusive() -> None:
    with pytest.raises(InputError) as info:
        sweep(_study(), workers=2, scheduler="tcp://127.0.0.1:9")
    assert info.value.where == "workers"
