"""A built-in scenario: a world with a start and a goal."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import WorldError
from ..world import World

__all__ = ["Scenario"]


@dataclass(frozen=True)
class Scenario:
    """A world with a start and a goal.

    Attributes
    ----------
    world:
        The :class:`World`.
    start, goal:
        ``(ndim,)`` world coordinates [m] (read-only float arrays).
    description:
        One line saying where the scenario comes from.
    """

    world: World
    start: np.ndarray
    goal: np.ndarray
    description: str

    def __post_init__(self) -> None:
        for attr in ("start", "goal"):
            p = np.array(getattr(self, attr), dtype=float, copy=True)
            if p.shape != (self.world.ndim,):
                raise WorldError(
                    f"Scenario {attr} must be one point with {self.world.ndim} coordinates "
                    f"in metres, got shape {p.shape}"
                )
            p.setflags(write=False)
            object.__setattr__(self, attr, p)
