"""Point sources in varying media: analytic cases, our errors and scikit-fmm's, rates.

Shared by ``test_sources.py`` (which asserts on these numbers) and
``docs/eikonal.md`` (whose accuracy table is this module's output)::

    .venv/bin/python tests/eikonal/point_source_cases.py           # print the tables
    .venv/bin/python tests/eikonal/point_source_cases.py --write   # update docs/eikonal.md

The cases (source at a node, error norms over the nodes at distance >= 0.1 m
from the source, "away from the source"):

* ``gradient``: a linear velocity v = 1 + g . x [m/s] on the unit square / cube,
  g = (1, 2) / (1, 2, 2) [1/s] (oblique: the rays are circular arcs in the plane
  of g), source at the centre. Exact time (e.g. Slotnick 1959):
  ``T = arccosh(1 + |g|^2 r^2 / (2 v_s v)) / |g|``.
* ``steep gradient``: v = 0.25 + 2.5 z [m/s] (11x over the domain), source at
  z = 0.1 m (x, y at the centre), v_s = 0.5 m/s. The nominal ball (R = 0.05 m)
  holds speeds 0.375 .. 0.625 (max/min 1.67 > 1.5), so the ball is halved to
  R = 0.025 m (4 and more cells from 161 nodes on; 2 cells at 81; none at 41,
  where 0.05 m is already 2 cells).
* ``radial``: slowness 1 + 0.5 sin(10 r) [s/m] around the source at the centre of
  [0, 2] x [0, 1] (x [0, 1]); the 2D grid 201 x 101 (h = 0.01 m) is the case of
  issue 16. The rays are straight: ``T = r + 0.05 (1 - cos 10 r)``.
* ``two-layer``: speed 1 m/s above z = 0.35 m, 2 m/s below, source at (0.2, 0.7)
  ((0.2, 0.5, 0.7) in 3D) on the unit square / cube. Exact first arrival: above
  the interface the direct wave or, beyond the critical offset, the head wave
  ``X / v2 + (d_s + d) cos(theta_c) / v1`` (sin theta_c = v1 / v2); below it the
  transmitted wave, the minimum over the crossing point (Snell's law). The grids
  have 30, 90, 270 cells per axis (refinement by 3), so the interface lies
  half-way between two node rows on every grid; speeds are sampled at the nodes.

scikit-fmm has no point sources: it marches from the zero level set of
``phi = r - r0``; its time is compared with ``T - T(r0)``, exact for the radial
case and to O(r0^2) for the others. ``r0 = h / 2`` throughout (phi < 0 at the
source node only); for the radial case also ``r0 = 2 h``, where scikit-fmm
starts from (nearly) exact data on a ring of nodes.
"""

from __future__ import annotations

import argparse
import functools
import math
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import skfmm

from fm2uav.eikonal import fast_marching

NEAR_SOURCE = 0.1  #: [m] the error norms exclude nodes nearer than this to the source
DOC = Path(__file__).resolve().parents[2] / "docs" / "eikonal.md"


# ------------------------------------------------------------------ exact fields
def gradient_time(r: np.ndarray, v_source: float, v: np.ndarray, g: float) -> np.ndarray:
    """Travel time [s] in a linear velocity field of gradient norm ``g`` [1/s].

    ``r``: distance from the source [m]; ``v_source``, ``v``: speeds [m/s] at the
    source and at the node.
    """
    return np.arccosh(1.0 + g * g * r * r / (2.0 * v_source * v)) / g


def radial_time(r: np.ndarray) -> np.ndarray:
    """Travel time [s] for slowness ``1 + 0.5 sin(10 r)`` [s/m] around the source."""
    return r + 0.05 * (1.0 - np.cos(10.0 * r))


def two_layer_time(
    offset: np.ndarray, z: np.ndarray, z_source: float, z_interface: float, v1: float, v2: float
) -> tuple[np.ndarray, np.ndarray]:
    """First arrival [s] of a point source in the slow top layer of two (v1 < v2).

    Parameters
    ----------
    offset : ndarray
        Horizontal distance [m] from the source.
    z : ndarray
        Height [m]; the source's layer is ``z > z_interface``.
    z_source, z_interface : float
        Heights [m] of the source and of the interface.
    v1, v2 : float
        Speeds [m/s] above and below the interface.

    Returns
    -------
    (time, head) : ndarrays
        The time, and where the head wave arrives first (top layer only).
    """
    d_src = z_source - z_interface
    d_rcv = np.abs(z - z_interface)
    sin_c = v1 / v2
    cos_c = math.sqrt(1.0 - sin_c * sin_c)
    direct = np.hypot(offset, z - z_source) / v1
    critical = (d_src + d_rcv) * sin_c / cos_c
    head_time = np.where(offset >= critical, offset / v2 + (d_src + d_rcv) * cos_c / v1, np.inf)
    # transmitted wave: the crossing offset xi in [0, offset] where the time
    # |S - (xi, z_i)| / v1 + |(xi, z_i) - P| / v2 is stationary (it is convex in xi)
    lo, hi = np.zeros_like(offset), offset.copy()
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        slope = mid / (v1 * np.hypot(mid, d_src)) - (offset - mid) / (
            v2 * np.maximum(np.hypot(offset - mid, d_rcv), 1e-300)
        )
        lo, hi = np.where(slope > 0, lo, mid), np.where(slope > 0, mid, hi)
    xi = 0.5 * (lo + hi)
    transmitted = np.hypot(xi, d_src) / v1 + np.hypot(offset - xi, d_rcv) / v2
    top = z > z_interface
    time = np.where(top, np.minimum(direct, head_time), transmitted)
    return time, top & (head_time < direct)


# ------------------------------------------------------------------------ cases
@dataclass(frozen=True)
class Grid:
    """One discretised case: speed [m/s], source index, spacing [m], exact time [s]."""

    speed: np.ndarray
    source: tuple[int, ...]
    h: float
    exact: np.ndarray
    r: np.ndarray  #: distance from the source [m]
    shift: Callable[[float], float]  #: exact time [s] at distance r0 (scikit-fmm's start)
    head: np.ndarray | None = None  #: where the head wave arrives first (two-layer)


def _axes(shape: tuple[int, ...], h: float) -> list[np.ndarray]:
    return np.meshgrid(*[np.arange(n) * h for n in shape], indexing="ij")


def _gradient(ndim: int, cells: int) -> Grid:
    h = 1.0 / cells
    shape = (cells + 1,) * ndim
    x = _axes(shape, h)
    g = np.array([1.0, 2.0] if ndim == 2 else [1.0, 2.0, 2.0])  # [1/s]
    speed = 1.0 + sum(gk * xk for gk, xk in zip(g, x))
    src = (cells // 2,) * ndim
    r = np.sqrt(sum((xk - s * h) ** 2 for xk, s in zip(x, src)))
    vs = float(speed[src])
    exact = gradient_time(r, vs, speed, float(np.linalg.norm(g)))
    return Grid(speed, src, h, exact, r, lambda r0: r0 / vs)


def _steep(ndim: int, cells: int) -> Grid:
    h = 1.0 / cells
    shape = (cells + 1,) * ndim
    x = _axes(shape, h)
    speed = 0.25 + 2.5 * x[-1]  # [m/s], 0.25 .. 2.75
    src = (cells // 2,) * (ndim - 1) + (round(0.1 / h),)
    r = np.sqrt(sum((xk - s * h) ** 2 for xk, s in zip(x, src)))
    vs = float(speed[src])
    exact = gradient_time(r, vs, speed, 2.5)
    return Grid(speed, src, h, exact, r, lambda r0: r0 / vs)


def _radial(ndim: int, cells: int) -> Grid:
    h = 1.0 / cells  # [0, 2] x [0, 1] (x [0, 1]): 2 cells x cells (x cells)
    shape = (2 * cells + 1,) + (cells + 1,) * (ndim - 1)
    x = _axes(shape, h)
    src = tuple(n // 2 for n in shape)
    r = np.sqrt(sum((xk - s * h) ** 2 for xk, s in zip(x, src)))
    speed = 1.0 / (1.0 + 0.5 * np.sin(10.0 * r))
    return Grid(speed, src, h, radial_time(r), r, lambda r0: float(radial_time(np.array(r0))))


TWO_LAYER = {"v1": 1.0, "v2": 2.0, "z_interface": 0.35, "source_x": 0.2, "source_z": 0.7}


def _two_layer(ndim: int, cells: int, **change: float) -> Grid:
    p = {**TWO_LAYER, **change}
    h = 1.0 / cells
    shape = (cells + 1,) * ndim
    x = _axes(shape, h)
    src = (round(p["source_x"] / h),) + (cells // 2,) * (ndim - 2) + (round(p["source_z"] / h),)
    offset = np.sqrt(sum((x[a] - src[a] * h) ** 2 for a in range(ndim - 1)))
    z = x[-1]
    speed = np.where(z > p["z_interface"], p["v1"], p["v2"])
    exact, head = two_layer_time(
        offset, z, src[-1] * h, p["z_interface"], p["v1"], p["v2"]
    )
    r = np.hypot(offset, z - src[-1] * h)
    v1 = p["v1"]
    return Grid(speed, src, h, exact, r, lambda r0: r0 / v1, head)


@dataclass(frozen=True)
class Case:
    """A medium on a sequence of grids (``cells`` along the unit length)."""

    name: str
    ndim: int
    cells: tuple[int, ...]
    build: Callable[[int, int], Grid]
    smooth: bool  #: smooth medium: second order expected
    ring: bool = False  #: also compare with scikit-fmm started from r0 = 2 h

    @property
    def refinement(self) -> float:
        """Spacing ratio between consecutive grids."""
        return self.cells[1] / self.cells[0]


CASES = {
    ("gradient", 2): Case("gradient", 2, (40, 80, 160, 320), _gradient, True),
    ("gradient", 3): Case("gradient", 3, (40, 80, 160), _gradient, True),
    ("steep gradient", 2): Case("steep gradient", 2, (40, 80, 160, 320), _steep, True),
    ("steep gradient", 3): Case("steep gradient", 3, (40, 80, 160), _steep, True),
    ("radial", 2): Case("radial", 2, (25, 50, 100, 200), _radial, True, ring=True),
    ("radial", 3): Case("radial", 3, (20, 40, 80), _radial, True, ring=True),
    ("two-layer", 2): Case("two-layer", 2, (30, 90, 270), _two_layer, False),
    ("two-layer", 3): Case("two-layer", 3, (30, 90), _two_layer, False),
}


#: Where the method stops helping (docs/eikonal.md, "Limits"): 2D, order 2,
#: measured by ``point_source_cases.py`` only (not by the tests).
LIMITS = {
    "two-layer, interface 1/3 or 2/3 of a cell from the nodes (z = 1/3 m)": Case(
        "two-layer", 2, (40, 80, 160, 320),
        functools.partial(_two_layer, z_interface=1 / 3, source_z=0.75), False,
    ),
    "two-layer, v2 = 3 v1 (the march is first order across jumps > 2x)": Case(
        "two-layer", 2, (30, 90, 270), functools.partial(_two_layer, v2=3.0), False
    ),
    "two-layer, source 0.017 m above the interface (z = 11/30 m)": Case(
        "two-layer", 2, (30, 90, 270), functools.partial(_two_layer, source_z=11 / 30), False
    ),
}


# ----------------------------------------------------------------- measurements
@dataclass(frozen=True)
class Row:
    """Errors [s] on one grid, over the nodes at distance >= NEAR_SOURCE."""

    shape: tuple[int, ...]
    h: float
    ours_max: float
    ours_l1: float
    sk_max: float  #: scikit-fmm from r0 = h / 2
    sk_l1: float
    sk_ring_max: float  #: scikit-fmm from r0 = 2 h (nan unless the case has ``ring``)
    ball_cells: float  #: radius of the frozen ball [cells]: farthest initial node / h


def _errors(T: np.ndarray, exact: np.ndarray, mask: np.ndarray) -> tuple[float, float]:
    err = np.abs(T - exact)[mask]
    assert err.size > 0 and np.all(np.isfinite(err))
    return float(err.max()), float(err.mean())


def _skfmm(grid: Grid, r0: float, order: int) -> np.ndarray:
    T = skfmm.travel_time(grid.r - r0, grid.speed, dx=grid.h, order=order)
    return np.asarray(T) + grid.shift(r0)


@functools.lru_cache(maxsize=None)
def measure_grid(name: str, ndim: int, order: int, cells: int) -> Row:
    """Our errors and scikit-fmm's on one grid of a case (cached per session)."""
    return _measure(CASES[(name, ndim)], order, cells)


def _measure(case: Case, order: int, cells: int) -> Row:
    ndim = case.ndim
    g = case.build(ndim, cells)
    far = g.r >= NEAR_SOURCE
    T = fast_marching(g.speed, [g.source], spacing=g.h, order=order)
    ours = _errors(T, g.exact, far)
    sk = _errors(_skfmm(g, 0.5 * g.h, order), g.exact, far)
    ring = _errors(_skfmm(g, 2.0 * g.h, order), g.exact, far)[0] if case.ring else math.nan
    # nodes frozen before the march (stopping at the source marches nothing)
    init = np.isfinite(fast_marching(g.speed, [g.source], spacing=g.h, stop_at=[g.source]))
    return Row(g.speed.shape, g.h, *ours, *sk, ring, float(g.r[init].max() / g.h))


def measure(name: str, ndim: int, order: int, up_to: int | None = None) -> tuple[Row, ...]:
    """:func:`measure_grid` on the grids of a case (those with at most ``up_to`` cells)."""
    cells = [c for c in CASES[(name, ndim)].cells if up_to is None or c <= up_to]
    return tuple(measure_grid(name, ndim, order, c) for c in cells)


def rates(errors: list[float], refinement: float) -> list[float]:
    """Convergence rate of each refinement: log(e_coarse / e_fine) / log(ratio)."""
    return [math.log(a / b) / math.log(refinement) for a, b in zip(errors, errors[1:])]


def slope(hs: list[float], errors: list[float]) -> float:
    """Least-squares slope of log(error) against log(h)."""
    return float(np.polyfit(np.log(hs), np.log(errors), 1)[0])


# ------------------------------------------------------------------------ table
def _fmt(x: float, spec: str = ".3g") -> str:
    return "–" if math.isnan(x) else format(x, spec)


TABLE_HEADER = [
    "| case | order | grid | h [m] | ball [cells] | ours max [s] | skfmm max [s] | "
    "ours / skfmm | ours / skfmm (r0 = 2h) | ours L1 [s] | skfmm L1 [s] | rate max | rate L1 |",
    "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
]


def markdown_table(orders: tuple[int, ...] = (2, 1)) -> str:
    """The accuracy table of docs/eikonal.md (one row per case, order and grid)."""
    lines = list(TABLE_HEADER)
    for order in orders:
        for (name, ndim), case in CASES.items():
            rows = measure(name, ndim, order)
            r_max = [math.nan] + rates([r.ours_max for r in rows], case.refinement)
            r_l1 = [math.nan] + rates([r.ours_l1 for r in rows], case.refinement)
            for row, a, b in zip(rows, r_max, r_l1):
                cells = [
                    f"{name} {ndim}D", str(order), "×".join(map(str, row.shape)),
                    _fmt(row.h, ".4g"), _fmt(row.ball_cells, ".2f"),
                    _fmt(row.ours_max), _fmt(row.sk_max),
                    _fmt(row.ours_max / row.sk_max, ".2f"),
                    _fmt(row.ours_max / row.sk_ring_max, ".2f"),
                    _fmt(row.ours_l1), _fmt(row.sk_l1), _fmt(a, ".2f"), _fmt(b, ".2f"),
                ]
                lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def limits_table() -> str:
    """The "Limits" table of docs/eikonal.md (order 2, 2D, scikit-fmm from r0 = h/2)."""
    lines = [
        "| case | grid | h [m] | ball [cells] | ours max [s] | skfmm max [s] | ours / skfmm | "
        "ours L1 / skfmm L1 | rate max |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for label, case in LIMITS.items():
        rows = [_measure(case, 2, c) for c in case.cells]
        r_max = [math.nan] + rates([r.ours_max for r in rows], case.refinement)
        for row, a in zip(rows, r_max):
            cells = [
                label, "×".join(map(str, row.shape)), _fmt(row.h, ".4g"),
                _fmt(row.ball_cells, ".2f"), _fmt(row.ours_max), _fmt(row.sk_max),
                _fmt(row.ours_max / row.sk_max, ".2f"), _fmt(row.ours_l1 / row.sk_l1, ".2f"),
                _fmt(a, ".2f"),
            ]
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


BLOCKS = {"point-source-table": markdown_table, "point-source-limits": limits_table}


def _markers(block: str) -> tuple[str, str]:
    return (
        f"<!-- {block}:start (tests/eikonal/point_source_cases.py --write) -->",
        f"<!-- {block}:end -->",
    )


def table_in_doc(text: str, block: str = "point-source-table") -> str:
    """A generated block of docs/eikonal.md (between its two markers)."""
    start, end = _markers(block)
    m = re.search(re.escape(start) + r"\n(.*?)" + re.escape(end), text, re.S)
    if m is None:
        raise AssertionError(f"{DOC} has no block between {start!r} and {end!r}")
    return m.group(1).rstrip("\n")


def write_doc(tables: dict[str, str]) -> None:
    """Replace the generated blocks of docs/eikonal.md."""
    text = DOC.read_text()
    for block, table in tables.items():
        start, end = _markers(block)
        i = text.index(start) + len(start)
        j = text.index(end, i)
        text = text[:i] + "\n" + table + "\n" + text[j:]
    DOC.write_text(text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help=f"update the tables in {DOC}")
    args = parser.parse_args(argv)
    tables = {block: make() for block, make in BLOCKS.items()}
    for table in tables.values():
        print(table, end="\n\n")
    if args.write:
        write_doc(tables)
        print(f"written to {DOC}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
