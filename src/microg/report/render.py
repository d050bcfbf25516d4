"""Figures rendered in helper processes that load matplotlib while the caller computes.

``microg analyze`` spends more time importing matplotlib and drawing its figures than
computing (issue 8, "Speed of the main job").  A :class:`FigureRenderer` started before the
computation forks one helper process, which imports the plotting modules (and warms the font
cache, and loads what a ``warm`` step asks, e.g. the HTML template) on another core while
the caller computes.  The caller may send an early request as soon as some figures can be
drawn (:meth:`FigureRenderer.draw_early`: the model's, once its modes are solved); the
helper forks an early drawer for them.  When the result is ready the caller sends it
(:meth:`FigureRenderer.render`); the helper and the early drawer (or a second fork) take
the figures left one at a time, the heaviest first, whoever is free (so they finish
within about one figure of each other whatever each costs), and a ``finish`` step may
make more files from them (the HTML page).  The
caller itself never imports matplotlib.  Requests leave out what no figure reads
(``omit``: a structure's sparse matrices), so the helper need not import scipy.

The PNG bytes are the same as those drawn in-process: the helpers are forks of the caller,
with its matplotlib settings.  Anything unexpected (no ``os.fork``, one CPU, other threads
running in the caller, a result that does not pickle or pickles larger than
:data:`MAX_PAYLOAD_BYTES`, a helper that fails or dies) makes
:meth:`FigureRenderer.render` return ``None``, and the caller draws in-process as before;
drawing processes die with their helper.  The environment variable
``MICROG_FIGURE_PROCESSES`` sets the number of drawing processes (``1``: no helper;
default: 2 where two CPUs are available).

This is for a command-line run (one process per job): ``microg analyze`` starts one before
it loads the model (:mod:`microg.cli.analyze`).  A library caller (a notebook, a server)
draws in-process: :func:`microg.report.analysis.figures` without a renderer.
"""

from __future__ import annotations

import contextlib
import gc
import importlib
import io
import os
import pickle
import select
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import TracebackType
from typing import Any

from microg._fork import (
    can_fork,
    fork,
    pipe,
    receive,
    receive_bytes,
    send,
    stop,
    usable_cpus,
    write_all,
)

__all__ = ["FigureJob", "FigureRenderer", "Omitted", "default_processes"]

#: drawing processes at most (the machine this is tuned for has two cores)
MAX_PROCESSES = 2

#: seconds a helper may take before the caller gives up on it and draws in-process
TIMEOUT_S = 600.0

#: seconds the helper waits for a drawing process's figure before it stops that process and
#: draws the figure itself (well within the caller's :data:`TIMEOUT_S`)
DRAWER_TIMEOUT_S = TIMEOUT_S / 3

#: seconds the caller waits for its final request to be written before its own work
_HANDOVER_S = 0.05

#: a pickled request larger than this is drawn in-process instead (bytes)
MAX_PAYLOAD_BYTES = 64_000_000

#: Linux prctl option: the signal a process gets when its parent exits
_PR_SET_PDEATHSIG = 1


@dataclass(frozen=True)
class FigureJob:
    """One figure of a report: its file name, a relative cost, and how to draw it.

    ``draw`` returns PNG bytes; ``weight`` is only used to order the jobs (the heaviest is
    drawn first, so the drawing processes finish close together).
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
    return max(1, min(MAX_PROCESSES, usable_cpus()))


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


def _draw(
    jobs: Sequence[FigureJob], which: Sequence[int], parent: int | None = None
) -> dict[str, bytes]:
    """PNG bytes of ``jobs[which]`` by name; with ``parent``, stop if it has gone between them."""
    out = {}
    for i in which:
        if parent is not None and os.getppid() != parent:  # orphaned: nobody will read them
            raise SystemExit(1)
        out[jobs[i].name] = jobs[i].draw()
    return out


def _readable(fd: int) -> bool:
    """Whether ``fd`` has data (or its end of file) to read now."""
    ready, _, _ = select.select([fd], [], [], 0)
    return bool(ready)


def _die_with(parent: int) -> None:
    """Have the kernel kill this process when ``parent`` goes (Linux); exit if it has gone."""
    with contextlib.suppress(Exception):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:
        os._exit(1)


@dataclass
class _Drawer:
    """A forked drawing process: its pid, the pipe of its PNGs, the pipe of its orders.

    ``has_final``: it was forked with the final jobs (else it is sent the final request).
    """

    pid: int
    replies: int
    orders: int
    has_final: bool = False


def _fork_drawer(
    early: Sequence[FigureJob],
    final: Sequence[FigureJob] | None,
    siblings: Sequence[_Drawer] = (),
) -> _Drawer:
    """Fork a process that draws, one at a time, the jobs the helper hands it.

    It asks for a job (``("next",)``, then with each PNG ``("png", kind, index, bytes)``) and
    is answered ``(kind, index, name, request)``: ``early[index]``, or with kind ``"final"``
    the final job ``index``, the final jobs made the first time from ``request`` (the final
    request as the helper received it, pickled) when it was forked before them (``final``
    None); a job not named ``name`` is an error, anything else stops it.  It dies with the
    helper (killed when its caller fails): nothing is left drawing.  The helper's ends of
    the pipes of ``siblings`` (drawing processes forked before) are closed in it.
    """
    r, w = pipe()
    orders_r, orders_w = pipe()
    parent = os.getpid()
    pid = fork()
    if pid == 0:  # the drawing process
        code = 0
        try:
            for fd in (r, orders_w, *(f for d in siblings for f in (d.replies, d.orders))):
                os.close(fd)
            _die_with(parent)
            jobs: dict[str, list[FigureJob] | None] = {
                "early": list(early),
                "final": None if final is None else list(final),
            }
            reply: tuple[Any, ...] = ("next",)
            while True:
                send(w, reply)
                order = receive(orders_r)
                if not isinstance(order, tuple) or order[0] not in jobs:
                    break
                kind, index, name, request = order
                todo = jobs[kind]
                if todo is None:
                    _, make_jobs, payload, *_ = pickle.loads(request)
                    todo = jobs[kind] = make_jobs(payload)
                if todo[index].name != name:
                    raise RuntimeError(f"job {index} is {todo[index].name!r}, not {name!r}")
                reply = ("png", kind, index, _draw(todo, [index], parent).popitem()[1])
        except BaseException:
            code = 1
        finally:
            os._exit(code)
    os.close(w)
    os.close(orders_r)
    return _Drawer(pid, r, orders_w, has_final=final is not None)


def _close(drawer: _Drawer) -> None:
    """Release a drawing process's pipes and reap it (killed if it has not stopped)."""
    for fd in (drawer.replies, drawer.orders):
        with contextlib.suppress(OSError):
            os.close(fd)
    stop(drawer.pid)


class _Queue:
    """The jobs left to draw, taken one at a time by the helper and by its drawing processes.

    The jobs are ``(kind, index)`` into ``jobs[kind]`` (``"early"``, ``"final"``), the
    heaviest first: whoever is free takes the next, so the processes finish within about one
    figure of each other whatever each job costs.  A thread of the helper serves each drawing
    process (:meth:`serve`); the lock is the condition's.
    """

    def __init__(self, early: list[FigureJob]) -> None:
        self.cond = threading.Condition()
        self.jobs: dict[str, list[FigureJob]] = {"early": early, "final": []}
        self.todo: list[tuple[str, int]] = self._heaviest_first("early", range(len(early)))
        self.drawn: dict[tuple[str, int], bytes] = {}
        self.busy: dict[int, tuple[str, int] | None] = {}  # drawer pid -> its job
        self.final_request: bytes | None = None  # the pickled final request, once it came
        self.closed = False  # no more jobs will come: a free drawer stops
        self.reuse = False  # whether the final request takes early figures
        self.final_names: set[str] = set()

    def _heaviest_first(self, kind: str, which: Any) -> list[tuple[str, int]]:
        jobs = self.jobs[kind]
        return [(kind, i) for i in sorted(which, key=lambda i: -jobs[i].weight)]

    def set_final(self, final: list[FigureJob], raw: bytes, reuse: bool) -> None:
        """The final jobs: those not among the early ones (all of them without ``reuse``)."""
        with self.cond:
            early = self.jobs["early"]
            names = {j.name for j in final}
            if reuse:  # the early jobs still wanted, then the final jobs not drawn early
                self.todo = [t for t in self.todo if early[t[1]].name in names]
                skip = {j.name for j in early}
            else:  # the early figures are not used: none is drawn any more
                self.todo, skip = [], set()
            self.jobs["final"] = final
            wanted = [i for i, j in enumerate(final) if j.name not in skip]
            self.todo = sorted(
                self.todo + self._heaviest_first("final", wanted),
                key=lambda t: -self.jobs[t[0]][t[1]].weight,
            )
            self.final_request = raw
            self.reuse, self.final_names = reuse, names
            self.closed = True
            self.cond.notify_all()

    def wanted(self, job: tuple[str, int] | None) -> bool:
        """Whether the final reply needs ``job``'s figure (an early one it does not: no)."""
        if job is None:
            return False
        kind, i = job
        return kind == "final" or (self.reuse and self.jobs["early"][i].name in self.final_names)

    def take(self, pid: int) -> tuple[str, int] | None:
        """The next job for ``pid`` (0: the helper); None when none is left."""
        with self.cond:
            while not self.todo and not self.closed:
                self.cond.wait()
            job = self.todo.pop(0) if self.todo else None
            self.busy[pid] = job
            return job

    def done(self, pid: int, job: tuple[str, int] | None, png: bytes | None) -> None:
        """Record ``pid``'s figure (None: it failed, or it is gone)."""
        with self.cond:
            if job is not None and png is not None:
                self.drawn[job] = png
            self.busy[pid] = None
            self.cond.notify_all()

    def serve(self, drawer: _Drawer) -> None:
        """Hand ``drawer`` its jobs, one at a time, until none is left or it is gone."""
        sent_final = drawer.has_final
        job: tuple[str, int] | None = None
        try:
            while True:
                reply = receive(drawer.replies, time.monotonic() + DRAWER_TIMEOUT_S, drawer.pid)
                if not isinstance(reply, tuple):
                    break  # it died or hangs (its job is drawn by the helper)
                if reply[0] == "png":
                    self.done(drawer.pid, (reply[1], reply[2]), reply[3])
                job = self.take(drawer.pid)
                if job is None:
                    break
                request = None
                if job[0] == "final" and not sent_final:
                    request, sent_final = self.final_request, True
                send(drawer.orders, (*job, self.jobs[job[0]][job[1]].name, request))
        except BaseException:  # a drawer that is gone: what it held is drawn by the helper
            pass
        finally:
            with contextlib.suppress(OSError):
                send(drawer.orders, ("stop",))
            self.done(drawer.pid, None, None)

    def wait_idle(self, idle: Callable[[], None]) -> list[int]:
        """Wait until no drawing process holds a wanted job; those holding another job.

        ``idle()`` runs first if one holds a wanted job.  A drawing process that does not
        answer within :data:`DRAWER_TIMEOUT_S` is given up (its figure is drawn here).
        """

        def left() -> bool:
            return any(self.wanted(job) for pid, job in self.busy.items() if pid)

        with self.cond:
            need = left()
        if need:
            idle()
            with self.cond:
                self.cond.wait_for(lambda: not left(), DRAWER_TIMEOUT_S + 1.0)
        with self.cond:
            return [pid for pid, job in self.busy.items() if pid and job is not None]


def _serve(queue: _Queue, drawer: _Drawer) -> threading.Thread:
    """A started thread handing ``drawer`` its jobs from ``queue`` (:meth:`_Queue.serve`)."""
    server = threading.Thread(target=queue.serve, args=(drawer,), daemon=True)
    server.start()
    return server


def _helper(
    preload: Sequence[str],
    then: Sequence[str],
    warm: Callable[[], object] | None,
    requests: int,
    replies: int,
    processes: int,
) -> None:
    """The helper process: load, warm up, load more; draw the early request; answer the final.

    Requests are ``(kind, make_jobs, payload, finish, reuse)``.  The first ``"early"``
    request's jobs go to a forked drawing process at once, while the caller still computes
    (one whose jobs cannot be made is ignored: the final one draws them).  The ``"final"``
    request is answered with its jobs' figures, each drawn once: with ``reuse``, a job named
    as an early one takes the early figure (the caller has checked that the early request
    was made from the same values); without, the early figures are not used.  The jobs left
    are taken one at a time, heaviest first, by this process and the drawing processes
    (:class:`_Queue`; with no early request, ``processes - 1`` are forked then).  The final
    request's ``finish`` (if any) makes more files from its payload and the figures.  The
    reply names the figures taken from the early request.
    """
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
        for name in then:
            importlib.import_module(name)
        warmed = warm is None

        def warm_now() -> None:
            """The ``warm`` step, once, when nothing else waits (its errors are ignored)."""
            nonlocal warmed
            if not warmed:
                warmed = True
                with contextlib.suppress(Exception):
                    warm()  # type: ignore[misc]

        queue: _Queue | None = None
        drawers: list[_Drawer] = []
        servers: list[threading.Thread] = []
        final: list[FigureJob] | None = None
        final_raw = b""
        while final is None:
            if queue is None and not warmed and not _readable(requests):
                # no request waiting: the time is free (once the early jobs are drawing, the
                # final request comes soon: the warm step waits for an idle moment then)
                warm_now()
                continue
            raw = receive_bytes(requests)
            if raw is None:  # the caller finished without (more) figures
                return
            kind, make_jobs, payload, finish, reuse = pickle.loads(raw)
            if kind == "final":
                final, final_raw = make_jobs(payload), raw
            elif queue is None:
                with contextlib.suppress(Exception):
                    jobs: list[FigureJob] = make_jobs(payload)
                    if jobs:
                        # a thread serves it from now on: this process forks no more
                        drawers = [_fork_drawer(jobs, None)]
                        queue = _Queue(jobs)
                        servers = [_serve(queue, drawers[0])]
        if queue is None:  # no early request: drawing processes for the final jobs
            queue = _Queue([])
            for _ in range(processes - 1):
                drawers.append(_fork_drawer([], final, drawers))
            servers = [_serve(queue, d) for d in drawers]  # threads once all are forked
        queue.set_final(final, final_raw, bool(reuse))
        # a drawing process waiting for its next job waits for the GIL of this one, which
        # draws meanwhile: hand it over within 1 ms, not the default 5 ms
        sys.setswitchinterval(0.001)
        while (job := queue.take(0)) is not None:
            png = None
            try:
                png = _draw(queue.jobs[job[0]], [job[1]]).popitem()[1]
            except Exception:
                if job[0] != "early":
                    raise
                # an early job that fails is drawn again from the final request below
            queue.done(0, job, png)
        # the warm step (for the finish step) while the last figures are drawn
        unwanted = queue.wait_idle(warm_now if finish is not None else lambda: None)
        for pid in unwanted:  # drawing an early figure the reply does not use
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        for server in servers:
            server.join(DRAWER_TIMEOUT_S + 1.0)
        for drawer in drawers:
            _close(drawer)
        drawn: dict[str, bytes] = {}
        taken: set[str] = set()  # the figures taken from the early request
        for (kind, i), png in queue.drawn.items():
            if kind == "final":
                drawn[final[i].name] = png
            elif reuse:
                drawn[queue.jobs["early"][i].name] = png
                taken.add(queue.jobs["early"][i].name)
        missing = [j for j in final if j.name not in drawn]  # a drawer failed: drawn here
        drawn.update(_draw(missing, range(len(missing))))
        pngs = {j.name: drawn[j.name] for j in final}
        extra = finish(payload, pngs) if finish is not None else {}
        send(replies, ("ok", pngs, extra, sorted(taken & set(pngs))))
    except BaseException:
        status = 1
        with contextlib.suppress(BaseException):
            send(replies, ("error", traceback.format_exc()))
    finally:
        os._exit(status)


# ----------------------------------------------------------------------------- caller side


class Omitted:
    """What a helper receives in place of an object its request omits (see ``omit``)."""

    def __init__(self, kind: str) -> None:
        self.kind = kind

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        raise AttributeError(f"a {self.kind} was omitted from the figure request ({name!r} read)")

    def __reduce__(self) -> tuple[Any, ...]:
        return (Omitted, (self.kind,))


class _OmittingPickler(pickle.Pickler):
    """A pickler that writes :class:`Omitted` for the objects ``omit`` selects."""

    def __init__(
        self,
        file: io.BytesIO,
        omit: Callable[[object], bool],
        buffer_callback: Callable[[pickle.PickleBuffer], object] | None = None,
    ) -> None:
        super().__init__(file, protocol=5, buffer_callback=buffer_callback)
        self._omit = omit

    def reducer_override(self, obj: Any) -> Any:
        if self._omit(obj):
            return (Omitted, (type(obj).__name__,))
        return NotImplemented


def _pickled_size(obj: Any, omit: Callable[[object], bool] | None) -> int:
    """The bytes ``_dumps(obj, omit)`` would make, counted without copying large arrays.

    Protocol 5 hands contiguous buffers (numpy arrays) to a callback instead of copying
    them: a 193-MB result is measured in milliseconds, not pickled to be refused.
    """
    buffers: list[pickle.PickleBuffer] = []
    buf = io.BytesIO()
    pickler = _OmittingPickler(buf, omit or (lambda _o: False), buffers.append)
    pickler.dump(obj)
    return buf.tell() + sum(b.raw().nbytes for b in buffers)


def _dumps(obj: Any, omit: Callable[[object], bool] | None) -> bytes:
    """``obj`` pickled, with the objects ``omit`` selects replaced by :class:`Omitted`."""
    if omit is None:
        return pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    buf = io.BytesIO()
    _OmittingPickler(buf, omit).dump(obj)
    return buf.getvalue()


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
        self._sender: threading.Thread | None = None
        self._too_large = False  # a request was refused for its size: so would the next
        self.early_payload: Any = None  #: the payload of the early request sent, if any
        self.early_used: list[str] = []  #: the figures the final answer took from it
        self.error: str | None = None  #: why the helper failed, if it did

    @property
    def active(self) -> bool:
        """Whether a helper process is running."""
        return self._pid is not None

    @classmethod
    def start(
        cls,
        preload: Sequence[str] = (),
        processes: int | None = None,
        then: Sequence[str] = (),
        warm: Callable[[], object] | None = None,
        shared: Sequence[str] = (),
    ) -> FigureRenderer:
        """Fork the helper now, which imports ``preload`` (module names) and waits.

        Parameters
        ----------
        preload : sequence of str
            Modules the helper imports while the caller computes, before it warms up.
        processes : int, optional
            Drawing processes (default :func:`default_processes`); 1 starts no helper.
        then : sequence of str
            Modules the helper imports after its warm-up (e.g. those the request unpickles
            with, which the caller imports while it computes).
        warm : callable, optional
            Called in the helper after those imports, when no request waits (e.g. loading
            a template that a ``finish`` step uses); its errors are ignored.
        shared : sequence of str
            Modules that both the caller and the helper will use: imported here, before
            the fork, so that the two processes pay for them once (a module that this
            process loads lazily is executed now).  Only when a helper starts.
        """
        n = default_processes() if processes is None else max(1, int(processes))
        if n < 2 or not can_fork():
            return cls(None, None, None)  # draw in-process
        for name in shared:
            module = importlib.import_module(name)
            getattr(module, "__name__", None)  # a lazily loaded module runs its code now
        req_r, req_w = pipe()
        rep_r, rep_w = pipe()
        try:
            pid = fork()
        except OSError:
            for fd in (req_r, req_w, rep_r, rep_w):
                os.close(fd)
            return cls(None, None, None)
        if pid == 0:
            os.close(req_w)
            os.close(rep_r)
            _helper(preload, then, warm, req_r, rep_w, n)  # never returns
        os.close(req_r)
        os.close(rep_w)
        return cls(pid, req_w, rep_r)

    def _post(self, data: bytes) -> None:
        """Write a request to the helper from a thread, in the order of the requests.

        A helper still importing or drawing reads it later, and the caller goes on.
        """
        fd, before = self._requests, self._sender
        if fd is None:
            return

        def run() -> None:
            if before is not None:
                before.join()
            with contextlib.suppress(OSError):  # a helper that died: render() sees it
                write_all(fd, data)

        self._sender = threading.Thread(target=run, name="microg-figure-request", daemon=True)
        self._sender.start()

    def _request(
        self,
        kind: str,
        make_jobs: Callable[[Any], list[FigureJob]],
        payload: Any,
        omit: Any,
        finish: Any = None,
        reuse: bool = False,
    ) -> bool:
        """Send one request; whether it went (else :attr:`error` says why, when it matters)."""
        if self._too_large:
            return False
        request = (kind, make_jobs, payload, finish, reuse)
        try:
            size = _pickled_size(request, omit)
            if size <= MAX_PAYLOAD_BYTES:
                data = _dumps(request, omit)
        except Exception as exc:  # e.g. a payload that does not pickle
            self.error = f"{type(exc).__name__}: {exc}"
            return False
        if size > MAX_PAYLOAD_BYTES:
            # a large model's result (issue 11: 193 MB of mode shapes): copying it through
            # the pipe and unpickling it costs more than drawing here saves
            self._too_large = True
            self.error = f"the request is {size / 1e6:.0f} MB: drawn in-process"
            return False
        self._post(data)
        return True

    def draw_early(
        self,
        make_jobs: Callable[[Any], list[FigureJob]],
        payload: Any,
        omit: Callable[[object], bool] | None = None,
    ) -> bool:
        """Have the helper draw ``make_jobs(payload)``'s figures now, for :meth:`render`.

        The figures are drawn while the caller goes on; :meth:`render` then answers a job of
        the same name with the early figure, without drawing it again: a caller sends early
        only figures that its final jobs would draw the same.

        Parameters
        ----------
        make_jobs, payload, omit
            As for :meth:`render`.

        Returns
        -------
        bool
            Whether the request went (False: no helper, an early request sent already, or a
            payload that does not pickle or is too large; :meth:`render` then draws those
            figures with the others).  The payload sent is kept as :attr:`early_payload`,
            for the caller to check that its final request is made from the same values.
        """
        if self._pid is None or self._requests is None or self.early_payload is not None:
            return False
        sent = self._request("early", make_jobs, payload, omit)
        if sent:
            self.early_payload = payload
        return sent

    def render(
        self,
        make_jobs: Callable[[Any], list[FigureJob]],
        payload: Any,
        while_waiting: Callable[[], object] | None = None,
        omit: Callable[[object], bool] | None = None,
        finish: Callable[[Any, dict[str, bytes]], dict[str, Any]] | None = None,
        reuse_early: bool = False,
    ) -> dict[str, Any] | None:
        """The PNG bytes of ``make_jobs(payload)``'s figures, drawn by the helpers.

        Parameters
        ----------
        make_jobs : callable
            A module-level function (it is pickled by name) from the payload to the jobs.
        payload : object
            Sent to the helper pickled.
        while_waiting : callable, optional
            Work the caller does while the helpers draw (e.g. loading the HTML template).
        omit : callable, optional
            Objects of the payload for which it is true are sent as :class:`Omitted`
            stand-ins: what no figure reads, and whose classes would cost the helper an
            import (a structure's sparse matrices: scipy).  A figure that reads one fails,
            and the figures are drawn in-process instead.
        finish : callable, optional
            A module-level function (pickled by name), called in the helper with the
            payload and the figures once all are drawn: more files (name -> text or bytes)
            to return with them (e.g. the HTML page that embeds the figures).
        reuse_early : bool
            Take the figures of the early request (:meth:`draw_early`) for the final jobs of
            the same names; the caller says so only when both requests come from the same
            values (else the early figures are dropped and all are drawn).

        Returns
        -------
        dict of str to bytes, or None
            The figures' PNG bytes by name, and the files ``finish`` made; None when no
            helper runs or it failed: the caller then does it all in-process.
        """
        if self._pid is None or self._requests is None or self._replies is None:
            return None
        if not self._request("final", make_jobs, payload, omit, finish, reuse_early):
            self.close()
            return None
        if self._sender is not None:
            # a waiting helper reads the request at once: let the write finish before the
            # caller's own work (which would hold the GIL between the writer's chunks, ~15
            # ms for a 3-MB request); a busy helper reads it later, and the caller goes on
            self._sender.join(_HANDOVER_S)
        if while_waiting is not None:
            while_waiting()
        reply = receive(self._replies, time.monotonic() + TIMEOUT_S, self._pid)
        self.close()
        if isinstance(reply, tuple) and reply[0] == "ok":
            self.early_used = list(reply[3])
            return {**reply[1], **reply[2]}
        self.error = reply[1] if isinstance(reply, tuple) else "the helper process stopped"
        return None

    def close(self) -> None:
        """Stop the helper (if it still runs) and release its pipes."""
        pid, self._pid = self._pid, None
        if pid is not None:
            # a helper that replied is exiting; one that never got work is killed at once
            # (it holds nothing: an error exit must not wait for its imports)
            stop(pid)
        sender, self._sender = self._sender, None
        if sender is not None:
            # done, or failing now that the helper is gone: its descriptor closes after it
            sender.join()
        for attr in ("_requests", "_replies"):
            fd = getattr(self, attr)
            if fd is not None:
                with contextlib.suppress(OSError):
                    os.close(fd)
                setattr(self, attr, None)

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
