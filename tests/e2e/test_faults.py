"""Fault tests of the output sets (issue 17 items 3 and 5): signals, concurrent runs,
read-only and full targets, exceptions, --force. A set is the previous one or the new one,
whole, and no temporary folder or lock file is left beside it."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import textwrap
import time
from contextlib import contextmanager
from pathlib import Path

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.errors import InputError
from fm2uav.io import outdir as od
from fm2uav.io.outdir import OutputDir

runner = CliRunner()

# A command shaped like every fm2uav command (handle_errors + OutputDir), which writes
# n files slowly so a signal or a second run can hit it mid-way.
SLOW = textwrap.dedent("""
    import os, sys, time
    import typer
    from fm2uav.cli._common import OutputDir, handle_errors

    app = typer.Typer()

    @app.command()
    @handle_errors
    def main(out: str = typer.Option(..., "--out"), n: int = 6, pause: float = 0.3,
             force: bool = False, hold: str = "") -> None:
        import os

        od = OutputDir(out, force=force)
        od.check([f"f{i}.txt" for i in range(n)])
        for i in range(n):
            with od.open(f"f{i}.txt") as fh:
                fh.write(f"new {i}\\n")
            print(f"wrote {i}", flush=True)
            while hold and not os.path.exists(hold):  # until the test lets it go on
                time.sleep(0.05)
            time.sleep(pause)

    app()
""")


def _slow(tmp_path: Path) -> Path:
    p = tmp_path / "slow_cmd.py"
    p.write_text(SLOW)
    return p


def _spawn(script: Path, out: Path, *args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, str(script), "--out", str(out), *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _leftovers(parent: Path, name: str) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.startswith(f".{name}."))


def _old_set(out: Path) -> None:
    out.mkdir()
    for i in range(3):
        (out / f"f{i}.txt").write_text(f"old {i}\n")
    (out / "old_only.plan").write_text("old mission")


@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 130), (signal.SIGINT, 130)])
def test_signal_mid_run_leaves_previous_set(tmp_path, sig, code):
    out = tmp_path / "out"
    _old_set(out)
    before = {p.name: p.read_text() for p in out.iterdir()}
    proc = _spawn(_slow(tmp_path), out, "--force")
    line = proc.stdout.readline()  # the first file is written (staged)
    assert line.startswith("wrote 0"), (line, proc.stderr.read())
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == code, err
    assert "interrupted" in err and "Traceback" not in err
    assert {p.name: p.read_text() for p in out.iterdir()} == before
    assert _leftovers(tmp_path, "out") == []


def test_signal_mid_run_without_previous_set_leaves_nothing(tmp_path):
    out = tmp_path / "sub" / "out"
    proc = _spawn(_slow(tmp_path), out)
    assert proc.stdout.readline().startswith("wrote 0")
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=30)
    assert proc.returncode == 130
    assert not out.exists() and not (tmp_path / "sub").exists()


@pytest.mark.slow  # subprocesses of a few seconds each
def test_killed_run_leftovers_are_cleaned_by_the_next_run(tmp_path):
    """SIGKILL cannot be caught: the next run into the folder removes the stale temp set."""
    out = tmp_path / "out"
    proc = _spawn(_slow(tmp_path), out)
    assert proc.stdout.readline().startswith("wrote 0")
    proc.kill()
    proc.communicate(timeout=30)
    assert not out.exists() and _leftovers(tmp_path, "out")  # the stale temp set
    proc = _spawn(_slow(tmp_path), out, "--n", "2", "--pause", "0")
    proc.communicate(timeout=60)
    assert proc.returncode == 0
    assert sorted(p.name for p in out.iterdir()) == ["f0.txt", "f1.txt"]
    assert _leftovers(tmp_path, "out") == []


@pytest.mark.slow  # subprocesses of a few seconds each
def test_two_concurrent_runs_one_is_refused(tmp_path):
    out = tmp_path / "out"
    script = _slow(tmp_path)
    go = tmp_path / "go"
    # the first run holds the folder until the second has tried (however slow its start-up)
    first = _spawn(script, out, "--n", "4", "--pause", "0", "--hold", str(go))
    assert first.stdout.readline().startswith("wrote 0")
    second = _spawn(script, out, "--n", "4", "--force", "--pause", "0")
    _, err2 = second.communicate(timeout=300)
    go.write_text("")
    _, err1 = first.communicate(timeout=300)
    assert first.returncode == 0, err1
    assert second.returncode == 2, err2
    assert "being written by another fm2uav run" in err2 and "--out" in err2
    assert sorted(p.name for p in out.iterdir()) == [f"f{i}.txt" for i in range(4)]
    assert all(p.read_text().startswith("new") for p in out.iterdir())
    assert _leftovers(tmp_path, "out") == []


def test_real_command_refused_while_the_folder_is_locked(tmp_path):
    out = tmp_path / "out"
    holder = OutputDir(out)
    holder.check([])
    try:
        res = runner.invoke(app, ["plan", "--out", str(out), "--quiet"])
    finally:
        holder.abort()
    assert res.exit_code == 2
    assert "being written by another fm2uav run" in res.output
    assert not out.exists() and _leftovers(tmp_path, "out") == []


def test_force_replaces_the_whole_set(tmp_path):
    """--force: an old mission's exports never remain beside the new ones."""
    out = tmp_path / "out"
    res = runner.invoke(app, ["plan", "--export", "all", "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    assert (out / "mission.plan").exists()
    res = runner.invoke(app, ["plan", "--out", str(out), "--quiet", "--force",
                              "--exponent", "2"])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in out.iterdir()) == ["path.csv", "plan.png", "summary.json"]
    assert '"exponent": 2.0' in (out / "summary.json").read_text()
    assert _leftovers(tmp_path, "out") == []


def test_without_force_an_existing_set_is_refused_before_work(tmp_path):
    out = tmp_path / "out"
    _old_set(out)
    res = runner.invoke(app, ["plan", "--out", str(out)])
    assert res.exit_code == 2 and "already exists" in res.output and "--force" in res.output
    assert sorted(p.name for p in out.iterdir()) == ["f0.txt", "f1.txt", "f2.txt",
                                                     "old_only.plan"]


def test_force_refuses_the_current_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "precious.txt").write_text("keep")
    res = runner.invoke(app, ["plan", "--out", ".", "--force", "--quiet"])
    assert res.exit_code == 2 and "current folder" in res.output
    assert (tmp_path / "precious.txt").read_text() == "keep"


@pytest.mark.parametrize("code, words", [(errno.EROFS, "read-only"),
                                         (errno.EACCES, "permission denied")])
def test_read_only_target_clear_error_nothing_written(tmp_path, monkeypatch, code, words):
    out = tmp_path / "out"

    def refuse(*a, **k):
        raise OSError(code, os.strerror(code), str(tmp_path))

    monkeypatch.setattr(od.tempfile, "mkdtemp", refuse)
    res = runner.invoke(app, ["plan", "--out", str(out), "--quiet"])
    assert res.exit_code == 2, res.output
    assert words in res.output and "--out" in res.output and "Traceback" not in res.output
    assert not out.exists() and _leftovers(tmp_path, "out") == []


@contextmanager
def _file_permissions_apply_to_root():
    """Drop CAP_DAC_OVERRIDE and CAP_DAC_READ_SEARCH from this thread's effective capabilities
    for the duration (capabilities(7): root then meets the kernel's permission checks like any
    user), restored after from the permitted set. Nothing to do for other users.

    Why this and not another way to make a folder unwritable for root: a read-only mount or
    ``chattr +i`` need CAP_SYS_ADMIN / CAP_LINUX_IMMUTABLE and a file system that supports
    them, which a CI container may lack; monkeypatching ``tempfile.mkdtemp`` (the test above)
    tests the message, not the code path. Here the real ``mkdtemp``/``mkdir`` of OutputDir gets
    EACCES from the kernel, for root as for a user (dropping a capability from the effective
    set needs no privilege, and a thread may raise it again from its permitted set)."""
    if os.geteuid() != 0:
        yield
        return
    import ctypes

    class Header(ctypes.Structure):
        _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]

    class Data(ctypes.Structure):
        _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32),
                    ("inheritable", ctypes.c_uint32)]

    libc = ctypes.CDLL(None, use_errno=True)
    head, data = Header(0x20080522, 0), (Data * 2)()  # _LINUX_CAPABILITY_VERSION_3, this thread

    def call(fn):
        if fn(ctypes.byref(head), data) != 0:
            err = ctypes.get_errno()
            raise OSError(err, f"{fn.__name__}: {os.strerror(err)}")

    call(libc.capget)
    saved = data[0].effective
    data[0].effective = saved & ~((1 << 1) | (1 << 2))  # CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH
    call(libc.capset)
    try:
        yield
    finally:
        data[0].effective = saved
        call(libc.capset)


def test_read_only_folder_for_real(tmp_path):
    """A folder the user cannot write into (also when the tests run as root, as in CI): the
    kernel refuses OutputDir's own calls; one line, exit 2, nothing left behind."""
    parent = tmp_path / "ro"
    parent.mkdir()
    parent.chmod(0o555)
    try:
        with _file_permissions_apply_to_root():
            with pytest.raises(PermissionError):  # the premise: this process cannot write here
                (parent / "probe").mkdir()
            res = runner.invoke(app, ["plan", "--out", str(parent / "out"), "--quiet"])
    finally:
        parent.chmod(0o755)
    assert res.exit_code == 2, res.output
    assert "permission denied" in res.output and "--out" in res.output
    assert "Traceback" not in res.output and len(res.output.strip().splitlines()) == 1
    assert list(parent.iterdir()) == []
    (parent / "probe").mkdir()  # and the capabilities are back


def test_full_disk_mid_run_keeps_previous_set(tmp_path, monkeypatch):
    out = tmp_path / "out"
    _old_set(out)
    before = {p.name: p.read_text() for p in out.iterdir()}
    real = OutputDir.commit
    calls = {"n": 0}

    def commit(self, tmp, name):
        calls["n"] += 1
        if calls["n"] == 2:
            raise OSError(errno.ENOSPC, "No space left on device", str(tmp))
        return real(self, tmp, name)

    monkeypatch.setattr(OutputDir, "commit", commit)
    res = runner.invoke(app, ["plan", "--out", str(out), "--force", "--quiet"])
    assert res.exit_code == 2, res.output
    assert "disk is full" in res.output
    assert {p.name: p.read_text() for p in out.iterdir()} == before
    assert _leftovers(tmp_path, "out") == []


def test_internal_error_mid_run_traceback_exit_70_and_previous_set(tmp_path, monkeypatch):
    """A genuine bug: a traceback, a line asking to report it, exit 70 — and no mix."""
    import fm2uav.viz as viz

    out = tmp_path / "out"
    _old_set(out)
    before = {p.name: p.read_text() for p in out.iterdir()}

    def broken(*a, **k):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(viz, "plan_figure", broken)
    res = runner.invoke(app, ["plan", "--out", str(out), "--force", "--quiet"])
    assert res.exit_code == 70
    assert "internal error" in res.output and "please report it" in res.output
    assert {p.name: p.read_text() for p in out.iterdir()} == before
    assert _leftovers(tmp_path, "out") == []


def test_library_use_as_context_manager(tmp_path):
    out = tmp_path / "set"
    with pytest.raises(RuntimeError):
        with OutputDir(out) as s:
            with s.open("a.txt") as fh:
                fh.write("x")
            raise RuntimeError("boom")
    assert not out.exists() and _leftovers(tmp_path, "set") == []
    with OutputDir(out) as s:
        with s.open("a.txt") as fh:
            fh.write("x")
        with s.open("sub/b.txt") as fh:
            fh.write("y")
        assert s.staged("a.txt").read_text() == "x"
    assert sorted(str(p.relative_to(out)) for p in out.rglob("*.txt")) == ["a.txt", "sub/b.txt"]
    with pytest.raises(InputError, match="already exists"):
        OutputDir(out).check(["a.txt"])
    assert od.active_sets() == []


def test_nested_set_writes_into_the_parent(tmp_path):
    out = tmp_path / "root"
    with OutputDir(out) as parent:
        with parent.open("table.md") as fh:
            fh.write("t")
        child = OutputDir(out / "case1")
        with child.open("x.csv") as fh:
            fh.write("1")
        assert not out.exists()
    assert (out / "case1" / "x.csv").read_text() == "1" and (out / "table.md").exists()


def test_files_written_meanwhile_by_a_library_are_kept(tmp_path):
    """A library writing into --out directly (a resumable sweep log) loses nothing."""
    out = tmp_path / "sweep"
    out.mkdir()
    (out / "cases.jsonl").write_text("1\n")
    with OutputDir(out, force=True) as s:
        s.check(["tables.md"])  # before the work, as cmd_sweep does
        (out / "cases.jsonl").write_text("1\n2\n")  # appended by the library meanwhile
        with s.open("tables.md") as fh:
            fh.write("t")
    assert (out / "cases.jsonl").read_text() == "1\n2\n" and (out / "tables.md").exists()


@pytest.mark.slow  # subprocesses of a few seconds each
def test_real_plan_sigterm_never_leaves_a_mix(tmp_path):
    """The real command, SIGTERM as soon as its set is being written: the old set or the
    complete new one, never a mix, and no temporary folder."""
    out = tmp_path / "out"
    _old_set(out)
    before = {p.name for p in out.iterdir()}
    exe = Path(sys.executable).with_name("fm2uav")
    if not exe.exists():
        pytest.skip("the fm2uav console script is not installed beside python")
    proc = subprocess.Popen([str(exe), "plan", "--out", str(out),
                             "--force", "--quiet", "--export", "all"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.time()
    while proc.poll() is None and time.time() - t0 < 120:
        if _leftovers(tmp_path, "out") and any(".tmp-" in n for n in _leftovers(tmp_path, "out")):
            proc.send_signal(signal.SIGTERM)
            break
        time.sleep(0.005)
    proc.communicate(timeout=120)
    names = {p.name for p in out.iterdir()}
    if proc.returncode == 0:
        assert names == {"path.csv", "plan.png", "summary.json", "path.geojson", "path.kml",
                         "mission.plan", "mission.waypoints"}
    else:
        assert proc.returncode == 130
        assert names == before
    assert _leftovers(tmp_path, "out") == []


def test_merge_mode_never_swaps(tmp_path):
    out = tmp_path / "sweep"
    out.mkdir()
    (out / "cases.jsonl").write_text("1\n")
    with OutputDir(out, force=True, merge=True) as s:
        with s.open("tables.md") as fh:
            fh.write("t")
        assert not (out / "tables.md").exists()  # staged until the end
    assert sorted(p.name for p in out.iterdir()) == ["cases.jsonl", "tables.md"]
    assert _leftovers(tmp_path, "sweep") == []


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
@pytest.mark.parametrize("moment", ["after_new_in_place", "after_old_aside"])
def test_stop_signal_during_the_swap_is_held(tmp_path, monkeypatch, sig, moment):
    """A stop signal that arrives while the set is being renamed into place waits until
    the renames are done: the complete new set, no .tmp-/.old- folder, no exception
    (the command is ending: a signal after the commit is ignored)."""
    out = tmp_path / "out"
    _old_set(out)
    real_rename = od.os.rename
    fired = []

    def rename(src, dst):
        real_rename(src, dst)
        hit = Path(dst) == out if moment == "after_new_in_place" else Path(src) == out
        if hit and not fired:
            fired.append(True)
            os.kill(os.getpid(), sig)  # delivered at once unless held

    monkeypatch.setattr(od.os, "rename", rename)
    with od.interrupt_signals():
        s = OutputDir(out, force=True)
        with s.open("a.txt") as fh:
            fh.write("new")
        od.finish_all()
    assert fired
    assert sorted(p.name for p in out.iterdir()) == ["a.txt"]
    assert _leftovers(tmp_path, "out") == []


def test_stop_signal_before_the_commit_still_stops(tmp_path):
    """Holding signals during the swap does not swallow one sent while the set is written."""
    out = tmp_path / "out"
    _old_set(out)
    before = sorted(p.name for p in out.iterdir())
    with pytest.raises(od.Interrupted):
        with od.interrupt_signals():
            s = OutputDir(out, force=True)
            try:
                with s.open("a.txt") as fh:
                    fh.write("new")
                    os.kill(os.getpid(), signal.SIGTERM)
                    time.sleep(0.5)  # the handler raises here
                od.finish_all()
            except BaseException:
                od.abort_all()
                raise
    assert sorted(p.name for p in out.iterdir()) == before
    assert _leftovers(tmp_path, "out") == []


# ------------------------------------------------- --force never deletes an input (issue 25)
def _mission(folder: Path, extra: str = "") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    m = folder / "m.yaml"
    m.write_text("world: {scenario: open-field}\nstart: {cell: [20, 20, 20]}\n"
                 "goal: {cell: [100, 80, 30]}\n" + extra)
    return m


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}


def _dem(path: Path) -> Path:
    from .conftest import relief, write_dem

    path.parent.mkdir(parents=True, exist_ok=True)
    return write_dem(path, relief(30))


def _zone(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text('{"type": "FeatureCollection", "features": [{"type": "Feature", '
                    '"properties": {}, "geometry": {"type": "Polygon", "coordinates": '
                    '[[[600, 600], [700, 600], [700, 700], [600, 600]]]}}]}')
    return path


def _path_csv(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("x_m,y_m,z_m\n300,300,540\n600,300,540\n900,600,540\n")
    return path


# (name, make(tmp) -> (args, the input in --out), the fragment naming the input)
INPUT_CASES = {
    "mission file": lambda t: (["run", str(_mission(t / "proj"))], t / "proj", "m.yaml"),
    "mission file, ancestor": lambda t: (["run", str(_mission(t / "proj" / "a" / "b"))],
                                         t / "proj", "m.yaml"),
    "mission file, outputs.dir '.'": lambda t: (
        ["run", str(_mission(t / "proj", "outputs: {dir: .}\n"))], None, "m.yaml"),
    "zone file of the mission": lambda t: (
        ["run", str(_mission(t / "proj2", f"no_fly_zones: [{_zone(t / 'proj' / 'z.geojson')}]"
                             "\n"))], t / "proj", "z.geojson"),
    "--dem": lambda t: (["plan", "--dem", str(_dem(t / "proj" / "dem.tif")), "--start",
                         "500100,4499500,150", "--goal", "500700,4499200,150"],
                        t / "proj", "dem.tif"),
    "--no-fly": lambda t: (["plan", "--no-fly", str(_zone(t / "proj" / "z.geojson"))],
                           t / "proj", "z.geojson"),
    "check PATH": lambda t: (["check", str(_path_csv(t / "proj" / "p.csv"))], t / "proj",
                             "p.csv"),
    "export PATH": lambda t: (["export", str(_path_csv(t / "proj" / "p.csv")), "--scenario",
                               "open-field"], t / "proj", "p.csv"),
    "export --mission": lambda t: (["export", str(_path_csv(t / "csv" / "p.csv")), "--mission",
                                    str(_mission(t / "proj"))], t / "proj", "m.yaml"),
}


@pytest.mark.parametrize("force", [True, False], ids=["force", "no-force"])
@pytest.mark.parametrize("name", list(INPUT_CASES))
def test_an_out_holding_an_input_is_refused_naming_it(tmp_path, name, force):
    """--out = the folder of an input (or an ancestor): exit 2 before any work, the input
    and --out named, every file as it was, no temporary folder left."""
    args, out, fragment = INPUT_CASES[name](tmp_path)
    (tmp_path / "proj" / "old_output.txt").write_text("an earlier run's file")
    before = _tree(tmp_path)
    argv = args + (["--out", str(out)] if out is not None else []) + (
        ["--force"] if force else [])
    res = runner.invoke(app, argv)
    assert res.exit_code == 2, res.output
    assert "holds an input of this command" in res.output and fragment in res.output
    assert "--out" in res.output and "Traceback" not in res.output
    assert _tree(tmp_path) == before
    assert not [p for p in tmp_path.rglob(".*") if ".tmp-" in p.name or ".old-" in p.name]


def test_an_out_holding_several_inputs_names_every_one(tmp_path):
    """The user learns in one go every file to move out, not one per attempt."""
    zone = _zone(tmp_path / "proj" / "zones" / "z.geojson")
    mission = _mission(tmp_path / "proj", f"no_fly_zones: [{zone}]\n")
    before = _tree(tmp_path)
    res = runner.invoke(app, ["run", str(mission), "--out", str(tmp_path / "proj"), "--force"])
    assert res.exit_code == 2, res.output
    msg = " ".join(res.output.split())
    assert "holds 2 inputs of this command:" in msg and "which would delete them" in msg
    assert "m.yaml (MISSION_FILE)" in msg and "z.geojson (" in msg and "move the inputs out" in msg
    assert _tree(tmp_path) == before


def test_an_input_read_after_the_check_is_caught_before_the_swap(tmp_path):
    """A reader that notes its file only after the early check (a new command forgetting
    to declare it): the old set is not moved aside; exit 2 naming the file."""
    from fm2uav import _validate

    out = tmp_path / "out"
    _old_set(out)
    (out / "late.tif").write_text("an input read late")
    before = _tree(out)
    with _validate.input_log():
        s = OutputDir(out, force=True)
        s.check(["f0.txt"])
        with s.open("f0.txt") as fh:
            fh.write("new")
        _validate.input_file(out / "late.tif", "the DEM")  # read while the set is staged
        with pytest.raises(InputError, match=r"holds an input of this command: .*late.tif "
                           r"\(the DEM\)"):
            s.finish()
    assert _tree(out) == before and _leftovers(tmp_path, "out") == []


def test_declared_inputs_and_merge_mode(tmp_path):
    out = tmp_path / "out"
    _old_set(out)
    with pytest.raises(InputError, match="f1.txt .the sweep configuration."):
        OutputDir(out, force=True, inputs=[(out / "f1.txt", "the sweep configuration")]).check()
    # merge mode replaces only the files it writes: another input may stay in the folder
    keep = OutputDir(out, force=True, merge=True, inputs=[(out / "f1.txt", "config")])
    keep.check(["report.md"])
    keep.abort()
    clash = OutputDir(out, force=True, merge=True, owned=["f2.txt"],
                      inputs=[(out / "f2.txt", "config")])
    with pytest.raises(InputError, match="f2.txt"):
        clash.check(["report.md"])
    assert (out / "f1.txt").read_text() == "old 1\n" and _leftovers(tmp_path, "out") == []


def test_a_link_to_an_input_inside_out_is_refused_too(tmp_path):
    """The input given through a symbolic link that lives in --out: deleting --out would
    break the path the user gave."""
    data = tmp_path / "data"
    m = _mission(data)
    out = tmp_path / "out"
    out.mkdir()
    (out / "m.yaml").symlink_to(m)
    res = runner.invoke(app, ["run", str(out / "m.yaml"), "--out", str(out), "--force"])
    assert res.exit_code == 2 and "holds an input" in res.output, res.output
    assert (out / "m.yaml").is_symlink() and m.exists()


# ---------------------------------------------------------- a symbolic link as --out
def test_force_through_a_symlinked_out_replaces_the_folder_it_points_to(tmp_path):
    real = tmp_path / "real"
    _old_set(real)
    link = tmp_path / "link"
    link.symlink_to(real, target_is_directory=True)
    res = runner.invoke(app, ["plan", "--out", str(link), "--force", "--quiet"])
    assert res.exit_code == 0, res.output
    assert link.is_symlink() and link.resolve() == real.resolve()
    assert sorted(p.name for p in real.iterdir()) == ["path.csv", "plan.png", "summary.json"]
    # no stray link, no old set, no temporary folder beside either
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_a_symlinked_out_without_force_is_refused_and_left_alone(tmp_path):
    real = tmp_path / "real"
    _old_set(real)
    link = tmp_path / "link"
    link.symlink_to(real, target_is_directory=True)
    res = runner.invoke(app, ["plan", "--out", str(link), "--quiet"])
    assert res.exit_code == 2 and "already exists" in res.output
    assert link.is_symlink() and sorted(p.name for p in real.iterdir()) == [
        "f0.txt", "f1.txt", "f2.txt", "old_only.plan"]


def test_a_dangling_symlink_out_is_created_where_it_points(tmp_path):
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "made", target_is_directory=True)
    res = runner.invoke(app, ["plan", "--out", str(link), "--quiet"])
    assert res.exit_code == 0, res.output
    assert link.is_symlink() and (tmp_path / "made" / "path.csv").exists()


# ------------------------------------------------------------ a deleted current folder
def test_a_deleted_current_folder_says_so(tmp_path):
    """The shell sits in a folder another program removed: relative paths cannot work,
    and the message says why (not "file not found"); absolute paths still do."""
    gone = tmp_path / "gone"
    gone.mkdir()
    code = textwrap.dedent("""
        import os, sys
        os.chdir(sys.argv[1]); os.rmdir(sys.argv[1])
        from fm2uav.cli import app
        for args in (["run", "m.yaml"], ["plan", "--out", "o", "--quiet"]):
            try:
                app(args)
            except SystemExit as exc:
                print(exc.code, file=sys.stderr)
    """)
    r = subprocess.run([sys.executable, "-c", code, str(gone)], capture_output=True, text=True,
                       timeout=300)
    lines = r.stderr.splitlines()
    assert len(lines) == 4 and lines[1] == lines[3] == "2", r.stderr
    for line in (lines[0], lines[2]):
        assert "the current folder no longer exists" in line and "cd " in line, r.stderr
    assert "Traceback" not in r.stderr


def test_a_tilde_out_is_the_home_folder_not_a_folder_named_tilde(tmp_path, monkeypatch):
    """"~/out" given in quotes (or from outputs.dir) means the home folder, as in a shell."""
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, ["plan", "--out", "~/plans/a", "--quiet"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "home" / "plans" / "a" / "path.csv").exists()
    assert not (tmp_path / "~").exists()
