"""Executors of the sweep runner: supervised local processes, in-process, Dask.

Each executor runs *jobs* — a context and an ordered list of units (the cases of
the job), ``fn(context, unit)`` per unit — and yields one :class:`Outcome` per
unit as soon as it is known, in completion order. A unit that raises is an
outcome with ``ok=False`` and the reason ``"Type: message"``; the other units
of its job go on.

Dead workers (:class:`LocalPool`)
    Each worker process runs one job at a time, says when it starts it and
    reports each unit as it finishes (the next unit is under way from then on),
    so when a worker dies (killed, out of memory, a crash in compiled code) the
    supervisor knows the unit it was running (none if it died before it started
    the job): that unit is charged one
    attempt and run again, alone, on a fresh worker; after ``max_attempts``
    deaths it is an outcome ``ok=False`` with the reason (e.g. "worker process
    died 2 times on this case (killed by SIGKILL) ..."). The units of the job it
    had not started yet are resubmitted without a charge; the other workers'
    jobs are untouched.

No orphans
    Workers are fresh interpreters (``python -c``, so they inherit no thread or
    lock state and do not re-import the caller's ``__main__``) and, on Linux, ask
    the kernel to kill them when the main process dies (``PR_SET_PDEATHSIG``), so
    a ``kill -9`` of the main process leaves no worker behind; elsewhere a
    watchdog thread exits when the parent is gone.
    :meth:`LocalPool.close` stops workers (terminate, then kill after a grace
    period); workers ignore SIGINT, so a Ctrl-C reaches only the main process,
    which shuts them down.

Dask (:class:`DaskPool`)
    Dask's scheduler re-runs the tasks of a worker that died
    (``distributed.scheduler.allowed-failures`` times, default 3); a task that
    exhausted them fails with ``KilledWorker``: a job of several units is then
    split into one task per unit, so only the unit that kills workers fails.
"""

from __future__ import annotations

import os
import pickle
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from ..errors import Fm2uavError

__all__ = ["Job", "Outcome", "InlinePool", "LocalPool", "DaskPool", "WorkerError", "max_workers",
           "check_workers", "make_pool"]

#: Seconds a worker gets to exit after SIGTERM before it is killed.
GRACE_S = 2.0


class WorkerError(Fm2uavError):
    """Worker processes cannot run at all (they die before finishing any case)."""


@dataclass
class Job:
    """A context shared by its units (cases) and the units, run in order.

    Attributes
    ----------
    context : any
        Passed to ``fn`` with each unit (picklable).
    units : list
        The cases of the job.
    attempts : list of int
        Attempt number of each unit (1 the first time).
    tag : any
        The caller's label of the job, returned in each :class:`Outcome`.
    """

    context: Any
    units: list[Any]
    attempts: list[int] = field(default_factory=list)
    tag: Any = None

    def __post_init__(self) -> None:
        if not self.attempts:
            self.attempts = [1] * len(self.units)

    def part(self, start: int, stop: int | None = None, *, charge: bool = False) -> Job:
        """A job of ``units[start:stop]`` (``charge``: one more attempt each)."""
        stop = len(self.units) if stop is None else stop
        att = [a + int(charge) for a in self.attempts[start:stop]]
        return Job(self.context, self.units[start:stop], att, self.tag)


@dataclass(frozen=True)
class Outcome:
    """The result of one unit.

    Attributes
    ----------
    job : Job
    unit : any
    ok : bool
        False when the unit raised or its worker died ``max_attempts`` times.
    value : any
        ``fn``'s return value, or the failure reason (str).
    attempt : int or None
        Attempt that produced the outcome (None: not known, Dask).
    worker : int or None
        Process id of the worker (None: not known).
    """

    job: Job
    unit: Any
    ok: bool
    value: Any
    attempt: int | None
    worker: int | None


def _describe_exit(code: int | None) -> str:
    if code is None:
        return "stopped responding"
    if code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exited with code {code}"


def _run_unit(fn: Callable[[Any, Any], Any], context: Any, unit: Any) -> tuple[bool, Any]:
    try:
        return True, fn(context, unit)
    except Exception as exc:  # noqa: BLE001 - reported as the unit's failure reason
        return False, f"{type(exc).__name__}: {exc}"


# ----------------------------------------------------------------- in-process
class InlinePool:
    """Runs every job in this process (``workers=1``): no isolation from crashes."""

    deaths = 0
    retried = 0

    def run(self, fn: Callable[[Any, Any], Any], jobs: Iterable[Job]) -> Iterator[Outcome]:
        pid = os.getpid()
        for job in jobs:
            for unit, attempt in zip(job.units, job.attempts):
                ok, value = _run_unit(fn, job.context, unit)
                yield Outcome(job, unit, ok, value, attempt, pid)

    def close(self, *, now: bool = False) -> None:
        pass


# ----------------------------------------------------------------- supervised processes
def _die_with_parent(parent_pid: int) -> None:
    """Make this worker exit when the main process dies (kernel signal on Linux)."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG: killed when the parent dies
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent_pid:  # the parent died before prctl
        os._exit(1)

    def watch() -> None:  # other systems (and a second line of defence)
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, name="fm2uav-parent-watch", daemon=True).start()


def _worker_main(fd: int, parent_pid: int) -> None:
    """Loop of a worker process: run jobs sent on socket ``fd``, one message per unit."""
    from multiprocessing.connection import Connection

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the main process stops us
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent(parent_pid)
    conn = Connection(fd)
    try:
        sys.path[:] = conn.recv()  # the main process's import path (its jobs' functions)
    except (EOFError, OSError):
        return
    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError):
            return
        if msg is None:
            return
        job_id, n_units, payload = msg
        conn.send_bytes(pickle.dumps(("start", job_id, 0)))  # later starts: implied by results
        try:
            fn, context, units = pickle.loads(payload)  # may import the job's modules
        except Exception as exc:  # noqa: BLE001 - every unit of the job fails with the reason
            why = f"cannot load the job in the worker: {type(exc).__name__}: {exc}"
            for i in range(n_units):
                conn.send_bytes(pickle.dumps(("unit", job_id, i, False, why)))
            conn.send_bytes(pickle.dumps(("done", job_id)))
            continue
        for i, unit in enumerate(units):
            ok, value = _run_unit(fn, context, unit)
            try:
                data = pickle.dumps(("unit", job_id, i, ok, value))
            except Exception as exc:  # noqa: BLE001 - an unpicklable result is that unit's failure
                data = pickle.dumps(("unit", job_id, i, False,
                                     f"result cannot be sent back: {type(exc).__name__}: {exc}"))
            conn.send_bytes(data)
        conn.send_bytes(pickle.dumps(("done", job_id)))


def _stderr_fd() -> int:
    """Workers print to stderr: the main process's stdout may be a JSON document."""
    try:
        os.fstat(2)
        return 2
    except OSError:
        import subprocess

        return subprocess.DEVNULL


_WORKER_CMD = ("import sys; from fm2uav.experiments._executors import _worker_main; "
               "_worker_main(int(sys.argv[1]), int(sys.argv[2]))")


class _Worker:
    """One worker: a fresh interpreter (``python -c``) joined by a socket pair.

    A plain subprocess rather than ``multiprocessing``: it does not re-import the
    caller's ``__main__`` (no ``if __name__ == "__main__"`` guard needed) and
    inherits no thread or lock state of the main process.
    """

    def __init__(self) -> None:
        import socket
        import subprocess
        from multiprocessing.connection import Connection

        mine, theirs = socket.socketpair()
        try:
            self.process = subprocess.Popen(
                [sys.executable, "-c", _WORKER_CMD, str(theirs.fileno()), str(os.getpid())],
                pass_fds=[theirs.fileno()], stdin=subprocess.DEVNULL, stdout=_stderr_fd())
        except BaseException:
            mine.close()
            raise
        finally:
            theirs.close()
        self.conn = Connection(mine.detach())
        self.conn.send(list(sys.path))
        self.job: Job | None = None
        self.job_id = -1
        self.next = 0  # index of the first unit of `job` not reported yet
        self.started = -1  # index of the last unit the worker said it started

    @property
    def pid(self) -> int:
        return self.process.pid

    def alive(self) -> bool:
        return self.process.poll() is None

    def join(self, timeout: float) -> None:
        import subprocess

        try:
            self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            pass


class LocalPool:
    """Supervised local worker processes (see the module docstring).

    Parameters
    ----------
    workers : int
        Number of worker processes (>= 1).
    max_attempts : int
        A unit whose worker died this many times is recorded as failed.
    """

    def __init__(self, workers: int, *, max_attempts: int = 2) -> None:
        self.size = max(1, int(workers))
        self.max_attempts = max(1, int(max_attempts))
        self._workers: list[_Worker] = []
        self._ids = 0
        self.deaths = 0  # worker processes that died while running a unit
        self.retried = 0  # units run again after a worker death
        self._silent_deaths = 0  # worker deaths since the last unit that finished

    def pids(self) -> list[int]:
        """Process ids of the live workers."""
        return [w.pid for w in self._workers if w.alive()]

    def _send(self, w: _Worker, fn: Callable, job: Job) -> None:
        self._ids += 1
        w.job, w.job_id, w.next, w.started = job, self._ids, 0, -1
        w.conn.send((w.job_id, len(job.units), pickle.dumps((fn, job.context, job.units))))

    def run(self, fn: Callable[[Any, Any], Any], jobs: Iterable[Job]) -> Iterator[Outcome]:
        from multiprocessing.connection import wait

        queue: deque[Job] = deque(j for j in jobs if j.units)
        while queue or any(w.job is not None for w in self._workers):
            # drop workers that died idle, start workers up to the pool size while there is
            # queued work, give each idle worker a job
            self._workers = [w for w in self._workers if w.job is not None or w.alive()]
            while queue and len(self._workers) < self.size:
                self._workers.append(_Worker())
            for w in self._workers:
                if w.job is None and queue:
                    job = queue.popleft()
                    try:
                        self._send(w, fn, job)
                    except (OSError, ValueError):  # died before it got the job: no charge
                        w.job = None
                        queue.appendleft(job)
                        w.join(GRACE_S)
                        self._workers.remove(w)
                        self._dead_start()
                        break
            busy = {w.conn: w for w in self._workers if w.job is not None}
            ready = set(wait(list(busy), timeout=1.0))
            for conn, w in busy.items():  # a pipe with news, or a worker gone without EOF
                if conn in ready or not w.alive():
                    yield from self._service(w, queue)

    def _service(self, w: _Worker, queue: deque[Job]) -> Iterator[Outcome]:
        dead = False
        while w.job is not None:
            try:
                if not w.conn.poll(0):
                    break
                msg = pickle.loads(w.conn.recv_bytes())
            except (EOFError, OSError):
                dead = True
                break
            if msg[0] == "start" and msg[1] == w.job_id:
                w.started = msg[2]
            elif msg[0] == "done" and msg[1] == w.job_id:
                w.job = None
            elif msg[0] == "unit" and msg[1] == w.job_id:
                _, _, i, ok, value = msg
                job = w.job
                w.next = w.started = i + 1  # a result means the next unit is under way
                self._silent_deaths = 0
                yield Outcome(job, job.units[i], ok, value, job.attempts[i], w.pid)
        if not dead and w.job is not None and not w.alive():
            dead = True
        if dead:
            yield from self._bury(w, queue)

    def _dead_start(self) -> None:
        self._silent_deaths += 1
        if self._silent_deaths > max(4, 2 * self.size):
            raise WorkerError(
                f"{self._silent_deaths} worker processes in a row died before finishing "
                "a single case; run with --workers 1 (in this process) to see why")

    def _bury(self, w: _Worker, queue: deque[Job]) -> Iterator[Outcome]:
        w.join(GRACE_S)
        if w.alive():  # closed its socket but did not exit
            w.process.kill()
            w.join(GRACE_S)
        reason = _describe_exit(w.process.returncode)
        job, start = w.job, w.next
        self._workers.remove(w)
        w.conn.close()
        if job is None or start >= len(job.units):
            return
        self._dead_start()
        if w.started < start:  # died before it started the next unit: nobody is charged
            queue.appendleft(job.part(start))
            return
        self.deaths += 1
        rest = job.part(start + 1)
        if rest.units:
            queue.appendleft(rest)
        attempt = job.attempts[start]
        if attempt >= self.max_attempts:
            yield Outcome(job, job.units[start], False,
                          f"worker process died {attempt} times on this case (last: {reason}); "
                          "out of memory or a crash in compiled code?", attempt, w.pid)
        else:
            self.retried += 1
            queue.appendleft(job.part(start, start + 1, charge=True))

    def close(self, *, now: bool = False) -> None:
        """Stop the workers: ask idle ones to exit, terminate busy ones (all with ``now``)."""
        for w in self._workers:
            try:
                if now or w.job is not None:
                    w.process.terminate()
                else:
                    w.conn.send(None)
            except (OSError, ValueError):
                pass
        deadline = time.monotonic() + GRACE_S
        for w in self._workers:
            w.join(max(0.0, deadline - time.monotonic()))
            if w.alive():
                w.process.kill()
                w.join(1.0)
            w.conn.close()
        self._workers = []


# ----------------------------------------------------------------- Dask
def _dask_job(fn: Callable[[Any, Any], Any], context: Any, units: list[Any]) -> list[tuple[bool, Any, int]]:
    """One Dask task: every unit of a job, in order (``(ok, value, pid)`` each)."""
    pid = os.getpid()
    return [(*_run_unit(fn, context, u), pid) for u in units]


class DaskPool:
    """An existing Dask cluster (scheduler address or Client)."""

    deaths = 0
    retried = 0

    def __init__(self, scheduler: str | None, client: Any) -> None:
        from dask.distributed import Client

        self.own = client is None
        self.client = client if client is not None else Client(scheduler, timeout="20s")
        self._futures: list[Any] = []

    def run(self, fn: Callable[[Any, Any], Any], jobs: Iterable[Job]) -> Iterator[Outcome]:
        from dask.distributed import as_completed
        from distributed import KilledWorker

        futs: dict[Any, Job] = {}

        def submit(job: Job) -> Any:
            f = self.client.submit(_dask_job, fn, job.context, job.units, pure=False)
            futs[f] = job
            self._futures.append(f)
            return f

        pending = as_completed([submit(j) for j in jobs if j.units])
        for f in pending:
            job = futs.pop(f)
            if f.status != "error":
                for unit, attempt, (ok, value, pid) in zip(job.units, job.attempts, f.result()):
                    yield Outcome(job, unit, ok, value, None, pid)
                continue
            exc = f.exception()
            if isinstance(exc, KilledWorker) and len(job.units) > 1:
                # only the case that kills workers may fail: one task per case
                self.deaths += 1
                for i in range(len(job.units)):
                    pending.add(submit(job.part(i, i + 1, charge=True)))
                continue
            if isinstance(exc, KilledWorker):
                reason = (f"Dask worker died on every attempt at this case (KilledWorker, "
                          f"{exc}); out of memory or a crash in compiled code?")
            else:
                reason = f"{type(exc).__name__}: {exc}"
            for unit, attempt in zip(job.units, job.attempts):
                yield Outcome(job, unit, False, reason, None, None)
        self._futures = []

    def close(self, *, now: bool = False) -> None:
        live = [f for f in self._futures if not f.done()]
        if live:
            try:
                self.client.cancel(live)
            except Exception:  # noqa: BLE001 - the scheduler may be gone already
                pass
        self._futures = []
        if self.own:
            self.client.close()


# ----------------------------------------------------------------- choosing one
def max_workers() -> int:
    """Most local worker processes a sweep or batch may start: 4 per core (at least 8);
    each is a Python process with numba's kernels loaded (~150 MB)."""
    return max(8, 4 * (os.cpu_count() or 1))


def check_workers(workers: Any) -> int | None:
    """``workers`` (None = all cores) as a count of local worker processes.

    Raises
    ------
    InputError
        Not an integer >= 1, or more than :func:`max_workers` (names ``--workers``).
    """
    from .. import _validate
    from ..errors import InputError

    if workers is None:
        return None
    n = _validate.integer(workers, "workers", minimum=1, where=(None, "--workers"))
    if n > max_workers():
        raise InputError(
            f"--workers {n} would start {n} worker processes (~150 MB each: "
            f"{n * 0.15:.3g} GB) on {os.cpu_count() or 1} cores; the limit is {max_workers()} "
            "(4 per core); for more, run a Dask cluster and give its scheduler address")
    return n


def make_pool(workers: int | None, scheduler: str | None = None,
              client: Any = None) -> InlinePool | LocalPool | DaskPool:
    """The executor of ``--workers`` / ``--scheduler``: a Dask cluster when a scheduler
    address or client is given, else ``workers`` supervised local processes (None = all
    cores), in this process for 1.

    Raises
    ------
    InputError
        The Dask scheduler cannot be reached (names ``--scheduler``).
    """
    from ..errors import InputError

    if scheduler is not None or client is not None:
        try:
            return DaskPool(scheduler, client)
        except (OSError, ValueError, TypeError) as exc:
            raise InputError(f"cannot reach the Dask scheduler {scheduler}: {exc}; check "
                             "--scheduler") from None
    n = max(1, int(workers or os.cpu_count() or 1))
    return InlinePool() if n == 1 else LocalPool(n)
