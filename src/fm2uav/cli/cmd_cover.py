"""``fm2uav cover`` (coverage mission) and ``fm2uav reproduce coverage`` (Tables 5.1/5.2)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..errors import InputError
from ._common import (
    Output,
    handle_errors,
    write_figure,
    write_json,
    write_text,
)
from .options import (
    MissionFlags,
    SafetyFlags,
    ScenarioOpt,
    WorldFlags,
    build_world,
    mission_options,
    output_options,
    safety_options,
    world_options,
)

if TYPE_CHECKING:
    from ..io.outdir import OutputDir


def _camera(camera: str):
    """``--camera`` text → :class:`~fm2uav.missions.coverage.Camera`."""
    from ..missions.coverage import Camera

    parts = [p for p in camera.replace(",", " ").split() if p]
    if len(parts) != 5:
        raise InputError(
            "--camera needs 5 numbers: sensor_width_mm,sensor_height_mm,focal_mm,"
            f"image_width_px,image_height_px (e.g. 13.2,8.8,8.8,5472,3648); got {camera!r}"
        )
    try:
        sw, sh, f, iw, ih = (float(p) for p in parts)
    except ValueError:
        raise InputError(f"--camera values must be numbers, got {camera!r}") from None
    return Camera(sw * 1e-3, sh * 1e-3, f * 1e-3, int(iw), int(ih))


def _load_area(area: str, world=None, crs=None):
    """(polygon in world metres, SourceFile or None) of --area."""
    from ..missions.coverage.area import load_area
    from ..scenarios.coverage import COVERAGE_AREAS, coverage_area

    if area.strip().upper() in COVERAGE_AREAS:
        if getattr(world, "crs", None) is not None:
            raise InputError(f"--area {area} is a built-in area of the synthetic coverage map; "
                             "on a --dem/--buildings world give the area as a file (GeoJSON in "
                             "lon/lat, GeoPackage, Shapefile, KML/KMZ)")
        return coverage_area(area), None
    if not Path(area).exists():
        raise InputError(
            f"--area {area!r} is neither an existing vector file nor a built-in area "
            f"({', '.join(COVERAGE_AREAS)}); give a path to a polygon (GeoJSON in lon/lat, "
            "GeoPackage, Shapefile, KML/KMZ; on a built-in map: GeoJSON in the map's metres) "
            "or one of those names"
        )
    return load_area(area, world, crs=crs)


def _write_coverage_figures(outdir: OutputDir, run) -> None:
    """bands_<area>.png, coverage_<area>.png and bands_S1_D<d>.png of a coverage run."""
    from ..missions.coverage import zigzag
    from ..scenarios.coverage import COVERAGE_AGL, coverage_area
    from ..viz.coverage import bands_figure, coverage_figure

    for n, cp in run.plans.items():
        write_figure(outdir, bands_figure(cp.zigzag, title=f"{n}, D = 80 m"), f"bands_{n}.png")
        write_figure(outdir, coverage_figure(cp, title=f"{n} at {COVERAGE_AGL:g} m AGL"),
                   f"coverage_{n}.png")
    s1 = coverage_area("S1")
    for d, angle in run.s1_angles.items():
        if d != 80:
            write_figure(outdir, bands_figure(zigzag(s1, d, angle), title=f"S1, D = {d} m"),
                       f"bands_S1_D{d}.png")


COVER_HELP = (
    "Coverage mission: zigzag bands over an area, steering angle by Differential "
    "Evolution, FM² along the bands at a height above the terrain. Writes path.csv, "
    "zigzag.csv, the mission (mission.plan for QGroundControl, mission.waypoints QGC WPL "
    "110, path.kml/.kmz, path.geojson: takeoff, the camera triggered on each band "
    "(DO_SET_CAM_TRIGG_DIST on at its start, off at its end), the end; frame and checks "
    "per --firmware), bands.png, coverage.png, coverage.html and summary.json (with the "
    "camera's ground sample distance and overlaps), and with --report an interactive, "
    "self-contained report.html.\n\n"
    "Examples:\n\n"
    "  fm2uav cover --area S1 --spacing 80 --agl 100 --out out/cover\n\n"
    "  fm2uav cover --area S3 --spacing 80 --report --out out/cover-report\n\n"
    "  fm2uav cover --area area.geojson --spacing 80 --agl 100 --out out/cover\n\n"
    "  fm2uav cover --area S2 --camera 13.2,8.8,8.8,5472,3648 --side-overlap 0.7 "
    "--agl 100 --out out/cam\n\n"
    "  fm2uav cover --dem dem.tif --area field.kml --spacing 60 --agl 90 "
    "--out out/field   (KML/KMZ, GeoPackage, Shapefile, GeoJSON in lon/lat)\n\n"
    "--area is a polygon file — on --dem/--buildings worlds in any CRS (GeoJSON: "
    "lon/lat), on the built-in maps a GeoJSON in the map's metres — or S1..S4 (the "
    "seeds' areas on the built-in coverage map)."
)

REPRODUCE_HELP = (
    "Reproduce the coverage experiments (paper 003 / thesis ch. 5): Table 5.1 (areas "
    "S1-S4, D = 80 m) and Table 5.2 (S1 with D = 40/60/80/100 m) from the seeds' DE, "
    "checked against a 0.1° sweep and scipy's DE, plus figures (bands, 3D path, path "
    "vs ideal profile) of the FM² path at 100 m AGL; with --report an interactive "
    "report.html of the four FM² paths and both tables.\n\n"
    "Examples:\n\n"
    "  fm2uav reproduce coverage --out out/coverage\n\n"
    "  fm2uav reproduce coverage --report --out out/coverage-report"
)

_REPORT_HELP = "Also write report.html (interactive, self-contained)."


@handle_errors
@output_options("out/cover", report_help=_REPORT_HELP)
@world_options
@safety_options
@mission_options("firmware", "vehicle", "frame", "end", "thin", "anchor", "speed_changes",
                 "min_speed", "cruise_speed", "hover_speed", "endurance", "reserve",
                 "power", "battery", "wind", "wind_file")
def cover_cmd(
    area: str = typer.Option(..., help="Polygon file (GeoJSON lon/lat, GPKG, SHP, "
                             "KML/KMZ) or S1..S4 (built-in map)."),
    spacing: float | None = typer.Option(None, help="Band spacing D (m)."),
    agl: float = typer.Option(100.0, help="Flight level above the ground (m)."),
    camera: str | None = typer.Option(
        None, help="Compute D from a camera: sensor_w_mm,sensor_h_mm,focal_mm,img_w,img_h."),
    side_overlap: float = typer.Option(0.0, help="Side overlap share in [0, 1) with --camera."),
    front_overlap: float = typer.Option(
        0.0, help="Front overlap share in [0, 1) between photos with --camera (sets the "
        "trigger distance)."),
    trigger_distance: float | None = typer.Option(
        None, help="Distance between photos (m); default: from --camera, else D."),
    mission: MissionFlags = None,
    angle: float | None = typer.Option(None, help="Steering angle (deg); default: searched."),
    bands: str = typer.Option(
        "search", "--bands", help="Band orientation: search (the steering angle of least "
        "zigzag cost, --search) or wind (across the wind of --wind / --wind-file: the "
        "fastest legs out and back)."),
    search: str = typer.Option("de", help="Angle search: de (seeds), sweep, scipy-de."),
    full_range: bool = typer.Option(False, "--full-range",
                                    help="Search α in [0°, 180°) instead of [1°, 89°]."),
    p1: float = typer.Option(0.5, help="Exponent on the flight level (seeds 0.5)."),
    p2: float = typer.Option(1.3, help="Exponent elsewhere (seeds 1.3)."),
    scenario: ScenarioOpt = None,
    seed: int = typer.Option(0, help="Seed of the terrain and of the DE."),
    output: Output = None,
    world: WorldFlags = None,
    safety: SafetyFlags = None,
) -> None:
    """``fm2uav cover``: parse, :func:`~fm2uav.pipeline.cover.run_cover`, print."""
    from ..missions.coverage import FULL_BOUNDS_DEG
    from .. import progress
    from ..pipeline.cover import (COVER_FILES, REPORT, across_wind_angle, band_cell,
                                  cover_rows, run_cover)
    from ..pipeline.outputs import with_wind_on
    from ..pipeline.rows import safety_rows
    from ..world.load import world_summary

    if bands not in ("search", "wind"):
        raise InputError(f"--bands must be search or wind, got {bands!r}")
    if bands == "wind" and angle is not None:
        raise InputError("give --angle or --bands wind, not both")
    level = safety.level(agl, p1=p1, p2=p2)  # refuses agl outside --min-agl/--max-agl
    from .. import _validate

    for name, share in (("--side-overlap", side_overlap), ("--front-overlap", front_overlap)):
        _validate.in_range(share, name.lstrip("-").replace("-", "_"), 0.0, 1.0,
                           high_open=True, where=(None, name))  # also without --camera
    if (spacing is None) == (camera is None):
        raise InputError("give exactly one of --spacing (metres) or --camera")
    cam = None if camera is None else _camera(camera)
    d = spacing if spacing is not None else cam.spacing(agl, side_overlap)
    mission_options = mission.export_options(name=f"coverage of {area}")
    from ..scenarios.coverage import COVERAGE_AREAS

    if area.strip().upper() not in COVERAGE_AREAS:  # a file: an input --force never deletes
        from .. import _validate

        _validate.note_input(Path(area), "--area")
    outdir = output.dir(COVER_FILES + ((REPORT,) if output.report else ()))
    opts = {"bounds_deg": FULL_BOUNDS_DEG} if full_range else {}
    with output.progress():
        progress.step("building the map", 0.1)
        w, _, scenario = build_world(world.spec(), scenario=scenario, seed=seed, agl=agl,
                                     default="coverage",
                                     max_cell=band_cell(d, bool(safety.no_fly)))
        poly, area_source = _load_area(area, w, world.crs)
        w = safety.apply(w, crs=world.crs)  # --no-fly zones become obstacles
        if bands == "wind":
            mission_options = with_wind_on(mission_options, w)
            angle = across_wind_angle(mission_options.wind, w, poly)
        progress.step(f"coverage of {area}", 0.9)
        run = run_cover(outdir, w, poly, area_label=area, spacing=d, level=level,
                        options=mission_options, camera=cam, front_overlap=front_overlap,
                        trigger_distance=trigger_distance, angle_deg=angle, search=search,
                        search_options=opts, seed=seed, shaping=safety.shaping(),
                        report=output.report, summary={
                            "area": area, "scenario": scenario, "world": world_summary(w),
                            **({"area_source": area_source.as_dict()} if area_source
                               else {})})
    output.summary("coverage plan", {**cover_rows(area, d, run.coverage, run.built, w,
                                                  run.summary.get("sorties")),
                                     **safety_rows(run.safety)}, run.summary)


@handle_errors
@output_options("out/coverage", json_help="Print the tables as JSON.", report_help=_REPORT_HELP)
def reproduce_coverage_cmd(
    seed: int = typer.Option(0, help="Seed of the terrain and of the DE."),
    output: Output = None,
) -> None:
    """``fm2uav reproduce coverage``: :func:`~fm2uav.experiments.coverage.reproduce_coverage`."""
    from ..experiments.coverage import (
        SEEDS_T51,
        SEEDS_T52,
        coverage_payload,
        reproduce_coverage,
        table_csv,
        tables_markdown,
    )
    from .. import progress
    from ..pipeline.cover import REPORT
    from ..scenarios.coverage import COVERAGE_AREAS

    names = list(COVERAGE_AREAS)
    files = ["table_5_1.csv", "table_5_2.csv", "tables.md", "summary.json"]
    files += [f"bands_{n}.png" for n in names] + [f"coverage_{n}.png" for n in names]
    files += [f"bands_S1_D{d}.png" for d in (40, 60, 100)]
    outdir = output.dir(files + ([REPORT] if output.report else []))
    with output.progress():
        progress.step("Tables 5.1 and 5.2", 0.85)
        run = reproduce_coverage(seed)
        progress.step("drawing the figures", 0.15)
        _write_coverage_figures(outdir, run)
    write_text(outdir, "table_5_1.csv", table_csv(run.table_5_1, "surface", SEEDS_T51))
    write_text(outdir, "table_5_2.csv", table_csv(run.table_5_2, "D_m", SEEDS_T52))
    write_text(outdir, "tables.md", tables_markdown(run))
    payload = coverage_payload(run)
    write_json(outdir, "summary.json", payload)
    if output.report:
        from ..viz.coverage import coverage_tables_report

        write_text(outdir, REPORT, coverage_tables_report(run, files))
    rows = {f"{n} (D=80)": f"best {r['min_cost']:.1f} m at {r['min_alpha']:.3f}° "
            f"(sweep {r['sweep_cost']:.1f}; seeds {SEEDS_T51[n][0]:.1f} at "
            f"{SEEDS_T51[n][1]:.3f}°), coverage {r['coverage_pct']:.2f} %"
            for n, r in run.table_5_1.items()}
    rows.update({f"S1 D={d}": f"best {r['min_cost']:.1f} m at {r['min_alpha']:.3f}° "
                 f"(seeds {SEEDS_T52[d][0]:.1f} at {SEEDS_T52[d][1]:.3f}°)"
                 for d, r in run.table_5_2.items()})
    output.summary("coverage (Tables 5.1 / 5.2)", rows, payload)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``cover`` and ``reproduce coverage``."""
    app.command("cover", help=COVER_HELP)(cover_cmd)
    reproduce_app.command("coverage", help=REPRODUCE_HELP)(reproduce_coverage_cmd)
