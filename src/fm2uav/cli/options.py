"""The world and point options every planning command shares, defined once.

Each planning command (``plan``, ``cover``, ``check``, ``tune``, ``formation``,
``run``) declares these typer ``Annotated`` aliases in its signature, then calls
:func:`world_spec` (→ :class:`fm2uav.world.load.WorldSpec`, the same object a
mission file's ``world:`` section becomes), :func:`build_world` and
:func:`cli_point`:

* ``--dem FILE`` (repeatable: tiles), ``--dem-fill FILE`` (repeatable: more DEMs in
  priority order that fill its gaps), ``--buildings FILE``, ``--bbox W,S,E,N``,
  ``--sea-level M``, ``--cell-size``, ``--dz``, ``--ceiling``, ``--nodata``,
  ``--nodata-value``, ``--crs``, ``--default-height``, ``--allow-filled``,
  ``--ground-elevation``, ``--margin``;
* ``--lonlat``: read ``--start``/``--goal`` as ``LON,LAT[,AGL]`` (degrees,
  degrees, metres above the ground; without AGL the command's ``--agl``).
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from ..errors import InputError
from ..pipeline.rows import world_rows  # noqa: F401  (re-exported: was defined here)

if TYPE_CHECKING:
    import numpy as np

__all__ = [
    "DemOpt", "DemFillOpt", "BuildingsOpt", "BboxOpt", "SeaLevelOpt", "CellSizeOpt", "DzOpt", "CeilingOpt",
    "NodataOpt", "NodataValueOpt", "CrsOpt", "DefaultHeightOpt", "AllowFilledOpt", "LonLatOpt",
    "GroundElevationOpt", "MarginOpt",
    "ScenarioOpt", "SCENARIO_NAMES", "AIRFRAME_NAMES", "WORLD_FLAGS", "world_spec",
    "build_world", "cli_point", "lonlat_point", "check_point_texts", "scenario_ndim", "world_rows", "requested_heights",
    "world_overrides", "point_overrides", "option_group", "WorldFlags", "world_options", "MissionFlags",
    "MISSION_FLAGS", "mission_options", "output_options", "NoFlyOpt", "MinAglOpt", "MaxAglOpt",
    "SaturationDistanceOpt", "SafetyFlags", "safety_options",
]

_P = "World (real data)"


def _option(kind: Any, flag: str, help: str, *, panel: str, metavar: str | None = None,
            show_default: bool = False) -> Any:
    """``Annotated[kind, typer.Option(flag, ...)]`` of a flag in the ``--help`` panel ``panel``."""
    return Annotated[kind, typer.Option(flag, show_default=show_default, rich_help_panel=panel,
                                        metavar=metavar, help=help)]


DemOpt = _option(
    list[Path] | None, "--dem", panel=_P, metavar="FILE",
    help="DEM raster, any GDAL format (GeoTIFF, VRT, SRTM .hgt); repeat for tiles. "
         "Geographic/Web Mercator DEMs are reprojected to the local UTM zone.")
DemFillOpt = _option(
    list[Path] | None, "--dem-fill", panel=_P, metavar="FILE",
    help="Another DEM (any CRS and resolution) that fills the gaps of --dem: the ground it "
         "measures is measured ground, not filled. Repeat in priority order (e.g. a 30 m "
         "national model under a 1 m survey).")
BuildingsOpt = _option(
    Path | None, "--buildings", panel=_P, metavar="FILE",
    help="Building footprints: GeoJSON (lon/lat, RFC 7946), GeoPackage, Shapefile, KML/KMZ; "
         "heights from height, else building:levels x 3 m, else --default-height.")
BboxOpt = _option(str | None, "--bbox", "Crop the world to W,S,E,N (lon/lat degrees).",
                  panel=_P, metavar="W,S,E,N")
SeaLevelOpt = _option(
    float | None, "--sea-level", panel=_P,
    help="Water surface (m): ground = max(DEM, sea level), e.g. 0 for a topo-bathymetric DEM.")
CellSizeOpt = _option(
    float | None, "--cell-size", panel=_P,
    help="Horizontal grid cell (m) of a --dem/--buildings world. Default: the DEM pixel "
         "(at most 250k columns), 2 m for buildings.")
DzOpt = _option(float | None, "--dz", panel=_P,
                help="Vertical cell (m). Default: the cell size, at most agl / 6.")
CeilingOpt = _option(
    float | None, "--ceiling", panel=_P,
    help="Altitude (m) of the top of the grid. Default: highest ground + agl + margin.")
NodataOpt = _option(
    str, "--nodata", panel=_P, show_default=True,
    help="Ground no DEM measures: 'error' (refuse the DEM), 'fill' (nearest valid elevation, "
         "reported as unknown ground, with a warning of the length flown over it) or "
         "'error_on_route' (fill, but refuse a plan that flies over it).")
NodataValueOpt = _option(
    float | None, "--nodata-value", panel=_P,
    help="An elevation value meaning 'no data' that the DEM file does not declare "
         "(e.g. -9999).")
CrsOpt = _option(
    str | None, "--crs", panel=_P,
    help="CRS of input files that declare none (e.g. EPSG:32630 for an old GeoJSON in UTM "
         "metres).")
DefaultHeightOpt = _option(float | None, "--default-height",
                           "Height (m) of buildings without height or building:levels.",
                           panel=_P)
AllowFilledOpt = _option(bool, "--allow-filled", panel=_P, show_default=True,
                         help="Only warn when the start/goal lies over filled DEM nodata.")
GroundElevationOpt = _option(
    float | None, "--ground-elevation", panel=_P,
    help="Altitude (m above sea level) of the flat ground of --buildings without --dem. "
         "Without it the mission is written relative to home (the ground's altitude is "
         "unknown).")
MarginOpt = _option(
    float | None, "--margin", panel=_P,
    help="Free border (m) around the footprints of --buildings without --dem. Default: "
         "50 m, at least 10 cells.")
LonLatOpt = Annotated[bool, typer.Option(
    "--lonlat", help="Read --start/--goal as LON,LAT[,AGL] (degrees, degrees, metres above "
                     "the ground; default AGL: --agl).")]
#: The built-in scenarios (:data:`fm2uav.scenarios.SCENARIOS`) and airframe presets
#: (:data:`fm2uav.vehicles.AIRFRAMES`) by name, for ``--help`` without importing them
#: (tests/cli/test_light.py keeps them equal to the library's).
SCENARIO_NAMES = ("open-field", "fissure", "jacksboro", "city", "city-high", "coverage",
                  "city2d")
AIRFRAME_NAMES = ("disco", "crosswind", "plane-jet", "arducopter")
#: The built-in scenarios on a 2D map (every other one, and every --dem/--buildings world,
#: is 3D; tests/cli/test_light.py keeps it equal to the library's).
SCENARIOS_2D = ("city2d",)

ScenarioOpt = Annotated[str | None, typer.Option(

    "--scenario", show_default=False,
    help="Built-in scenario (when no --dem/--buildings is given).")]

#: WorldSpec field -> CLI flag (for one-line errors that name the flag).
WORLD_FLAGS = {
    "dem": "--dem", "dem_fill": "--dem-fill", "buildings": "--buildings", "bbox": "--bbox",
    "sea_level": "--sea-level",
    "cell_size": "--cell-size", "dz": "--dz", "ceiling": "--ceiling", "nodata": "--nodata",
    "nodata_value": "--nodata-value", "crs": "--crs", "default_height": "--default-height",
    "allow_filled": "--allow-filled", "ground_elevation": "--ground-elevation",
    "margin": "--margin",
}


def _bbox(text: str) -> list[float]:
    parts = [p for p in text.replace(",", " ").split() if p]
    try:
        v = [float(p) for p in parts]
    except ValueError:
        v = []
    if len(v) != 4:
        raise InputError(f"--bbox must be 4 numbers W,S,E,N in lon/lat degrees (e.g. "
                         f"-3.78,40.33,-3.74,40.35), got {text!r}")
    return v


def world_spec(
    *,
    dem: list[Path] | None = None,
    dem_fill: list[Path] | None = None,
    buildings: Path | None = None,
    bbox: str | None = None,
    sea_level: float | None = None,
    cell_size: float | None = None,
    dz: float | None = None,
    ceiling: float | None = None,
    nodata: str = "error",
    nodata_value: float | None = None,
    crs: str | None = None,
    default_height: float | None = None,
    allow_filled: bool = False,
    ground_elevation: float | None = None,
    margin: float | None = None,
) -> Any:
    """The :class:`~fm2uav.world.load.WorldSpec` of the world options, or None without data.

    Raises
    ------
    InputError
        One line naming the flag (``--bbox = ...: west < east ...``), also for
        data-only flags given without ``--dem``/``--buildings``.
    """
    from pydantic import ValidationError

    from ..world.load import WorldSpec

    values = {"dem": [str(p) for p in dem] if dem else None,
              "dem_fill": [str(p) for p in dem_fill] if dem_fill else None,
              "buildings": None if buildings is None else str(buildings),
              "bbox": None if bbox is None else _bbox(bbox), "sea_level": sea_level,
              "cell_size": cell_size, "dz": dz, "ceiling": ceiling, "nodata": nodata,
              "nodata_value": nodata_value, "crs": crs, "default_height": default_height,
              "allow_filled": allow_filled, "ground_elevation": ground_elevation,
              "margin": margin}
    if values["dem"] is not None and len(values["dem"]) == 1:
        values["dem"] = values["dem"][0]
    if values["dem"] is None and values["buildings"] is None:
        given = [WORLD_FLAGS[k] for k, v in values.items()
                 if v is not None and v is not False and not (k == "nodata" and v == "error")]
        if given:
            raise InputError(f"{given[0]} needs real data: give --dem FILE and/or --buildings "
                             "FILE (built-in scenarios have a fixed grid)")
        return None
    try:
        return WorldSpec.model_validate({k: v for k, v in values.items() if v is not None})
    except ValidationError as exc:
        err = exc.errors()[0]
        key = str(err["loc"][0]) if err["loc"] else "dem"
        msg = str(err.get("ctx", {}).get("error", err["msg"])).removeprefix("Value error, ")
        if err["type"] in ("greater_than", "greater_than_equal", "less_than",
                           "less_than_equal", "literal_error"):
            msg = err["msg"]
        raise InputError(f"{WORLD_FLAGS.get(key, '--' + key)} = {err.get('input')!r}: "
                         f"{msg}") from None


def world_overrides(**options: Any) -> dict[str, Any] | None:
    """The world options given to ``fm2uav run`` as mission-file ``world:`` keys (or None).

    Takes the same keywords as :func:`world_spec`; unset options are left out,
    so the mission file's values stay.
    """
    values = dict(options)
    out: dict[str, Any] = {}
    if values.get("dem"):
        dems = [str(p) for p in values["dem"]]
        out["dem"] = dems[0] if len(dems) == 1 else dems
    if values.get("dem_fill"):
        out["dem_fill"] = [str(p) for p in values["dem_fill"]]
    if values.get("buildings") is not None:
        out["buildings"] = str(values["buildings"])
    if values.get("bbox") is not None:
        out["bbox"] = _bbox(values["bbox"])
    for k in ("sea_level", "cell_size", "dz", "ceiling", "nodata_value", "crs",
              "default_height", "ground_elevation", "margin"):
        if values.get(k) is not None:
            out[k] = values[k]
    if values.get("nodata", "error") != "error":
        out["nodata"] = values["nodata"]
    if values.get("allow_filled"):
        out["allow_filled"] = True
    return out or None


def point_overrides(*, start: str | None, goal: str | None, lonlat: bool
                    ) -> dict[str, Any] | None:
    """``--start``/``--goal`` of ``fm2uav run`` as mission-file point mappings (or None).

    ``LON,LAT,AGL`` with ``lonlat`` → ``{lon, lat, agl}``; else ``x,y,z`` → ``[x, y, z]``.

    Raises
    ------
    InputError
        Not 3 numbers (a mission point needs its height).
    """
    out: dict[str, Any] = {}
    for what, text in (("start", start), ("goal", goal)):
        if text is None:
            continue
        parts = [p for p in text.replace(",", " ").split() if p]
        try:
            v = [float(p) for p in parts]
        except ValueError:
            v = []
        if len(v) != 3:
            form = "LON,LAT,AGL (degrees, degrees, metres above ground)" if lonlat else "x,y,z (m)"
            raise InputError(f"--{what} must be {form} for fm2uav run, got {text!r}")
        out[what] = {"lon": v[0], "lat": v[1], "agl": v[2]} if lonlat else v
    return out or None


def build_world(spec: Any, *, scenario: str | None, seed: int = 0, agl: float | None = None,
                top: float | None = None, default: str = "open-field",
                max_cell: tuple[float, str] | None = None) -> tuple[Any, Any, str]:
    """``(world, scenario or None, description)`` from a spec, else a built-in scenario.

    ``agl`` / ``top`` / ``max_cell`` size a data world (see
    :func:`fm2uav.world.load.load_world`).
    Warnings of the data (below sea level, distortion) are shown by
    :func:`~fm2uav.cli._common.handle_errors` as one-line ``warning:`` lines.

    Raises
    ------
    InputError
        Both ``--scenario`` and ``--dem``/``--buildings`` given.
    """
    from ..world.load import load_world

    if spec is None:
        from ..scenarios import get_scenario

        sc = get_scenario(scenario or default, seed=seed)
        return sc.world, sc, scenario or default
    if scenario is not None:
        raise InputError("give either --scenario or --dem/--buildings, not both")
    world = load_world(spec, agl=agl, top=top, max_cell=max_cell)
    return world, None, spec.describe()


def cli_point(text: str | None, what: str, world: Any, *, lonlat: bool = False,
              cells: bool = False, agl: float | None = None, default: Any = None,
              anchor: Any = None) -> np.ndarray:
    """A ``--start``/``--goal`` value in world metres.

    ``x,y[,z]`` metres (default), ``i,j[,k]`` cells (``cells``), or
    ``LON,LAT[,AGL]`` (``lonlat``: through the world's CRS, or ``anchor`` for a
    built-in scenario; AGL in metres above the ground, default ``agl``).

    Raises
    ------
    InputError
        Wrong count of numbers, a lon/lat point without a height, both
        ``--lonlat`` and ``--cells``.
    """
    import numpy as np

    from ._common import parse_point

    if text is None:
        if default is None:
            raise InputError(f"--{what} is missing: a --dem/--buildings world has no default "
                             f"{what}; give --{what} LON,LAT,AGL --lonlat (or x,y,z metres)")
        return np.asarray(default, dtype=float)
    if lonlat and cells:
        raise InputError("give --lonlat or --cells, not both")
    if lonlat:
        return lonlat_point(text, what, world, agl=agl, anchor=anchor)
    p = parse_point(text, world.ndim, what)
    return world.to_world(p) if cells else p


def lonlat_point(text: str, what: str, world: Any, *, agl: float | None = None,
                 anchor: Any = None) -> np.ndarray:
    """A ``--<what> LON,LAT[,AGL]`` value in world metres (through the world's CRS, or
    ``anchor`` on a built-in scenario; AGL metres above the ground, default ``agl``; a 2D
    map takes no height).

    Raises
    ------
    InputError
        Not 2 or 3 numbers, not a WGS84 position, no height on a 3D map, a height <= 0.
    """
    from ..io.mission import PointSpec, resolve_point

    lon, lat, h = lonlat_numbers(text, what, ndim=world.ndim, agl=agl)
    return resolve_point(PointSpec(lon=lon, lat=lat, agl=h), world, anchor, what)


def lonlat_numbers(text: str, what: str, *, ndim: int, agl: float | None
                   ) -> tuple[float, float, float]:
    """``(lon, lat, agl)`` of a ``--<what> LON,LAT[,AGL]`` text, checked (pure Python: also
    before the world loads); the height defaults to ``agl``; a 2D map (``ndim`` 2) takes
    none (1.0 is returned).

    Raises
    ------
    InputError
        Not 2 or 3 numbers, not a WGS84 position, no height on a 3D map, a height <= 0.
    """
    parts = [p for p in text.replace(",", " ").split() if p]
    try:
        v = [float(p) for p in parts]
    except ValueError:
        v = []
    if len(v) not in (2, 3):
        raise InputError(f"--{what} must be LON,LAT or LON,LAT,AGL (degrees, degrees, metres "
                         f"above the ground), got {text!r}")
    if not (-180 <= v[0] <= 180 and -90 <= v[1] <= 90):
        raise InputError(f"--{what} = {text!r}: longitude must be in [-180, 180] and "
                         "latitude in [-90, 90] degrees (order LON,LAT)")
    h = v[2] if len(v) == 3 else (agl if ndim == 3 else 1.0)  # 2D: xy alone
    if h is None:
        raise InputError(f"--{what} {text!r} has no height: add ,AGL (metres above the "
                         "ground) or give --agl")
    if not h > 0:
        raise InputError(f"--{what}: the height above ground must be > 0 m, got {h:g}")
    return v[0], v[1], float(h)


def scenario_ndim(scenario: str | None) -> int:
    """The dimensions of the map of ``--scenario`` (3 for a data world or the default)."""
    return 2 if scenario in SCENARIOS_2D else 3


def check_point_texts(points: dict[str, str | None], *, scenario: str | None, lonlat: bool,
                      cells: bool, agl: float | None) -> None:
    """The ``--start``/``--goal``/``--via`` texts checked before the world loads.

    The numbers and their count (metres or cells: the map's dimensions,
    :func:`scenario_ndim`), a ``LON,LAT[,AGL]`` text as :func:`lonlat_numbers` checks it
    (``agl``: ``--agl``), ``--lonlat`` with ``--cells``. Where the points fall on the map is
    checked once it is built (:func:`cli_point`, ``check_points``).

    Parameters
    ----------
    points
        ``{"start": text, "goal": text, "via 1": text, ...}``; None: not given.
    scenario, lonlat, cells, agl
        ``--scenario``, ``--lonlat``, ``--cells``, ``--agl``.

    Raises
    ------
    InputError
        Naming the flag, as :func:`cli_point` would later.
    """
    from ._common import point_numbers

    given = {what: text for what, text in points.items() if text is not None}
    if lonlat and cells and given:
        raise InputError("give --lonlat or --cells, not both")
    ndim = scenario_ndim(scenario)
    for what, text in given.items():
        if lonlat:
            lonlat_numbers(text, what, ndim=ndim, agl=agl)
        else:
            point_numbers(text, ndim, what)


def requested_heights(*texts: str | None, lonlat: bool, agl: float | None
                      ) -> tuple[float | None, float | None]:
    """``(highest agl, highest altitude)`` asked for by ``--agl`` and the points' text.

    Lets :func:`build_world` size a data world before the points are placed.
    """
    agls = [] if agl is None else [float(agl)]
    tops: list[float] = []
    for t in texts:
        if t is None:
            continue
        parts = [p for p in t.replace(",", " ").split() if p]
        try:
            v = [float(p) for p in parts]
        except ValueError:
            continue  # cli_point reports it
        if len(v) == 3:
            (agls if lonlat else tops).append(v[2])
    return (max(agls) if agls else None), (max(tops) if tops else None)


# -- option groups: one decorator adds a group's flags to a command --------------------------

def option_group(name: str, params: Sequence[tuple[str, Any, Any]],
                 build: Callable[..., Any]) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """A decorator that replaces the command parameter ``name`` by a group of options.

    The command declares one parameter ``name`` (e.g. ``world: WorldFlags``) where the
    group's flags belong in ``--help``; the decorated function's signature (read by
    typer) has the group's ``(parameter, Annotated alias, default)`` entries in its
    place, and the command is called with ``name=build(**their values)``.
    """
    keys = [p for p, _, _ in params]

    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        sig = inspect.signature(func, eval_str=True)
        if name not in sig.parameters:
            raise TypeError(f"{func.__name__} has no parameter {name!r} for its option group")
        new: list[inspect.Parameter] = []
        for p in sig.parameters.values():
            if p.name == name:
                new += [inspect.Parameter(k, inspect.Parameter.POSITIONAL_OR_KEYWORD,
                                          annotation=ann, default=default)
                        for k, ann, default in params]
            else:
                new.append(p)

        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            kwargs[name] = build(**{k: kwargs.pop(k) for k in keys if k in kwargs})
            return func(*args, **kwargs)

        wrapper.__signature__ = sig.replace(parameters=new)  # type: ignore[attr-defined]
        wrapper.__annotations__ = {p.name: p.annotation for p in new
                                   if p.annotation is not inspect.Parameter.empty}
        return wrapper

    return decorate


@dataclass(frozen=True)
class WorldFlags:
    """The world options as given (``--dem`` ... ``--allow-filled``)."""

    dem: list[Path] | None = None
    dem_fill: list[Path] | None = None
    buildings: Path | None = None
    bbox: str | None = None
    sea_level: float | None = None
    cell_size: float | None = None
    dz: float | None = None
    ceiling: float | None = None
    nodata: str = "error"
    nodata_value: float | None = None
    crs: str | None = None
    default_height: float | None = None
    allow_filled: bool = False
    ground_elevation: float | None = None
    margin: float | None = None

    def values(self) -> dict[str, Any]:
        """The flags as keywords of :func:`world_spec` / :func:`world_overrides`."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def spec(self) -> Any:
        """:func:`world_spec` of the flags (None without ``--dem``/``--buildings``)."""
        return world_spec(**self.values())

    def overrides(self) -> dict[str, Any] | None:
        """:func:`world_overrides` of the flags (mission-file ``world:`` keys)."""
        return world_overrides(**self.values())

    def build(self, scenario: str | None, *points: str | None, seed: int, lonlat: bool,
              agl: float | None, default: str = "open-field") -> tuple[Any, Any, str]:
        """:func:`build_world` of the flags, a data world sized for ``agl`` and the heights
        of the ``--start``/``--goal`` texts ``points`` (:func:`requested_heights`)."""
        need_agl, need_top = requested_heights(*points, lonlat=lonlat, agl=agl)
        return build_world(self.spec(), scenario=scenario, seed=seed, agl=need_agl,
                           top=need_top, default=default)


#: ``@world_options``: the 15 world flags in place of the command's ``world`` parameter.
world_options = option_group("world", [
    ("dem", DemOpt, None), ("dem_fill", DemFillOpt, None), ("buildings", BuildingsOpt, None),
    ("bbox", BboxOpt, None),
    ("sea_level", SeaLevelOpt, None), ("cell_size", CellSizeOpt, None), ("dz", DzOpt, None),
    ("ceiling", CeilingOpt, None), ("nodata", NodataOpt, "error"),
    ("nodata_value", NodataValueOpt, None), ("crs", CrsOpt, None),
    ("default_height", DefaultHeightOpt, None), ("allow_filled", AllowFilledOpt, False),
    ("ground_elevation", GroundElevationOpt, None), ("margin", MarginOpt, None),
], WorldFlags)


@dataclass(frozen=True)
class MissionFlags:
    """The mission options as given: route (``--via``, ``--return``) and export flags."""

    via: list[str] | None = None
    return_to_start: bool | None = None
    export: dict[str, Any] = field(default_factory=dict)

    def export_options(self, base: Any = None, **more: Any) -> Any:
        """``base`` ExportOptions with the export flags that were given (and ``more``)."""
        from ._mission_options import export_options

        return export_options(base, **self.export, **more)


def _mission_params() -> dict[str, Any]:
    from . import _mission_options as m

    return {"via": m.Via, "return_to_start": m.Return, "firmware": m.Firmware,
            "vehicle": m.Vehicle, "frame": m.Frame, "end": m.End, "thin": m.Thin,
            "anchor": m.AnchorText, "speed_changes": m.SpeedChanges, "min_speed": m.MinSpeed,
            "cruise_speed": m.CruiseSpeed, "hover_speed": m.HoverSpeed,
            "endurance": m.Endurance, "reserve": m.Reserve, "terrain": m.Terrain,
            "terrain_spacing": m.TerrainSpacing, "power": m.Power, "battery": m.Battery,
            "wind": m.Wind, "wind_file": m.WindFile}


#: The mission flags of ``plan``/``formation`` (in their ``--help`` order).
MISSION_FLAGS = ("via", "return_to_start", "firmware", "vehicle", "frame", "end",
                 "speed_changes", "min_speed", "cruise_speed", "hover_speed", "endurance",
                 "reserve", "terrain", "terrain_spacing", "power", "battery", "wind",
                 "wind_file")


def _mission_flags(via: list[str] | None = None, return_to_start: bool | None = None,
                   **export: Any) -> MissionFlags:
    return MissionFlags(via=via, return_to_start=return_to_start, export=export)


def mission_options(*names: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``@mission_options(...)``: mission flags (default :data:`MISSION_FLAGS`) in place of
    the command's ``mission`` parameter, passed as one :class:`MissionFlags`."""
    table = _mission_params()
    return option_group("mission", [(n, table[n], None) for n in names or MISSION_FLAGS],
                        _mission_flags)


def output_options(out: str | None, *, out_help: str = "Output directory.",
                   force_help: str = "Replace an existing --out folder as a whole (never "
                                     "one that holds an input of the command).",
                   json_help: str = "Print the summary as JSON.",
                   report_help: str | None = None
                   ) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``@output_options("out/plan", ...)``: ``--out``, ``--force``, ``--json``, ``--quiet``
    (and ``--report`` with ``report_help``) in place of the command's ``output`` parameter,
    passed as one :class:`~fm2uav.cli._common.Output`.

    The command runs inside an :func:`fm2uav._validate.input_log` in which its path
    arguments (``MISSION_FILE``, ``--dem``, ``--no-fly``, ...) are noted up front and
    every file reader notes its file: the command's output sets refuse an ``--out``
    that holds one of them (:class:`~fm2uav.io.outdir.OutputDir`). Its path parameters
    are checked by fm2uav's readers (one line), not by click (:func:`_own_path_checks`).
    """
    from ._common import Output

    params = [
        ("out", Annotated[Path | None if out is None else Path,
                          typer.Option(help=out_help, readable=False)],
         None if out is None else Path(out)),
        ("force", Annotated[bool, typer.Option("--force", help=force_help)], False),
        ("as_json", Annotated[bool, typer.Option("--json", help=json_help)], False),
        ("quiet", Annotated[bool, typer.Option("--quiet", help="Print nothing but errors.")],
         False),
    ]
    if report_help is not None:
        params.append(("report", Annotated[bool, typer.Option("--report", help=report_help)],
                       False))
    group = option_group("output", params, Output)

    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        inner = group(func)
        labels = _param_labels(inner)
        _own_path_checks(inner)

        @functools.wraps(inner)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            from .. import _validate

            # every input the command reads is noted (here: its path arguments, up front;
            # the readers note theirs), so --force never replaces a folder holding one
            with _validate.input_log():
                for key, value in kwargs.items():
                    if key != "out":
                        for path, label in _paths_in(value, labels.get(key, key)):
                            _validate.note_input(path, label)
                return inner(*args, **kwargs)

        return wrapper

    return decorate


def _own_path_checks(func: Callable[..., Any]) -> None:
    """Let fm2uav, not click, check the command's path parameters.

    click's ``Path(readable=True)`` refuses an unreadable file with a usage box of
    several lines; fm2uav's readers (:func:`fm2uav._validate.input_file`) refuse it
    with one line naming the flag and the fix, as they do a folder or a named pipe.
    """
    for p in inspect.signature(func).parameters.values():
        if "Path" not in str(p.annotation):
            continue
        for info in (p.default, *getattr(p.annotation, "__metadata__", ())):
            if isinstance(info, (typer.models.ArgumentInfo, typer.models.OptionInfo)):
                info.readable = False


def _param_labels(func: Callable[..., Any]) -> dict[str, str]:
    """Parameter name -> how the user spells it (``--no-fly``, ``MISSION_FILE``)."""
    out: dict[str, str] = {}
    for name, p in inspect.signature(func).parameters.items():
        infos = [p.default, *getattr(p.annotation, "__metadata__", ())]
        label = "--" + name.replace("_", "-")
        for info in infos:
            if isinstance(info, typer.models.ArgumentInfo):
                label = name.upper()
            elif isinstance(info, typer.models.OptionInfo):
                decls = [d for d in (info.param_decls or ()) if d.startswith("--")]
                if decls:
                    label = decls[0].split("/")[0]
        out[name] = label
    return out


def _paths_in(value: Any, label: str) -> list[tuple[Path, str]]:
    """The paths in a command argument: a Path, a list of them, or a flag group's fields."""
    if isinstance(value, Path):
        return [(value, label)]
    if isinstance(value, (list, tuple)):
        return [e for v in value for e in _paths_in(v, label)]
    if hasattr(value, "__dataclass_fields__") and not isinstance(value, type):
        return [e for f in fields(value)
                for e in _paths_in(getattr(value, f.name), "--" + f.name.replace("_", "-"))]
    return []


# -- flight safety (issue 13): no-fly zones, AGL limits, saturation in metres ------------------

_S = "Flight safety"

NoFlyOpt = _option(
    list[Path] | None, "--no-fly", panel=_S, metavar="FILE",
    help="No-fly zones file (GeoJSON lon/lat, KML/KMZ, GPKG, SHP; points need a 'radius' in "
         "metres): the zones become obstacles, the flight keeps out of them and the .plan "
         "carries them as geofences. Repeatable.")
MinAglOpt = _option(
    float | None, "--min-agl", panel=_S,
    help="Hard floor (m) above the ground for the whole flight except the take-off/landing "
         "points (with --agl).")
MaxAglOpt = _option(float | None, "--max-agl",
                    "Hard ceiling (m) above the ground, e.g. 120 (with --agl).", panel=_S)
SaturationDistanceOpt = _option(
    float | None, "--saturation-distance", panel=_S,
    help="Distance (m) from the obstacles beyond which W = 1 (a margin that means the same "
         "on any map).")


@dataclass(frozen=True)
class SafetyFlags:
    """The flight-safety options as given (``--no-fly``, ``--min-agl``, ``--max-agl``,
    ``--saturation-distance``)."""

    no_fly: list[Path] | None = None
    min_agl: float | None = None
    max_agl: float | None = None
    saturation_distance: float | None = None

    def limits(self, agl: float | None) -> dict[str, float]:
        """``min_agl`` / ``max_agl`` keywords of a :class:`~fm2uav.FlightLevel` (the given ones).

        Raises
        ------
        InputError
            A limit without a requested height above ground ``agl`` (names the flag).
        """
        out = {k: float(v) for k, v in (("min_agl", self.min_agl), ("max_agl", self.max_agl))
               if v is not None}
        if out and agl is None:
            flag = "--min-agl" if "min_agl" in out else "--max-agl"
            raise InputError(f"{flag} limits a terrain-following flight; give --agl too (the "
                             "requested height above ground)")
        return out

    def level(self, agl: float | None, **keys: Any) -> Any:
        """The :class:`~fm2uav.FlightLevel` at ``agl`` with the limits (None without ``agl``).

        Raises
        ------
        InputError
            One line naming ``--max-agl`` / ``--min-agl`` when ``agl`` is outside the limits.
        """
        limits = self.limits(agl)
        from ..planning import FlightLevel

        if agl is None:
            if keys:  # unused without --agl, but never silently garbage (--p1 nan)
                FlightLevel(agl=1.0, **keys)
            return None

        return FlightLevel(agl=agl, **keys, **limits)

    def shaping(self, **keys: Any) -> Any:
        """The :class:`~fm2uav.Shaping` with ``--saturation-distance`` (None when not given
        and no ``keys``)."""
        if self.saturation_distance is None and not keys:
            return None
        from ..planning.params import planner_objects

        extra = ({} if self.saturation_distance is None
                 else {"saturation_distance": float(self.saturation_distance)})
        return planner_objects({**keys, **extra})[0]

    def apply(self, world: Any, points: dict[str, Any] | None = None, *, crs: str | None = None
              ) -> Any:
        """``world`` with the ``--no-fly`` zones as obstacles (``world`` itself without them);
        ``points`` (name → metres) are checked to lie outside the zones.

        Raises
        ------
        InputError
            A file not found or not readable, a point inside a zone (names it).
        """
        if not self.no_fly:
            return world
        from ..io.zone_spec import zones_from_cli
        from ..world.zones import check_points_allowed, with_zones

        out = with_zones(world, zones_from_cli([str(f) for f in self.no_fly], world, crs=crs))
        if points:
            check_points_allowed(out, points)
        return out


#: ``@safety_options``: ``--no-fly`` (repeatable), ``--min-agl``, ``--max-agl``,
#: ``--saturation-distance`` in place of the command's ``safety`` parameter.
safety_options = option_group("safety", [
    ("no_fly", NoFlyOpt, None), ("min_agl", MinAglOpt, None), ("max_agl", MaxAglOpt, None),
    ("saturation_distance", SaturationDistanceOpt, None),
], SafetyFlags)
