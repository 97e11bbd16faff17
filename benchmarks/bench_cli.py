"""An instant command line (issue 27 deliverable 4): help pages and one-line errors, warm.

Each case starts the installed ``fm2uav`` console script (``python -m fm2uav`` where there
is none) as a user's shell does, several times after one untimed run (the ``.pyc`` files
and the OS file cache warm, and the code of the source text the imports generate kept:
``fm2uav._code_cache``, in the run's own cache folder), and records the median wall time
and the median CPU time of the process (user + system, from the OS accounting of the
child: what the command costs the machine, whatever the load). Cases:

* ``fm2uav --help`` and ``fm2uav plan --help`` (the largest help page, 50+ options): the
  page kept from the untimed run (``fm2uav._help_cache``, in a cache of the run's own), and
  rendered by typer and rich (``FM2UAV_HELP_CACHE=0``) in the notes;
* ``fm2uav plan --bogus``: a bad flag, refused by the parser;
* ``fm2uav run missing.yaml``: a one-line input error found by the command itself;
* ``fm2uav run bad.yaml``: a mission file with one field out of range, refused by its
  schema (pydantic and yaml load; numpy, the world's builders, the kernels and the
  geodata libraries do not);
* ``fm2uav plan --threads 0`` and ``fm2uav plan --start 1,2``: a bad value of a planner flag
  and of a point, found by the command before the library loads.

Output goes to a pipe (as under ``| less``); the help pages are timed in a terminal too
(a pseudo-terminal: rich's colours, the notes' "tty CPU"), which renders the same page.
The peer in the same run is the floor of the framework: a one-command typer app (same
typer and rich, same rich help) asked for its help / given a bad flag; ratio = its time /
ours. Bar: each <= 0.3 s warm. What keeps fm2uav under the framework's own floor: only the
invoked command is built (``fm2uav.cli._lazy``), typer's pydantic coercion only where a
value needs it (``_coerce``), its renderer without rich.markdown / rich.traceback
(``_rich_light``), no numba, scipy, matplotlib... on these paths (tests/cli/test_init.py,
test_lazy.py, test_rich_light.py check the imports, never the seconds).
"""

from __future__ import annotations

import os
import pty
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BAR_S = 0.3

PEER_APP = '''
import typer

app = typer.Typer(help="One command.", add_completion=False, rich_markup_mode="rich")


@app.command()
def main(x: int = typer.Option(0, help="A number.")) -> None:
    """Print x."""
    print(x)


@app.command()
def other() -> None:
    """Nothing."""


app()
'''


def _fm2uav() -> list[str]:
    script = Path(sys.executable).with_name("fm2uav")
    return [str(script)] if script.exists() else [sys.executable, "-m", "fm2uav"]


def _in_terminal(cmd: list[str], env: dict) -> int:
    """Run ``cmd`` with stdout and stderr on a pseudo-terminal (read to the end); its exit code."""
    main, sub = pty.openpty()
    try:
        proc = subprocess.Popen(cmd, stdout=sub, stderr=sub, env={**env, "TERM": "xterm-256color"})
        os.close(sub)
        sub = -1
        while True:
            try:
                if not os.read(main, 65536):
                    break
            except OSError:  # EIO: the terminal's other side closed
                break
        return proc.wait(timeout=300)
    finally:
        os.close(main)
        if sub >= 0:
            os.close(sub)


def timed(cmd: list[str], repeats: int, *, tty: bool = False, warm_up: bool = True,
          env: dict | None = None) -> dict:
    """Median wall and CPU seconds of ``cmd`` over ``repeats`` runs after one untimed run
    (output to a pipe, or with ``tty`` to a pseudo-terminal). ``warm_up=False`` leaves the
    untimed run out (``--quick``, the smoke test: every run's exit code is still checked, the
    seconds are not worth reporting). ``env``: variables set for the runs."""
    env = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"},
           **(env or {})}
    env["COLUMNS"] = "100"  # the .pyc files are written by the untimed run, as for a user
    walls, cpus, codes = [], [], set()
    first = 0 if warm_up else 1
    for k in range(first, repeats + 1):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        if tty:
            code = _in_terminal(cmd, env)
        else:
            code = subprocess.run(cmd, capture_output=True, env=env, timeout=300).returncode
        wall = time.perf_counter() - t
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        codes.add(code)
        if k:  # the first run warms the caches
            walls.append(wall)
            cpus.append((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime))
    return {"s": statistics.median(walls), "cpu_s": statistics.median(cpus),
            "codes": sorted(codes)}


def run(quick: bool = False) -> list[dict]:
    repeats = 1 if quick else 9
    warm_up = not quick  # quick: one run of each command (its exit code checked), no warm-up
    with tempfile.TemporaryDirectory(prefix="fm2uav-bench-cli-") as tmp:
        peer = Path(tmp) / "peer_app.py"
        peer.write_text(PEER_APP)
        peer_cmd = [sys.executable, str(peer)]
        # help pages kept in a cache of this run's own (fm2uav._help_cache): the untimed run
        # renders and keeps each page, the timed runs copy it — a warm page, as for a user
        # after the first; the rendering itself is timed too (FM2UAV_HELP_CACHE=0)
        kept = {"FM2UAV_CACHE_DIR": str(Path(tmp) / "cache")}
        bad = Path(tmp) / "bad.yaml"
        bad.write_text("world: {scenario: open-field}\nplanner: {saturation: 1.5}\n")
        cases = [
            ("`fm2uav --help`", ["--help"], peer_cmd + ["--help"], [0]),
            ("`fm2uav plan --help`", ["plan", "--help"], peer_cmd + ["main", "--help"], [0]),
            ("`fm2uav plan --bogus` (a bad flag)", ["plan", "--bogus"],
             peer_cmd + ["main", "--bogus"], [2]),
            ("`fm2uav run missing.yaml` (a missing mission file)",
             ["run", str(Path(tmp) / "missing.yaml")], None, [2]),
            ("`fm2uav run bad.yaml` (one bad field in a mission file)",
             ["run", str(bad), "--out", str(Path(tmp) / "out")], None, [2]),
            ("`fm2uav plan --threads 0` (a bad flag value)",
             ["plan", "--threads", "0", "--out", str(Path(tmp) / "out")], None, [2]),
            ("`fm2uav plan --start 1,2` (a bad point)",
             ["plan", "--start", "1,2", "--out", str(Path(tmp) / "out")], None, [2]),
        ]
        rows = []
        for case, args, peer_args, codes in cases:
            ours = timed(_fm2uav() + args, repeats, warm_up=warm_up, env=kept)
            if ours["codes"] != codes:
                raise RuntimeError(f"fm2uav {' '.join(args)} exited {ours['codes']}, "
                                   f"expected {codes}")
            row = {"benchmark": "cli", "case": case, "ours_s": ours["s"],
                   "cpu_s": ours["cpu_s"], "bar": f"<= {BAR_S:g} s warm",
                   "notes": f"CPU {ours['cpu_s']:.2f} s (median of {repeats} runs)"}
            if "--help" in args:  # the page as a user sees it: rich's colours on a terminal
                tty = timed(_fm2uav() + args, repeats, tty=True, warm_up=warm_up, env=kept)
                drawn = timed(_fm2uav() + args, repeats, warm_up=warm_up,
                              env={"FM2UAV_HELP_CACHE": "0"})
                row.update(tty_s=tty["s"], tty_cpu_s=tty["cpu_s"], rendered_s=drawn["s"],
                           rendered_cpu_s=drawn["cpu_s"])
                row["notes"] += (f"; in a terminal {tty['s']:.3f} s, CPU {tty['cpu_s']:.2f} s; "
                                 f"rendered (no kept page) {drawn['s']:.3f} s, "
                                 f"CPU {drawn['cpu_s']:.2f} s")
            if peer_args is not None:
                theirs = timed(peer_args, repeats, warm_up=warm_up)
                row.update(peer="one-command typer app (framework floor)",
                           peer_s=theirs["s"], ratio=theirs["s"] / ours["s"])
                row["notes"] += f"; peer CPU {theirs['cpu_s']:.2f} s"
            rows.append(row)
    return rows


if __name__ == "__main__":
    from benchmarks.run import print_table

    print_table(run(quick="--quick" in sys.argv))
