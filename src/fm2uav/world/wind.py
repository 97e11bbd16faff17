"""Wind fields: the velocity of the air over a world, in metres per second.

Three kinds, one object (:class:`WindField`):

* **constant** — a speed and the direction it blows *from*, in degrees clockwise from
  true north, as meteorology and every weather report say it: ``270`` is a west wind,
  the air moving east. Its velocity is ``u = −s sin θ`` (east), ``v = −s cos θ`` (north).
* **profile** — the same direction, the speed growing with the height above ground
  ``h`` by the power law ``s(h) = s_ref (h / h_ref)^α`` (``α = 1/7`` over open
  terrain, about 0.25–0.4 over towns and forest; below ``h_min`` = 1 m the speed of
  1 m). ``s_ref`` is measured at ``h_ref`` (10 m for a weather station, METAR).
* **grid** — ``u`` (east) and ``v`` (north) given on the nodes of a regular ``x, y``
  grid in world metres (a weather model's output, :mod:`fm2uav.world.wind_files`
  reads NetCDF and two-band GeoTIFFs onto the world), interpolated bilinearly,
  constant with height.

The wind is horizontal (no vertical air motion). The CLI takes ``--wind SPEED@DIR``
(e.g. ``8@270``: 8 m/s from the west) and ``--wind-file``; the mission file
``wind:`` (``{speed: 8, from: 270}``, with ``ref_height`` and ``exponent`` for a
profile, or ``{file: ...}``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .._validate import Where, in_range, non_negative, positive
from ..errors import InputError

__all__ = ["WindField", "parse_wind_text"]


@dataclass(frozen=True, eq=False)
class WindField:
    """A horizontal wind over a world (module docstring).

    Attributes
    ----------
    kind : {"constant", "profile", "grid"}
    speed : float
        Speed [m/s] (constant; the reference speed of a profile).
    direction_deg : float
        Direction the wind blows *from* [deg clockwise from true north].
    ref_height : float
        Height above ground of the reference speed [m] (profile).
    exponent : float
        Power-law exponent α (profile).
    x, y : ndarray
        Grid node coordinates [m], increasing (grid).
    u, v : ndarray, shape (len(x), len(y))
        East and north wind on the nodes [m/s] (grid).
    source : str
        Where the wind comes from (for the summary).
    """

    kind: Literal["constant", "profile", "grid", "file"] = "constant"
    speed: float = 0.0
    direction_deg: float = 0.0
    ref_height: float = 10.0
    exponent: float = 1.0 / 7.0
    x: np.ndarray | None = field(default=None, repr=False)
    y: np.ndarray | None = field(default=None, repr=False)
    u: np.ndarray | None = field(default=None, repr=False)
    v: np.ndarray | None = field(default=None, repr=False)
    source: str = ""
    file: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in ("constant", "profile", "grid", "file"):
            raise InputError(f"wind kind must be constant, profile, grid or file, got "
                             f"{self.kind!r}")
        object.__setattr__(self, "speed", non_negative(self.speed, "wind speed", unit="m/s",
                                                       where=("wind.speed", "--wind")))
        object.__setattr__(self, "direction_deg", in_range(
            self.direction_deg, "wind direction", 0.0, 360.0, unit="degrees",
            where=("wind.from", "--wind")) % 360.0)
        if self.kind == "profile":
            object.__setattr__(self, "ref_height", positive(
                self.ref_height, "wind reference height", unit="m",
                where=("wind.ref_height", None)))
            object.__setattr__(self, "exponent", in_range(
                self.exponent, "wind profile exponent", 0.0, 1.0, where=("wind.exponent", None)))
        if self.kind == "grid":
            x, y = np.asarray(self.x, float), np.asarray(self.y, float)
            u, v = np.asarray(self.u, float), np.asarray(self.v, float)
            if x.ndim != 1 or y.ndim != 1 or len(x) < 2 or len(y) < 2 or \
                    not (np.all(np.diff(x) > 0) and np.all(np.diff(y) > 0)):
                raise InputError("a gridded wind needs increasing x and y node coordinates, "
                                 "at least 2 each")
            if u.shape != (len(x), len(y)) or v.shape != u.shape:
                raise InputError(f"gridded wind u and v must have shape ({len(x)}, {len(y)}) "
                                 f"(x, y), got {u.shape} and {v.shape}")
            if not (np.all(np.isfinite(u)) and np.all(np.isfinite(v))):
                raise InputError("gridded wind has missing (NaN) values over the world: give "
                                 "a file that covers the whole map")
            for name, a in (("x", x), ("y", y), ("u", u), ("v", v)):
                object.__setattr__(self, name, a)

    # ------------------------------------------------------------------ builders
    @classmethod
    def constant(cls, speed: float, direction_deg: float, source: str = "") -> WindField:
        """A uniform wind of ``speed`` [m/s] from ``direction_deg`` [deg from north]."""
        return cls("constant", speed, direction_deg, source=source)

    @classmethod
    def profile(cls, speed: float, direction_deg: float, *, ref_height: float = 10.0,
                exponent: float = 1.0 / 7.0, source: str = "") -> WindField:
        """A power-law profile: ``speed`` at ``ref_height`` above ground, exponent α."""
        return cls("profile", speed, direction_deg, ref_height, exponent, source=source)

    @classmethod
    def from_file(cls, path: Any) -> WindField:
        """A gridded wind still in its file: :func:`fm2uav.world.wind_files.resolve_wind`
        samples it onto a world (checked there; ``at`` refuses it until then)."""
        return cls("file", file=str(path), source=str(path))

    @classmethod
    def grid(cls, x: Any, y: Any, u: Any, v: Any, source: str = "") -> WindField:
        """A gridded wind: ``u``, ``v`` [m/s] of shape ``(len(x), len(y))`` on nodes [m]."""
        return cls("grid", x=x, y=y, u=u, v=v, source=source)

    # ------------------------------------------------------------------ answers
    @property
    def is_calm(self) -> bool:
        """No wind anywhere."""
        self._resolved()
        if self.kind == "grid":
            return bool(np.all(self.u == 0) and np.all(self.v == 0))
        return self.speed == 0.0

    def _resolved(self) -> None:
        if self.kind == "file":
            raise InputError(f"the wind of {self.file} is not on a map yet "
                             "(fm2uav.world.wind_files.resolve_wind)")

    def max_speed(self) -> float:
        """An upper bound of the wind speed [m/s] (a profile's at 500 m above ground)."""
        self._resolved()
        if self.kind == "grid":
            return float(np.max(np.hypot(self.u, self.v)))
        if self.kind == "profile":
            return self.speed * (500.0 / self.ref_height) ** self.exponent
        return self.speed

    def at(self, points: Any, agl: Any = None) -> np.ndarray:
        """Wind ``(u, v)`` [m/s] at points ``(..., 2|3)`` [m].

        Parameters
        ----------
        points : array_like, shape (..., 2) or (..., 3)
            Positions in world metres.
        agl : array_like, shape (...), optional
            Height above ground [m] (a profile needs it; default: ``ref_height``).

        Examples
        --------
        >>> w = WindField.constant(10.0, 270.0)       # from the west: blows east
        >>> np.round(w.at([[0.0, 0.0]]), 12).tolist()
        [[10.0, 0.0]]
        >>> p = WindField.profile(5.0, 0.0, ref_height=10.0, exponent=0.5)
        >>> np.round(p.at([[0, 0, 0]], agl=[40.0]), 12).tolist()   # from the north
        [[-0.0, -10.0]]
        """
        self._resolved()
        p = np.asarray(points, dtype=float)
        if p.ndim == 0 or p.shape[-1] not in (2, 3):
            raise InputError(f"wind points must be (..., 2|3) coordinates, got shape {p.shape}")
        lead = p.shape[:-1]
        if self.kind == "grid":
            return np.stack([self._bilinear(self.u, p), self._bilinear(self.v, p)], axis=-1)
        s = np.full(lead, self.speed)
        if self.kind == "profile":
            h = np.full(lead, self.ref_height) if agl is None else np.broadcast_to(
                np.asarray(agl, dtype=float), lead)
            s = self.speed * (np.maximum(h, 1.0) / self.ref_height) ** self.exponent
        th = math.radians(self.direction_deg)
        return np.stack([-s * math.sin(th), -s * math.cos(th)], axis=-1)

    def _bilinear(self, a: np.ndarray, p: np.ndarray) -> np.ndarray:
        x, y = self.x, self.y
        fx = np.interp(p[..., 0], x, np.arange(len(x)))
        fy = np.interp(p[..., 1], y, np.arange(len(y)))
        i = np.clip(np.floor(fx).astype(int), 0, len(x) - 2)
        j = np.clip(np.floor(fy).astype(int), 0, len(y) - 2)
        tx, ty = fx - i, fy - j
        return ((1 - tx) * (1 - ty) * a[i, j] + tx * (1 - ty) * a[i + 1, j]
                + (1 - tx) * ty * a[i, j + 1] + tx * ty * a[i + 1, j + 1])

    def on_nodes(self, world: Any) -> np.ndarray:
        """The wind on every node of ``world``: shape ``(*world.shape, world.ndim)`` [m/s]
        (the vertical component 0), as :func:`fm2uav.eikonal.fast_marching` takes it."""
        axes = [world.origin[k] + world.spacing[k] * np.arange(n)
                for k, n in enumerate(world.shape)]
        mesh = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
        agl = None
        if self.kind == "profile" and world.ndim == 3:
            ground = np.asarray(world.ground_height(mesh[..., 0], mesh[..., 1]), dtype=float)
            agl = mesh[..., 2] - ground
        uv = self.at(mesh[..., :2] if world.ndim == 2 else mesh, agl)
        if world.ndim == 3:
            uv = np.concatenate([uv, np.zeros(uv.shape[:-1] + (1,))], axis=-1)
        return uv

    def summary(self) -> dict[str, Any]:
        """JSON-friendly description."""
        out: dict[str, Any] = {"kind": self.kind, "max_speed_mps": round(self.max_speed(), 3),
                               "source": self.source}
        if self.kind != "grid":
            out.update(speed_mps=self.speed, from_deg=self.direction_deg)
        if self.kind == "profile":
            out.update(ref_height_m=self.ref_height, exponent=self.exponent)
        return out

    def describe(self) -> str:
        """One line for the printed summary."""
        if self.kind == "grid":
            return f"gridded, up to {self.max_speed():.1f} m/s ({self.source or 'arrays'})"
        base = f"{self.speed:g} m/s from {self.direction_deg:g}°"
        if self.kind == "profile":
            base += f" at {self.ref_height:g} m AGL, power law α = {self.exponent:.3g}"
        return base


def parse_wind_text(text: str, where: Where = ("wind", "--wind")) -> WindField:
    """``"SPEED@DIR"`` (m/s @ degrees the wind blows from) → a constant :class:`WindField`.

    Examples
    --------
    >>> parse_wind_text("8@270").describe()
    '8 m/s from 270°'
    """
    parts = str(text).replace(" ", "").split("@")
    try:
        speed, direction = (float(parts[0]), float(parts[1])) if len(parts) == 2 else (None, None)
    except ValueError:
        speed = direction = None
    if speed is None or direction is None:
        raise InputError(f"wind must be SPEED@DIRECTION, m/s @ degrees the wind blows from "
                         f"(clockwise from north), e.g. 8@270 for 8 m/s from the west; got "
                         f"{text!r} (CLI: --wind)")
    return WindField.constant(speed, direction, source=f"--wind {text}")
