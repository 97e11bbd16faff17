"""Fill numba's cache with the vehicles' kernels (``make install``, after the planning ones).

The planning warm-up (:mod:`fm2uav.planning.warmup`) cannot import this layer, so each layer
above it warms its own kernels with the same machinery::

    python -m fm2uav.vehicles.warmup            # every group
    python -m fm2uav.vehicles.warmup power      # one group

Groups: ``power`` (the rotor induced velocity's bisection of more than a few flight states,
every multirotor energy estimate).
"""

from __future__ import annotations

import sys
from collections.abc import Callable

import numpy as np

from ..planning.warmup import main as _main
from .power import _SCALAR_STATES, induced_velocity

__all__ = ["GROUPS", "main"]


def _power() -> None:
    """The compiled bisection (more states than the Python-float path takes)."""
    n = _SCALAR_STATES + 1
    induced_velocity(np.linspace(0.0, 10.0, n), np.zeros(n), 6.0)


#: Group name -> what it runs.
GROUPS: dict[str, Callable[[], None]] = {"power": _power}


def main(argv: list[str] | None = None) -> int:
    """``python -m fm2uav.vehicles.warmup [GROUP ...]``: print each group's time."""
    return _main(argv, table=GROUPS)


if __name__ == "__main__":
    sys.exit(main())
