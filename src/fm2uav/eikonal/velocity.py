"""The FM² velocity map: distance to the nearest obstacle, rescaled to [0, 1].

Step 2 of FM² (thesis §2.2): a wave is started from every obstacle cell; its
arrival time (the distance to the nearest obstacle) rescaled so the maximum is
1 is the velocity map ``W``. The thesis' adjustment exponent and the Sensors
2022 paper's saturation then shape it: ``W = min(W / saturation, 1) ** exponent``,
or, with a saturation distance ``d_sat`` in metres, ``W = min(d / d_sat, 1) ** exponent``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
from scipy import ndimage

from ..errors import InputError
from . import _edt, _parallel
from .fmm import as_spacing, fast_marching

__all__ = [
    "distance_map",
    "velocity_map",
    "normalise_distance",
    "normalised_distance",
    "distance_scale",
    "shape_velocity",
]

Method = Literal["edt", "fmm"]


def _as_occupancy(occupancy: Any) -> np.ndarray:
    occ = np.asarray(occupancy)
    if occ.dtype != bool:
        raise InputError(
            f"occupancy must be a boolean array (True = obstacle), got dtype {occ.dtype}; "
            "convert with `occupancy > 0`"
        )
    if occ.ndim not in (2, 3) or occ.size == 0:
        raise InputError(f"occupancy must be a non-empty 2D or 3D array, got shape {occ.shape}")
    return occ


def distance_map(
    occupancy: Any,
    *,
    spacing: float | Sequence[float] = 1.0,
    method: Method = "edt",
    walls: bool = False,
    order: int = 2,
    threads: int | None = None,
) -> np.ndarray:
    """Distance from every node to the nearest obstacle node [m].

    Parameters
    ----------
    occupancy : array_like of bool, shape (nx, ny[, nz])
        True = obstacle.
    spacing : float or sequence of float
        Node spacing [m], one value or one per axis.
    method : {"edt", "fmm"}
        ``"edt"``: exact Euclidean distance transform (scipy). ``"fmm"``: Fast
        Marching from every obstacle node with unit speed, as in the seeds.
    walls : bool
        Treat the map border as an obstacle (a ghost layer of obstacle nodes
        one spacing outside the map).
    order : {1, 2}
        FMM order for ``method="fmm"``.
    threads : int, optional
        Threads of the transform (``>= 1``; grids of at least 2 M nodes use more than
        one); None: ``FM2UAV_THREADS`` if set, else every core. The values do not
        depend on it.

    Returns
    -------
    ndarray of float64
        Distance [m]; 0 on obstacles; ``inf`` everywhere if there is no
        obstacle at all (and ``walls`` is False).
    """
    return _distance(occupancy, spacing, method, walls, order, threads, False)[0]


def _distance(occupancy: Any, spacing: float | Sequence[float], method: Method, walls: bool,
              order: int, threads: int | None, normalise: bool
              ) -> tuple[np.ndarray, float | None]:
    """:func:`distance_map` and its largest value [m] (None: not known, ``method="fmm"``);
    ``normalise``: the EDT's map divided by that value in place (see :func:`_edt.edt`)."""
    occ = _as_occupancy(occupancy)
    h = as_spacing(spacing, occ.ndim)
    if method not in ("edt", "fmm"):
        raise InputError(f"method must be 'edt' or 'fmm', got {method!r}")
    nth = _parallel.resolve_threads(threads)
    if walls:
        occ = np.pad(occ, 1, mode="constant", constant_values=True)
    if not occ.any():
        return np.full(occupancy.shape if not walls else occ.shape, np.inf), np.inf
    top = None
    if method == "edt":
        # Our separable exact EDT (numba, lines in parallel) instead of
        # scipy.ndimage.distance_transform_edt: identical values (tested), but
        # 12x faster on a 500x500x40 map (0.28 s vs 3.4 s) and without scipy's
        # (ndim, *shape) int feature array, which dominates memory on big maps.
        # The square root, the maximum and (normalise) the division are in its last
        # passes: no more passes over the grid, no temporaries.
        occ3 = np.ascontiguousarray(occ.reshape(occ.shape + (1,) * (3 - occ.ndim)))
        h3 = h + (1.0,) * (3 - occ.ndim)
        dist, top = _edt.edt(occ3, *h3, normalise=normalise, threads=nth)
        dist = dist.reshape(occ.shape)
    else:
        # Only obstacle nodes with a free neighbour can be nearest; interior
        # obstacle nodes are impassable (speed 0) and stay at distance 0.
        interior = ndimage.binary_erosion(occ, border_value=1)
        boundary = occ & ~interior
        speed = (~interior).astype(np.float64)
        dist = fast_marching(speed, np.argwhere(boundary), spacing=h, order=order,
                             threads=nth)
        dist[interior] = 0.0
    if walls:  # the ring's distances are 0: the largest value is the interior's
        dist = dist[(slice(1, -1),) * occ.ndim]
    return np.asarray(dist, dtype=np.float64), top


def normalised_distance(occupancy: Any, *, spacing: float | Sequence[float] = 1.0,
                        method: Method = "edt", walls: bool = False,
                        threads: int | None = None) -> tuple[np.ndarray, float]:
    """``d / max d`` and ``max d`` [m]: :func:`normalise_distance` of :func:`distance_map`
    and its :func:`distance_scale`, the same values, in one map-sized array.

    With the exact transform the maximum and the division come from the transform's
    last passes, on ``threads`` (as :func:`distance_map`'s). Used by
    :func:`velocity_map` and the planner's cached base map.

    Returns
    -------
    W : ndarray of float64
        The normalised distance map in [0, 1] (all ones without obstacles).
    scale : float
        The distance [m] it was divided by (``inf`` without obstacles).
    """
    dist, top = _distance(occupancy, spacing, method, walls, 2, threads, True)
    if top is not None and 0.0 < top < np.inf:
        return dist, top  # divided by the transform
    scale = distance_scale(dist)  # before the division in place
    return normalise_distance(dist, overwrite=True), scale


def normalise_distance(dist: np.ndarray, *, overwrite: bool = False) -> np.ndarray:
    """Rescale a distance map so that its maximum is 1 (thesis §2.2, step 2).

    A map with no obstacle (all ``inf``) becomes all ones; ``inf`` entries of a
    partly infinite map become 1. ``overwrite=True`` divides a float64 ``dist`` in
    place in the usual case (finite, positive maximum): the same values without a
    second map-sized array (320 MB on a 1000 x 1000 x 40 map).
    """
    top = float(np.max(dist))
    if np.isfinite(top):  # the usual case: one pass for the max, one for the division
        if top > 0.0 and overwrite and dist.dtype == np.float64:
            return np.divide(dist, top, out=dist)
        return dist / top if top > 0.0 else np.zeros_like(dist)
    finite = np.isfinite(dist)
    finite_max = float(np.max(dist, initial=0.0, where=finite))
    if finite_max <= 0.0:
        return np.where(finite, 0.0, 1.0)
    return np.where(finite, dist / finite_max, 1.0)


def distance_scale(dist: np.ndarray) -> float:
    """The distance [m] that :func:`normalise_distance` divides by (W = 1 there).

    The largest finite distance; ``inf`` when no distance is finite (a map
    without obstacles, whose W is all ones).
    """
    top = float(np.max(dist))
    if np.isfinite(top):
        return top
    finite = np.isfinite(dist)
    return float(np.max(dist, initial=0.0, where=finite)) if finite.any() else np.inf


def shape_velocity(
    W: np.ndarray,
    *,
    saturation: float = 1.0,
    exponent: float = 1.0,
    saturation_distance: float | None = None,
    max_distance: float | None = None,
) -> np.ndarray:
    """Apply saturation and exponent β: ``W = min(W / α, 1) ** β``.

    Parameters
    ----------
    W : ndarray
        Normalised velocity map in [0, 1] (``d / max_distance``).
    saturation : float
        α in (0, 1]: distances above α (as a share of the largest) get full speed.
    exponent : float
        β > 0: > 1 darkens the map (paths further from obstacles), < 1 lightens it.
    saturation_distance : float, optional
        ``d_sat`` [m] > 0: distances above it get full speed,
        ``W = min(d / d_sat, 1) ** β`` (overrides ``saturation``). Needs
        ``max_distance``. When ``d_sat > max_distance`` W stays below 1.
    max_distance : float, optional
        The distance [m] ``W`` was normalised by (:func:`distance_scale`).

    Examples
    --------
    >>> import numpy as np
    >>> W = np.array([0.0, 0.25, 0.5, 1.0])          # d / 40 m
    >>> shape_velocity(W, saturation_distance=20.0, max_distance=40.0).tolist()
    [0.0, 0.5, 1.0, 1.0]
    """
    if not (np.isfinite(saturation) and 0.0 < saturation <= 1.0):
        raise InputError(f"saturation must be in (0, 1], got {saturation!r}")
    if not (np.isfinite(exponent) and exponent > 0.0):
        raise InputError(f"exponent must be > 0, got {exponent!r}")
    if saturation_distance is not None:
        if not (np.isfinite(saturation_distance) and saturation_distance > 0.0):
            raise InputError(
                f"saturation_distance must be > 0 metres, got {saturation_distance!r}")
        if max_distance is None or not max_distance >= 0.0:
            raise InputError(
                "saturation_distance needs max_distance, the distance [m] W was normalised by "
                "(eikonal.distance_scale of the distance map)")
        if np.isfinite(max_distance) and max_distance > 0.0:
            out = np.multiply(W, max_distance / saturation_distance)
            np.minimum(out, 1.0, out=out)
        else:  # no obstacle (W all 1) or no free space (W all 0): nothing to saturate
            out = W
    elif saturation == 1.0:
        out = W
    else:
        out = np.divide(W, saturation)
        np.minimum(out, 1.0, out=out)
    # one new map at most, each step in place in it (the same values as the expressions
    # written out; 320 MB per map on a 1000 x 1000 x 40 grid)
    if exponent != 1.0:
        out = np.power(out, exponent, out=None if out is W else out)
    elif out is W:
        out = W.copy()
    return out


def velocity_map(
    occupancy: Any,
    *,
    spacing: float | Sequence[float] = 1.0,
    saturation: float = 1.0,
    exponent: float = 1.0,
    method: Method = "edt",
    walls: bool = False,
    saturation_distance: float | None = None,
    threads: int | None = None,
) -> np.ndarray:
    """The FM² velocity map ``W`` in [0, 1] (0 on obstacles).

    ``W = min(d / max(d) / saturation, 1) ** exponent`` where ``d`` is the
    distance to the nearest obstacle (see :func:`distance_map`), or
    ``W = min(d / saturation_distance, 1) ** exponent``.

    Parameters
    ----------
    occupancy : array_like of bool
        True = obstacle.
    spacing : float or sequence of float
        Node spacing [m].
    saturation : float
        α in (0, 1]. Default 1 (no saturation).
    exponent : float
        β > 0. Default 1.
    method : {"edt", "fmm"}
        Distance computation, see :func:`distance_map`.
    walls : bool
        Treat the map border as an obstacle.
    saturation_distance : float, optional
        ``d_sat`` [m]: full speed from this distance to the obstacles on
        (overrides ``saturation``).
    threads : int, optional
        Threads of the distance transform, as :func:`distance_map`'s.

    Returns
    -------
    ndarray of float64
        W in [0, 1], same shape as ``occupancy``.

    Examples
    --------
    >>> import numpy as np
    >>> occ = np.zeros((5, 1), bool); occ[0, 0] = True
    >>> velocity_map(occ)[:, 0].tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0]
    """
    W, scale = normalised_distance(occupancy, spacing=spacing, method=method, walls=walls,
                                   threads=threads)
    top = scale if saturation_distance is not None else None
    return shape_velocity(W, saturation=saturation, exponent=exponent,
                          saturation_distance=saturation_distance, max_distance=top)
