"""Zones become .plan geofences (exclusion / inclusion, polygons / circles)."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.autopilot.geofence import (
    FenceCircle,
    FencePolygon,
    fence_statement,
    statement_warning,
    zone_fences,
)
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
    assert warnings == []  # the zone 'low' is stated by fence_statement (below)
    st = fence_statement(zones, fences, firmware="px4", home_amsl=100.0)
    assert [e["zone"] for e in st["not_carried"]] == ["low"]
    assert st["not_carried"][0]["ceiling_m"] == 80 and "2D" in st["limits"]
    assert [c["zone"] for c in st["carried"]] == ["wall", "c", "operating area 4"]
    line = statement_warning(st)
    assert "'low' (ceiling 80 m AMSL" in line and "left out of geoFence" in line
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


def test_ardupilot_altitude_fence_only_where_it_represents_the_zone():
    """FENCE_ALT_MAX / _MIN are metres above home over the whole flight: they stand for an
    operating area's AMSL ceiling / floor (home's altitude known) or an AGL one over flat
    ground, never for a no-fly zone's local limits."""
    w = get_scenario("open-field").world
    area = zone_from_mapping({"polygon": [[10, 10], [1700, 10], [1700, 1300], [10, 1300]],
                              "ceiling": 600, "floor": 150, "buffer": 10, "name": "ops"},
                             inclusion=True)
    agl_area = zone_from_mapping({"polygon": [[10, 10], [1700, 10], [1700, 1300], [10, 1300]],
                                  "ceiling": 120, "reference": "agl", "name": "ops"},
                                 inclusion=True)
    nofly = zone_from_mapping({"polygon": [[0, 0], [50, 0], [50, 50]], "ceiling": 80,
                               "name": "low"})
    fences, _ = zone_fences([area, nofly], w)
    st = fence_statement([area, nofly], fences, firmware="ardupilot", home_amsl=250.0)
    p = st["ardupilot_parameters"]["ops"]
    assert p["FENCE_ALT_MAX"] == 600 - 10 - 250 and p["FENCE_ALT_MIN"] == 150 + 10 - 250
    assert p["FENCE_TYPE_bits"] == 1 | 8
    low = next(e for e in st["not_carried"] if e["zone"] == "low")
    assert "cannot represent" in low["ardupilot"]
    # AGL over uneven ground or an unknown home altitude: no parameter claims to hold it
    st2 = fence_statement([agl_area], zone_fences([agl_area], w)[0], firmware="ardupilot",
                          home_amsl=250.0, flat_ground=False)
    assert "ardupilot_parameters" not in st2 and "cannot represent" in \
        st2["not_carried"][0]["ardupilot"]
    st3 = fence_statement([agl_area], [], firmware="ardupilot", flat_ground=True)
    assert st3["ardupilot_parameters"]["ops"]["FENCE_ALT_MAX"] == 120.0
    assert "ardupilot_parameters" not in fence_statement([area], [], firmware="px4",
                                                         home_amsl=250.0)
