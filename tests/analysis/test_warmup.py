"""The analysis layer's warm-up (``make install``) compiles what later path comparisons call."""

from __future__ import annotations

import pytest

from fm2uav.analysis import warmup
from tests.planning.warmup_layer_probe import assert_covers

#: Later calls: 3D curves, a read-only array, integer points, curves of one point, lists.
LATER = """
import numpy as np
from fm2uav.analysis.similarity import area_between_curves, frechet_distance
rng = np.random.default_rng(0)
P = np.cumsum(rng.normal(size=(40, 3)), axis=0)
Q = P + rng.normal(scale=0.1, size=P.shape)
frechet_distance(P, Q)
R = P[:, :2].copy(); R.flags.writeable = False
frechet_distance(R, Q[::2, :2])
frechet_distance(np.arange(10).reshape(5, 2), [[0, 0], [9, 9]])
frechet_distance([[1.0, 2.0]], [[3.0, 4.0]])
S = np.column_stack([np.linspace(0, 1, 30), np.zeros(30)])
T = np.column_stack([np.linspace(0, 1, 30), np.sin(np.linspace(0, 3, 30))])
T[-1] = S[-1]
area_between_curves(S, T)
area_between_curves(S[::-1].copy(), T[::-1])
"""


@pytest.mark.slow
@pytest.mark.parametrize("kernel", ["_frechet_kernel", "_wound_area"])
def test_a_later_comparison_needs_no_signature_the_warm_up_did_not_compile(kernel):
    assert_covers("fm2uav.analysis.warmup", f"fm2uav.analysis.similarity:{kernel}", LATER)


def test_an_unknown_group_is_refused(capsys):
    assert warmup.main(["nope"]) == 2 and "similarity" in capsys.readouterr().err
