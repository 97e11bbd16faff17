"""What the warm-up groups leave compiled, and what later runs need: run in a subprocess.

``python warmup_probe.py GROUP ... -- WORKLOAD ...`` runs the warm-up groups
(:data:`fm2uav.planning.warmup.GROUPS`, in the order given), then the later workloads of
:data:`WORKLOADS`, in one fresh process, and prints one JSON object:

``groups`` / ``later``
    For each group / workload, the ``(kernel, signature)`` pairs it added to fm2uav's numba
    dispatchers (``dispatcher.signatures``: compiled here or loaded from the cache), beyond
    the groups and workloads before it. A workload that adds nothing needs only what the
    groups before it compiled: in a later process, loaded from the cache.
``compiled``
    The pairs numba compiled in this process (a cache miss; ``numba:compile``).
``not_on_disk``
    The pairs of kernels cached on disk (``cache=True``) whose entry is not in the kernel's
    cache index under the key a later process looks up: signature, CPU, bytecode and
    closure values, for the current source stamp and numba version
    (``numba.core.caching``).
``unlisted``
    Dispatchers holding signatures that the scan of fm2uav's modules missed (the scan
    must see every kernel, or a new signature could go unseen).

``--stop-at-first-compile`` prints ``compiled <module>`` and exits at the start of the
first compilation of an fm2uav kernel (a cold cache costs no compile time then).
The cache is numba's: ``NUMBA_CACHE_DIR`` when set, else the package's ``__pycache__``.
"""

from __future__ import annotations

import gc
import json
import os
import sys
from collections.abc import Callable

import numpy as np
from numba.core import event
from numba.core.caching import NullCache
from numba.core.registry import CPUDispatcher

from fm2uav.eikonal import _edt, _kernels, _parallel, _tuning, distance_map, fast_marching
from fm2uav.planning import warmup
from fm2uav.planning.geodesic import drop_ties, reaches_any


def _patched(module, **values):
    """Set module attributes (size floors) for one workload; returns the restore."""
    old = {k: getattr(module, k) for k in values}
    for k, v in values.items():
        setattr(module, k, v)
    return lambda: [setattr(module, k, v) for k, v in old.items()]


def _run3d() -> None:
    """A big grid's distance map (lines on two threads), set-up (two threads) and serial
    march in the lean layout (float32 speed), order 1 and 2, with ``stop_at``, on a small
    grid; the plan's scans of the field."""
    restore = [_patched(_kernels, LEAN_NODES=0, SETUP_PARALLEL_MIN_NODES=0),
               _patched(_edt, EDT_PARALLEL_MIN_NODES=0)]
    try:
        rng = np.random.default_rng(0)
        occ = rng.random((30, 20, 10)) < 0.05
        occ[0, 0, 0] = True
        W = distance_map(occ, spacing=(15.0, 15.0, 10.0), threads=2)
        for order in (1, 2):
            T = fast_marching(W / W.max() + 0.01, [(29, 19, 9)], spacing=(15.0, 15.0, 10.0),
                              order=order, stop_at=[(0, 0, 1)], threads=2)
            assert np.isfinite(T[0, 0, 1])
        drop_ties(T, (0, 0, 1))
        assert not reaches_any(T, occ & ~np.isfinite(T))
    finally:
        for r in restore:
            r()


def _on_slabs(ndim: int, run: Callable[[], None], orders: tuple[int, ...]) -> None:
    """``run()`` with the slab march's size floors at 0; asserts it marched on the slabs, at
    each order of ``orders`` in turn (the later runs must reach the parallel kernels)."""
    marches, march = [], _parallel.march

    def spy(*a, **k):
        marches.append(k["order"])
        return march(*a, **k)

    restore = [_patched(_tuning, PARALLEL_MIN_NODES=0, ORDER2_MIN_NODES_3D=0,
                        ORDER2_MIN_NODES_2D=0), _patched(_parallel, march=spy)]
    try:
        run()
    finally:
        for undo in restore:
            undo()
    assert marches == list(orders), (ndim, marches)


def _par3d() -> None:
    """A big 3D grid's march on two threads, order 1 and 2, in the float64 layout (grids
    below ``LEAN_NODES``) and the lean one (float32 speed, e.g. a 1000x1000x40 terrain plan),
    with the two-thread input scan; on a small grid."""
    v = np.ones((40, 36, 20))
    v[10:14, :30, :] = 0.0

    def run():
        for order in (1, 2):
            T = fast_marching(v, [(30, 5, 3)], spacing=(15.0, 15.0, 10.0), order=order,
                              threads=2)
            assert np.isfinite(T[0, 0, 1])

    for lean in (_kernels.LEAN_NODES, 0):
        restore = _patched(_kernels, LEAN_NODES=lean, SETUP_PARALLEL_MIN_NODES=0)
        try:
            _on_slabs(3, run, (1, 2))
        finally:
            restore()


def _uniform2d() -> None:
    """A 2D march of a uniform speed alone (separate arrays), order 1."""
    distance_map(np.eye(4, dtype=bool))
    fast_marching(np.ones((5, 5)), [(2, 2)], order=1)


def _run2d() -> None:
    """A 2D FM² map (interleaved layout) and a uniform one (separate arrays), order 1 and 2."""
    occ = np.zeros((40, 36), dtype=bool)
    occ[10:14, :30] = True
    W = np.sqrt(distance_map(occ, spacing=15.0))
    for speed in (W / W.max(), (W > 0) * 1.0):
        for order in (1, 2):
            T = fast_marching(speed, [(30, 5)], spacing=15.0, order=order, stop_at=[(0, 0)])
            assert np.isfinite(T[0, 0])


def _par2d() -> None:
    """A big 2D map's march on two threads, order 1 and 2: slabs interleaved (a varying
    speed), in separate arrays (a uniform one), and in the lean layout (float32 speed) on a
    grid too thin for the cuts' coarse march."""
    v = np.ones((160, 40))
    v[50:54, :30] = 0.0

    def run():
        for speed in (v * np.linspace(0.5, 1.0, 40), v):
            for order in (1, 2):
                T = fast_marching(speed, [(30, 5)], spacing=15.0, order=order, threads=2)
                assert np.isfinite(T[0, 0])

    _on_slabs(2, run, (1, 2, 1, 2))

    def run_lean():
        for order in (1, 2):
            T = fast_marching(v[:40] * np.linspace(0.5, 1.0, 40), [(30, 5)], order=order,
                              threads=2)
            assert np.isfinite(T[0, 0])

    restore = _patched(_kernels, LEAN_NODES=0)
    try:
        _on_slabs(2, run_lean, (1, 2))
    finally:
        restore()


def _level() -> None:
    """A small terrain plan at a flight level: its altitude envelopes' slope sweeps."""
    import fm2uav

    heights = 10.0 + 20.0 * np.add.outer(np.sin(np.arange(12) / 3), np.cos(np.arange(10) / 4))
    world = fm2uav.World.from_heightmap(heights, 15.0, 8)
    level = fm2uav.FlightLevel(agl=30.0)
    p = fm2uav.plan(world, (20.0, 20.0, 60.0), (150.0, 120.0, 60.0), level=level)
    assert len(p.path) > 1


#: Later runs: name -> what it runs (each restores the size floors it lowers).
WORKLOADS: dict[str, Callable[[], None]] = {
    "run3d": _run3d,
    "par3d": _par3d,
    "uniform2d": _uniform2d,
    "run2d": _run2d,
    "par2d": _par2d,
    "level": _level,
}


def _fm2uav(disp) -> bool:
    mod = getattr(disp.py_func, "__module__", "") or ""
    return mod == "fm2uav" or mod.startswith("fm2uav.")


def _name(disp) -> str:
    return f"{disp.py_func.__module__}:{disp.py_func.__qualname__}"


def dispatchers() -> dict[str, CPUDispatcher]:
    """fm2uav's kernels, by ``module:qualname``: the dispatchers its imported modules hold
    (as attributes, or in a dict, list or tuple attribute: the kernels of a factory)."""
    found: dict[str, CPUDispatcher] = {}
    for mod_name, mod in list(sys.modules.items()):
        if not (mod_name == "fm2uav" or mod_name.startswith("fm2uav.")) or mod is None:
            continue
        for value in list(vars(mod).values()):
            items = (value.values() if isinstance(value, dict)
                     else value if isinstance(value, (list, tuple)) else (value,))
            for d in items:
                if isinstance(d, CPUDispatcher) and _fm2uav(d):
                    other = found.setdefault(_name(d), d)
                    if other is not d:
                        raise AssertionError(f"two kernels named {_name(d)}")
    return found


def _pairs() -> set[tuple[str, str]]:
    return {(name, str(sig)) for name, d in dispatchers().items() for sig in d.signatures}


class _Compiles(event.Listener):
    """Records each fm2uav kernel numba compiles (a cache miss), or exits at the first."""

    def __init__(self, stop: bool) -> None:
        self.stop, self.seen = stop, []

    def on_start(self, ev):
        disp = ev.data.get("dispatcher") if isinstance(ev.data, dict) else None
        if disp is None or not _fm2uav(disp):
            return
        if self.stop:
            print("compiled", disp.py_func.__module__, flush=True)
            os._exit(0)
        self.seen.append((_name(disp), str(tuple(ev.data["args"]))))

    def on_end(self, ev):
        pass


def _not_on_disk(pairs: set[tuple[str, str]]) -> list[tuple[str, str]]:
    """The pairs of kernels cached on disk that a later process would not find there."""
    by_name = dispatchers()
    out = []
    for name, d in by_name.items():
        if isinstance(d._cache, NullCache):
            continue  # not cached: compiled into its callers (tested in test_warmup.py)
        index = d._cache._cache_file._load_index()  # {} when stale (source stamp, numba)
        codegen = d.targetctx.codegen()
        for sig in d.signatures:
            if (name, str(sig)) in pairs and d._cache._index_key(sig, codegen) not in index:
                out.append((name, str(sig)))
    return sorted(out)


def main(argv: list[str]) -> int:
    stop = "--stop-at-first-compile" in argv
    argv = [a for a in argv if a != "--stop-at-first-compile"]
    groups, later = (argv[:argv.index("--")], argv[argv.index("--") + 1:]) if "--" in argv \
        else (argv, [])
    compiles = _Compiles(stop)
    event.register("numba:compile", compiles)
    out: dict[str, object] = {"groups": {}, "later": {}}
    seen = _pairs()
    for kind, names, table in (("groups", groups, warmup.GROUPS), ("later", later, WORKLOADS)):
        for name in names:
            table[name]()
            now = _pairs()
            out[kind][name] = sorted(now - seen)
            seen = now
    gc.collect()
    listed = set(dispatchers().values())
    out["unlisted"] = sorted(_name(d) for d in gc.get_objects()
                             if isinstance(d, CPUDispatcher) and _fm2uav(d)
                             and d.signatures and d not in listed)
    out["compiled"] = sorted(set(compiles.seen))
    out["not_on_disk"] = _not_on_disk(seen)
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
