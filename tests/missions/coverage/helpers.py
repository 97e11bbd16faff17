"""Seeded random areas and the checkers the judged properties use."""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon


def random_polygon(rng: np.random.Generator, *, holes: bool = False) -> Polygon:
    """A random non-convex (star-shaped) polygon around (700, 700) m, maybe with a hole."""
    while True:
        n = int(rng.integers(5, 18))
        ang = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(150, 600, n)
        p = Polygon(np.column_stack([r * np.cos(ang), r * np.sin(ang)]) + 700.0)
        if not p.is_valid or p.area < 1e4:
            continue
        if holes:
            c = p.representative_point()
            hole = shapely.Point(c.x, c.y).buffer(rng.uniform(20, 80), quad_segs=4)
            if p.buffer(-5).contains(hole):
                p = Polygon(p.exterior.coords, [hole.exterior.coords])
        return p


def excess_outside(area: Polygon, lines, spacing: float) -> float:
    """Largest distance [m] by which the lines leave ``area`` enlarged by D/2."""
    worst = 0.0
    for seg in lines:
        pts = shapely.get_coordinates(shapely.segmentize(seg, spacing / 50.0))
        d = shapely.distance(shapely.points(pts), area).max()
        worst = max(worst, float(d) - spacing / 2.0)
    return worst
