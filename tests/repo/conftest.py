"""The docs' run (``doc_runs``), shared by the tests of tests/repo that read it."""

from __future__ import annotations

from pathlib import Path

import pytest

from . import docs_data
from .docs_run import DOCS, Workspace, run_docs

#: README.md: always run (the later pages use its outputs)
README = DOCS[0]


def pages_wanted(items) -> set[Path]:
    """The pages the session's ``doc_runs`` must run: README.md, the page of every selected
    ``test_the_block_runs_as_written`` case and the page (``DOC``, a path) of every selected
    test module that reads ``doc_runs``."""
    wanted = {README}
    for item in items:
        callspec = getattr(item, "callspec", None)
        if getattr(item, "originalname", None) == "test_the_block_runs_as_written" \
                and callspec is not None:
            wanted.add(callspec.params["block"].doc)
        elif "doc_runs" in getattr(item, "fixturenames", ()):
            doc = getattr(getattr(item, "module", None), "DOC", None)
            if isinstance(doc, Path):
                wanted.add(doc)
    return wanted


@pytest.fixture(scope="session")
def doc_runs(request, tmp_path_factory, cli_once):
    """Every block of the pages this session tests (:func:`pages_wanted`), in order, in one
    workspace: ``block id -> BlockResult`` (tests/repo/docs_run.py)."""
    ws = Workspace(tmp_path_factory.mktemp("docs"), cli_once, docs_data.FILES,
                   docs_data.PRODUCERS)
    for name, make in docs_data.OVERRIDES.items():
        make(ws.path / name)
    wanted = pages_wanted(request.session.items)
    return run_docs(ws, [d for d in DOCS if d in wanted])
