"""plan.png (fm2uav.viz.figures.plan_figure): unknown ground is marked and its length said."""

from __future__ import annotations

import numpy as np

import fm2uav
from fm2uav import World
from fm2uav.analysis.known_ground import ground_split
from fm2uav.viz import plan_figure


def _world():
    x = np.arange(40)[:, None] * 25.0
    h = 100.0 + 0.05 * x + np.zeros((40, 24))
    filled = np.zeros((40, 24), bool)
    filled[15:25, :] = True  # a band of filled nodata across the map
    return World.from_heightmap(h, (25.0, 25.0, 10.0), 30).with_fields(filled=filled)


def test_the_path_over_filled_ground_is_marked_and_its_length_said():
    w = _world()
    p = fm2uav.plan(w, (50.0, 300.0, 180.0), (925.0, 300.0, 190.0),
                    level=fm2uav.FlightLevel(agl=60.0))
    split = ground_split(w, p.path, p.path[:, 2] - w.ground_height(p.path[:, 0], p.path[:, 1]))
    fig = plan_figure(p, title="t", ground=split)
    sub = fig.texts[0].get_text()
    km = split["filled"]["length_m"] / 1000
    assert f"WARNING: {km:.2f} km of" in sub and "FILLED DEM nodata" in sub
    top, side = fig.axes[:2]
    labels = [t.get_text() for t in top.get_legend().get_texts()]
    assert "path over FILLED ground" in labels and "filled DEM nodata (unknown ground)" in labels
    assert "over FILLED ground (invented heights)" in [t.get_text()
                                                       for t in side.get_legend().get_texts()]
    spans = [a for a in side.patches if a.get_alpha() == 0.15]
    assert len(spans) == split["filled"]["stretch_count"]


def test_no_note_without_unknown_ground():
    sc = fm2uav.scenarios.get_scenario("open-field")
    p = fm2uav.plan(sc.world, sc.start, sc.goal)
    fig = plan_figure(p, title="t")
    assert "FILLED" not in fig.texts[0].get_text()
