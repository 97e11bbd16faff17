"""Help pages kept between runs (``fm2uav._help_cache``): the kept page is byte for byte the
page typer renders, for the terminal it is asked from; a hit loads neither typer nor rich;
failures and other requests are never kept; the key follows the source, the renderers and
the terminal."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from fm2uav import _help_cache

PAGES = [(), ("plan",), ("reproduce", "curvature")]


def _fm2uav(words, cache, *, extra_env=None, importtime=False):
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "FORCE_COLOR")}
    env.update({"FM2UAV_CACHE_DIR": str(cache), **(extra_env or {})})
    cmd = [sys.executable, *(["-X", "importtime"] if importtime else []), "-m", "fm2uav",
           *words, "--help"]
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("words", PAGES, ids=lambda w: " ".join(w) or "top")
def test_the_kept_page_is_the_rendered_page_and_a_hit_loads_no_typer(tmp_path, words):
    fresh = _fm2uav(words, tmp_path, extra_env={"FM2UAV_HELP_CACHE": "0"})
    assert fresh.returncode == 0 and "Usage: " in fresh.stdout, fresh.stderr
    assert not (tmp_path / "help").exists()  # turned off: nothing kept
    first = _fm2uav(words, tmp_path)  # rendered, then kept
    assert (first.returncode, first.stdout, first.stderr) == (0, fresh.stdout, "")
    assert len(list((tmp_path / "help").glob("*.txt"))) == 1
    hit = _fm2uav(words, tmp_path, importtime=True)
    assert hit.returncode == 0 and hit.stdout == fresh.stdout
    loaded = {line.split("|")[-1].strip() for line in hit.stderr.splitlines()}
    assert not {"typer", "rich", "click", "numpy"} & loaded, sorted(loaded)


def test_each_width_and_colour_has_its_own_page(tmp_path):
    pages = {}
    for env in ({"COLUMNS": "60"}, {"COLUMNS": "120", "FORCE_COLOR": "1"}):
        fresh = _fm2uav(("plan",), tmp_path, extra_env={**env, "FM2UAV_HELP_CACHE": "0"})
        for _ in range(2):  # rendered and kept, then copied
            got = _fm2uav(("plan",), tmp_path, extra_env=env)
            assert got.returncode == 0 and got.stdout == fresh.stdout
        pages[tuple(env.items())] = fresh.stdout
    assert len(set(pages.values())) == 2
    assert "\x1b[" in pages[(("COLUMNS", "120"), ("FORCE_COLOR", "1"))]
    assert max(len(line) for line in pages[(("COLUMNS", "60"),)].splitlines()) <= 60
    assert len(list((tmp_path / "help").glob("*.txt"))) == 2


def test_failures_are_never_kept_and_a_bad_cache_is_ignored(tmp_path):
    bad = _fm2uav(("nosuch",), tmp_path)
    assert bad.returncode == 2 and "nosuch" in bad.stderr
    assert not list((tmp_path / "help").glob("*.txt")) if (tmp_path / "help").exists() else True
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    got = _fm2uav(("plan",), blocked)  # the cache cannot be made: the page all the same
    assert got.returncode == 0 and "fm2uav plan [OPTIONS]" in got.stdout and got.stderr == ""


def test_only_plain_help_requests_are_pages():
    assert _help_cache.help_words(["--help"]) == ()
    assert _help_cache.help_words(["reproduce", "tff", "--help"]) == ("reproduce", "tff")
    for argv in ([], ["plan"], ["plan", "-h"], ["plan", "--out", "x", "--help"],
                 ["plan", "--help", "--out"], ["Plan", "--help"], ["pl/an", "--help"],
                 ["", "--help"], ["--version", "--help"]):
        assert _help_cache.help_words(argv) is None, argv


def test_the_key_follows_words_environment_and_every_source_file(tmp_path, monkeypatch):
    base = _help_cache.page_key(("plan",))
    assert _help_cache.page_key(("plan",)) == base
    assert _help_cache.page_key(("routes",)) != base
    monkeypatch.setattr(sys, "argv", ["/somewhere/else/fm2uav-dev"])  # "Usage: <name> ..."
    assert _help_cache.page_key(("plan",)) != base
    monkeypatch.undo()
    with monkeypatch.context() as m:  # (restores a COLUMNS the environment may have set)
        m.setenv("COLUMNS", "77" if os.environ.get("COLUMNS") != "77" else "78")
        assert _help_cache.page_key(("plan",)) != base
    with monkeypatch.context() as m:
        m.setenv("SOMETHING_ELSE", "1")  # not a rendering variable: same page
        assert _help_cache.page_key(("plan",)) == base
    # a source file's size or time changes the listing the key is made of
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    f = pkg / "sub" / "m.py"
    f.write_text("x = 1\n")
    (pkg / "data.txt").write_text("not source")

    def listing():
        out = []
        _help_cache._tree(str(pkg), out)
        return out

    before = listing()
    assert len(before) == 1 and before[0].startswith(str(f))
    os.utime(f, ns=(1, 1))
    assert listing() != before
    # the package's own files and the renderers' are in the key
    parts = []
    _help_cache._tree(os.path.dirname(_help_cache.__file__), parts)
    assert any(p.startswith(os.path.join(os.path.dirname(_help_cache.__file__), "cli",
                                         "cmd_plan.py ")) for p in parts)
    assert _help_cache._package_dir("typer") is not None
