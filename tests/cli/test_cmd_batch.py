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
