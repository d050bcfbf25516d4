"""Figures rendered in helper processes that load matplotlib while the caller computes.

``microg analyze`` spends more time importing matplotlib and drawing its figures than
computing (issue 8, "Speed of the main job").  A :class:`FigureRenderer` started before the
computation forks one helper process, which imports the plotting modules (and warms the font
cache, and loads what a ``warm`` step asks, e.g. the HTML template) on another core while
the caller computes.  The caller may send an early request as soon as some figures can be
drawn (:meth:`FigureRenderer.draw_early`: the model's, once its modes are solved); the
helper forks an early drawer for them.  When the result is ready the caller sends it
(:meth:`FigureRenderer.render`); the helper and the early drawer (or a second fork) share
its figures, and a ``finish`` step may make more files from them (the HTML page).  The
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

__all__ = ["FigureJob", "FigureRenderer", "Omitted", "default_processes", "split_jobs"]

#: drawing processes at most (the machine this is tuned for has two cores)
MAX_PROCESSES = 2

#: seconds a helper may take before the caller gives up on it and draws in-process
TIMEOUT_S = 600.0

#: a pickled request larger than this is drawn in-process instead (bytes)
MAX_PAYLOAD_BYTES = 64_000_000

#: Linux prctl option: the signal a process gets when its parent exits
_PR_SET_PDEATHSIG = 1


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
    return max(1, min(MAX_PROCESSES, usable_cpus()))


def split_jobs(
    weights: Sequence[float], parts: int, loads: Sequence[float] | None = None
) -> list[list[int]]:
    """Indices of ``weights`` shared into ``parts`` groups of nearly equal total weight.

    Longest first, each into the lightest group so far (the LPT rule), counting the work
    each group has already (``loads``, default none); each group keeps the order of the
    input.  Without ``loads`` the empty groups are dropped; with them the groups keep their
    places (group k is the one that had ``loads[k]``).
    """
    n = max(1, parts) if loads is None else len(loads)
    groups: list[list[int]] = [[] for _ in range(n)]
    load = [0.0] * n if loads is None else [float(x) for x in loads]
    for i in sorted(range(len(weights)), key=lambda k: -weights[k]):
        g = min(range(n), key=lambda k: load[k])
        groups[g].append(i)
        load[g] += weights[i]
    out = [sorted(g) for g in groups]
    return out if loads is not None else [g for g in out if g]


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
    """A forked drawing process, the pipe of its replies, and its pipe for a second batch.

    Only the early drawer has the second pipe (``more``): it waits on it for a share of
    the final jobs once its own are drawn.
    """

    pid: int
    replies: int
    more: int | None = None


def _fork_drawer(jobs: Sequence[FigureJob], which: Sequence[int], more: bool = False) -> _Drawer:
    """Fork a process that draws ``jobs[which]`` and sends back their PNGs.

    With ``more`` it then waits for a second batch from the helper: ``("draw", request,
    names)``, a final request as the helper received it (pickled) and the names of its
    jobs to draw, or anything else to stop.  It dies with the helper (killed when its
    caller fails): nothing is left drawing.
    """
    r, w = pipe()
    more_r, more_w = pipe() if more else (None, None)
    parent = os.getpid()
    pid = fork()
    if pid == 0:  # the drawing process
        code = 0
        try:
            os.close(r)
            if more_w is not None:
                os.close(more_w)
            _die_with(parent)
            send(w, ("ok", _draw(jobs, which, parent)))
            if more_r is not None:
                batch = receive(more_r)
                if isinstance(batch, tuple) and batch[0] == "draw":
                    _, make_jobs, payload, *_ = pickle.loads(batch[1])
                    final = make_jobs(payload)
                    names = set(batch[2])
                    which = [k for k, j in enumerate(final) if j.name in names]
                    send(w, ("ok", _draw(final, which, parent)))
        except BaseException:
            code = 1
        finally:
            os._exit(code)
    os.close(w)
    if more_r is not None:
        os.close(more_r)
    return _Drawer(pid, r, more_w)


def _send_quietly(fd: int, obj: Any) -> None:
    """:func:`send`, with a reader that has gone ignored (its figures are drawn anyway)."""
    with contextlib.suppress(OSError):
        send(fd, obj)


def _discard(drawer: _Drawer) -> None:
    """Stop a drawing process whose figures are not wanted, and reap it."""
    with contextlib.suppress(ProcessLookupError):
        os.kill(drawer.pid, signal.SIGKILL)
    _close(drawer)


def _close(drawer: _Drawer) -> None:
    for fd in (drawer.replies, drawer.more):
        if fd is not None:
            with contextlib.suppress(OSError):
                os.close(fd)
    with contextlib.suppress(ChildProcessError):
        os.waitpid(drawer.pid, 0)


def _reply(drawer: _Drawer) -> dict[str, bytes] | None:
    """A drawing process's next batch of PNGs; None if it failed or stopped."""
    reply = receive(drawer.replies, time.monotonic() + TIMEOUT_S, drawer.pid)
    return dict(reply[1]) if isinstance(reply, tuple) and reply[0] == "ok" else None


def _collect(drawer: _Drawer) -> dict[str, bytes] | None:
    """A drawing process's PNGs (None if it failed), once it has sent them; reaps it."""
    pngs = _reply(drawer)
    _close(drawer)
    return pngs


#: the share of its work an early drawer still has when the final request comes (a guess,
#: to balance the final jobs: the final request comes ~0.1 s into its ~0.25 s)
_EARLY_LEFT = 0.5


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
    request's jobs are drawn at once by a forked drawing process, while the caller still
    computes (one whose jobs cannot be made is ignored: the final one draws them).  The
    ``"final"`` request is answered with its jobs' figures, each drawn once: with ``reuse``,
    a job named as an early one takes the early figure (the caller has checked that the
    early request was made from the same values); without, the early drawer is stopped.
    The other final jobs are shared between this process and the early drawer, once it is
    done with its own (by the LPT rule, counting what it has left), or with ``processes -
    1`` more forks when there was none.  The final request's ``finish`` (if any) makes
    more files from its payload and the figures.  The reply names the figures taken from
    the early request.
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
        warmed = False
        early: _Drawer | None = None  # the early drawer
        early_jobs: list[FigureJob] = []
        final: list[FigureJob] | None = None
        while final is None:
            if warm is not None and not warmed and not _readable(requests):
                # no request waiting (or the early drawer just started): the time is free
                warmed = True
                with contextlib.suppress(Exception):
                    warm()
                continue
            raw = receive_bytes(requests)
            if raw is None:  # the caller finished without (more) figures
                return
            kind, make_jobs, payload, finish, reuse = pickle.loads(raw)
            if kind == "final":
                final = make_jobs(payload)
            elif early is None:
                with contextlib.suppress(Exception):
                    jobs: list[FigureJob] = make_jobs(payload)
                    if jobs:
                        early = _fork_drawer(jobs, range(len(jobs)), more=True)
                        early_jobs = jobs
        if early is not None and not reuse:
            _discard(early)
            early = None
        drawn: dict[str, bytes] = {}
        done = False  # whether the early figures are in
        if early is not None and _readable(early.replies):
            done = True
            drawn.update(_reply(early) or {})
        taken = set(drawn)
        busy = {j.name for j in early_jobs} if early is not None and not done else set()
        todo = [j for j in final if j.name not in drawn and j.name not in busy]
        weights = [j.weight for j in todo]
        children: list[_Drawer] = []
        sender: threading.Thread | None = None
        if early is not None and early.more is not None:
            # the early drawer takes a share of the final jobs once it is free: this process
            # draws its own share, and between its figures hands the drawer its share if it
            # has finished its own figures, or takes the share back if this one is idle first
            left = 0.0 if done else _EARLY_LEFT * sum(j.weight for j in early_jobs)
            mine, theirs = split_jobs(weights, 2, loads=[0.0, left])
            queue = list(mine)
            sent = False
            while queue or (theirs and not sent):
                if theirs and not sent and (done or _readable(early.replies)):
                    if not done:  # its own figures (a failure: drawn below)
                        late = _reply(early) or {}
                        drawn.update({k: v for k, v in late.items() if k not in drawn})
                        taken |= set(late)
                        done = True
                    # from a thread: a large request fills the pipe, and this process goes
                    # on drawing (it forks no more: a thread is safe here)
                    batch = ("draw", raw, [todo[i].name for i in theirs])
                    sender = threading.Thread(target=_send_quietly, args=(early.more, batch))
                    sender.start()
                    sent = True
                elif queue:
                    drawn.update(_draw(todo, [queue.pop(0)]))
                else:  # idle while the drawer is still busy: its share is drawn here
                    queue, theirs = list(theirs), []
            if not sent:
                _send_quietly(early.more, ("stop",))
            if not done:
                late = _reply(early) or {}
                drawn.update({k: v for k, v in late.items() if k not in drawn})
                taken |= set(late)
            if sent:
                drawn.update(_reply(early) or {})  # its share (a failure: drawn below)
                if sender is not None:
                    sender.join()  # done, or failed on a drawer that is gone
            _close(early)
        else:
            groups = split_jobs(weights, processes) or [[]]
            children = [_fork_drawer(todo, g) for g in groups[1:]]
            drawn.update(_draw(todo, groups[0]))
            for child in children:
                pngs = _collect(child)
                if pngs is None:
                    raise RuntimeError("a drawing process failed")
                drawn.update(pngs)
        missing = [j for j in final if j.name not in drawn]
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
        """
        n = default_processes() if processes is None else max(1, int(processes))
        if n < 2 or not can_fork():
            return cls(None, None, None)  # draw in-process
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
