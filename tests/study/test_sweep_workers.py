"""The local workers' malloc settings (run.worker_environ) and one modal group per process."""

from __future__ import annotations

from microg.study import loads_study, sweep
from microg.study.run import WORKER_ENVIRON, worker_environ

DISTRIBUTED_DEFAULT = {"MALLOC_TRIM_THRESHOLD_": 65536, "OMP_NUM_THREADS": 1}


def test_distributed_trim_default_is_replaced_and_its_other_settings_kept(monkeypatch) -> None:
    for k in WORKER_ENVIRON:
        monkeypatch.delenv(k, raising=False)
    env = worker_environ(DISTRIBUTED_DEFAULT)
    assert env["MALLOC_TRIM_THRESHOLD_"] == str(1 << 30)
    assert env["MALLOC_MMAP_THRESHOLD_"] == str(1 << 25)  # glibc's largest on 64 bits
    assert env["OMP_NUM_THREADS"] == "1"


def test_a_users_own_setting_is_kept(monkeypatch) -> None:
    monkeypatch.delenv("MALLOC_MMAP_THRESHOLD_", raising=False)
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "123456")  # the nanny reads this first
    assert worker_environ(DISTRIBUTED_DEFAULT)["MALLOC_TRIM_THRESHOLD_"] == "123456"
    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_")
    mine = {**DISTRIBUTED_DEFAULT, "MALLOC_MMAP_THRESHOLD_": 1 << 20}
    assert worker_environ(mine)["MALLOC_MMAP_THRESHOLD_"] == str(1 << 20)


STUDY = """
[study]
model = "ioc"
[axes]
force = ["foot-pushoff-max"]
at = ["crew", "vertical-lab", "keel-mid", "a", "b", "c", "d", "e"]
direction = ["x", "z"]
observe = ["lab", "keel-tip"]
damping = [0.002, 0.01]
[record]
duration = "20 s"
dt = "0.1 s"
max_freq = "2 Hz"
""" + "".join(
    f'[[point]]\nname = "{n}"\non = "keel"\ns = "{s} ft"\n'
    for n, s in (("keel-mid", 148), ("a", 20), ("b", 60), ("c", 100), ("d", 200), ("e", 260))
)


def test_each_modal_group_is_computed_once_whatever_the_tasks(monkeypatch) -> None:
    """Blocks of one group split over several tasks share its computation (the same bits)."""
    import microg.study.cases as cases
    import microg.study.kernel as kernel
    import microg.study.run as run

    monkeypatch.setattr(cases, "BLOCK_CELLS", 4)  # 8 blocks of 4 cases per group
    study = loads_study(STUDY, filename="s.toml")
    calls: list[tuple[int, ...]] = []
    real = kernel.modal_group

    def counted(basis, plan, *key):
        calls.append(key)
        return real(basis, plan, *key)

    monkeypatch.setattr(kernel, "modal_group", counted)
    whole = sweep(study).dataset.load()
    n_groups = len(set(calls))
    assert n_groups == 2 and len(calls) == n_groups
    calls.clear()
    monkeypatch.setattr(run, "TASK_CASES", 1)  # one block per task
    split = sweep(study)
    assert len(calls) == n_groups and split.computed_blocks == 8 * n_groups
    for v in ("peak_accel_g", "band_rms_g", "margin", "complies"):
        assert (split.dataset[v].values == whole[v].values).all(), v


def test_a_scatter_that_never_answers_is_abandoned_and_tried_again(monkeypatch) -> None:
    # distributed's scatter(timeout=) did not bound a scatter racing a worker's death (a CI
    # run waited 10 minutes in Client.scatter): each attempt is now bounded by wall time
    import threading
    import time

    from microg.study import run

    monkeypatch.setattr(run, "SCATTER_TIMEOUT_S", 0.2)
    never = threading.Event()
    calls = []

    class Client:
        def scatter(self, data, **kw):
            calls.append(kw)
            if len(calls) == 1:
                never.wait()  # the first attempt hangs for good
            return f"future of {data}"

    t0 = time.perf_counter()
    assert run._scatter(Client(), "basis", True) == "future of basis"
    assert len(calls) == 2 and calls[1]["broadcast"] is True
    assert time.perf_counter() - t0 < 5.0
    never.set()
