"""Fill numba's cache with the autopilot layer's kernels (``make install``, after planning's).

The planning warm-up (:mod:`fm2uav.planning.warmup`) cannot import this layer, so each layer
above it warms its own kernels with the same machinery::

    python -m fm2uav.autopilot.warmup           # every group
    python -m fm2uav.autopilot.warmup thin      # one group

Groups: ``thin`` (the Douglas–Peucker splits of :func:`~fm2uav.autopilot.thin.thin_indices`:
every export's waypoints and every ``fm2uav routes`` line, 2D and 3D paths).
"""

from __future__ import annotations

import sys
from collections.abc import Callable

import numpy as np

from ..planning.warmup import main as _main
from .thin import thin_indices

__all__ = ["GROUPS", "main"]


def _thin() -> None:
    """A wavy 2D and 3D path of 50 points, thinned to 0.1 m."""
    t = np.linspace(0.0, 10.0, 50)
    path = np.column_stack([t, np.sin(t), 0.1 * t])
    thin_indices(path[:, :2], 0.1)
    thin_indices(path, 0.1)


#: Group name -> what it runs.
GROUPS: dict[str, Callable[[], None]] = {"thin": _thin}


def main(argv: list[str] | None = None) -> int:
    """``python -m fm2uav.autopilot.warmup [GROUP ...]``: print each group's time."""
    return _main(argv, table=GROUPS)


if __name__ == "__main__":
    sys.exit(main())
