"""Forked worker processes that run numbered tasks, with a bounded number in flight.

The parent sends task numbers (never task data: a worker is forked with
everything it needs) and reads the results back in task order.  Each worker
holds at most ``in_flight`` tasks not yet consumed, so a slow reader stops
the workers instead of letting them run ahead without limit.

A pool never starts more processes than it has tasks, nor more than
:func:`pool_size`'s cap (4 per core, at most :data:`MAX_WORKERS`), however
many are asked for: each costs a fork, three descriptors and its memory.

Faults end a run instead of hanging it: a worker that dies (killed, out of
memory, a bus error on a memory-mapped file) raises :class:`WorkerDied` in
the parent as soon as the parent next waits; workers ignore SIGINT, SIGTERM
and SIGHUP, which are the parent's to handle, and are stopped with SIGKILL
when the pool closes early; a worker dies with its parent.
"""

from __future__ import annotations

import os
import signal
from collections import deque
from collections.abc import Callable, Iterator
from typing import Any

from .signals import STOP_SIGNALS, signals_blocked

__all__ = ["MAX_WORKERS", "Pool", "WorkerDied", "WorkerFailed", "pool_size"]

_PR_SET_PDEATHSIG = 1

#: The most processes a pool starts, whatever the machine.
MAX_WORKERS = 64


def pool_size(workers: int, tasks: int | None = None) -> int:
    """How many processes a pool asked for ``workers`` starts for ``tasks`` tasks
    (None: not known yet): at least one, at most ``tasks``, and at most 4 per
    core and :data:`MAX_WORKERS`, beyond which more processes only queue for
    the cores.

    >>> pool_size(10_000, tasks=3), pool_size(2, tasks=100), pool_size(0)
    (3, 2, 1)
    """
    cap = min(MAX_WORKERS, 4 * (os.cpu_count() or 1))
    return max(1, min(workers, cap, workers if tasks is None else tasks))


#: What a signal that kills a worker usually means.
_CAUSES = {
    signal.SIGKILL: "killed; the system may be out of memory",
    signal.SIGBUS: "bus error; a memory-mapped input file changed or shrank while it was read",
    signal.SIGSEGV: "segmentation fault",
}


class WorkerDied(Exception):
    """A worker process ended before its work was done."""

    def __init__(self, pid: int, exitcode: int | None):
        self.pid = pid
        self.exitcode = exitcode
        if exitcode is not None and exitcode < 0:
            sig = signal.Signals(-exitcode)
            how = f"was stopped by {sig.name} ({_CAUSES.get(sig, signal.strsignal(sig) or 'signal')})"
        else:
            how = f"ended unexpectedly (exit status {exitcode})"
        super().__init__(f"worker process {pid} {how}")


class WorkerFailed(Exception):
    """A task raised in a worker; the message names the exception, a note holds its traceback."""


class Pool:
    """Forked processes running ``task(i)`` (``workers`` of them, capped by
    :func:`pool_size`); results in order by :meth:`results`.

    Use as a context manager: leaving it normally lets the workers exit;
    leaving it by an exception (a signal, a dead worker) kills them.

    >>> with Pool(lambda i: i * i, workers=2) as pool:
    ...     list(pool.results(5))
    [0, 1, 4, 9, 16]
    """

    def __init__(self, task: Callable[[int], Any], workers: int, in_flight: int = 2):
        from multiprocessing.connection import Pipe

        self._in_flight = max(1, in_flight)
        self._workers: list[_Worker] = []
        try:
            for _ in range(pool_size(workers)):
                here, there = Pipe()
                # the child closes the parent's ends it inherits: a copy there would hide their end-of-file
                self._workers.append(_Worker.fork(task, there, [w.conn for w in self._workers] + [here]))
                self._workers[-1].conn = here
        except BaseException:
            self.close(wait=False)
            raise

    @property
    def size(self) -> int:
        """The number of worker processes."""
        return len(self._workers)

    def results(self, count: int) -> Iterator[Any]:
        """``task(0)``, ..., ``task(count - 1)``, in order; a task is sent only
        when its worker has fewer than ``in_flight`` results not yet consumed."""
        pending: deque[tuple[int, _Worker]] = deque()  # in task order
        sent = 0

        def send(worker: _Worker) -> None:
            nonlocal sent
            if sent < count:
                try:
                    worker.conn.send(sent)
                except OSError:  # its end is closed: it died
                    raise self._died(worker) from None
                pending.append((sent, worker))
                sent += 1

        for _ in range(self._in_flight):
            for worker in self._workers:
                send(worker)
        while pending:
            _, worker = pending.popleft()
            status, value = self._receive(worker)
            if status == "error":
                message, trace = value
                failed = WorkerFailed(message)
                failed.add_note(trace)
                raise failed
            yield value
            send(worker)  # the worker that delivered has room again

    def _receive(self, worker: _Worker):
        from multiprocessing.connection import wait

        sentinels = {w.sentinel: w for w in self._workers}
        while True:
            ready = wait([worker.conn, *sentinels])
            for s in ready:
                if s in sentinels:  # workers end only when told to: this one died
                    raise self._died(sentinels[s])
            try:
                return worker.conn.recv()
            except (EOFError, OSError):  # it died while sending
                raise self._died(worker) from None

    @staticmethod
    def _died(worker: _Worker) -> WorkerDied:
        return WorkerDied(worker.pid, worker.reap(timeout=5.0))

    def close(self, wait: bool = True) -> None:
        """End the workers: let them exit (``wait``, which an idle worker does
        at once) or kill them; one still busy after a second is killed too.
        Stop signals wait until this is done: it must not be cut short."""
        with signals_blocked():
            for worker in self._workers:
                if not wait:
                    worker.kill()
                if worker.conn is not None:
                    worker.conn.close()  # a waiting worker reads end-of-file and exits; a sending one fails
            for worker in self._workers:
                if worker.reap(timeout=1.0) is None:
                    worker.kill()
                    worker.reap()
                os.close(worker.sentinel)
            self._workers = []

    def __enter__(self) -> Pool:
        return self

    def __exit__(self, kind, value, trace) -> None:
        self.close(wait=kind is None)


class _Worker:
    """A forked process: its id, the parent's end of its pipe, and a file
    descriptor that becomes readable when it dies (it holds the other end)."""

    def __init__(self, pid: int, sentinel: int):
        self.pid = pid
        self.sentinel = sentinel
        self.conn = None
        self.exitcode: int | None = None

    @classmethod
    def fork(cls, task, conn, parents_ends: list) -> _Worker:
        sentinel, alive = os.pipe()
        parent = os.getpid()
        with signals_blocked():  # the child must not run the parent's handlers before it ignores them
            pid = os.fork()
            if pid == 0:
                try:
                    os.close(sentinel)
                    for end in parents_ends:
                        end.close()
                    _serve(conn, task, parent)
                finally:
                    os._exit(0)  # never the parent's code, atexit handlers or buffers
        os.close(alive)
        conn.close()
        return cls(pid, sentinel)

    def kill(self) -> None:
        if self.exitcode is None:
            os.kill(self.pid, signal.SIGKILL)  # workers ignore the gentler signals; unreaped, it still exists

    def reap(self, timeout: float | None = None) -> int | None:
        """Its exit code (negative: the signal that killed it), waiting up to ``timeout``; None if still running."""
        from multiprocessing.connection import wait

        if self.exitcode is None and wait([self.sentinel], timeout):
            _, status = os.waitpid(self.pid, 0)
            self.exitcode = os.waitstatus_to_exitcode(status)
        return self.exitcode


def _serve(conn, task: Callable[[int], Any], parent: int) -> None:
    """A worker's life: run the task numbers the parent sends, send back each result."""
    for sig in STOP_SIGNALS:
        signal.signal(sig, signal.SIG_IGN)  # also drops any that arrived while blocked
    signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)
    _die_with(parent)
    try:
        while True:
            try:
                i = conn.recv()
            except EOFError:  # the parent is done with us
                return
            try:
                reply = ("ok", task(i))
            except Exception as exc:  # noqa: BLE001 - sent to the parent, which reports it
                import traceback

                reply = ("error", (f"{type(exc).__name__}: {exc}", traceback.format_exc()))
            conn.send(reply)
    except OSError:  # the parent went away: nobody to tell
        return


def _die_with(parent: int) -> None:
    """Ask the kernel to kill this process when its parent dies (Linux), and
    exit now if that already happened."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):  # not Linux: the parent's end-of-file still stops us
        pass
    if os.getppid() != parent:
        os._exit(0)
