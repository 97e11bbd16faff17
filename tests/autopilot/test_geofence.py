"""Zones become .plan geofences (exclusion / inclusion, polygons / circles)."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.autopilot.geofence import FenceCircle, FencePolygon, zone_fences
from fm2uav.io.qgc import geofence_document
from fm2uav.world.geo import from_lonlat
from fm2uav.scenarios import get_scenario
from fm2uav.world.zones import zone_from_mapping


def test_zone_fences_kinds_and_positions():
    w = get_scenario("open-field").world
    zones = [zone_from_mapping({"polygon": [[700, 300], [900, 300], [900, 1000]],
                                "buffer": 30, "name": "wall"}),
             zone_from_mapping({"circle": {"center": [400, 900], "radius": 120}, "name": "c"}),
             zone_from_mapping({"polygon": [[0, 0], [50, 0], [50, 50]], "ceiling": 80,
                                "name": "low"}),
             zone_from_mapping({"polygon": [[10, 10], [1700, 10], [1700, 1300], [10, 1300]]},
                               inclusion=True)]
    fences, warnings = zone_fences(zones, w)
    kinds = [(type(f).__name__, f.inclusion) for f in fences]
    assert kinds == [("FencePolygon", False), ("FenceCircle", False), ("FencePolygon", True)]
    assert len(warnings) == 1 and "low" in warnings[0] and "2D" in warnings[0]
    # the polygon's vertices go back to the zone's metres (no buffer in the fence)
    lat, lon = np.array(fences[0].points).T
    back = from_lonlat(w, np.column_stack([lon, lat]))
    got = np.array(sorted(map(tuple, np.round(back[:, :2], 3))))
    np.testing.assert_allclose(got, [(700, 300), (900, 300), (900, 1000)], atol=0.01)
    c = fences[1]
    assert isinstance(c, FenceCircle) and c.radius == 120.0
    doc = geofence_document(fences)
    assert len(doc["polygons"]) == 2 and len(doc["circles"]) == 1
    assert doc["polygons"][1]["inclusion"] is True
    assert isinstance(fences[0], FencePolygon)
