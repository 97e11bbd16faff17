"""Sweep runner: the α–β sweep on local processes or a Dask cluster.

``run_sweep(config, out_dir)`` does the sweep of :mod:`fm2uav.experiments.sweep`
at scale:

1. the reference paths (one lattice search per pair and model) are computed
   once, in parallel, and stored in ``out_dir/references.npz``;
2. the FM² cases are grouped in tasks of one pair × one α (all β), run on
   local processes (default, ``workers`` of them) or on an existing Dask
   cluster (``scheduler="tcp://host:8786"`` or a ``client``);
3. results stream to ``out_dir/<results>`` as tasks finish: a CSV file
   (appended row by row) or a Parquet dataset (a directory of part files,
   flushed every few seconds);
4. a re-run with the same configuration resumes: finished cases are read back
   and not redone; a failed case is recorded with its error (status
   ``"error"``) and never loses the others (``retry_failed`` runs them again);
5. ``on_progress(done, total, failed)`` is called as tasks finish.
"""

from __future__ import annotations

import csv
import json
import math
import os
import shutil
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from ..errors import InputError
from ..world import World
from ..baselines.reference import MODELS, reference_path
from .sweep import METRICS, parameter_grid, sweep_alpha_row

__all__ = ["GridSpec", "SweepConfig", "SweepResult", "load_config", "run_sweep", "sweep_world"]


class GridSpec(BaseModel):
    """``start:step:stop`` (inclusive) of α or β."""

    model_config = ConfigDict(extra="forbid")
    start: float = Field(0.02, gt=0, le=1)
    stop: float = Field(1.0, gt=0, le=1)
    step: float = Field(0.02, gt=0)

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
        Results file name in the output directory: ``*.csv`` or ``*.parquet``.
    """

    model_config = ConfigDict(extra="forbid")
    scenario: str = "city2d"
    cell: float = Field(2.0, gt=0)
    pairs: int | list[list[float]] = 24
    pair_seed: int = 0
    alpha: GridSpec = GridSpec()
    beta: GridSpec = GridSpec()
    models: list[str] = Field(default_factory=lambda: list(MODELS))
    xi: float = Field(10.0, gt=0)
    max_int: int = Field(4, ge=1, le=6)
    ds: float = Field(1.0, gt=0)
    order: int = Field(2, ge=1, le=2)
    results: str = "results.parquet"

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
        if not (v.endswith(".csv") or v.endswith(".parquet")) or "/" in v:
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

    def result_columns(self) -> list[str]:
        cols = ["pair", "alpha", "beta", "status", "error", "fm2_time_s", "length_m", "clearance_m"]
        return cols + [f"{m}_{model}" for m in METRICS for model in self.models]


def load_config(path: str | os.PathLike[str]) -> SweepConfig:
    """Read a YAML sweep configuration (unknown keys are errors)."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"config file {p} not found; give the path of a YAML file")
    try:
        data = yaml.safe_load(p.read_text()) or {}
    except yaml.YAMLError as exc:
        raise InputError(f"{p} is not valid YAML: {exc}") from None
    if not isinstance(data, dict):
        raise InputError(f"{p} must hold a YAML mapping of sweep settings")
    return make_config(data, where=str(p))


def make_config(data: dict[str, Any], where: str = "config") -> SweepConfig:
    try:
        return SweepConfig(**data)
    except ValidationError as exc:
        first = exc.errors()[0]
        loc = ".".join(str(x) for x in first["loc"])
        raise InputError(f"{where}: {loc}: {first['msg']}") from None


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
        if arr.ndim != 2 or arr.shape[1] != 4:
            raise InputError("pairs must be a number or a list of [x0, y0, x1, y1] in metres")
        starts, goals = arr[:, :2], arr[:, 2:]
    return world, starts, goals


# ----------------------------------------------------------------- tasks (picklable)
def _reference_task(cfg: dict[str, Any], pair: int, model: str) -> dict[str, Any]:
    config = SweepConfig(**cfg)
    world, starts, goals = sweep_world(config)
    t0 = time.perf_counter()
    try:
        ref = reference_path(world, starts[pair], goals[pair], model=model, xi=config.xi,
                             max_int=config.max_int)
    except Exception as exc:  # recorded, never lost
        return {"pair": pair, "model": model, "error": f"{type(exc).__name__}: {exc}",
                "time_s": time.perf_counter() - t0}
    return {"pair": pair, "model": model, "error": "", "path": ref.path, "cost": ref.cost,
            "length": ref.length, "time_s": ref.timings["search"]}


def _fm2_task(cfg: dict[str, Any], pair: int, alpha: float, betas: list[float],
              references: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    config = SweepConfig(**cfg)
    world, starts, goals = sweep_world(config)
    rows = sweep_alpha_row(world, starts[pair], goals[pair], alpha, betas, references,
                           ds=config.ds, order=config.order)
    for r in rows:
        r["pair"] = pair
    return rows


# ----------------------------------------------------------------- executors
class _Local:
    """Local process pool (or inline with one worker)."""

    def __init__(self, workers: int) -> None:
        self.workers = workers
        self.pool = None
        if workers > 1:
            from concurrent.futures import ProcessPoolExecutor

            self.pool = ProcessPoolExecutor(max_workers=workers)

    def map_unordered(self, fn: Callable, arglist: list[tuple]) -> Iterable[tuple[tuple, Any, BaseException | None]]:
        if self.pool is None:
            for args in arglist:
                try:
                    yield args, fn(*args), None
                except Exception as exc:  # noqa: BLE001 - recorded by the caller
                    yield args, None, exc
            return
        from concurrent.futures import as_completed

        futs = {self.pool.submit(fn, *a): a for a in arglist}
        try:
            for f in as_completed(futs):
                exc = f.exception()
                yield futs[f], (None if exc else f.result()), exc
        finally:
            for f in futs:
                f.cancel()

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)


class _Dask:
    """An existing Dask cluster (scheduler address or Client)."""

    def __init__(self, scheduler: str | None, client: Any) -> None:
        from dask.distributed import Client

        self.own = client is None
        self.client = client if client is not None else Client(scheduler, timeout="20s")

    def map_unordered(self, fn: Callable, arglist: list[tuple]):
        from dask.distributed import as_completed

        futs = {}
        for a in arglist:
            futs[self.client.submit(fn, *a, pure=False)] = a
        try:
            for f in as_completed(list(futs)):
                a = futs[f]
                if f.status == "error":
                    yield a, None, f.exception()
                else:
                    yield a, f.result(), None
        finally:
            self.client.cancel([f for f in futs if not f.done()])

    def close(self) -> None:
        if self.own:
            self.client.close()


# ----------------------------------------------------------------- result store
class _Store:
    """Results file: CSV (appended) or Parquet dataset (part files)."""

    def __init__(self, path: Path, columns: list[str]) -> None:
        self.path = path
        self.columns = columns
        self.parquet = path.suffix == ".parquet"
        self.buffer: list[dict[str, Any]] = []
        self.last_flush = time.monotonic()

    def read(self) -> list[dict[str, Any]]:
        if not self.path.exists():
            return []
        if self.parquet:
            import pyarrow.parquet as pq

            parts = sorted(self.path.glob("part-*.parquet"))
            rows: list[dict[str, Any]] = []
            for part in parts:
                rows.extend(pq.read_table(part).to_pylist())
            return rows
        with open(self.path, newline="") as fh:
            rows = list(csv.DictReader(fh))
        for r in rows:
            for k, v in r.items():
                if k in ("status", "error"):
                    continue
                r[k] = int(v) if k == "pair" else (float(v) if v not in ("", None) else math.nan)
        return rows

    def append(self, rows: list[dict[str, Any]], *, force: bool = False) -> None:
        self.buffer.extend({c: r.get(c, math.nan if c not in ("status", "error") else "")
                            for c in self.columns} for r in rows)
        if force or not self.parquet or time.monotonic() - self.last_flush > 5.0:
            self.flush()

    def flush(self) -> None:
        if not self.buffer:
            return
        if self.parquet:
            import pyarrow as pa
            import pyarrow.parquet as pq

            self.path.mkdir(parents=True, exist_ok=True)
            n = len(list(self.path.glob("part-*.parquet")))
            table = pa.Table.from_pylist(self.buffer)
            tmp = self.path / f".part-{n:05d}.tmp"
            pq.write_table(table, tmp)
            os.replace(tmp, self.path / f"part-{n:05d}.parquet")
        else:
            new = not self.path.exists()
            with open(self.path, "a", newline="") as fh:
                w = csv.DictWriter(fh, fieldnames=self.columns)
                if new:
                    w.writeheader()
                w.writerows(self.buffer)
                fh.flush()
                os.fsync(fh.fileno())
        self.buffer = []
        self.last_flush = time.monotonic()


@dataclass
class SweepResult:
    """Outcome of :func:`run_sweep`.

    Attributes
    ----------
    config : SweepConfig
    columns : dict of str to ndarray
        All result rows (latest row per case), column-wise.
    alphas, betas : ndarray
        The grid.
    starts, goals : ndarray, (n, 2)
        The pairs [m].
    references : dict
        ``(pair, model) -> dict(path, cost, length, time_s, error)``.
    cases_run, cases_skipped, cases_failed : int
        Cases computed now, read back from a previous run, failed (now or before).
    wall_s : dict
        Wall time of the references and of the FM² cases [s].
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
    wall_s: dict[str, float] = field(default_factory=dict)


def _columns(rows: list[dict[str, Any]], names: list[str]) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    for c in names:
        vals = [r.get(c) for r in rows]
        if c in ("status", "error"):
            out[c] = np.array(["" if v is None else str(v) for v in vals], dtype=object)
        elif c == "pair":
            out[c] = np.array(vals, dtype=np.int64)
        else:
            out[c] = np.array([math.nan if v is None else float(v) for v in vals], dtype=float)
    return out


def _load_references(path: Path) -> dict[tuple[int, str], dict[str, Any]]:
    refs: dict[tuple[int, str], dict[str, Any]] = {}
    if not path.exists():
        return refs
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(str(z["meta"]))
        for m in meta:
            key = (int(m["pair"]), str(m["model"]))
            entry = dict(m)
            if not m["error"]:
                entry["path"] = z[f"path_{m['pair']}_{m['model']}"]
            refs[key] = entry
    return refs


def _save_references(path: Path, refs: dict[tuple[int, str], dict[str, Any]]) -> None:
    arrays = {}
    meta = []
    for (pair, model), r in sorted(refs.items()):
        meta.append({k: v for k, v in r.items() if k != "path"})
        if not r["error"]:
            arrays[f"path_{pair}_{model}"] = np.asarray(r["path"])
    tmp = path.with_suffix(".tmp.npz")
    np.savez_compressed(tmp, meta=np.array(json.dumps(meta)), **arrays)
    os.replace(tmp, path)


def run_sweep(
    config: SweepConfig,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    retry_failed: bool = False,
    fresh: bool = False,
    on_progress: Callable[[str, int, int, int], None] | None = None,
) -> SweepResult:
    """Run (or resume) an α–β sweep; see the module docstring.

    Parameters
    ----------
    config : SweepConfig
    out_dir : path-like
        Holds ``config.json``, ``references.npz`` and the results file.
    workers : int, optional
        Local processes (default: all cores). 1 runs in this process.
    scheduler : str, optional
        Address of an existing Dask scheduler, e.g. ``"tcp://10.0.0.5:8786"``.
    client : dask.distributed.Client, optional
        Use this client (e.g. a ``LocalCluster`` in tests).
    retry_failed : bool
        Run the cases that failed in a previous run again.
    fresh : bool
        Discard previous results in ``out_dir`` (needed when the configuration
        changed).
    on_progress : callable, optional
        ``on_progress(stage, done, total, failed)`` with stage
        ``"references"`` or ``"fm2"``.

    Raises
    ------
    fm2uav.InputError
        ``out_dir`` holds results of a different configuration (pass
        ``fresh=True``), or a bad configuration.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg_path = out / "config.json"
    results_path = out / config.results
    refs_path = out / "references.npz"
    identity = config.identity()
    if cfg_path.exists() and not fresh:
        previous = json.loads(cfg_path.read_text())
        if previous != json.loads(json.dumps(identity)):
            raise InputError(
                f"{out} holds a sweep with a different configuration; pass --force (fresh=True) "
                "to discard it or choose another output directory"
            )
    if fresh:
        for p in (results_path, refs_path, cfg_path):
            if p.is_dir():
                shutil.rmtree(p)
            elif p.exists():
                p.unlink()
    cfg_path.write_text(json.dumps(identity, indent=2))

    world, starts, goals = sweep_world(config)
    alphas, betas = config.alpha.values(), config.beta.values()
    cfg = config.model_dump()
    n_pairs = len(starts)

    if scheduler is not None or client is not None:
        executor: Any = _Dask(scheduler, client)
    else:
        executor = _Local(max(1, int(workers or os.cpu_count() or 1)))
    wall: dict[str, float] = {}
    try:
        # 1. references
        t0 = time.perf_counter()
        refs = _load_references(refs_path)
        todo = [(cfg, p, m) for p in range(n_pairs) for m in config.models if (p, m) not in refs]
        done = len(refs)
        total = n_pairs * len(config.models)
        failed = sum(1 for r in refs.values() if r["error"])
        if on_progress:
            on_progress("references", done, total, failed)
        for args, res, exc in executor.map_unordered(_reference_task, todo):
            if exc is not None:
                res = {"pair": args[1], "model": args[2], "error": f"{type(exc).__name__}: {exc}",
                       "time_s": math.nan}
            refs[(res["pair"], res["model"])] = res
            done += 1
            failed += bool(res["error"])
            if done % 8 == 0 or done == total:
                _save_references(refs_path, refs)
            if on_progress:
                on_progress("references", done, total, failed)
        if todo:
            _save_references(refs_path, refs)
        wall["references"] = time.perf_counter() - t0

        # 2. FM² cases
        t1 = time.perf_counter()
        store = _Store(results_path, config.result_columns())
        previous = store.read()
        latest: dict[tuple[int, float, float], dict[str, Any]] = {}
        for r in previous:
            latest[(int(r["pair"]), round(float(r["alpha"]), 10), round(float(r["beta"]), 10))] = r
        finished = {k for k, r in latest.items() if r["status"] == "ok" or not retry_failed}
        tasks = []
        skipped = 0
        for p in range(n_pairs):
            ref_paths = {m: refs[(p, m)]["path"] for m in config.models if not refs[(p, m)]["error"]}
            for a in alphas:
                todo_b = [float(b) for b in betas if (p, float(a), float(b)) not in finished]
                skipped += len(betas) - len(todo_b)
                if todo_b:
                    tasks.append((cfg, p, float(a), todo_b, ref_paths))
        total = n_pairs * len(alphas) * len(betas)
        done = skipped
        failed = sum(1 for k in finished if latest[k]["status"] != "ok")
        run = 0
        if on_progress:
            on_progress("fm2", done, total, failed)
        for args, rows, exc in executor.map_unordered(_fm2_task, tasks):
            if exc is not None:
                rows = [{"pair": args[1], "alpha": args[2], "beta": b, "status": "error",
                         "error": f"{type(exc).__name__}: {exc}"} for b in args[3]]
            store.append(rows)
            for r in rows:
                latest[(int(r["pair"]), round(float(r["alpha"]), 10), round(float(r["beta"]), 10))] = r
            done += len(rows)
            run += len(rows)
            failed += sum(r["status"] != "ok" for r in rows)
            if on_progress:
                on_progress("fm2", done, total, failed)
        store.flush()
        wall["fm2"] = time.perf_counter() - t1
    finally:
        executor.close()

    rows = list(latest.values())
    columns = _columns(rows, config.result_columns())
    return SweepResult(
        config=config,
        columns=columns,
        alphas=alphas,
        betas=betas,
        starts=starts,
        goals=goals,
        references=refs,
        cases_run=run,
        cases_skipped=skipped,
        cases_failed=int(np.sum(columns["status"] != "ok")) if rows else 0,
        wall_s=wall,
    )
