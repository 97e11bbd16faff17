"""Coverage flights around no-fly zones (missions/coverage/zones.py): bands the route
resolves, straight bands with FM² legs only across the zones, ceilings flown over, and the
band ends every camera trigger needs (issue 25: narrow bands failed with "band 65: the path
does not fly it forward ... is it this zigzag's path?")."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from fm2uav.errors import InputError
from fm2uav.missions.coverage import plan_coverage
from fm2uav.missions.coverage.triggers import camera_plan
from fm2uav.missions.coverage.zones import ROUTE_BAND_CELLS, route_cell
from fm2uav.planning import FlightLevel
from fm2uav.world import World
from fm2uav.world.zones import Zone, with_zones, zone_violations


def _hills(cell=10.0, nx=60, ny=40):
    x = np.arange(nx) * cell
    y = np.arange(ny) * cell
    h = 20.0 + 10.0 * np.sin(x / 90.0)[:, None] + 6.0 * np.cos(y / 70.0)[None, :]
    return World.from_heightmap(h, cell, int(200 / cell))


AREA = Polygon([(60, 60), (540, 60), (540, 330), (60, 330)])


def test_bands_closer_than_the_route_resolves_name_the_flags():
    world = _hills()
    zone = Zone(Polygon([(270, 20), (330, 20), (330, 370), (270, 370)]), name="strip")
    wz = with_zones(world, [zone])
    with pytest.raises(InputError) as e:
        plan_coverage(wz, AREA, 20.0, level=FlightLevel(agl=60.0), angle=0.0)
    msg = str(e.value)
    assert "--cell-size 8" in msg and "bands at least 25 m apart (--spacing)" in msg and "\n" not in msg
    assert route_cell(20.0) == 20.0 / ROUTE_BAND_CELLS


def test_a_ceiling_strip_across_the_area_is_flown_over_and_every_band_is_flown():
    world = _hills()
    strip = Polygon([(270, 20), (330, 20), (330, 370), (270, 370)])
    zone = Zone(strip, name="low", ceiling=40.0, reference="agl", buffer=5.0)
    wz = with_zones(world, [zone])
    cp = plan_coverage(wz, AREA, 30.0, level=FlightLevel(agl=60.0), angle=0.0)
    assert cp.params["grid"] == "route"
    # straight bands; FM² legs only where a segment crosses the strip
    route_params = cp.plan.params
    assert route_params["straight_segments"] > route_params["legs"] >= 1
    assert zone_violations(wz, cp.path, step=0.5) == []
    # the whole flight is at the flight level over the ground (the final profile), so the
    # strip (ceiling 40 m AGL + 5 m) is flown over, not around
    h = cp.path[:, 2] - world.ground_height(cp.path[:, 0], cp.path[:, 1])
    cruise = cp.plan.profile.phase == "cruise"
    assert h[cruise].min() >= 60.0 - 2.0 - 1e-6
    inside = shapely.contains_xy(strip.buffer(5.0), cp.path[:, 0], cp.path[:, 1])
    assert inside.any() and h[inside].min() >= 45.0 - 1e-3
    # every band is found on the flown path, in order (the camera triggers need it)
    shots = camera_plan(cp)
    assert len(shots.bands) == cp.zigzag.n_bands
    assert all(a < b for a, b in shots.bands)
    assert shots.info["band_end_mismatch_m"] < 2 * world.spacing[0]
    # all but the strip and its margin (two cells) is covered
    kept = AREA.difference(zone.keep_out(2 * world.spacing[0])).area / AREA.area
    assert kept - 0.02 < cp.coverage <= 1.0
