"""Run every benchmark module (``benchmarks/bench_*.py``) and write one JSON report.

Usage::

    python -m benchmarks.run            # full run (make bench)
    python -m benchmarks.run --quick    # seconds, for smoke tests
    python -m benchmarks.run core       # only bench_core.py

Each module exposes ``run(quick: bool = False) -> list[dict]``; a row has at
least ``benchmark``, ``case`` and ``ours_s`` (median seconds), and, against a
peer measured in the same run, ``peer``, ``peer_s`` and ``ratio`` (peer/ours).
Speed is reported, never asserted: the bars of the issues are printed next to
the numbers so a reader sees whether they hold on this machine.

A full run of every module (no names, no ``--quick``, no failure) also writes
its table into docs/performance.md and a summary into README.md, between the
markers ``<!-- bench:NAME (make bench) -->`` and ``<!-- /bench:NAME -->``
(``--no-docs`` leaves them alone): those numbers are never typed by hand.
"""

from __future__ import annotations

import argparse
import datetime
import importlib
import json
import os
import platform
import re
import sys
import time
import traceback
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def discover(names: list[str] | None = None) -> list[Path]:
    """Benchmark modules, optionally filtered by the part after ``bench_``."""
    files = sorted(HERE.glob("bench_*.py"))
    if names:
        files = [f for f in files if f.stem.removeprefix("bench_") in names]
    return files


def load(path: Path):
    """Import ``benchmarks/<name>.py`` as ``benchmarks.<name>``."""
    return importlib.import_module(f"{__package__ or 'benchmarks'}.{path.stem}")


def fmt(value, digits=3) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}g}" if abs(value) < 1000 else f"{value:.0f}"
    return str(value)


def print_table(rows: list[dict]) -> None:
    cols = ["benchmark", "case", "ours_s", "peer", "peer_s", "ratio", "peak_mb", "bar", "notes"]
    table = [[fmt(r.get(c)) for c in cols] for r in rows]
    widths = [max(len(c), *(len(t[i]) for t in table)) if table else len(c) for i, c in enumerate(cols)]
    line = "  ".join(c.ljust(w) for c, w in zip(cols, widths))
    print(line)
    print("-" * len(line))
    for t in table:
        print("  ".join(v.ljust(w) for v, w in zip(t, widths)))


# ------------------------------------------------------------------ docs blocks
def marker(name: str) -> tuple[str, str]:
    """Opening and closing marker of the bench block ``name``."""
    return f"<!-- bench:{name} (make bench) -->", f"<!-- /bench:{name} -->"


def fill(text: str, name: str, body: str) -> str:
    """``text`` with the bench block ``name`` replaced by ``body``.

    Raises
    ------
    ValueError
        The page has no such block (both markers, in order).
    """
    start, end = marker(name)
    pattern = re.compile(re.escape(start) + r"\n.*?" + re.escape(end), re.S)
    if not pattern.search(text):
        raise ValueError(f"no block {start} ... {end} in the page")
    return pattern.sub(lambda m: f"{start}\n{body.rstrip()}\n{end}", text, count=1)


def _seconds(x) -> str:
    if x is None:
        return ""
    return f"{x * 1e3:.3g} ms" if x < 0.1 else f"{fmt(x)} s"


def cpu_model() -> str:
    """The processor's model name (``/proc/cpuinfo``; else ``platform.processor()``, maybe
    empty): ratios against the peers move with it (session 28: 13-33 % between an AMD EPYC
    and an Intel Xeon host)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def _cpu(m: dict) -> str:
    """`` (the CPU model)`` for a run's header, empty when the report has none."""
    return f" ({m['cpu']})" if m.get("cpu") else ""


def markdown_table(rows: list[dict], report: dict) -> str:
    """The whole run as one markdown table, with the machine and its load."""
    m = report["machine"]
    lines = [
        f"Run of {m['date']}: Python {m['python']}, {m['cpus']} CPUs{_cpu(m)}, load average "
        f"{m['load_before']:.1f} before / {m['load_after']:.1f} after the run "
        f"({'machine otherwise idle' if max(m['load_before'], m['load_after']) < 1.5 else 'machine shared with other jobs: wall times are inflated'}).",
        "",
        "| benchmark | case | ours | peer | peer time | ratio (peer/ours) | peak MB ours / peer | bar | notes |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        peak = fmt(r.get("peak_mb"), 3) if r.get("peak_mb") is not None else ""
        if r.get("peer_peak_mb") is not None:
            peak += f" / {fmt(r['peer_peak_mb'], 3)}"
        ratio = f"{r['ratio']:.2f}×" if r.get("ratio") else ""
        cells = [r["benchmark"], r["case"], _seconds(r.get("ours_s")), r.get("peer") or "",
                 _seconds(r.get("peer_s")), ratio, peak, r.get("bar") or "",
                 str(r.get("notes") or "")]
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(lines)


def _span(values: list[float]) -> str:
    lo, hi = min(values), max(values)
    return f"{lo:.2f}×" if f"{lo:.2f}" == f"{hi:.2f}" else f"{lo:.2f}–{hi:.2f}×"


def summary(rows: list[dict], report: dict) -> str:
    """The README's performance paragraph, from the rows of a full run."""
    m = report["machine"]
    parts = [f"`make bench` of {m['date']} on this {m['cpus']}-core machine{_cpu(m)} (load average "
             f"{max(m['load_before'], m['load_after']):.1f}; table and method in "
             "`docs/performance.md`):"]
    fmm = [r for r in rows if r["benchmark"] == "fmm" and r.get("ratio")
           and "FM²" not in r["case"]]
    for peer in ("scikit-fmm", "eikonalfm", "eikonalfm factored"):
        ratios = [r["ratio"] for r in fmm if r["peer"] == peer]
        if ratios:
            parts.append(f"FMM {_span(ratios)} faster than {peer};")
    sizes = sorted({r["case"].split(" ")[0] for r in fmm})
    if sizes:
        parts[-1] = parts[-1].rstrip(";") + f" ({', '.join(sizes)}, order 1 and 2);"
    shaped = [r["ratio"] for r in rows if r["benchmark"] == "fmm" and "FM²" in r["case"]]
    if shaped:
        parts.append(f"{_span(shaped)} on FM²-shaped maps (obstacles, W from 0 at the walls);")
    by_case = {r["case"]: r for r in rows}
    warm_plan = next((r for r in rows if r["benchmark"] == "plan"
                      and r["case"].startswith("open field") and "cached" in r["case"]), None)
    if warm_plan:
        parts.append(f"an FM² plan on the open field in {_seconds(warm_plan['ours_s'])};")
    for r in rows:
        if r["benchmark"] == "plan" and (r["case"].startswith("terrain") or (
                r["case"].startswith("regional ") and not r["case"].startswith("regional vs"))):
            peak = f", peak {r['peak_mb'] / 1024:.2f} GB" if r.get("peak_mb") else ""
            parts.append(f"{r['case']}: {_seconds(r['ours_s'])}{peak};")
    cli = {r["case"].split("`")[1]: r for r in rows if r["benchmark"] == "cli" and "`" in r["case"]}
    if "fm2uav --help" in cli:
        parts.append("`fm2uav --help` answers in " + _seconds(cli["fm2uav --help"]["ours_s"])
                     + "".join(f", `{k}` in {_seconds(r['ours_s'])}" for k, r in cli.items()
                               if k != "fm2uav --help")
                     + " (warm, CPU " + "/".join(f"{r['cpu_s']:.2f}" for r in cli.values())
                     + " s);")
    cold = by_case.get("first `fm2uav plan`, empty numba cache")

    warm = by_case.get("first `fm2uav plan`, numba cache filled")
    if cold and warm:
        parts.append(
            f"the first `fm2uav plan` after a fresh install takes {_seconds(cold['ours_s'])} "
            f"(numba compiles the kernels once, the notice shows after "
            f"{_seconds(cold['first_output_s'])}), every later one {_seconds(warm['ours_s'])}.")
    text = " ".join(parts)
    return text.rstrip(";") + ("" if text.endswith(".") else ".")


def write_docs(rows: list[dict], report: dict, root: Path = ROOT) -> list[Path]:
    """Write the table into docs/performance.md and the summary into README.md."""
    pages = [(root / "docs" / "performance.md", "table", markdown_table(rows, report)),
             (root / "README.md", "summary", summary(rows, report))]
    for path, name, body in pages:
        path.write_text(fill(path.read_text(), name, body))
    return [p for p, _, _ in pages]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("only", nargs="*", help="benchmark names (e.g. core coverage)")
    ap.add_argument("--quick", action="store_true", help="tiny sizes, seconds")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "bench.json")
    ap.add_argument("--no-docs", action="store_true",
                    help="do not write docs/performance.md and README.md (full runs write them)")
    args = ap.parse_args(argv)
    load_before = os.getloadavg()[0]

    rows: list[dict] = []
    failures = 0
    for path in discover(args.only):
        t0 = time.perf_counter()
        print(f"== {path.stem} ...", flush=True)
        try:
            module_rows = load(path).run(quick=args.quick)
        except Exception:  # report and go on: one broken benchmark must not hide the others
            failures += 1
            traceback.print_exc()
            module_rows = [{"benchmark": path.stem, "case": "FAILED", "ours_s": None}]
        rows.extend(module_rows)
        print(f"   done in {time.perf_counter() - t0:.1f} s", flush=True)
    print()
    print_table(rows)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    report = {
        "machine": {"python": sys.version.split()[0], "platform": platform.platform(),
                    "processor": platform.processor(), "cpu": cpu_model(),
                    "cpus": os.cpu_count(),
                    "date": datetime.date.today().isoformat(),
                    "load_before": load_before, "load_after": os.getloadavg()[0]},
        "quick": args.quick,
        "rows": rows,
    }
    args.out.write_text(json.dumps(report, indent=2))
    print(f"\nwritten {args.out}")
    if not (args.quick or args.only or failures or args.no_docs):
        for path in write_docs(rows, report):
            print(f"written {path}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
