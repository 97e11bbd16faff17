"""Docs that run: every fenced block of README.md and docs/*.md, executed as a reader would.

How a block is run depends on its language (the word after the opening fence):

* ``bash`` (also ``sh``, ``shell``, ``console``): each command (``\\``-continued lines
  joined, comment lines dropped) runs in one workspace folder shared by all the docs, which
  holds a copy of the repository's ``examples/``, ``.venv`` (a link to the test environment)
  and the data files the docs name (``country.tif``, ``osm.geojson``, ...: made on demand by
  :data:`tests.repo.docs_data.FILES`). ``fm2uav ...`` and ``.venv/bin/fm2uav ...`` run in this
  process through the CLI (with ``--out``: once per session, shared with every test asking for
  the same run, ``cli_once``; a ``sweep`` into the folder that another run of the docs filled
  resumes it, in a copy of that folder, as the reader's does); ``fm2uav app ...`` is started
  as a server, asked for its page and session, and stopped with Ctrl-C; ``make run`` runs the
  Makefile's target with ``OUT`` in the workspace; anything else runs in ``bash`` with the venv
  first on ``PATH``. Each must exit 0.
* ``python``: the blocks of one document run in order in one namespace, in the workspace. An
  expression statement whose comment starts with ``→`` states its value: the numbers (and
  ``True``/``False``/``None``, quoted strings) after the arrow, up to an opening parenthesis,
  must equal the value's, to the digits written (``T[100, 100]  # → 0.7061 (exact: 0.7071)``).
  On a ``print`` line the arrow states the printed numbers (``print(v)  # → [-0.5, 0.866]``).
  A comment on an expression or ``print`` line that holds a measured-looking number without
  the arrow is an error (a number nobody checks).
* ``yaml`` / ``json``: parsed; a YAML block whose keys are mission-file keys is read by
  fm2uav's mission parser (fragments completed with a scenario, start and goal).
* ``text``: quoted output. Every line must be printed (``...`` stands for anything) by one of
  the commands named in its ``output`` markers.
* a markdown table right under an ``output`` marker (no fence): a measured table; each of its
  rows (the separator row aside) must be printed by the marked command(s), as in a ``text``
  block (e.g. ``output "cat out/x/table.md"`` after the command that writes it).

Markers: HTML comments on the lines right above the opening fence (invisible on the rendered
page, visible in the source), ``<!-- docs-run: VERB ... -->``:

* ``file NAME``: the block is the content of the file NAME in the workspace (written before any
  command of the docs runs), e.g. the mission file that a later ``fm2uav run`` reads;
* ``output "COMMAND"`` / ``output @producer``: a ``text`` block's lines come from COMMAND (run
  as in a bash block, in the workspace) or from a producer function of
  :data:`tests.repo.docs_data.PRODUCERS` (outputs that need several files or runs);
* ``with "TEXT" ARGS: REASON``: the commands holding TEXT run with ARGS appended (lighter runs
  of long reproductions, shared with the tests that make the same run);
* ``skip "TEXT": REASON`` / ``skip: REASON``: the commands holding TEXT (or the whole block) are
  not run — for what cannot run in a test (a Dask cluster at a given address, the test suite
  itself); the reason is required and shows in the source.
"""

from __future__ import annotations

import ast
import contextlib
import io
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[2]
#: the documents, in the order they run (README first: later docs use its outputs)
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LANGS = {"bash": "bash", "sh": "bash", "shell": "bash", "console": "bash", "python": "python",
         "yaml": "yaml", "yml": "yaml", "json": "json", "text": "text", "table": "text"}
VERBS = ("file", "output", "with", "skip")
WIDE = {"COLUMNS": "4000", "NO_COLOR": "1", "BROWSER": "true"}

_FENCE = re.compile(r"^(?P<indent>[ \t]*)```(?P<lang>[^`\s]*)\s*$")
_MARK = re.compile(r"^\s*<!--\s*docs-run:\s*(?P<body>.*?)\s*-->\s*$")
_QUOTED = re.compile(r'^(?P<verb>\w+)\s+"(?P<text>[^"]*)"\s*(?P<rest>.*)$')


@dataclass
class Marker:
    verb: str
    text: str = ""  # the quoted TEXT / COMMAND, or the file name / @producer
    args: str = ""  # with: the arguments appended
    reason: str = ""


@dataclass
class Block:
    doc: Path
    line: int  # 1-based line of the opening fence
    lang: str  # as written
    body: str
    markers: list[Marker] = field(default_factory=list)

    @property
    def id(self) -> str:
        return f"{_rel(self.doc)}:{self.line}"

    @property
    def kind(self) -> str | None:
        return LANGS.get(self.lang.lower())

    def marked(self, verb: str) -> list[Marker]:
        return [m for m in self.markers if m.verb == verb]


def _rel(doc: Path) -> str:
    """``doc`` as the ids name it: relative to the repository when it is in it."""
    try:
        return str(doc.relative_to(ROOT))
    except ValueError:
        return str(doc)


def parse_marker(body: str, where: str) -> Marker:
    """One ``docs-run:`` comment (module docstring); ValueError naming ``where`` if wrong."""
    verb = body.split(None, 1)[0].rstrip(":") if body else ""
    if verb not in VERBS:
        raise ValueError(f"{where}: unknown docs-run marker {body!r}; one of {', '.join(VERBS)}")
    if verb == "file":
        name = body.split(None, 1)[1].strip() if " " in body else ""
        if not name:
            raise ValueError(f"{where}: 'file' needs a file name")
        return Marker("file", name)
    if verb == "output":
        rest = body[len("output"):].strip()
        if rest.startswith("@"):
            return Marker("output", rest)
        m = re.fullmatch(r'"(.+)"', rest)
        if not m:
            raise ValueError(f'{where}: write output "COMMAND" or output @producer')
        return Marker("output", m.group(1))
    m = _QUOTED.match(body)
    if m:
        rest = m.group("rest")
        args, _, reason = rest.partition(":")
        marker = Marker(verb, m.group("text"), args.strip(), reason.strip())
    else:
        _, _, reason = body.partition(":")
        marker = Marker(verb, "", "", reason.strip())
    if not marker.reason:
        raise ValueError(f"{where}: '{verb}' needs a reason after a colon")
    if verb == "with" and not (marker.text and marker.args):
        raise ValueError(f'{where}: write with "TEXT" ARGS: REASON')
    return marker


def _markers_above(doc: Path, lines: list[str], start: int) -> list[Marker]:
    markers, k = [], start - 1
    while k >= 0 and _MARK.match(lines[k]):
        markers.insert(0, parse_marker(_MARK.match(lines[k]).group("body"),
                                       f"{_rel(doc)}:{k + 1}"))
        k -= 1
    return markers


def blocks(doc: Path) -> list[Block]:
    """The fenced blocks of ``doc`` with their markers, and the markdown tables right under an
    ``output`` marker (kind ``table``: checked like quoted output, row by row)."""
    lines = doc.read_text(encoding="utf-8").splitlines()
    out: list[Block] = []
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            if lines[i].lstrip().startswith("|") and i > 0 and _MARK.match(lines[i - 1]):
                j = i
                while j < len(lines) and lines[j].lstrip().startswith("|"):
                    j += 1
                rows = [ln.strip() for ln in lines[i:j]
                        if not re.fullmatch(r"\|(\s*:?-+:?\s*\|)+", ln.strip())]
                out.append(Block(doc, i + 1, "table", "\n".join(rows) + "\n",
                                 _markers_above(doc, lines, i)))
                i = j
                continue
            i += 1
            continue
        indent, start = m.group("indent"), i
        j = i + 1
        while j < len(lines) and lines[j].strip() != "```":
            j += 1
        body = "\n".join(ln[len(indent):] if ln.startswith(indent) else ln.lstrip()
                         for ln in lines[i + 1:j])
        out.append(Block(doc, start + 1, m.group("lang"), body + "\n",
                         _markers_above(doc, lines, start)))
        i = j + 1
    return out


def all_blocks() -> list[Block]:
    return [b for d in DOCS for b in blocks(d)]


def commands(body: str) -> list[str]:
    """The commands of a bash block: continuation lines joined, blank and comment lines
    dropped (a trailing ``# comment`` stays: the shell and shlex drop it)."""
    out, cur = [], ""
    for ln in body.splitlines():
        s = ln.rstrip()
        if not cur and (not s.strip() or s.lstrip().startswith("#")):
            continue
        if s.endswith("\\"):
            cur += s[:-1] + " "
            continue
        out.append((cur + s).strip())
        cur = ""
    if cur.strip():
        out.append(cur.strip())
    return out


# ---------------------------------------------------------------------------- the workspace
@dataclass
class Result:
    command: str
    code: int
    output: str
    out: Path | None = None  # the output folder (``--out``), when there is one


class Workspace:
    """The folder the docs run in, and how each kind of command is run there."""

    def __init__(self, path: Path, cli_once: Callable[..., Any], files: dict,
                 producers: dict) -> None:
        self.path = path
        self.cli_once = cli_once
        self.files = files
        self.producers = producers
        shutil.copytree(ROOT / "examples", path / "examples",
                        ignore=shutil.ignore_patterns("*.tif", "__pycache__"))
        (path / ".venv").symlink_to(Path(sys.prefix))
        self.bin = Path(sys.prefix) / "bin"
        #: the output folders linked to a session run, and the arguments of that run
        self.linked: dict[Path, list[str]] = {}
        self.env = {**os.environ, **WIDE,
                    "PATH": f"{self.bin}{os.pathsep}{os.environ.get('PATH', '')}"}

    @contextlib.contextmanager
    def here(self):
        old = os.getcwd()
        os.chdir(self.path)
        try:
            yield
        finally:
            os.chdir(old)

    def make_files(self, text: str) -> None:
        """Make the data files ``text`` names that are not there yet (docs_data.FILES)."""
        for tok in re.findall(r"[\w./-]+\.[A-Za-z]\w*", text):
            name = tok.strip("./")
            if name in self.files and not (self.path / name).exists():
                (self.path / name).parent.mkdir(parents=True, exist_ok=True)
                self.files[name](self.path / name)

    # ------------------------------------------------------------------ one command
    def run(self, command: str, *, wide: bool = False) -> Result:
        """Run one command line in the workspace (module docstring). ``wide``: capture the
        output unwrapped (for quoted output) instead of sharing a session run."""
        self.make_files(command)
        if command.startswith("@"):
            name = command[1:]
            with self.here():
                return Result(command, 0, self.producers[name](self))
        words = shlex.split(command, comments=True)
        if words and Path(words[0]).name == "fm2uav" and not _shell(command):
            if words[1:2] == ["app"]:
                return self._serve(command, words)
            return self._cli(command, words[1:], wide)
        if words[:1] == ["make"]:
            return self._make(command, words[1:])
        res = subprocess.run(["bash", "-c", command], cwd=self.path, env=self.env,
                             capture_output=True, text=True, timeout=900)
        return Result(command, res.returncode, res.stdout + res.stderr)

    def _cli(self, command: str, args: list[str], wide: bool) -> Result:
        from typer.testing import CliRunner

        from fm2uav.cli import app

        out = _option(args, "--out")
        with self.here():
            if out is not None and not wide:
                key = _without(args, "--out")
                target = self.path / out
                if not (args[:1] == ["sweep"] and self.linked.get(target, key) != key):
                    run = self.cli_once(key)
                    if not target.exists() and not target.is_symlink():
                        target.parent.mkdir(parents=True, exist_ok=True)
                        target.symlink_to(run.out)
                        self.linked[target] = key
                    return Result(command, run.result.exit_code, run.result.output, target)
                # a sweep into the folder another sweep filled resumes it, as the reader's
                # does (docs/sweeps.md): in a copy, the shared run's folder stays as it was made
                shared = target.resolve()
                target.unlink()
                shutil.copytree(shared, target)
                del self.linked[target]
            res = CliRunner(env=WIDE).invoke(app, args)
        text = res.output
        if res.exception is not None and not isinstance(res.exception, SystemExit):
            text += f"\n{type(res.exception).__name__}: {res.exception}"
        return Result(command, res.exit_code, text, self.path / out if out else None)

    def _serve(self, command: str, words: list[str]) -> Result:
        """``fm2uav app``: started as the user starts it (on a free port), its page and
        session read, then stopped with Ctrl-C; exit 0 and both answers are the result."""
        exe = words[0] if "/" in words[0] else str(self.bin / "fm2uav")
        proc = subprocess.Popen([exe, *words[1:], "--port", "0"], cwd=self.path, env=self.env,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        lines = []
        try:
            for _ in range(200):
                line = proc.stdout.readline()
                if not line:
                    break
                lines.append(line)
                url = re.search(r"http://127\.0\.0\.1:\d+/", line)
                if url:
                    page = urllib.request.urlopen(url.group(0), timeout=60).read().decode()
                    session = json.load(urllib.request.urlopen(url.group(0) + "api/session",
                                                               timeout=60))
                    lines.append(f"page: {len(page)} characters, <title> "
                                 f"{'<title>' in page}; session: {sorted(session)}\n")
                    break
        finally:
            proc.send_signal(signal.SIGINT)
            try:
                rest, _ = proc.communicate(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                rest, _ = proc.communicate()
        ok = proc.returncode == 0 and any(ln.startswith("page:") for ln in lines)
        return Result(command, 0 if ok else (proc.returncode or 1), "".join(lines) + rest)

    def _make(self, command: str, args: list[str]) -> Result:
        """``make TARGET``: the Makefile's own recipe, run in the repository with its outputs
        in the workspace (``OUT``), in the environment running the tests (``VENV``) and the
        install step taken as done (``-o`` the stamp)."""
        venv = Path(sys.prefix)
        res = subprocess.run(["make", "-o", str(venv / ".installed-stamp"), *args,
                              f"VENV={venv}", f"OUT={self.path / 'out'}"], cwd=ROOT,
                             env=self.env, capture_output=True, text=True, timeout=900)
        return Result(command, res.returncode, res.stdout + res.stderr)


def _shell(command: str) -> bool:
    """Whether the command needs a shell (pipes, redirections, several commands)."""
    return bool(re.search(r"[|;&<>]|\$\(", command.split(" #", 1)[0]))


def _option(args: list[str], name: str) -> str | None:
    for i, a in enumerate(args):
        if a == name and i + 1 < len(args):
            return args[i + 1]
        if a.startswith(name + "="):
            return a.split("=", 1)[1]
    return None


def _without(args: list[str], name: str) -> list[str]:
    out, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a == name:
            skip = True
            continue
        if a.startswith(name + "="):
            continue
        out.append(a)
    return out


def with_markers(command: str, block: Block) -> str | None:
    """The command as the block's markers run it (None: skipped)."""
    if any(m.text == "" for m in block.marked("skip")):
        return None
    if any(m.text and m.text in command for m in block.marked("skip")):
        return None
    for m in block.marked("with"):
        if m.text in command:
            head, sep, comment = command.partition(" #")
            command = f"{_overridden(head.rstrip(), m.args)} {m.args}" + (
                f" #{comment}" if sep else "")
    return command


def _overridden(command: str, args: str) -> str:
    """``command`` without the ``--option value`` pairs that ``args`` gives again (the last
    one wins on the command line; dropping the first lets equal runs share one session run)."""
    given = {a for a in shlex.split(args) if a.startswith("--")}
    words, out, i = command.split(), [], 0
    while i < len(words):
        if words[i] in given:
            i += 2 if i + 1 < len(words) and not words[i + 1].startswith("--") else 1
            continue
        out.append(words[i])
        i += 1
    return " ".join(out)


# ---------------------------------------------------------------------------- python blocks
_MEASURE = re.compile(r"\d+\.\d+|\b\d+\s*(?:m|s|ms|km|min|%|°|deg|m/s)\b")
_ARROW = re.compile(r"#\s*(?:→|->)\s*(?P<claim>.*)$")


def _claims(text: str) -> list[Any]:
    """The values an arrow comment states: numbers, True/False/None, quoted strings (up to
    the first opening parenthesis that is not part of a quoted string)."""
    out: list[Any] = []
    pos = 0
    pat = re.compile(r"""\s*(?:≈|~)?\s*(?P<tok>'[^']*'|"[^"]*"|True|False|None"""
                     r"""|[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?)\s*(?:[a-zA-Z%°/²³]+)?\s*,?""")
    while pos < len(text):
        if text[pos] == "(":  # an explanation follows
            break
        m = pat.match(text, pos)
        if not m:
            if text[pos] in " ,[]":
                pos += 1
                continue
            break
        tok = m.group("tok")
        out.append(ast.literal_eval(tok) if tok[0] in "'\"" or tok in ("True", "False", "None")
                   else float(tok) if any(c in tok for c in ".e") else int(tok))
        pos = m.end()
    return out


def _flatten(value: Any) -> list[Any]:
    import numpy as np

    if isinstance(value, (str, bool, type(None))):
        return [value]
    if isinstance(value, (int, float, np.integer, np.floating, np.bool_)):
        return [value.item() if hasattr(value, "item") else value]
    if isinstance(value, np.ndarray):
        return [v.item() for v in value.ravel()]
    if isinstance(value, (tuple, list)):
        return [x for v in value for x in _flatten(v)]
    return [value]


def _digits(tok: float | int) -> int:
    s = repr(tok)
    return len(s.split(".", 1)[1]) if "." in s and "e" not in s else 0


def check_claim(value: Any, claim: str, where: str) -> None:
    """Assert that ``value`` is what the arrow comment ``claim`` states."""
    want = _claims(claim)
    got = _flatten(value)
    if not want:
        raise AssertionError(f"{where}: '→ {claim}' states no value (numbers, True/False/None, "
                             "'text')")
    if len(got) < len(want):
        raise AssertionError(f"{where}: '→ {claim}' states {len(want)} values, the code gives "
                             f"{got!r}")
    for w, g in zip(want, got):
        if isinstance(w, (bool, str)) or w is None:
            ok = g == w if not isinstance(w, str) else str(g) == w
        else:
            tol = 0.5 * 10 ** -_digits(w) + 1e-12 * abs(w)
            ok = isinstance(g, (int, float)) and not isinstance(g, bool) and abs(g - w) <= tol
        if not ok:
            raise AssertionError(f"{where}: the doc says {w!r}, the code gives {g!r} "
                                 f"(whole value {value!r})")


def run_python(body: str, namespace: dict, where: str) -> str:
    """Run one python block statement by statement (module docstring); returns its stdout."""
    tree = ast.parse(body)
    lines = body.splitlines()
    out = io.StringIO()
    for node in tree.body:
        last = lines[node.end_lineno - 1]
        comment = last[last.index("#"):] if "#" in last and _code_part(last) != last else ""
        here = f"{where}+{node.lineno}"
        is_print = (isinstance(node, ast.Expr) and isinstance(node.value, ast.Call)
                    and isinstance(node.value.func, ast.Name) and node.value.func.id == "print")
        arrow = _ARROW.search(comment) if comment else None
        with contextlib.redirect_stdout(out):
            if isinstance(node, ast.Expr) and not is_print:
                value = eval(compile(ast.Expression(node.value), here, "eval"), namespace)
            else:
                start = out.tell()
                exec(compile(ast.Module([node], []), here, "exec"), namespace)
                value = out.getvalue()[start:].strip()
        if isinstance(node, ast.Expr) and comment:
            if arrow and is_print:  # the printed numbers (and True/False/None)
                check_claim(_printed(value), arrow.group("claim"), here)
            elif arrow:
                check_claim(value, arrow.group("claim"), here)
            elif _MEASURE.search(comment):
                raise AssertionError(f"{here}: the comment {comment!r} shows a number no one "
                                     "checks; write it as '# → value' (checked against the "
                                     "run) or drop it")
    return out.getvalue()


def _printed(text: str) -> list[Any]:
    """The numbers, True/False/None and nothing else of printed text, in order."""
    toks = re.findall(r"True|False|None|nan|[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text)
    return [{"True": True, "False": False, "None": None, "nan": float("nan")}[t]
            if t in ("True", "False", "None", "nan")
            else float(t) if any(c in t for c in ".e") else int(t) for t in toks]


def _code_part(line: str) -> str:
    """The line without its comment (a '#' inside a string literal is kept)."""
    try:
        import tokenize

        toks = list(tokenize.generate_tokens(io.StringIO(line + "\n").readline))
        for t in toks:
            if t.type == tokenize.COMMENT:
                return line[:t.start[1]]
    except (SyntaxError, tokenize.TokenError):
        pass
    return line


# ---------------------------------------------------------------------------- other blocks
MISSION_KEYS = {"version", "name", "description", "world", "start", "goal", "via", "return",
                "planner", "airframe", "outputs", "no_fly_zones", "operating_area"}


def check_yaml(body: str, ws: Workspace, where: str) -> None:
    import yaml

    from fm2uav.io.mission import parse_mission

    doc = yaml.safe_load(body)
    if isinstance(doc, dict) and set(doc) <= MISSION_KEYS:
        full = {"world": {"scenario": "open-field"}, **doc}
        if "world" in doc and not (doc["world"].keys() & {"scenario", "dem", "buildings"}):
            full["world"] = {"scenario": "open-field", **doc["world"]}
        full.setdefault("start", [100.0, 100.0, 150.0])
        full.setdefault("goal", [1500.0, 1200.0, 150.0])
        ws.make_files(body)
        with ws.here():
            parse_mission(full, source=where)


def text_lines_found(body: str, output: str) -> list[str]:
    """The lines of a quoted-output block that no line of ``output`` matches."""
    printed = [" ".join(ln.split()) for ln in output.splitlines()]
    missing = []
    for ln in body.splitlines():
        want = " ".join(ln.split())
        if not want:
            continue
        pat = re.compile(".*?".join(re.escape(p) for p in want.split("...")))
        if not any(pat.fullmatch(p) for p in printed):
            missing.append(ln)
    return missing


# ---------------------------------------------------------------------------- a whole run
@dataclass
class BlockResult:
    block: Block
    problems: list[str] = field(default_factory=list)
    results: list[Result] = field(default_factory=list)
    seconds: float = 0.0


def run_docs(ws: Workspace, docs: list[Path] = DOCS) -> dict[str, BlockResult]:
    """Run every block of ``docs`` in order in ``ws``; the outcome of each by block id."""
    every = [b for d in docs for b in blocks(d)]
    for b in every:  # data blocks first: a command may read a file shown further down
        for m in b.marked("file"):
            (ws.path / m.text).parent.mkdir(parents=True, exist_ok=True)
            (ws.path / m.text).write_text(b.body, encoding="utf-8")
    done: dict[str, BlockResult] = {}
    namespaces: dict[Path, dict] = {}
    for b in every:
        r = done[b.id] = BlockResult(b)
        t0 = time.perf_counter()
        try:
            _run_block(b, ws, namespaces.setdefault(b.doc, {"__name__": "__doc__"}), r)
        except Exception as exc:  # the message is the point
            r.problems.append(f"{type(exc).__name__}: {exc}")
        r.seconds = time.perf_counter() - t0
        if os.environ.get("DOCS_RUN_VERBOSE"):
            print(f"{b.id}: {r.seconds:.1f} s, {len(r.problems)} problem(s)", file=sys.__stderr__)
    return done


def runs_by_out(runs: dict[str, BlockResult], doc: Path) -> dict[str, Result]:
    """The commands of ``doc``'s bash blocks as :func:`run_docs` made them, by the output folder
    they name (``--out out/sorties`` -> ``"out/sorties"``; :attr:`Result.out` is that folder in
    the workspace)."""
    found = {}
    for r in runs.values():
        if r.block.doc != doc or r.block.kind != "bash":
            continue
        for res in r.results:
            out = _option(shlex.split(res.command, comments=True), "--out")
            if out is not None:
                found[out] = res
    return found


def _run_block(b: Block, ws: Workspace, namespace: dict, r: BlockResult) -> None:
    if b.marked("skip") and not b.marked("skip")[0].text:
        return
    kind = b.kind
    if kind == "bash":
        for cmd in commands(b.body):
            c = with_markers(cmd, b)
            if c is None:
                continue
            res = ws.run(c)
            r.results.append(res)
            if res.code != 0:
                r.problems.append(f"`{c}` exited {res.code}:\n{res.output[-3000:]}")
    elif kind == "python":
        ws.make_files(b.body)
        with ws.here():
            run_python(b.body, namespace, b.id)
    elif kind == "yaml":
        if not b.marked("file"):
            check_yaml(b.body, ws, b.id)
        else:
            import yaml

            yaml.safe_load(b.body)
    elif kind == "json":
        json.loads(b.body)
    elif kind == "text":
        outputs = [ws.run(m.text, wide=True) for m in b.marked("output")]
        if not outputs:
            r.problems.append("a quoted output (text block) needs an output marker naming the "
                              "command that prints it (tests/README.md, Docs that run)")
            return
        r.results += outputs
        missing = text_lines_found(b.body, "\n".join(o.output for o in outputs))
        if missing:
            r.problems.append("not printed by " + ", ".join(repr(o.command) for o in outputs)
                              + ":\n" + "\n".join(missing) + "\n--- printed:\n"
                              + "\n".join(o.output for o in outputs)[-4000:])
    else:
        r.problems.append(f"a block in {b.lang!r}: give it one of "
                          f"{', '.join(sorted(LANGS))} (or a skip marker with the reason)")
