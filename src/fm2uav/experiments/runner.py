"""Sweep runner: the α–β sweep on local processes or a Dask cluster, losing nothing.

``run_sweep(config, out_dir)`` does the sweep of :mod:`fm2uav.experiments.sweep`
at scale:

1. the reference paths (one lattice search per pair and model) are computed
   once, in parallel, and kept in ``out_dir/references.npz``;
2. the FM² cases are grouped in jobs of one pair × one α (all β) and run on
   supervised local worker processes (default, ``workers`` of them), in this
   process (``workers=1``) or on an existing Dask cluster
   (``scheduler="tcp://host:8786"`` or a ``client``);
3. every case outcome is appended to the log ``out_dir/cases.jsonl`` as soon as
   it is known; at the end the summary ``out_dir/<results>`` (CSV or Parquet,
   one row per case) is written from the log, atomically;
4. a re-run with the same configuration resumes: cases with an "ok" row in the
   log are not run again; missing cases and (unless ``retry_failed=False``)
   failed cases and failed references are;
5. ``on_progress(stage, done, total, failed)`` is called as cases finish.

Files of a sweep folder
    ``config.json`` (the configuration; a resume must match it),
    ``references.npz`` (written to a temporary file and renamed),
    ``cases.jsonl`` (the log), ``results.csv``/``results.parquet`` (the
    summary) and ``.sweep.lock`` (held while a sweep runs).

The log
    One line per case outcome: ``<CRC-32 of the JSON, 8 hex digits> <JSON>``;
    the first line is a header naming the configuration (its SHA-256). Each line
    is written with a single ``write(2)`` as soon as its case finished, so a
    killed process loses no recorded case; the file is fsync'd at most once a
    second and at the end. On reading, a torn last line (a write cut short) and
    any line whose checksum does not match are dropped with a warning and their
    cases run again; a torn tail is cut off before new lines are appended. A row
    is never both "ok" and non-finite: a case whose metrics are NaN or missing
    is recorded ``status="failed"`` with the reason in ``error``.

Faults
    A worker process that dies costs its case only: that case is run once more
    on a fresh worker, then recorded as failed with the reason; the other cases
    go on (:mod:`fm2uav.experiments._executors`). On Dask the scheduler re-runs
    the tasks of a dead worker (``distributed.scheduler.allowed-failures``,
    default 3); a job whose task still fails with ``KilledWorker`` is split into
    one task per case, so again only the deadly case fails. References are
    handled the same way; a case whose pair has no reference for a model is
    recorded as failed ("no dubins reference: ...") and is run on a later resume
    once the reference has been computed.

Interruption
    SIGINT and SIGTERM (in the main thread) stop the workers, flush the log and
    the references, and raise :class:`SweepInterrupted`; run the same sweep again
    to resume. A second sweep into a folder that is in use is refused
    (:func:`sweep_lock`).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import shutil
import signal
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator
from pydantic import model_validator

from .. import progress as _progress
from ..errors import Fm2uavError, InputError
from ..world import World
from ..baselines.reference import MODELS, reference_path
from ._executors import (  # noqa: F401  (check_workers, max_workers: re-exported)
    DaskPool,
    InlinePool,
    Job,
    LocalPool,
    check_workers,
    make_pool,
    max_workers,
)
from ._store import (
    LOG_NAME,
    CaseKey,
    CaseLog,
    case_key,
    checked_row,
    columns_of,
    decode_line,
    latest_rows,
    load_references,
    read_config_json,
    read_summary,
    save_references,
    sweep_lock,
    write_atomic,
    write_summary,
)
from .sweep import METRICS, parameter_grid, resample_references, sweep_alpha_row

__all__ = [
    "GridSpec",
    "SweepConfig",
    "SweepResult",
    "SweepInterrupted",
    "SweepWarning",
    "load_config",
    "make_config",
    "check_workers",
    "max_workers",
    "run_sweep",
    "same_sweep",
    "sweep_lock",
    "sweep_world",
    "read_log",
    "raise_on_signals",
    "LOG_NAME",
]

_CONFIG_NAME = "config.json"
_REFS_NAME = "references.npz"


#: Largest number of FM² cases a sweep may have (33 times the seed's 60 000, which take
#: about 3 minutes on 2 cores: ~400 cases/s).
MAX_SWEEP_CASES = 2_000_000
#: Largest number of start/goal pairs (each needs one reference path per model, ~1-2 s each).
MAX_SWEEP_PAIRS = 1000
#: Measured FM² sweep throughput on the 2-core development machine [cases/s] (the seed's
#: 60 000 cases in ~2.5 min of FM²), for the time a refused sweep would take.
SWEEP_CASES_PER_S = 400.0
#: Bytes of one case in the log (a checksummed JSON line with the metrics).
SWEEP_LOG_BYTES = 350

_SWEEP_CONFIG = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)


class GridSpec(BaseModel):
    """``start:step:stop`` (inclusive) of α or β."""

    model_config = _SWEEP_CONFIG
    start: float = Field(0.02, gt=0, le=1)
    stop: float = Field(1.0, gt=0, le=1)
    step: float = Field(0.02, gt=0, le=1)

    @model_validator(mode="after")
    def _ordered(self) -> GridSpec:
        if self.start > self.stop:
            raise ValueError(f"start {self.start:g} is above stop {self.stop:g}; give "
                             "start <= stop")
        return self

    def count(self) -> int:
        """How many values :meth:`values` has (without making them)."""
        return int(math.floor((self.stop - self.start) / self.step + 1e-9)) + 1

    def values(self) -> np.ndarray:
        return parameter_grid(self.start, self.stop, self.step)


class SweepConfig(BaseModel):
    """Configuration of an α–β sweep (YAML keys of ``fm2uav sweep``).

    Attributes
    ----------
    scenario : str
        Map; ``"city2d"`` (the seed's 2D city map).
    cell : float
        Node spacing of the city map [m].
    pairs : int or list of [x0, y0, x1, y1]
        Number of seeded start/goal pairs, or the pairs themselves [m].
    pair_seed : int
        Seed of the drawn pairs.
    alpha, beta : GridSpec
        Saturation and exponent grids (default 0.02:0.02:1).
    models : list of str
        Reference models, subset of dubins, elastica, rs.
    xi : float
        ξ of the references [m].
    max_int : int
        Lattice headings (48 for 4).
    ds : float
        Resampling step before comparing curves [m].
    order : int
        FM² Fast Marching order.
    results : str
        Summary file name in the output directory: ``*.csv`` or ``*.parquet``.
    """

    model_config = _SWEEP_CONFIG
    scenario: str = "city2d"
    cell: float = Field(2.0, ge=0.25, le=20)
    pairs: int | list[list[float]] = 24
    pair_seed: int = Field(0, ge=0, le=2**32 - 1)
    alpha: GridSpec = GridSpec()
    beta: GridSpec = GridSpec()
    models: list[str] = Field(default_factory=lambda: list(MODELS))
    xi: float = Field(10.0, gt=0, le=1000)
    max_int: int = Field(4, ge=1, le=6)
    ds: float = Field(1.0, ge=0.1, le=100)
    order: int = Field(2, ge=1, le=2)
    results: str = "results.parquet"

    @field_validator("pairs")
    @classmethod
    def _pairs(cls, v: int | list[list[float]]) -> int | list[list[float]]:
        n = v if isinstance(v, int) else len(v)
        if isinstance(v, int) and v < 1:
            raise ValueError(f"pairs must be at least 1, got {v}")
        if n > MAX_SWEEP_PAIRS:
            raise ValueError(
                f"{n} pairs would need {n} reference paths per model (~1-2 s each: "
                f"{n * 1.5 / 3600:.3g} h per model); the limit is {MAX_SWEEP_PAIRS} pairs")
        return v

    @model_validator(mode="after")
    def _size(self) -> SweepConfig:
        """Refuse, before anything runs, a sweep beyond :data:`MAX_SWEEP_CASES`, saying
        what it would take."""
        n_pairs = self.pairs if isinstance(self.pairs, int) else len(self.pairs)
        na, nb = self.alpha.count(), self.beta.count()
        cases = float(n_pairs) * na * nb
        if cases > MAX_SWEEP_CASES:
            hours = cases / SWEEP_CASES_PER_S / 3600
            raise ValueError(
                f"the sweep would have {cases:.3g} cases ({n_pairs} pairs x {na} alpha x {nb} "
                f"beta values): about {hours:.3g} hours of FM² on 2 cores (~"
                f"{SWEEP_CASES_PER_S:.0f} cases/s) and {cases * SWEEP_LOG_BYTES / 1e9:.3g} GB "
                f"of log; the limit is {MAX_SWEEP_CASES:,} cases — use a larger alpha/beta "
                "step (or a narrower start..stop) or fewer pairs")
        return self

    @field_validator("models")
    @classmethod
    def _models(cls, v: list[str]) -> list[str]:
        bad = [m for m in v if m not in MODELS]
        if bad or not v:
            raise ValueError(f"models must be a non-empty subset of {list(MODELS)}, got {v}")
        return list(dict.fromkeys(v))

    @field_validator("results")
    @classmethod
    def _results(cls, v: str) -> str:
        if not (v.endswith(".csv") or v.endswith(".parquet")) or "/" in v or v.startswith("."):
            raise ValueError(f"results must be a file name ending in .csv or .parquet, got {v!r}")
        return v

    @field_validator("scenario")
    @classmethod
    def _scenario(cls, v: str) -> str:
        if v != "city2d":
            raise ValueError(f"scenario must be 'city2d' (the only 2D map), got {v!r}")
        return v

    def identity(self) -> dict[str, Any]:
        """Everything that defines the cases (a resume must match it)."""
        return self.model_dump()

    def identity_hash(self) -> str:
        """SHA-256 of :meth:`identity` (names the sweep in its log)."""
        text = json.dumps(self.identity(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def metric_columns(self) -> list[str]:
        """``frechet_<model>``, ``area_<model>`` for the configured models."""
        return [f"{m}_{model}" for m in METRICS for model in self.models]

    def result_columns(self) -> list[str]:
        """Columns of the summary (one row per case)."""
        cols = ["pair", "alpha", "beta", "status", "error", "fm2_time_s", "length_m", "clearance_m"]
        return cols + self.metric_columns() + ["attempts"]


def load_config(path: str | os.PathLike[str]) -> SweepConfig:
    """Read a YAML sweep configuration (unknown keys are errors).

    Read like a mission file (:func:`fm2uav._validate.load_yaml`: YAML 1.2 numbers,
    duplicate keys refused, a regular UTF-8 file); types are strict (``pairs: true``
    or ``cell: "2"`` are refused), and a sweep too large to run is refused with the
    size it would need (:data:`MAX_SWEEP_CASES`).
    """
    from .. import _validate

    p = Path(path)
    data = _validate.load_yaml(p, "sweep configuration")
    if data is None:  # an empty file is a mistake (a failed copy), not "the defaults"
        raise InputError(f"sweep configuration {p} is empty; write the settings (e.g. pairs: 4, "
                         "alpha: {start: 0.1, stop: 1, step: 0.1}), or {} for the seed's full "
                         "sweep of 60 000 cases")
    if not isinstance(data, dict):
        raise InputError(f"{p} must hold a YAML mapping of sweep settings (scenario:, pairs:, "
                         f"alpha:, ...), got {type(data).__name__}")
    return make_config(data, where=str(p))


def make_config(data: dict[str, Any], where: str = "config") -> SweepConfig:
    """A :class:`SweepConfig` from a mapping; errors name ``where``, the key, the value
    and what is allowed."""
    try:
        return SweepConfig(**data)
    except ValidationError as exc:
        first = exc.errors()[0]
        loc = ".".join(str(x) for x in first["loc"] if not str(x).startswith(("int", "list[")))
        msg = str(first.get("ctx", {}).get("error", first["msg"]))
        value = first.get("input")
        shown = "" if isinstance(value, dict) or not loc else f" = {value!r}"
        raise InputError(f"{where}: {loc}{shown}: {msg}" if loc else f"{where}: {msg}") from None
    except TypeError as exc:  # e.g. non-string keys
        raise InputError(f"{where}: {exc}") from None


@lru_cache(maxsize=4)
def _world_cached(scenario: str, cell: float) -> World:
    from ..scenarios.city2d import city2d_world

    return city2d_world(cell)


def sweep_world(config: SweepConfig) -> tuple[World, np.ndarray, np.ndarray]:
    """The map and the start/goal pairs ``(starts, goals)`` [m] of a configuration."""
    from ..scenarios.city2d import city2d_pairs

    world = _world_cached(config.scenario, float(config.cell))
    if isinstance(config.pairs, int):
        starts, goals = city2d_pairs(config.pairs, config.pair_seed, world=world)
    else:
        arr = np.asarray(config.pairs, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 4 or not np.all(np.isfinite(arr)):
            raise InputError("pairs must be a number or a list of [x0, y0, x1, y1] in metres")
        starts, goals = arr[:, :2], arr[:, 2:]
    return world, starts, goals


# ----------------------------------------------------------------- case functions (workers)
def _reference_case(ctx: dict[str, Any], model: str) -> dict[str, Any]:
    world = _world_cached(ctx["scenario"], ctx["cell"])
    ref = reference_path(world, ctx["start"], ctx["goal"], model=model, xi=ctx["xi"],
                         max_int=ctx["max_int"])
    return {"path": np.asarray(ref.path, dtype=float), "cost": float(ref.cost),
            "length": float(ref.length), "time_s": float(ref.timings["search"])}


def _fm2_case(ctx: dict[str, Any], beta: float) -> dict[str, Any]:
    world = _world_cached(ctx["scenario"], ctx["cell"])
    row = sweep_alpha_row(world, ctx["start"], ctx["goal"], ctx["alpha"], [beta],
                          ctx["references"], ds=ctx["ds"], order=ctx["order"],
                          resampled=ctx.get("resampled", False))[0]
    row["pair"] = ctx["pair"]
    return row


# ----------------------------------------------------------------- folder
def same_sweep(config: SweepConfig, out_dir: str | os.PathLike[str]) -> bool:
    """True if ``out_dir`` holds (part of) the sweep of ``config``.

    Decided by ``config.json``, or by the log's header when ``config.json`` is missing.
    Raises :class:`~fm2uav.InputError` if ``config.json`` is damaged.
    """
    out = Path(out_dir)
    data = read_config_json(out / _CONFIG_NAME)
    if data is not None:
        return data == json.loads(json.dumps(config.identity()))
    try:
        with open(out / LOG_NAME, "rb") as fh:
            header = decode_line(fh.readline().rstrip(b"\n"))
    except OSError:
        return False
    return header is not None and header.get("identity") == config.identity_hash()


def read_log(out_dir: str | os.PathLike[str], config: SweepConfig,
             warn: Callable[[str], None] | None = None) -> list[dict[str, Any]]:
    """Every case row of a sweep folder's log, in the order written (latest last)."""
    return CaseLog(Path(out_dir) / LOG_NAME, config.identity_hash()).read(warn or _warn)


# ----------------------------------------------------------------- lock and signals
class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by SIGINT or SIGTERM; its recorded cases are kept.

    Attributes
    ----------
    signum : int
        The signal.
    message : str
        What was kept and how to resume.
    """

    def __init__(self, signum: int, message: str = "") -> None:
        super().__init__(message or f"sweep interrupted by {signal.Signals(signum).name}")
        self.signum = signum
        self.message = message or str(self.args[0])

    def __str__(self) -> str:
        return self.message


class _Signals:
    """SIGINT/SIGTERM raise :class:`SweepInterrupted`, deferred out of log writes; a signal
    the parent ignores (a background job of a shell without job control: SIGINT) stays
    ignored, as on the command line (:func:`fm2uav.io.outdir.interrupt_signals`)."""

    def __init__(self) -> None:
        self.critical = 0
        self.pending: int | None = None
        self.closing = False
        self._old: dict[int, Any] = {}

    def __enter__(self) -> _Signals:
        if threading.current_thread() is threading.main_thread():
            for s in (signal.SIGINT, signal.SIGTERM):
                if signal.getsignal(s) is not signal.SIG_IGN:
                    self._old[s] = signal.signal(s, self._handler)
        return self

    def __exit__(self, exc_type: Any, *exc: Any) -> None:
        for s, h in self._old.items():
            signal.signal(s, h)
        self._old = {}
        if exc_type is None and self.pending:  # deferred and not raised yet: never swallowed
            signum, self.pending = self.pending, None
            raise SweepInterrupted(signum)

    def _handler(self, signum: int, frame: Any) -> None:
        if self.closing or self.critical:
            self.pending = self.pending or signum
            return
        raise SweepInterrupted(signum)

    @contextlib.contextmanager
    def deferred(self) -> Iterator[None]:
        self.critical += 1
        try:
            yield
        finally:
            self.critical -= 1
        if not self.critical and self.pending and not self.closing:
            raise SweepInterrupted(self.pending)


def raise_on_signals() -> contextlib.AbstractContextManager[Any]:
    """Within the block (main thread), SIGINT and SIGTERM raise :class:`SweepInterrupted`."""
    return _Signals()


class SweepWarning(UserWarning):
    """Something in a sweep folder was repaired (e.g. a torn log line dropped)."""


def _warn(message: str) -> None:
    import warnings

    warnings.warn(message, SweepWarning, stacklevel=3)


# ----------------------------------------------------------------- result
@dataclass
class SweepResult:
    """Outcome of :func:`run_sweep`.

    Attributes
    ----------
    config : SweepConfig
    columns : dict of str to ndarray
        One row per case (the summary), column-wise.
    alphas, betas : ndarray
        The grid.
    starts, goals : ndarray, (n, 2)
        The pairs [m].
    references : dict
        ``(pair, model) -> dict(path, cost, length, time_s, error, attempts)``.
    cases_run, cases_skipped, cases_failed : int
        Cases computed now, taken from a previous run, failed (now or before).
    cases_retried : int
        Cases run a second time now because their worker process died.
    worker_deaths : int
        Worker processes that died while running a case or reference.
    wall_s : dict
        Wall time of the references and of the FM² cases [s].
    log, summary : Path
        The case log and the summary file.
    warnings : list of str
        What was repaired on reading (torn or damaged log lines).
    """

    config: SweepConfig
    columns: dict[str, np.ndarray]
    alphas: np.ndarray
    betas: np.ndarray
    starts: np.ndarray
    goals: np.ndarray
    references: dict[tuple[int, str], dict[str, Any]]
    cases_run: int = 0
    cases_skipped: int = 0
    cases_failed: int = 0
    cases_retried: int = 0
    worker_deaths: int = 0
    wall_s: dict[str, float] = field(default_factory=dict)
    log: Path | None = None
    summary: Path | None = None
    warnings: list[str] = field(default_factory=list)


# ----------------------------------------------------------------- run
_executor = make_pool  # the executor of --workers / --scheduler (shared with batches)


@_progress.stage()
def run_sweep(
    config: SweepConfig,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    retry_failed: bool = True,
    fresh: bool = False,
    on_progress: Callable[[str, int, int, int], None] | None = None,
    on_warning: Callable[[str], None] | None = None,
) -> SweepResult:
    """Run (or resume) an α–β sweep; see the module docstring.

    Parameters
    ----------
    config : SweepConfig
    out_dir : path-like
        The sweep folder (created if missing; see the module docstring).
    workers : int, optional
        Local worker processes (default: all cores). 1 runs in this process
        (no protection against a crash of the process itself).
    scheduler : str, optional
        Address of an existing Dask scheduler, e.g. ``"tcp://10.0.0.5:8786"``.
    client : dask.distributed.Client, optional
        Use this client (e.g. a ``LocalCluster`` in tests).
    retry_failed : bool
        Run failed cases and failed references of a previous run again
        (default). With False they are kept as they are.
    fresh : bool
        Discard previous results in ``out_dir`` (needed when the configuration
        changed).
    on_progress : callable, optional
        ``on_progress(stage, done, total, failed)`` with stage
        ``"references"`` or ``"fm2"``, called after each outcome is recorded.
    on_warning : callable, optional
        Receives one-line warnings (damaged log lines that were dropped);
        default: :func:`warnings.warn`.

    Raises
    ------
    fm2uav.InputError
        ``out_dir`` holds a sweep of a different configuration (pass
        ``fresh=True``), is used by another sweep, holds a damaged file (the
        message names it and the fix), or a bad configuration.
    SweepInterrupted
        SIGINT/SIGTERM: the workers were stopped and every finished case kept.
    """
    out = Path(out_dir)
    workers = check_workers(workers)
    warnings_seen: list[str] = []

    def warn(message: str) -> None:
        warnings_seen.append(message)
        (on_warning or _warn)(message)

    with sweep_lock(out):
        cfg_path = out / _CONFIG_NAME
        results_path = out / config.results
        refs_path = out / _REFS_NAME
        log = CaseLog(out / LOG_NAME, config.identity_hash())
        identity = json.loads(json.dumps(config.identity()))
        if fresh:
            old_results = []
            with contextlib.suppress(InputError):  # the summary of the sweep being discarded
                name = (read_config_json(cfg_path) or {}).get("results")
                if isinstance(name, str) and name.endswith((".csv", ".parquet")) \
                        and "/" not in name and not name.startswith("."):
                    old_results.append(out / name)
            for p in (log.path, results_path, refs_path, cfg_path, *old_results):
                if p.is_dir():
                    shutil.rmtree(p)
                elif p.exists():
                    p.unlink()
        else:
            previous = read_config_json(cfg_path)
            if previous is not None and previous != identity:
                raise InputError(
                    f"{out} holds a sweep with a different configuration; pass --force "
                    "(fresh=True) to discard it or choose another output directory")
        metric_cols = config.metric_columns()
        history = [checked_row(r, metric_cols) for r in log.read(warn)]
        imported: list[dict[str, Any]] = []
        if not log.path.exists() and results_path.exists():
            # a sweep folder of an older fm2uav: keep its finished cases
            for r in read_summary(results_path, config.result_columns(), warn):
                r = checked_row(r, metric_cols)
                if r["status"] == "ok":
                    imported.append(r)
        write_atomic(cfg_path, lambda tmp: tmp.write_text(json.dumps(identity, indent=2)))
        refs = load_references(refs_path)
        return _run(config, out, log, history, imported, refs, refs_path, results_path,
                    workers=workers, scheduler=scheduler, client=client,
                    retry_failed=retry_failed, on_progress=on_progress, warnings=warnings_seen)


def _run(config: SweepConfig, out: Path, log: CaseLog, history: list[dict[str, Any]],
         imported: list[dict[str, Any]], refs: dict[tuple[int, str], dict[str, Any]],
         refs_path: Path, results_path: Path, *, workers: int | None, scheduler: str | None,
         client: Any, retry_failed: bool, on_progress: Callable[..., None] | None,
         warnings: list[str]) -> SweepResult:
    world, starts, goals = sweep_world(config)
    alphas, betas = config.alpha.values(), config.beta.values()
    n_pairs = len(starts)
    grid = {(p, float(a), float(b)) for p in range(n_pairs) for a in alphas for b in betas}
    metric_cols = config.metric_columns()
    base_ctx = {"scenario": config.scenario, "cell": float(config.cell)}
    wall: dict[str, float] = {}
    stats = {"run": 0, "skipped": 0, "retried": 0, "deaths": 0}
    signals = _Signals()
    executor: Any = None
    stage = "references"
    latest: dict[CaseKey, dict[str, Any]] = {}
    refs_total = n_pairs * len(config.models)
    refs_dirty = False

    events = _ProgressEvents()
    if on_progress is None:
        progress = events
    else:
        def progress(*args: Any) -> None:
            events(*args)
            on_progress(*args)

    with signals:  # installed until the cleanup is over (a second Ctrl-C waits)
        try:
            log.open()
            for r in imported:
                with signals.deferred():
                    log.append(r)
            latest = {k: r for k, r in latest_rows(history + imported).items() if k in grid}

            # 1. references
            t0 = time.perf_counter()
            need, done, failed = _references_to_run(config, refs, n_pairs, retry_failed)
            progress("references", done, refs_total, failed)
            executor = _executor(workers, scheduler, client)
            for o in executor.run(_reference_case, _reference_jobs(config, base_ctx, starts, goals, need)):
                entry = _reference_entry(o)
                refs[(o.job.tag, o.unit)] = entry
                refs_dirty = True
                with signals.deferred():  # each reference is kept as soon as it is known
                    save_references(refs_path, refs)
                refs_dirty = False
                done += 1
                failed += bool(entry["error"])
                progress("references", done, refs_total, failed)
            wall["references"] = time.perf_counter() - t0
            retried0 = executor.retried

            # 2. FM² cases
            stage = "fm2"
            t1 = time.perf_counter()
            total = len(grid)
            done = failed = 0

            def record(row: dict[str, Any]) -> None:
                nonlocal done, failed
                _log_case(log, signals, latest, row)
                stats["run"] += 1
                done += 1
                failed += row["status"] != "ok"

            jobs, missing_refs, skipped, skipped_failed = _fm2_jobs(
                config, refs, latest, base_ctx, starts, goals, alphas, betas, retry_failed)
            stats["skipped"] += skipped
            done += skipped
            failed += skipped_failed
            progress("fm2", done, total, failed)
            for p, a, todo, reason in missing_refs:
                for b in todo:
                    record({"pair": p, "alpha": a, "beta": b, "status": "failed", "error": reason})
                progress("fm2", done, total, failed)
            for o in executor.run(_fm2_case, jobs):
                record(_fm2_row(o, metric_cols))
                progress("fm2", done, total, failed)
            wall["fm2"] = time.perf_counter() - t1
            stats["deaths"] = executor.deaths
            stats["retried"] = executor.retried - retried0
        except SweepInterrupted as exc:
            signals.closing = True
            if executor is not None:
                executor.close(now=True)
                executor = None
            if refs_dirty:
                with contextlib.suppress(OSError):
                    save_references(refs_path, refs)
            log.close()
            raise _interrupted(exc.signum, stage, refs, refs_total, refs_path, latest,
                               len(grid), log.path) from None
        finally:
            signals.closing = True
            if executor is not None:
                executor.close()
            log.close()

    # 3. the summary, from the log
    rows, cols = _write_results(config, log, grid, metric_cols, results_path)
    return _sweep_result(config, cols, bool(rows), starts, goals, refs, stats, wall,
                         log.path, results_path, warnings)


def _sweep_result(config: SweepConfig, cols: dict[str, Any], any_rows: bool, starts: Any,
                  goals: Any, refs: dict[tuple[int, str], dict[str, Any]], stats: dict[str, int],
                  wall: dict[str, float], log_path: Path, results_path: Path,
                  warnings: list[str]) -> SweepResult:
    """The :class:`SweepResult` of a finished sweep (``cols``: the summary's columns)."""
    return SweepResult(
        config=config,
        columns=cols,
        alphas=config.alpha.values(),
        betas=config.beta.values(),
        starts=starts,
        goals=goals,
        references=refs,
        cases_run=stats["run"],
        cases_skipped=stats["skipped"],
        cases_failed=int(np.sum(cols["status"] != "ok")) if any_rows else 0,
        cases_retried=stats["retried"],
        worker_deaths=stats["deaths"],
        wall_s=wall,
        log=log_path,
        summary=results_path,
        warnings=warnings,
    )


def _references_to_run(config: SweepConfig, refs: dict[tuple[int, str], dict[str, Any]],
                       n_pairs: int, retry_failed: bool) -> tuple[list[tuple[int, str]], int, int]:
    """The (pair, model) references still to compute; and how many are done / failed already."""
    need = [(p, m) for p in range(n_pairs) for m in config.models
            if (p, m) not in refs or (retry_failed and refs[(p, m)]["error"])]
    done = n_pairs * len(config.models) - len(need)
    failed = sum(1 for k, r in refs.items() if r["error"] and k not in need)
    return need, done, failed


class _ProgressEvents:
    """The sweep's ``(stage, done, total, failed)`` reports as :mod:`fm2uav.progress` steps and
    counts: the references a fifth of the run, the FM² cases the rest."""

    def __init__(self) -> None:
        self.stage: str | None = None

    def __call__(self, stage: str, done: int, total: int, failed: int) -> None:
        if stage != self.stage:
            self.stage = stage
            if stage == "references":
                _progress.step("reference paths (Dubins, elastica, Reeds–Shepp)", 0.2)
            else:
                _progress.step("FM² cases", 1.0)
        _progress.count(done, total, "done" + (f", {failed} failed" if failed else ""))


def _reference_jobs(config: SweepConfig, base_ctx: dict[str, Any], starts: Any, goals: Any,
                    need: list[tuple[int, str]]) -> list[Job]:
    """One job per (pair, model) reference in ``need``."""
    return [Job({**base_ctx, "start": starts[p], "goal": goals[p], "xi": float(config.xi),
                 "max_int": int(config.max_int)}, [m], tag=p) for p, m in need]


def _log_case(log: CaseLog, signals: _Signals, latest: dict[CaseKey, dict[str, Any]],
              row: dict[str, Any]) -> None:
    """Append ``row`` to the log (unless it repeats a failure word for word) and make it the latest."""
    k = case_key(row)
    if not _repeats_failure(latest.get(k), row):
        with signals.deferred():
            log.append(row)
    latest[k] = row


def _repeats_failure(old: dict[str, Any] | None, row: dict[str, Any]) -> bool:
    """True when ``row`` is a failure that repeats ``old`` word for word (not appended again)."""
    return (old is not None and old["status"] == row["status"] == "failed"
            and old.get("error") == row.get("error"))


def _reference_entry(o: Any) -> dict[str, Any]:
    """The references-file entry of one finished reference job ``o`` (its value or its error)."""
    entry = {"pair": o.job.tag, "model": o.unit, "attempts": o.attempt}
    if o.ok:
        entry.update(o.value, error="")
    else:
        entry.update(error=str(o.value), time_s=math.nan)
    return entry


def _fm2_jobs(config: SweepConfig, refs: dict[tuple[int, str], dict[str, Any]],
              latest: dict[CaseKey, dict[str, Any]], base_ctx: dict[str, Any],
              starts: Any, goals: Any, alphas: Any, betas: Any, retry_failed: bool,
              ) -> tuple[list[Job], list[tuple[int, float, list[float], str]], int, int]:
    """The FM² cases still to run, one job per (pair, alpha) with its betas.

    A case already in ``latest`` is skipped when it succeeded (or failed and
    ``retry_failed`` is off). Returns the jobs, the cases that cannot run because a
    reference failed ``(pair, alpha, betas, reason)``, and the numbers of skipped
    cases and of skipped failed cases.
    """
    jobs: list[Job] = []
    missing_refs: list[tuple[int, float, list[float], str]] = []
    skipped = skipped_failed = 0
    for p in range(len(starts)):
        ref_paths, ref_errors = {}, []
        resampled = None
        for m in config.models:
            r = refs[(p, m)]
            if r["error"]:
                ref_errors.append(f"no {m} reference: {r['error']}")
            else:
                ref_paths[m] = r["path"]
        for a in alphas:
            todo = []
            for b in betas:
                old = latest.get((p, float(a), float(b)))
                if old is not None and (old["status"] == "ok" or not retry_failed):
                    skipped += 1
                    skipped_failed += old["status"] != "ok"
                else:
                    todo.append(float(b))
            if not todo:
                continue
            if ref_errors:
                missing_refs.append((p, float(a), todo, "; ".join(ref_errors)))
            else:
                if resampled is None:  # once per pair, for all of its cases
                    resampled = _resampled(ref_paths, float(config.ds))
                jobs.append(Job({**base_ctx, "pair": p, "start": starts[p],
                                 "goal": goals[p], "alpha": float(a), **resampled,
                                 "ds": float(config.ds), "order": int(config.order)},
                                todo, tag=(p, float(a))))
    return jobs, missing_refs, skipped, skipped_failed


def _resampled(ref_paths: dict[str, Any], ds: float) -> dict[str, Any]:
    """The ``references`` of a pair's FM² jobs: resampled every ``ds`` once (``resampled``
    True), or as they are if that fails, so each case then fails with the error, as before."""
    try:
        return {"references": resample_references(ref_paths, ds), "resampled": True}
    except (Fm2uavError, ValueError, FloatingPointError):
        return {"references": ref_paths, "resampled": False}


def _fm2_row(o: Any, metric_cols: Any) -> dict[str, Any]:
    """The log row of one finished FM² case ``o`` (its metrics or its error), stamped."""
    p, a = o.job.tag
    if o.ok:
        row = dict(o.value)
    else:
        row = {"pair": p, "alpha": a, "beta": o.unit, "status": "failed",
               "error": str(o.value)}
    row = checked_row(row, metric_cols)
    row.update(pair=p, alpha=a, beta=float(o.unit), attempts=o.attempt,
               worker=o.worker, time=time.time())
    return row


def _interrupted(signum: int, stage: str, refs: dict[tuple[int, str], dict[str, Any]],
                 refs_total: int, refs_path: Path, latest: dict[CaseKey, dict[str, Any]],
                 n_cases: int, log_path: Path) -> SweepInterrupted:
    """The one-line :class:`SweepInterrupted` of a sweep stopped by ``signum``: what it kept."""
    if stage == "references":
        ok_refs = sum(1 for r in refs.values() if not r["error"])
        what = f"in the references phase ({ok_refs} of {refs_total} references kept in {refs_path})"
    else:
        kept = sum(1 for r in latest.values() if r["status"] == "ok")
        what = f"{kept} of {n_cases} cases recorded in {log_path}"
    return SweepInterrupted(signum, f"sweep interrupted by {signal.Signals(signum).name}: "
                            f"workers stopped, {what}; run the same sweep again to resume")


def _write_results(config: SweepConfig, log: CaseLog, grid: set[CaseKey], metric_cols: Any,
                   results_path: Path) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Write the summary table from the log (latest row per case of ``grid``, sorted); rows and columns."""
    rows_by_key = {k: r for k, r in latest_rows([checked_row(r, metric_cols) for r in
                                             log.read(lambda m: None)]).items() if k in grid}
    rows = [rows_by_key[k] for k in sorted(rows_by_key)]
    columns = config.result_columns()
    write_summary(results_path, rows, columns)
    return rows, columns_of(rows, columns)
