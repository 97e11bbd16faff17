"""The parallel march under settings of ``fm2uav.eikonal._tuning``, alternating in one process (issue 27).

Each setting is a JSON object of ``_tuning`` names and values (a dict's keys as Python
literals, its other keys kept: ``{"SOURCE_CUT_ROWS": {"(2, 2)": 32}}``; ``{}`` the defaults).
One process marches the case on one thread, then on two threads under each setting in turn,
round after round (a change of the machine's load hits them alike; the settings are read at
each march, no kernel is compiled again)::

    python -m benchmarks.tuning_ab --case 2048x2048:fm2:2 --repeats 9 \\
        '{}' '{"SOURCE_CUT_ROWS": {"(2, 2)": 32}}' [--profile]

A case is ``threads_march``'s (``SHAPE:FIELD[:2]``, ``fm2@SEED`` another seed). Prints the
serial march's median wall time, then a row per setting: the median wall time on two threads,
one thread over it, the slabs, windows, nodes re-opened and the windows' balance of its last
march, and whether its times equal the serial march's bit for bit. ``--profile`` turns on
the drive's profile (``_parallel.PROFILE``: its clock reads cost a few per cent) and adds the
medians of its windows' and exchanges' wall time, the sums over windows of their busiest
thread's CPU, and the windows' CPU of each thread [ms]. Not part of ``make bench``;
docs/performance.md quotes it.
"""

from __future__ import annotations

import argparse
import ast
import json
import statistics
import time

import numpy as np


def _setting(text: str) -> dict:
    """A setting from its JSON text: names of ``_tuning``, a dict's keys read as literals."""
    from fm2uav.eikonal import _tuning

    raw = json.loads(text)
    if not isinstance(raw, dict):
        raise SystemExit(f"a setting is a JSON object, not {text!r}")
    out = {}
    for name, value in raw.items():
        if not hasattr(_tuning, name):
            raise SystemExit(f"_tuning has no {name!r} (setting {text!r})")
        current = getattr(_tuning, name)
        if isinstance(current, dict):
            merged = dict(current)
            merged.update({ast.literal_eval(k): v for k, v in value.items()})
            value = merged
        out[name] = value
    return out


def _case(text: str):
    """``(speed, source, order)`` of a case ``SHAPE:FIELD[:ORDER]``."""
    from benchmarks import fields

    parts = text.split(":")
    shape = tuple(int(n) for n in parts[0].split("x"))
    field = parts[1] if len(parts) > 1 else "fm2"
    order = int(parts[2]) if len(parts) > 2 else 1
    if field.startswith("fm2"):
        v, src = fields.fm2_shaped(shape, seed=int(field.partition("@")[2] or 0))
    elif field == "smooth":
        v, src = fields.smooth(shape)
    elif field == "constant":
        v, src = np.ones(shape), tuple(n // 2 for n in shape)
    else:
        raise SystemExit(f"unknown field {field!r} in case {text!r}")
    return v, src, order


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("settings", nargs="+", help="JSON objects of _tuning names and values")
    ap.add_argument("--case", default="2048x2048:fm2:2")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--profile", action="store_true")
    args = ap.parse_args()

    from benchmarks._march_spy import watch_parallel_march
    from fm2uav import fast_marching
    from fm2uav.eikonal import _parallel, _tuning

    settings = [_setting(s) for s in args.settings]
    defaults = {name: getattr(_tuning, name) for s in settings for name in s}
    v, src, order = _case(args.case)
    _parallel.PROFILE = args.profile
    seen = watch_parallel_march()  # each parallel march's statistics
    serial = fast_marching(v, [src], order=order, threads=1)
    walls: list[list[float]] = [[] for _ in settings]
    profiles: list[list[dict]] = [[] for _ in settings]
    last: list[dict] = [{} for _ in settings]
    same = [True] * len(settings)
    one: list[float] = []
    try:
        for r in range(args.repeats + 1):  # round 0 warms up
            w = time.perf_counter()
            fast_marching(v, [src], order=order, threads=1)
            if r:
                one.append(time.perf_counter() - w)
            for i, s in enumerate(settings):
                for name, value in defaults.items():
                    setattr(_tuning, name, value)
                for name, value in s.items():
                    setattr(_tuning, name, value)
                seen.clear()
                w = time.perf_counter()
                T = fast_marching(v, [src], order=order, threads=2)
                d = time.perf_counter() - w
                same[i] = same[i] and bool(np.array_equal(T, serial))
                if not seen:
                    raise SystemExit(f"{args.case} does not march on slabs on two threads "
                                     "(too few nodes for its order: _tuning's "
                                     "PARALLEL_MIN_NODES, ORDER2_MIN_NODES_2D / _3D)")
                if r:
                    walls[i].append(d)
                    last[i] = dict(seen)
                    if args.profile:
                        profiles[i].append(seen["profile"])
    finally:
        for name, value in defaults.items():
            setattr(_tuning, name, value)
        _parallel.PROFILE = False
    s0 = statistics.median(one)
    print(f"{args.case}: one thread {s0 * 1e3:.1f} ms, medians of {args.repeats}")
    head = "| setting | 2 threads [ms] | 1 / 2 | slabs | windows | re-opened | balance | exact |"
    if args.profile:
        head += (" windows' wall | exchanges' wall | windows' busiest | exchanges' busiest"
                 " | windows' CPU per thread |")
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for s, text, w, st, ok, prof in zip(settings, args.settings, walls, last, same, profiles):
        m = statistics.median(w)
        row = (f"| {text} | {m * 1e3:.1f} | {s0 / m:.3f}x | {st['slabs']} | {st['windows']} | "
               f"{st['reopened']} | {st['balance']:.3f} | {ok} |")
        if args.profile:
            def med(key, p=prof):
                return statistics.median(x[key] for x in p) * 1e3
            cpu = " / ".join(f"{statistics.median(x['window_cpu'][t] for x in prof) * 1e3:.1f}"
                             for t in range(len(prof[0]["window_cpu"])))
            row += (f" {med('window_wall'):.1f} | {med('exchange_wall'):.1f} | "
                    f"{med('window_max'):.1f} | {med('exchange_max'):.1f} | {cpu} |")
        print(row)


if __name__ == "__main__":
    main()
