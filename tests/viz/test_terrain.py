"""fm2uav.viz.terrain: shaded relief and contour lines of an elevation grid."""

from __future__ import annotations

import math

import numpy as np
import pytest
from affine import Affine

from fm2uav.viz.terrain import contour_interval, contour_lines, hillshade, shaded_relief


def test_hillshade_lights_slopes_facing_the_sun():
    x = np.arange(20.0)
    facing = np.tile(x, (20, 1))           # rises to the east: faces west, towards the sun
    # (azimuth 315°: the north-west); one falling to the east faces away from it
    away = -facing
    assert hillshade(facing, 1.0)[10, 10] > hillshade(np.zeros((20, 20)), 1.0)[10, 10]
    assert hillshade(away, 1.0)[10, 10] < hillshade(np.zeros((20, 20)), 1.0)[10, 10]
    # a 45° slope facing the sun exactly (falling to the north-west; rows run north →
    # south) is lit square on
    yy, xx = np.mgrid[0:20, 0:20].astype(float)
    nw = (xx + yy) / math.sqrt(2)
    assert hillshade(nw, 1.0)[10, 10] == pytest.approx(1.0, abs=1e-9)


def test_shaded_relief_tints_by_height_and_leaves_nodata_transparent():
    z = np.linspace(0, 100, 25).reshape(5, 5)
    z[0, 0] = np.nan
    img = shaded_relief(z, 1.0, (0.0, 100.0))
    assert img.shape == (5, 5, 4) and img.dtype == np.uint8
    assert img[0, 0, 3] == 0 and (img[..., 3].ravel()[1:] == 255).all()
    assert not np.array_equal(img[1, 0, :3], img[4, 4, :3])


@pytest.mark.parametrize("lo, hi, step", [(0, 1, 0.1), (100, 400, 20), (0, 3000, 200),
                                          (250, 260, 1)])
def test_contour_interval_is_round(lo, hi, step):
    assert contour_interval(lo, hi) == step


def test_contours_of_a_cone_are_circles_at_the_right_radius():
    n = 101
    yy, xx = np.mgrid[0:n, 0:n].astype(float)
    # pixel (col, row) centres at map x = col + 0.5, y = -(row + 0.5) (a north-up raster)
    cx, cy = 50.5, -50.5
    r = np.hypot(xx + 0.5 - cx, -(yy + 0.5) - cy)
    feats = contour_lines(r, Affine(1, 0, 0, 0, -1, 0), 10.0)
    assert [f["properties"]["elevation"] for f in feats] == [0.0, 10.0, 20.0, 30.0, 40.0, 50.0,
                                                             60.0, 70.0][1:len(feats) + 1]
    for f in feats:
        level = f["properties"]["elevation"]
        pts = np.array([p for line in f["geometry"]["coordinates"] for p in line])
        dist = np.hypot(pts[:, 0] - cx, pts[:, 1] - cy)
        if level <= 40:   # whole circles inside the grid
            assert dist == pytest.approx(level, abs=0.05)
    assert feats[4]["properties"]["index"] is True and feats[0]["properties"]["index"] is False
    assert contour_lines(np.full((3, 3), np.nan), Affine.identity(), 1.0) == []
