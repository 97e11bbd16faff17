"""The vehicles' warm-up (``make install``) compiles what later energy estimates call."""

from __future__ import annotations

import pytest

from fm2uav.vehicles import warmup
from tests.planning.warmup_layer_probe import assert_covers

KERNEL = "fm2uav.vehicles._power_kernels:bisect_induced"

#: Later calls: many states given as a read-only array, a broadcast 2D grid, integers,
#: through a preset's power curve.
LATER = """
import numpy as np
from fm2uav.vehicles.power import get_power_model, induced_velocity
v = np.linspace(0.0, 12.0, 9)
v.flags.writeable = False
induced_velocity(v, -1.0, 6.3)
induced_velocity(np.arange(12).reshape(3, 4), np.zeros((1, 4)), 6.3)
get_power_model("arducopter").power(np.linspace(0.0, 15.0, 50), 0.5)
"""


@pytest.mark.slow
def test_a_later_energy_estimate_needs_no_signature_the_warm_up_did_not_compile():
    assert_covers("fm2uav.vehicles.warmup", KERNEL, LATER)


def test_an_unknown_group_is_refused(capsys):
    assert warmup.main(["nope"]) == 2 and "power" in capsys.readouterr().err
