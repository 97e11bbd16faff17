"""Analytic wind cases of the Zermelo eikonal solver: errors and convergence rates.

Shared by ``test_wind_analytic.py`` (which asserts on these numbers) and
``docs/eikonal.md`` (whose "Wind" accuracy table is this module's output)::

    .venv/bin/python tests/eikonal/wind_cases.py           # print the table
    .venv/bin/python tests/eikonal/wind_cases.py --write   # update docs/eikonal.md

Every case has airspeed ``V`` [m/s], wind ``w`` [m/s], a point source at the
centre node, and errors over the nodes at least 0.1 m from the source:

* ``constant``: V = 1, w = (0.4, 0.3) (2D) / (0.4, 0.3, 0.1) (3D) on the unit
  square / cube. Exact: the ``t`` of ``|x - w t| = V t``,
  ``t = (sqrt((w.x)^2 + (V^2 - |w|^2)|x|^2) - w.x) / (V^2 - |w|^2)``.
* ``spiral``: V = 1 + 0.5 r, w = -0.3 x + 0.5 (-y, x) (2D; 3D: -0.3 x + 0.5
  z^ x x, an inflow plus a solid rotation about the vertical) on [-1, 1]^d,
  r = |x|. The front is a circle (sphere) although the rays spiral: with
  ``grad T`` radial the rotation does not count and ``T' = 1 / (V + u)``,
  ``u = -0.3 r`` the radial wind, so ``T = ln(1 + 0.2 r) / 0.2``.
* ``shear``: Zermelo's linear current, V = 1, w = (0.5 y, 0) on [-1, 1]^2. The
  time-optimal headings turn as ``d theta / dt = -s cos^2 theta`` (s = 0.5), so
  from heading ``a`` at the source to ``b`` at the node ``T = (tan a - tan b) /
  s`` with closed-form positions ``y = (sec a - sec b) V / s``, ``x = -(V / s)
  [L(b) - L(a) + sec a (tan b - tan a) - S3(b) + S3(a)]`` (``L = ln|sec + tan|``,
  ``S3 = (sec tan + L) / 2``); ``(a, b)`` of each node are found by Newton's
  method from the solver's own heading (only a starting point: the result is an
  extremal through the node to 1e-12).
* ``strong crosswind``: V = 1, w = (0, 0.9) on the unit square: beyond the 2D
  stencil's causal limit (0.707), so the march corrects labels (the ``reopened``
  column).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fm2uav.eikonal.wind import heading, zermelo_march, zermelo_time

NEAR_SOURCE = 0.1  #: [m] the error norms exclude nodes nearer than this to the source
DOC = Path(__file__).resolve().parents[2] / "docs" / "eikonal.md"
SHEAR = 0.5  #: [1/s] the shear rate of the ``shear`` case


@dataclass(frozen=True)
class Field:
    """One grid of a case: speed, wind, spacing, source and the exact times."""

    speed: np.ndarray
    wind: np.ndarray
    h: float
    source: tuple[int, ...]
    r: np.ndarray  #: distance [m] of each node from the source
    exact: Callable[[np.ndarray], np.ndarray]  #: exact times, given the numerical result


def _grid(ndim: int, n: int, half: float) -> tuple[list[np.ndarray], float]:
    h = 2 * half / (n - 1)
    x = np.arange(n) * h - half
    return np.meshgrid(*([x] * ndim), indexing="ij"), h


def constant(ndim: int, n: int) -> Field:
    X, h = _grid(ndim, n, 0.5)
    w = np.array([0.4, 0.3, 0.1][:ndim])
    x = np.stack(X, axis=-1)
    exact = zermelo_time(x, 1.0, w)
    return Field(np.ones(X[0].shape), w, h, (n // 2,) * ndim,
                 np.linalg.norm(x, axis=-1), lambda T: exact)


def spiral(ndim: int, n: int) -> Field:
    X, h = _grid(ndim, n, 1.0)
    r = np.sqrt(sum(c * c for c in X))
    comps = [-0.3 * X[0] - 0.5 * X[1], -0.3 * X[1] + 0.5 * X[0]] + [-0.3 * c for c in X[2:]]
    exact = np.log1p(0.2 * r) / 0.2
    return Field(1 + 0.5 * r, np.stack(comps, axis=-1), h, (n // 2,) * ndim, r,
                 lambda T: exact)


def shear_extremal(phi0, t, sigma, V: float = 1.0, s: float = SHEAR):
    """Position [m] after the time ``t`` [s] on the extremal leaving the origin with
    heading ``theta_0`` (``phi0 = tan theta_0``, ``sigma`` the sign of its cosine,
    constant along the extremal) in the current w = (s y, 0).

    ``tan theta = phi0 - s t``; with ``sec theta = sigma sqrt(1 + tan^2)`` and
    ``ln|sec + tan| = sigma asinh(tan)`` the closed forms of the module
    docstring become (``q = sqrt(1 + phi^2)``, ``d = phi1 - phi0 = -s t``)
    ``y = V sigma t (phi0 + phi1) / (q0 + q1)`` and ``x = -(V / s) sigma
    [(asinh phi1 - asinh phi0) / 2 + d (1 - d (phi0 + phi1) + q0 q1 - phi0 phi1)
    / (2 (q0 + q1))]``, each difference written without cancellation (the
    headings may be nearly vertical, where ``phi`` is large).
    """
    phi1 = phi0 - s * t
    d = -s * t
    q0, q1 = np.sqrt(1 + phi0 * phi0), np.sqrt(1 + phi1 * phi1)
    same = phi0 * phi1 > 0
    with np.errstate(all="ignore"):
        qq = np.where(same, (1 + phi0 * phi0 + phi1 * phi1) / (q0 * q1 + phi0 * phi1),
                      q0 * q1 - phi0 * phi1)
        da = np.where(same, np.arcsinh(d * (phi0 + phi1) / (phi1 * q0 + phi0 * q1)),
                      np.arcsinh(phi1) - np.arcsinh(phi0))
    y = V * sigma * t * (phi0 + phi1) / (q0 + q1)
    x = -(V / s) * sigma * (0.5 * da + d * (1 - d * (phi0 + phi1) + qq) / (2 * (q0 + q1)))
    return x, y


def _newton(X, Y, phi0, t, sigma):
    """Newton's method on ``(tan theta_0, T)``; returns ``T`` and the position residual."""
    phi0, t = phi0.copy(), t.copy()
    live = np.ones(X.shape, dtype=bool)
    with np.errstate(all="ignore"):
        for _ in range(40):
            i = np.flatnonzero(live)
            if i.size == 0:
                break
            p, tt, sg = phi0[i], t[i], sigma[i]
            x, y = shear_extremal(p, tt, sg)
            fx, fy = x - X[i], y - Y[i]
            done = ~(np.abs(fx) + np.abs(fy) >= 1e-14)  # converged, or NaN (given up)
            live[i[done]] = False
            ep = 1e-7 * np.maximum(1.0, np.abs(p))
            xa, ya = shear_extremal(p + ep, tt, sg)
            xb, yb = shear_extremal(p, tt + 1e-7, sg)
            j11, j12 = (xa - x) / ep, (xb - x) / 1e-7
            j21, j22 = (ya - y) / ep, (yb - y) / 1e-7
            det = j11 * j22 - j12 * j21
            dphi = (j22 * fx - j12 * fy) / det
            dt = (-j21 * fx + j11 * fy) / det
            # damped: at most 0.2 s in time and 0.5 (1 + |phi0|) in tan per step
            k = np.minimum(1.0, np.minimum(0.2 / np.abs(dt), 0.5 * (1 + np.abs(p)) / np.abs(dphi)))
            k = np.where(np.isfinite(k) & ~done, k, 0.0)
            phi0[i], t[i] = p - k * dphi, tt - k * dt
        x, y = shear_extremal(phi0, t, sigma)
        res = np.abs(x - X) + np.abs(y - Y)
    return t, np.where(np.isfinite(res), res, np.inf)


def shear_times(X: np.ndarray, Y: np.ndarray, T0: np.ndarray, b0: np.ndarray) -> np.ndarray:
    """Exact times [s] at ``(X, Y)`` by Newton's method on ``(tan theta_0, T)``,
    started from approximate times ``T0`` and final headings ``b0``; where the
    heading is near vertical both signs of its cosine are tried, and the
    earliest extremal through the node is kept."""
    best = np.full(X.shape, np.inf)
    tan0 = np.clip(np.tan(b0), -30.0, 30.0)  # a vertical heading: start a little off it
    for sign in (1.0, -1.0):
        sigma = np.full(X.shape, sign)
        phi0 = tan0 + SHEAR * T0
        phi0 = np.where(np.sign(np.cos(b0)) == sign, phi0, -phi0)  # the mirrored start
        t, res = _newton(X, Y, phi0, T0, sigma)
        ok = (res < 1e-10) & (t > 0)
        best = np.where(ok & (t < best), t, best)
    # the vertical extremal (heading +-90 degrees throughout: tan = inf, outside the
    # parametrisation) reaches x = s y |y| / (2 V) at t = |y| / V
    vertical = np.isinf(best) & (np.abs(X - SHEAR * Y * np.abs(Y) / 2) < 1e-12)
    best = np.where(vertical, np.abs(Y), best)
    assert np.all(np.isfinite(best)), "Newton did not converge"
    return best


def shear(ndim: int, n: int) -> Field:
    assert ndim == 2
    X, h = _grid(2, n, 1.0)
    w = np.stack([SHEAR * X[1], np.zeros_like(X[1])], axis=-1)
    r = np.hypot(*X)

    def exact(res) -> np.ndarray:
        out = np.zeros_like(r)
        far = r > 0
        hd = heading(res.track[far], 1.0, w[far])
        out[far] = shear_times(X[0][far], X[1][far], res.times[far],
                               np.arctan2(hd[:, 1], hd[:, 0]))
        return out

    return Field(np.ones_like(r), w, h, (n // 2, n // 2), r, exact)


def strong(ndim: int, n: int) -> Field:
    X, h = _grid(ndim, n, 0.5)
    w = np.array([0.0, 0.9][:ndim])
    x = np.stack(X, axis=-1)
    exact = zermelo_time(x, 1.0, w)
    return Field(np.ones(X[0].shape), w, h, (n // 2,) * ndim,
                 np.linalg.norm(x, axis=-1), lambda T: exact)


#: (name, ndim) -> (field maker, grid sizes measured by the tests; the docs table adds
#: the sizes after the bar)
CASES: dict[tuple[str, int], tuple[Callable[[int, int], Field], tuple[int, ...], tuple[int, ...]]] = {
    ("constant", 2): (constant, (41, 81, 161), (321,)),
    ("spiral", 2): (spiral, (41, 81, 161), (321,)),
    ("shear", 2): (shear, (41, 81, 161), (321,)),
    ("strong crosswind", 2): (strong, (41, 81, 161), (321,)),
    ("constant", 3): (constant, (21, 41, 81), (161,)),
    ("spiral", 3): (spiral, (21, 41, 81), (161,)),
}


@dataclass(frozen=True)
class Row:
    name: str
    ndim: int
    order: int
    n: int
    h: float
    err_max: float
    err_l1: float
    reopened: int


def measure_one(name: str, ndim: int, order: int, n: int) -> Row:
    make = CASES[(name, ndim)][0]
    f = make(ndim, n)
    res = zermelo_march(f.speed, [f.source], f.wind, spacing=f.h, order=order,
                        track=name == "shear")
    exact = f.exact(res)
    mask = f.r >= NEAR_SOURCE
    err = np.abs(res.times - exact)[mask]
    return Row(name, ndim, order, n, f.h, float(err.max()), float(err.mean()), res.reopened)


def measure(name: str, ndim: int, order: int, full: bool = False) -> list[Row]:
    _, sizes, more = CASES[(name, ndim)]
    return [measure_one(name, ndim, order, n) for n in sizes + (more if full else ())]


def rates(errors: list[float]) -> list[float]:
    """Convergence rates between consecutive grids (spacing halved)."""
    return [math.log2(a / b) for a, b in zip(errors, errors[1:])]


TABLE_HEADER = [
    "| case | order | grid | h [m] | max error [s] | L1 error [s] | rate max | rate L1 | "
    "reopened |",
    "|---|---|---|---|---|---|---|---|---|",
]


def _fmt(x: float, spec: str = ".3g") -> str:
    return "–" if math.isnan(x) else format(x, spec)


def markdown_table(full: bool = True) -> str:
    lines = list(TABLE_HEADER)
    for order in (2, 1):
        for name, ndim in CASES:
            rows = measure(name, ndim, order, full)
            r_max = [math.nan] + rates([r.err_max for r in rows])
            r_l1 = [math.nan] + rates([r.err_l1 for r in rows])
            for row, a, b in zip(rows, r_max, r_l1):
                cells = [f"{name} {ndim}D", str(order), "×".join([str(row.n)] * ndim),
                         _fmt(row.h, ".4g"), _fmt(row.err_max), _fmt(row.err_l1),
                         _fmt(a, ".2f"), _fmt(b, ".2f"), str(row.reopened)]
                lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


MARKERS = ("<!-- wind-table:start (tests/eikonal/wind_cases.py --write) -->",
           "<!-- wind-table:end -->")


def table_in_doc(text: str) -> str:
    """The generated table of docs/eikonal.md (between its two markers)."""
    start, end = MARKERS
    i = text.index(start) + len(start)
    return text[i:text.index(end, i)].strip("\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help=f"update the table in {DOC}")
    args = parser.parse_args(argv)
    table = markdown_table()
    print(table)
    if args.write:
        text = DOC.read_text()
        start, end = MARKERS
        i = text.index(start) + len(start)
        j = text.index(end, i)
        DOC.write_text(text[:i] + "\n" + table + "\n" + text[j:])
        print(f"written to {DOC}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
