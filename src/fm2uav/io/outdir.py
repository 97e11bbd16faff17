"""Whole output sets: a command's files appear all together, or not at all.

:class:`OutputDir` is the one output-directory helper every ``fm2uav`` command
writes through:

* files are written into a temporary folder beside the target
  (``.<name>.tmp-XXXX`` in the same parent, so the final rename is atomic) and
  the folder is renamed into place by :meth:`OutputDir.finish`;
* an existing target is refused unless ``force``; with ``force`` the *whole* old
  set is moved aside (``.<name>.old-XXXX``), the new one renamed into place, then
  the old one removed — an old mission's exports never remain beside the new ones;
* a run that fails (an exception, SIGINT/SIGTERM, a full disk, a read-only
  folder) removes its temporary folder: the previous set stays intact, and no
  stray temporary file is left;
* a lock (``fcntl.flock`` on ``.<name>.lock`` beside the target, removed at the
  end) refuses a second run into the same folder while one is writing;
* an ``OutputDir`` inside the target of an active one (a per-case subfolder)
  writes into the parent's temporary folder, so the subfolders belong to the
  parent's set;
* **inputs are never inside what is replaced**: a target that holds (or is) one of
  the command's inputs — given to ``OutputDir(inputs=...)``, or noted by any
  reader in the running :func:`fm2uav._validate.input_log` (every file reader
  calls :func:`fm2uav._validate.input_file`; the command line opens the log for
  every command, so a new command cannot forget one) — is refused, naming the input
  and ``--out``/``--force``: before any work for the inputs known then, and again
  just before the old set is moved aside for every input read meanwhile;
* a target that is a **symbolic link** to a folder is followed: the set replaces
  the folder the link points to (staged beside it, so the rename stays atomic),
  and the link is left as it was, pointing at the new set.

If files appear in the target *while* the run writes (a library that writes
into the folder directly, e.g. a resumable sweep's results log), the target is
not swapped: the staged files are moved in one by one instead, so nothing that
was written meanwhile is lost.

Exit codes and messages are the CLI's business: every refusal here is an
:class:`~fm2uav.errors.InputError` naming ``--out`` / ``--force``.
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ..errors import InputError
from ._stops import (  # noqa: F401  (the stop signals: a light module of their own)
    _ACTIVE,
    Interrupted,
    _Commit,
    abort_all,
    active_sets,
    finish_all,
    _on_stop_signal,
    _signals_held,
    install_stop_signals,
    interrupt_signals,
    raise_if_stopped,
    stop_reported,
    unreported_stop,
)

__all__ = ["OutputDir", "Interrupted", "active_sets", "finish_all", "abort_all",
           "interrupt_signals", "install_stop_signals", "raise_if_stopped", "stop_reported",
           "unreported_stop"]


def _umask_mode(path: Path, directory: bool = False) -> None:
    """Give a temporary file/folder the permissions of a normally created one."""
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(path, (0o777 if directory else 0o666) & ~mask)


def _real(path: Path) -> str:
    return os.path.realpath(path)


def _spellings(path: Path) -> set[str]:
    """The absolute names of ``path``: as written (a link itself) and resolved (its file)."""
    link = os.path.join(os.path.realpath(os.path.dirname(os.path.abspath(path))),
                        os.path.basename(os.path.abspath(path)))
    return {link, os.path.realpath(path)}


def _under(path: str, folder: str) -> bool:
    """Whether the absolute ``path`` is ``folder`` or lies inside it."""
    return path == folder or path.startswith(folder.rstrip(os.sep) + os.sep)


def _is_dangerous(target: Path) -> str | None:
    """Why replacing ``target`` as a whole would be a mistake, or None."""
    t = target.resolve()
    home = Path.home().resolve()
    if t == Path(t.anchor):
        return "it is the root of the file system"
    if t == home or t in home.parents:
        return "it is (or contains) your home folder"
    try:
        cwd = Path.cwd().resolve()
    except FileNotFoundError:  # the current folder was deleted: it is not inside anything
        cwd = None
    if cwd is not None and (t == cwd or t in cwd.parents):
        return "it is (or contains) the current folder"
    if (t / ".git").exists():
        return "it holds a git repository"
    return None


def _listing(path: Path) -> dict[str, tuple[int, int]]:
    """Name -> (mtime_ns, size) of the entries of ``path`` (empty if missing)."""
    try:
        with os.scandir(path) as it:
            out = {}
            for e in it:
                try:
                    st = e.stat(follow_symlinks=False)
                    out[e.name] = (st.st_mtime_ns, st.st_size)
                except OSError:
                    out[e.name] = (0, 0)
            return out
    except (FileNotFoundError, NotADirectoryError):
        return {}


class OutputDir:
    """An output folder written as one set (see the module docstring).

    Parameters
    ----------
    path : path-like
        The folder the outputs end up in (CLI ``--out``).
    force : bool
        Replace an existing folder as a whole (CLI ``--force``).
    merge : bool
        Never swap the folder: move the staged files into it one by one at the end
        (for folders a library also writes into directly, e.g. a resumable sweep).
        The staged files still appear only when the run succeeds.
    inputs : iterable of path or (path, what)
        The command's input files and folders (``what`` names one in a message,
        e.g. ``"the mission file"``); added to those of the running
        :func:`~fm2uav._validate.input_log`. None may lie inside the target.
    owned : iterable of str
        With ``merge``: names of files a library writes into the folder directly
        (they replace an input of that name, so one is refused).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> with OutputDir(root / "run") as out:
    ...     with out.open("a.txt") as fh:
    ...         _ = fh.write("one")
    >>> sorted(p.name for p in (root / "run").iterdir())
    ['a.txt']
    """

    def __init__(self, path: str | os.PathLike[str], *, force: bool = False,
                 merge: bool = False, inputs: Iterable[Any] = (),
                 owned: Iterable[str] = ()) -> None:
        if str(path).strip() == "":
            raise InputError("--out is empty; give the folder to write into (e.g. --out "
                             "out/mission)")
        path = os.path.expanduser(path)  # "~/out" in quotes, or a mission's outputs.dir
        from .. import _validate  # numpy: not on the light path of an output set

        gone = _validate.cwd_gone(path)
        if gone:
            raise InputError(f"--out {path}: {gone}")
        #: The folder as given (messages, :attr:`written`).
        self.given = Path(path)
        #: The folder written: the given one, or the folder a symbolic link points to
        #: (``.`` and ``..`` by their absolute name: the set is staged beside the folder).
        self.path = (Path(os.path.realpath(self.given)) if os.path.islink(self.given)
                     else Path(os.path.abspath(self.given)) if self.given.name in ("", "..")
                     else self.given)
        if self.path.name == "":
            raise InputError(f"--out {self.given} is the root of the file system; give a "
                             "dedicated folder (e.g. --out out/mission)")
        for parent in self.path.parents:  # a file where a folder of the path should be
            if parent.exists() or os.path.islink(parent):
                if not parent.is_dir():
                    raise InputError(f"--out {self.given}: {parent} is a file, not a folder; "
                                     "choose another --out")
                break
        self.force = force
        self.merge = merge
        self.inputs: list[tuple[Path, str]] = [
            (Path(i[0]), str(i[1])) if isinstance(i, tuple) else (Path(i), "an input")
            for i in inputs]
        self._noted = _validate.noted_inputs()  # the live list of the command's reads
        self._owned = list(owned)
        self.written: list[Path] = []
        self.parent_set: OutputDir | None = None
        self._stage: Path | None = None
        self._lock_fd: int | None = None
        self._lock_path: Path | None = None
        self._made_dirs: list[Path] = []
        self._before: dict[str, tuple[int, int]] | None = None
        self._checked = False
        self._done = False
        for od in reversed(_ACTIVE):
            if od is not self and od._contains(self.path):
                self.parent_set = od
                break
        if self.parent_set is None:
            _ACTIVE.append(self)
            _Commit.done = False

    # -- context manager ----------------------------------------------------------------
    def __enter__(self) -> OutputDir:
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        if exc_type is None:
            self.finish()
        else:
            self.abort()

    # -- checks -------------------------------------------------------------------------
    def _contains(self, other: Path) -> bool:
        a, b = os.path.realpath(self.path), os.path.realpath(other)
        return b != a and b.startswith(a.rstrip(os.sep) + os.sep)

    def _all_inputs(self) -> list[tuple[Path, str]]:
        return self.inputs + [e for e in (self._noted or ()) if e not in self.inputs]

    def _check_inputs(self, names: Iterable[str] = ()) -> None:
        """Refuse (InputError) a target that holds any of the command's inputs, naming each.

        A swapped set replaces the whole folder, so any input inside it counts; a
        merged set (``merge``) only replaces the files of ``names`` (and ``owned``).
        """
        if self.merge:
            written = (os.path.relpath(w, self.given) for w in self.written)
            doomed = {_real(self.path / n) for n in (*names, *self._owned, *written)}
        hits = []
        for path, what in self._all_inputs():
            if self.merge:
                hit = bool(_spellings(path) & doomed)
            else:
                hit = any(_under(q, _real(self.path)) for q in _spellings(path))
            if hit and all(_real(path) != _real(p) for p, _ in hits):
                hits.append((path, what))
        if not hits:
            return
        many = len(hits) > 1
        verb = "is" if not many and _real(hits[0][0]) == _real(self.path) else "holds"
        them = "them" if many else "it"
        why = (f"an output of the same name would replace {them}" if self.merge else
               "the output set replaces the folder as a whole (with --force), which would "
               f"delete {them}")
        some = (f"{len(hits)} inputs of this command: " if many else
                "an input of this command: ") + ", ".join(f"{p} ({w})" for p, w in hits)
        raise InputError(
            f"--out {self.given} {verb} {some}; {why} — choose another --out (a new folder) or "
            f"move the input{'s' if many else ''} out of {self.given}")

    def _relative(self) -> Path:
        assert self.parent_set is not None
        return Path(os.path.relpath(os.path.realpath(self.path),
                                    os.path.realpath(self.parent_set.path)))

    def check(self, names: Iterable[str] = ()) -> None:
        """Refuse (InputError) before any work: a target that is a file, a folder that
        already holds files (unless ``force``), another run writing into it.

        ``names`` are the files the command will write; a clash is named first.
        """
        if self.parent_set is not None:
            self.parent_set.check(())
            return
        if self._checked:
            return
        try:
            self._check(list(names))
        except BaseException:
            self.abort()  # a refused set holds no lock and is not active any more
            raise

    def _check(self, names: list[str]) -> None:
        p, shown = self.path, self.given
        if p.exists() and not p.is_dir():
            raise InputError(f"--out {shown} exists and is not a folder; choose another --out")
        if p.is_dir() and not os.access(p, os.W_OK | os.X_OK):
            raise InputError(f"--out {shown} is read-only (permission denied); nothing was "
                             "written; fix its permissions or choose another --out")
        self._check_inputs(names)
        self._lock()
        entries = sorted(_listing(p))
        if entries:
            clashes = [n for n in names if (p / n).exists()] or entries
            first = shown / clashes[0]
            more = len(entries) - 1
            if not self.force:
                raise InputError(
                    f"{first} already exists" + (f" (and {more} more in {shown})" if more else "")
                    + "; pass --force to replace the whole output folder or choose another "
                    "--out")
            why = _is_dangerous(p)
            if why:
                raise InputError(f"--force would replace the whole folder {shown}, but {why}; "
                                 "give a dedicated --out folder")
        self._before = _listing(p)
        self._checked = True

    # -- the lock -----------------------------------------------------------------------
    def _lock(self) -> None:
        if self._lock_fd is not None:
            return
        lock = self._parent() / f".{self.path.name}.lock"
        self._lock_fd, self._lock_path = take_lock(lock, self.given, "fm2uav run"), lock
        self._clean_stale()

    def _unlock(self) -> None:
        if self._lock_fd is None:
            return
        release_lock(self._lock_fd, self._lock_path)
        self._lock_fd = None

    def _clean_stale(self) -> None:
        """Remove temporary folders of this target left by a killed run (we hold the lock)."""
        parent = self.path.parent if str(self.path.parent) else Path(".")
        prefixes = (f".{self.path.name}.tmp-", f".{self.path.name}.old-")
        try:
            with os.scandir(parent) as it:
                stale = [Path(e.path) for e in it if e.name.startswith(prefixes)]
        except OSError:
            return
        for s in stale:
            shutil.rmtree(s, ignore_errors=True)

    def _parent(self) -> Path:
        parent, missing = make_parent(self.path)
        self._made_dirs.extend(missing)  # innermost first
        return parent

    # -- writing ------------------------------------------------------------------------
    def _staging(self) -> Path:
        if self.parent_set is not None:
            d = self.parent_set._staging() / self._relative()
            d.mkdir(parents=True, exist_ok=True)
            return d
        if self._done:
            raise RuntimeError(f"output set {self.path} is already finished")
        if not self._checked:
            self.check(())
        if self._stage is None:
            parent = self._parent()
            try:
                with _signals_held():  # no stop between making the folder and knowing it
                    self._stage = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.tmp-",
                                                        dir=parent))
            except OSError as exc:
                raise _os_error(exc, parent, "write into") from None
            _umask_mode(self._stage, directory=True)
        return self._stage

    def _final(self, name: str) -> Path:
        return self.given / name

    @contextmanager
    def open(self, name: str, mode: str = "w", **kwargs: Any) -> Iterator[Any]:
        """Open ``name`` (may contain ``/``) in the set for writing."""
        tmp = self.target(name)
        if "b" not in mode:
            kwargs.setdefault("encoding", "utf-8")
        try:
            with open(tmp, mode, **kwargs) as fh:
                yield fh
        except OSError as exc:
            if exc.errno in _WRITE_ERRNOS:
                raise _os_error(exc, self._final(name), "write") from None
            raise
        self.commit(tmp, name)

    def target(self, name: str) -> Path:
        """A path in the temporary folder for libraries that write by filename;
        call :meth:`commit` with it when written."""
        tmp = self._staging() / name
        tmp.parent.mkdir(parents=True, exist_ok=True)
        return tmp

    def commit(self, tmp: Path, name: str) -> Path:
        """Record the file ``name`` written at ``tmp`` (from :meth:`target`) as part of
        the set; returns its final path."""
        dest = self._staging() / name
        if Path(tmp) != dest:
            os.replace(tmp, dest)
        final = self._final(name)
        if final not in self.written:
            self.written.append(final)
        if self.parent_set is not None and final not in self.parent_set.written:
            self.parent_set.written.append(final)
        return final

    def staged(self, name: str) -> Path:
        """Where ``name`` is until :meth:`finish` (to read back a file just written)."""
        return self._staging() / name

    # -- the end ------------------------------------------------------------------------
    def finish(self) -> None:
        """Rename the set into place (replacing an old set as a whole); release the lock."""
        if self.parent_set is not None or self._done:
            return
        with _signals_held():  # a stop signal waits until the set is in place (or removed)
            try:
                if self._stage is not None:
                    self._swap()
            except BaseException:
                self.abort()
                raise
            self._done = True
            self._forget()
            self._unlock()

    def _swap(self) -> None:
        stage, target = self._stage, self.path
        assert stage is not None
        self._check_inputs()  # every input read since the first check, before anything moves
        changed = _listing(target) != (self._before or {})
        try:
            if (changed or self.merge) and target.is_dir():
                # someone wrote into the folder meanwhile: keep their files, add ours
                self._merge(stage, target)
                shutil.rmtree(stage, ignore_errors=True)
            else:
                old = None
                if target.is_dir():
                    if any(target.iterdir()):
                        old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-",
                                                    dir=target.parent))
                        os.rmdir(old)
                        os.rename(target, old)
                    else:
                        os.rmdir(target)
                try:
                    os.rename(stage, target)
                except BaseException:
                    if old is not None and not target.exists():
                        os.rename(old, target)  # put the previous set back
                    raise
                if old is not None:
                    shutil.rmtree(old, ignore_errors=True)
        except OSError as exc:
            raise _os_error(exc, target, "write") from None
        self._stage = None

    def _merge(self, stage: Path, target: Path) -> None:
        for root, _dirs, files in os.walk(stage):
            rel = Path(root).relative_to(stage)
            (target / rel).mkdir(parents=True, exist_ok=True)
            for f in files:
                os.replace(Path(root) / f, target / rel / f)

    def abort(self) -> None:
        """Remove the temporary folder (the target is left as it was); release the lock."""
        if self.parent_set is not None or self._done:
            return
        with _signals_held():  # a second signal must not leave the folder half-removed
            self._done = True
            if self._stage is not None:
                shutil.rmtree(self._stage, ignore_errors=True)
                self._stage = None
            self.written.clear()
            self._unlock()
            remove_empty(self._made_dirs)  # parents this set created, innermost first
            self._forget()

    def _forget(self) -> None:
        if self in _ACTIVE:
            _ACTIVE.remove(self)


def take_lock(lock: Path, given: Any, holder: str) -> int:
    """Lock the file ``lock`` (``flock``, created if missing) or refuse at once.

    The lock dies with its process; :func:`release_lock` removes the file, and a
    waiter that locked a file removed meanwhile locks the live one.

    Parameters
    ----------
    lock : Path
        The lock file (its folder exists).
    given : path
        The ``--out`` folder as the user gave it (for the message).
    holder : str
        What holds such a lock (``"fm2uav run"``, ``"fm2uav batch"``), for the message.

    Returns
    -------
    int
        The file descriptor holding the lock.

    Raises
    ------
    InputError
        Another process holds it (naming ``--out`` and the lock file), or the file
        cannot be created.
    """
    import fcntl

    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise _os_error(exc, lock, "create the lock file of") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise InputError(
                f"--out {given} is being written by another {holder} (lock {lock} "
                "is held); wait for it to finish or choose another --out") from None
        try:  # the holder before us may have removed the file: lock the live one
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)


def release_lock(fd: int, lock: Path | None) -> None:
    """Remove the lock file ``lock`` and release the lock held by ``fd`` (:func:`take_lock`)."""
    try:
        if lock is not None:
            lock.unlink(missing_ok=True)
    except OSError:
        pass
    os.close(fd)


@contextmanager
def folder_lock(out: str | os.PathLike[str], kind: str, holder: str) -> Iterator[None]:
    """Hold ``out`` for a run that writes many output sets into it (``fm2uav batch``).

    The lock file ``.<out name>.<kind>.lock`` sits beside ``out`` (as each output
    set's own lock does), so ``out`` is not created by taking it; folders made for it
    are removed again when it is released, if empty.

    Raises
    ------
    InputError
        Another process holds it (see :func:`take_lock`).
    """
    path = Path(out)
    parent, missing = make_parent(path)
    lock = parent / f".{path.name}.{kind}.lock"
    try:
        fd = take_lock(lock, out, holder)
    except BaseException:
        remove_empty(missing)
        raise
    try:
        yield
    finally:
        release_lock(fd, lock)
        remove_empty(missing)


def make_parent(path: Path) -> tuple[Path, list[Path]]:
    """Create the folder that holds ``path``; returns it and the folders made for it
    (innermost first, for :func:`remove_empty`). An OSError is an InputError naming it."""
    parent = path.parent if str(path.parent) else Path(".")
    missing = []
    q = parent
    while not q.exists():
        missing.append(q)
        if q.parent == q:
            break
        q = q.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _os_error(exc, parent, "create") from None
    return parent, missing


def remove_empty(dirs: list[Path]) -> None:
    """Remove the folders ``dirs`` (innermost first) while they are empty."""
    for d in dirs:
        try:
            d.rmdir()
        except OSError:
            break


_WRITE_ERRNOS = (errno.ENOSPC, errno.EROFS, errno.EDQUOT, errno.EFBIG)


def _os_error(exc: OSError, path: Path, verb: str) -> InputError:
    """An OSError while writing the set as a one-line InputError naming --out."""
    code = exc.errno
    if code == errno.ENOSPC:
        why = "the disk is full"
    elif code == errno.EROFS:
        why = "the file system is read-only"
    elif code in (errno.EACCES, errno.EPERM):
        why = "permission denied"
    elif code == errno.EDQUOT:
        why = "the disk quota is exceeded"
    else:
        why = exc.strerror or str(exc)
    return InputError(f"cannot {verb} {path}: {why}; nothing was written (an earlier output set "
                      "is left as it was); free space, fix the permissions or choose another "
                      "--out")
