"""fm2uav._code_cache: the code of generated source kept between runs is exactly what
compiling gives, exec/eval/compile behave as the built-ins for their callers, and the
command line's entry point keeps and reuses the table."""

from __future__ import annotations

import builtins
import json
import marshal
import os
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
    p = P(1, (2,))
    ok = (repr(p) == "P(x=1, y=(2,))" and p == P(1, (2,)) and P(0) < p
          and hash(p) == hash(P(1, (2,)))
          and Pair(1, 2).b == 2 and ref.__forward_code__.co_filename == "<string>")
    stats = _code_cache.stats()
    saved = _code_cache.save()
    print(json.dumps({"installed": installed, "ok": ok, "stats": stats, "saved": saved}))
""")


def _probe(tmp_path, **env):
    run_env = {**os.environ, "FM2UAV_CACHE_DIR": str(tmp_path), **env}
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                         env=run_env, check=True)
    return json.loads(out.stdout)


def test_a_second_process_takes_every_entry_from_the_table(tmp_path):
    first = _probe(tmp_path)
    assert first["installed"] and first["ok"] and first["saved"]
    assert first["stats"]["new"] >= 5  # the dataclass's methods, the namedtuple, the ref
    second = _probe(tmp_path)
    assert second["ok"] and not second["saved"]
    assert second["stats"]["new"] == 0 and second["stats"]["hits"] == first["stats"]["new"]
    off = _probe(tmp_path, FM2UAV_CODE_CACHE="0")
    assert off["ok"] and not off["installed"] and off["stats"]["entries"] == 0


def test_the_entry_point_keeps_the_table_and_answers_the_same(tmp_path):
    cmd = [sys.executable, "-m", "fm2uav", "plan", "--bogus"]
    env = {**os.environ, "FM2UAV_CACHE_DIR": str(tmp_path), "COLUMNS": "100"}
    answers = [subprocess.run(cmd, capture_output=True, text=True, env=e)
               for e in (env, env, {**env, "FM2UAV_CODE_CACHE": "0"})]
    assert len({(a.returncode, a.stdout, a.stderr) for a in answers}) == 1
    assert answers[0].returncode == 2
    files = list((tmp_path / "code").iterdir())
    assert [f.name for f in files] == [os.path.basename(_code_cache.cache_file("plan"))]
    assert len(_code_cache._load(str(files[0]))) > 50


def test_each_command_word_has_a_table_and_anything_else_shares_one():
    names = {w: os.path.basename(_code_cache.cache_file(w))
             for w in ("plan", "run", "x-y2", "", "--help", "Plan", "../x", "a b")}
    assert names["plan"].endswith("-plan.marshal") and names["x-y2"].endswith("-x-y2.marshal")
    assert len({names[w] for w in ("", "--help", "Plan", "../x", "a b")}) == 1
    assert names[""].endswith("-_.marshal") and sys.implementation.cache_tag in names[""]
