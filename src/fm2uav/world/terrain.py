"""Synthetic terrain: the seeds' open-field map with mountains and a fissure.

The source documents (terrain-following paper, thesis ch. 4 and 6) describe the
open field only in words — the figures are lost:

* a 120 x 90 x 40 grid of 15 m cells, "open field with mountainous terrain where
  the surface is rather uneven";
* a *central mountain* that a low (flight level 2) path avoids by the "lateral
  areas of the map, where the terrain is more uniform", while flight levels 5 and
  10 go "along the centre of the map";
* seen from the front, "two lateral mountains ... form a fissure, which will be
  crossed by the UAVs formation" flying from cell (x=30, y=40) to (x=112, y=40).

:func:`open_field_heights` rebuilds a terrain with these features, in *cells*
(multiply by the cell size for metres). Everything is smooth (Gaussian shapes
and Gaussian-filtered noise) and deterministic for a given seed.
"""

from __future__ import annotations

import numpy as np

__all__ = ["open_field_heights", "OPEN_FIELD_SHAPE", "FISSURE_Y"]

#: (nx, ny) of the open-field height map [cells].
OPEN_FIELD_SHAPE = (120, 90)
#: y index [cells] of the fissure axis; the fissure runs along x.
FISSURE_Y = 40.0


def _gauss(x: np.ndarray, y: np.ndarray, cx: float, cy: float, sx: float, sy: float) -> np.ndarray:
    return np.exp(-0.5 * (((x - cx) / sx) ** 2 + ((y - cy) / sy) ** 2))


def _box(x: np.ndarray, x0: float, x1: float, soft: float) -> np.ndarray:
    """Smooth indicator of ``x0 <= x <= x1`` (tanh edges ``soft`` wide)."""
    return 0.5 * (np.tanh((x - x0) / soft) - np.tanh((x - x1) / soft))


def open_field_heights(
    seed: int | np.random.Generator = 0,
    shape: tuple[int, int] = OPEN_FIELD_SHAPE,
) -> np.ndarray:
    """Ground height of the open-field scenario, ``(nx, ny)`` in **cells**.

    Composition (x, y in cells of the 120 x 90 map):

    * base ground rising gently from ~6 cells at the south-west corner to ~13
      at the north-east corner, plus a low upland near the goal (100, 80);
    * central mountain, centred (66, 60), ~14 cells above the base, the
      highest peak (~23-27 cells over seeds), lying across the start → goal diagonal;
    * two lateral ridges elongated along x (x ~ 40..105): south at y = 22 and
      north at y = 58. Between them, along y = 40, runs the *fissure*, a
      valley whose floor is ~10 cells below the ridge crests;
    * seeded random relief: white noise smoothed with a Gaussian filter
      (sigma 4 cells), scaled so that max |relief| = 3 cells;
    * a final light smoothing (sigma 1 cell).

    Parameters
    ----------
    seed:
        Seed (or generator) of the random relief; same seed → same terrain.
    shape:
        ``(nx, ny)`` in cells; the features are laid out for (120, 90) and
        scaled proportionally for other shapes.
    """
    nx, ny = int(shape[0]), int(shape[1])
    sxf, syf = nx / OPEN_FIELD_SHAPE[0], ny / OPEN_FIELD_SHAPE[1]
    x, y = np.meshgrid(
        np.arange(nx, dtype=float) / sxf, np.arange(ny, dtype=float) / syf, indexing="ij"
    )
    X, Y = OPEN_FIELD_SHAPE[0] - 1.0, OPEN_FIELD_SHAPE[1] - 1.0

    # gentle base slope (SW low, NE high) and an upland around the goal
    base = 6.0 + 7.0 * 0.5 * (x / X + y / Y)
    base += 4.0 * _gauss(x, y, 104.0, 84.0, 14.0, 12.0)

    central = 14.0 * _gauss(x, y, 66.0, 60.0, 11.0, 8.0)
    south = 13.0 * _box(x, 40.0, 105.0, 6.0) * np.exp(-0.5 * ((y - 22.0) / 6.0) ** 2)
    north = 11.0 * _box(x, 42.0, 108.0, 6.0) * np.exp(-0.5 * ((y - 58.0) / 5.5) ** 2)
    mountains = np.maximum(np.maximum(central, south), north)

    # fissure: a trough along y = FISSURE_Y between the lateral ridges
    trough = 2.0 * _box(x, 28.0, 116.0, 6.0) * np.exp(-0.5 * ((y - FISSURE_Y) / 4.0) ** 2)

    from scipy.ndimage import gaussian_filter  # the scenarios' names load without scipy

    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    noise = gaussian_filter(
        rng.standard_normal((nx, ny)), sigma=4.0 * min(sxf, syf), mode="reflect"
    )
    noise *= 3.0 / np.max(np.abs(noise))

    h = base + mountains - trough + noise
    h = gaussian_filter(h, sigma=1.0 * min(sxf, syf), mode="nearest")
    return np.maximum(h, 1.0)
