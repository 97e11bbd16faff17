"""Top views in lon/lat (fm2uav.viz.mapfigure): plan.png draws buildings and no-fly zones where
they are, and the lon/lat tick labels never collide, at any figure size or map extent."""

from __future__ import annotations

import io

import numpy as np
import pytest
import shapely
from matplotlib.figure import Figure

import fm2uav
from fm2uav import World
from fm2uav.viz import plan_figure
from fm2uav.viz.mapfigure import LonLatMap
from fm2uav.world.zones import Zone, with_zones


def _city() -> World:
    """600 m x 400 m of flat ground at 50 m with one 60 m x 60 m, 80 m tall building at
    x 240..300, y 160..220 and a no-fly zone x 420..540, y 40..160 (0..300 m AMSL)."""
    ground = World.from_heightmap(np.full((61, 41), 50.0), (10.0, 10.0, 10.0), 30)
    occ = np.array(ground.occupancy)
    occ[24:31, 16:23, :14] = True                          # the building, roof at 130 m
    w = ground.with_fields(occupancy=occ, name="block")
    zone = Zone(shapely.box(420, 40, 540, 160), name="hospital", floor=0.0, ceiling=300.0)
    return with_zones(w, [zone])


@pytest.fixture(scope="module")
def city_plan():
    w = _city()
    return fm2uav.plan(w, (30.0, 30.0, 110.0), (570.0, 370.0, 110.0),
                       level=fm2uav.FlightLevel(agl=60.0))


def _pixels(fig: Figure) -> tuple[np.ndarray, int]:
    """The figure rendered at 100 dpi as an RGB array, and its height in pixels."""
    from PIL import Image

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    img = np.asarray(Image.open(io.BytesIO(buf.getvalue())).convert("RGB"), dtype=float)
    return img, img.shape[0]


def _at(img: np.ndarray, ax, m: LonLatMap, xy_m) -> np.ndarray:
    """The mean colour of a 5 x 5 pixel patch at the world point ``xy_m`` [m]."""
    ll = m.lonlat(np.asarray([xy_m], dtype=float))[0]
    px, py = ax.transData.transform(ll)
    r, c = int(round(img.shape[0] - py)), int(round(px))
    return img[r - 2:r + 3, c - 2:c + 3].reshape(-1, 3).mean(axis=0)


def test_plan_png_draws_the_building_and_the_no_fly_zone_where_they_are(city_plan):
    fig = plan_figure(city_plan, title="block")
    fig.set_dpi(100)
    ax = fig.axes[0]
    m = LonLatMap.__new__(LonLatMap)          # only its lon/lat conversion
    m.world, m.anchor = city_plan.world, None
    img, _ = _pixels(fig)
    building = _at(img, ax, m, (270.0, 190.0))
    zone = _at(img, ax, m, (480.0, 70.0))
    open_ground = _at(img, ax, m, (150.0, 330.0))
    # the building: dark grey (#5f5f66 over the relief); the open ground: green lowland
    assert building.max() < 130 and np.ptp(building) < 15, building
    assert open_ground[1] - max(open_ground[0], open_ground[2]) > 25, open_ground
    # the zone: the same ground tinted red (a 22 % red fill): redder, less green
    assert zone[0] - open_ground[0] > 10 and open_ground[1] - zone[1] > 10, (zone, open_ground)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "buildings (1)" in labels and "no-fly zone" in labels
    assert any("hospital" in t.get_text() and "0–300 m AMSL" in t.get_text()
               for t in ax.texts)


def test_a_zone_outside_the_map_leaves_no_label_outside_it():
    w = with_zones(World.from_heightmap(np.zeros((31, 21)), 10.0, 10),
                   [Zone(shapely.box(500, 0, 600, 100), name="far away")])
    fig = Figure(figsize=(6, 5))
    ax = fig.add_subplot()
    LonLatMap(ax, w)
    assert not any("far away" in t.get_text() for t in ax.texts)


def _overlaps(boxes) -> list[tuple[int, int]]:
    return [(i, j) for i in range(len(boxes)) for j in range(i + 1, len(boxes))
            if boxes[i].overlaps(boxes[j])]


@pytest.mark.parametrize("size_m, figsize", [
    ((600.0, 400.0), (4.0, 3.5)),        # a small figure: few ticks
    ((600.0, 400.0), (14.0, 6.0)),
    ((48_000.0, 30_000.0), (6.0, 4.0)),  # a regional map: labels with fewer decimals
    ((2_000.0, 9_000.0), (8.0, 6.0)),    # tall and narrow
])
def test_lonlat_tick_labels_never_overlap(size_m, figsize):
    nx, ny = 41, 31
    h = np.zeros((nx, ny))
    w = World.from_heightmap(h, (size_m[0] / (nx - 1), size_m[1] / (ny - 1), 10.0), 5)
    fig = Figure(figsize=figsize)
    ax = fig.add_subplot()
    LonLatMap(ax, w, contours=False)
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    for axis, name in ((ax.xaxis, "lon"), (ax.yaxis, "lat")):
        labels = [t for t in axis.get_ticklabels() if t.get_visible() and t.get_text()]
        assert len(labels) >= 1, (name, [t.get_text() for t in labels])
        boxes = [t.get_window_extent(renderer).expanded(1.05, 1.0) for t in labels]
        assert not _overlaps(boxes), (name, [t.get_text() for t in labels])
        texts = [t.get_text() for t in labels]
        assert len(set(texts)) == len(texts), texts          # no two ticks read the same
        assert all(t.endswith(("E", "W") if name == "lon" else ("N", "S")) for t in texts)
