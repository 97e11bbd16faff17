"""Background jobs of the app: one worker process, progress events, cancel.

Planning runs in a separate process (started with ``spawn``), one job at a time,
so that the server keeps answering (tiles, progress) while the numba kernels
run, a job can be cancelled at once (the worker is terminated and a fresh one
started for the next job) and a crash or an out-of-memory end of a job never
takes the server down. The worker runs :func:`fm2uav.app.worker.run_job` and
sends back :class:`fm2uav.progress.ProgressEvent` stages, warnings, the result
or the error in the command line's words.
"""

from __future__ import annotations

import itertools
import multiprocessing as mp
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Job", "JobManager"]

#: Job states; the last three are final.
STATES = ("queued", "running", "done", "error", "cancelled")


@dataclass
class Job:
    """One job: what it is, where it is, and how it ended."""

    id: str
    kind: str
    payload: dict[str, Any]
    state: str = "queued"
    fraction: float = 0.0
    stage: str = "waiting for the worker"
    warnings: list[str] = field(default_factory=list)
    result: Any = None
    error: str | None = None
    exit_code: int | None = None
    started: float | None = None
    ended: float | None = None
    version: int = 0

    @property
    def final(self) -> bool:
        """Whether the job has ended (done, error or cancelled)."""
        return self.state in STATES[2:]

    def public(self) -> dict[str, Any]:
        """The job as the page sees it (without the payload)."""
        elapsed = None if self.started is None else (self.ended or time.time()) - self.started
        return {"id": self.id, "kind": self.kind, "state": self.state,
                "fraction": round(self.fraction, 4), "stage": self.stage,
                "warnings": self.warnings, "error": self.error, "exit_code": self.exit_code,
                "elapsed_s": None if elapsed is None else round(elapsed, 2),
                "result": self.result if self.state == "done" else None}


class JobManager:
    """Queue of jobs run one at a time by a worker process.

    Parameters
    ----------
    warm : bool
        Start the worker at once (it imports the planner while the page loads).
    """

    def __init__(self, *, warm: bool = True) -> None:
        self._ctx = mp.get_context("spawn")
        self._lock = threading.Condition()
        self._jobs: dict[str, Job] = {}
        self._queue: deque[str] = deque()
        self._ids = itertools.count(1)
        self._proc: Any = None
        self._conn: Any = None
        self._running: str | None = None
        self._stop = False
        self._thread = threading.Thread(target=self._loop, name="fm2uav-jobs", daemon=True)
        self._thread.start()
        if warm:
            with self._lock:
                self._ensure_worker()

    # -- public ------------------------------------------------------------------------
    def new_id(self) -> str:
        """A fresh job id (to prepare a job's files before :meth:`submit`)."""
        with self._lock:
            return f"{next(self._ids)}"

    def submit(self, kind: str, payload: dict[str, Any], job_id: str | None = None) -> Job:
        """Queue a job (see :func:`fm2uav.app.worker.run_job` for the kinds)."""
        with self._lock:
            job = Job(id=job_id or f"{next(self._ids)}", kind=kind, payload=payload)
            self._jobs[job.id] = job
            self._queue.append(job.id)
            self._lock.notify_all()
            return job

    def get(self, job_id: str) -> Job | None:
        """The job of that id (None if unknown)."""
        with self._lock:
            return self._jobs.get(job_id)

    def cancel(self, job_id: str) -> Job | None:
        """Cancel a queued or running job (a running one: its worker is terminated)."""
        with self._lock:
            job = self._jobs.get(job_id)
            if job is None or job.final:
                return job
            if job.state == "queued":
                self._queue.remove(job_id)
            elif self._running == job_id:
                self._kill_worker()
                self._running = None
            self._finish(job, "cancelled", stage="cancelled")
            self._lock.notify_all()
            return job

    def wait(self, job_id: str, version: int, timeout: float) -> Job | None:
        """Block until the job changes past ``version`` (or ``timeout`` seconds)."""
        with self._lock:
            self._lock.wait_for(lambda: (j := self._jobs.get(job_id)) is None
                                or j.version > version, timeout=timeout)
            return self._jobs.get(job_id)

    def close(self) -> None:
        """Stop the worker and the dispatcher thread."""
        with self._lock:
            self._stop = True
            self._kill_worker()
            self._lock.notify_all()
        self._thread.join(timeout=5)

    # -- internals -----------------------------------------------------------------------
    def _ensure_worker(self) -> None:
        if self._proc is not None and self._proc.is_alive():
            return
        from .worker import worker_main

        parent, child = self._ctx.Pipe(duplex=True)
        proc = self._ctx.Process(target=worker_main, args=(child,), name="fm2uav-worker",
                                 daemon=True)
        proc.start()
        child.close()
        self._proc, self._conn = proc, parent

    def _kill_worker(self) -> None:
        if self._proc is not None:
            self._proc.terminate()
            self._proc.join(timeout=5)
            if self._proc.is_alive():  # pragma: no cover - terminate ignored
                self._proc.kill()
                self._proc.join(timeout=5)
        if self._conn is not None:
            self._conn.close()
        self._proc = self._conn = None

    def _finish(self, job: Job, state: str, **changes: Any) -> None:
        job.state = state
        job.ended = time.time()
        for k, v in changes.items():
            setattr(job, k, v)
        if state == "done":
            job.fraction = 1.0
        job.version += 1

    def _loop(self) -> None:
        while True:
            with self._lock:
                if self._stop:
                    return
                if self._running is None and self._queue:
                    job = self._jobs[self._queue.popleft()]
                    self._ensure_worker()
                    self._running = job.id
                    job.state, job.started, job.stage = "running", time.time(), "starting"
                    job.version += 1
                    self._conn.send((job.id, job.kind, job.payload))
                    self._lock.notify_all()
                conn, running = self._conn, self._running
            if running is None or conn is None:
                with self._lock:
                    self._lock.wait(timeout=0.5)
                continue
            try:
                ready = conn.poll(0.1)
                message = conn.recv() if ready else None
            except (EOFError, OSError):  # the worker died (cancel, crash, out of memory)
                with self._lock:
                    job = self._jobs.get(running)
                    if self._running == running and job is not None and not job.final:
                        code = None if self._proc is None else self._proc.exitcode
                        self._finish(job, "error", exit_code=70, error=(
                            f"internal error: the planning worker stopped (exit code {code}) — "
                            "this is a bug in fm2uav or the machine ran out of memory; the "
                            "app started a new worker"))
                        self._proc = self._conn = None
                        self._running = None
                    self._lock.notify_all()
                continue
            if message is not None:
                self._handle(message)

    def _handle(self, message: tuple[Any, ...]) -> None:
        kind, job_id, *data = message
        with self._lock:
            job = self._jobs.get(job_id)
            if job is None or job.final or self._running != job_id:
                return
            if kind == "progress":
                job.fraction, job.stage = data
            elif kind == "warning":
                job.warnings.append(data[0])
            elif kind == "done":
                self._finish(job, "done", result=data[0], stage="done")
                self._running = None
            elif kind == "error":
                self._finish(job, "error", error=data[0], exit_code=data[1], stage="failed")
                self._running = None
            job.version += 1
            self._lock.notify_all()
