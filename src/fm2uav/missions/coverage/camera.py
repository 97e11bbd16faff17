"""Band spacing from a camera, as ground-control software computes it.

Same relations as QGroundControl's survey camera calculator (pinhole camera
looking straight down over flat ground):

* ground sample distance ``GSD = sensor_width · AGL / (focal · image_width)`` [m/px];
* footprint across the track ``image_width · GSD`` and along it
  ``image_height · GSD`` [m] (swap sensor/image axes for a portrait mount);
* band spacing ``D = footprint_across · (1 − side_overlap)``; distance between
  photos ``footprint_along · (1 − front_overlap)``.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..._validate import positive
from ...errors import InputError

__all__ = ["Camera", "band_spacing"]


@dataclass(frozen=True)
class Camera:
    """A downward-looking camera.

    Attributes
    ----------
    sensor_width, sensor_height : float
        Sensor size [m] (e.g. 13.2e-3 x 8.8e-3 for a 1" sensor).
    focal_length : float
        Focal length [m] (e.g. 8.8e-3).
    image_width, image_height : int
        Image size [px].
    landscape : bool
        True: the image width lies across the flight direction (QGC default).
    """

    sensor_width: float
    sensor_height: float
    focal_length: float
    image_width: int
    image_height: int
    landscape: bool = True

    def __post_init__(self) -> None:
        for name in ("sensor_width", "sensor_height", "focal_length", "image_width",
                     "image_height"):
            positive(getattr(self, name), f"camera {name}")

    def gsd(self, agl: float) -> float:
        """Ground sample distance [m/px] at ``agl`` metres above the ground."""
        agl = positive(agl, "camera altitude AGL")
        sw, iw = ((self.sensor_width, self.image_width) if self.landscape
                  else (self.sensor_height, self.image_height))
        return sw * agl / (self.focal_length * iw)

    def footprint(self, agl: float) -> tuple[float, float]:
        """Ground footprint ``(across, along)`` the flight direction [m]."""
        g = self.gsd(agl)
        across, along = ((self.image_width, self.image_height) if self.landscape
                         else (self.image_height, self.image_width))
        return across * g, along * g

    def spacing(self, agl: float, side_overlap: float = 0.0) -> float:
        """Band spacing D [m] for a side overlap in [0, 1)."""
        return self.footprint(agl)[0] * (1.0 - _overlap("side_overlap", side_overlap))

    def trigger_distance(self, agl: float, front_overlap: float = 0.0) -> float:
        """Distance between photos along a band [m] for a front overlap in [0, 1)."""
        return self.footprint(agl)[1] * (1.0 - _overlap("front_overlap", front_overlap))


def _overlap(name: str, value: float) -> float:
    v = float(value)
    if not (0.0 <= v < 1.0):
        raise InputError(f"{name} must be a share in [0, 1) (e.g. 0.7 for 70 %), got {value!r}")
    return v


def band_spacing(camera: Camera, agl: float, side_overlap: float = 0.0) -> float:
    """Band spacing D [m] of ``camera`` flying ``agl`` metres above the ground."""
    return camera.spacing(agl, side_overlap)
