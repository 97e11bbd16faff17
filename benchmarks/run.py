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
"""

from __future__ import annotations

import argparse
import importlib
import json
import platform
import sys
import time
import traceback
from pathlib import Path

HERE = Path(__file__).resolve().parent


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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("only", nargs="*", help="benchmark names (e.g. core coverage)")
    ap.add_argument("--quick", action="store_true", help="tiny sizes, seconds")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "bench.json")
    args = ap.parse_args(argv)

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
                    "processor": platform.processor()},
        "quick": args.quick,
        "rows": rows,
    }
    args.out.write_text(json.dumps(report, indent=2))
    print(f"\nwritten {args.out}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
