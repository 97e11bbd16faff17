"""Fill numba's cache with the kernels of a plan, by running them on tiny inputs.

Each group runs the public functions a plan calls (the same wrappers, hence
the same argument types and the same compiled specialisations) on a few
nodes, so the run costs only the compilation. Used by ``make install`` (all
groups) and by the command line on a cold cache, which compiles the groups in
two processes at once (see :mod:`fm2uav.__main__`)::

    python -m fm2uav.planning.warmup            # every group, in this process
    python -m fm2uav.planning.warmup fmm3d_o2   # one group

Groups: ``edt`` (distance map), ``fmm{2,3}d_o{1,2}`` (Fast Marching, one
dimension and order), ``descent`` (geodesic extraction), ``surface``
(continuous clearance to a terrain surface), ``many`` (many routes from one wave: the
descents' sweep; the clearance to obstacle cells), ``profile`` (the slope sweeps of a
flight level's altitude envelopes), and two of big grids only, which
call their kernels directly: ``edt_parallel`` (the distance map's lines in
parallel) and ``fmm3d_o{1,2}_lean`` (the 3D march in the lean layout, see
``fm2uav.eikonal._kernels.LEAN_NODES``); ``fmm{2,3}d_parallel`` (the march on both cores,
order 1 and 2, ``plan()``'s default) compile both layouts. Numbers: docs/performance.md.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterable, Mapping

import numpy as np

from ..eikonal import _edt as _edt_kernels
from ..eikonal import _kernels, _parallel, _tuning, distance_map, fast_marching
from ..world import World
from ..world.clearance import min_surface_clearances, surface_clearance
from .altitude import envelope_above
from .geodesic import descend, descend_stopped, drop_ties, reaches_any

__all__ = ["GROUPS", "FIRST_PLAN_MAIN", "FIRST_PLAN_CHILD", "warm"]


def _edt() -> None:
    occ = np.zeros((4, 4, 4), dtype=bool)
    occ[0, 0, 0] = True
    distance_map(occ, spacing=1.0)


def _edt_parallel() -> None:
    """The distance transform of big grids (lines in parallel)."""
    occ = np.zeros((4, 4, 4), dtype=bool)
    occ[0, 0, 0] = True
    _edt_kernels._edt_parallel(_kernels._readonly(occ), 1.0, 1.0, 1.0, True, True, 1)


def _fmm(ndim: int, order: int) -> Callable[[], None]:
    """The march of one dimension and order in both layouts (a uniform speed marches in
    separate arrays, a varying one without a plateau interleaved: ``_kernels._buffers``)."""
    def run() -> None:
        speed = np.ones((5,) * ndim)
        fast_marching(speed, [(2,) * ndim], order=order)
        speed = np.linspace(0.5, 1.0, speed.size).reshape(speed.shape)  # no plateau
        fast_marching(speed, [(2,) * ndim], order=order)

    return run


def _fmm_lean(order: int) -> Callable[[], None]:
    """The 3D march in the lean layout of grids over ``LEAN_NODES`` nodes (float32 V), and
    the set-up of big grids on two threads (the input scan, the padding)."""
    def run() -> None:
        T = np.full(125, np.inf)
        state = np.zeros(125, dtype=np.uint8)
        T[62], state[62] = 0.0, _kernels.FROZEN
        floor = _kernels.SETUP_PARALLEL_MIN_NODES
        _kernels.SETUP_PARALLEL_MIN_NODES = 0
        try:
            for threads in (1, 2):
                _kernels.march(np.ones(125), _kernels.Start.whole(T, state, (5, 5, 5)),
                               (5, 5, 5), (1.0, 1.0, 1.0), order,
                               np.zeros((0, 3), dtype=np.int64), lean=True, threads=threads)
        finally:
            _kernels.SETUP_PARALLEL_MIN_NODES = floor
        _kernels.scan_speed_parallel(2, _kernels._readonly(np.ones(125)), 1e-150)

    return run


def _fmm_parallel(ndim: int) -> Callable[[], None]:
    """The march on both cores (grids of ``PARALLEL_MIN_NODES`` nodes and more), order 1 and
    2 (unless ``_tuning.ORDER2`` is off), in every layout (float64 ``V``: in 2D interleaved
    with ``T`` unless the speed is uniform, whose separate arrays pad and unpad as other
    specialisations; and the lean float32 ``V`` of grids over ``LEAN_NODES`` padded nodes,
    e.g. a 1000x1000x40 terrain plan, with the page toucher of its buffers), its size floors
    lowered for a 16-node-wide grid while it compiles, stopped at a node as a plan's march
    (the times after the stop set to inf on the threads) and to the end (2D: the windows
    pipelined, :data:`~fm2uav.eikonal._tuning.PIPELINE`); and the descent placing the slab
    cuts and their comparison."""
    def run() -> None:
        speed = np.ones((16,) * ndim)
        speed[(0,) * ndim] = 0.5  # a plateau with its mask (a uniform grid needs none)
        speeds = (speed, np.ones((16,) * ndim)) if ndim == 2 else (speed,)
        floor, lean = _tuning.PARALLEL_MIN_NODES, _kernels.LEAN_NODES
        floor2 = _tuning.ORDER2_MIN_NODES_3D, _tuning.ORDER2_MIN_NODES_2D
        slab = _tuning.MIN_SLAB_ROWS, _tuning.MIN_SLAB_NODES
        _tuning.PARALLEL_MIN_NODES = _tuning.ORDER2_MIN_NODES_3D = 0
        _tuning.ORDER2_MIN_NODES_2D = 0
        # slabs of a few rows: two threads march (the pipelined windows need two)
        _tuning.MIN_SLAB_ROWS, _tuning.MIN_SLAB_NODES = 4, 0
        try:
            for lean_nodes in (lean, 0):
                _kernels.LEAN_NODES = lean_nodes
                for v in speeds:
                    for order in (1, 2) if _tuning.ORDER2 else (1,):
                        # toward a stop node (the windows' regions) and to the end (2D: the
                        # pipelined windows, _tuning.PIPELINE)
                        for stop in ([(12,) * ndim], None):
                            fast_marching(v, [(3,) * ndim], order=order, threads=2,
                                          stop_at=stop)
        finally:
            _tuning.PARALLEL_MIN_NODES, _kernels.LEAN_NODES = floor, lean
            _tuning.ORDER2_MIN_NODES_3D, _tuning.ORDER2_MIN_NODES_2D = floor2
            _tuning.MIN_SLAB_ROWS, _tuning.MIN_SLAB_NODES = slab
        # the page toucher's kernels (the top speed first, then the page faults): on a grid
        # this small its thread may be stopped before its first touch (the cuts are placed
        # at once), so they are compiled here
        _parallel._touch(np.zeros(8, dtype=np.uint8), 4096)
        _parallel._top_speed(_kernels._readonly(np.ones(8)))
        # the plateau test's pass over the speeds of a march not given their span: the
        # cuts' coarse march (fast_marching gives its own march the span of its input scan)
        _kernels.speed_range(_kernels._readonly(np.ones(8)))
        cum = np.cumsum(np.ones((5, 3), dtype=np.int64), axis=0)
        cuts = np.array([0, 2, 4], dtype=np.int64)
        for shared in (False, True):
            _parallel._descend_cuts(cum, cuts, 1, 2, shared)
        _parallel._shared_cost(cum, cuts, 2)  # the two descents' cuts compared
        _parallel._time_bins(np.zeros((2, 2)), np.zeros(1), 2)  # the coarse march's bins
        # the start box's rows padded once the balls are written (a march that padded its
        # slabs beside them: timing decides), in each layout: the 2D interleaved views, the
        # separate float64 arrays, the lean layout's float32 V
        pairs = np.zeros(16)
        layouts = ((pairs[0::2], pairs[1::2]), (np.zeros(8), np.zeros(8)),
                   (np.zeros(8), np.zeros(8, dtype=np.float32)))
        for Tp, Vp in layouts:
            _parallel._fill_start_rows(
                _kernels._readonly(np.ones(4)), np.zeros(1), np.zeros(1, dtype=np.uint8),
                np.zeros((1, 8), dtype=np.int64), np.array([0, 2], dtype=np.int64),
                np.zeros(1, dtype=np.int64), 2, 1, 1, Tp, Vp, np.zeros(0, dtype=np.int64))

    return run


def _descent() -> None:
    """The descent and the plan's scans of its field (ties at the start, obstacles reached)."""
    g = np.array([4.0, 4.0, 4.0])
    axes = np.meshgrid(*[np.arange(5.0)] * 3, indexing="ij")
    T = np.sqrt(sum((a - c) ** 2 for a, c in zip(axes, g)))
    drop_ties(T, (0, 0, 0))
    reaches_any(T, np.zeros(T.shape, dtype=bool))
    descend(T, (0.0, 0.0, 0.0), tuple(g), spacing=(1.0, 1.0, 1.0))


def _many() -> None:
    """Many routes from one wave (``plan_many``): the descents' compiled sweep, and the
    clearance of paths measured to obstacle cells (2D worlds, also ``plan()``'s)."""
    g = np.array([4.0, 4.0, 4.0])
    axes = np.meshgrid(*[np.arange(5.0)] * 3, indexing="ij")
    T = np.sqrt(sum((a - c) ** 2 for a, c in zip(axes, g)))
    ball = np.where(T <= 1.0, T, np.inf)
    descend_stopped(T, [(0.0, 0.0, 0.0), (4.0, 3.0, 4.0)], tuple(g), frozen=ball)
    occ = np.zeros((4, 4), dtype=bool)
    occ[0, 0] = True
    min_surface_clearances(World(occ, spacing=1.0), [np.array([[2.5, 2.5], [3.0, 3.0]])])


def _surface() -> None:
    world = World.from_heightmap(np.zeros((4, 4)), 1.0, 4)
    surface_clearance(world, np.array([[1.5, 1.5, 2.5]]))


def _profile() -> None:
    """The slope sweeps of a flight level's altitude envelopes (every flight-level plan and
    route; not the plain first ``fm2uav plan``)."""
    envelope_above(np.array([0.0, 1.0, 2.0]), np.array([0.0, 2.0, 0.0]), 0.5, 0.5)


#: Group name -> what it runs.
GROUPS: dict[str, Callable[[], None]] = {
    "edt": _edt,
    "edt_parallel": _edt_parallel,
    "fmm2d_o1": _fmm(2, 1),
    "fmm2d_o2": _fmm(2, 2),
    "fmm3d_o1": _fmm(3, 1),
    "fmm3d_o2": _fmm(3, 2),
    "fmm3d_o1_lean": _fmm_lean(1),
    "fmm3d_o2_lean": _fmm_lean(2),
    "fmm2d_parallel": _fmm_parallel(2),
    "fmm3d_parallel": _fmm_parallel(3),
    "descent": _descent,
    "surface": _surface,
    "many": _many,
    "profile": _profile,
}

#: A first ``fm2uav plan`` (3D, order 2) split in two halves of about equal
#: compile time (the ``coldstart`` rows of ``make bench``): the child process
#: compiles the Fast Marching kernels while the command compiles the rest.
FIRST_PLAN_CHILD: tuple[str, ...] = ("fmm3d_o2",)
FIRST_PLAN_MAIN: tuple[str, ...] = ("descent", "edt", "surface")


def warm(groups: Iterable[str] | None = None, *,
         table: Mapping[str, Callable[[], None]] = GROUPS) -> dict[str, float]:
    """Run the named groups; returns the seconds each took (compile + tiny run).

    Parameters
    ----------
    groups : iterable of str, optional
        Keys of ``table`` (default: all of them).
    table : mapping of str to callable
        The groups: :data:`GROUPS`, or the warm-up of a layer above this one
        (``fm2uav.vehicles.warmup``, ``fm2uav.baselines.warmup``).

    Raises
    ------
    KeyError
        An unknown group name.
    """
    out = {}
    for name in (table if groups is None else groups):
        fn = table[name]
        t = time.perf_counter()
        fn()
        out[name] = time.perf_counter() - t
    return out


def main(argv: list[str] | None = None, *,
         table: Mapping[str, Callable[[], None]] = GROUPS) -> int:
    """``python -m fm2uav.planning.warmup [GROUP ...]``: print each group's time (``table``:
    the groups, :func:`warm`)."""
    names = (sys.argv[1:] if argv is None else argv) or list(table)
    unknown = [n for n in names if n not in table]
    if unknown:
        print(f"unknown warm-up group(s) {unknown}; choose from {sorted(table)}",
              file=sys.stderr)
        return 2
    for name, seconds in warm(names, table=table).items():
        print(f"{name}: {seconds:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
