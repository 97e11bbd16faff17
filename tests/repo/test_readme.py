"""The README's Python tour runs as written (one namespace, blocks in order), each block also
on its own (no name from an earlier block), and every number printed in a comment after an
expression (``p.length, p.clearance   # ≈ 54.0 m, ≈ 4.8 m``) is the value the run gives, to
the decimals shown."""

import ast
import re
from pathlib import Path

import numpy as np
import pytest

README = Path(__file__).resolve().parents[2] / "README.md"
_NUMBER = r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?"


def _blocks():
    return re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def claimed_numbers(comment: str) -> list[str]:
    """The numbers a comment claims for its expression: the leading ``N`` or ``≈ N unit``
    items, up to the first ``:`` or ``(`` (``# 0.7061 (exact: 0.7071)`` claims 0.7061)."""
    head = re.split(r"[:(]", comment, maxsplit=1)[0]
    items = [s.strip() for s in head.split(",")]
    out = []
    for item in items:
        m = re.match(rf"^≈?\s*({_NUMBER})\b", item)
        if not m:
            break
        out.append(m.group(1))
    return out


def _matches(value, text: str) -> bool:
    decimals = len(text.split(".")[1]) if "." in text else 0
    return abs(float(value) - float(text)) <= 0.5 * 10.0 ** -decimals + 1e-12


def test_claimed_numbers_reads_the_comment_forms():
    assert claimed_numbers(" ≈ 54.0 m, ≈ 4.8 m") == ["54.0", "4.8"]
    assert claimed_numbers(" 0.7061 (exact: 0.7071)") == ["0.7061"]
    assert claimed_numbers(" 1.0: share within ±1 cell") == ["1.0"]
    assert claimed_numbers(" (N, 2) metres, start → goal exactly") == []
    assert claimed_numbers(" lon, lat, alt of the first points") == []
    assert not _matches(4.76, "5.4") and _matches(4.76, "4.8")


@pytest.mark.slow
def test_readme_python_blocks_run_and_print_their_numbers():
    blocks = _blocks()
    assert len(blocks) >= 4
    namespace: dict = {}
    checked = 0
    for i, block in enumerate(blocks):
        lines = block.splitlines()
        for stmt in ast.parse(block).body:
            code = ast.Module(body=[stmt], type_ignores=[])
            where = f"README.md python block {i + 1}, line {stmt.lineno}"
            try:
                if isinstance(stmt, ast.Expr):
                    value = eval(compile(ast.Expression(stmt.value), where, "eval"), namespace)
                else:
                    exec(compile(code, where, "exec"), namespace)
                    continue
            except Exception as exc:  # pragma: no cover - the message is the point
                raise AssertionError(f"{where} fails: {exc!r}\n{block}") from exc
            line = lines[stmt.end_lineno - 1]
            if "#" not in line:
                continue
            claims = claimed_numbers(line.split("#", 1)[1])
            if not claims:
                continue
            values = np.atleast_1d(np.asarray(value, dtype=float)).ravel().tolist()
            assert len(values) == len(claims), f"{where}: {line!r} shows {claims}, got {values}"
            for v, c in zip(values, claims):
                assert _matches(v, c), f"{where}: {line.strip()!r} claims {c}, the run gives {v}"
            checked += 1
    assert checked >= 3  # the solver's T, the map's length and clearance, the level share


def _unbound_names(code: str) -> set[str]:
    """Names a block reads that it neither assigns nor imports (nor are builtins)."""
    import builtins

    tree = ast.parse(code)
    bound = set(dir(builtins))
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, (ast.Store, ast.Del)):
            bound.add(node.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            bound.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            bound.add(node.name)
        elif isinstance(node, ast.arg):
            bound.add(node.arg)
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)
            and isinstance(n.ctx, ast.Load) and n.id not in bound}


def test_unbound_names_finds_a_name_from_another_block():
    assert _unbound_names("import fm2uav\nr = fm2uav.check(p.path)") == {"p"}
    assert _unbound_names("import numpy as np\nx = np.ones(3)\nx.sum()") == set()


@pytest.mark.parametrize("k", range(len(_blocks())))
def test_every_readme_python_block_stands_on_its_own(k):
    """A reader may copy one block: it must not use a name defined in an earlier one."""
    assert _unbound_names(_blocks()[k]) == set(), _blocks()[k]
