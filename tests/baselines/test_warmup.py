"""The baselines' warm-up (``make install``) compiles what later reference paths call."""

from __future__ import annotations

import pytest

from fm2uav.baselines import warmup
from tests.planning.warmup_layer_probe import added_after

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
    after = added_after("fm2uav.baselines.warmup", KERNEL, LATER)
    assert after["warm"] and after["added"] == []
    # the check can fail: without the warm-up the same calls add the signature
    assert added_after(None, KERNEL, LATER)["added"] == after["warm"]


def test_an_unknown_group_is_refused(capsys):
    assert warmup.main(["nope"]) == 2
    assert "lattice" in capsys.readouterr().err
