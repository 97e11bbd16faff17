"""The missions' warm-up (``make install``) compiles what later surveys call."""

from __future__ import annotations

import pytest

from fm2uav.missions import warmup
from tests.planning.warmup_layer_probe import assert_covers

#: Later calls: an area with a hole and integer corners, the optimiser's array of angles,
#: the bands at another angle.
LATER = """
import numpy as np
from shapely.geometry import Polygon
from fm2uav.missions.coverage.bands import zigzag
from fm2uav.missions.coverage.cost import ZigzagCost
area = Polygon([(0, 0), (300, 0), (300, 200), (0, 200)], [[(100, 50), (150, 50), (150, 90)]])
ZigzagCost.of(area, 25.0)(np.linspace(0.0, 180.0, 19))
zigzag(area, 25, 1.2)
"""


@pytest.mark.slow
@pytest.mark.parametrize("kernel", ["zigzag_cost", "strip_extents", "band_ends"])
def test_a_later_survey_needs_no_signature_the_warm_up_did_not_compile(kernel):
    assert_covers("fm2uav.missions.warmup", f"fm2uav.missions.coverage._kernels:{kernel}",
                  LATER)


def test_an_unknown_group_is_refused(capsys):
    assert warmup.main(["nope"]) == 2 and "coverage" in capsys.readouterr().err
