"""One set of flags (issue 24): every message that names a flag names one the command accepts.

``for_command`` (the rewrite every error goes through) is checked on hand-made messages; then
every string in ``src/`` that names a ``--flag`` is walked, with the commands that can raise
it (a static call graph of the ``cli`` functions, then the modules they import), and what the
user of each of those commands reads must name only that command's flags. Help texts name
only their own command's flags, and the airframe speed flags the docs list are accepted.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from functools import lru_cache
from pathlib import Path

import pytest
import typer

from fm2uav._validate import where_text
from fm2uav.cli import app

from fm2uav.cli._flags import FLAG, FLAG_KEYS, FOREIGN_FLAGS, flags_in, for_command

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src" / "fm2uav"

#: Modules whose flag-like strings are not fm2uav command-line messages.
NOT_MESSAGES = {
    "fm2uav.__main__",            # the entry point itself (no message names a flag)
    "fm2uav.experiments.docs",    # `python -m fm2uav.experiments.docs --write/--check`
    "fm2uav.cli._flags",          # the flag → key table
}


#: Messages raised only when the flag they name was given (so only by commands that have it),
#: which the name-based walk cannot see: (module, text) → why.
RAISED_ONLY_WITH_THE_FLAG = {
    ("fm2uav.cli.options", "give --lonlat or --cells, not both"):
        "cli_point(lonlat=..., cells=...): only plan and formation pass cells=True",
    ("fm2uav.experiments._executors",
     "cannot reach the Dask scheduler {}: {}; check --scheduler"):
        "a Dask pool is made only from a --scheduler (sweep, reproduce curvature, batch)",
    ("fm2uav.missions.coverage.fm2", "--angle (degrees, within ±360)"):
        "checked only for a given angle: cover --angle (reproduce coverage searches it)",
}


#: Modules whose messages only some commands can raise, which the name-based walk cannot see
#: (it follows ``obj.read(...)`` into every method called ``read``): module → (does the
#: command ``name`` with ``flags`` raise them?, why).
RAISED_ONLY_BY = {
    "fm2uav.experiments._store": (lambda name, flags: name in ("sweep", "reproduce curvature"),
                                  "the sweep log: opened only by the sweep runner"),
    "fm2uav.experiments._executors": (
        lambda name, flags: name in ("sweep", "reproduce curvature", "batch"),
        "the worker pools: made only by the sweep runner and fm2uav batch"),
    "fm2uav.io.outdir": (lambda name, flags: "--out" in flags,
                         "an output set is made only by a command that writes one (--out)"),
}


# -- the rewrite ---------------------------------------------------------------------------

@pytest.mark.parametrize("message, accepted, expected", [
    ("crop with world.bbox (CLI --bbox W,S,E,N)", set(), "crop with world.bbox"),
    ("crop with world.bbox (CLI --bbox W,S,E,N)", {"--bbox"},
     "crop with world.bbox (CLI --bbox W,S,E,N)"),
    ("agl must be > 0 (mission file: planner.agl; CLI: --agl)", set(),
     "agl must be > 0 (mission file: planner.agl)"),
    ("x (mission file: planner.agl, planner.min_agl; CLI: --agl, --min-agl)", {"--min-agl"},
     "x (mission file: planner.agl, planner.min_agl; CLI: --min-agl)"),
    ("plan with storage 'full' (CLI --storage full --cell-size)", {"--cell-size"},
     "plan with storage 'full' (CLI --cell-size)"),
    ("raise planner.step (CLI --step, default 0.5 cells) or a coarser grid (world.dz / --dz)",
     set(), "raise planner.step or a coarser grid (world.dz)"),
    ("(mission file planner.agl / world.ceiling; CLI --agl / --ceiling)", {"--ceiling"},
     "(mission file planner.agl / world.ceiling; CLI --ceiling)"),
    ("need airframe.min_speed (a margin above the stall speed; CLI --min-speed) so that",
     set(), "need airframe.min_speed (a margin above the stall speed) so that"),
    ("(mission file outputs.frame, CLI --frame)", set(), "(mission file outputs.frame)"),
    ("--min-agl / --max-agl limit a terrain-following flight; give --agl too", {"--max-agl"},
     "planner.min_agl / --max-agl limit a terrain-following flight; give planner.agl too"),
    ("accept it with --allow-filled (world.allow_filled)", set(),
     "accept it with world.allow_filled"),
    ("check the CRS (--area / world.crs, --crs)", {"--area"},
     "check the CRS (--area / world.crs)"),
    ("or shift it (gdalwarp --config CENTER_LONG 180)", set(),
     "or shift it (gdalwarp --config CENTER_LONG 180)"),
    ("--out is read-only; choose another --out", {"--out"},
     "--out is read-only; choose another --out"),
])
def test_a_flag_the_command_lacks_becomes_its_mission_file_key(message, accepted, expected):
    assert for_command(message, accepted) == expected


# -- the commands and their flags ------------------------------------------------------------

@lru_cache(maxsize=1)
def commands() -> dict[str, tuple[object, frozenset[str]]]:
    """``"plan"``, ``"reproduce tff"`` ... → (callback, its flags)."""
    out: dict[str, tuple[object, frozenset[str]]] = {}

    def walk(cmd, prefix):
        subs = getattr(cmd, "commands", None)
        if subs:
            for name, sub in subs.items():
                walk(sub, f"{prefix} {name}".strip())
            return
        flags = frozenset(o for p in cmd.params for o in (*p.opts, *p.secondary_opts)
                          if o.startswith("--"))
        out[prefix] = (cmd.callback, flags | {"--help"})

    walk(typer.main.get_command(app), "")
    return out


def all_flags() -> set[str]:
    return set().union(*(f for _, f in commands().values()))


# -- a static picture of who can raise what ----------------------------------------------------
#
# Every function, method, class and module-level variable of src/fm2uav is a node; a node
# reaches every node it names: a name through its module's own definitions and imports
# (re-exports and lazy packages followed), `module.name` likewise, `obj.method` every method
# of that name in any class (the receiver's type is unknown: an over-approximation, so a
# message is checked for every command that might raise it), a class its dunder methods.
# A string belongs to the node it is written in.

def _module_name(path: Path) -> str:
    rel = path.relative_to(SRC.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@lru_cache(maxsize=1)
def sources() -> dict[str, Path]:
    return {_module_name(p): p for p in SRC.rglob("*.py") if "__pycache__" not in p.parts}


@lru_cache(maxsize=None)
def tree(module: str) -> ast.Module:
    return ast.parse(sources()[module].read_text(encoding="utf-8"))


def _runtime(node: ast.AST) -> Iterator[ast.AST]:
    """``ast.walk`` without the ``if TYPE_CHECKING:`` blocks (never run)."""
    todo = [node]
    while todo:
        n = todo.pop()
        yield n
        if isinstance(n, ast.If) and "TYPE_CHECKING" in ast.unparse(n.test):
            todo.extend(n.orelse)
            continue
        todo.extend(ast.iter_child_nodes(n))


Node = tuple[str, str]  # (module, qualified name: "f", "Class.method", "CONSTANT")


@lru_cache(maxsize=1)
def nodes() -> dict[Node, ast.AST]:
    out: dict[Node, ast.AST] = {}
    for module in sources():
        for node in tree(module).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                out[(module, node.name)] = node
            elif isinstance(node, ast.ClassDef):
                out[(module, node.name)] = node  # the class body (fields, defaults)
                for sub in node.body:
                    if isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef)):
                        out[(module, f"{node.name}.{sub.name}")] = sub
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                for t in (node.targets if isinstance(node, ast.Assign) else [node.target]):
                    if isinstance(t, ast.Name):
                        out[(module, t.id)] = node
    return out


@lru_cache(maxsize=None)
def _imports(module: str) -> dict[str, tuple[str, str | None]]:
    """Local name → (module, attribute or None for a module) of every import in ``module``."""
    out: dict[str, tuple[str, str | None]] = {}
    package = module if sources()[module].name == "__init__.py" else module.rsplit(".", 1)[0]
    for node in ast.walk(tree(module)):
        if isinstance(node, ast.Import):
            for a in node.names:
                out[a.asname or a.name.split(".")[0]] = (a.name if a.asname else
                                                         a.name.split(".")[0], None)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                src = ".".join(base + ([node.module] if node.module else []))
            else:
                src = node.module or ""
            for a in node.names:
                sub = f"{src}.{a.name}"
                out[a.asname or a.name] = (sub, None) if sub in sources() else (src, a.name)
    return out


def _lazy_names(package: str) -> dict[str, str]:
    """A lazy package's ``_LAZY_NAMES`` (public name → its module, absolute)."""
    for node in tree(package).body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "_LAZY_NAMES"
                                                for t in node.targets):
            raw = ast.literal_eval(node.value)
            out = {}
            for k, v in raw.items():
                level = len(v) - len(v.lstrip("."))
                base = package.split(".")[:len(package.split(".")) - level + 1] if level else [
                    package]
                out[k] = ".".join(base + [v.lstrip(".")])
            return out
    return {}


@lru_cache(maxsize=None)
def _resolve(module: str, name: str) -> tuple[Node, ...]:
    """The node(s) ``name`` means in ``module`` (its own, or imported: re-exports followed)."""
    if module not in sources():
        return ()
    if (module, name) in nodes():
        return ((module, name),)
    target = _imports(module).get(name)
    if target is None or target[1] is None:
        lazy = _lazy_names(module).get(name)
        return _resolve(lazy, name) if lazy else ()
    return _resolve(*target)


@lru_cache(maxsize=1)
def _methods() -> dict[str, list[Node]]:
    """Method name → the methods of that name (any class)."""
    index: dict[str, list[Node]] = {}
    for module, q in nodes():
        if "." in q:
            index.setdefault(q.split(".")[1], []).append((module, q))
    return index


@lru_cache(maxsize=1)
def _by_module() -> dict[str, list[tuple[str, ast.AST]]]:
    """Module → its nodes ``(qualified name, node)``, in :func:`nodes`' order."""
    out: dict[str, list[tuple[str, ast.AST]]] = {}
    for (module, q), n in nodes().items():
        out.setdefault(module, []).append((q, n))
    return out


@lru_cache(maxsize=None)
def _class_members(key: Node) -> tuple[Node, ...]:
    """A class reaches its body and its dunder methods (run without being named)."""
    module, q = key
    return tuple((module, n) for n, _ in _by_module().get(module, ())
                 if n.startswith(q + ".__"))


@lru_cache(maxsize=None)
def _mentions(key: Node) -> tuple[Node, ...]:
    """The nodes the body of ``key`` names (each command's walk reads them: kept)."""
    return tuple(_mentioned(key))


def _mentioned(key: Node) -> Iterator[Node]:
    module = key[0]
    aliases = {k for k, (m, a) in _imports(module).items() if a is None}
    for n in _runtime(nodes()[key]):
        if isinstance(n, ast.Name):
            yield from _resolve(module, n.id)
        elif isinstance(n, ast.Attribute):
            if isinstance(n.value, ast.Name) and n.value.id in aliases:
                yield from _resolve(_imports(module)[n.value.id][0], n.attr)
            elif (isinstance(n.value, ast.Call) and isinstance(n.value.func, ast.Name)
                  and n.value.func.id == "super"):
                yield from _base_methods(key, n.attr)
            else:  # obj.method: any method of that name
                yield from _methods().get(n.attr, [])


def _base_methods(key: Node, name: str) -> Iterator[Node]:
    """``super().name`` in the method ``key``: ``name`` of the classes its class derives from
    (fm2uav's own, followed up their bases; a library base class has none of ours)."""
    module, q = key
    if "." not in q:
        return
    todo = [(module, q.split(".")[0])]
    seen: set[Node] = set()
    while todo:
        cls = todo.pop()
        if cls in seen or not isinstance(nodes().get(cls), ast.ClassDef):
            continue
        seen.add(cls)
        for base in nodes()[cls].bases:
            if isinstance(base, ast.Name):
                for b in _resolve(cls[0], base.id):
                    if (b[0], f"{b[1]}.{name}") in nodes():
                        yield (b[0], f"{b[1]}.{name}")
                    todo.append(b)


#: What ``fm2uav app`` runs once the server is up reports its errors on the web page, not on
#: the terminal: the walk of the command line stops there. (Those messages still name CLI
#: flags, e.g. "give exactly one of --spacing (metres) or --camera": the app's to rewrite.)
PAGE_PACKAGE = "fm2uav.app."


@lru_cache(maxsize=None)
def reach(callback) -> frozenset[Node]:
    """The nodes a command callback can run (see above)."""
    fn = callback
    while hasattr(fn, "__wrapped__"):
        fn = fn.__wrapped__
    seen: set[Node] = set()
    todo = [(fn.__module__, fn.__qualname__)]
    while todo:
        key = todo.pop()
        if key in seen or key not in nodes() or key[0].startswith(PAGE_PACKAGE):
            continue
        seen.add(key)
        todo += _mentions(key)
        if isinstance(nodes()[key], ast.ClassDef):
            todo += _class_members(key)
    return frozenset(seen)


def _is_doc(node: ast.AST, parent: ast.AST | None) -> bool:
    return (isinstance(parent, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
            and parent.body and parent.body[0] is node)


def _text(node: ast.AST) -> str:
    if isinstance(node, ast.Constant):
        return node.value
    return "".join(v.value if isinstance(v, ast.Constant) else "{}" for v in node.values)


def _is_option_declaration(node: ast.AST, parent: dict[int, ast.AST]) -> bool:
    """``typer.Option(..., "--report", help=...)``: a flag declared, not a message."""
    call = parent.get(id(node))
    return (isinstance(call, ast.Call) and node in call.args
            and ast.unparse(call.func).split(".")[-1] in ("Option", "Argument", "_option"))


def messages() -> Iterator[tuple[str, str | None, int, str]]:
    """``(module, node or None, line, text)`` of every string in src/ that names a flag: not
    docstrings, help texts (``help=``, ``*_HELP``), option declarations or comments."""
    for module in sorted(sources()):
        if module in NOT_MESSAGES:
            continue
        t = tree(module)
        everything = list(ast.walk(t))
        kids = {id(n): list(ast.iter_child_nodes(n)) for n in everything}

        def walk(top: ast.AST) -> Iterator[ast.AST]:  # ast.walk on the children listed once
            todo = [top]
            while todo:
                n = todo.pop()
                yield n
                todo.extend(kids[id(n)])

        parent = {id(c): n for n in everything for c in kids[id(n)]}
        skip: set[int] = set()
        for node in everything:
            for child in kids[id(node)]:
                if isinstance(child, ast.Expr) and _is_doc(child, node):
                    skip.update(id(n) for n in walk(child))
            if isinstance(node, ast.keyword) and node.arg == "help":
                skip.update(id(n) for n in walk(node.value))
            if isinstance(node, ast.Assign) and any(getattr(x, "id", "").endswith("_HELP")
                                                    for x in node.targets):
                skip.update(id(n) for n in walk(node.value))
            if isinstance(node, ast.FunctionDef) and node.name == "_help":  # a help text
                skip.update(id(n) for n in walk(node))
        pieces = {id(v) for p in everything if isinstance(p, ast.JoinedStr) for v in p.values}
        owner: dict[int, str] = {}
        own = _by_module().get(module, [])
        for q, n in own:
            if not isinstance(n, ast.ClassDef):
                for sub in walk(n):
                    owner.setdefault(id(sub), q)
        for q, n in own:  # class bodies (defaults) last: methods win
            if isinstance(n, ast.ClassDef):
                for sub in walk(n):
                    owner.setdefault(id(sub), q)
        for node in everything:
            if id(node) in skip or id(node) in pieces:
                continue
            if not (isinstance(node, ast.JoinedStr) or isinstance(node, ast.Constant)
                    and isinstance(node.value, str)):
                continue
            if _is_option_declaration(node, parent):
                continue
            text = _text(node)
            if FLAG.search(text):
                yield module, owner.get(id(node)), node.lineno, text


@lru_cache(maxsize=1)
def all_messages() -> list[tuple[str, str | None, int, str]]:
    return list(messages())


def test_the_walk_finds_the_messages_and_their_commands():
    found = all_messages()
    assert len(found) > 80
    speeds = [(m, owner) for m, owner, _, text in found if text.startswith(
        "fixed-wing speed changes need airframe.min_speed (a margin above the stall speed; "
        "CLI --min-speed)")]
    assert len(speeds) == 1 and speeds[0][1] is not None  # the function that raises it
    run = reach(commands()["run"][0])
    urban = reach(commands()["reproduce urban"][0])
    assert {speeds[0], ("fm2uav.world.dem_read", "_CRS_HINT"),
            ("fm2uav.planning.altitude", "final_profile")} <= run
    assert speeds[0] not in urban  # the thesis' city writes no mission



def test_every_flag_named_in_a_message_is_a_flag_of_some_command():
    known = all_flags() | FOREIGN_FLAGS
    unknown = sorted({(f"{m}:{line}", f) for m, _, line, text in all_messages()
                      for f in FLAG.findall(text) if f not in known})
    assert not unknown, f"messages name flags no command has: {unknown}"


def test_every_message_names_only_flags_of_the_commands_that_can_raise_it():
    wrong = []
    for name, (callback, flags) in sorted(commands().items()):
        reached = reach(callback)
        for module, owner, line, text in all_messages():
            if owner is not None and (module, owner) not in reached:
                continue
            if owner is None and not any(m == module for m, _ in reached):
                continue
            if (module, text) in RAISED_ONLY_WITH_THE_FLAG:
                continue
            if module in RAISED_ONLY_BY and not RAISED_ONLY_BY[module][0](name, flags):
                continue
            if FLAG.fullmatch(text):  # a flag passed as `where`: " (CLI: --flag)" in the text
                text = where_text((None, text))
            shown = for_command(text, flags)
            bad = [f for f in flags_in(shown) if f not in flags]
            if bad:
                wrong.append(f"fm2uav {name}: {module}:{line} names {bad}: {shown!r}")
    assert not wrong, "\n".join(wrong)


def test_flag_keys_are_mission_file_keys_and_flags():
    from fm2uav.io.mission import Mission

    def keys(model, prefix=""):
        for name, field in model.model_fields.items():
            key = prefix + (field.alias or name)
            yield key
            ann = field.annotation
            for sub in (ann, *getattr(ann, "__args__", ())):
                if isinstance(sub, type) and hasattr(sub, "model_fields"):
                    yield from keys(sub, key + ".")

    schema = set(keys(Mission))
    assert set(FLAG_KEYS.values()) <= schema, set(FLAG_KEYS.values()) - schema
    assert set(FLAG_KEYS) <= all_flags(), set(FLAG_KEYS) - all_flags()


def _help_texts(cmd) -> Iterator[str]:
    yield cmd.help or ""
    for p in cmd.params:
        yield getattr(p, "help", None) or ""


def test_help_texts_name_only_their_own_command_s_flags():
    wrong = []
    for name, (callback, flags) in commands().items():
        cmd = typer.main.get_command(app)
        for word in name.split():
            cmd = cmd.commands[word]
        for text in _help_texts(cmd):
            for line in text.splitlines():
                # an example of another command (`fm2uav run ... --x`) names that one's flags
                other = re.search(r"fm2uav ([a-z]+(?: [a-z]+)?)", line)
                if other and other.group(1) not in (name, name.split()[0]):
                    continue
                bad = [f for f in flags_in(line) if f not in flags]
                if bad:
                    wrong.append(f"fm2uav {name}: {bad} in {line.strip()!r}")
    assert not wrong, "\n".join(wrong)


# -- one set of flags (issue 24 deliverable 4, docs/operator.md §9 "On the command line") ------

MISSION_FLAGS = ("--firmware", "--vehicle", "--frame", "--end", "--min-speed", "--cruise-speed",
                 "--hover-speed", "--endurance", "--reserve", "--thin", "--anchor")


@pytest.mark.parametrize("command", ["run", "plan", "cover", "formation", "export"])
def test_every_mission_command_takes_the_mission_flags_the_docs_list(command):
    flags = commands()[command][1]
    missing = [f for f in MISSION_FLAGS if f not in flags]
    assert not missing, f"fm2uav {command} lacks {missing}"
    if command != "formation":  # its missions command each leg's simulated speed
        assert "--speed-changes" in flags


def test_the_operator_guide_lists_the_same_mission_flags():
    text = (ROOT / "docs" / "operator.md").read_text(encoding="utf-8")
    section = text.split("### On the command line", 1)[1].split("```", 1)[0]
    listed = set(re.findall(r"`(--[a-z-]+)`", section))
    assert set(MISSION_FLAGS) | {"--speed-changes"} <= listed
