"""Fill numba's cache with the missions' kernels (``make install``, after the planning ones).

The planning warm-up (:mod:`fm2uav.planning.warmup`) cannot import this layer, so each layer
above it warms its own kernels with the same machinery::

    python -m fm2uav.missions.warmup             # every group
    python -m fm2uav.missions.warmup coverage    # one group

Groups: ``coverage`` (the zigzag's strip extents, band ends and cost — every survey's
optimiser and bands, through the public :func:`~fm2uav.missions.coverage.cost.cost` and
:func:`~fm2uav.missions.coverage.bands.zigzag`).
"""

from __future__ import annotations

import sys
from collections.abc import Callable

from ..planning.warmup import main as _main

__all__ = ["GROUPS", "main"]


def _coverage() -> None:
    """The cost and the bands of a 40 m x 30 m rectangle, 10 m apart, at 0.3 rad."""
    from shapely.geometry import box

    from .coverage.bands import zigzag
    from .coverage.cost import cost

    area = box(0.0, 0.0, 40.0, 30.0)
    cost(area, 10.0, 0.3)
    zigzag(area, 10.0, 0.3)


#: Group name -> what it runs.
GROUPS: dict[str, Callable[[], None]] = {"coverage": _coverage}


def main(argv: list[str] | None = None) -> int:
    """``python -m fm2uav.missions.warmup [GROUP ...]``: print each group's time."""
    return _main(argv, table=GROUPS)


if __name__ == "__main__":
    sys.exit(main())
