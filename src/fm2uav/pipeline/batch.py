"""Run many mission files at once: local worker processes or a Dask cluster.

``fm2uav batch A.yaml B.yaml DIR/`` is :func:`prepare_batch` (the files, their output
folders, checked before any work) then :func:`run_batch` (the missions on the sweep's
executors, :mod:`fm2uav.experiments._executors`, one job per mission).

Who writes what
    A worker runs :func:`run_mission` — the very function of ``fm2uav run FILE`` —
    into a private temporary folder and sends the files back as bytes; the main
    process alone writes each mission's output set (:class:`~fm2uav.io.outdir.OutputDir`:
    the folder appears whole when the mission's result arrives, or not at all). So a
    worker that dies mid-mission leaves nothing behind in the outputs, the mission run
    again on another worker cannot meet a half-written folder, each mission is written
    exactly once, and a Dask cluster's workers need no access to the output folders
    (they need the mission files and the data they name, at the same paths).

Same files as ``fm2uav run FILE``
    The mission is loaded from its path as given (relative to the current folder of
    the main process), so ``summary.json`` and ``path.geojson``, which record that path,
    equal those of ``fm2uav run FILE`` run in the same folder. A Dask worker running in
    another folder loads it by its absolute path (those records are then absolute).
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from ..errors import EXIT_INTERNAL, InputError

__all__ = ["BatchMission", "MissionResult", "BATCH_FILE", "mission_files", "prepare_batch",
           "plan_mission_files", "write_mission_set", "run_batch", "write_batch_file"]

#: The batch's summary file, in the batch's ``--out`` folder.
BATCH_FILE = "batch.json"

#: Suffixes of the mission files taken from a folder argument.
MISSION_SUFFIXES = (".yaml", ".yml")


@dataclass(frozen=True)
class BatchMission:
    """One mission file of a batch, as sent to a worker.

    Attributes
    ----------
    index : int
        Position in the batch (0-based).
    file : str
        The path as given (recorded in ``summary.json``, like ``fm2uav run FILE``).
    path : str
        Its absolute path (for workers running in another folder).
    out : str
        The mission's output folder: its ``outputs.dir``, else ``OUT/<file stem>``.
    formats : tuple of str
        The output formats (``outputs.formats``, plus ``html`` with ``--report``).
    """

    index: int
    file: str
    path: str
    out: str
    formats: tuple[str, ...]


@dataclass
class MissionResult:
    """What became of one mission of a batch (a row of ``batch.json``).

    Attributes
    ----------
    file : str
        The mission file as given.
    status : {"ok", "failed", "not run"}
        ``not run``: the batch was interrupted first.
    out : str or None
        Its output folder (written when ``status`` is ``ok``).
    name : str or None
        The mission's ``name``.
    error : str
        The one-line reason of a failure (what ``fm2uav run FILE`` would print).
    exit_code : int or None
        The exit code ``fm2uav run FILE`` would give (1 planning, 2 input, 70 a bug).
    time_s : float or None
        Wall time of the mission on its worker [s] (None when it was not run).
    attempt : int or None
        Which attempt gave the result (2: its first worker died; None: not known, Dask).
    worker : int or None
        Process id of the worker.
    length_m : float or None
        Length of the planned path [m].
    waypoints : int or None
        Waypoints of the autopilot mission.
    warnings : list of str
        The mission's warnings (one line each).
    files : list of str
        The files written into ``out``.
    path : str
        The mission file's absolute path.
    sha256 : str
        The mission file's SHA-256 (``--resume`` plans a changed file again).
    resumed : bool
        Kept from the earlier batch by ``--resume`` (not planned now).
    """

    file: str
    status: str
    out: str | None = None
    name: str | None = None
    error: str = ""
    exit_code: int | None = None
    time_s: float | None = None
    attempt: int | None = None
    worker: int | None = None
    length_m: float | None = None
    waypoints: int | None = None
    warnings: list[str] = field(default_factory=list)
    files: list[str] = field(default_factory=list)
    path: str = ""
    sha256: str = ""
    resumed: bool = False

    def failed(self, error: str, code: int) -> MissionResult:
        """This result marked failed with ``error`` (exit ``code``); no files."""
        self.status, self.error, self.exit_code, self.files = "failed", error, code, []
        return self


# ----------------------------------------------------------------- before any work
def mission_files(paths: Iterable[str | os.PathLike[str]]) -> list[Path]:
    """The mission files of the arguments: files as given, folders as their ``*.yaml`` /
    ``*.yml`` files in name order; a file given twice is kept once (its first place).

    Raises
    ------
    InputError
        A path that does not exist, a folder without mission files, no path at all.
    """
    out: list[Path] = []
    seen: set[str] = set()
    for given in paths:
        p = Path(given)
        if p.is_dir():
            found = sorted(q for q in p.iterdir()
                           if q.suffix.lower() in MISSION_SUFFIXES and q.is_file())
            if not found:
                raise InputError(f"folder {p} holds no mission file (*.yaml, *.yml); give "
                                 "mission files or a folder of them")
        elif p.exists():
            from .. import _validate

            found = [_validate.input_file(p, "mission file")]  # a pipe, a device: refused
        else:
            raise InputError(f"mission file {p} does not exist; nothing was run (check the "
                             "name, or give a folder of mission files)")
        for q in found:
            key = os.path.realpath(q)
            if key not in seen:
                seen.add(key)
                out.append(q)
    if not out:
        raise InputError("no mission file given; e.g. fm2uav batch missions/*.yaml --out "
                         "out/batch")
    return out


def prepare_batch(paths: Iterable[str | os.PathLike[str]], out: str | os.PathLike[str], *,
                  force: bool = False, report: bool = False, resume: bool = False,
                  describe: Callable[[BaseException], tuple[str, int]] | None = None,
                  ) -> tuple[list[BatchMission], list[MissionResult]]:
    """The missions of a batch with their output folders, checked before any work.

    Each file is read (a file that cannot be is a failed mission, not the batch's
    error); its output folder is its ``outputs.dir`` (relative to the mission file),
    else ``out/<file stem>``.

    Parameters
    ----------
    paths : iterable of path
        Mission files and folders of them (:func:`mission_files`).
    out : path
        The batch's folder (``--out``).
    force : bool
        Replace existing output folders as a whole (``--force``).
    report : bool
        Add ``report.html`` to every mission's formats (``--report``).
    resume : bool
        Keep the missions ``out/batch.json`` lists as ok whose mission file is
        unchanged (same SHA-256) and whose files are all there (``--resume``); plan
        the others.
    describe : callable, optional
        ``exc -> (message, exit code)`` of a mission file that cannot be read
        (default :func:`fm2uav.errors.describe_error`).

    Returns
    -------
    missions : list of BatchMission
        Those to run.
    results : list of MissionResult
        One per file, in order: ``not run`` for those to run, ``failed`` for those that
        cannot be read, ``ok`` (``resumed``) for those ``resume`` keeps.

    Raises
    ------
    InputError
        A missing path; two missions with one output folder; an output folder or
        ``batch.json`` that exists (without ``force``) or is being written by another
        run; with ``resume``, no readable ``batch.json``.
    """
    from ..io.mission import load_mission
    from ..io.outdir import OutputDir
    from .outputs import output_names

    describe = describe or _describe
    files = mission_files(paths)
    summary = Path(out) / BATCH_FILE
    done = _earlier_batch(summary) if resume else {}
    if summary.exists() and not (force or resume):
        raise InputError(f"{summary} already exists (an earlier batch); pass --force to "
                         "replace it and the missions' folders, or choose another --out")
    od = _batch_file_set(out)
    try:
        od.check([BATCH_FILE])  # a folder batch.json cannot go into: said now, not at the end
    finally:
        od.abort()
    missions: list[BatchMission] = []
    results: list[MissionResult] = []
    owners: dict[str, str] = {}
    for i, f in enumerate(files):
        target = Path(out) / f.stem
        res = MissionResult(file=str(f), status="not run", out=str(target),
                            path=os.path.abspath(f))
        results.append(res)
        try:
            res.sha256 = _sha256(f)
            m = load_mission(f)
            target = m.output_dir() or target
            formats = tuple(dict.fromkeys(m.outputs.formats + (["html"] if report else [])))
            res.name, res.out = m.name, str(target)
            notice = m.output_dir_notice()
            res.warnings = [notice] if notice else []
        except Exception as exc:  # noqa: BLE001 - one mission's error, not the batch's
            res.failed(*describe(exc))
            continue
        key = os.path.realpath(target)
        if key in owners:
            raise InputError(
                f"mission files {owners[key]} and {f} would both write {target}; rename one, "
                "or give one an outputs.dir of its own; nothing was run")
        owners[key] = str(f)
        kept = done.get(os.path.realpath(f))
        if (kept is not None and kept.get("sha256") == res.sha256 and kept.get("out") == res.out
                and kept.get("files") and all(os.path.isfile(p) for p in kept["files"])):
            results[i] = MissionResult(**{**kept, "file": str(f), "path": res.path,
                                          "resumed": True})
            continue
        od = OutputDir(target, force=force)
        try:
            od.check(output_names(list(formats)))  # exists without --force, locked, an input
        finally:
            od.abort()
        missions.append(BatchMission(index=i, file=str(f), path=os.path.abspath(f),
                                     out=str(target), formats=formats))
    return missions, results


def _sha256(path: Path) -> str:
    import hashlib

    return hashlib.sha256(path.read_bytes()).hexdigest()


def _earlier_batch(summary: Path) -> dict[str, dict[str, Any]]:
    """The missions an earlier ``batch.json`` lists as ok, by the real path of their file.

    Raises
    ------
    InputError
        No such file, or not a batch.json (names ``--resume``).
    """
    import json

    if not summary.is_file():
        raise InputError(f"--resume: {summary} does not exist (no earlier batch in this "
                         "--out); run without --resume")
    try:
        rows = json.loads(summary.read_text(encoding="utf-8"))["results"]
        known = {f.name for f in fields(MissionResult)}
        return {os.path.realpath(r["path"]): {k: v for k, v in r.items() if k in known}
                for r in rows if r["status"] == "ok"}
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError(f"--resume: {summary} is not a batch summary of fm2uav batch "
                         f"({type(exc).__name__}: {exc}); run without --resume and with "
                         "--force to start the batch over") from None


def _describe(exc: BaseException) -> tuple[str, int]:
    """``(message, exit code)`` of a mission's error; a bug is exit 70 with its type."""
    from ..errors import describe_error

    known = describe_error(exc)
    if known is None:
        return f"internal error: {type(exc).__name__}: {exc}", EXIT_INTERNAL
    return known


def batch_lock(out: str | os.PathLike[str]) -> contextlib.AbstractContextManager[None]:
    """Hold the batch's folder ``out`` from the first check to ``batch.json``
    (``.<out name>.batch.lock`` beside it, removed when released).

    A second batch into the same ``--out`` is refused at once with an
    :class:`~fm2uav.InputError` naming the holder (each mission folder is locked on its
    own as it is written; this keeps two batches from both writing ``batch.json``).
    """
    from ..io.outdir import folder_lock

    return folder_lock(out, "batch", "fm2uav batch")


def _batch_file_set(out: str | os.PathLike[str]) -> Any:
    """The output set of ``batch.json``: merged into ``out``, beside the missions' folders."""
    from ..io.outdir import OutputDir

    return OutputDir(out, force=True, merge=True)


def write_batch_file(out: str | os.PathLike[str], payload: dict[str, Any]) -> Path:
    """Write ``payload`` as ``out/batch.json`` (whole: staged, then moved in).

    Returns
    -------
    Path
        The file written.
    """
    from .outputs import write_json

    od = _batch_file_set(out)
    try:
        od.check([BATCH_FILE])
        write_json(od, BATCH_FILE, payload)
        od.finish()
    except BaseException:
        od.abort()
        raise
    return Path(out) / BATCH_FILE


# ----------------------------------------------------------------- on a worker
#: Prefix of a worker's private folder: ``fm2uav-batch-<pid>-XXXX`` in the system's temporary
#: folder (its process id, so that a folder left by a killed worker is known to be stale).
WORK_PREFIX = "fm2uav-batch-"


def _remove_stale_work(tmpdir: str | os.PathLike[str]) -> list[Path]:
    """Remove the private folders of workers that no longer run (killed mid-mission: a
    SIGKILL leaves its folder behind); return them. Folders of live processes stay."""
    import shutil

    removed = []
    for d in Path(tmpdir).glob(f"{WORK_PREFIX}*-*"):
        pid = d.name[len(WORK_PREFIX):].split("-", 1)[0]
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        try:
            os.kill(int(pid), 0)
        except ProcessLookupError:  # gone: nobody writes there any more
            shutil.rmtree(d, ignore_errors=True)
            removed.append(d)
        except OSError:  # alive, or not ours to ask about
            continue
    return removed


def plan_mission_files(context: dict[str, Any], mission: BatchMission) -> dict[str, Any]:
    """Worker side: run one mission into a private folder, return its files as bytes.

    Parameters
    ----------
    context : dict
        ``cwd``: the current folder of the main process.
    mission : BatchMission

    Returns
    -------
    dict
        ``ok``; ``files`` (relative name → bytes), ``name``, ``length_m``,
        ``waypoints`` when ok; ``error``, ``exit_code`` when not; ``time_s``,
        ``warnings`` always. A mission's error is a result, never an exception.
    """
    import tempfile
    import warnings

    from ..io.mission import load_mission
    from ..io.outdir import OutputDir
    from .run import run_mission

    t0 = time.perf_counter()
    here = os.path.isabs(mission.file) or os.getcwd() == context.get("cwd")
    file = mission.file if here else mission.path
    out: dict[str, Any] = {"ok": False}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            m = load_mission(file)
            _remove_stale_work(tempfile.gettempdir())
            with tempfile.TemporaryDirectory(prefix=f"{WORK_PREFIX}{os.getpid()}-") as tmp:
                od = OutputDir(Path(tmp) / "set")
                try:
                    run = run_mission(m, od, mission_file=file, formats=list(mission.formats))
                    od.finish()
                except BaseException:
                    od.abort()
                    raise
                root = Path(tmp) / "set"
                files = {p.relative_to(root).as_posix(): p.read_bytes()
                         for p in sorted(root.rglob("*")) if p.is_file()}
            out.update(ok=True, files=files, name=m.name,
                       length_m=run.info.get("length_m"), waypoints=run.info.get("waypoints"))
        except Exception as exc:  # noqa: BLE001 - the mission's failure, reported in the batch
            out["error"], out["exit_code"] = _describe(exc)
    out["warnings"] = list(dict.fromkeys(
        str(w.message) for w in caught
        if (getattr(w.category, "__module__", "") or "").startswith("fm2uav")))
    out["time_s"] = time.perf_counter() - t0
    return out


# ----------------------------------------------------------------- the batch
def write_mission_set(out: str | os.PathLike[str], files: dict[str, bytes], *,
                      force: bool = False) -> list[str]:
    """Write one mission's files as an output set at ``out`` (whole, or nothing).

    Returns
    -------
    list of str
        The files written (paths).
    """
    from ..io.outdir import OutputDir

    od = OutputDir(out, force=force)
    try:
        od.check(list(files))
        for name, data in files.items():
            with od.open(name, "wb") as fh:
                fh.write(data)
        od.finish()
    except BaseException:
        od.abort()
        raise
    return [str(p) for p in od.written]


def run_batch(missions: Sequence[BatchMission], results: list[MissionResult], pool: Any, *,
              force: bool = False,
              on_result: Callable[[MissionResult], None] | None = None) -> list[MissionResult]:
    """Run the missions on ``pool``, writing each one's output set as its result arrives.

    Parameters
    ----------
    missions : sequence of BatchMission
        From :func:`prepare_batch`.
    results : list of MissionResult
        From :func:`prepare_batch`; the missions' rows are filled in place.
    pool : InlinePool, LocalPool or DaskPool
        :func:`fm2uav.experiments._executors.make_pool`. A worker that dies costs
        its mission one attempt: it is run again on another worker (the local pool:
        once; Dask: ``distributed.scheduler.allowed-failures`` times), then failed
        with the reason.
    force : bool
        Replace existing output folders (``--force``).
    on_result : callable, optional
        Called with each mission's result as it is known (progress).

    Returns
    -------
    list of MissionResult
        ``results``. A mission that failed, or whose folder could not be written, is
        ``failed`` with the reason; the others go on. Interrupted (KeyboardInterrupt,
        :class:`~fm2uav.io.outdir.Interrupted`): the pool is stopped, the sets written
        so far are kept, the rest stay ``not run``, and the exception propagates.
    """
    from ..experiments._executors import Job

    context = {"cwd": os.getcwd()}
    jobs = [Job(context, [m], tag=m.index) for m in missions]
    done: set[int] = set()
    try:
        for o in pool.run(plan_mission_files, jobs):
            m: BatchMission = o.unit
            if m.index in done:  # never twice (an executor gives one outcome per unit)
                continue
            done.add(m.index)
            res = results[m.index]
            res.attempt, res.worker = o.attempt, o.worker
            value = o.value if o.ok else {"ok": False, "error": str(o.value),
                                          "exit_code": EXIT_INTERNAL}
            res.time_s = value.get("time_s")
            res.warnings = list(dict.fromkeys(res.warnings + value.get("warnings", [])))
            if not value["ok"]:
                res.failed(value["error"], value["exit_code"])
            else:
                res.name = value.get("name", res.name)
                res.length_m, res.waypoints = value.get("length_m"), value.get("waypoints")
                try:
                    res.files = write_mission_set(m.out, value["files"], force=force)
                    res.status, res.error, res.exit_code = "ok", "", 0
                except Exception as exc:  # noqa: BLE001 - this mission's folder, not the batch
                    res.failed(*_describe(exc))
            if on_result is not None:
                on_result(res)
    except BaseException:
        pool.close(now=True)
        raise
    pool.close()
    return results
