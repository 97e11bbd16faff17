"""The baselines' warm-up (``make install``) compiles what later reference paths call."""

from __future__ import annotations

import pytest

from fm2uav.baselines import warmup
from tests.planning.warmup_layer_probe import assert_covers

KERNEL = "fm2uav.baselines.reference._kernels:lattice_search"

#: Later calls: the other models, A*, a start heading, a map with obstacles and another
#: spacing (the curvature docs' sweep).
LATER = """
import numpy as np
from fm2uav import World
from fm2uav.baselines import reference_path
occ = np.zeros((20, 14), dtype=bool)
occ[8:11, :8] = True
w = World(occ, spacing=2.0)
for model in ("dubins", "elastica", "rs"):
    reference_path(w, (3.0, 3.0), (35.0, 3.0), model=model, xi=4.0, heuristic=True,
                   start_heading=0.0)
"""


@pytest.mark.slow
def test_a_later_reference_needs_no_signature_the_warm_up_did_not_compile():
    assert_covers("fm2uav.baselines.warmup", KERNEL, LATER)


def test_an_unknown_group_is_refused(capsys):
    assert warmup.main(["nope"]) == 2 and "lattice" in capsys.readouterr().err
