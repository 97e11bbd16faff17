"""Compiled clearance search for column worlds (private; see clearance.py)."""

from __future__ import annotations

import math

import numpy as np

from .._numba import njit


@njit(cache=True, error_model="numpy")
def column_clearance(points, surf, hx, hy, hz, ox, oy, oz):
    """Distance from each point to the nearest obstacle node of a column world.

    In a column world every obstacle column ``(i, j)`` is solid from layer 0
    up to ``surf[i, j]`` (``-1``: no obstacle). The nearest node of column
    ``(i, j)`` to a point at height ``z`` is the layer closest to ``z`` within
    ``[0, surf]``, so the search is 2D: columns are visited in rings of growing
    Chebyshev radius until the ring's smallest horizontal distance exceeds the
    best distance found.

    Parameters
    ----------
    points : ndarray, shape (N, 3)
        World coordinates [m].
    surf : ndarray of int64, shape (nx, ny)
        Top obstacle layer per column.
    hx, hy, hz : float
        Spacing [m].
    ox, oy, oz : float
        Origin [m].

    Returns
    -------
    ndarray, shape (N,)
        Distance [m] (``inf`` if there is no obstacle).
    """
    nx, ny = surf.shape
    out = np.empty(points.shape[0])
    rmax = nx + ny
    for p in range(points.shape[0]):
        x = points[p, 0]
        y = points[p, 1]
        z = points[p, 2]
        ci = int(math.floor((x - ox) / hx + 0.5))
        cj = int(math.floor((y - oy) / hy + 0.5))
        kz = (z - oz) / hz
        best2 = np.inf
        for r in range(rmax + abs(ci) + abs(cj) + 1):
            # smallest horizontal distance of any column on ring r
            ring = (r - 0.5) * min(hx, hy)
            if r > 0 and ring > 0 and ring * ring >= best2:
                break
            for i in range(ci - r, ci + r + 1):
                if i < 0 or i >= nx:
                    continue
                on_edge_i = i == ci - r or i == ci + r
                step = 1 if on_edge_i else 2 * r
                j = cj - r
                while j <= cj + r:
                    if 0 <= j < ny:
                        top = surf[i, j]
                        if top >= 0:
                            k = min(max(int(math.floor(kz + 0.5)), 0), top)
                            dx = ox + i * hx - x
                            dy = oy + j * hy - y
                            dz = oz + k * hz - z
                            d2 = dx * dx + dy * dy + dz * dz
                            if d2 < best2:
                                best2 = d2
                    if step == 0:
                        break
                    j += step
        out[p] = math.sqrt(best2)
    return out


@njit(cache=True, error_model="numpy")
def _tri_dist2(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Squared distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5)."""
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        qx, qy, qz = ax, ay, az
    else:
        bpx, bpy, bpz = px - bx, py - by, pz - bz
        d3 = abx * bpx + aby * bpy + abz * bpz
        d4 = acx * bpx + acy * bpy + acz * bpz
        if d3 >= 0.0 and d4 <= d3:
            qx, qy, qz = bx, by, bz
        else:
            vc = d1 * d4 - d3 * d2
            if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
                v = d1 / (d1 - d3)
                qx, qy, qz = ax + v * abx, ay + v * aby, az + v * abz
            else:
                cpx, cpy, cpz = px - cx, py - cy, pz - cz
                d5 = abx * cpx + aby * cpy + abz * cpz
                d6 = acx * cpx + acy * cpy + acz * cpz
                if d6 >= 0.0 and d5 <= d6:
                    qx, qy, qz = cx, cy, cz
                else:
                    vb = d5 * d2 - d1 * d6
                    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
                        w = d2 / (d2 - d6)
                        qx, qy, qz = ax + w * acx, ay + w * acy, az + w * acz
                    else:
                        va = d3 * d6 - d5 * d4
                        if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
                            w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
                            qx = bx + w * (cx - bx)
                            qy = by + w * (cy - by)
                            qz = bz + w * (cz - bz)
                        else:
                            den = 1.0 / (va + vb + vc)
                            v = vb * den
                            w = vc * den
                            qx = ax + abx * v + acx * w
                            qy = ay + aby * v + acy * w
                            qz = az + abz * v + acz * w
    dx, dy, dz = px - qx, py - qy, pz - qz
    return dx * dx + dy * dy + dz * dz


@njit(cache=True, error_model="numpy")
def surface_distance(points, start, heights, ox, oy, hx, hy, roofs, rox, roy, rhx, rhy):
    """Distance from each point to a terrain surface with box-shaped buildings on it.

    The terrain is the height grid ``heights`` (node ``(i, j)`` at ``(ox + i hx,
    oy + j hy)``) with each cell split into four triangles around its centre
    (centre height = mean of the corners, equal to the bilinear surface there;
    the triangles coincide with the bilinear surface on every cell edge).
    Buildings are the columns of ``roofs`` with a finite height: boxes
    ``[x_i ± rhx/2] x [y_j ± rhy/2]`` up to the roof.

    Parameters
    ----------
    points : ndarray (N, 3)
        World coordinates [m].
    start : ndarray (N,)
        An upper bound of each distance (the height above the surface right
        below the point) [m]; the search radius. Points with ``start <= 0`` are
        returned as ``start`` (at or below the surface).

    Returns
    -------
    ndarray (N,)
        Distance [m].
    """
    n = points.shape[0]
    mx, my = heights.shape
    nx, ny = roofs.shape
    out = np.empty(n)
    for p in range(n):
        x = points[p, 0]
        y = points[p, 1]
        z = points[p, 2]
        best = start[p]
        if not best > 0.0:
            out[p] = best
            continue
        best2 = best * best
        r = best
        i0 = max(int(math.floor((x - r - ox) / hx)), 0)
        i1 = min(int(math.floor((x + r - ox) / hx)), mx - 2)
        j0 = max(int(math.floor((y - r - oy) / hy)), 0)
        j1 = min(int(math.floor((y + r - oy) / hy)), my - 2)
        for i in range(i0, i1 + 1):
            xa = ox + i * hx
            xb = xa + hx
            gx = 0.0 if xa <= x <= xb else min(abs(x - xa), abs(x - xb))
            for j in range(j0, j1 + 1):
                ya = oy + j * hy
                yb = ya + hy
                gy = 0.0 if ya <= y <= yb else min(abs(y - ya), abs(y - yb))
                if gx * gx + gy * gy >= best2:
                    continue
                h00 = heights[i, j]
                h10 = heights[i + 1, j]
                h01 = heights[i, j + 1]
                h11 = heights[i + 1, j + 1]
                lo = min(min(h00, h10), min(h01, h11))
                if z > lo:
                    dzmin = 0.0 if z <= max(max(h00, h10), max(h01, h11)) else \
                        z - max(max(h00, h10), max(h01, h11))
                else:
                    dzmin = lo - z
                if gx * gx + gy * gy + dzmin * dzmin >= best2:
                    continue
                xc = xa + 0.5 * hx
                yc = ya + 0.5 * hy
                hc = 0.25 * (h00 + h10 + h01 + h11)
                d2 = _tri_dist2(x, y, z, xc, yc, hc, xa, ya, h00, xb, ya, h10)
                d2 = min(d2, _tri_dist2(x, y, z, xc, yc, hc, xb, ya, h10, xb, yb, h11))
                d2 = min(d2, _tri_dist2(x, y, z, xc, yc, hc, xb, yb, h11, xa, yb, h01))
                d2 = min(d2, _tri_dist2(x, y, z, xc, yc, hc, xa, yb, h01, xa, ya, h00))
                if d2 < best2:
                    best2 = d2
        if nx > 0:
            r = math.sqrt(best2)
            i0 = max(int(math.floor((x - r - rox) / rhx + 0.5)) - 1, 0)
            i1 = min(int(math.floor((x + r - rox) / rhx + 0.5)) + 1, nx - 1)
            j0 = max(int(math.floor((y - r - roy) / rhy + 0.5)) - 1, 0)
            j1 = min(int(math.floor((y + r - roy) / rhy + 0.5)) + 1, ny - 1)
            for i in range(i0, i1 + 1):
                xa = rox + (i - 0.5) * rhx
                xb = xa + rhx
                gx = 0.0 if xa <= x <= xb else min(abs(x - xa), abs(x - xb))
                for j in range(j0, j1 + 1):
                    top = roofs[i, j]
                    if not top > -1e300:
                        continue
                    ya = roy + (j - 0.5) * rhy
                    yb = ya + rhy
                    gy = 0.0 if ya <= y <= yb else min(abs(y - ya), abs(y - yb))
                    gz = z - top if z > top else 0.0
                    d2 = gx * gx + gy * gy + gz * gz
                    if d2 < best2:
                        best2 = d2
        out[p] = math.sqrt(best2)
    return out


@njit(cache=True, error_model="numpy", nogil=True)
def _box_window(px, py, pz, rim, ox, oy, oz, hx, hy, hz, reach, best):
    """Smallest distance [m] from point p to the boxes of the ``rim`` nodes whose centres
    lie within ``reach`` [m] of p on every axis (``best`` if none is nearer).

    A box's distance is ``sqrt(gx^2 + gy^2 + gz^2)``, ``g = max(|c - p| - h / 2, 0)`` per
    axis (``c = o + i h`` its centre): the numbers :func:`clearance._box_distances`
    computes with numpy, operation for operation.
    """
    nx, ny, nz = rim.shape
    i0 = max(int(math.floor((px - reach - ox) / hx)) - 1, 0)
    i1 = min(int(math.ceil((px + reach - ox) / hx)) + 1, nx - 1)
    j0 = max(int(math.floor((py - reach - oy) / hy)) - 1, 0)
    j1 = min(int(math.ceil((py + reach - oy) / hy)) + 1, ny - 1)
    k0 = max(int(math.floor((pz - reach - oz) / hz)) - 1, 0)
    k1 = min(int(math.ceil((pz + reach - oz) / hz)) + 1, nz - 1)
    for i in range(i0, i1 + 1):
        gx = max(abs((ox + i * hx) - px) - 0.5 * hx, 0.0)
        for j in range(j0, j1 + 1):
            gy = max(abs((oy + j * hy) - py) - 0.5 * hy, 0.0)
            for k in range(k0, k1 + 1):
                if not rim[i, j, k]:
                    continue
                gz = max(abs((oz + k * hz) - pz) - 0.5 * hz, 0.0)
                d = math.sqrt(gx * gx + gy * gy + gz * gz)
                if d < best:
                    best = d
    return best


@njit(cache=True, error_model="numpy", nogil=True)
def min_box_clearances(points, offsets, dist, rim, ox, oy, oz, hx, hy, hz, r):
    """Smallest distance [m] from the points of each path to the obstacle cells (boxes).

    Path ``m`` is ``points[offsets[m]:offsets[m + 1]]``. With ``d`` the distance from a
    point's nearest node to the nearest ``rim`` node (``dist``, a distance transform)
    and ``e`` the point's distance to that node, its clearance lies in
    ``[d - e - r, d + e]`` (``r`` half a cell diagonal); a point whose lower bound
    exceeds the smallest upper bound (or the smallest exact distance found) cannot hold
    the path's minimum. The others are measured exactly against the boxes of the rim
    nodes (obstacle nodes with a free axis neighbour; the nearest box is always one)
    whose centres lie within that bound plus ``r``: the path's minimum is the minimum of
    the exact distances, whatever the order.

    Parameters
    ----------
    points : ndarray, shape (N, 3)
        World coordinates [m] (2D worlds padded with z = 0).
    offsets : ndarray of int64, shape (M + 1,)
    dist : ndarray, shape (nx, ny, nz)
        Distance [m] from each node to the nearest rim node's centre.
    rim : ndarray of bool, shape (nx, ny, nz)
        The obstacle nodes with a free axis neighbour (at least one).
    ox, oy, oz, hx, hy, hz : float
        Origin and spacing [m] (2D: any positive ``hz``).
    r : float
        Half the diagonal of a cell [m] (of the map's own axes).

    Returns
    -------
    ndarray, shape (M,)
        ``inf`` for a path without points.
    """
    nx, ny, nz = dist.shape
    m = offsets.shape[0] - 1
    out = np.full(m, np.inf)
    for p in range(m):
        a = offsets[p]
        b = offsets[p + 1]
        if b <= a:
            continue
        lower = np.empty(b - a)
        upper = np.inf
        first = a
        for q in range(a, b):
            px = points[q, 0]
            py = points[q, 1]
            pz = points[q, 2]
            i = min(max(int(math.floor((px - ox) / hx + 0.5)), 0), nx - 1)
            j = min(max(int(math.floor((py - oy) / hy + 0.5)), 0), ny - 1)
            k = min(max(int(math.floor((pz - oz) / hz + 0.5)), 0), nz - 1)
            ex = px - (ox + i * hx)
            ey = py - (oy + j * hy)
            ez = pz - (oz + k * hz)
            e = math.sqrt(ex * ex + ey * ey + ez * ez)
            d = dist[i, j, k]
            lower[q - a] = d - e - r
            if d + e < upper:
                upper = d + e
                first = q
        # the point of the smallest upper bound first: its exact distance bounds the others
        best = _box_window(points[first, 0], points[first, 1], points[first, 2], rim,
                           ox, oy, oz, hx, hy, hz, upper * (1 + 1e-12) + 1e-12 + r, np.inf)
        bound = min(best, upper)
        for q in range(a, b):
            if q == first or lower[q - a] > bound * (1 + 1e-12) + 1e-12:
                continue
            best = _box_window(points[q, 0], points[q, 1], points[q, 2], rim, ox, oy, oz,
                               hx, hy, hz, bound * (1 + 1e-12) + 1e-12 + r, best)
            bound = min(best, upper)
        out[p] = best
    return out
