"""Shaping.saturation_distance: the safety margin means the same on any map size."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.planning import Shaping, plan
from fm2uav.world import World
from fm2uav.world.clearance import surface_clearance


def _world(extra: int) -> World:
    # a wall with a 12 m gap at x = 50; `extra` metres of open field added around the map
    occ = np.zeros((100 + 2 * extra, 60 + 2 * extra), bool)
    occ[extra + 48:extra + 52, extra:extra + 24] = True
    occ[extra + 48:extra + 52, extra + 36:extra + 60] = True
    return World(occ, spacing=1.0, origin=(-extra, -extra))


def _margin(shaping: Shaping, extra: int) -> float:
    p = plan(_world(extra), (10.0, 30.0), (90.0, 30.0), shaping=shaping)
    return float(surface_clearance(p.world, p.path).min())


def test_saturation_distance_gives_the_same_margin_on_two_map_sizes():
    s = Shaping(saturation_distance=5.0, exponent=2.0)
    small, large = _margin(s, 0), _margin(s, 150)
    assert small == pytest.approx(large, abs=0.05)
    assert small > 3.0  # the path keeps to the middle of the gap (6 m from each side)


def test_relative_saturation_does_not():
    s = Shaping(saturation=0.1, exponent=2.0)
    small, large = _margin(s, 0), _margin(s, 150)
    assert abs(small - large) > 0.2
