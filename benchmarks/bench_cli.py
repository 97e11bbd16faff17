"""An instant command line (issue 27 deliverable 4): help pages and one-line errors, warm.

Each case starts the installed ``fm2uav`` console script (``python -m fm2uav`` where there
is none) as a user's shell does, several times after one untimed run (the ``.pyc`` files
and the OS file cache warm), and records the median wall time and the median CPU time of
the process (user + system, from the OS accounting of the child: what the command costs
the machine, whatever the load). Cases:

* ``fm2uav --help`` and ``fm2uav plan --help`` (the largest help page, 50+ options);
* ``fm2uav plan --bogus``: a bad flag, refused by the parser;
* ``fm2uav run missing.yaml``: a one-line input error found by the command itself.

The peer in the same run is the floor of the framework: a one-command typer app (same
typer and rich, same rich help) asked for its help / given a bad flag; ratio = its time /
ours. Bar: each <= 0.3 s warm. The import checks that keep these numbers low (no numba,
scipy, matplotlib... on these paths) are tests: tests/cli/test_init.py.
"""

from __future__ import annotations

import os
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


def timed(cmd: list[str], repeats: int) -> dict:
    """Median wall and CPU seconds of ``cmd`` over ``repeats`` runs after one untimed run."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["COLUMNS"] = "100"  # the .pyc files are written by the untimed run, as for a user
    walls, cpus, codes = [], [], set()
    for k in range(repeats + 1):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        res = subprocess.run(cmd, capture_output=True, env=env, timeout=300)
        wall = time.perf_counter() - t
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        codes.add(res.returncode)
        if k:  # the first run warms the caches
            walls.append(wall)
            cpus.append((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime))
    return {"s": statistics.median(walls), "cpu_s": statistics.median(cpus),
            "codes": sorted(codes)}


def run(quick: bool = False) -> list[dict]:
    repeats = 1 if quick else 9
    with tempfile.TemporaryDirectory(prefix="fm2uav-bench-cli-") as tmp:
        peer = Path(tmp) / "peer_app.py"
        peer.write_text(PEER_APP)
        peer_cmd = [sys.executable, str(peer)]
        cases = [
            ("`fm2uav --help`", ["--help"], peer_cmd + ["--help"], [0]),
            ("`fm2uav plan --help`", ["plan", "--help"], peer_cmd + ["main", "--help"], [0]),
            ("`fm2uav plan --bogus` (a bad flag)", ["plan", "--bogus"],
             peer_cmd + ["main", "--bogus"], [2]),
            ("`fm2uav run missing.yaml` (a missing mission file)",
             ["run", str(Path(tmp) / "missing.yaml")], None, [2]),
        ]
        rows = []
        for case, args, peer_args, codes in cases:
            ours = timed(_fm2uav() + args, repeats)
            if ours["codes"] != codes:
                raise RuntimeError(f"fm2uav {' '.join(args)} exited {ours['codes']}, "
                                   f"expected {codes}")
            row = {"benchmark": "cli", "case": case, "ours_s": ours["s"],
                   "cpu_s": ours["cpu_s"], "bar": f"<= {BAR_S:g} s warm",
                   "notes": f"CPU {ours['cpu_s']:.2f} s (median of {repeats} runs)"}
            if peer_args is not None:
                theirs = timed(peer_args, repeats)
                row.update(peer="one-command typer app (framework floor)",
                           peer_s=theirs["s"], ratio=theirs["s"] / ours["s"])
                row["notes"] += f"; peer CPU {theirs['cpu_s']:.2f} s"
            rows.append(row)
    return rows


if __name__ == "__main__":
    from benchmarks.run import print_table

    print_table(run(quick="--quick" in sys.argv))
