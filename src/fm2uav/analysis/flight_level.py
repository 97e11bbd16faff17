"""Flight-level deviation of a path against the ideal terrain-following path.

The ideal path flies ``agl`` metres over the surface Algorithm 2 follows (the
ground, or a roof): its altitude at a path point's horizontal position is
``World.surface_height(x, y) + agl`` (``reference="terrain"``: the ground
interpolated bilinearly, roofs from the nearest column; see
:mod:`fm2uav.world.ground`), or the flight-level node ``z0 + (Surface +
round(agl/dz)) dz`` of the nearest column, i.e. exactly the layer Algorithm 2
clarifies (``reference="layer"``).

As in the seeds, the start and goal *transition stretches* (the initial descent
or climb to the level and the final one to the goal) are reported apart: the
start stretch is every point before the first point within ``tolerance`` of the
ideal altitude, the end stretch every point after the last such point. The
middle statistics are over the points in between.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import arc_length
from ..planning.flight_level import level_cells
from ..world import World

__all__ = [
    "FlightLevelReport",
    "flight_level_deviation",
    "ideal_altitude",
    "transition_bounds",
    "tff_metrics",
]


def _xy_index(world: World, points: np.ndarray) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"points must be an (N, 3) array in metres, got shape {p.shape}")
    idx = world.to_index(p)[:, :2]
    hi = np.asarray(world.shape[:2], dtype=float) - 1
    return np.clip(idx, 0, hi)


def ideal_altitude(
    world: World, points: Any, agl: float, *, reference: str = "terrain"
) -> np.ndarray:
    """Altitude [m] of the ideal terrain-following path above each point.

    Parameters
    ----------
    reference : {"terrain", "layer"}
        ``"terrain"``: :meth:`World.surface_height` (ground bilinear, roofs) +
        ``agl``. ``"layer"``: the flight-level node of the nearest column
        (Algorithm 2's layer).
    """
    pts = np.asarray(points, dtype=float)
    if reference == "terrain":
        level_cells(world, agl)  # validates agl
        _xy_index(world, pts)  # validates the points
        return world.surface_height(pts[:, 0], pts[:, 1]) + float(agl)
    if reference == "layer":
        lf = level_cells(world, agl)
        near = np.floor(_xy_index(world, pts) + 0.5).astype(int)
        surf = world.surface_index()[near[:, 0], near[:, 1]]
        return world.origin[2] + (surf + lf) * world.spacing[2]
    raise InputError(f"reference must be 'terrain' or 'layer', got {reference!r}")


def transition_bounds(ok: np.ndarray) -> tuple[int, int]:
    """``(a, b)``: first and last index where ``ok`` holds; ``(n, -1)`` if never."""
    ok = np.asarray(ok, dtype=bool)
    if not ok.any():
        return len(ok), -1
    return int(np.argmax(ok)), int(len(ok) - 1 - np.argmax(ok[::-1]))


@dataclass(frozen=True)
class FlightLevelReport:
    """Deviation of a path from the ideal flight level.

    Attributes
    ----------
    within : float
        Share of the middle points (between the transition stretches) within
        ``tolerance`` of the ideal altitude, in [0, 1]; 0 if the path never
        reaches the level.
    within_all : float
        Share of all points (transitions included) within ``tolerance``.
    mean_dev_m, max_dev_m : float
        Mean and max |deviation| over the middle points [m] (nan if none).
    mean_dev_all_m, max_dev_all_m : float
        The same over the whole path [m].
    start_transition_m, end_transition_m : float
        Arc length of the start and end transition stretches [m].
    transition_share : float
        Share of the path length in the two transition stretches.
    middle_points : int
        Number of points between the transition stretches.
    inside_terrain : int
        Path points at or below the ground (bilinear terrain) or in an
        obstacle node.
    min_agl_m : float
        Smallest height of a path point over the ground [m].
    tolerance_m : float
        Tolerance used [m] (one vertical cell by default).
    deviation : ndarray
        Signed ``z - ideal`` per path point [m].
    """

    within: float
    within_all: float
    mean_dev_m: float
    max_dev_m: float
    mean_dev_all_m: float
    max_dev_all_m: float
    start_transition_m: float
    end_transition_m: float
    transition_share: float
    middle_points: int
    inside_terrain: int
    min_agl_m: float
    tolerance_m: float
    deviation: np.ndarray = field(repr=False)

    def summary(self) -> dict[str, float]:
        """JSON-friendly numbers (the deviation array left out)."""
        return {k: (float(v) if not isinstance(v, int) else v)
                for k, v in self.__dict__.items() if k != "deviation"}


def flight_level_deviation(
    world: World,
    path: Any,
    agl: float,
    *,
    tolerance: float | None = None,
    reference: str = "terrain",
) -> FlightLevelReport:
    """Compare a path with the ideal terrain-following path at ``agl`` metres.

    Parameters
    ----------
    world : World
        3D world the path was planned in.
    path : array_like, (N, 3)
        Path [m], start to goal.
    agl : float
        Flight level over the ground [m].
    tolerance : float, optional
        |deviation| counted as "on the level" [m]. Default one vertical cell.
    reference : {"terrain", "layer"}
        See :func:`ideal_altitude`.

    Examples
    --------
    >>> import numpy as np
    >>> from fm2uav import World
    >>> w = World.from_heightmap(np.full((10, 4), 10.0), 5.0, 12)
    >>> path = np.array([[0, 5, 40.0], [15, 5, 30.0], [30, 5, 30.0], [45, 5, 30.0]])
    >>> r = flight_level_deviation(w, path, agl=20.0)
    >>> r.within, round(r.start_transition_m, 2)    # hypot(15, 10)
    (1.0, 18.03)
    """
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
        raise InputError(f"path must be an (N, 3) array of N >= 2 points [m], got shape {p.shape}")
    tol = world.spacing[2] if tolerance is None else float(tolerance)
    if not (np.isfinite(tol) and tol >= 0):
        raise InputError(f"tolerance must be >= 0 metres, got {tolerance!r}")
    ideal = ideal_altitude(world, p, agl, reference=reference)
    dev = p[:, 2] - ideal
    ok = np.abs(dev) <= tol + 1e-9
    a, b = transition_bounds(ok)
    s = arc_length(p)
    if b >= a:
        mid = np.abs(dev[a : b + 1])
        within, mean_d, max_d = float(ok[a : b + 1].mean()), float(mid.mean()), float(mid.max())
        start_m, end_m, n_mid = float(s[a]), float(s[-1] - s[b]), b - a + 1
    else:
        within, mean_d, max_d = 0.0, float("nan"), float("nan")
        start_m, end_m, n_mid = float(s[-1]), 0.0, 0
    ground = world.surface_height(p[:, 0], p[:, 1])
    cells = np.floor(world.to_index(p) + 0.5).astype(int)
    cells = np.clip(cells, 0, np.asarray(world.shape) - 1)
    in_obstacle = world.occupancy[cells[:, 0], cells[:, 1], cells[:, 2]]
    inside = int(np.count_nonzero((p[:, 2] <= ground) | in_obstacle))
    length = float(s[-1]) if s[-1] > 0 else 1.0
    return FlightLevelReport(
        within=within,
        within_all=float(ok.mean()),
        mean_dev_m=mean_d,
        max_dev_m=max_d,
        mean_dev_all_m=float(np.abs(dev).mean()),
        max_dev_all_m=float(np.abs(dev).max()),
        start_transition_m=start_m,
        end_transition_m=end_m,
        transition_share=(start_m + end_m) / length,
        middle_points=int(n_mid),
        inside_terrain=inside,
        min_agl_m=float((p[:, 2] - ground).min()),
        tolerance_m=tol,
        deviation=dev,
    )


def tff_metrics(plan: Any, agl: float, *, ds: float | None = None) -> dict[str, float]:
    """All terrain-following numbers of one plan, as a flat dict.

    Flight-level deviation against terrain + agl (``within``, ``within_all``,
    mean/max |dev|, transitions, inside terrain), mean |dev| against the
    Algorithm-2 layer (``mean_dev_layer_m``), and the turn/climb/curvature
    summary of :func:`fm2uav.analysis.profiles.path_profiles` (resampled every
    ``ds`` metres, default one horizontal cell), plus length and clearance.
    """
    from .profiles import path_profiles

    world = plan.world
    fl = flight_level_deviation(world, plan.path, agl)
    fl_layer = flight_level_deviation(world, plan.path, agl, reference="layer")
    step = float(max(world.spacing[:2])) if ds is None else float(ds)
    out: dict[str, float] = {k: v for k, v in fl.summary().items()}
    out["mean_dev_layer_m"] = fl_layer.mean_dev_all_m
    out["within_layer"] = fl_layer.within
    out.update(path_profiles(plan.path, ds=step).summary())
    out["length_m"] = float(plan.length)
    out["clearance_m"] = float(plan.clearance)
    return out
