"""A call computed in a forked child process while the caller does other work.

The ``microg`` command runs one job per process, most of it spent importing (issue 8,
"Speed of the main job"): loading a station model imports pydantic and validates the TOML
(~0.15 s), while discretising it imports scipy (~0.15 s).  :class:`Forked` runs the first in
a child process on the second core while the caller imports the second, and returns the
child's result, pickled through a pipe.

The result is the call's, or nothing: whatever goes wrong in the child (an exception, a
warning, a result that does not pickle, a child that dies or outlives the timeout) makes
:meth:`Forked.result` compute the call in the caller instead, where it raises or warns as it
always does.  No fork happens without ``os.fork``, on one CPU, or with other threads running
(a fork copies only the calling thread).  The framing (length-prefixed pickles) and the
checks on the child's life are shared with the figure helpers (:mod:`microg.report.render`).
"""

from __future__ import annotations

import contextlib
import os
import pickle
import select
import signal
import struct
import sys
import threading
import time
import warnings
from collections.abc import Callable
from types import TracebackType
from typing import Any

__all__ = [
    "Forked",
    "can_fork",
    "exited",
    "fork",
    "pipe",
    "receive",
    "receive_bytes",
    "send",
    "stop",
    "usable_cpus",
    "write_all",
]

_HEADER = struct.Struct("<Q")

#: seconds the caller waits for a child's result before computing it itself
TIMEOUT_S = 120.0


def usable_cpus() -> int:
    """The CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def can_fork() -> bool:
    """Whether a fork is possible and safe here: ``os.fork`` exists and no other thread runs."""
    return hasattr(os, "fork") and threading.active_count() == 1


def fork() -> int:
    """``os.fork`` with the standard streams flushed first (their buffers are not copied twice).

    Raises OSError when the system refuses.
    """
    sys.stdout.flush()
    sys.stderr.flush()
    with warnings.catch_warnings():
        # Python >= 3.12 warns of fork with threads running: BLAS's idle pool, which
        # OpenBLAS stops and restarts around a fork itself (pthread_atfork)
        warnings.simplefilter("ignore", DeprecationWarning)
        return os.fork()


#: the pipe buffer asked for (Linux ``F_SETPIPE_SZ``; 1 MiB is the default ceiling of
#: /proc/sys/fs/pipe-max-size): a request of a few MB then goes in a few writes, not ~50
PIPE_BYTES = 1 << 20


def pipe() -> tuple[int, int]:
    """``os.pipe()``, with a larger buffer where the system allows it (best effort)."""
    r, w = os.pipe()
    try:
        import fcntl

        fcntl.fcntl(w, getattr(fcntl, "F_SETPIPE_SZ", 1031), PIPE_BYTES)
    except (ImportError, OSError):
        pass  # the default buffer (64 KiB): slower, the same bytes
    return r, w


def send(fd: int, obj: Any) -> None:
    """Write ``obj`` pickled to ``fd``, framed by its length."""
    write_all(fd, pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL))


def write_all(fd: int, data: bytes) -> None:
    """``data`` (pickled bytes) written whole to ``fd``, framed by its length."""
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
                if pid is not None and exited(pid):
                    # the child died; whatever it wrote is still readable
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


def receive_bytes(fd: int, deadline: float | None = None, pid: int | None = None) -> bytes | None:
    """One framed pickle from ``fd``, still pickled; None as :func:`receive` says."""
    head = _read_exact(fd, _HEADER.size, deadline, pid)
    if head is None:
        return None
    return _read_exact(fd, _HEADER.unpack(head)[0], deadline, pid)


def receive(fd: int, deadline: float | None = None, pid: int | None = None) -> Any:
    """One framed pickle from ``fd``, unpickled; None at end of file, timeout or ``pid``'s death.

    Parameters
    ----------
    fd : int
        The pipe's read end.
    deadline : float, optional
        ``time.monotonic()`` after which to give up.
    pid : int, optional
        The writer, whose death ends the wait.
    """
    body = receive_bytes(fd, deadline, pid)
    return None if body is None else pickle.loads(body)


def exited(pid: int) -> bool:
    """Whether child ``pid`` has exited (reaping it if so)."""
    try:
        done, _ = os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return done == pid


def stop(pid: int, grace_s: float = 0.05) -> None:
    """Reap child ``pid``: wait up to ``grace_s`` for it to exit, then kill it."""
    deadline = time.monotonic() + grace_s
    while not exited(pid):
        if time.monotonic() > deadline:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
            with contextlib.suppress(ChildProcessError):
                os.waitpid(pid, 0)
            return
        time.sleep(0.002)


def _child(fd: int, fn: Callable[..., Any], args: tuple, kwargs: dict[str, Any]) -> None:
    """The child: compute, send ("ok", value) or ("redo",), exit without cleanup."""
    code = 0
    try:
        with warnings.catch_warnings(record=True) as caught:
            value = fn(*args, **kwargs)
        # a warning is the caller's to show, in its place: the caller computes it again
        send(fd, ("redo",) if caught else ("ok", value))
    except BaseException:
        code = 1
        with contextlib.suppress(BaseException):
            send(fd, ("redo",))
    finally:
        os._exit(code)


class Forked:
    """``fn(*args, **kwargs)`` computed in a forked child while the caller goes on.

    Use as a context manager, so that the child is stopped if the caller fails first::

        with Forked.start(load_model, "ioc") as pending:
            import scipy.linalg          # meanwhile
            model = pending.result()     # the child's result, or computed here
    """

    def __init__(
        self,
        fn: Callable[..., Any],
        args: tuple,
        kwargs: dict[str, Any],
        pid: int | None,
        fd: int | None,
    ) -> None:
        self._call = (fn, args, kwargs)
        self._pid = pid
        self._fd = fd
        self.forked = pid is not None  #: whether a child was started
        self.computed_here = False  #: whether :meth:`result` computed the call itself

    @classmethod
    def start(cls, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Forked:
        """Fork a child computing ``fn(*args, **kwargs)`` now (when safe; see the module doc).

        ``fn`` must be a module-level function whose result pickles; the call must depend
        only on its arguments and the files it reads (it runs in a copy of this process).
        """
        if usable_cpus() < 2 or not can_fork():
            return cls(fn, args, kwargs, None, None)
        r, w = pipe()
        try:
            pid = fork()
        except OSError:
            os.close(r)
            os.close(w)
            return cls(fn, args, kwargs, None, None)
        if pid == 0:
            os.close(r)
            _child(w, fn, args, kwargs)  # never returns
        os.close(w)
        return cls(fn, args, kwargs, pid, r)

    def result(self, timeout_s: float = TIMEOUT_S) -> Any:
        """The call's result: the child's, or computed here when the child has none.

        Parameters
        ----------
        timeout_s : float
            Seconds to wait for the child before computing the call here.
        """
        reply = None
        if self._fd is not None:
            try:
                reply = receive(self._fd, time.monotonic() + timeout_s, self._pid)
            except Exception:  # a reply that does not unpickle here
                reply = None
        self.close()
        if isinstance(reply, tuple) and len(reply) == 2 and reply[0] == "ok":
            return reply[1]
        fn, args, kwargs = self._call
        self.computed_here = True
        return fn(*args, **kwargs)

    def close(self) -> None:
        """Stop the child (if it still runs) and release its pipe."""
        fd, self._fd = self._fd, None
        if fd is not None:
            with contextlib.suppress(OSError):
                os.close(fd)
        pid, self._pid = self._pid, None
        if pid is not None:
            stop(pid)

    def __enter__(self) -> Forked:
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
