"""Mission-export options shared by every command that writes a mission, defined once.

``fm2uav plan``, ``cover``, ``formation`` and ``export`` take the same flags
(``--firmware``, ``--vehicle``, ``--frame``, ``--end``, ``--thin``,
``--speed-changes``, ``--endurance``, ...) with the names of the mission file's
``airframe:`` / ``outputs:`` keys. Each defaults to None = "not given", so a
mission file's value (``fm2uav export --mission``) or the library default
applies; :func:`export_options` builds the :class:`~fm2uav.io.ExportOptions`.
"""

from __future__ import annotations

from typing import Annotated, Any

import typer

from .._lazy import lazy_names
from ..errors import InputError

# re-exported from fm2uav.pipeline.outputs on first use: a parse error does not load it
__getattr__, __dir__ = lazy_names(__name__, {"export_options": "fm2uav.pipeline.outputs",
                                             "parse_anchor": "fm2uav.pipeline.outputs"})

__all__ = [
    "Firmware", "Vehicle", "Frame", "End", "Thin", "AnchorText", "SpeedChanges", "MinSpeed",
    "CruiseSpeed", "HoverSpeed", "Endurance", "Reserve", "Terrain", "TerrainSpacing", "Power",
    "Battery", "Wind", "WindFile", "Via", "Return", "parse_anchor",
    "via_points", "export_options",
]

Firmware = Annotated[str | None, typer.Option(
    help="Autopilot firmware: px4, ardupilot or generic (mission file airframe.firmware). "
    "Default px4.")]
Vehicle = Annotated[str | None, typer.Option(
    help="Airframe kind: multirotor, fixed_wing or vtol (airframe.type). Default multirotor.")]
Frame = Annotated[str | None, typer.Option(
    help="Altitude frame: auto (ArduPilot: terrain, PX4: amsl = DEM ground + AGL), terrain, "
    "amsl or relative (outputs.frame). Default auto.")]
End = Annotated[str | None, typer.Option(
    help="Mission end: auto, rtl, land or loiter (outputs.end). Default auto: land for "
    "multirotor/VTOL, rtl for fixed-wing (plus a landing at home on PX4).")]
Thin = Annotated[float | None, typer.Option(
    help="Waypoint tolerance (m) of the 3D Douglas–Peucker thinning (outputs.thin_tolerance). "
    "Default 5.")]
AnchorText = Annotated[str | None, typer.Option(
    "--anchor", help="lon,lat[,alt] of world x=y=0 for worlds without CRS (world.anchor). "
    "Default: -3.7649,40.3326,0 (UC3M Leganés).")]
SpeedChanges = Annotated[bool | None, typer.Option(
    "--speed-changes/--no-speed-changes",
    help="Write DO_CHANGE_SPEED items from the planned speed W (outputs.speed_changes).")]
MinSpeed = Annotated[float | None, typer.Option(
    help="Lowest commanded speed (m/s); fixed-wing speed changes need it (airframe.min_speed).")]
CruiseSpeed = Annotated[float | None, typer.Option(
    help="Fixed-wing / VTOL forward speed (m/s) (airframe.cruise_speed). Default 15.")]
HoverSpeed = Annotated[float | None, typer.Option(
    help="Multirotor forward speed (m/s) (airframe.hover_speed). Default 5.")]
Endurance = Annotated[float | None, typer.Option(
    help="Airframe endurance (min): the flight time is checked against it (airframe.endurance).")]
Reserve = Annotated[float | None, typer.Option(
    help="Share of the endurance kept in reserve (airframe.reserve). Default 0.2.")]
Terrain = Annotated[bool | None, typer.Option(
    "--terrain/--no-terrain",
    help="Write ArduPilot's terrain files (terrain/NxxEyyy.DAT for the SD card's "
    "APM/terrain/) from the world's ground (outputs.terrain). Default: with every "
    "terrain-frame mission.")]
TerrainSpacing = Annotated[int | None, typer.Option(
    help="Grid spacing (m) of the terrain files = the vehicle's TERRAIN_SPACING "
    "(outputs.terrain_spacing). Default: half the DEM's resolution, 30 to 100 m.")]
Power = Annotated[str | None, typer.Option(
    help="Power model of the energy figures: a preset (arducopter, disco, crosswind) or a "
    ".yaml/.json file of parameters, e.g. the one `fm2uav calibrate` fits to a flight log "
    "(airframe.power). Default: the class model of --vehicle.")]
Battery = Annotated[float | None, typer.Option(
    help="Battery energy (Wh) the flight's energy is checked against, with the reserve "
    "(airframe.battery). Default: the power model's.")]
Wind = Annotated[str | None, typer.Option(
    help="Wind as SPEED@DIR: m/s @ degrees it blows FROM, clockwise from north (8@270: 8 m/s "
    "from the west); the route is planned time-optimal in it and the energy and times "
    "figured in it (mission file wind:).")]
WindFile = Annotated[str | None, typer.Option(
    help="Gridded wind: a NetCDF file (u/v, u10/v10, ... on lon/lat; its first time step) "
    "or a two-band GeoTIFF (u, v in m/s) covering the map (mission file wind: {file: ..}).")]


Via = Annotated[list[str] | None, typer.Option(
    "--via", help="A point to pass on the way, in order (repeat for more): x,y,z metres, or "
    "LON,LAT,AGL with --lonlat (mission file via:). FM² plans each leg.")]
Return = Annotated[bool | None, typer.Option(
    "--return/--no-return", help="Plan a leg back from the goal to the start (mission file "
    "return:).")]


def via_points(via: list[str] | None, *, lonlat: bool) -> list[Any] | None:
    """``--via`` values as mission-file points (``[x, y, z]`` or ``{lon, lat, agl}``)."""
    if not via:
        return None
    out: list[Any] = []
    for k, text in enumerate(via):
        try:
            v = [float(p) for p in text.replace(",", " ").split() if p]
        except ValueError:
            v = []
        if len(v) != 3:
            form = "LON,LAT,AGL (degrees, degrees, metres above ground)" if lonlat else "x,y,z (m)"
            raise InputError(f"--via {k + 1} must be {form}, got {text!r}")
        out.append({"lon": v[0], "lat": v[1], "agl": v[2]} if lonlat else v)
    return out
