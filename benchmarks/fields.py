"""Speed fields of the Fast Marching benchmarks, the same in every benchmark child.

* :func:`smooth`: ``1 + 0.4 sum_k sin(3 x_k)`` on the unit cube, source at the centre;
* :func:`fm2_shaped`: what an FM² plan marches over (issue 27): discs (2D) or balls (3D) of
  random centres and radii 1-5 % of the grid (seed 0) as obstacles until they cover a quarter
  of the nodes, speed 0 inside them, ``W = (d / d_max)^0.5`` outside (``d`` the exact
  distance to the nearest obstacle node, so W rises from 0 at the walls and is < 1 almost
  everywhere), the source off-centre: the node with ``W >= 0.5`` nearest to
  ``(0.3, 0.6, 0.45)`` of the grid.
"""

from __future__ import annotations

import numpy as np

__all__ = ["smooth", "fm2_shaped", "skfmm_point_source"]


def smooth(shape: tuple[int, ...]) -> tuple[np.ndarray, tuple[int, ...]]:
    """The smooth speed field [m/s] and its source (the centre node)."""
    axes = np.meshgrid(*[np.linspace(0, 1, n) for n in shape], indexing="ij")
    v = np.ones(shape)
    for a in axes:
        v += 0.4 * np.sin(3.0 * a)
    return v, tuple(n // 2 for n in shape)


def fm2_shaped(shape: tuple[int, ...], seed: int = 0,
               share: float = 0.25) -> tuple[np.ndarray, tuple[int, ...]]:
    """An FM²-shaped speed field (module docstring) and its source node."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    n = np.asarray(shape)
    occ = np.zeros(shape, dtype=bool)
    covered = 0
    while covered < share * occ.size:
        c = rng.random(len(shape)) * n
        r = (0.01 + 0.04 * rng.random()) * n.min()
        lo = np.maximum(np.floor(c - r).astype(int), 0)
        hi = np.minimum(np.ceil(c + r).astype(int) + 1, n)
        box = tuple(slice(a, b) for a, b in zip(lo, hi))
        axes = np.meshgrid(*[np.arange(a, b) for a, b in zip(lo, hi)], indexing="ij",
                           sparse=True)
        new = (sum((a - ci) ** 2 for a, ci in zip(axes, c)) <= r * r) & ~occ[box]
        covered += int(new.sum())
        occ[box] |= new
    d = ndimage.distance_transform_edt(~occ)
    W = np.sqrt(d / d.max())
    target = (n * np.array([0.3, 0.6, 0.45][: len(shape)])).astype(int)
    free = np.argwhere(W >= 0.5)
    src = tuple(int(x) for x in free[np.argmin(((free - target) ** 2).sum(axis=1))])
    return W, src


def skfmm_point_source(v: np.ndarray, src: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """scikit-fmm's input for the same problem: ``phi`` (zero contour a half-cell circle
    around the source, masked on the speed-0 nodes) and a speed without zeros."""
    axes = np.meshgrid(*[np.arange(n) - s for n, s in zip(v.shape, src)], indexing="ij")
    phi = np.sqrt(sum(a.astype(float) ** 2 for a in axes)) - 0.5
    wall = v <= 0
    if wall.any():
        return np.ma.MaskedArray(phi, wall), np.where(wall, 1.0, v)
    return phi, v
