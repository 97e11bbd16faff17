"""``fm2uav batch``: many mission files, a table and batch.json, exit 3 when one failed
(issue 27, deliverable 5). The executors and the killed workers: tests/pipeline/test_batch.py."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app
from tests.pipeline.batch_missions import same_as_single_run, write_missions

runner = CliRunner()


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    root = tmp_path_factory.mktemp("cli_batch")
    files = write_missions(root / "m", names=("east", "outside"))
    single = root / "single"
    res = runner.invoke(app, ["run", str(files["east"]), "--out", str(single), "--quiet"])
    assert res.exit_code == 0, res.output
    return root / "m", files, single


def test_batch_of_a_folder_writes_the_good_mission_and_exits_3_for_the_bad_one(folder,
                                                                             tmp_path):
    m, files, single = folder
    out = tmp_path / "out"
    args = ["batch", str(m), "--out", str(out), "--workers", "1"]
    res = runner.invoke(app, args)
    assert res.exit_code == 3, res.output
    text = " ".join(res.output.split())
    assert "fm2uav batch: 1 of 2 missions ok, 1 failed" in text
    assert "1 of 2 missions failed (first: " in text and "outside the map" in text
    same_as_single_run(out / "east", single)
    assert sorted(p.name for p in out.iterdir()) == ["batch.json", "east"]
    summary = json.loads((out / "batch.json").read_text())
    assert (summary["missions"], summary["ok"], summary["failed"], summary["not run"]) == \
        (2, 1, 1, 0)
    rows = {r["file"]: r for r in summary["results"]}
    ok, bad = rows[str(files["east"])], rows[str(files["outside"])]
    assert ok["status"] == "ok" and ok["out"] == str(out / "east") and ok["exit_code"] == 0
    assert ok["files"] == [str(out / "east" / p) for p in sorted(
        q.name for q in (out / "east").iterdir())]
    assert bad["status"] == "failed" and bad["exit_code"] == 2 and bad["files"] == []
    assert "goal" in bad["error"] and bad["time_s"] > 0

    # the same command again: refused before any work, nothing changed
    before = (out / "batch.json").read_bytes()
    res = runner.invoke(app, args)
    assert res.exit_code == 2 and "batch.json already exists" in res.output
    assert (out / "batch.json").read_bytes() == before
    # --force: the mission folders and batch.json replaced, --json prints batch.json
    res = runner.invoke(app, [*args, "--force", "--json"])
    assert res.exit_code == 3
    printed = json.loads(res.stdout)
    assert printed["file"] == str(out / "batch.json") and printed["ok"] == 1
    assert json.loads((out / "batch.json").read_text())["results"][0]["status"] == "ok"
    same_as_single_run(out / "east", single)


def test_a_batch_of_good_missions_exits_0_quietly(folder, tmp_path):
    m, files, single = folder
    out = tmp_path / "out"
    res = runner.invoke(app, ["batch", str(files["east"]), "--out", str(out), "--workers", "1",
                              "--quiet"])
    assert res.exit_code == 0, res.output
    assert res.output == ""
    same_as_single_run(out / "east", single)
    assert json.loads((out / "batch.json").read_text())["ok"] == 1


@pytest.mark.parametrize("args, fragment", [
    (["{m}/none.yaml"], "mission file {m}/none.yaml does not exist"),
    (["{m}", "--workers", "0"], "--workers"),
    (["{m}/east.yaml", "{m2}/east.yaml"], "would both write"),
])
def test_bad_batch_input_is_one_line_exit_2_and_runs_nothing(folder, tmp_path, args,
                                                              fragment):
    m, files, _ = folder
    m2 = tmp_path / "m2"
    write_missions(m2, names=("east",))
    out = tmp_path / "out"
    fill = {"m": m, "m2": m2}
    res = runner.invoke(app, ["batch", *[a.format(**fill) for a in args], "--out", str(out)])
    assert res.exit_code == 2, res.output
    assert fragment.format(**fill) in " ".join(res.output.split())
    assert "Traceback" not in res.output and not out.exists()


def test_help_names_the_exit_codes_and_the_command_is_listed():
    text = " ".join(runner.invoke(app, ["batch", "--help"]).output.split())
    assert "3 the batch ran to the end but some missions failed" in text
    assert "--scheduler" in text and "--workers" in text
    assert "batch" in runner.invoke(app, ["--help"]).output


def test_an_interrupted_batch_keeps_what_finished_and_exits_130(folder, tmp_path, monkeypatch):
    import fm2uav.pipeline.batch as batch

    m, files, single = folder
    real = batch.run_batch

    def stopped_after_the_first(todo, results, pool, *, force=False, on_result=None):
        def hook(res):
            on_result(res)
            raise KeyboardInterrupt  # Ctrl-C once the first mission is written

        return real(todo, results, pool, force=force, on_result=hook)

    monkeypatch.setattr(batch, "run_batch", stopped_after_the_first)
    out = tmp_path / "out"
    res = runner.invoke(app, ["batch", str(files["east"]), str(files["outside"]), "--out",
                              str(out), "--workers", "1"])
    assert res.exit_code == 130, res.output
    assert "interrupted: by SIGINT (Ctrl-C); 1 of 2 missions were written, 1 not run" in \
        " ".join(res.output.split())
    summary = json.loads((out / "batch.json").read_text())
    assert summary["interrupted"] == "interrupted by SIGINT (Ctrl-C)"
    assert [r["status"] for r in summary["results"]] == ["ok", "not run"]
    same_as_single_run(out / "east", single)
    assert sorted(p.name for p in out.iterdir()) == ["batch.json", "east"]


def test_resume_keeps_the_missions_written_and_plans_the_rest(tmp_path):
    import yaml

    files = write_missions(tmp_path / "m", names=("east", "outside"))
    out = tmp_path / "out"
    args = ["batch", str(tmp_path / "m"), "--out", str(out), "--workers", "1", "--json"]
    res = runner.invoke(app, ["batch", str(files["east"]), "--out", str(out), "--resume"])
    assert res.exit_code == 2 and "--resume: " in res.output and "does not exist" in res.output
    assert runner.invoke(app, args).exit_code == 3
    east_files = {p.name: p.stat().st_mtime_ns for p in (out / "east").iterdir()}

    # fix the failed mission: --resume plans it alone, the written one is kept as it was
    fixed = yaml.safe_load(files["outside"].read_text())
    fixed["goal"] = {"x": 440070.0, "y": 4470330.0, "agl": 20}
    files["outside"].write_text(yaml.safe_dump(fixed))
    res = runner.invoke(app, [*args, "--resume"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    assert (summary["ok"], summary["failed"], summary["resumed"]) == (2, 0, 1)
    rows = {r["file"]: r for r in summary["results"]}
    assert rows[str(files["east"])]["resumed"] and not rows[str(files["outside"])]["resumed"]
    assert {p.name: p.stat().st_mtime_ns for p in (out / "east").iterdir()} == east_files
    assert (out / "outside" / "mission.plan").is_file()

    # a mission file changed since: planned again, over its folder only with --force
    changed = yaml.safe_load(files["east"].read_text())
    changed["name"] = "town east, renamed"
    files["east"].write_text(yaml.safe_dump(changed))
    res = runner.invoke(app, [*args, "--resume"])
    assert res.exit_code == 2 and "already exists" in res.output and "--force" in res.output
    res = runner.invoke(app, [*args, "--resume", "--force"])
    assert res.exit_code == 0, res.output
    rows = {r["file"]: r for r in json.loads(res.stdout)["results"]}
    assert not rows[str(files["east"])]["resumed"] and rows[str(files["outside"])]["resumed"]
    assert json.loads((out / "east" / "summary.json").read_text())["mission"] == \
        "town east, renamed"
    # a damaged batch.json is one line naming --resume
    (out / "batch.json").write_text("{not json")
    res = runner.invoke(app, [*args, "--resume"])
    assert res.exit_code == 2 and "is not a batch summary of fm2uav batch" in res.output


def test_a_second_batch_into_the_same_out_is_refused_while_the_first_runs(folder, tmp_path):
    """Two batches into one --out would both write batch.json (each mission folder is
    locked on its own): the batch holds its folder from the first check to batch.json."""
    from fm2uav.pipeline.batch import batch_lock

    m, files, single = folder
    out = tmp_path / "runs" / "out"
    args = ["batch", str(files["east"]), "--out", str(out), "--workers", "1"]
    with batch_lock(out):  # another batch is running (its lock is beside the folder)
        lock = tmp_path / "runs" / ".out.batch.lock"
        assert lock.is_file() and not out.exists()
        res = runner.invoke(app, args)
        text = " ".join(res.output.split())
        assert res.exit_code == 2, res.output
        assert f"--out {out} is being written by another fm2uav batch" in text
        assert "Traceback" not in res.output and not out.exists()
    # released: no lock file left, the folder it made for the lock removed again
    assert not (tmp_path / "runs").exists()
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    same_as_single_run(out / "east", single)
    assert sorted(p.name for p in (tmp_path / "runs").iterdir()) == ["out"]
