"""fm2uav._code_cache: the code of generated source kept between runs is exactly what
compiling gives, exec/eval/compile behave as the built-ins for their callers, and the
command line's entry point keeps and reuses the table."""

from __future__ import annotations

import builtins
import json
import marshal
import os
import re
import subprocess
import sys
import textwrap

import pytest

from fm2uav import _code_cache

SOURCES = [
    ("exec", "def __create_fn__(a, b):\n def __init__(self, x: a = b):\n  self.x = x\n"
             " return __init__"),
    ("eval", "lambda _cls, a, b: _tuple_new(_cls, (a, b))"),
    ("eval", "list[int] | None"),
]


@pytest.fixture
def table(monkeypatch):
    """An empty table of this process (no stand-ins installed)."""
    monkeypatch.setattr(_code_cache._State, "table", {})
    monkeypatch.setattr(_code_cache._State, "used", {})
    monkeypatch.setattr(_code_cache._State, "new", 0)
    monkeypatch.setattr(_code_cache._State, "hits", 0)
    monkeypatch.setattr(_code_cache._State, "mask", _code_cache._future_mask())
    return _code_cache._State


@pytest.mark.parametrize(("mode", "source"), SOURCES)
def test_a_kept_entry_is_exactly_the_compiled_code(table, mode, source):
    flags = _code_cache._future_mask() & 0x1000000  # annotations, as a __future__ caller
    first = _code_cache.lookup(source, mode, flags)
    kept = marshal.loads(marshal.dumps(first))  # as read back from the file
    again = _code_cache.lookup(source, mode, flags)
    fresh = builtins.compile(source, "<string>", mode, flags, True)
    assert kept == fresh and again is first
    assert _code_cache.stats() == {"entries": 1, "hits": 1, "new": 1}


def test_exec_inherits_the_callers_future_flags_as_the_builtin_does(table):
    # this module has `from __future__ import annotations`: an exec'd annotation is text
    ns: dict = {}
    _code_cache._exec("def f(x: not_defined_anywhere): pass", {}, ns)
    assert ns["f"].__annotations__ == {"x": "not_defined_anywhere"}
    plain: dict = {}  # a caller without the flag (dataclasses): the annotation is evaluated
    caller = compile("run('def f(x: not_defined_anywhere): pass', {}, ns)", "<caller>", "exec",
                     0, True)
    with pytest.raises(NameError):
        exec(caller, {"run": _code_cache._exec, "ns": plain})
    with pytest.raises(NameError):
        exec(compile("exec('def f(x: not_defined_anywhere): pass', {}, {})", "<c>", "exec",
                     0, True), {})


def test_exec_and_eval_default_to_the_callers_namespaces(table):
    scope = {"_code_cache": _code_cache, "y": 41}
    exec(compile("_code_cache._exec('z = y + 1')\nw = _code_cache._eval('  z * 2')",
                 "<c>", "exec", 0, True), scope)
    assert scope["z"] == 42 and scope["w"] == 84  # eval drops leading blanks, as the built-in


def test_what_the_builtin_refuses_raises_the_builtins_error(table):
    for bad in ("def (:", "x = 1\0"):
        with pytest.raises((SyntaxError, ValueError)) as ours:
            _code_cache._exec(bad, {})
        with pytest.raises((SyntaxError, ValueError)) as theirs:
            exec(bad, {})
        assert type(ours.value) is type(theirs.value)
        assert str(ours.value) == str(theirs.value)
    with pytest.raises(SyntaxError):
        _code_cache._compile("1 +", "<string>", "eval")
    assert table.table == {}  # nothing refused is kept


def test_other_compile_calls_go_to_the_builtin(table):
    code = _code_cache._compile("x = 1", "file.py", "exec")
    assert code.co_filename == "file.py" and table.table == {}
    tree = _code_cache._compile("x = 1", "<string>", "exec", 0x400)  # ast.PyCF_ONLY_AST
    assert type(tree).__name__ == "Module" and table.table == {}
    _code_cache._compile("x", "<string>", "eval")
    assert len(table.table) == 1


def test_a_table_of_another_interpreter_or_unreadable_is_ignored(tmp_path):
    path = tmp_path / "t.marshal"
    assert _code_cache._load(str(path)) == {}
    path.write_bytes(b"\0garbage")
    assert _code_cache._load(str(path)) == {}
    path.write_bytes(marshal.dumps((_code_cache._HEADER, "2.7.18", {("eval", 0, "1"): None})))
    assert _code_cache._load(str(path)) == {}
    code = compile("1", "<string>", "eval", 0, True)
    path.write_bytes(marshal.dumps((_code_cache._HEADER, sys.version, {("eval", 0, "1"): code})))
    assert _code_cache._load(str(path)) == {("eval", 0, "1"): code}


PATTERNS = [
    (r"(?P<key>[A-Za-z_][\w.-]*)\s*=\s*(?P<value>.*?)\s*$", 0),
    (r"^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+][0-9]+)?)$", re.X),
    (r"(?<=abc)déf|\bG[h-k]+", re.IGNORECASE | re.UNICODE),
    (rb"\x00(?P<n>[\x01-\x7f]{2,})\Z", 0),
    (r"(a)(b)?(?(2)c|d)", re.MULTILINE | re.DOTALL),
    (r"", 0),
]


@pytest.fixture
def alone(monkeypatch):
    """This process runs one Python thread, as far as the pattern table can tell (a test
    worker may keep threads of earlier tests alive: a server's, a cluster's)."""
    import threading

    monkeypatch.setattr(threading, "active_count", lambda: 1)


@pytest.mark.parametrize(("pattern", "flags"), PATTERNS)
def test_a_kept_pattern_is_exactly_what_re_compiles(table, alone, pattern, flags):
    flags = int(flags)
    first = _code_cache._re_compile(pattern, flags)
    fresh = re._compiler.compile(pattern, flags)  # re's own compiler (not installed here)
    key = ("re", flags, pattern)
    kept = marshal.loads(marshal.dumps(table.table[key]))  # as read back from the file
    table.table[key] = kept
    again = _code_cache._re_compile(pattern, flags)
    for p in (first, again):  # Pattern's == compares the text, the flags and the code
        assert p == fresh and p.groupindex == fresh.groupindex and p.groups == fresh.groups
    text = "x" * 3 if isinstance(pattern, str) else b"\x00ab"
    assert [m.span() for m in again.finditer(text)] == [m.span() for m in fresh.finditer(text)]
    assert _code_cache.stats() == {"entries": 1, "hits": 1, "new": 1}


def test_a_pattern_re_refuses_or_that_warns_or_debug_is_not_kept(table, alone, capsys):
    with pytest.raises(re.error, match="missing \\)"):
        _code_cache._re_compile("(ab", 0)
    for _ in range(2):  # said again on every compilation, as by re itself
        with pytest.warns(FutureWarning, match="Possible nested set"):
            assert _code_cache._re_compile("[[a]", 0).match("[")
    _code_cache._re_compile("ab", re.DEBUG)
    assert "LITERAL 97" in capsys.readouterr().out  # re's own debug listing
    assert table.table == {} and _code_cache.stats()["new"] == 0


PROBE = textwrap.dedent("""
    import json, sys
    from fm2uav import _code_cache
    installed = _code_cache.install()
    import dataclasses, collections, typing
    @dataclasses.dataclass(frozen=True, order=True)
    class P:
        x: int
        y: "tuple[int, ...]" = dataclasses.field(default_factory=tuple)
    Pair = collections.namedtuple("Pair", "a b")
    ref = typing.ForwardRef("dict[str, int]")
    import re
    word = re.compile(r"(?P<w>[a-z]+)-(?P=w)[0-9]{2,}", re.I)
    p = P(1, (2,))
    ok = (repr(p) == "P(x=1, y=(2,))" and p == P(1, (2,)) and P(0) < p
          and hash(p) == hash(P(1, (2,)))
          and Pair(1, 2).b == 2 and ref.__forward_code__.co_filename == "<string>"
          and word.fullmatch("Ab-ab42").group("w") == "Ab")
    ours = re._compiler.compile.__module__ == "fm2uav._code_cache"
    stats = _code_cache.stats()
    saved = _code_cache.save()
    print(json.dumps({"installed": installed, "ok": ok, "stats": stats, "saved": saved,
                      "re": ours}))
""")


def _probe(tmp_path, **env):
    run_env = {**os.environ, "FM2UAV_CACHE_DIR": str(tmp_path), **env}
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                         env=run_env, check=True)
    return json.loads(out.stdout)


def test_a_second_process_takes_every_entry_from_the_table(tmp_path):
    first = _probe(tmp_path)
    assert first["installed"] and first["ok"] and first["saved"] and first["re"]
    assert first["stats"]["new"] >= 6  # the dataclass's methods, the namedtuple, the ref, re
    second = _probe(tmp_path)
    assert second["ok"] and not second["saved"]
    assert second["stats"]["new"] == 0 and second["stats"]["hits"] == first["stats"]["new"]
    off = _probe(tmp_path, FM2UAV_CODE_CACHE="0")
    assert off["ok"] and not off["installed"] and off["stats"]["entries"] == 0 and not off["re"]


def test_the_entry_point_keeps_the_table_and_answers_the_same(tmp_path):
    cmd = [sys.executable, "-m", "fm2uav", "plan", "--bogus"]
    env = {**os.environ, "FM2UAV_CACHE_DIR": str(tmp_path), "COLUMNS": "100"}
    answers = [subprocess.run(cmd, capture_output=True, text=True, env=e)
               for e in (env, env, {**env, "FM2UAV_CODE_CACHE": "0"})]
    assert len({(a.returncode, a.stdout, a.stderr) for a in answers}) == 1
    assert answers[0].returncode == 2
    files = list((tmp_path / "code").iterdir())
    assert [f.name for f in files] == [os.path.basename(_code_cache.cache_file("plan"))]
    kept = _code_cache._load(str(files[0]))
    assert len(kept) > 50 and sum(key[0] == "re" for key in kept) > 10  # typer's, rich's...


def test_each_command_word_has_a_table_and_anything_else_shares_one():
    names = {w: os.path.basename(_code_cache.cache_file(w))
             for w in ("plan", "run", "x-y2", "", "--help", "Plan", "../x", "a b")}
    assert names["plan"].endswith("-plan.marshal") and names["x-y2"].endswith("-x-y2.marshal")
    assert len({names[w] for w in ("", "--help", "Plan", "../x", "a b")}) == 1
    assert names[""].endswith("-_.marshal") and sys.implementation.cache_tag in names[""]


def test_a_write_that_fails_leaves_the_kept_table_and_no_partial_file(table, tmp_path,
                                                                      monkeypatch):
    path = tmp_path / "code" / "t.marshal"
    path.parent.mkdir()
    path.write_bytes(b"kept")
    monkeypatch.setattr(_code_cache._State, "path", str(path))
    _code_cache.lookup("1 + 1", "eval", 0)
    real_dumps = marshal.dumps

    def full_disk(obj):  # the table cannot be written whole
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(marshal, "dumps", full_disk)
    assert not _code_cache.save()
    assert sorted(p.name for p in path.parent.iterdir()) == ["t.marshal"]
    assert path.read_bytes() == b"kept"
    monkeypatch.setattr(marshal, "dumps", real_dumps)
    assert _code_cache.save() and _code_cache._load(str(path))


def test_a_new_pattern_while_other_threads_run_goes_to_re(table, monkeypatch):
    import threading

    release = threading.Event()
    other = threading.Thread(target=release.wait)
    other.start()
    try:
        assert threading.active_count() > 1
        assert _code_cache._re_compile("a+b", 0) == re._compiler.compile("a+b", 0)
        assert table.table == {}
    finally:
        release.set()
        other.join()
    monkeypatch.setattr(threading, "active_count", lambda: 1)  # alone (see `alone`)
    _code_cache._re_compile("a+b", 0)
    assert list(table.table) == [("re", 0, "a+b")]
