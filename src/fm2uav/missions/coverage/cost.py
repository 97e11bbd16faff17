"""The cost of a zigzag, C(α) = Σ (dᵢ + lᵢ) [m] (seeds eq. 3 / thesis eq. 5.4).

:class:`ZigzagCost` is the objective handed to the optimisers: the area is
validated and its edges extracted once, then every evaluation is one compiled
call (a few microseconds), shared with :func:`~.bands.zigzag` so the cost of
an angle is exactly the length of the zigzag built at that angle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from shapely.geometry import Polygon

from ._kernels import zigzag_cost
from .area import as_area, check_spacing, exterior_edges

__all__ = ["ZigzagCost", "cost"]


@dataclass(frozen=True, eq=False)
class ZigzagCost:
    """Objective C(α) of an area and a band spacing.

    Call it with an angle in **degrees** (the optimisers' and the seeds'
    unit) or use :meth:`radians`; an array of angles gives an array of costs.

    Attributes
    ----------
    area : shapely.Polygon
        The validated area [m].
    spacing : float
        Band spacing D [m].
    """

    area: Polygon
    spacing: float
    _edges: tuple = field(repr=False, default=())

    @classmethod
    def of(cls, area, spacing: float) -> ZigzagCost:
        """Validate ``area`` and ``spacing`` (see :func:`~.area.as_area`) and prepare."""
        poly = as_area(area)
        d = check_spacing(poly, spacing)
        return cls(area=poly, spacing=d, _edges=exterior_edges(poly))

    def radians(self, angle: float) -> float:
        """C(α) [m] for α in radians."""
        ax, ay, bx, by = self._edges
        return float(zigzag_cost(ax, ay, bx, by, float(angle), self.spacing))

    def __call__(self, angle_deg):
        """C(α) [m] for α in degrees (scalar or array)."""
        a = np.asarray(angle_deg, dtype=float)
        if a.ndim == 0:
            return self.radians(math.radians(float(a)))
        ax, ay, bx, by = self._edges
        flat = np.radians(a.ravel())
        out = np.array([zigzag_cost(ax, ay, bx, by, v, self.spacing) for v in flat])
        return out.reshape(a.shape)


def cost(area, spacing: float, angle: float) -> float:
    """C(α) [m] of the zigzag covering ``area`` with bands ``spacing`` [m] apart at ``angle`` [rad]."""
    return ZigzagCost.of(area, spacing).radians(angle)
