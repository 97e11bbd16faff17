"""Mission files: one YAML file describes a whole mission.

Schema (pydantic v2, strict types, unknown keys rejected)::

    version: 1                      # schema version (only 1)
    name: open-field TFF            # free text
    world:                          # a scenario, or dem and/or buildings (real data)
      scenario: open-field          # a built-in scenario (see `fm2uav plan --help`)
      seed: 0                       # relief seed of the scenario
      dem: terrain.tif              # or: any GDAL raster with a CRS, or [tile1.tif, tile2.tif]
      buildings: osm.geojson        # and/or: footprints (GeoJSON lon/lat, GPKG, SHP, KML/KMZ)
      bbox: [-3.78, 40.33, -3.74, 40.35]   # crop, lon/lat W, S, E, N
      sea_level: 0                  # [m] ground = max(DEM, sea_level) (topo-bathymetry)
      cell_size: 15                 # [m] horizontal grid cell (default: from the data)
      dz: 15                        # [m] vertical cell (default cell_size, <= planner.agl / 6)
      ceiling: 1500                 # [m] top node (default: highest ground + agl + margin)
      dem_fill: [national_30m.tif]  # DEMs in priority order filling the gaps of dem
      nodata: error                 # unknown ground: error | fill | error_on_route;
                                    # nodata_value: -9999 if undeclared
      default_height: 10            # buildings without height/building:levels; crs, margin,
                                    # height_cells, metres_per_level, ground_elevation,
                                    # allow_filled
      anchor: {lon: -3.7649, lat: 40.3326, alt: 0}   # where a world without CRS sits
    start: [300, 300, 300]          # x, y, z [m]; or {x, y, agl}, {lon, lat, alt},
    goal: {lon: -3.747, lat: 40.343, agl: 60}        # {lon, lat, agl} or {cell: [i, j, k]}
    via: [{lon: -3.755, lat: 40.338, agl: 60}]       # points to pass in order (like start/goal)
    return: false                   # true: plan a leg back from the goal to the start
    planner: {saturation: 1.0, exponent: 1.0, order: 2, agl: 60, p1: 0.5, p2: 1.5,
              min_agl: 30, max_agl: 120, saturation_distance: 100}   # [m]
    no_fly_zones: [airports.geojson, {polygon: [[x, y], ...], buffer: 50, ceiling: 120,
                   reference: agl}]   # files or inline zones (see fm2uav.io.zone_spec)
    operating_area: area.geojson    # or {polygon: ..., lonlat: true}; the plan stays inside
    airframe: {type: multirotor, firmware: px4, cruise_speed: 12, hover_speed: 5,
               endurance: 25, reserve: 0.2,   # [min] endurance checked with a 20 % reserve
               power: arducopter, battery: 74}   # power model (preset, file, or
                                    # {preset: .., mass_kg: ..}) and battery [Wh]
    wind: {speed: 8, from: 270}     # [m/s] from [deg]; + ref_height, exponent: a profile;
                                    # or {file: wind.nc} (NetCDF u/v on lon/lat, 2-band GeoTIFF)
    outputs:
      dir: out/my-mission           # relative to this file; default out/<file name> in the
                                    # current folder; `fm2uav run --out` overrides
      formats: [csv, geojson, kml, plan, wpl, html, png, json]
      thin_tolerance: 5             # [m] Douglas–Peucker tolerance of the waypoints
      frame: auto                   # auto | terrain | amsl | relative (MAVLink 10 / 0 / 3);
                                    # auto: ArduPilot terrain, PX4 amsl (DEM ground + AGL)
      end: auto                     # auto | rtl | land | loiter (auto: airframe-aware)
      speed_changes: false          # DO_CHANGE_SPEED from the planned speed W
    rally: [{lon: -3.76, lat: 40.34, agl: 60}]   # rally points (or a file, or auto / auto:3)
    returns: {enabled: true, min_agl: 30, strict: false}   # safe returns (docs/returns.md)

**Relative paths** in a mission file (``world.dem``, ``world.buildings``, zone
files, ``outputs.dir``) are relative to the folder of the mission file, whatever
the current folder (:meth:`Mission.output_dir`); before fm2uav 0.2 ``outputs.dir``
alone was read against the current folder, and ``fm2uav run`` says so where the
two differ (:class:`MissionWarning`). Paths given on the command line are
relative to the current folder.

**Types are strict**: numbers are numbers (``5e-1`` and ``1e3`` too: the file is
read with YAML 1.2's core schema for numbers, :func:`fm2uav._validate.load_yaml`),
never text, booleans or NaN/infinity; integers (``order``, ``version``, ``seed``)
are never ``true``/``false``.

The full field reference with ranges is in docs/operator.md. Every validation
error is reported on one line naming the field, the bad
value and what is allowed, e.g. ``planner.saturation = 1.5 is out of range;
allowed: 0 < saturation <= 1``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, PrivateAttr, ValidationError
from pydantic import ValidationInfo, field_validator, model_validator

from ..errors import InputError
from ..world.load import WorldSpec as DataWorldSpec
from ..world.load import check_points, load_world
from ..autopilot.firmware import FIRMWARES, VEHICLES
from .formats import EXPORT_FILES
from .zone_spec import ZoneSpec, resolve_zones

# numpy and the geo module load with the first world, not with the schema: a mission file's
# error is reported without them (tests/cli/test_init.py, bench_cli's `run bad.yaml`)
if TYPE_CHECKING:
    import numpy as np

    from ..world.geo import Anchor
    from ..autopilot.build import ExportOptions

__all__ = [
    "Mission",
    "MissionWarning",
    "WorldSpec",
    "PointSpec",
    "PlannerSpec",
    "AirframeSpec",
    "OutputSpec",
    "RallySpec",
    "ReturnsSpec",
    "OUTPUT_FORMATS",
    "ResolvedMission",
    "resolve_point",
    "load_mission",
    "parse_mission",
    "parse_world",
]

#: Output formats a mission can ask for (exports + report + figure + summary).
OUTPUT_FORMATS = (*EXPORT_FILES, "html", "png", "json")

_STRICT = ConfigDict(strict=True, extra="forbid", frozen=True, allow_inf_nan=False)


class MissionWarning(UserWarning):
    """Something about a mission file the user should know (shown as a ``warning:`` line)."""


def _no_bool(v: Any) -> Any:
    """Refuse ``true``/``false`` and ``2.0`` where an integer is expected (``True == 1``
    and ``2.0 == 2`` in Python, so a ``Literal[1, 2]`` would take them)."""
    if isinstance(v, (bool, float)):
        raise ValueError(f"has the wrong type ({type(v).__name__}), expected an integer")
    return v


def _empty() -> list:
    """A new empty list: the default of a list field. (``default_factory=list`` costs the
    command line ~4 ms: pydantic reads ``list``'s signature from its text, which compiles
    :mod:`tokenize`'s regular expressions.)"""
    return []


#: An integer literal that is never a boolean (``order: true`` is refused).
def _int_choice(*values: int) -> Any:
    from typing import Annotated

    return Annotated[Literal[values], BeforeValidator(_no_bool)]  # type: ignore[valid-type]


def _num(default: Any = None, *, unit: str = "", desc: str = "", **bounds: float) -> Any:
    return Field(default, description=desc, json_schema_extra={"unit": unit}, **bounds)


class AnchorSpec(BaseModel):
    """Where a world without a CRS is placed (lon/lat of world x = y = 0)."""

    model_config = _STRICT
    lon: float = _num(..., unit="deg", ge=-180, le=180, desc="longitude of world x=y=0")
    lat: float = _num(..., unit="deg", ge=-89, le=89, desc="latitude of world x=y=0")
    alt: float = _num(0.0, unit="m", ge=-500, le=9000, desc="altitude of world z=0 AMSL")


class WorldSpec(DataWorldSpec):
    """The map: a built-in scenario, or real data (DEM and/or buildings).

    The real-data keys (``dem``, ``dem_fill``, ``buildings``, ``bbox``, ``sea_level``,
    ``cell_size``, ``dz``, ``ceiling``, ``nodata``, ``nodata_value``, ``crs``,
    ``default_height``, ``metres_per_level``, ``height_cells``, ``margin``,
    ``ground_elevation``, ``allow_filled``) are :class:`fm2uav.world.load.WorldSpec`'s, shared with
    the CLI's world options; this adds the built-in ``scenario`` with its
    ``seed``, and the ``anchor`` of worlds without a CRS.
    """

    model_config = _STRICT
    scenario: str | None = Field(None, description="built-in scenario name")
    seed: int = _num(0, ge=0, le=2**31 - 1, desc="seed of the scenario's relief")
    anchor: AnchorSpec | None = Field(None, description="placement of a world without CRS")

    @field_validator("scenario")
    @classmethod
    def _known_scenario(cls, v: str | None) -> str | None:
        if v is None:
            return v
        from ..scenarios import SCENARIOS

        key = v.strip().lower().replace("_", "-").replace(" ", "-")
        if key not in SCENARIOS:
            raise ValueError(f"unknown scenario; allowed: {', '.join(sorted(SCENARIOS))}")
        return key

    @model_validator(mode="after")
    def _one_source(self) -> WorldSpec:
        data = [k for k in ("dem", "buildings") if getattr(self, k) is not None]
        if self.scenario is not None and data:
            raise ValueError(f"give either scenario or real data (dem and/or buildings), not "
                             f"both (got scenario and {' and '.join(data)})")
        if self.scenario is None and not data:
            raise ValueError("give exactly one of scenario, dem, buildings (or dem and "
                             "buildings together); got none")
        defaults = DataWorldSpec()
        if self.scenario is not None:
            for k in DataWorldSpec.model_fields:
                if getattr(self, k) != getattr(defaults, k):
                    raise ValueError(f"{k} does not apply to a built-in scenario (its grid is "
                                     "fixed); remove it")
            return self
        only = {"dem": ("ceiling", "nodata", "nodata_value", "sea_level", "allow_filled",
                        "dem_fill"),
                "buildings": ("height_cells", "default_height", "metres_per_level", "margin",
                              "ground_elevation")}
        for source, keys in only.items():
            if getattr(self, source) is None:
                for k in keys:
                    if getattr(self, k) != getattr(defaults, k):
                        raise ValueError(f"{k} only applies to a world with {source}, not a "
                                         f"{' and '.join(data)} world; remove it")
        if self.dem is not None and (self.height_cells is not None or self.margin is not None
                                     or self.ground_elevation is not None):
            raise ValueError("height_cells, margin and ground_elevation apply to buildings on "
                             "flat ground; on a DEM the grid and the ground follow the DEM (use "
                             "ceiling, bbox); remove them")
        return self

    def data_spec(self) -> DataWorldSpec:
        """The real-data part, as :func:`fm2uav.world.load.load_world` takes it."""
        return DataWorldSpec.model_construct(
            **{k: getattr(self, k) for k in DataWorldSpec.model_fields})


class PointSpec(BaseModel):
    """A start or goal: metres, lon/lat or grid cells; height as z/alt or agl."""

    model_config = _STRICT
    x: float | None = _num(None, unit="m", desc="world x")
    y: float | None = _num(None, unit="m", desc="world y")
    z: float | None = _num(None, unit="m", desc="world z")
    lon: float | None = _num(None, unit="deg", ge=-180, le=180, desc="longitude")
    lat: float | None = _num(None, unit="deg", ge=-90, le=90, desc="latitude")
    alt: float | None = _num(None, unit="m", desc="altitude above mean sea level")
    agl: float | None = _num(None, unit="m", gt=0, le=10000, desc="height above ground")
    cell: list[int] | None = Field(None, min_length=3, max_length=3,
                                   description="grid node [i, j, k]")

    @model_validator(mode="before")
    @classmethod
    def _from_list(cls, data: Any) -> Any:
        if isinstance(data, (list, tuple)):
            if len(data) != 3 or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in data
            ):
                raise ValueError("must be [x, y, z] (3 numbers, metres) or a mapping such as "
                                 "{lon: .., lat: .., agl: ..}")
            return {"x": data[0], "y": data[1], "z": data[2]}
        return data

    @model_validator(mode="after")
    def _consistent(self) -> PointSpec:
        xy = self.x is not None or self.y is not None
        ll = self.lon is not None or self.lat is not None
        cell = self.cell is not None
        if xy + ll + cell != 1:
            raise ValueError("give exactly one of: x and y [m], lon and lat [deg], or cell")
        if xy and (self.x is None or self.y is None):
            raise ValueError("give both x and y")
        if ll and (self.lon is None or self.lat is None):
            raise ValueError("give both lon and lat")
        heights = [k for k in ("z", "alt", "agl") if getattr(self, k) is not None]
        if cell:
            if heights:
                raise ValueError("a cell already fixes the height; drop " + heights[0])
            return self
        if len(heights) != 1:
            raise ValueError("give exactly one height: z [m] (or alt for lon/lat) or agl [m]")
        if xy and self.alt is not None:
            raise ValueError("with x/y give the height as z or agl, not alt")
        if ll and self.z is not None:
            raise ValueError("with lon/lat give the height as alt or agl, not z")
        return self


class PlannerSpec(BaseModel):
    """FM² parameters: the fields of :class:`~fm2uav.Shaping`, :class:`~fm2uav.FlightLevel`
    and :class:`~fm2uav.PlanOptions`, one spelling (see :func:`fm2uav.plan`).

    Flight-level keys need ``agl``. With ``agl`` and no ``p2`` the mission file
    keeps its historical default :data:`MISSION_P2` = 1.5 (the Python
    ``FlightLevel`` default is 1.3).
    """

    model_config = _STRICT
    saturation: float = _num(1.0, gt=0, le=1, desc="saturation α of W")
    exponent: float = _num(1.0, gt=0, le=10, desc="exponent β on W")
    saturation_distance: float | None = _num(None, unit="m", gt=0, le=100000,
                                             desc="distance from obstacles with W = 1")
    order: _int_choice(1, 2) = Field(2, description="Fast Marching order")  # type: ignore[valid-type]
    method: Literal["edt", "fmm"] = Field("edt", description="distance to obstacles")
    walls: bool = Field(False, description="treat the map border as an obstacle")
    agl: float | None = _num(None, unit="m", gt=0, le=5000, desc="flight level above ground")
    p1: float | None = _num(None, gt=0, le=10, desc="exponent on the flight-level cells (0.5)")
    p2: float | None = _num(None, gt=0, le=10, desc="exponent on the other cells (1.5)")
    band: float | None = _num(None, unit="m", ge=0, le=5000,
                              desc="half-width of the level band (0)")
    graded: bool | None = Field(None, description="blend p1→p2 across the band (false)")
    mode: Literal["capped", "literal"] | None = Field(
        None, description="reading of Algorithm 2 (capped)")
    tolerance: float | None = _num(None, unit="m", ge=0, le=1000,
                                   desc="cruise never below agl - tolerance (2)")
    min_agl: float | None = _num(None, unit="m", ge=0, le=5000, desc="hard floor above ground")
    max_agl: float | None = _num(None, unit="m", gt=0, le=5000, desc="hard ceiling above ground")
    max_climb: float | None = _num(None, unit="deg", gt=0, le=90, desc="steepest climb (45)")
    max_descent: float | None = _num(None, unit="deg", gt=0, le=90,
                                     desc="steepest descent (45)")
    heights: Literal["ground", "fm2"] | None = Field(
        None, description="ground: final profile above the continuous ground; fm2: the "
        "FM² layer's own heights")
    step: float = _num(0.5, gt=0, le=1, desc="geodesic step in cells")
    storage: Literal["auto", "full", "regional"] = Field(
        "auto", description="grid storage: full 3D grid, regional (coarse-to-fine windows, "
        "terrain + agl), or auto by memory")
    threads: int | None = Field(None, ge=1, le=4096, description="threads of the Fast "
                                "Marching (default: FM2UAV_THREADS, else every core)")

    @model_validator(mode="after")
    def _objects(self) -> PlannerSpec:
        # the objects check what the ranges cannot (agl <= max_agl, level keys need agl)
        from ..planning.params import planner_objects

        try:
            planner_objects(_planner_values(self))
        except InputError as exc:
            raise ValueError(str(exc)) from None
        return self


#: ``planner.p2`` of a mission file with ``agl`` and no ``p2`` (the value mission
#: files have always had; ``FlightLevel`` defaults to 1.3).
MISSION_P2 = 1.5


def _planner_values(spec: PlannerSpec) -> dict[str, Any]:
    """The given planner keys (None = not given), ``p2`` defaulted with ``agl``."""
    out = {k: v for k, v in spec.model_dump().items() if v is not None}
    if "agl" in out:
        out.setdefault("p2", MISSION_P2)
    return out


def _beside_mission(v: str, info: ValidationInfo) -> Path:
    """A path of the mission file: relative ones are taken from the file's folder."""
    p = Path(v).expanduser()
    base = (info.context or {}).get("base_dir")
    return p if p.is_absolute() or base is None else Path(base) / p


class AirframeSpec(BaseModel):
    """The aircraft, as far as the exports need it."""

    model_config = _STRICT
    type: Literal[VEHICLES] = Field("multirotor")  # type: ignore[valid-type]
    firmware: Literal[FIRMWARES] = Field("px4")  # type: ignore[valid-type]
    cruise_speed: float = _num(15.0, unit="m/s", gt=0, le=100, desc="cruise speed")
    hover_speed: float = _num(5.0, unit="m/s", gt=0, le=50, desc="multirotor speed")
    min_speed: float | None = _num(None, unit="m/s", gt=0, le=100,
                                   desc="lowest commanded speed (fixed-wing: above stall)")
    max_speed: float | None = _num(None, unit="m/s", gt=0, le=200,
                                   desc="highest airspeed (fixed-wing AIRSPEED_MAX)")
    max_bank: float | None = _num(None, unit="deg", ge=5, le=85,
                                  desc="bank limit (fixed-wing ROLL_LIMIT_DEG)")
    climb_rate: float | None = _num(None, unit="m/s", gt=0, le=50, desc="climb speed")
    descent_rate: float | None = _num(None, unit="m/s", gt=0, le=50, desc="descent speed")
    endurance: float | None = _num(None, unit="min", gt=0, le=10000,
                                   desc="flight endurance (battery / fuel)")
    reserve: float = _num(0.2, ge=0, lt=1, desc="share of the endurance kept in reserve")
    power: str | dict[str, Any] | None = Field(
        None, description="power model: a preset (arducopter, disco, crosswind), a .yaml/.json "
        "file (fm2uav calibrate writes one) or {preset: .., <parameter>: ..}")
    battery: float | None = _num(None, unit="Wh", gt=0, le=1_000_000,
                                 desc="battery energy (default: the power model's)")

    @field_validator("power")
    @classmethod
    def _power(cls, v: Any, info: ValidationInfo) -> Any:
        from ..vehicles.power import get_power_model

        if v is None:
            return v
        if isinstance(v, str) and Path(v).suffix.lower() in (".yaml", ".yml", ".json"):
            v = str(_beside_mission(v, info))
        try:
            get_power_model(v)
        except InputError as exc:
            raise ValueError(str(exc)) from None
        return v

    @model_validator(mode="after")
    def _speeds(self) -> AirframeSpec:
        key = "hover_speed" if self.type == "multirotor" else "cruise_speed"
        if self.min_speed is not None and self.min_speed > getattr(self, key):
            raise ValueError(
                f"min_speed {self.min_speed:g} m/s is above {key} {getattr(self, key):g} m/s, "
                f"the speed this {self.type.replace('_', '-')} flies the mission at; allowed: "
                f"min_speed <= {key}")
        return self


class WindSpec(BaseModel):
    """The wind: constant, a power-law profile with ``ref_height`` / ``exponent``, or a
    gridded ``file`` (NetCDF or two-band GeoTIFF)."""

    model_config = ConfigDict(strict=True, extra="forbid", frozen=True, populate_by_name=True)
    speed: float | None = _num(None, unit="m/s", ge=0, le=100, desc="wind speed")
    from_deg: float | None = Field(None, alias="from", ge=0, le=360,
                                   description="direction the wind blows from [deg from north]")
    ref_height: float | None = _num(None, unit="m", gt=0, le=1000,
                                    desc="height above ground of the speed (a profile)")
    exponent: float | None = _num(None, ge=0, le=1, desc="power-law exponent (a profile)")
    file: str | None = Field(None, description="gridded wind: NetCDF (u/v on lon/lat) or "
                             "two-band GeoTIFF, relative to the mission file")

    @field_validator("file")
    @classmethod
    def _file(cls, v: str | None, info: ValidationInfo) -> str | None:
        from ..world.wind_files import check_wind_file

        if v is None:
            return v
        try:
            return str(check_wind_file(_beside_mission(v, info)))
        except InputError as exc:
            raise ValueError(str(exc)) from None

    @model_validator(mode="after")
    def _one_kind(self) -> WindSpec:
        if self.file is not None:
            if any(x is not None for x in (self.speed, self.from_deg, self.ref_height,
                                           self.exponent)):
                raise ValueError("give either file or speed/from (a file holds the whole "
                                 "field)")
        elif self.speed is None or self.from_deg is None:
            raise ValueError("needs speed and from (m/s and degrees the wind blows from), or "
                             "a file")
        return self

    def field(self) -> Any:
        """The :class:`~fm2uav.world.wind.WindField` (a file's: read onto the map later)."""
        from ..world.wind import WindField

        if self.file is not None:
            return WindField.from_file(self.file)
        if self.ref_height is None and self.exponent is None:
            return WindField.constant(self.speed, self.from_deg, source="mission file wind:")
        return WindField.profile(self.speed, self.from_deg, ref_height=self.ref_height or 10.0,
                                 exponent=1 / 7 if self.exponent is None else self.exponent,
                                 source="mission file wind:")


class OutputSpec(BaseModel):
    """What to write and where."""

    model_config = _STRICT
    dir: str | None = Field(None, description="output folder")
    formats: list[Literal[OUTPUT_FORMATS]] = Field(  # type: ignore[valid-type]
        default_factory=lambda: list(OUTPUT_FORMATS), min_length=1)
    thin_tolerance: float = _num(5.0, unit="m", ge=0, le=1000, desc="waypoint tolerance")
    max_waypoints: int | None = _num(None, ge=2, le=10000, desc="cap on waypoints")
    frame: Literal["auto", "terrain", "amsl", "relative"] = Field("auto")
    takeoff: bool = Field(True, description="start with NAV_TAKEOFF (always true)")
    end: Literal["auto", "rtl", "land", "loiter"] = Field("auto")
    speed_changes: bool = Field(False, description="DO_CHANGE_SPEED from the planned speed")
    speed_step: float = _num(1.0, unit="m/s", gt=0, le=20, desc="speed quantum")
    terrain: bool | None = Field(None, description="ArduPilot terrain files (terrain/*.DAT); "
                                 "default: with terrain-frame missions")
    terrain_spacing: int | None = _num(None, unit="m", ge=5, le=1000,
                                       desc="terrain files grid spacing (TERRAIN_SPACING)")


class RallySiteSpec(BaseModel):
    """One rally site: lon/lat or x/y, and optionally the approach height above the ground."""

    model_config = _STRICT
    x: float | None = _num(None, unit="m", desc="world x")
    y: float | None = _num(None, unit="m", desc="world y")
    lon: float | None = _num(None, unit="deg", ge=-180, le=180, desc="longitude")
    lat: float | None = _num(None, unit="deg", ge=-90, le=90, desc="latitude")
    agl: float | None = _num(None, unit="m", gt=0, le=10000,
                             desc="approach height above the ground (default: the start's)")

    @model_validator(mode="after")
    def _one(self) -> RallySiteSpec:
        xy = self.x is not None and self.y is not None
        ll = self.lon is not None and self.lat is not None
        if xy == ll or (not xy and (self.x is not None or self.y is not None)):
            raise ValueError("give lon and lat [deg], or x and y [m]")
        return self


class RallySpec(BaseModel):
    """Rally points: ``auto`` / ``auto:K`` (the planner chooses K), a file, or a list of sites."""

    model_config = _STRICT
    auto: int | None = _num(None, ge=1, le=10, desc="rally points for the planner to choose")
    file: str | None = Field(None, description="points file (relative to the mission file)")
    points: list[RallySiteSpec] = Field(default_factory=_empty, max_length=10,
                                        description="rally sites")

    @model_validator(mode="before")
    @classmethod
    def _forms(cls, data: Any) -> Any:
        if isinstance(data, list):
            return {"points": data}
        if isinstance(data, str):
            t = data.strip()
            if t.lower() == "auto" or t.lower().startswith("auto:"):
                from .rally import parse_rally_text

                try:
                    return {"auto": parse_rally_text(t)[1]}
                except InputError as exc:
                    raise ValueError(str(exc).replace("--rally", "rally")) from None
            return {"file": t}
        return data

    @field_validator("file")
    @classmethod
    def _file(cls, v: str | None, info: Any) -> str | None:
        if v is None:
            return v
        p = Path(v).expanduser()
        base = (info.context or {}).get("base_dir") if info is not None else None
        if not p.is_absolute() and base is not None:
            p = Path(base) / p
        if not p.is_file():
            raise ValueError(f"file not found ({p}); allowed: a GeoJSON/KML/GPKG/SHP file of "
                             "points or a CSV lon,lat[,agl]")
        return str(p)


class ReturnsSpec(BaseModel):
    """The safe returns (docs/returns.md)."""

    model_config = _STRICT
    enabled: bool = Field(True, description="compute the ways back, the point of no return, "
                                            "the firmware return settings")
    min_agl: float | None = _num(None, unit="m", ge=0, le=5000,
                                 desc="floor of the straight firmware return lines above the "
                                      "surface (default planner.min_agl, else the cruise floor)")
    strict: bool = Field(False, description="refuse a mission that passes its point of no "
                                            "return before its end")


def _default(model: type[BaseModel]) -> Any:
    """The default factory of a section left out: ``model()`` (a function, not the class:
    pydantic reads a class factory's signature, one parameter per field, to see whether it
    takes the validated data)."""
    return lambda: model()


class Mission(BaseModel):
    """A whole mission file."""

    model_config = _STRICT
    version: _int_choice(1) = Field(1, description="schema version")  # type: ignore[valid-type]
    name: str = Field("mission", description="mission name")
    description: str = Field("", description="free text")
    world: WorldSpec = Field(..., description="the map: scenario, dem or buildings")
    start: PointSpec | None = Field(None, description="start point")
    goal: PointSpec | None = Field(None, description="goal point")
    via: list[PointSpec] = Field(default_factory=_empty, max_length=100,
                                 description="points to pass, in order")
    return_to_start: bool = Field(False, alias="return",
                                  description="plan a leg back to the start")
    planner: PlannerSpec = Field(default_factory=_default(PlannerSpec))
    no_fly_zones: list[ZoneSpec] = Field(default_factory=_empty, max_length=10000,
                                         description="no-fly zones: files or inline zones")
    operating_area: ZoneSpec | None = Field(None, description="area the mission stays in")
    airframe: AirframeSpec = Field(default_factory=_default(AirframeSpec))
    wind: WindSpec | None = Field(None, description="the wind: {speed, from[, ref_height, "
                                  "exponent]} or {file}")
    outputs: OutputSpec = Field(default_factory=_default(OutputSpec))
    _base_dir: Path | None = PrivateAttr(None)
    rally: RallySpec | None = Field(None, description="rally points: sites, a file or auto")
    returns: ReturnsSpec = Field(default_factory=_default(ReturnsSpec))

    @model_validator(mode="after")
    def _points_needed(self) -> Mission:
        if self.world.scenario is None:
            for what in ("start", "goal"):
                if getattr(self, what) is None:
                    raise ValueError(f"{what} is missing: a {self.world.describe() or 'data'}"
                                     f" world has no default {what}; give {what}: "
                                     "{lon: .., lat: .., agl: ..} or [x, y, z]")
        return self

    # ------------------------------------------------------------------ resolving
    def output_dir(self) -> Path | None:
        """``outputs.dir`` relative to the mission file's folder (None when not given).

        Like every path in a mission file (``world.dem``, zone files); a mission given
        as a dict without ``base_dir`` keeps it relative to the current folder.
        """
        if self.outputs.dir is None:
            return None
        p = Path(self.outputs.dir).expanduser()
        return p if p.is_absolute() or self._base_dir is None else self._base_dir / p

    def output_dir_notice(self) -> str | None:
        """The one-line notice that ``outputs.dir`` now lands elsewhere than before
        fm2uav 0.2 (read against the current folder), or None where both agree."""
        new = self.output_dir()
        if new is None or Path(self.outputs.dir).expanduser().is_absolute():
            return None
        import os

        try:
            old = Path(os.path.abspath(Path(self.outputs.dir).expanduser()))
        except FileNotFoundError:  # no current folder: nothing to compare with
            return None
        if os.path.realpath(old) == os.path.realpath(new):
            return None
        return (f"outputs.dir {self.outputs.dir!r} is relative to the mission file's folder, "
                f"like world.dem: writing to {new} (before fm2uav 0.2 it meant {old}, relative "
                "to the current folder); give --out or an absolute outputs.dir to choose")

    def anchor(self) -> Anchor:
        """The :class:`Anchor` of a world without CRS (default :data:`DEFAULT_ANCHOR`)."""
        from ..world.geo import DEFAULT_ANCHOR, Anchor

        a = self.world.anchor
        return DEFAULT_ANCHOR if a is None else Anchor(lon=a.lon, lat=a.lat, alt=a.alt)

    def export_options(self) -> ExportOptions:
        """The :class:`ExportOptions` of this mission."""
        from ..autopilot.build import ExportOptions  # the autopilot layer: only to build

        o, a = self.outputs, self.airframe
        return ExportOptions(
            tolerance=o.thin_tolerance, max_points=o.max_waypoints, frame=o.frame,
            anchor=self.anchor(), takeoff=o.takeoff, cruise_speed=a.cruise_speed,
            hover_speed=a.hover_speed, vehicle=a.type, firmware=a.firmware, end=o.end,
            speed_changes=o.speed_changes, speed_step=o.speed_step, min_speed=a.min_speed,
            max_speed=a.max_speed, max_bank=a.max_bank, terrain=o.terrain,
            terrain_spacing=o.terrain_spacing,
            climb_rate=a.climb_rate, descent_rate=a.descent_rate,
            endurance_s=None if a.endurance is None else 60.0 * a.endurance,
            reserve=a.reserve, name=self.name, power=a.power, battery_wh=a.battery,
            wind=None if self.wind is None else self.wind.field(),
        )

    def return_options(self, world: Any) -> Any:
        """The :class:`~fm2uav.autopilot.safe_return.ReturnOptions` of ``rally:`` and
        ``returns:``, the rally sites placed on ``world`` (metres).

        Raises
        ------
        InputError
            A rally file that cannot be read (named).
        """
        from ..autopilot.safe_return import ReturnOptions
        from ..world.geo import from_lonlat
        from .rally import read_rally_sites

        r, anchor = self.rally, self.anchor()
        sites: list[tuple[float, float, float | None]] = []
        auto = 0
        if r is not None:
            auto = int(r.auto or 0)
            if r.file is not None:
                sites += read_rally_sites(r.file, world, anchor=anchor, crs=self.world.crs)
            for p in r.points:
                if p.lon is not None:
                    xy = from_lonlat(world, [[p.lon, p.lat]], anchor=anchor)[0]
                else:
                    xy = (p.x, p.y)
                sites.append((float(xy[0]), float(xy[1]), p.agl))
        ret = self.returns
        return ReturnOptions(enabled=ret.enabled, rally=tuple(sites), auto_rally=auto,
                             min_agl=ret.min_agl, strict=ret.strict)

    def plan_kwargs(self) -> dict[str, Any]:
        """The ``planner:`` section as one flat dict of the given keys (defaults filled
        in, ``p2`` = :data:`MISSION_P2` with ``agl``), for
        :func:`fm2uav.planning.params.planner_objects`."""
        return _planner_values(self.planner)

    def plan_objects(self) -> tuple[Any, Any, Any]:
        """``(Shaping, FlightLevel or None, PlanOptions)`` of the ``planner:`` section.

        Raises
        ------
        InputError
            A flight-level key without ``agl``, or values the objects refuse
            together (e.g. ``agl`` above ``max_agl``), naming ``planner.<key>``.
        """
        from ..planning.params import planner_objects

        return planner_objects(self.plan_kwargs())

    def _points(self) -> list[PointSpec]:
        return [p for p in (self.start, self.goal, *getattr(self, "via", ())) if p is not None]

    def requested_agl(self) -> float | None:
        """Highest height above ground asked for [m]: ``planner.agl`` and the points' ``agl``."""
        v = [float(p.agl) for p in self._points() if p.agl is not None]
        if self.planner.agl is not None:
            v.append(float(self.planner.agl))
        return max(v) if v else None

    def requested_top(self) -> float | None:
        """Highest altitude asked for [m]: the points' ``alt`` / ``z``."""
        v = [float(p.alt if p.alt is not None else p.z) for p in self._points()
             if p.alt is not None or p.z is not None]
        return max(v) if v else None

    def resolve(self) -> ResolvedMission:
        """Build the world and the start/goal in world metres.

        Raises
        ------
        WorldError, InputError
            The world cannot be built (message names ``world.<field>``), or a
            point cannot be placed (names ``start`` / ``goal``).
        """
        import numpy as np

        w = self.world
        start_default = goal_default = None
        if w.scenario is not None:
            from ..scenarios import get_scenario

            sc = get_scenario(w.scenario, seed=w.seed)
            world, start_default, goal_default = sc.world, sc.start, sc.goal
        else:
            world = load_world(w.data_spec(), agl=self.requested_agl(), top=self.requested_top())
        anchor = self.anchor()
        start = (_resolve_point(self.start, world, anchor, "start")
                 if self.start is not None else np.asarray(start_default, dtype=float))
        goal = (_resolve_point(self.goal, world, anchor, "goal")
                if self.goal is not None else np.asarray(goal_default, dtype=float))
        via = tuple(_resolve_point(v, world, anchor, f"via[{k}]") for k, v in enumerate(self.via))
        check_points(world, {"start": start, "goal": goal,
                             **{f"via[{k}]": v for k, v in enumerate(via)}},
                     allow_filled=w.allow_filled)
        zones = resolve_zones(self.no_fly_zones, self.operating_area, world, anchor)
        if zones:  # no-fly zones / operating area become obstacles of the world
            from ..world.zones import check_points_allowed, with_zones

            world = with_zones(world, zones)
            check_points_allowed(world, {"start": start, "goal": goal,
                                         **{f"via[{k}]": v for k, v in enumerate(via)}})
        return ResolvedMission(mission=self, world=world, start=start, goal=goal, via=via,
                               return_to_start=self.return_to_start)


@dataclass(frozen=True)
class ResolvedMission:
    """A validated mission with its world built and its points in metres."""

    mission: Mission
    world: Any
    start: np.ndarray
    goal: np.ndarray
    via: tuple[np.ndarray, ...] = ()
    return_to_start: bool = False


def _resolve_point(p: PointSpec, world: Any, anchor: Anchor, what: str) -> np.ndarray:
    """A start/goal/via point in world metres (see :func:`resolve_point`)."""
    import numpy as np

    from ..world.geo import from_lonlat
    if p.cell is not None:
        if world.ndim != 3:
            raise InputError(f"{what}.cell needs a 3D world")
        return world.to_world(np.asarray(p.cell, dtype=float))
    if p.lon is not None:
        xy = from_lonlat(world, [[p.lon, p.lat]], anchor=anchor)[0]
        if p.alt is not None:
            z = float(from_lonlat(world, [[p.lon, p.lat, p.alt]], anchor=anchor)[0, 2])
        else:
            z = float(world.ground_height(xy[0], xy[1])) + float(p.agl)
    else:
        xy = np.array([p.x, p.y], dtype=float)
        z = p.z if p.z is not None else float(world.ground_height(xy[0], xy[1])) + float(p.agl)
    if world.ndim == 2:
        return xy
    point = np.array([xy[0], xy[1], z], dtype=float)
    if not world.contains(point):
        b = world.bounds
        where = ""
        if getattr(world, "crs", None) is not None:
            from ..world.geo import bounds_lonlat, to_lonlat

            w_, s_, e_, n_ = bounds_lonlat((b[0, 0], b[1, 0], b[0, 1], b[1, 1]), world.crs)
            ll = to_lonlat(world, point[None])[0]
            where = (f" (lon {ll[0]:.5f}, lat {ll[1]:.5f}; the map covers about lon "
                     f"{w_:.5f}..{e_:.5f}, lat {s_:.5f}..{n_:.5f})")
        raise InputError(
            f"{what} = ({point[0]:.1f}, {point[1]:.1f}, {point[2]:.1f}) m{where} lies outside "
            f"the map; allowed: x in [{b[0, 0]:.1f}, {b[0, 1]:.1f}], y in [{b[1, 0]:.1f}, "
            f"{b[1, 1]:.1f}], z in [{b[2, 0]:.1f}, {b[2, 1]:.1f}] m{_swap_hint(p, world, anchor)}")
    return point


def _swap_hint(p: PointSpec, world: Any, anchor: Anchor) -> str:
    """``"; lon and lat look swapped ..."`` when the lon/lat point ``p`` lies off the map but
    would lie on it with its two coordinates exchanged, else ``""``."""
    from ..world.geo import from_lonlat

    if p.lon is None or not (abs(p.lat) <= 180 and abs(p.lon) <= 90):
        return ""
    try:
        xy = from_lonlat(world, [[p.lat, p.lon]], anchor=anchor)[0]
    except Exception:  # noqa: BLE001 - a transform that fails is no hint
        return ""
    b = world.bounds
    if b[0, 0] <= xy[0] <= b[0, 1] and b[1, 0] <= xy[1] <= b[1, 1]:
        return (f"; lon and lat look swapped: lon {p.lat:g}, lat {p.lon:g} lies on the map "
                "(write {lon: .., lat: ..} / LON,LAT)")
    return ""


def resolve_point(p: PointSpec, world: Any, anchor: Anchor | None = None,
                  what: str = "point") -> np.ndarray:
    """A point given like a mission's ``start`` (metres, lon/lat, cell; z, alt or agl) → metres.

    Used by the mission file and the CLI (``--start LON,LAT,AGL --lonlat``).
    Lon/lat go through the world's CRS, or through ``anchor`` (default
    :data:`~fm2uav.world.geo.DEFAULT_ANCHOR`) for a world without one; ``agl``
    is added to the ground height there (bilinear).

    Raises
    ------
    InputError
        The point lies outside the map (names ``what`` and the map's bounds).
    """
    from ..world.geo import DEFAULT_ANCHOR

    return _resolve_point(p, world, DEFAULT_ANCHOR if anchor is None else anchor, what)


# ---------------------------------------------------------------------- errors
def _field_info(loc: tuple[Any, ...]) -> tuple[Any, str]:
    """FieldInfo of the last named field of ``loc`` and its name (or (None, ""))."""
    model: Any = Mission
    info, name = None, ""
    for key in loc:
        if not isinstance(key, str):
            continue
        fields = getattr(model, "model_fields", None)
        by_alias = {f.alias: k for k, f in (fields or {}).items() if f.alias}
        if fields and key in by_alias:
            info, name = fields[by_alias[key]], key
        elif not fields or key not in fields:
            return info, name
        else:
            info, name = fields[key], key
        ann = info.annotation
        nxt = None
        for cand in (ann, *getattr(ann, "__args__", ())):
            if isinstance(cand, type) and issubclass(cand, BaseModel):
                nxt = cand
        model = nxt
    return info, name


def _fmt_num(v: float) -> str:
    return str(int(v)) if float(v).is_integer() else f"{v:g}"


def _allowed(info: Any, name: str) -> str:
    """Human description of what a field allows (range + unit, or the choices)."""
    if info is None:
        return ""
    lo = hi = None
    lo_op = hi_op = ""
    for m in info.metadata:
        for attr, op in (("gt", "<"), ("ge", "<=")):
            if getattr(m, attr, None) is not None:
                lo, lo_op = getattr(m, attr), op
        for attr, op in (("lt", "<"), ("le", "<=")):
            if getattr(m, attr, None) is not None:
                hi, hi_op = getattr(m, attr), op
    unit = (info.json_schema_extra or {}).get("unit", "") if isinstance(
        info.json_schema_extra, dict) else ""
    unit = f" {unit}" if unit else ""
    if info.annotation in (bool, bool | None):
        return "true or false"
    if lo is not None or hi is not None:
        kind = "an integer" if info.annotation in (int, int | None) else "a number"
        left = f"{_fmt_num(lo)} {lo_op} " if lo is not None else ""
        right = f" {hi_op} {_fmt_num(hi)}" if hi is not None else ""
        return f"{kind}, {left}{name}{right}{unit}"
    args = getattr(info.annotation, "__args__", ())
    if getattr(info.annotation, "__origin__", None) is Literal:
        return "one of " + ", ".join(repr(a) for a in args)
    if info.description:
        return info.description
    return ""


_TYPE_WORDS = {
    "float_type": "a number", "int_type": "an integer", "string_type": "a string",
    "bool_type": "true or false", "list_type": "a list", "tuple_type": "a list",
    "dict_type": "a mapping", "model_type": "a mapping (key: value lines)",
    "int_from_float": "an integer", "float_parsing": "a number", "int_parsing": "an integer",
}


def _show(v: Any) -> str:
    text = repr(v)
    # a long value keeps its end too: a path's file name says which file is wrong
    return text if len(text) <= 60 else text[:22] + "..." + text[-35:]


def _format_error(err: dict[str, Any]) -> str:
    loc = tuple(err["loc"])
    typ = err["type"]
    ctx = err.get("ctx") or {}
    path = "".join(f"[{k}]" if isinstance(k, int) else (("." if i else "") + str(k))
                   for i, k in enumerate(loc)) or "mission"
    info, name = _field_info(loc)
    allowed = _allowed(info, name) if loc and isinstance(loc[-1], str) else ""
    value = err.get("input")
    if typ == "missing":
        return f"{path} is missing; add it" + (f" (allowed: {allowed})" if allowed else "")
    if typ == "extra_forbidden":
        parent_info, _ = _field_info(loc[:-1])
        model = Mission
        if parent_info is not None:
            for cand in (parent_info.annotation, *getattr(parent_info.annotation, "__args__", ())):
                if isinstance(cand, type) and issubclass(cand, BaseModel):
                    model = cand
        keys = ", ".join(f.alias or k for k, f in model.model_fields.items())
        return f"{path} is not a known field; allowed fields here: {keys}"
    if typ in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        return f"{path} = {_show(value)} is out of range; allowed: {allowed}"
    if typ == "literal_error":
        return f"{path} = {_show(value)} is not allowed; allowed: {ctx.get('expected')}"
    if typ in ("too_short", "too_long"):
        n = ctx.get("actual_length")
        lo, hi = (info.metadata if info is not None else []), None
        lo = next((m.min_length for m in lo if getattr(m, "min_length", None) is not None), None)
        hi = next((m.max_length for m in (info.metadata if info is not None else [])
                   if getattr(m, "max_length", None) is not None), None)
        want = (f"exactly {lo}" if lo == hi else
                f"at least {lo}" if hi is None else f"{lo} to {hi}")
        desc = f" ({info.description})" if info is not None and info.description else ""
        return f"{path} = {_show(value)} has {n} item(s); allowed: {want} item(s){desc}"
    if typ == "finite_number":
        return f"{path} = {_show(value)} is not a finite number" + (
            f"; allowed: {allowed}" if allowed else "")
    if typ in _TYPE_WORDS:
        extra = (f"; allowed: {allowed}" if allowed and allowed != _TYPE_WORDS[typ] else "")
        if typ == "bool_type" and isinstance(value, str) and value.lower() in (
                "yes", "no", "on", "off", "y", "n"):
            extra += "; write true or false (in YAML 1.2 yes/no/on/off are text)"
        return (f"{path} = {_show(value)} has the wrong type ({type(value).__name__}), "
                f"expected {_TYPE_WORDS[typ]}{extra}")
    if typ == "value_error":
        msg = str(ctx.get("error", err["msg"]))
        if msg.startswith("has the wrong type"):
            return f"{path} = {_show(value)} {msg}" + (f"; allowed: {allowed}" if allowed else "")
        if isinstance(value, (str, int, float)) and not isinstance(value, bool):
            return f"{path} = {_show(value)} {msg}" if msg.startswith(("has ", "cannot ")) \
                else f"{path} = {_show(value)}: {msg}"
        return f"{path}: {msg}"
    return f"{path} = {_show(value)}: {err['msg']}"


def parse_mission(data: Any, *, source: str = "mission", base_dir: str | Path | None = None
                  ) -> Mission:
    """Validate a mission given as a dict (e.g. parsed YAML).

    Raises
    ------
    InputError
        One line: ``<source>: <field> = <value> <problem>; allowed: <range>``
        (the first problem; ``(+N more)`` says how many others were found).
    """
    if not isinstance(data, dict):
        raise InputError(f"{source}: a mission file must be a mapping of keys (world:, start:, "
                         f"goal:, ...), got {type(data).__name__}")
    try:
        m = Mission.model_validate(data, context={"base_dir": base_dir})
    except ValidationError as exc:
        errs = exc.errors()
        more = f" (+{len(errs) - 1} more)" if len(errs) > 1 else ""
        raise InputError(f"{source}: {_format_error(errs[0])}{more}") from None
    if base_dir is not None:
        m._base_dir = Path(base_dir)
    return m


def parse_world(data: Any, *, source: str = "mission", base_dir: str | Path | None = None
                ) -> WorldSpec:
    """Validate a mission's ``world:`` section alone (e.g. to show a map before planning).

    The same checks and the same one-line messages as :func:`parse_mission`
    gives for that section (``<source>: world.dem = ... cannot be read as a
    raster ...``), with paths relative to ``base_dir``.

    Raises
    ------
    InputError
    """
    if not isinstance(data, dict):
        raise InputError(f"{source}: world must be a mapping (scenario:, dem:, buildings:, ...), "
                         f"got {type(data).__name__}")
    try:
        return WorldSpec.model_validate(data, context={"base_dir": base_dir})
    except ValidationError as exc:
        errs = exc.errors()
        more = f" (+{len(errs) - 1} more)" if len(errs) > 1 else ""
        first = {**errs[0], "loc": ("world", *errs[0]["loc"])}
        raise InputError(f"{source}: {_format_error(first)}{more}") from None


def load_mission(file: str | Path, *, world_overrides: dict[str, Any] | None = None,
                 point_overrides: dict[str, Any] | None = None) -> Mission:
    """Read and validate a YAML mission file (paths inside are relative to it).

    ``world_overrides`` (the CLI's world options of ``fm2uav run``: ``dem``,
    ``buildings``, ``bbox``, ``sea_level``, ...) replace the file's ``world:``
    keys; their paths are taken as given (relative to the working directory),
    and a ``dem``/``buildings`` override drops the file's ``scenario``/``seed``.
    ``point_overrides`` (``{"start": ..., "goal": ...}``, written like the
    file's points) replace its ``start`` / ``goal``.

    Raises
    ------
    InputError
        Missing file, invalid YAML (line and column named) or an invalid
        mission (see :func:`parse_mission`).
    """
    from .. import _validate as v

    file = Path(file)
    # a regular UTF-8 file (no directory, no pipe), YAML without duplicate keys (issue 17)
    data = v.load_yaml(file, "")
    if data is None:
        raise InputError(f"{file}: the mission file is empty; see examples/ for a template")
    if world_overrides and isinstance(data, dict):
        over = {k: v for k, v in world_overrides.items() if v is not None}
        for k in ("dem", "dem_fill", "buildings"):
            if k in over:
                over[k] = ([str(Path(v).resolve()) for v in over[k]] if isinstance(over[k], list)
                           else str(Path(over[k]).resolve()))
        world = dict(data.get("world") or {}) if isinstance(data.get("world"), dict) else {}
        if "dem" in over or "buildings" in over:
            for k in ("scenario", "seed"):
                world.pop(k, None)
        data = {**data, "world": {**world, **over}}
    if point_overrides and isinstance(data, dict):
        data = {**data, **point_overrides}
    return parse_mission(data, source=str(file), base_dir=file.parent)
