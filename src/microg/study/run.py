"""Running a sweep: serially in this process, or as tasks on a Dask cluster.

The same functions compute the same blocks on both paths (:mod:`microg.study.kernel`, with
one BLAS thread), so both give the same bits:

1. every model variant that has blocks left is solved once (:func:`~microg.study.kernel.
   solve_basis`; on a cluster, one task per variant, so the eigen-solves run in parallel);
2. the variant's modal basis (the modes at the study's points: small) stays on the cluster
   as the solving task's result, and the small plan of the axes as a task's: each worker
   fetches them once, and the scheduler recomputes them if the worker holding them dies
   (a future with lineage; scattered data has none, and a broadcast racing a worker's death
   waited on the dead worker);
3. its blocks are grouped into tasks of about a second (:data:`TASK_CASES` cases) and
   submitted, at most a few per worker at a time; each result is written to the store as it
   arrives (:class:`~microg.study.store.SweepStore`), and the progress callback is told.

A task that raises is retried (:data:`RETRIES`); a worker that dies loses only the tasks it
held, which the scheduler reruns elsewhere.  A sweep that stops (an error, an interrupt)
leaves the blocks written readable and raises :class:`SweepIncompleteError`, which says how to
resume: run the same sweep into the same directory; finished blocks are not recomputed.
"""

from __future__ import annotations

import contextlib
import logging
import signal
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from microg import _args
from microg._io import sigterm_raises
from microg.errors import InputError, MicrogError
from microg.study.cases import Block, Study, default_n_modes
from microg.study.kernel import (
    Basis,
    BlockWork,
    KernelPlan,
    clear_groups,
    kernel_plan,
    run_blocks,
    solve_basis,
)
from microg.study.plan import load_study
from microg.study.store import STORE_NAME, SweepStore

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "RETRIES",
    "TASK_CASES",
    "CONNECT_TIMEOUT_S",
    "WORKER_ENVIRON",
    "worker_environ",
    "SweepIncompleteError",
    "SweepResult",
    "sweep",
]

#: times a failed task is retried (a worker's death is handled by the scheduler itself)
RETRIES = 2
#: cases per task (about a second on the shipped IOC model, 20,001-sample records)
TASK_CASES = 1024
#: at most this many modal groups (force, damping, isolator) per task
TASK_GROUPS = 8
#: seconds to wait for a scheduler to answer and to have a worker
CONNECT_TIMEOUT_S = 10.0
#: seconds one scatter may take before it is tried again: a scatter racing a worker's
#: restart can otherwise wait without end (seen once in CI); a model of ~200 MB moves in ~2 s
SCATTER_TIMEOUT_S = 30.0
#: tasks in flight per worker thread
IN_FLIGHT_PER_THREAD = 2
#: glibc malloc settings of the local workers, set before each worker process starts (the
#: nanny's ``distributed.nanny.pre-spawn-environ``).  distributed ships
#: ``MALLOC_TRIM_THRESHOLD_=65536``, which returns freed memory to the system after every
#: large temporary, so a task's next array of a few MB is mapped (and page-faulted) again:
#: a block's task ran at half its in-process speed.  Trimming above 1 GiB keeps the freed
#: pages for the next block; a fixed mmap threshold of 32 MiB (glibc's largest on 64 bits)
#: serves the block-sized arrays from the heap.  docs/scale.md says how to set them for a
#: cluster's workers.
WORKER_ENVIRON: dict[str, str] = {
    "MALLOC_TRIM_THRESHOLD_": str(1 << 30),
    "MALLOC_MMAP_THRESHOLD_": str(1 << 25),
}
#: distributed's own default trim threshold (replaced by :data:`WORKER_ENVIRON`'s)
_DISTRIBUTED_TRIM = "65536"

TaskFn = Callable[[Basis, KernelPlan, Sequence[BlockWork], int], list[Any]]


class SweepIncompleteError(MicrogError):
    """A sweep stopped part-way; the blocks written are kept and the sweep can be resumed.

    Attributes
    ----------
    done_blocks, total_blocks : blocks written and blocks of the plan
    done_cases, total_cases : the same in cases
    store : the store's path (None: in memory)
    signal_number : the signal that stopped it (``signal.SIGTERM``, ``signal.SIGINT``), or
        None when a failure stopped it; the CLI exits with 128 + this number, else 1
    """

    def __init__(
        self,
        cause: str,
        *,
        done_blocks: int,
        total_blocks: int,
        done_cases: int,
        total_cases: int,
        store: Path | None,
        resume: str,
        signal_number: int | None = None,
    ):
        self.signal_number = signal_number
        self.done_blocks, self.total_blocks = done_blocks, total_blocks
        self.done_cases, self.total_cases = done_cases, total_cases
        self.store = store
        kept = (
            f"{store} holds the {done_blocks} blocks written ({done_cases:,} of "
            f"{total_cases:,} cases; xarray.open_zarr reads them, computed marks them)"
            if store is not None
            else "the results were in memory and are lost"
        )
        super().__init__(f"sweep stopped after {done_blocks} of {total_blocks} blocks: {cause}; "
                         f"{kept}; to resume, {resume}")  # fmt: skip


# --------------------------------------------------------------------------- the result


@dataclass
class SweepResult:
    """The result of :func:`sweep`: the dataset, the plan, the modes of each variant.

    Attributes
    ----------
    study : the Study
    store : the SweepStore (``store.path``: ``DIR/results.zarr``, or None in memory)
    out : the output directory (None: in memory)
    bases : ``"model/variant"`` -> the modes in its response (JSON-ready)
    warnings : what the user should know (the plan's and each variant's)
    computed_blocks, resumed_blocks : blocks computed by this call and found done
    """

    study: Study
    store: SweepStore = field(repr=False)
    out: Path | None = None
    bases: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    computed_blocks: int = 0
    resumed_blocks: int = 0

    @property
    def dataset(self) -> Any:
        """The results as a labelled ``xarray.Dataset`` (lazy: read from the store)."""
        return self.store.dataset()

    def to_xarray(self) -> Any:
        """The results Dataset (dims and units in the attributes)."""
        return self.dataset

    def summary(self, heatmap: Sequence[str] | None = None, n_worst: int = 5) -> Any:
        """The report's numbers: worst cases, complying fraction, heat map (see summary.py)."""
        from microg.study.summary import summarize

        return summarize(self, heatmap=heatmap, n_worst=n_worst)

    def to_dict(self) -> dict[str, Any]:
        """``{"cases", "complying_fraction", "worst", ...}``: the ``--json`` contract."""
        return self.summary().to_dict()

    def plot(self, heatmap: Sequence[str] | None = None, ax: Any = None) -> Figure:
        """Heat map of the worst margin over two axes (a Figure).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.study import heatmap_figure

        return heatmap_figure(self.summary(heatmap=heatmap), ax=ax)

    def case_model(self, model: str, variant: str) -> Any:
        """The model object of (model, variant), as the sweep used it."""
        im = self.study.coords["model"].index(model)
        iv = self.study.coords["variant"].index(variant)
        return self.study.variant_model(im, iv)

    def analyze_case(self, case: dict[str, Any], **kwargs: Any) -> Any:
        """Run the per-case path on one case alone, no isolator.

        :func:`microg.analyze` for a force history; for a source catalogue,
        :func:`microg.environment.vibratory.assess_sources` on the variant's modes.

        Parameters
        ----------
        case : labels of the case, one per case dimension (as in ``dataset.sel``)
        kwargs : passed to :func:`microg.analyze` (e.g. ``isolation=False``)
        """
        from microg.analysis import analyze

        s = self.study
        f = s.forces[s.coords["force"].index(case["force"])]
        d = s.directions[s.coords["direction"].index(case["direction"])]
        disc, rec = s.discretisation, s.record
        n_modes = disc.n_modes or default_n_modes(s)
        common: dict[str, Any] = dict(
            observe=[case["observe"]],
            method=disc.method,
            plane=disc.plane,
            n=disc.n,
            n_modes=n_modes,
            gravity_gradient=disc.gravity_gradient,
            damping=float(case["damping"]),
            duration=rec.duration_s,
            dt=rec.dt_s,
            max_freq=rec.max_freq_hz,
            requirement=rec.requirement,
        )
        model = self.case_model(case["model"], case["variant"])
        if f.catalogue is not None:
            return analyze(model, sources=f.catalogue, **common, **kwargs)
        return analyze(model, force=f.spec, at=case["at"], direction=d.vector, **common, **kwargs)


# ----------------------------------------------------------------------------- planning


def _tasks(study: Study, blocks: Sequence[Block]) -> dict[tuple[int, int], list[list[BlockWork]]]:
    """The blocks to do, per (model, variant), grouped into tasks of about TASK_CASES cases."""
    out: dict[tuple[int, int], list[list[BlockWork]]] = {}
    for b in blocks:
        key = (b.index[0], b.index[1])
        tasks = out.setdefault(key, [])
        work = BlockWork(b.id, b.index, b.at, b.observe, study.block_mask(b.index, b.at, b.observe))
        if tasks:
            last = tasks[-1]
            cases = sum(int(w.mask.sum()) for w in last)
            groups = len({w.index[2:] for w in last} | {b.index[2:]})
            if cases + b.n_cases <= TASK_CASES and groups <= TASK_GROUPS:
                last.append(work)
                continue
        tasks.append([work])
    return out


def _solve_args(study: Study, im: int, iv: int) -> tuple[Any, dict[str, Any]]:
    d, r = study.discretisation, study.record
    return study.variant_model(im, iv), {
        "model_label": study.models[im].label,
        "variant_label": study.variants[iv].label,
        "method": d.method,
        "plane": d.plane,
        "n": d.n,
        "n_modes": d.n_modes,
        "gravity_gradient": d.gravity_gradient,
        "max_freq_hz": r.max_freq_hz,
        "dt_s": r.dt_s,
        "at": study.at,
        "observe": study.observe,
        "directions": np.array([x.vector for x in study.directions], float),
        "where": f"{study.file}: record.dt",
        "catalogues": [
            (i_f, i_z, f.catalogue, study.damping[i_z])
            for i_f, f in enumerate(study.forces)
            if f.catalogue is not None
            for i_z in range(len(study.damping))
            if study.damping[i_z] > 0
        ],
        "requirement": r.requirement,
    }


def _check_reach(study: Study, basis: Basis) -> list[str]:
    """Refuse a force the model cannot carry (as the analysis does); warn of a partial one."""
    bad = np.argwhere(basis.reach < 1e-9)
    own = [f.history is None or f.history.direction is not None for f in study.forces]
    if bad.size and not all(own):
        ia, idr = (int(x) for x in bad[0])
        raise InputError(
            f"a force along {study.directions[idr].label!r} at {study.at[ia]!r} does no work on "
            f"model {basis.model}/{basis.variant}: the response would be zero",
            where=f"{study.file}: axes.direction[{idr}]",
            fix="give directions the model can move in (in the plane of a planar model)",
        )
    part = np.argwhere(basis.reach < 1 - 1e-9)
    return [
        f"only {100 * basis.reach[ia, idr]:.3g}% of a force along "
        f"{study.directions[idr].label!r} at {study.at[ia]!r} acts on the model; the rest is "
        "dropped"
        for ia, idr in part[:5]
    ]


# ----------------------------------------------------------------------------- running


def _progress_none(done: int, total: int) -> None:
    return None


class _Runner:
    """One sweep's loop: what is left, the store, progress, and the stop message."""

    def __init__(
        self,
        study: Study,
        store: SweepStore,
        progress: Callable[[int, int], None] | None,
        resume: str,
    ):
        self.study, self.store = study, store
        self.progress = progress or _progress_none
        self.resume = resume
        self.total_cases = study.n_cases
        blocks = list(study.blocks())
        self.total_blocks = len(blocks)
        done = store.done()
        self.todo = [b for b in blocks if not done[b.id]]
        self.block_of = {b.id: b for b in blocks}
        self.done_blocks = self.total_blocks - len(self.todo)
        self.resumed_blocks = self.done_blocks
        self.done_cases = sum(b.n_cases for b in blocks if done[b.id])
        self.bases: dict[str, Any] = store.bases()
        self.warnings: list[str] = list(study.warnings)
        self.tasks = _tasks(study, self.todo)

    def start(self) -> None:
        self.store.set_state("running")
        self.progress(self.done_cases, self.total_cases)

    def basis_done(self, basis: Basis) -> None:
        extra = _check_reach(self.study, basis)
        info = basis.to_dict()
        info["warnings"] = list(basis.warnings) + extra
        self.bases[f"{basis.model}/{basis.variant}"] = info
        self.store.record_basis((basis.model, basis.variant), info)

    def results(self, results: Sequence[Any]) -> None:
        for r in results:
            blk = self.block_of[r.id]
            self.store.write(blk, r.values)
            self.done_blocks += 1
            self.done_cases += blk.n_cases
            self.progress(self.done_cases, self.total_cases)

    def stopped(self, cause: str, signal_number: int | None = None) -> SweepIncompleteError:
        self.store.set_state("stopped", cause=cause)
        return SweepIncompleteError(
            cause,
            done_blocks=self.done_blocks,
            total_blocks=self.total_blocks,
            done_cases=self.done_cases,
            total_cases=self.total_cases,
            store=self.store.path,
            resume=self.resume,
            signal_number=signal_number,
        )

    def finish(self) -> None:
        self.store.set_state("complete")
        for key, info in self.bases.items():
            self.warnings += [f"{key}: {w}" for w in info.get("warnings", [])]


def _serial(runner: _Runner, task_fn: TaskFn, threads: int) -> None:
    s = runner.study
    plan = kernel_plan(s)
    for (im, iv), tasks in runner.tasks.items():
        model, kw = _solve_args(s, im, iv)
        basis = solve_basis(model, threads=threads, **kw)
        runner.basis_done(basis)
        for works in tasks:
            runner.results(task_fn(basis, plan, works, threads))


def worker_environ(current: dict[str, Any] | None = None) -> dict[str, str]:
    """The ``distributed.nanny.pre-spawn-environ`` of microg's local workers.

    :data:`WORKER_ENVIRON` over distributed's defaults; a value the user set (in the Dask
    configuration, or in this process's environment, which the nanny reads first) is kept,
    except distributed's own ``MALLOC_TRIM_THRESHOLD_=65536``.

    Parameters
    ----------
    current : the configured ``pre-spawn-environ`` (default: ``dask.config``'s)
    """
    import os

    if current is None:
        import dask

        current = dict(dask.config.get("distributed.nanny.pre-spawn-environ", default={}))
    env = {k: str(v) for k, v in current.items() if v is not None}
    for k, v in WORKER_ENVIRON.items():
        mine = os.environ.get(k, env.get(k))
        env[k] = v if mine is None or mine == _DISTRIBUTED_TRIM else mine
    return env


@contextmanager
def _local_environ(env: dict[str, str]) -> Iterator[None]:
    """``env`` as this process's environment while local workers start.

    The nanny reads the environment before its configuration, and writes its own values there.
    """
    import os

    old = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


@contextmanager
def _client(workers: int | None, scheduler: str | None, timeout_s: float) -> Iterator[Any]:
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise InputError(
            "Dask's distributed scheduler is not installed",
            where="workers" if workers else "scheduler",
            fix="pip install 'microg[sweep]' (dask[distributed])",
        ) from None
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=timeout_s)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            reason = " ".join(str(exc).split())[:200]
            raise InputError(
                f"no Dask scheduler answered at {scheduler!r} within {timeout_s:g} s ({reason})",
                where="scheduler",
                fix="start one (dask scheduler, dask-jobqueue, dask-kubernetes) and give its "
                "address, e.g. tcp://host:8786; or use --workers N for a local cluster",
            ) from None
        try:
            try:
                client.wait_for_workers(1, timeout=timeout_s)
            except (TimeoutError, OSError):
                raise InputError(
                    f"the Dask scheduler at {scheduler!r} has no worker after {timeout_s:g} s",
                    where="scheduler",
                    fix="start workers for it (dask worker ADDRESS), or local ones (workers=N)",
                ) from None
            yield client
        finally:
            client.close()
        return
    assert workers is not None
    import dask

    env = worker_environ()
    with dask.config.set({"distributed.nanny.pre-spawn-environ": env}), _local_environ(env):
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # any free port: 8787 may be taken
            silence_logs=logging.ERROR,
        )
    try:
        client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
    finally:
        cluster.close()


#: times a task whose scattered inputs were lost with a worker is resubmitted
RESUBMIT = 3
#: a future's states from which the scheduler will not compute it again
_GONE = ("cancelled", "lost", "error")


def _lost(exc: BaseException) -> bool:
    """True when a task failed because a worker (and the data it held) was lost."""
    from asyncio import CancelledError
    from concurrent.futures import CancelledError as FutureCancelled  # distributed's base

    lost = (CancelledError, FutureCancelled, KeyError, OSError)
    return isinstance(exc, lost) or "lost" in str(exc).lower()


def _identity(value: Any) -> Any:
    """The value itself (a task whose result is data the cluster can recompute)."""
    return value


def _scatter(client: Any, data: Any, broadcast: bool, attempts: int = 5) -> Any:
    """``client.scatter``, again after a moment if a worker is leaving (a restart is racing).

    Each attempt is bounded by :data:`SCATTER_TIMEOUT_S` of wall time: distributed's own
    ``timeout`` does not bound a scatter that raced a worker's death (it waited without end
    in CI), so the call runs in a daemon thread that is abandoned when it does not answer.
    """
    import threading
    import time

    def attempt_once() -> Any:
        box: dict[str, Any] = {}

        def run() -> None:
            try:
                box["value"] = client.scatter(
                    data, broadcast=broadcast, hash=False, timeout=SCATTER_TIMEOUT_S
                )
            except BaseException as exc:  # handed to the caller's thread
                box["error"] = exc

        worker = threading.Thread(target=run, name="microg-scatter", daemon=True)
        worker.start()
        worker.join(SCATTER_TIMEOUT_S)
        if worker.is_alive():
            raise TimeoutError(f"scatter did not answer in {SCATTER_TIMEOUT_S:g} s")
        if "error" in box:
            raise box["error"]
        return box["value"]

    for attempt in range(attempts):
        try:
            return attempt_once()
        except (KeyError, OSError):
            if attempt == attempts - 1:
                raise
            time.sleep(0.5 * (attempt + 1))
    raise AssertionError("unreachable")  # pragma: no cover


def _submit_solve(
    client: Any, study: Study, key: tuple[int, int], threads: int, attempts: int = 5
) -> Any:
    """Submit the modal solve of one (model, variant): the future of its :class:`Basis`."""
    model, kw = _solve_args(study, *key)
    # a model may be large (a modal file's shapes): scattered, not put in the task graph
    model_f = _scatter(client, model, False, attempts)
    return client.submit(solve_basis, model_f, threads=threads, pure=False, retries=RETRIES, **kw)


def _submit_solves(client: Any, study: Study, threads: int) -> dict[tuple[int, int], Any]:
    """Every variant's modal solve, submitted before the store is made (they overlap).

    One scatter attempt each: a variant whose submission fails here (the futures made so far
    are cancelled) is submitted again inside the run, with its retries and its report.
    """
    out: dict[tuple[int, int], Any] = {}
    try:
        for im in range(len(study.models)):
            for iv in range(len(study.variants)):
                out[(im, iv)] = _submit_solve(client, study, (im, iv), threads, attempts=1)
    except BaseException:
        for f in out.values():
            f.cancel()
        raise
    return out


def _distributed(
    runner: _Runner,
    client: Any,
    task_fn: TaskFn,
    threads: int,
    solving: dict[tuple[int, int], Any] | None = None,
) -> None:
    """The sweep on a Dask cluster (see the module docstring).

    The variants' modal solves may have been submitted already (``solving``: before the store
    was made, so the two overlap).  The plan and the bases are tasks' results: a worker's
    death loses none of them for good (the scheduler recomputes them), except a basis whose
    scattered model went with it; its variant is then solved again before its blocks are
    resubmitted.  A task that failed because its worker died is resubmitted :data:`RESUBMIT`
    times.
    """
    from asyncio import CancelledError

    from distributed import as_completed

    s = runner.study
    plan = kernel_plan(s)
    # the plan and each basis as tasks' results (lineage: recomputed if their worker dies),
    # held here until the sweep ends so that a task submitted later still finds them
    plan_f = client.submit(_identity, plan, pure=False)
    basis_f: dict[tuple[int, int], Any] = {}
    # blocks waiting on a variant solved again, with their attempt (it counts to RESUBMIT)
    again: dict[tuple[int, int], list[tuple[list[BlockWork], int]]] = {}
    n_threads = max(1, sum(client.nthreads().values()))
    limit = IN_FLIGHT_PER_THREAD * n_threads
    meta: dict[str, tuple[str, tuple[int, int], Any, int]] = {}
    ac = as_completed()

    def solve(key: tuple[int, int], attempt: int) -> None:
        early = solving.pop(key, None) if solving is not None and attempt == 0 else None
        f = early if early is not None else _submit_solve(client, s, key, threads)
        meta[f.key] = ("basis", key, None, attempt)
        ac.add(f)

    def submit(key: tuple[int, int], works: list[BlockWork], attempt: int) -> None:
        f = client.submit(task_fn, basis_f[key], plan_f, works, threads, pure=False,
                          retries=RETRIES)  # fmt: skip
        meta[f.key] = ("blocks", key, works, attempt)
        ac.add(f)

    queue: deque[tuple[tuple[int, int], list[BlockWork], int]] = deque()
    in_flight = 0
    try:
        for key in runner.tasks:
            solve(key, 0)
        for f in (solving or {}).values():  # solved early, but every block is already written
            f.cancel()
        for fut in ac:
            kind, key, works, attempt = meta.pop(fut.key)
            try:
                result = fut.result()
            except (Exception, CancelledError) as exc:  # CancelledError is no Exception
                fut.release()
                if not _lost(exc) or attempt >= RESUBMIT:
                    raise
                if kind == "basis":
                    solve(key, attempt + 1)
                elif basis_f[key].status not in _GONE:  # lineage: the same futures serve
                    submit(key, works, attempt + 1)
                else:  # the basis cannot be recomputed (its scattered model went with a
                    # worker): the variant is solved again, then these blocks are queued
                    if key not in again:
                        solve(key, attempt + 1)
                    again.setdefault(key, []).append((works, attempt + 1))
                    in_flight -= 1
                continue
            if kind == "basis":
                # kept (not released) for the variant's block tasks; they are submitted once
                # the basis is there, so the scheduler spreads them over the workers (blocks
                # submitted on a pending basis all went to the worker solving it)
                basis_f[key] = fut
                if key in again:
                    queue.extend((key, w, a) for w, a in again.pop(key))
                else:
                    runner.basis_done(result)
                    queue.extend((key, w, 0) for w in runner.tasks[key])
            else:
                fut.release()
                in_flight -= 1
                runner.results(result)
            while queue and in_flight < limit:
                submit(*queue.popleft())
                in_flight += 1
    except BaseException:
        for f in list(ac.futures):
            f.cancel()
        raise


class _Terminated(KeyboardInterrupt):
    """SIGTERM during a sweep (SLURM's and PBS's time limit): stop as on Ctrl-C, resumably."""


def _is_new(out: Path) -> bool:
    """Whether ``out`` is absent or an empty directory (a sweep may then remove all it wrote)."""
    try:
        return not out.exists() or (out.is_dir() and next(out.iterdir(), None) is None)
    except OSError:
        return False


def _discard_fresh(target: Path, created: bool) -> None:
    """Remove what a refused sweep wrote into a directory that was new or empty before it.

    Only the sweep's own entries are removed (the marker, ``models/``, the store); the
    directory itself only if this call created it and it is then empty.
    """
    import shutil

    from microg._io import RUN_MARKER

    for name in (STORE_NAME, "models"):
        if (target / name).is_dir() and not (target / name).is_symlink():
            shutil.rmtree(target / name, ignore_errors=True)
    (target / RUN_MARKER).unlink(missing_ok=True)
    if created:
        with contextlib.suppress(OSError):
            target.rmdir()  # only when empty: nothing of anyone else's is there


def _prepare_out(study: Study, out: Path) -> Path:
    """Check the output directory (new, empty, or microg's), mark it, write derived models."""
    import json

    from microg._io import RUN_MARKER, atomic_write_text, check_writable
    from microg.models.station import Station
    from microg.models.toml import dump_station
    from microg.study.summary import model_file

    target = check_writable(out, where="out", resumable=True)
    try:
        target.mkdir(parents=True, exist_ok=True)
        marker = {"microg_run": 1, "files": [STORE_NAME, "report.html", "models"],
                  "command": "sweep"}  # fmt: skip
        atomic_write_text(target / RUN_MARKER, json.dumps(marker) + "\n")
        for im, m in enumerate(study.models):
            for iv, v in enumerate(study.variants):
                if not (v.kind == "move" or m.derived or (v.model is not None and v.model.derived)):
                    continue
                st = study.variant_model(im, iv)
                if isinstance(st, Station):
                    (target / "models").mkdir(exist_ok=True)
                    path = target / "models" / model_file(m.label, v.label)
                    atomic_write_text(path, dump_station(st))
    except OSError as exc:
        raise InputError(
            f"cannot write in {str(target)!r}: {exc.strerror or exc}",
            where="out",
            fix="choose a writable directory with free space",
        ) from None
    return target


def sweep(
    study: Study | str | Path,
    out: str | Path | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    timeout_s: float = CONNECT_TIMEOUT_S,
    restart: bool = False,
    progress: Callable[[int, int], None] | None = None,
    resume_hint: str | None = None,
    threads: int = 1,
    _task_fn: TaskFn | None = None,
) -> SweepResult:
    """Run a study: every case by linearity, serially or on a Dask cluster, into one Dataset.

    Parameters
    ----------
    study : Study, or the path of a study file (``docs/scale.md``)
    out : output directory; the results go to ``out/results.zarr`` as they are computed (a
        directory holding this study's results is resumed).  None: in memory
    workers : start a local Dask cluster of this many worker processes (one thread each)
    scheduler : address of a running Dask scheduler (``tcp://host:8786``); exclusive with
        ``workers``
    timeout_s : seconds to wait for the scheduler to answer and to have a worker
    restart : discard results of another study in ``out`` instead of refusing
    progress : called with (cases done, cases in the plan) as blocks are written
    resume_hint : what to tell the user to do to resume (default: call sweep again)
    threads : BLAS threads per task (1: the same bits on every path)

    Returns
    -------
    SweepResult

    Raises
    ------
    InputError
        A bad study (one line naming the file and field), a bad output directory, a
        scheduler that does not answer.
    SweepIncompleteError
        The sweep stopped part-way (the blocks written are kept; the message says how to
        resume).
    """
    if not isinstance(study, Study):
        study = load_study(_args.path(study, "study"))
    if out is not None:
        out = _args.path(out, "out")
    if workers is not None and scheduler is not None:
        raise InputError("give workers or scheduler, not both", where="workers")
    if workers is not None:
        workers = _args.integer(workers, "workers", lo=1, hi=1024)
    if scheduler is not None:
        _args.text(scheduler, "scheduler")
    timeout_s = _args.number(timeout_s, "timeout_s", lo=0.0, lo_open=True, unit="s")
    threads = _args.integer(threads, "threads", lo=1, hi=1024)
    _args.boolean(restart, "restart")
    if progress is not None:
        _args.function(progress, "progress")
    # what can be checked is checked before the first write (each variant's model, the
    # scheduler's answer); what only a variant's modal solve finds (a mechanism, a record too
    # coarse for the modes) removes again what this call wrote into a new or empty directory
    for im in range(len(study.models)):
        for iv in range(len(study.variants)):
            study.variant_model(im, iv)
    with contextlib.ExitStack() as stack:
        client = None
        if workers is not None or scheduler is not None:
            client = stack.enter_context(_client(workers, scheduler, timeout_s))
        fresh = out is not None and _is_new(Path(out))
        created = out is not None and not Path(out).exists()
        out_dir = None if out is None else _prepare_out(study, Path(out))
        solving: dict[tuple[int, int], Any] = {}
        if client is not None:
            # the variants' modal solves start on the cluster while the store is made here
            # (a variant whose blocks are all written already is cancelled); a submission that
            # fails is made again inside the run, which reports a failure and how to resume
            try:
                solving = _submit_solves(client, study, threads)
            except Exception:  # noqa: BLE001
                solving = {}
            stack.callback(lambda: [f.cancel() for f in solving.values()])
        store = SweepStore(study, None if out_dir is None else out_dir / STORE_NAME,
                           restart=restart, where="out")  # fmt: skip
        hint = resume_hint or (
            f"call microg.sweep({study.file!r}, {str(out_dir)!r}) again"
            if out_dir is not None
            else "run the sweep again with an output directory"
        )
        runner = _Runner(study, store, progress, hint)
        task_fn = _task_fn or run_blocks
        try:
            runner.start()
            with sigterm_raises(_Terminated):
                if runner.todo:
                    if client is None:
                        try:
                            _serial(runner, task_fn, threads)
                        finally:
                            clear_groups()
                    else:
                        _distributed(runner, client, task_fn, threads, solving)
        except InputError:
            if fresh and out_dir is not None:  # all of it is this call's: nothing half-written
                _discard_fresh(out_dir, created)
            else:
                store.set_state("stopped", cause="bad input")
            raise
        except _Terminated:
            cause = "terminated (SIGTERM: a batch system's time limit?)"
            raise runner.stopped(cause, signal.SIGTERM) from None
        except KeyboardInterrupt:
            raise runner.stopped("interrupted", signal.SIGINT) from None
        except Exception as exc:  # a failure part-way: keep what is written, say how to resume
            cause = f"{type(exc).__name__}: {' '.join(str(exc).split())[:300]}"
            raise runner.stopped(cause) from exc
    runner.finish()
    return SweepResult(
        study=study,
        store=store,
        out=out_dir,
        bases=runner.bases,
        warnings=runner.warnings,
        computed_blocks=runner.total_blocks - runner.resumed_blocks,
        resumed_blocks=runner.resumed_blocks,
    )
