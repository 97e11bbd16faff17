"""Fill numba's cache with the baselines' kernels (``make install``, after the planning ones).

The planning warm-up (:mod:`fm2uav.planning.warmup`) cannot import this layer, so each layer
above it warms its own kernels with the same machinery::

    python -m fm2uav.baselines.warmup             # every group
    python -m fm2uav.baselines.warmup lattice     # one group

Groups: ``lattice`` (the curvature references' lattice search, through the public
:func:`~fm2uav.baselines.reference_path`: the argument types of every later call).
"""

from __future__ import annotations

import sys
from collections.abc import Callable

import numpy as np

from ..planning.warmup import main as _main
from ..world import World
from .reference import reference_path

__all__ = ["GROUPS", "main"]


def _lattice() -> None:
    """A Dubins reference on an empty 8 x 8 map (the search is the same for every model)."""
    reference_path(World(np.zeros((8, 8), dtype=bool), spacing=1.0), (1.0, 1.0), (6.0, 6.0),
                   xi=1.0, max_int=1)


#: Group name -> what it runs.
GROUPS: dict[str, Callable[[], None]] = {"lattice": _lattice}


def main(argv: list[str] | None = None) -> int:
    """``python -m fm2uav.baselines.warmup [GROUP ...]``: print each group's time."""
    return _main(argv, table=GROUPS)


if __name__ == "__main__":
    sys.exit(main())
