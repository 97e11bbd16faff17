"""Top views of a world in lon/lat for the matplotlib figures (plan.png, coverage.png, ...).

:class:`LonLatMap` draws, on one matplotlib ``Axes`` in degrees (aspect
1/cos(latitude), so a metre is as long east as north):

* the ground as shaded relief with labelled contours
  (:func:`fm2uav.viz.basemap.lonlat_image`, filled DEM nodata hatched orange),
* buildings / obstacles as filled outlines with their footprints
  (:func:`fm2uav.viz.basemap.obstacle_footprints`) — never a black panel,
* no-fly zones (red, filled) and the operating area (green, dashed), labelled with
  their floor and ceiling,
* paths — one coloured by its height above the ground with a colour bar — points,
  areas, and a scale bar,

with lon/lat ticks from :class:`LonLatLocator` / :class:`LonLatFormatter`: as many
round steps as the axis has room for at its size and font (labels never collide),
written ``10.335° E``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.ticker import Formatter, MaxNLocator

__all__ = ["LonLatMap", "LonLatLocator", "LonLatFormatter", "AGL_CMAP"]

#: Colours of the height above ground as a share of the requested height (as the map's).
_AGL_STOPS = ((0.0, "#d7191c"), (0.5 / 1.6, "#fdae61"), (1.0 / 1.6, "#1a9641"),
              (1.0, "#2b83ba"))


def _agl_cmap() -> Any:
    from matplotlib.colors import LinearSegmentedColormap

    return LinearSegmentedColormap.from_list("fm2uav_agl", list(_AGL_STOPS))


AGL_CMAP = _agl_cmap()


def _decimals(step: float) -> int:
    """Decimals that write every multiple of ``step`` exactly (0.25 → 2, 0.005 → 3)."""
    for d in range(0, 9):
        if abs(round(step * 10 ** d) - step * 10 ** d) < 1e-6 * max(1.0, step * 10 ** d):
            return d
    return 8


class LonLatFormatter(Formatter):
    """Degrees with a hemisphere: ``10.335° E``, ``46.03° N``; decimals from the tick step."""

    def __init__(self, axis: str) -> None:
        if axis not in ("lon", "lat"):
            raise ValueError("axis must be 'lon' or 'lat'")
        self.kind = axis
        self._decimals = 3

    def _text(self, v: float) -> str:
        hemi = ("E" if v >= 0 else "W") if self.kind == "lon" else ("N" if v >= 0 else "S")
        return f"{abs(v):.{self._decimals}f}° {hemi}"

    def format_ticks(self, values: Any) -> list[str]:
        v = np.asarray(values, dtype=float)
        if len(v) > 1:
            self._decimals = _decimals(float(np.min(np.diff(v))))
        return [self._text(x) for x in v]

    def __call__(self, x: float, pos: int | None = None) -> str:
        return self._text(x)

    def format_data_short(self, value: float) -> str:
        return f"{value:.6f}°"


class LonLatLocator(MaxNLocator):
    """Round degree ticks (1, 2, 2.5, 5 × 10^k) as many as fit: the number of ticks follows
    the axis length and the widest label at the tick labels' font size, so neighbouring
    labels keep a gap (x axis: their widths; y axis: their heights)."""

    def __init__(self, axis: str, *, fontsize: float = 8.0, gap_pt: float = 14.0) -> None:
        super().__init__(nbins=5, steps=[1, 2, 2.5, 5, 10])
        self.kind = axis
        self.fontsize = float(fontsize)
        self.gap_pt = gap_pt

    def __call__(self) -> Any:
        vmin, vmax = self.axis.get_view_interval()
        return self.tick_values(vmin, vmax)

    def tick_values(self, vmin: float, vmax: float) -> Any:
        axis = getattr(self, "axis", None)
        if axis is not None and axis.axes is not None:
            ax = axis.axes
            fig = ax.figure
            box = ax.get_position()
            w_in, h_in = fig.get_size_inches()
            length_pt = 72.0 * (box.width * w_in if self.kind == "lon" else box.height * h_in)
            size = self.fontsize
            # the widest label: "179.9999° W" → digits + 3 characters; the y labels are
            # one line high
            span = abs(vmax - vmin) or 1.0
            digits = len(f"{max(abs(vmin), abs(vmax)):.0f}") + _decimals(span / 5) + 1
            need = ((digits + 3) * 0.62 * size if self.kind == "lon" else 1.3 * size)
            # one tick is allowed: MaxNLocator otherwise shrinks the step below the room
            # a label needs to show two (a narrow map would get colliding labels)
            self.set_params(nbins=max(1, int(length_pt // (need + self.gap_pt))),
                            min_n_ticks=1)
        return super().tick_values(vmin, vmax)


class LonLatMap:
    """A top view of ``world`` in lon/lat on ``ax`` (see the module docstring).

    Parameters
    ----------
    ax : matplotlib Axes
    world : World
    anchor : Anchor, optional
        Placement of a world without CRS (the exports' default).
    relief : bool
        Draw the shaded relief and contours (else a plain ground).
    buildings : bool
        Draw what stands on the ground.
    zones : bool
        Draw ``world.zones`` with their labels.
    """

    def __init__(self, ax: Any, world: Any, anchor: Any = None, *, relief: bool = True,
                 buildings: bool = True, zones: bool = True, contours: bool = True) -> None:
        from .basemap import lonlat_image

        self.ax, self.world, self.anchor = ax, world, anchor
        self.image = lonlat_image(world, anchor, rows="linear", max_px=900, min_px=500)
        w, s, e, n = self.image.bounds
        self.lat0 = 0.5 * (s + n)
        ax.imshow(self.image.rgba if relief else self._plain(), extent=self.image.extent(),
                  origin="upper", interpolation="bilinear", zorder=0)
        if relief and contours and self.image.elev is not None:
            self._contours()
        if buildings:
            self.buildings()
        if zones:
            self.zones()
        if self.image.filled:
            from .basemap import FILLED_RGB

            ax.fill([], [], facecolor=np.array(FILLED_RGB) / 255, hatch="///", alpha=0.6,
                    label="filled DEM nodata (unknown ground)")
        ax.set_xlim(w, e)
        ax.set_ylim(s, n)
        ax.set_aspect(1.0 / math.cos(math.radians(self.lat0)))
        ax.xaxis.set_major_locator(LonLatLocator("lon", fontsize=8))
        ax.xaxis.set_major_formatter(LonLatFormatter("lon"))
        ax.yaxis.set_major_locator(LonLatLocator("lat", fontsize=8))
        ax.yaxis.set_major_formatter(LonLatFormatter("lat"))
        ax.tick_params(labelsize=8)
        ax.grid(color="#334", alpha=0.25, lw=0.5, ls=":")

    def _plain(self) -> np.ndarray:
        img = self.image.rgba.copy()
        img[..., :3] = np.where(img[..., 3:] > 0, 236, 255)
        return img

    def _contours(self) -> None:
        from .terrain import contour_interval

        z = self.image.elev
        lo, hi = float(np.nanmin(z)), float(np.nanmax(z))
        if not hi - lo > 1e-6:
            return
        step = contour_interval(lo, hi, lines=10)
        levels = np.arange(math.floor(lo / step + 1) * step, hi, step)
        if not len(levels):
            return
        cs = self.ax.contour(self.image.lon, self.image.lat, np.ma.masked_invalid(z),
                             levels=levels, colors="#3b2f20", linewidths=0.4, alpha=0.55,
                             zorder=1)
        self.ax.clabel(cs, levels=levels[::2], fontsize=6, fmt="%.0f m", inline=True)

    def lonlat(self, pts: Any) -> np.ndarray:
        """World points [m] → ``(n, 2)`` lon/lat (NaN rows kept)."""
        from ..world.geo import to_lonlat

        p = np.asarray(pts, dtype=float)
        out = np.full((len(p), 2), np.nan)
        ok = np.all(np.isfinite(p[:, :2]), axis=1)
        if ok.any():
            out[ok] = np.asarray(to_lonlat(self.world, p[ok, :2], anchor=self.anchor))[:, :2]
        return out

    def buildings(self) -> None:
        """Obstacles standing on the ground: filled grey, outlined."""
        from matplotlib.collections import PathCollection
        from matplotlib.path import Path as MPath

        from .basemap import footprints_lonlat, obstacle_footprints

        fps = footprints_lonlat(self.world, obstacle_footprints(self.world), self.anchor)
        if not fps:
            return
        paths = []
        for rings, _h in fps:
            verts = np.concatenate(rings)
            codes = np.concatenate([[MPath.MOVETO] + [MPath.LINETO] * (len(r) - 2)
                                    + [MPath.CLOSEPOLY] for r in rings])
            paths.append(MPath(verts, codes))
        coll = PathCollection(paths, facecolor="#5f5f66", edgecolor="#1b1b1b", linewidth=0.5,
                              alpha=0.85, zorder=3)
        self.ax.add_collection(coll)
        label = "buildings" if self.world.ndim == 3 else "obstacles"
        self.ax.fill([], [], facecolor="#5f5f66", edgecolor="#1b1b1b", lw=0.5,
                     label=f"{label} ({len(fps)})")

    def zones(self) -> None:
        """No-fly zones (red, filled) and the operating area (green, dashed), labelled."""
        zs = tuple(getattr(self.world, "zones", ()))
        seen = set()
        for z in zs:
            geoms = getattr(z.geometry, "geoms", [z.geometry])
            colour = "#1a9641" if z.inclusion else "#c0392b"
            for g in geoms:
                ring = self.lonlat(np.asarray(g.exterior.coords)[:, :2])
                if z.inclusion:
                    self.ax.plot(ring[:, 0], ring[:, 1], color=colour, lw=1.6, ls="--",
                                 zorder=4)
                else:
                    self.ax.fill(ring[:, 0], ring[:, 1], facecolor=colour, alpha=0.22,
                                 edgecolor=colour, lw=1.6, zorder=4)
            kind = "operating area" if z.inclusion else "no-fly zone"
            if kind not in seen:
                seen.add(kind)
                if z.inclusion:
                    self.ax.plot([], [], color=colour, lw=1.6, ls="--", label=kind)
                else:
                    self.ax.fill([], [], facecolor=colour, alpha=0.3, edgecolor=colour,
                                 label=kind)
            c = self.lonlat(np.asarray(z.geometry.representative_point().coords)[:, :2])[0]
            w, s, e, n = self.image.bounds
            if not (w <= c[0] <= e and s <= c[1] <= n):
                continue      # a zone beyond the map: its outline is cut, no label outside
            self.ax.text(c[0], c[1], _zone_label(z), fontsize=7, color="#8e1b10",
                         ha="center", va="center", zorder=6, clip_on=True,
                         bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none",
                               "alpha": 0.7})

    def path(self, pts: Any, **kw: Any) -> Any:
        """Plot a path [m] (``ax.plot`` keywords)."""
        ll = self.lonlat(pts)
        return self.ax.plot(ll[:, 0], ll[:, 1], **{"zorder": 5, **kw})

    def agl_path(self, pts: Any, agl: Any, requested: float | None, *, lw: float = 2.6,
                 label: str = "route", colorbar: bool = True) -> Any:
        """A path coloured by its height above ground (red at 0, green at ``requested``,
        blue above), with a colour bar; returns the LineCollection."""
        from matplotlib.collections import LineCollection
        from matplotlib.colors import Normalize

        ll = self.lonlat(pts)
        a = np.asarray(agl, dtype=float)
        top = float(np.nanmax(a)) if np.isfinite(a).any() else 1.0
        scale = requested if requested else max(top, 1.0) / 1.6
        segs = np.stack([ll[:-1], ll[1:]], axis=1)
        if lw >= 1.5:     # a dark edge lifts a route off the relief; dense bands go without
            self.ax.plot(ll[:, 0], ll[:, 1], color="black", lw=lw + 2.2, alpha=0.35, zorder=5,
                         solid_capstyle="round")
        lc = LineCollection(segs, cmap=AGL_CMAP, norm=Normalize(0.0, 1.6 * scale), lw=lw,
                            zorder=5, capstyle="round")
        lc.set_array(0.5 * (a[:-1] + a[1:]))
        self.ax.add_collection(lc)
        self.ax.plot([], [], color=AGL_CMAP(1.0 / 1.6), lw=lw, label=f"{label} (colour: "
                     "height above ground)")
        if colorbar:
            cb = self.ax.figure.colorbar(lc, ax=self.ax, shrink=0.8, pad=0.02, fraction=0.04)
            cb.set_label("height above ground [m]" + (f" (requested {requested:g} m)"
                                                      if requested else ""), fontsize=8)
            cb.ax.tick_params(labelsize=7)
        return lc

    def points(self, start: Any = None, goal: Any = None) -> None:
        """Start (green circle) and goal (gold star) of a path [m]."""
        if start is not None:
            q = self.lonlat(np.asarray(start, dtype=float)[None])[0]
            self.ax.plot(*q, "o", color="limegreen", mec="k", ms=8, label="start", zorder=7)
        if goal is not None:
            q = self.lonlat(np.asarray(goal, dtype=float)[None])[0]
            self.ax.plot(*q, "*", color="gold", mec="k", ms=13, label="goal", zorder=7)

    def legend(self, ncol: int = 3) -> Any:
        """The legend under the map (never over the route)."""
        return self.ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncol=ncol,
                              fontsize=7, frameon=False)

    def scale_bar(self) -> None:
        """A scale bar of a round length (about a fifth of the width), bottom right."""
        from matplotlib.offsetbox import AnchoredOffsetbox, AuxTransformBox, TextArea, VPacker
        from matplotlib.patches import Rectangle

        w, e = self.ax.get_xlim()
        m_per_deg = 111_320.0 * math.cos(math.radians(self.lat0))
        target = 0.2 * (e - w) * m_per_deg * (1.0 + 1e-9)   # a fifth of 500 m: 100 m, not 50
        e10 = 10 ** math.floor(math.log10(max(target, 1e-3)))
        length = max(m for m in (e10, 2 * e10, 5 * e10) if m <= target) if target >= e10 \
            else e10
        box = AuxTransformBox(self.ax.transData)
        box.add_artist(Rectangle((0, 0), length / m_per_deg, 0, fc="none", ec="black", lw=3))
        text = TextArea(f"{length / 1000:g} km" if length >= 1000 else f"{length:g} m",
                        textprops={"fontsize": 7})
        pack = VPacker(children=[box, text], align="center", pad=0, sep=2)
        self.ax.add_artist(AnchoredOffsetbox(loc="lower right", child=pack, pad=0.4,
                                             frameon=True, borderpad=0.5))


def _zone_label(z: Any) -> str:
    name = z.name or ("operating area" if z.inclusion else "no-fly zone")
    ref = "AGL" if z.reference == "agl" else "AMSL"
    if z.floor is None and z.ceiling is None:
        return f"{name}\nall heights"
    lo = "ground" if z.floor is None else f"{z.floor:g}"
    hi = "∞" if z.ceiling is None else f"{z.ceiling:g}"
    return f"{name}\n{lo}–{hi} m {ref}"
