"""Shared helpers for the eikonal tests: exact fields, error norms, rate fits.

Imported by the test modules of this folder as ``from fmm_checks import ...``
(pytest puts this folder on ``sys.path`` because it has no ``__init__.py``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from fm2uav.eikonal import fast_marching
from fm2uav.eikonal._reference import fast_marching_reference



def node_coords(shape: Sequence[int], spacing: Sequence[float]) -> list[np.ndarray]:
    """World coordinates [m] of every node, one array per axis (``origin = 0``)."""
    axes = [np.arange(n) * h for n, h in zip(shape, spacing)]
    return np.meshgrid(*axes, indexing="ij")


def distance_from(
    shape: Sequence[int], spacing: Sequence[float], node: Sequence[int]
) -> np.ndarray:
    """Euclidean distance [m] of every node from the node ``node`` (an index)."""
    coords = node_coords(shape, spacing)
    return np.sqrt(sum((c - i * h) ** 2 for c, i, h in zip(coords, node, spacing)))


def error_norms(T: np.ndarray, exact: np.ndarray, mask: np.ndarray) -> tuple[float, float]:
    """Max and mean (L1 per node) of ``|T - exact|`` over ``mask`` [s]."""
    err = np.abs(T - exact)[mask]
    assert err.size > 0 and np.all(np.isfinite(err))
    return float(err.max()), float(err.mean())


def loglog_slope(h: Sequence[float], err: Sequence[float]) -> float:
    """Least-squares slope of ``log(err)`` against ``log(h)``: the convergence rate."""
    slope, _ = np.polyfit(np.log(np.asarray(h)), np.log(np.asarray(err)), 1)
    return float(slope)


def assert_same_field(actual: np.ndarray, desired: np.ndarray, rtol: float) -> None:
    """Same ``inf`` pattern, finite values equal to ``rtol`` (relative)."""
    assert actual.shape == desired.shape
    np.testing.assert_array_equal(np.isinf(actual), np.isinf(desired))
    finite = np.isfinite(desired)
    np.testing.assert_allclose(actual[finite], desired[finite], rtol=rtol, atol=0.0)


def fast_marching_parallel(*args, threads: int = 2, **kwargs) -> np.ndarray:
    """:func:`fast_marching` with the parallel march on every grid (no size floor, slabs
    of one row or node on): the small exactness cases then run through the slabs, windows and
    repairs of :mod:`fm2uav.eikonal._parallel`, at order 1 and 2 (``ORDER2`` set)."""
    from fm2uav.eikonal import _tuning

    saved = (_tuning.PARALLEL_MIN_NODES, _tuning.MIN_SLAB_ROWS, _tuning.MIN_SLAB_NODES,
             _tuning.ORDER2, _tuning.ORDER2_MIN_NODES_3D, _tuning.ORDER2_MIN_NODES_2D)
    (_tuning.PARALLEL_MIN_NODES, _tuning.MIN_SLAB_ROWS, _tuning.MIN_SLAB_NODES,
     _tuning.ORDER2, _tuning.ORDER2_MIN_NODES_3D, _tuning.ORDER2_MIN_NODES_2D) = (
        0, 1, 0, True, 0, 0)
    try:
        return fast_marching(*args, threads=threads, **kwargs)
    finally:
        (_tuning.PARALLEL_MIN_NODES, _tuning.MIN_SLAB_ROWS,
         _tuning.MIN_SLAB_NODES, _tuning.ORDER2, _tuning.ORDER2_MIN_NODES_3D,
         _tuning.ORDER2_MIN_NODES_2D) = saved


#: The implementations of the same discretisation; exact-value tests run on each.
SOLVERS = {"compiled": fast_marching, "reference": fast_marching_reference,
           "parallel": fast_marching_parallel}
