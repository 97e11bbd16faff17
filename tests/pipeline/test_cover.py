"""fm2uav.pipeline.cover: what fm2uav cover and the app's cover job share."""

from fm2uav.missions.coverage.zones import ROUTE_BAND_CELLS
from fm2uav.pipeline.cover import band_cell


def test_a_survey_around_zones_caps_the_automatic_cell_and_says_why():
    assert band_cell(20.0, zones=False) is None  # the corridor grid resolves any spacing
    cell, why = band_cell(20.0, zones=True)
    assert cell == 20.0 / ROUTE_BAND_CELLS == 8.0
    assert why == ("at most D / 2.5 = 8 m so that the route around the no-fly zones resolves "
                   "the bands")
