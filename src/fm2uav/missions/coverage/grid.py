"""The corridor grid: the enlarged zigzag unrolled, on which the coverage FM² runs.

Why. Neighbouring bands are D apart and each sees D/2 on either side, so the
visual-field strips touch with no overlap: any sideways drift of the flown
path off a band line leaves an uncovered sliver along the strip boundary
(coverage loss ≈ drift / D). On the map's own grid a band crosses the node
rows at a slant and between nodes, and the FM² geodesic drifts 1–2 m off it
(the arrival times are only known at the nodes; the descent interpolates
them): S1–S4 come out 99.4–99.6 % covered, random polygons down to 96.6 %
(docs/coverage.md). Even on a grid aligned with the bands, a level that
varies across the corridor (sloping terrain) and the turns make the
descent settle 0.5–1 m off the line, depending on the fine print of the
gradient interpolation.

What. The corridor of half-width h around the zigzag is unrolled into a
curvilinear grid: axis 0 is the arc length σ along the zigzag (bands and
turns), axis 1 the signed offset ρ across it (ρ = 0 on the zigzag, nodes
``hρ ≤ one map cell`` apart, inside (-h, h)), axis 2 the map's z. Column
``(σ, ρ)`` sits at ``P(σ) + ρ N(σ)`` with P the zigzag and N its unit
normal. The velocity is the seeds' enlarged zigzag, ``C(ρ) = 1 - |ρ| / h``,
times the flight-level speed of the zigzag's own column (the level imposed
on the vertical curtain under the zigzag, Algorithm 2) extruded across the
corridor, and 0 on the obstacles of every column (sampled conservatively).
The map is symmetric about ρ = 0 wherever no obstacle intrudes into the
corridor at the flight level, hence so are the arrival times, and the
descent started on ρ = 0 stays on it: the flown ground track is the zigzag,
to rounding. An obstacle beside the line at the level height breaks the
symmetry and the path moves away from it inside the corridor (one on the
line is overflown: the level rises over it).

The metric of the unrolled grid is exact on ρ = 0 (σ is arc length); off it,
in the turns, lengths are scaled by ``1 - κρ`` (κ = 2/D on the semicircles),
which only matters for a detour around an obstacle in a turn.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from ...errors import InputError
from ...world import World
from .bands import Zigzag

__all__ = ["CorridorGrid", "corridor_grid"]


@dataclass(frozen=True, eq=False)
class CorridorGrid:
    """The map resampled on the unrolled corridor of a zigzag.

    Attributes
    ----------
    world : World
        The resampled map; axes ``(σ, ρ, z)`` [m], node ``(i, j, k)`` at
        ``origin + (i, j, k) * spacing`` with ``origin = (0, -(m - 1)/2 · hρ, z0)``.
    map : World
        The map it was sampled from.
    half_width : float
        Corridor half-width h [m].
    inside : ndarray of bool, shape (nσ, nρ)
        Columns whose (x, y) lies inside the map.
    skeleton : ndarray, shape (K, 2)
        The zigzag, densely sampled [m] (P).
    sigma : ndarray, shape (K,)
        Arc length of every skeleton point [m].
    normal : ndarray, shape (K, 2)
        Unit normal N (left of the direction of flight) at every skeleton point.
    """

    world: World
    map: World = field(repr=False)
    half_width: float
    inside: np.ndarray = field(repr=False)
    skeleton: np.ndarray = field(repr=False)
    sigma: np.ndarray = field(repr=False)
    normal: np.ndarray = field(repr=False)

    @property
    def centre(self) -> int:
        """Index of the column row ρ = 0."""
        return (self.world.shape[1] - 1) // 2

    @property
    def offsets(self) -> np.ndarray:
        """ρ of every node row [m]."""
        return self.world.origin[1] + self.world.spacing[1] * np.arange(self.world.shape[1])

    def to_map(self, points: np.ndarray) -> np.ndarray:
        """Grid points ``(..., 2 or 3)`` ``(σ, ρ[, z])`` → map ``(x, y[, z])`` [m]."""
        p = np.asarray(points, dtype=float)
        sig = np.clip(p[..., 0], self.sigma[0], self.sigma[-1])
        x = np.interp(sig, self.sigma, self.skeleton[:, 0])
        y = np.interp(sig, self.sigma, self.skeleton[:, 1])
        nx = np.interp(sig, self.sigma, self.normal[:, 0])
        ny = np.interp(sig, self.sigma, self.normal[:, 1])
        norm = np.hypot(nx, ny)
        out = p.copy()
        out[..., 0] = x + p[..., 1] * nx / norm
        out[..., 1] = y + p[..., 1] * ny / norm
        return out

    def from_map(self, xy: np.ndarray) -> np.ndarray:
        """Map points ``(..., 2)`` → ``(σ, ρ)`` of their nearest skeleton point [m]."""
        p = np.asarray(xy, dtype=float)[..., :2]
        _, idx = cKDTree(self.skeleton).query(p.reshape(-1, 2))
        rel = p.reshape(-1, 2) - self.skeleton[idx]
        rho = np.einsum("ij,ij->i", rel, self.normal[idx])
        return np.column_stack([self.sigma[idx], rho]).reshape(p.shape)

    def _map_index(self) -> tuple[np.ndarray, np.ndarray]:
        """Continuous map indices (ix, iy) of every grid column, each shape (nσ, nρ)."""
        g, m = self.world, self.map
        S, R = np.meshgrid(g.origin[0] + g.spacing[0] * np.arange(g.shape[0]), self.offsets,
                           indexing="ij")
        xy = self.to_map(np.stack([S, R], axis=-1))
        return ((xy[..., 0] - m.origin[0]) / m.spacing[0],
                (xy[..., 1] - m.origin[1]) / m.spacing[1])

    def sample(self, values: np.ndarray) -> np.ndarray:
        """Resample a map-node array ``(nx, ny, nz)`` at the grid's nodes (linear in x-y)."""
        return _sample(np.asarray(values, dtype=float), *self._map_index())

    def to_map_nodes(self, values: np.ndarray, fill: float) -> np.ndarray:
        """Resample a grid-node array ``(nσ, nρ, nz)`` at the map's nodes (linear).

        Map columns farther from the zigzag than the grid's outer rows, or
        next to a non-finite grid value, get ``fill``.
        """
        g, m = self.world, self.map
        x = m.origin[0] + m.spacing[0] * np.arange(m.shape[0])
        y = m.origin[1] + m.spacing[1] * np.arange(m.shape[1])
        X, Y = np.meshgrid(x, y, indexing="ij")
        sr = self.from_map(np.stack([X, Y], axis=-1))
        i = (sr[..., 0] - g.origin[0]) / g.spacing[0]
        j = (sr[..., 1] - g.origin[1]) / g.spacing[1]
        v = np.asarray(values, dtype=float)
        v = np.where(np.isfinite(v), v, np.nan)
        out = _sample(v, i, j, cval=np.nan)
        return np.where(np.isfinite(out), out, fill)


def _sample(values: np.ndarray, ix: np.ndarray, iy: np.ndarray, *,
            cval: float | None = None) -> np.ndarray:
    """``values[ix, iy, k]`` for every k, bilinear in (ix, iy); shape ``ix.shape + (nz,)``."""
    nz = values.shape[2]
    n2 = ix.size
    coords = np.empty((3, n2 * nz))
    coords[0] = np.repeat(ix.ravel(), nz)
    coords[1] = np.repeat(iy.ravel(), nz)
    coords[2] = np.tile(np.arange(nz, dtype=float), n2)
    mode = "nearest" if cval is None else "constant"
    out = ndimage.map_coordinates(values, coords, order=1, mode=mode,
                                  cval=0.0 if cval is None else cval, prefilter=False)
    return out.reshape(ix.shape + (nz,))


def _unit_normals(xy: np.ndarray) -> np.ndarray:
    tangent = np.gradient(xy, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    return np.column_stack([-tangent[:, 1], tangent[:, 0]])


#: Most geodesic steps (of half the corridor grid's finest cell) a coverage path may take.
MAX_CORRIDOR_STEPS = 5_000_000


def _check_corridor_work(total: float, n_sigma: int, n_rho: int, world: World, fine: float,
                         spacing: float) -> None:
    """Refuse a corridor grid too large to allocate or to descend (a tiny band spacing)."""
    from ...errors import WorldError
    from ...world.geo import check_size

    cell = min(world.spacing[0], world.spacing[1])
    hint = (f"use a band spacing of at least the map cell, {cell:g} m (fm2uav cover --spacing, "
            "or a camera/altitude giving a wider footprint with --camera)")
    steps = total / (0.5 * fine)
    if steps > MAX_CORRIDOR_STEPS:
        raise InputError(
            f"the band spacing D = {spacing:g} m is far finer than the map's {cell:g} m cells: "
            f"the coverage path ({total:.0f} m) would take {steps:.3g} steps of "
            f"{0.5 * fine:.3g} m (limit {MAX_CORRIDOR_STEPS:.0e}); {hint}")
    try:
        check_size((n_sigma, n_rho, world.shape[2]), (total / max(n_sigma - 1, 1), fine,
                                                      world.spacing[2]))
    except WorldError as exc:  # it names the world options; name the spacing here
        raise InputError(f"the coverage corridor grid is too large for D = {spacing:g} m "
                         f"({exc}); {hint}") from None


def corridor_grid(world: World, zz: Zigzag, half_width: float) -> CorridorGrid:
    """Resample ``world`` on the unrolled corridor of half-width ``half_width`` around ``zz``.

    Parameters
    ----------
    world : World
        3D map.
    zz : Zigzag
        The zigzag (its bands and turns are the corridor's centre line).
    half_width : float
        Corridor half-width h [m], in (0, D/2) (so the corridor does not fold
        over itself in the turns, whose radius is D/2).

    Returns
    -------
    CorridorGrid

    Raises
    ------
    InputError
        2D world, h outside (0, D/2).
    """
    if world.ndim != 3:
        raise InputError("the corridor grid needs a 3D world (nx, ny, nz)")
    h = float(half_width)
    if not (np.isfinite(h) and 0 < h < zz.spacing / 2.0):
        raise InputError(
            f"the corridor half-width must be in (0, D/2 = {zz.spacing / 2:g}) metres, got "
            f"{half_width!r}"
        )
    cell = min(world.spacing[0], world.spacing[1])
    skeleton = zz.path(step=cell / 8.0)
    seg = np.linalg.norm(np.diff(skeleton, axis=0), axis=1)
    keep = np.r_[True, seg > 1e-9 * zz.spacing]  # a zero-length band repeats a point
    skeleton, seg = skeleton[keep], seg[keep[1:]]
    sigma = np.r_[0.0, np.cumsum(seg)]
    normal = _unit_normals(skeleton)
    total = float(sigma[-1])
    n_sigma = max(int(math.ceil(total / cell - 1e-9)), 1) + 1
    h_sigma = total / (n_sigma - 1)
    # rows at 0, ±hρ, … strictly inside (-h, h): the edge rows would have C = 0
    r = max(int(math.ceil(h / cell - 1e-9)), 2)
    h_rho = h / r
    n_rho = 2 * r - 1
    _check_corridor_work(total, n_sigma, n_rho, world, min(h_sigma, h_rho), zz.spacing)
    g0 = World(np.zeros((n_sigma, n_rho, 1), bool), spacing=(h_sigma, h_rho, 1.0),
               origin=(0.0, -(r - 1) * h_rho, 0.0))
    probe = CorridorGrid(world=g0, map=world, half_width=h, inside=np.ones((1, 1), bool),
                         skeleton=skeleton, sigma=sigma, normal=normal)
    ix, iy = probe._map_index()
    tol = 1e-9
    inside = ((ix >= -tol) & (ix <= world.shape[0] - 1 + tol)
              & (iy >= -tol) & (iy <= world.shape[1] - 1 + tol))
    # conservative: an obstacle if any map node around the column (same height) is one
    occ = _sample(world.occupancy.astype(np.float32), ix, iy) > 1e-6
    grid = World(occ, spacing=(h_sigma, h_rho, world.spacing[2]),
                 origin=(0.0, -(r - 1) * h_rho, world.origin[2]),
                 name=f"{world.name} (corridor grid)".strip())
    return CorridorGrid(world=grid, map=world, half_width=h, inside=inside,
                        skeleton=skeleton, sigma=sigma, normal=normal)
