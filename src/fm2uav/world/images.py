"""Worlds from 2D map images: plain PNG/PGM pictures and ROS ``map_server`` maps.

The Sensors paper's maps are 2D pictures (black obstacles on white); mobile
robots store maps in the ROS ``map_server`` format: a YAML file naming a
PGM/PNG image with its resolution, origin and thresholds. Both become a 2D
:class:`~fm2uav.world.World` (indexed ``[ix, iy]``, x to the right, y up).

Pixel → occupancy follows ``map_server`` (ROS 1 and ROS 2 ``nav2_map_server``):
for a pixel value ``x`` in 0..255 (colour images averaged over their colour
channels), the occupancy probability is ``p = (255 - x) / 255`` (``negate: 0``,
dark = occupied) or ``p = x / 255`` (``negate: 1``). ``p > occupied_thresh`` is
occupied, ``p < free_thresh`` is free, anything between is *unknown*, which is
an obstacle here unless ``unknown="free"`` (a planner must not fly into the
unmapped).

Geometry: ``origin`` is the position [m] of the lower-left pixel's lower-left
corner; pixel centres are the world's nodes, so node ``(0, 0)`` sits at
``origin + resolution / 2``. Image row 0 is the top of the map (largest y).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Literal

import numpy as np

from ..errors import InputError, WorldError
from .world import World

__all__ = ["occupancy_from_pixels", "world_from_image", "world_from_ros_map"]

#: ``map_server`` defaults (ROS wiki map_server, nav2_map_server).
ROS_OCCUPIED_THRESH = 0.65
ROS_FREE_THRESH = 0.196


def _read_pixels(path: Path, what: str) -> np.ndarray:
    """Grey values 0..255 of an image file, shape (rows, cols), float."""
    from PIL import Image, UnidentifiedImageError

    if not path.exists():
        raise InputError(f"{what}: no such file {str(path)!r}; check the path")
    if not path.is_file():
        raise InputError(f"{what}: {str(path)!r} is not a regular file; give an image file (PNG, PGM)")
    try:
        with Image.open(path) as img:
            img.load()
            mode = img.mode
            if mode in ("I;16", "I;16B", "I;16L", "I"):
                arr = np.asarray(img, dtype=float)
                top = 65535.0 if mode.startswith("I;16") else max(float(arr.max()), 1.0)
                return arr * (255.0 / top)
            if mode in ("RGBA", "LA", "PA"):
                img = img.convert("RGBA" if mode != "LA" else "LA")
                arr = np.asarray(img, dtype=float)[..., :-1]  # alpha ignored, as map_server does
            elif mode == "P":
                arr = np.asarray(img.convert("RGB"), dtype=float)
            else:
                arr = np.asarray(img, dtype=float)
    except UnidentifiedImageError:
        raise InputError(
            f"{what}: {str(path)!r} is not an image Pillow can read; give a PNG, PGM or other raster picture"
        ) from None
    except OSError as exc:
        raise InputError(f"{what}: cannot read {str(path)!r}: {exc}") from None
    if arr.ndim == 3:
        arr = arr.mean(axis=2)
    if arr.ndim != 2 or arr.size == 0:
        raise InputError(f"{what}: {str(path)!r} has no pixels")
    return arr


def occupancy_from_pixels(
    pixels: np.ndarray,
    *,
    occupied_thresh: float = ROS_OCCUPIED_THRESH,
    free_thresh: float = ROS_FREE_THRESH,
    negate: bool = False,
    unknown: Literal["obstacle", "free"] = "obstacle",
) -> np.ndarray:
    """Occupancy ``[ix, iy]`` (True = obstacle) from image pixels ``[row, col]``.

    Parameters
    ----------
    pixels : ndarray, shape (rows, cols)
        Grey values in 0..255, row 0 at the top of the map.
    occupied_thresh, free_thresh : float
        Probability thresholds in [0, 1], ``free_thresh <= occupied_thresh``.
    negate : bool
        ``False``: dark pixels are occupied (``p = (255 - x) / 255``).
    unknown : {"obstacle", "free"}
        What pixels between the thresholds become.

    Returns
    -------
    ndarray of bool, shape (cols, rows)
        Indexed ``[ix, iy]`` with ``iy = 0`` the bottom row of the picture.
    """
    for name, v in (("occupied_thresh", occupied_thresh), ("free_thresh", free_thresh)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and 0.0 <= v <= 1.0):
            raise InputError(f"{name} must be a number in [0, 1], got {v!r}")
    if free_thresh > occupied_thresh:
        raise InputError(
            f"free_thresh ({free_thresh}) must not exceed occupied_thresh ({occupied_thresh})"
        )
    if unknown not in ("obstacle", "free"):
        raise InputError(f"unknown must be 'obstacle' or 'free', got {unknown!r}")
    x = np.asarray(pixels, dtype=float)
    p = x / 255.0 if negate else (255.0 - x) / 255.0
    occ = p > occupied_thresh
    if unknown == "obstacle":
        occ |= p >= free_thresh
    # [row, col] with row 0 at the top -> [ix, iy] with iy 0 at the bottom
    return np.ascontiguousarray(occ[::-1, :].T)


def world_from_image(
    path: str | Path,
    resolution: float,
    *,
    threshold: float = 0.5,
    negate: bool = False,
    origin: tuple[float, float] = (0.0, 0.0),
    name: str | None = None,
) -> World:
    """A 2D world from a picture: pixels darker than ``threshold`` are obstacles.

    Parameters
    ----------
    path : str or Path
        PNG, PGM, BMP, ... (anything Pillow reads); colour images are averaged
        over their channels, alpha is ignored.
    resolution : float
        Size of one pixel [m].
    threshold : float
        Occupancy probability in (0, 1) above which a pixel is an obstacle
        (``p = (255 - x) / 255``; 0.5 = darker than mid-grey).
    negate : bool
        ``True``: bright pixels are obstacles.
    origin : (float, float)
        Position [m] of the picture's lower-left corner.
    name : str, optional
        World name (default: the file name).

    Returns
    -------
    World
        2D, one node per pixel at the pixel centres.
    """
    if not (isinstance(resolution, (int, float)) and math.isfinite(resolution) and resolution > 0):
        raise InputError(f"image resolution must be a positive number of metres per pixel, got {resolution!r}")
    if not (isinstance(threshold, (int, float)) and 0.0 < threshold < 1.0):
        raise InputError(f"image threshold must be a number in (0, 1), got {threshold!r}")
    path = Path(path)
    pixels = _read_pixels(path, "image map")
    occ = occupancy_from_pixels(
        pixels, occupied_thresh=threshold, free_thresh=threshold, negate=negate, unknown="free"
    )
    return _world(occ, float(resolution), origin, name or path.name, "image map")


def _world(occ: np.ndarray, res: float, origin: Any, name: str, what: str) -> World:
    try:
        ox, oy = (float(v) for v in origin)
    except (TypeError, ValueError):
        raise InputError(f"{what} origin must be two numbers (x, y) in metres, got {origin!r}") from None
    if not (math.isfinite(ox) and math.isfinite(oy)):
        raise InputError(f"{what} origin must be finite, got {origin!r}")
    if occ.all():
        raise WorldError(
            f"{what} {name!r} has no free pixel: check the thresholds or 'negate' "
            "(dark pixels are obstacles unless negate is set)"
        )
    return World(occ, spacing=res, origin=(ox + res / 2, oy + res / 2), name=name)


def _threshold(meta: dict, key: str, default: float, what: str) -> float:
    v = meta.get(key, default)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not (0.0 <= float(v) <= 1.0):
        raise InputError(f"{what}: {key} must be a number in [0, 1], got {v!r}")
    return float(v)


def world_from_ros_map(
    yaml_path: str | Path,
    *,
    unknown: Literal["obstacle", "free"] = "obstacle",
) -> World:
    """A 2D world from a ROS ``map_server`` map (``map.yaml`` + its image).

    Parameters
    ----------
    yaml_path : str or Path
        The map's YAML file with keys ``image`` (relative to the YAML file's
        folder or absolute), ``resolution`` [m/pixel], ``origin`` ``[x, y, yaw]``
        [m, m, rad], and optionally ``occupied_thresh`` (0.65), ``free_thresh``
        (0.196), ``negate`` (0) and ``mode`` (``trinary``, ``scale`` or ``raw``).
    unknown : {"obstacle", "free"}
        What cells of unknown occupancy become.

    Returns
    -------
    World
        2D world, one node per pixel.

    Notes
    -----
    A non-zero ``yaw`` is refused: map_server itself ignores it in most of the
    ROS stack, so a rotated map would mean different things to different tools.
    In ``raw`` mode the pixel value is the occupancy in percent (0..100; 255 or
    anything above 100 is unknown).
    """
    import yaml

    yaml_path = Path(yaml_path)
    what = f"ROS map {str(yaml_path)!r}"
    if not yaml_path.is_file():
        raise InputError(f"{what}: no such file; give the map's .yaml file")
    try:
        meta = yaml.safe_load(yaml_path.read_text(encoding="utf-8"))
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise InputError(f"{what} is not valid YAML: {str(exc).splitlines()[0]}") from None
    if not isinstance(meta, dict):
        raise InputError(f"{what} must be a mapping with keys image, resolution, origin")
    missing = [k for k in ("image", "resolution", "origin") if k not in meta]
    if missing:
        raise InputError(f"{what} lacks the key(s) {', '.join(missing)} (map_server format)")
    res = meta["resolution"]
    if not (isinstance(res, (int, float)) and not isinstance(res, bool) and math.isfinite(res) and res > 0):
        raise InputError(f"{what}: resolution must be a positive number of metres per pixel, got {res!r}")
    origin = meta["origin"]
    if not (isinstance(origin, (list, tuple)) and len(origin) in (2, 3)):
        raise InputError(f"{what}: origin must be [x, y, yaw] (metres, metres, radians), got {origin!r}")
    if len(origin) == 3 and float(origin[2]) != 0.0:
        raise InputError(
            f"{what}: origin yaw {origin[2]} is not 0; rotated maps are not supported "
            "(map_server ignores yaw too): re-export the map with yaw 0"
        )
    mode = str(meta.get("mode", "trinary"))
    if mode not in ("trinary", "scale", "raw"):
        raise InputError(f"{what}: mode must be trinary, scale or raw, got {mode!r}")
    negate = meta.get("negate", 0)
    if negate not in (0, 1, True, False):
        raise InputError(f"{what}: negate must be 0 or 1, got {negate!r}")
    image = Path(str(meta["image"]))
    if not image.is_absolute():
        image = yaml_path.parent / image
    pixels = _read_pixels(image, f"{what} image")
    occ_t = _threshold(meta, "occupied_thresh", ROS_OCCUPIED_THRESH, what)
    free_t = _threshold(meta, "free_thresh", ROS_FREE_THRESH, what)
    if mode == "raw":  # pixel = occupancy in percent, > 100 (e.g. 255) = unknown
        p = np.where(pixels <= 100, pixels / 100.0, np.nan)
        occ_rows = p > occ_t
        if unknown == "obstacle":
            occ_rows |= np.isnan(p) | (p >= free_t)
        occ = np.ascontiguousarray(occ_rows[::-1, :].T)
    else:
        occ = occupancy_from_pixels(
            pixels,
            occupied_thresh=occ_t,
            free_thresh=free_t,
            negate=bool(negate),
            unknown=unknown,
        )
    return _world(occ, float(res), origin[:2], yaml_path.stem, what)
