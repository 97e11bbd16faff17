"""Marches of the layout tests (``test_kernels_layout.py``): FM²-shaped speed fields (walls
of speed 0, ``W = (d / d_max)^0.5`` outside them), a uniform one, in 2D and 3D, with the
options whose code paths differ (order, anisotropic spacing, ``stop_at``, many sources)."""

from __future__ import annotations

import numpy as np

from fm2uav.eikonal import distance_map


def fm2_field(shape, seed):
    """Discs (balls) of speed 0 on ~a fifth of the nodes, ``W = (d / d_max)^0.5`` outside."""
    rng = np.random.default_rng(seed)
    n = np.asarray(shape)
    axes = np.meshgrid(*[np.arange(k) for k in shape], indexing="ij")
    occ = np.zeros(shape, dtype=bool)
    while occ.mean() < 0.2:
        c = rng.random(len(shape)) * n
        r = (0.03 + 0.07 * rng.random()) * n.min()
        occ |= sum((a - ci) ** 2 for a, ci in zip(axes, c)) <= r * r
    d = distance_map(occ)
    return np.sqrt(d / d.max())


def free_near(v, frac):
    """The free node nearest to ``frac`` of the grid (per axis)."""
    free = np.argwhere(v >= 0.5 * v.max())
    target = (np.asarray(v.shape) * np.asarray(frac[: v.ndim])).astype(int)
    return tuple(int(x) for x in free[np.argmin(((free - target) ** 2).sum(axis=1))])


def cases():
    """``name -> (speed, sources, options of fast_marching)``."""
    out = {}
    v2 = fm2_field((97, 83), 0)
    src2 = [free_near(v2, (0.3, 0.6))]
    for order in (1, 2):
        out[f"2d fm2 o{order}"] = (v2, src2, dict(order=order))
        out[f"2d fm2 o{order} anisotropic"] = (v2, src2, dict(order=order, spacing=(0.7, 1.1)))
    out["2d fm2 o1 stop_at"] = (v2, src2, dict(order=1, stop_at=[free_near(v2, (0.9, 0.1))]))
    rng = np.random.default_rng(1)
    many = np.argwhere(v2 > 0.3)
    many = [tuple(int(x) for x in p) for p in many[rng.choice(len(many), 70, replace=False)]]
    for order in (1, 2):
        out[f"2d fm2 o{order} 70 sources"] = (v2, many, dict(order=order))
    walls = np.ones((64, 71))
    walls[rng.random(walls.shape) < 0.1] = 0.0
    walls[20, 30] = 1.0
    out["2d uniform o1"] = (walls, [(20, 30)], dict(order=1, source_ball=False))
    v3 = fm2_field((23, 19, 17), 2)
    src3 = [free_near(v3, (0.3, 0.6, 0.45))]
    for order in (1, 2):
        out[f"3d fm2 o{order}"] = (v3, src3, dict(order=order))
    return out
