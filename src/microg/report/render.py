"""Figures rendered in helper processes that load matplotlib while the caller computes.

``microg analyze`` spends more time importing matplotlib and drawing its figures than
computing (issue 8, "Speed of the main job").  A :class:`FigureRenderer` started before the
computation forks one helper process, which imports the plotting modules (and warms the font
cache) on another core while the caller computes; when the result is ready, the caller sends
it (pickled) and the helper forks once more, so that two processes draw shares of the figures
while the caller prepares the HTML.  The caller itself never imports matplotlib.

The PNG bytes are the same as those drawn in-process: the helpers are forks of the caller,
with its matplotlib settings.  Anything unexpected (no ``os.fork``, one CPU, other threads
running in the caller, a result that does not pickle or pickles larger than
:data:`MAX_PAYLOAD_BYTES`, a helper that fails or dies) makes
:meth:`FigureRenderer.render` return ``None``, and the caller draws in-process as before.
The environment variable ``MICROG_FIGURE_PROCESSES`` sets the number of drawing processes
(``1``: no helper; default: 2 where two CPUs are available).

This is for a command-line run (one process per job): ``microg analyze`` starts one before
it loads the model (:mod:`microg.cli.analyze`).  A library caller (a notebook, a server)
draws in-process: :func:`microg.report.analysis.figures` without a renderer.
"""

from __future__ import annotations

import contextlib
import gc
import importlib
import os
import pickle
import select
import signal
import struct
import sys
import threading
import time
import traceback
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import TracebackType
from typing import Any

__all__ = ["FigureJob", "FigureRenderer", "default_processes", "split_jobs"]

#: drawing processes at most (the machine this is tuned for has two cores)
MAX_PROCESSES = 2

#: seconds a helper may take before the caller gives up on it and draws in-process
TIMEOUT_S = 600.0

#: a pickled request larger than this is drawn in-process instead (bytes)
MAX_PAYLOAD_BYTES = 64_000_000

_HEADER = struct.Struct("<Q")


@dataclass(frozen=True)
class FigureJob:
    """One figure of a report: its file name, a relative cost, and how to draw it.

    ``draw`` returns PNG bytes; ``weight`` is only used to share the figures out evenly
    between the drawing processes.
    """

    name: str
    weight: float
    draw: Callable[[], bytes]


def default_processes() -> int:
    """Drawing processes: ``MICROG_FIGURE_PROCESSES``, else 2 when two CPUs are usable."""
    env = os.environ.get("MICROG_FIGURE_PROCESSES", "").strip()
    if env:
        try:
            return max(1, int(env))
        except ValueError:
            return 1
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cpus = os.cpu_count() or 1
    return max(1, min(MAX_PROCESSES, cpus))


def split_jobs(weights: Sequence[float], parts: int) -> list[list[int]]:
    """Indices of ``weights`` shared into ``parts`` groups of nearly equal total weight.

    Longest first, each into the lightest group so far (the LPT rule); each group keeps
    the order of the input.
    """
    groups: list[list[int]] = [[] for _ in range(max(1, parts))]
    load = [0.0] * len(groups)
    for i in sorted(range(len(weights)), key=lambda k: -weights[k]):
        g = min(range(len(groups)), key=lambda k: load[k])
        groups[g].append(i)
        load[g] += weights[i]
    return [sorted(g) for g in groups if g]


# ----------------------------------------------------------------------------- pipes


def _send(fd: int, obj: Any) -> None:
    _write_all(fd, pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL))


def _write_all(fd: int, data: bytes) -> None:
    """``data`` (pickled bytes) written whole, framed by its length."""
    view = memoryview(_HEADER.pack(len(data)) + data)
    while view:
        n = os.write(fd, view)
        view = view[n:]


def _read_exact(fd: int, n: int, deadline: float | None, pid: int | None) -> bytes | None:
    """``n`` bytes from ``fd``; None at end of file, past the deadline or when ``pid`` died."""
    chunks = []
    while n > 0:
        if deadline is not None:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            ready, _, _ = select.select([fd], [], [], min(left, 0.5))
            if not ready:
                if pid is not None and _exited(pid):
                    # the helper died; whatever it wrote is still readable
                    ready, _, _ = select.select([fd], [], [], 0)
                    if not ready:
                        return None
                else:
                    continue
        chunk = os.read(fd, min(n, 1 << 20))
        if not chunk:
            return None
        chunks.append(chunk)
        n -= len(chunk)
    return b"".join(chunks)


def _receive(fd: int, deadline: float | None = None, pid: int | None = None) -> Any:
    head = _read_exact(fd, _HEADER.size, deadline, pid)
    if head is None:
        return None
    body = _read_exact(fd, _HEADER.unpack(head)[0], deadline, pid)
    return None if body is None else pickle.loads(body)


def _exited(pid: int) -> bool:
    try:
        done, _ = os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return done == pid


# ----------------------------------------------------------------------------- helper side


def _warm_up() -> None:
    """Load what a first figure loads (fonts, the PNG writer) before any work arrives."""
    from microg.plotting.common import finish, new_figure, png_bytes

    fig = new_figure(1.5, 1.0)
    ax = fig.add_subplot()
    ax.loglog([1.0, 1e3], [1.0, 1e3], label="x")
    ax.set_xlabel("f [Hz]")
    ax.set_title("warm-up")
    ax.legend()
    png_bytes(finish(fig), dpi=20)


def _draw(jobs: Sequence[FigureJob], which: Sequence[int]) -> dict[str, bytes]:
    return {jobs[i].name: jobs[i].draw() for i in which}


def _helper(preload: Sequence[str], requests: int, replies: int, processes: int) -> None:
    """The helper process: load, wait for one request, draw, reply, exit."""
    status = 0
    try:
        # the helper exits by os._exit once it has replied: its objects never need
        # collecting, and collections over matplotlib's heap would slow the imports and the
        # drawing (as :func:`microg.report.analysis.figures` pauses it in-process)
        gc.disable()
        for name in preload:
            importlib.import_module(name)
        with contextlib.suppress(Exception):
            _warm_up()
        request = _receive(requests)
        if request is None:  # the caller finished without figures
            return
        make_jobs, payload = request
        jobs: list[FigureJob] = make_jobs(payload)
        groups = split_jobs([j.weight for j in jobs], processes)
        mine, others = groups[0], groups[1:]
        children = []
        for group in others:
            r, w = os.pipe()
            pid = os.fork()
            if pid == 0:  # a second drawing process
                code = 0
                try:
                    os.close(r)
                    _send(w, ("ok", _draw(jobs, group)))
                except BaseException:
                    code = 1
                finally:
                    os._exit(code)
            os.close(w)
            children.append((pid, r))
        out = _draw(jobs, mine)
        for pid, r in children:
            reply = _receive(r, time.monotonic() + TIMEOUT_S, pid)
            os.close(r)
            with contextlib.suppress(ChildProcessError):
                os.waitpid(pid, 0)
            if not (isinstance(reply, tuple) and reply[0] == "ok"):
                raise RuntimeError("a drawing process failed")
            out.update(reply[1])
        _send(replies, ("ok", {j.name: out[j.name] for j in jobs}))
    except BaseException:
        status = 1
        with contextlib.suppress(BaseException):
            _send(replies, ("error", traceback.format_exc()))
    finally:
        os._exit(status)


# ----------------------------------------------------------------------------- caller side


class FigureRenderer:
    """A forked helper that loads the plotting modules now and draws figures later.

    Use as a context manager around the computation::

        with FigureRenderer.start(["microg.plotting.analysis"]) as renderer:
            result = compute()
            pngs = renderer.render(make_jobs, result)   # None: draw in-process instead
    """

    def __init__(self, pid: int | None, requests: int | None, replies: int | None) -> None:
        self._pid = pid
        self._requests = requests
        self._replies = replies
        self.error: str | None = None  #: why the helper failed, if it did

    @property
    def active(self) -> bool:
        """Whether a helper process is running."""
        return self._pid is not None

    @classmethod
    def start(cls, preload: Sequence[str] = (), processes: int | None = None) -> FigureRenderer:
        """Fork the helper now, which imports ``preload`` (module names) and waits.

        Parameters
        ----------
        preload : sequence of str
            Modules the helper imports while the caller computes.
        processes : int, optional
            Drawing processes (default :func:`default_processes`); 1 starts no helper.
        """
        n = default_processes() if processes is None else max(1, int(processes))
        if n < 2 or not hasattr(os, "fork") or threading.active_count() > 1:
            return cls(None, None, None)  # draw in-process
        req_r, req_w = os.pipe()
        rep_r, rep_w = os.pipe()
        sys.stdout.flush()
        sys.stderr.flush()
        try:
            with warnings.catch_warnings():
                # Python >= 3.12 warns of fork with threads running: BLAS's idle pool, which
                # OpenBLAS stops and restarts around a fork itself (pthread_atfork)
                warnings.simplefilter("ignore", DeprecationWarning)
                pid = os.fork()
        except OSError:
            for fd in (req_r, req_w, rep_r, rep_w):
                os.close(fd)
            return cls(None, None, None)
        if pid == 0:
            os.close(req_w)
            os.close(rep_r)
            _helper(preload, req_r, rep_w, n)  # never returns
        os.close(req_r)
        os.close(rep_w)
        return cls(pid, req_w, rep_r)

    def render(
        self,
        make_jobs: Callable[[Any], list[FigureJob]],
        payload: Any,
        while_waiting: Callable[[], object] | None = None,
    ) -> dict[str, bytes] | None:
        """The PNG bytes of ``make_jobs(payload)``'s figures, drawn by the helpers.

        Parameters
        ----------
        make_jobs : callable
            A module-level function (it is pickled by name) from the payload to the jobs.
        payload : object
            Sent to the helper pickled.
        while_waiting : callable, optional
            Work the caller does while the helpers draw (e.g. loading the HTML template).

        Returns
        -------
        dict of str to bytes, or None
            None when no helper runs or it failed: the caller then draws in-process.
        """
        if self._pid is None or self._requests is None or self._replies is None:
            return None
        try:
            data = pickle.dumps((make_jobs, payload), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as exc:  # e.g. a payload that does not pickle
            self.error = f"{type(exc).__name__}: {exc}"
            self.close()
            return None
        if len(data) > MAX_PAYLOAD_BYTES:
            # a large model's result (issue 11: 193 MB of mode shapes): copying it through
            # the pipe and unpickling it costs more than drawing here saves
            self.error = f"the result is {len(data) / 1e6:.0f} MB: drawn in-process"
            self.close()
            return None
        try:
            _write_all(self._requests, data)
        except OSError as exc:
            self.error = f"{type(exc).__name__}: {exc}"
            self.close()
            return None
        os.close(self._requests)
        self._requests = None
        if while_waiting is not None:
            while_waiting()
        reply = _receive(self._replies, time.monotonic() + TIMEOUT_S, self._pid)
        self.close()
        if isinstance(reply, tuple) and reply[0] == "ok":
            return dict(reply[1])
        self.error = reply[1] if isinstance(reply, tuple) else "the helper process stopped"
        return None

    def close(self) -> None:
        """Stop the helper (if it still runs) and release its pipes."""
        for attr in ("_requests", "_replies"):
            fd = getattr(self, attr)
            if fd is not None:
                with contextlib.suppress(OSError):
                    os.close(fd)
                setattr(self, attr, None)
        pid, self._pid = self._pid, None
        if pid is None:
            return
        # a helper that replied is exiting; one that never got work is killed at once (it
        # holds nothing: an error exit must not wait for its imports)
        deadline = time.monotonic() + 0.05
        while not _exited(pid):
            if time.monotonic() > deadline:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, signal.SIGKILL)
                with contextlib.suppress(ChildProcessError):
                    os.waitpid(pid, 0)
                return
            time.sleep(0.002)

    def __enter__(self) -> FigureRenderer:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def __del__(self) -> None:
        with contextlib.suppress(Exception):
            self.close()
