"""Small plans whose every output is pinned bit for bit (``data/golden_plans.json``).

The digests were written by the code before the velocity map, the march's set-up and
the descent's checks were made parallel (commit dbf51f4, issue 27): the faster stages
must give the same bytes. ``CASES`` maps a name to ``(world, start, goal, keyword
arguments of plan)``; :func:`digest` is what is compared.

Rewritten since: ``2d_obstacles_fmm`` and ``2d_obstacles_fmm_dsat`` by the radix queue on
8-bit digits (session 29), which pops nodes of exactly equal times in another order. Their
distance map is an order-2 march from every boundary cell at one speed, full of such ties,
and an order-2 update depends on which tied neighbour is frozen first: 144 of 6,300
distances moved (by up to 0.11 cells; mean error against the exact EDT 0.17415 -> 0.17407
cells, the largest the same), the paths' lengths by 7e-8 and 2e-7 relative. At order 1 the
map is the same bit for bit, as is every other case. Again by the deferred queue entries
(session 32: a far node reached while a band neighbour across another axis is earlier is
queued only when that neighbour updates it), which change the order of tied pops once more:
81 and 70 of 6,300 distances moved (by up to 0.088 and 0.196 cells; mean error over the free
nodes against the
exact EDT 0.19479 -> 0.19458 and 0.12597 -> 0.12623 cells, the largest the same), the paths'
lengths by 2.3e-9 and 5.1e-8 relative; every other case the same bit for bit. Again, every
case, by the update's quadratic solved in ``T - tau`` instead of ``T`` (session 41,
``_kernels._combine``: its discriminant no longer cancels terms of size ``T^2``): the times
moved by at most 7.4e-13 relative, the paths' points by at most 8.7e-10 m, their lengths
by at most 2.8e-13 relative, W not at all but by the order-2 distance maps of the two
``_fmm`` cases (3.8e-14 at most).

Regenerate only when a change of the numbers is intended (e.g. a new march scheme),
and say so in the commit::

    PYTHONPATH=src python -m tests.planning.golden_plans --write
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np

import fm2uav
from fm2uav import FlightLevel, PlanOptions, Shaping, World

DATA = Path(__file__).resolve().parent / "data" / "golden_plans.json"


def _bytes_digest(a: np.ndarray) -> str:
    a = np.ascontiguousarray(a)
    return hashlib.sha256(f"{a.dtype.str}{a.shape}".encode() + a.tobytes()).hexdigest()


def _obstacles_2d() -> World:
    rng = np.random.default_rng(7)
    occ = np.zeros((90, 70), bool)
    for _ in range(14):  # boxes of random size
        x, y = rng.integers(0, 80), rng.integers(0, 60)
        occ[x:x + rng.integers(2, 12), y:y + rng.integers(2, 12)] = True
    occ[:6, :6] = occ[-6:, -6:] = False
    return World(occ, spacing=1.0)


def _obstacles_3d() -> World:
    rng = np.random.default_rng(11)
    occ = np.zeros((48, 40, 18), bool)
    occ[:, :, 0] = True  # the ground
    for _ in range(12):  # buildings
        x, y = rng.integers(4, 40), rng.integers(4, 32)
        occ[x:x + rng.integers(2, 7), y:y + rng.integers(2, 7), :rng.integers(3, 15)] = True
    occ[:4, :4, 1:] = occ[-4:, -4:, 1:] = False
    return World(occ, spacing=(10.0, 10.0, 5.0))


def _terrain(nx: int = 56, ny: int = 44, nz: int = 20, cell: float = 15.0) -> World:
    rng = np.random.default_rng(3)
    from scipy import ndimage

    relief = ndimage.gaussian_filter(rng.standard_normal((nx, ny)), 4, mode="wrap")
    heights = (relief - relief.min()) / np.ptp(relief) * 12 * cell + cell
    return World.from_heightmap(heights, cell, nz)


def cases() -> dict:
    """Name -> ``(world, start [m], goal [m], plan keyword arguments)``."""
    w2, w3, wt = _obstacles_2d(), _obstacles_3d(), _terrain()
    s2, g2 = (2.0, 2.0), (87.0, 67.0)
    s3, g3 = (15.0, 15.0, 30.0), (460.0, 380.0, 30.0)
    st, gt = (3 * 15.0, 3 * 15.0, 17 * 15.0), (52 * 15.0, 40 * 15.0, 17 * 15.0)
    return {
        "2d_obstacles": (w2, s2, g2, {}),
        "2d_obstacles_order1": (w2, s2, g2, {"options": PlanOptions(order=1)}),
        "2d_obstacles_shaped": (w2, s2, g2, {"shaping": Shaping(saturation=0.4, exponent=2.0)}),
        "2d_obstacles_dsat": (w2, s2, g2, {"shaping": Shaping(saturation_distance=6.0,
                                                               exponent=0.5)}),
        "2d_obstacles_walls": (w2, s2, g2, {"shaping": Shaping(walls=True, exponent=1.5)}),
        "2d_obstacles_fmm": (w2, s2, g2, {"shaping": Shaping(method="fmm")}),
        "2d_obstacles_fmm_dsat": (w2, s2, g2, {"shaping": Shaping(method="fmm", walls=True,
                                                                   saturation_distance=5.0)}),
        "3d_obstacles": (w3, s3, g3, {}),
        "3d_obstacles_shaped": (w3, s3, g3, {"shaping": Shaping(saturation=0.6,
                                                                 exponent=1.7)}),
        "3d_terrain": (wt, st, gt, {}),
        "3d_terrain_order1": (wt, st, gt, {"options": PlanOptions(order=1)}),
        "3d_terrain_level": (wt, st, gt, {"level": FlightLevel(agl=60.0)}),
    }


def digest(p: fm2uav.Plan) -> dict:
    """Every output of a plan: digests of W, T, the path and w; the summary's numbers."""
    summary = p.summary()
    summary.pop("timings_s")
    return {
        "W": _bytes_digest(np.asarray(p.W, dtype=np.float64)),
        "T": _bytes_digest(np.asarray(p.T, dtype=np.float64)),
        "path": _bytes_digest(p.path),
        "w": _bytes_digest(p.w),
        "length": repr(float(p.length)),
        "clearance": repr(float(p.clearance)),
        "speed_share": _bytes_digest(p.speed_share()),
        "summary": json.loads(json.dumps(summary, default=repr)),
    }


def run(name: str, **extra) -> dict:
    """The digest of case ``name`` planned now (``extra`` updates its plan keywords)."""
    world, s, g, kw = cases()[name]
    world._cache.clear()
    return digest(fm2uav.plan(world, s, g, **{**kw, **extra}))


def run_case(name: str, threads: int | None = None, force_parallel: bool = False,
             lean: bool = False, exponent: float | None = None) -> dict:
    """:func:`run` with arguments a child Python can be given (tests/planning/golden_numpy.py).

    ``threads``: the case's order on that many threads (None: the case's own options);
    ``force_parallel``: the distance transform's and the march set-up's parallel paths on
    this small world; ``lean``: the lean layout forced; ``exponent``: another shaping
    exponent (a changed plan). The thresholds are restored afterwards.
    """
    from fm2uav.eikonal import _edt, _kernels

    saved = (_edt.EDT_PARALLEL_MIN_NODES, _kernels.SETUP_PARALLEL_MIN_NODES,
             _kernels.LEAN_NODES)
    try:
        if force_parallel or lean:
            _kernels.SETUP_PARALLEL_MIN_NODES = 0
        if force_parallel:
            _edt.EDT_PARALLEL_MIN_NODES = 0
        if lean:
            _kernels.LEAN_NODES = 0
        extra: dict = {}
        if threads is not None:
            opts = cases()[name][3].get("options", PlanOptions())
            extra["options"] = PlanOptions(order=opts.order, threads=threads)
        if exponent is not None:
            extra["shaping"] = Shaping(exponent=exponent)
        return run(name, **extra)
    finally:
        (_edt.EDT_PARALLEL_MIN_NODES, _kernels.SETUP_PARALLEL_MIN_NODES,
         _kernels.LEAN_NODES) = saved


def main(argv: list[str], cases=cases, run=run, data: Path = DATA,
         target: str = "tests.planning.golden_plans:run") -> int:
    """Print the digest of every case, or (``--write``) write them to ``data``.

    Computed as the tests compute them: on a CPU whose numpy has AVX-512 loops, in a child
    Python with those off (``target``: ``run`` as ``module:function``; golden_numpy.py says
    why), else in this process. Written here directly, an AVX-512 machine's digests of the
    shaped cases would be its own numpy's, not the code's, and the tests would fail them.
    """
    from . import golden_numpy

    names = list(cases())
    wide = golden_numpy.wide_features()
    if wide:
        got = golden_numpy.in_child(target, [((name,), {}) for name in names], wide)
        out = dict(zip(names, got))
    else:
        out = {name: run(name) for name in names}
    if "--write" in argv:
        data.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
        print(f"wrote {data}")
    else:
        print(json.dumps(out, indent=1, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
