"""Zigzag (boustrophedon) bands over an irregular area (seeds 003 §III-A, thesis §5.2.1).

For a steering angle α the tangent line to the area with direction α is found;
the first band is D/2 from it, the next bands D apart, until the visual field
(D/2 each side) of the last band reaches the far tangent — when the last band
needed lies outside the area this is the seeds' extra band ``b(n+1)``. Each
band is cut where its visual-field strip leaves the area (the seeds' cut
points with the D/2 lines ``bv``), consecutive bands are joined by semicircles
of diameter D, and where two joined bands end at different places the shorter
one is extended to the longer one's perpendicular (the seeds' cut-point
adjustment). Band 0 is flown from the greatest x to the smallest.

The exact strip extents are computed in :mod:`._kernels`, shared with the
cost function, so the geometry and the cost are the same construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from shapely.geometry import LineString, Polygon

from ...errors import InputError
from ._kernels import band_ends, strip_extents
from .area import as_area, check_spacing, exterior_edges

__all__ = ["Zigzag", "zigzag", "frame"]


def frame(angle: float) -> tuple[np.ndarray, np.ndarray]:
    """Unit band direction ``u`` and sweep direction ``n`` for a steering angle [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c, s]), np.array([-s, c])


def _to_xy(t: np.ndarray, s: np.ndarray, angle: float) -> np.ndarray:
    u, n = frame(angle)
    return np.asarray(t)[..., None] * u + np.asarray(s)[..., None] * n


@dataclass(frozen=True, eq=False)
class Zigzag:
    """A zigzag coverage path over an area.

    Attributes
    ----------
    area : shapely.Polygon
        The area covered [m].
    spacing : float
        Band spacing D [m] (= width of the camera's useful visual field).
    angle : float
        Steering angle α of the bands [rad], measured from the x axis.
    band_s : ndarray, shape (n,)
        Across coordinate ``s`` of each band line [m] (see :mod:`._kernels`).
    t_start, t_end : ndarray, shape (n,)
        Along-band coordinate where each straight band starts / ends, in
        flight order [m].
    extent : ndarray, shape (n, 2)
        ``[lo, hi]`` along-band extent of the area inside each band's
        visual-field strip [m] (what the band must fly over to cover it).
    """

    area: Polygon
    spacing: float
    angle: float
    band_s: np.ndarray = field(repr=False)
    t_start: np.ndarray = field(repr=False)
    t_end: np.ndarray = field(repr=False)
    extent: np.ndarray = field(repr=False)

    # ---------------------------------------------------------------- numbers
    @property
    def n_bands(self) -> int:
        """Number of straight bands."""
        return int(self.band_s.size)

    @property
    def angle_deg(self) -> float:
        """Steering angle [deg]."""
        return math.degrees(self.angle)

    @property
    def straight_length(self) -> float:
        """Σ dᵢ: total length of the straight bands [m]."""
        return float(np.abs(self.t_end - self.t_start).sum())

    @property
    def arc_length(self) -> float:
        """Σ lᵢ: total length of the semicircles joining the bands [m]."""
        return (self.n_bands - 1) * math.pi * self.spacing / 2.0

    @property
    def cost(self) -> float:
        """C(α) = Σ (dᵢ + lᵢ) [m] (seeds eq. 5.4)."""
        return self.straight_length + self.arc_length

    @property
    def starts(self) -> np.ndarray:
        """(n, 2) start point of each straight band [m], flight order."""
        return _to_xy(self.t_start, self.band_s, self.angle)

    @property
    def ends(self) -> np.ndarray:
        """(n, 2) end point of each straight band [m], flight order."""
        return _to_xy(self.t_end, self.band_s, self.angle)

    @property
    def start(self) -> np.ndarray:
        """First point of the path [m]."""
        return self.starts[0]

    @property
    def goal(self) -> np.ndarray:
        """Last point of the path [m]."""
        return self.ends[-1]

    @cached_property
    def extra_bands(self) -> list[int]:
        """Bands whose line does not meet the area (the seeds' extra last band)."""
        out = []
        for i, seg in enumerate(self.band_lines()):
            if not seg.intersects(self.area):
                out.append(i)
        return out

    # ---------------------------------------------------------------- geometry
    def band_lines(self) -> list[LineString]:
        """The straight legs as flown [m], flight order.

        Each leg is a band plus what the path flies on the same line: the
        extension that brings a shorter band to its neighbour's perpendicular
        (the seeds' cut-point adjustment, part of the turn) and transits over
        bays or holes wider than the strip. Those parts can lie up to 1.5 D
        from the area where a side of it is nearly parallel to the bands; the
        bands proper are :meth:`bands`.
        """
        return [LineString([a, b]) for a, b in zip(self.starts, self.ends)]

    def arc_points(self, i: int, n: int = 33) -> np.ndarray:
        """(n, 2) points of the semicircle joining band ``i`` to band ``i + 1`` [m]."""
        if not 0 <= i < self.n_bands - 1:
            raise InputError(f"arc index {i} out of range 0..{self.n_bands - 2}")
        r = self.spacing / 2.0
        side = -1.0 if i % 2 == 0 else 1.0  # band 0 ends on the low-t side
        phi = np.linspace(-math.pi / 2, math.pi / 2, n)
        t = self.t_end[i] + side * r * np.cos(phi)
        s = self.band_s[i] + r + r * np.sin(phi)
        return _to_xy(t, s, self.angle)

    def path(self, step: float | None = None) -> np.ndarray:
        """The whole zigzag as one (N, 2) polyline [m]: bands and sampled arcs.

        Parameters
        ----------
        step : float, optional
            Largest distance between consecutive points [m]; default D/16.
        """
        step = self.spacing / 16.0 if step is None else float(step)
        if not step > 0:
            raise InputError(f"step must be > 0 metres, got {step!r}")
        n_arc = max(int(math.ceil(math.pi * self.spacing / 2.0 / step)), 8) + 1
        pieces = []
        starts, ends = self.starts, self.ends
        for i in range(self.n_bands):
            seg_len = float(np.linalg.norm(ends[i] - starts[i]))
            k = max(int(math.ceil(seg_len / step)), 1) + 1
            w = np.linspace(0.0, 1.0, k)[:, None]
            band = starts[i] + w * (ends[i] - starts[i])
            pieces.append(band if i == 0 else band[1:])
            if i < self.n_bands - 1:
                pieces.append(self.arc_points(i, n_arc)[1:])
        return np.vstack(pieces)

    def line(self) -> LineString:
        """The whole zigzag as a shapely line [m]."""
        return LineString(self.path())

    def bands(self) -> list[LineString]:
        """The bands: the parts of the legs that see the area, flight order [m].

        Every point of a band is within D/2 of the area (inside the polygon
        enlarged by D/2), and flying the bands covers the whole area.
        """
        return self.covering_segments()

    def covering_segments(self) -> list[LineString]:
        """The parts of the bands that see the area (what must be flown to cover it).

        A band crossing a hole or a bay wider than its strip is split there;
        the remaining parts of the straight bands are transits or the
        extensions that let two bands meet a semicircle.
        """
        u, n = frame(self.angle)
        out: list[LineString] = []
        half = self.spacing / 2.0
        for i in range(self.n_bands):
            lo, hi = self.extent[i]
            pad = self.spacing
            corners = _to_xy(
                np.array([lo - pad, hi + pad, hi + pad, lo - pad]),
                self.band_s[i] + np.array([-half, -half, half, half]),
                self.angle,
            )
            piece = self.area.intersection(Polygon(corners))
            intervals = []
            for g in getattr(piece, "geoms", [piece]):
                if g.is_empty or g.geom_type not in ("Polygon", "LineString", "Point"):
                    continue
                xy = np.asarray(g.exterior.coords if g.geom_type == "Polygon" else g.coords)
                t = xy @ u
                intervals.append((float(t.min()), float(t.max())))
            intervals.sort()
            merged: list[list[float]] = []
            for a, b in intervals:
                if merged and a <= merged[-1][1] + 1e-9:
                    merged[-1][1] = max(merged[-1][1], b)
                else:
                    merged.append([a, b])
            pieces = [(a, b) for a, b in merged if b - a > 1e-9]
            if i % 2 == 0:  # even bands are flown towards decreasing t
                pieces = [(b, a) for a, b in reversed(pieces)]
            for a, b in pieces:
                out.append(LineString(_to_xy(np.array([a, b]), np.full(2, self.band_s[i]),
                                             self.angle)))
        return out


def zigzag(area, spacing: float, angle: float) -> Zigzag:
    """Build the zigzag path covering ``area`` with bands D apart at steering angle α.

    Parameters
    ----------
    area : Polygon or GeoJSON dict or (k, 2) vertices
        The area [m]; non-convex and with holes allowed (validated by
        :func:`~fm2uav.missions.coverage.area.as_area`).
    spacing : float
        Band spacing D [m].
    angle : float
        Steering angle α [rad] (the seeds search α in [1°, 89°]; any real
        angle is accepted, α and α + π give the same band lines).

    Returns
    -------
    Zigzag

    Raises
    ------
    InputError
        Invalid area, D <= 0 or larger than the area, non-finite angle.

    Examples
    --------
    >>> import math
    >>> z = zigzag([(0, 0), (400, 0), (400, 200), (0, 200)], 100.0, 0.0)
    >>> z.n_bands, round(z.cost, 3) == round(2 * 400 + math.pi * 50, 3)
    (2, True)
    """
    poly = as_area(area)
    d = check_spacing(poly, spacing)
    a = float(angle)
    if not math.isfinite(a):
        raise InputError(f"the steering angle must be finite (radians), got {angle!r}")
    ax, ay, bx, by = exterior_edges(poly)
    smin, lo, hi = strip_extents(ax, ay, bx, by, a, d)
    t0, t1 = band_ends(lo, hi)
    band_s = smin + (np.arange(lo.size) + 0.5) * d
    return Zigzag(area=poly, spacing=d, angle=a, band_s=band_s, t_start=t0, t_end=t1,
                  extent=np.column_stack([lo, hi]))
