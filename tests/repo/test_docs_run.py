"""Docs that run: every fenced block of README.md and docs/*.md runs as a reader runs it
(tests/repo/docs_run.py says how each kind of block is run and checked; tests/README.md,
"Docs that run", says how to mark a block).

The documents run once per session (``doc_runs``, tests/repo/conftest.py), in one workspace;
each block is one test case, so a failure names the document and line of the block.
``-k operator.md`` runs README.md and docs/operator.md only.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from .conftest import README, pages_wanted
from .docs_run import (DOCS, LANGS, BlockResult, Result, Workspace, _claims, all_blocks,
                       blocks, check_claim, commands, parse_marker, run_python, runs_by_out,
                       text_lines_found, with_markers)

BLOCKS = all_blocks()


@pytest.mark.slow
@pytest.mark.parametrize("block", BLOCKS, ids=[b.id for b in BLOCKS])
def test_the_block_runs_as_written(block, doc_runs):
    problems = doc_runs[block.id].problems
    assert not problems, f"{block.id} ({block.lang}):\n" + "\n\n".join(problems)


# ------------------------------------------------------------------ static, fast checks
@pytest.mark.parametrize("block", BLOCKS, ids=[b.id for b in BLOCKS])
def test_every_block_has_a_kind_the_engine_runs(block):
    """A block in an unknown language would silently not run: give it a language or a
    visible skip marker with its reason."""
    assert block.kind is not None or any(not m.text for m in block.marked("skip")), (
        f"{block.id}: the fence says {block.lang!r}; write one of {', '.join(sorted(LANGS))}")


def test_the_docs_hold_blocks_of_every_kind():
    kinds = {b.kind for b in BLOCKS}
    assert {"bash", "python", "text", "yaml"} <= kinds
    assert len(BLOCKS) >= 30


def test_skips_are_rare_and_give_their_reason():
    skips = [(b.id, m) for b in BLOCKS for m in b.marked("skip")]
    assert len(skips) <= 5, skips
    assert all(m.reason for _, m in skips)


# ------------------------------------------------------------------ the engine itself
def test_commands_join_continuations_and_drop_comments():
    body = "# a comment\nfm2uav plan \\\n  --scenario x   # why\n\nmake run\n"
    assert [c.split() for c in commands(body)] == [
        ["fm2uav", "plan", "--scenario", "x", "#", "why"], ["make", "run"]]


@pytest.mark.parametrize("claim, values", [
    ("0.7061 (exact: 0.7071)", [0.7061]),
    ("True", [True]),
    ("'disco', 12 m", ["disco", 12]),
    ("[1.5, 2.0] m/s", [1.5, 2.0]),
    ("≈ 3e-3", [3e-3]),
])
def test_arrow_claims_are_read(claim, values):
    assert _claims(claim) == values


def test_a_claim_is_checked_to_the_digits_written():
    check_claim(0.70612, "0.7061", "x")
    check_claim((3, 4.25), "3, 4.25", "x")
    with pytest.raises(AssertionError, match="the doc says 0.7071"):
        check_claim(0.70612, "0.7071", "x")
    with pytest.raises(AssertionError, match="states no value"):
        check_claim(1.0, "roughly one", "x")
    with pytest.raises(AssertionError):
        check_claim(True, "False", "x")


def test_a_python_block_fails_on_a_wrong_or_unchecked_number():
    ns: dict = {}
    assert run_python("x = 2\nprint(x * 3)\nx / 4  # → 0.5\n", ns, "b") == "6\n"
    with pytest.raises(AssertionError, match="the doc says 0.6"):
        run_python("x / 4  # → 0.6\n", ns, "b")
    with pytest.raises(AssertionError, match="a number no one checks"):
        run_python("x / 4  # 0.5 m\n", ns, "b")
    run_python("print([x / 4, -x])  # → [0.5, -2]: printed\n", ns, "b")
    with pytest.raises(AssertionError, match="the doc says -3"):
        run_python("print([x / 4, -x])  # → [0.5, -3]\n", ns, "b")


def test_quoted_output_lines_must_be_printed():
    out = "error: the DEM has nodata under 585 of 42262 nodes\nok\n"
    assert text_lines_found("error: the DEM has nodata under ... nodes\nok", out) == []
    assert text_lines_found("error: the DEM has nodata under 586 of 42262 nodes", out) == [
        "error: the DEM has nodata under 586 of 42262 nodes"]


def test_a_measured_table_under_an_output_marker_is_a_block(tmp_path):
    doc = tmp_path / "d.md"
    doc.write_text("| a | b |\n|---|---|\n| 1 | 2 |\n\ntext\n"
                   '<!-- docs-run: output "cat t.md" -->\n| x | y |\n|:--|--:|\n| 3 | 4.5 |\n')
    (b,) = blocks(doc)  # the unmarked table is prose
    assert (b.kind, b.line, b.body) == ("text", 7, "| x | y |\n| 3 | 4.5 |\n")
    assert text_lines_found(b.body, "| x | y |\n|---|---|\n| 3 | 4.50 |") == ["| 3 | 4.5 |"]


def test_markers_are_read_and_need_reasons(tmp_path):
    doc = tmp_path / "d.md"
    doc.write_text('text\n<!-- docs-run: with "reproduce" --cell 0.1: lighter run -->\n'
                   '<!-- docs-run: skip "dask-scheduler": needs a cluster -->\n'
                   "```bash\nfm2uav reproduce x --out o\ndask-scheduler\n```\n")
    (b,) = blocks(doc)
    assert [m.verb for m in b.markers] == ["with", "skip"]
    assert with_markers("fm2uav reproduce x --out o", b) == "fm2uav reproduce x --out o --cell 0.1"
    assert with_markers("dask-scheduler", b) is None
    # an option given again replaces the written one (equal runs share one session run)
    assert with_markers("fm2uav reproduce x --cell 0.5 --out o  # why", b) == \
        "fm2uav reproduce x --out o --cell 0.1 # why"
    with pytest.raises(ValueError, match="needs a reason"):
        parse_marker('skip "x"', "d.md:1")
    with pytest.raises(ValueError, match="unknown docs-run marker"):
        parse_marker("run it", "d.md:1")


def test_a_sweep_into_another_sweeps_folder_resumes_a_copy_of_it(tmp_path):
    """The docs' runs share one run per argument list (cli_once); a sweep into the folder of
    a different sweep is the reader's resume: it runs in a copy, the shared folder untouched."""
    made, runs = [], {}

    def cli_once(args):  # as tests/conftest.py's: one run per argument list
        if tuple(args) not in runs:
            out = tmp_path / "shared" / str(len(made))
            out.mkdir(parents=True)
            (out / "cases.jsonl").write_text("kept\n")
            made.append(tuple(args))
            runs[tuple(args)] = SimpleNamespace(
                result=SimpleNamespace(exit_code=0, output="ran"), out=out)
        return runs[tuple(args)]

    ws = Workspace(tmp_path / "ws", cli_once, {}, {})
    (ws.path / "bad.yaml").write_text("xi: -1\n")
    first = ws.run("fm2uav sweep examples/sweeps/city2d_small.yaml --out out/sweep")
    again = ws.run("fm2uav sweep examples/sweeps/city2d_small.yaml --out out/sweep  # resumes")
    assert (first.code, again.code) == (0, 0) and (ws.path / "out/sweep").is_symlink()
    assert made == [("sweep", "examples/sweeps/city2d_small.yaml")]
    resumed = ws.run("fm2uav sweep bad.yaml --out out/sweep --keep-failed")
    assert resumed.code == 2 and "xi" in resumed.output  # the CLI's own answer, not a shared run
    assert len(made) == 1 and not (ws.path / "out/sweep").is_symlink()
    assert (ws.path / "out/sweep/cases.jsonl").read_text() == "kept\n"
    assert sorted(p.name for p in (tmp_path / "shared" / "0").iterdir()) == ["cases.jsonl"]
    # any other command into a folder already made shares its own run, as before
    ws.run("fm2uav plan --scenario open-field --out out/sweep")
    assert made[-1] == ("plan", "--scenario", "open-field")


# ------------------------------------------------------------------ what the session runs
def _item(name, *, block=None, fixtures=(), doc=None):
    return SimpleNamespace(originalname=name, fixturenames=fixtures,
                           callspec=SimpleNamespace(params={"block": block}) if block else None,
                           module=SimpleNamespace(DOC=doc) if doc is not None else None)


def test_the_session_runs_readme_the_selected_blocks_pages_and_the_pages_read():
    op = next(b for b in BLOCKS if b.doc.name == "operator.md")
    energy = next(d for d in DOCS if d.name == "energy.md")
    wind = next(d for d in DOCS if d.name == "wind.md")
    assert pages_wanted([]) == {README}
    assert pages_wanted([_item("test_the_block_runs_as_written", block=op)]) == {README, op.doc}
    # a module reading doc_runs brings its DOC; one not taking doc_runs, or whose DOC is text, not
    assert pages_wanted([_item("test_x", fixtures=("doc_runs",), doc=energy),
                         _item("test_y", fixtures=("tmp_path",), doc=wind),
                         _item("test_z", fixtures=("doc_runs",), doc="docs/wind.md")]) == {
        README, energy}


def test_a_pages_runs_by_the_output_folder_they_name():
    energy = next(b for b in BLOCKS if b.doc.name == "energy.md" and b.kind == "bash")
    other = next(b for b in BLOCKS if b.doc.name == "wind.md" and b.kind == "bash")
    res = [Result(".venv/bin/fm2uav cover --area S1 --out out/sorties  # why", 0, "", Path("a")),
           Result(".venv/bin/python examples/make_flight_log.py", 0, ""),
           Result("fm2uav plan --out=out/energy", 1, "", Path("b"))]
    runs = {energy.id: BlockResult(energy, results=res),
            other.id: BlockResult(other, results=[Result("fm2uav plan --out out/wind", 0, "")])}
    found = runs_by_out(runs, energy.doc)
    assert set(found) == {"out/sorties", "out/energy"}
    assert found["out/sorties"].out == Path("a") and found["out/energy"].code == 1
