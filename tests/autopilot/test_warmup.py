"""The autopilot layer's warm-up (``make install``) compiles what later exports call."""

from __future__ import annotations

import pytest

from fm2uav.autopilot import warmup
from tests.planning.warmup_layer_probe import assert_covers

#: Later calls: a plan's 3D path, a 2D route, a column slice, a Fortran-ordered copy, a
#: read-only array, integers, every point kept (tolerance 0).
LATER = """
import numpy as np
from fm2uav.autopilot.thin import thin_indices, thin_path
rng = np.random.default_rng(0)
p = np.cumsum(rng.normal(size=(200, 3)), axis=0)
thin_indices(p, 0.5)
thin_indices(p[:, :2], 0.5)
thin_indices(np.asfortranarray(p), 1.0)
q = p.copy(); q.flags.writeable = False
thin_indices(q, 2.0)
thin_indices(np.arange(30).reshape(10, 3), 0.5)
thin_path(p, 0.0)
"""


@pytest.mark.slow
def test_a_later_export_needs_no_signature_the_warm_up_did_not_compile():
    assert_covers("fm2uav.autopilot.warmup", "fm2uav.autopilot._thin_kernels:split_all", LATER)


def test_an_unknown_group_is_refused(capsys):
    assert warmup.main(["nope"]) == 2 and "thin" in capsys.readouterr().err
