"""Files of a sweep folder: the case log, the references, the summary, the lock.

Formats and guarantees are described in :mod:`fm2uav.experiments.runner`. Every
damaged file is reported as a one-line :class:`~fm2uav.InputError` naming the
file and the fix (except torn or damaged log lines: dropped with a warning, their
cases run again).
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import os
import shutil
import threading
import time
import zipfile
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError

#: Name of the case log in a sweep folder.
LOG_NAME = "cases.jsonl"
LOCK_NAME = ".sweep.lock"
LOG_VERSION = 1

# ----------------------------------------------------------------- rows
CaseKey = tuple[int, float, float]


def case_key(row: dict[str, Any]) -> CaseKey:
    return int(row["pair"]), round(float(row["alpha"]), 10), round(float(row["beta"]), 10)


def finite(v: Any) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) \
        and math.isfinite(float(v))


def checked_row(row: dict[str, Any], metric_columns: list[str]) -> dict[str, Any]:
    """Normalise a case row: status "ok" only if every number is finite, else "failed"."""
    row = dict(row)
    if row.get("status") != "ok":
        row["status"] = "failed"
        row["error"] = str(row.get("error") or "failed (no reason recorded)")
        return row
    need = ["fm2_time_s", "length_m", "clearance_m", *metric_columns]
    bad = [c for c in need if not finite(row.get(c))]
    if bad:
        more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
        row["status"] = "failed"
        row["error"] = f"{bad[0]} is {row.get(bad[0], 'missing')}, not a finite number{more}"
    else:
        row["error"] = ""
    return row


def latest_rows(rows: list[dict[str, Any]]) -> dict[CaseKey, dict[str, Any]]:
    """One row per case: the last one, except that an "ok" row is never replaced."""
    out: dict[CaseKey, dict[str, Any]] = {}
    for r in rows:
        k = case_key(r)
        if k in out and out[k]["status"] == "ok" and r["status"] != "ok":
            continue
        out[k] = r
    return out


def number(v: Any) -> float | int:
    return int(v) if isinstance(v, (int, np.integer)) and not isinstance(v, bool) else float(v)


def plain(v: Any) -> Any:
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating, float)):
        return float(v) if math.isfinite(float(v)) else None
    return v


# ----------------------------------------------------------------- the log
def encode_line(record: dict[str, Any]) -> bytes:
    clean = {k: pv for k, v in record.items() if (pv := plain(v)) is not None}
    payload = json.dumps(clean, sort_keys=True, separators=(",", ":"), allow_nan=False).encode()
    return b"%08x %s\n" % (zlib.crc32(payload), payload)


def decode_line(line: bytes) -> dict[str, Any] | None:
    if len(line) < 11 or line[8:9] != b" ":
        return None
    try:
        crc = int(line[:8], 16)
    except ValueError:
        return None
    payload = line[9:]
    if zlib.crc32(payload) != crc:
        return None
    try:
        rec = json.loads(payload)
    except ValueError:
        return None
    return rec if isinstance(rec, dict) else None


def _valid_row(rec: dict[str, Any]) -> bool:
    try:
        case_key(rec)
    except (KeyError, TypeError, ValueError):
        return False
    return rec.get("status") in ("ok", "failed")


def _fsync_dir(path: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


class CaseLog:
    """The append-only case log of a sweep folder (format in the module docstring).

    Parameters
    ----------
    path : Path
        ``out_dir/cases.jsonl``.
    identity : str
        :meth:`SweepConfig.identity_hash` of the sweep.
    """

    def __init__(self, path: Path, identity: str) -> None:
        self.path = path
        self.identity = identity
        self._fd: int | None = None
        self._keep: int | None = None  # bytes to keep (a torn tail is cut off on open)
        self._synced = 0.0

    def read(self, warn: Callable[[str], None]) -> list[dict[str, Any]]:
        """Rows of the log (damaged lines dropped with a warning)."""
        if not self.path.exists():
            return []
        if not self.path.is_file():
            raise InputError(f"{self.path} is not a file; remove it or pass --force to start over")
        try:
            data = self.path.read_bytes()
        except OSError as exc:
            raise InputError(f"cannot read {self.path}: {exc.strerror}; check its permissions") from None
        lines = data.split(b"\n")
        tail = lines.pop()  # b"" when the file ends with a newline
        if tail:
            self._keep = len(data) - len(tail)
            if lines:
                warn(f"{self.path}: the last line is incomplete (a write cut short); dropped it, "
                     "its case will be run again")
        if not lines:
            return []
        header = decode_line(lines[0])
        if header is None or "fm2uav_sweep_log" not in header:
            raise InputError(
                f"{self.path} does not start with a sweep log header (damaged, or not written by "
                "fm2uav); delete it to run every case again, or pass --force to start over")
        if header["fm2uav_sweep_log"] != LOG_VERSION:
            raise InputError(
                f"{self.path} is a version {header['fm2uav_sweep_log']} sweep log, this fm2uav "
                f"reads version {LOG_VERSION}; pass --force to start over or use another --out")
        if header.get("identity") != self.identity:
            raise InputError(
                f"{self.path} belongs to a sweep with a different configuration; pass --force "
                "(fresh=True) to discard it or choose another output directory")
        rows, bad = [], []
        for n, line in enumerate(lines[1:], start=2):
            rec = decode_line(line)
            if rec is None or not _valid_row(rec):
                bad.append(n)
            else:
                rows.append(rec)
        if bad:
            where = ", ".join(str(n) for n in bad[:5]) + (" ..." if len(bad) > 5 else "")
            warn(f"{self.path}: {len(bad)} damaged line(s) (line {where}: checksum or format) "
                 "ignored; their cases will be run again")
        return rows

    def open(self) -> None:
        """Open for appending (cut a torn tail, write the header of a new log)."""
        try:
            if self._keep is not None:
                os.truncate(self.path, self._keep)
                self._keep = None
            self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
            if os.fstat(self._fd).st_size == 0:
                self._write(encode_line({"fm2uav_sweep_log": LOG_VERSION, "identity": self.identity,
                                     "created": time.time()}))
                os.fsync(self._fd)
                _fsync_dir(self.path.parent)
        except OSError as exc:
            raise InputError(f"cannot write {self.path}: {exc.strerror}; fix the permissions or "
                             "choose another --out") from None

    def _write(self, line: bytes) -> None:
        assert self._fd is not None
        size = os.fstat(self._fd).st_size
        try:
            view = memoryview(line)
            while view:
                view = view[os.write(self._fd, view):]
        except OSError as exc:
            with contextlib.suppress(OSError):
                os.ftruncate(self._fd, size)  # never leave a partial line behind
            raise InputError(f"cannot write {self.path}: {exc.strerror}; free space (or fix the "
                             "permissions) and run the same sweep again to resume") from None

    def append(self, row: dict[str, Any]) -> None:
        """Append one case row (one write; fsync at most once a second)."""
        self._write(encode_line(row))
        now = time.monotonic()
        if now - self._synced > 1.0:
            os.fsync(self._fd)
            self._synced = now

    def close(self) -> None:
        if self._fd is not None:
            with contextlib.suppress(OSError):
                os.fsync(self._fd)
            os.close(self._fd)
            self._fd = None


# ----------------------------------------------------------------- other files
def _damaged(path: Path, why: str, fix: str) -> InputError:
    return InputError(f"{path} is damaged ({why}); {fix}")


def write_atomic(path: Path, write: Callable[[Path], None]) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        write(tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
    _fsync_dir(path.parent)


def read_config_json(path: Path) -> dict[str, Any] | None:
    if not path.exists():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        raise _damaged(path, f"not valid JSON: {exc}",
                       "delete it (the cases are checked against the log) or pass --force to "
                       "start over") from None
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror}; check its permissions") from None
    if not isinstance(data, dict):
        raise _damaged(path, "not a JSON object", "delete it or pass --force to start over")
    return data


def load_references(path: Path) -> dict[tuple[int, str], dict[str, Any]]:
    refs: dict[tuple[int, str], dict[str, Any]] = {}
    if not path.exists():
        return refs
    fix = "delete it to compute the references again (the cases are kept)"
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            for m in meta:
                key = (int(m["pair"]), str(m["model"]))
                entry = dict(m)
                for k in ("cost", "length", "time_s"):
                    entry[k] = math.nan if entry.get(k) is None else float(entry[k])
                if not m["error"]:
                    p = np.asarray(z[f"path_{m['pair']}_{m['model']}"], dtype=float)
                    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 2 or not np.all(np.isfinite(p)):
                        raise ValueError(f"reference path {key} is not a finite (n, 2) array")
                    entry["path"] = p
                refs[key] = entry
    except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile,
            zlib.error) as exc:
        raise _damaged(path, f"{type(exc).__name__}: {exc}", fix) from None
    return refs


def save_references(path: Path, refs: dict[tuple[int, str], dict[str, Any]]) -> None:
    arrays = {}
    meta = []
    for (pair, model), r in sorted(refs.items()):
        meta.append({k: (v if v is None or isinstance(v, str) else number(v))
                     for k, v in r.items() if k != "path"})
        if not r["error"]:
            arrays[f"path_{pair}_{model}"] = np.asarray(r["path"])

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, meta=np.array(json.dumps(meta)), **arrays)

    write_atomic(path, write)


def read_summary(path: Path, columns: list[str], warn: Callable[[str], None]) -> list[dict[str, Any]]:
    """Rows of an existing summary (CSV / Parquet file or dataset of an older fm2uav)."""
    fix = "delete it to run its cases again, or pass --force to start over"
    if path.suffix == ".parquet":
        try:
            import pyarrow.parquet as pq

            if path.is_dir():
                rows: list[dict[str, Any]] = []
                for part in sorted(path.glob("part-*.parquet")):
                    rows.extend(pq.read_table(part).to_pylist())
                return rows
            return pq.read_table(path).to_pylist()
        except Exception as exc:  # noqa: BLE001 - pyarrow raises many types on a damaged file
            raise _damaged(path, f"{type(exc).__name__}: {exc}", fix) from None
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise _damaged(path, f"{type(exc).__name__}: {exc}", fix) from None
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    elif len(lines) > 1:  # the old streaming writer was cut mid-row
        warn(f"{path}: the last row is incomplete (a write cut short); dropped it, its case will "
             "be run again")
        lines.pop()
    rows = []
    reader = csv.DictReader(lines)
    if reader.fieldnames is None or not {"pair", "alpha", "beta", "status"} <= set(reader.fieldnames):
        raise _damaged(path, "no header with pair, alpha, beta, status", fix)
    for n, r in enumerate(reader, start=2):
        try:
            out: dict[str, Any] = {}
            for k, v in r.items():
                if k is None or v is None:
                    raise ValueError("wrong number of fields")
                if k in ("status", "error"):
                    out[k] = v
                elif k == "pair":
                    out[k] = int(v)
                else:
                    out[k] = float(v) if v != "" else math.nan
        except ValueError as exc:
            raise _damaged(path, f"line {n}: {exc}", fix) from None
        rows.append(out)
    return rows


def write_summary(path: Path, rows: list[dict[str, Any]], columns: list[str]) -> None:
    if path.suffix == ".parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        cols = columns_of(rows, columns)
        arrays = {c: (pa.array(list(v), type=pa.string()) if v.dtype == object else pa.array(v))
                  for c, v in cols.items()}

        def write(tmp: Path) -> None:
            pq.write_table(pa.table(arrays), tmp)
    else:
        def write(tmp: Path) -> None:
            with open(tmp, "w", newline="", encoding="utf-8") as fh:
                w = csv.writer(fh)
                w.writerow(columns)
                for r in rows:
                    vals = []
                    for c in columns:
                        v = r.get(c)
                        if c in ("status", "error"):
                            vals.append("" if v is None else str(v))
                        elif v is None or not finite(v):
                            vals.append("")
                        else:
                            vals.append(repr(int(v)) if c == "pair" else repr(float(v)))
                    w.writerow(vals)

    if path.is_dir():  # an older fm2uav wrote a dataset directory here
        aside = path.with_name(f".{path.name}.old-{os.getpid()}")
        os.replace(path, aside)
        write_atomic(path, write)
        shutil.rmtree(aside, ignore_errors=True)
    else:
        write_atomic(path, write)


def columns_of(rows: list[dict[str, Any]], names: list[str]) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    for c in names:
        vals = [r.get(c) for r in rows]
        if c in ("status", "error"):
            out[c] = np.array(["" if v is None else str(v) for v in vals], dtype=object)
        elif c == "pair":
            out[c] = np.array(vals, dtype=np.int64)
        else:
            out[c] = np.array([float(v) if finite(v) else math.nan for v in vals], dtype=float)
    return out



# ----------------------------------------------------------------- lock
_HELD: dict[tuple[str, int], int] = {}


@contextlib.contextmanager
def sweep_lock(out_dir: str | os.PathLike[str]) -> Iterator[None]:
    """Hold the sweep folder ``out_dir`` for this thread (re-entrant).

    Raises :class:`~fm2uav.InputError` at once if another process or thread
    holds it. The lock (``flock`` on ``out_dir/.sweep.lock``) dies with its
    process, so a killed sweep never leaves a stale lock behind.
    """
    out = Path(out_dir)
    prepare_dir(out)
    key = (str(out.resolve()), threading.get_ident())
    if key in _HELD:
        _HELD[key] += 1
        try:
            yield
        finally:
            _HELD[key] -= 1
        return
    try:
        import fcntl
    except ImportError:  # not POSIX: no locking
        yield
        return
    path = out / LOCK_NAME
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError as exc:
        raise InputError(f"cannot write {path}: {exc.strerror}; choose another --out") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 200, 0).decode(errors="replace").strip() or "another process"
        os.close(fd)
        raise InputError(f"{out} is in use by another sweep ({holder}); wait for it to finish "
                         "or choose another --out") from None
    except OSError as exc:
        os.close(fd)
        raise InputError(f"cannot lock {path}: {exc.strerror} (the file system does not support "
                         "locks?); choose an --out on a local disk") from None
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()}, since {time.strftime('%Y-%m-%d %H:%M:%S')}\n".encode(), 0)
    except OSError:
        pass
    _HELD[key] = 1
    try:
        yield
    finally:
        del _HELD[key]
        os.close(fd)  # releases the lock; the file stays (removing it would race)


def prepare_dir(out: Path) -> None:
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} exists and is not a directory; choose another path")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create --out {out}: {exc.strerror}; choose another path") from None


