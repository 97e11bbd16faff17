"""Fill numba's cache with the analysis layer's kernels (``make install``, after planning's).

The planning warm-up (:mod:`fm2uav.planning.warmup`) cannot import this layer, so each layer
above it warms its own kernels with the same machinery::

    python -m fm2uav.analysis.warmup                # every group
    python -m fm2uav.analysis.warmup similarity     # one group

Groups: ``similarity`` (the discrete Fréchet distance and the winding test of the area
between two curves: every path comparison of the curvature study and the baselines).
"""

from __future__ import annotations

import sys
from collections.abc import Callable

import numpy as np

from ..planning.warmup import main as _main
from .similarity import area_between_curves, frechet_distance

__all__ = ["GROUPS", "main"]


def _similarity() -> None:
    """Two 2D curves sharing their ends: their Fréchet distance and the area between them."""
    t = np.linspace(0.0, 1.0, 20)
    P = np.column_stack([t, np.zeros_like(t)])
    Q = np.column_stack([t, 0.2 * np.sin(np.pi * t)])
    frechet_distance(P, Q)
    area_between_curves(P, Q)


#: Group name -> what it runs.
GROUPS: dict[str, Callable[[], None]] = {"similarity": _similarity}


def main(argv: list[str] | None = None) -> int:
    """``python -m fm2uav.analysis.warmup [GROUP ...]``: print each group's time."""
    return _main(argv, table=GROUPS)


if __name__ == "__main__":
    sys.exit(main())
