"""``fm2uav formation`` / ``fm2uav reproduce formation``: leader–follower flights (thesis ch. 6)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import typer

from ._common import (
    EXIT_PLANNING,
    Output,
    handle_errors,
    print_summary,
    write_json,
    write_text,
)
from .options import (
    SCENARIO_NAMES,
    LonLatOpt,
    MissionFlags,
    SafetyFlags,
    ScenarioOpt,
    WorldFlags,
    cli_point,
    mission_options,
    output_options,
    safety_options,
    world_options,
    world_rows,
)

if TYPE_CHECKING:
    from ..io.outdir import OutputDir

FIGURES = ("paths.png", "profiles.png", "metrics.png")
#: Mission files written per UAV (``leader_mission.plan``, ``follower1_mission.waypoints``,
#: ``leader_path.kml`` / ``.kmz`` / ``.geojson`` / ``.csv``, ...).
MISSION_FORMATS = ("plan", "wpl", "kml", "kmz", "geojson", "csv")
TABLES = ("trajectories.csv", "metrics.csv", "cycles.csv", "summary.json")
ANIMATION = "formation.gif"
REPORT = "report.html"


def _write_tables(outdir: OutputDir, result) -> None:
    from ..io.trajectories import (
        write_cycles_csv,
        write_formation_metrics_csv,
        write_trajectories_csv,
    )

    r = result
    with outdir.open("trajectories.csv") as fh:
        write_trajectories_csv(fh, r.times, r.positions, r.names)
    with outdir.open("metrics.csv") as fh:
        write_formation_metrics_csv(fh, r.times, r.min_distance, r.shape_error,
                                    r.shape_error_norm)
    with outdir.open("cycles.csv") as fh:
        write_cycles_csv(fh, r.cycle_start, r.compute_s, r.grey, r.partial_goals, r.held,
                         r.names)


def _outputs(gif: bool, report: bool) -> tuple[str, ...]:
    return FIGURES + TABLES + ((ANIMATION,) if gif else ()) + ((REPORT,) if report else ())


def _write_case(outdir: OutputDir, result, summary: dict[str, Any], *, title: str, gif: bool,
                frames: int, report: bool = False, subtitle: str = "") -> None:
    """The figures, tables, summary.json (animation, report.html) of one formation flight;
    each file a :mod:`fm2uav.progress` step of the caller's current part."""
    from .. import progress
    from ..viz.formation import (
        formation_animation,
        formation_metrics_figure,
        formation_paths_figure,
        formation_profiles_figure,
        formation_report_html,
    )

    # shares: a figure ~1, the animation ~4, the report ~2 (plotly and the map inlined)
    parts = len(FIGURES) + (4 if gif else 0) + (2 if report else 0)
    for name, make in zip(FIGURES, (formation_paths_figure, formation_profiles_figure,
                                    formation_metrics_figure)):
        progress.step(f"drawing {name}", 1 / parts)
        fig = make(result, title=title)
        tmp = outdir.target(name)
        fig.savefig(tmp, dpi=100)
        outdir.commit(tmp, name)
    _write_tables(outdir, result)
    write_json(outdir, "summary.json", summary)
    if gif:
        progress.step(f"drawing {ANIMATION}", 4 / parts)
        tmp = outdir.target(ANIMATION)
        formation_animation(result, tmp, max_frames=frames)
        outdir.commit(tmp, ANIMATION)
    if report:
        progress.step(f"writing {REPORT}", 2 / parts)
        write_text(outdir, REPORT, formation_report_html(
            result, summary, title=title, subtitle=subtitle, files=list(_outputs(gif, False))))


FORMATION_HELP = (
    "Fly a leader–follower formation with FM² (thesis ch. 6) and write trajectories.csv, "
    "metrics.csv, cycles.csv, summary.json, paths.png, profiles.png, metrics.png, "
    "formation.gif (and with --report an interactive report.html), and one mission per "
    "UAV in every format (leader_mission.plan / .waypoints, leader_path.kml / .kmz / "
    ".geojson / .csv, follower1_..., ...): its own route "
    "with a DO_CHANGE_SPEED per leg and holds so that it keeps the simulated timing; "
    "started together, the vehicles leave their start points at the same moment.\n\n"
    "Examples:\n\n"
    "  fm2uav formation --scenario fissure --out out/formation\n\n"
    "  fm2uav formation --scenario fissure --level 7 --report --out out/formation-l7\n\n"
    "  fm2uav formation --shape v --followers 4 --dist 45 --no-gif --out out/v4\n\n"
    "  fm2uav formation --dem dem.tif --bbox 10.05,45.54,10.2,45.66 --lonlat --start "
    "10.06,45.55 --goal 10.19,45.65 --agl 120 --no-gif --out out/formation-dem\n\n"
    f"Scenarios: {', '.join(SCENARIO_NAMES)}."
)

REPRODUCE_HELP = (
    "Thesis ch. 6: the triangle formation across the fissure without (case 1) and with "
    "(case 2) the flight level 7 cells; case 2 is run with the thesis' p1 = 1, p2 = 0.5 "
    "and with the planner's p1 = 0.5, p2 = 1.5. Writes one folder per case and "
    "table.md comparing our times with the thesis' 130.6 s / 135.6 s (Matlab); with "
    "--report also report.html per case and one comparing the cases.\n\n"
    "Examples:\n\n"
    "  fm2uav reproduce formation --out out/formation-thesis\n\n"
    "  fm2uav reproduce formation --no-gif --report --out out/formation-report"
)


@handle_errors
@output_options("out/formation",
                report_help="Also write report.html (interactive, self-contained).")
@world_options
@safety_options
@mission_options("firmware", "vehicle", "frame", "end", "thin", "anchor", "min_speed",
                 "cruise_speed", "hover_speed", "endurance", "reserve")
def formation_cmd(
    scenario: ScenarioOpt = None,
    start: str | None = typer.Option(None, help="Leader start x,y,z (m) (cells with --cells; "
                                     "LON,LAT[,AGL] with --lonlat)."),
    goal: str | None = typer.Option(None, help="Leader goal x,y,z (m) (cells with --cells; "
                                    "LON,LAT[,AGL] with --lonlat)."),
    cells: bool = typer.Option(False, "--cells", help="Read --start/--goal as grid cells."),
    lonlat: LonLatOpt = False,
    shape: str = typer.Option("triangle", help="Formation: triangle, v or line."),
    followers: int = typer.Option(2, help="Number of followers."),
    dist: float = typer.Option(
        60.0, help="Safety distance dist (m); UAVs never closer than dist/2."),
    speed: float = typer.Option(10.0, help="Leader speed (m/s)."),
    follower_speed: float | None = typer.Option(
        None, help="Followers' top speed (m/s) (default 1.5 × leader)."),
    cycle: float = typer.Option(1.0, help="Re-planning period (s)."),
    agl: float | None = typer.Option(None, help="Flight level (m above ground) for all UAVs."),
    level: float | None = typer.Option(
        None, help="Flight level in vertical cells (thesis: 7)."),
    p1: float = typer.Option(0.5, help="Flight-level exponent on the level (thesis ch. 6: 1)."),
    p2: float = typer.Option(1.5, help="Flight-level exponent elsewhere (thesis ch. 6: 0.5)."),
    grey: str = typer.Option(
        "goal", help="Grey level at the partial 'goal' or the 'follower'."),
    seed: int = typer.Option(0, help="Seed of the scenario's random relief."),
    gif: bool = typer.Option(True, "--gif/--no-gif", help="Write the animation."),
    frames: int = typer.Option(60, help="Animation frames (at most)."),
    output: Output = None,
    world: WorldFlags = None,
    mission: MissionFlags = None,
    safety: SafetyFlags = None,
) -> None:
    """``fm2uav formation``: parse, :func:`~fm2uav.experiments.formation.fly_and_summarise`,
    one mission per UAV, write, print."""
    from ..missions.formation.config import MAX_FOLLOWERS, FormationConfig

    # before a name per follower is made, and before the planner loads
    if not 1 <= followers <= MAX_FOLLOWERS:
        FormationConfig(n_followers=followers)  # raises the one-line error naming --followers
    import numpy as np

    from ..errors import InputError
    from ..experiments.formation import fly_and_summarise, summary_rows
    from ..io.exports import EXPORT_FILES, export_formation, file_prefix
    from ..autopilot.geofence import zone_fences
    from ..scenarios.scenario import Scenario
    from ..world.load import check_points, world_summary
    from ..viz.formation import check_frames
    from .cmd_run import write_exports

    check_frames(frames)  # also with --no-gif: a given value is never silently garbage
    w, sc, scenario = world.build(scenario, start, goal, seed=seed, lonlat=lonlat, agl=agl,
                                  default="fissure")
    if agl is not None and level is not None:
        raise InputError("give either --agl (metres) or --level (cells), not both")
    if level is not None:
        agl = float(level) * w.spacing[2]
    flight_level = safety.level(agl, p1=p1, p2=p2)  # refuses agl outside --min/--max-agl
    uavs = ["leader"] + [f"follower {k + 1}" for k in range(followers)]
    mission_names = [file_prefix(n) + EXPORT_FILES[f] for n in uavs for f in MISSION_FORMATS]
    outdir = output.dir(_outputs(gif, output.report) + tuple(mission_names))
    mission_options = mission.export_options(name=f"formation {scenario}")

    def point(text: str | None, default: np.ndarray | None, what: str) -> np.ndarray:
        return cli_point(text, what, w, lonlat=lonlat, cells=cells, agl=agl, default=default)

    s = point(start, sc.start if sc else None, "start")
    g = point(goal, sc.goal if sc else None, "goal")
    check_points(w, {"start": s, "goal": g}, allow_filled=world.allow_filled)
    w = safety.apply(w, {"start": s, "goal": g}, crs=world.crs)  # --no-fly: obstacles
    zones = tuple(getattr(w, "zones", ()))
    fences, fence_warnings = (zone_fences(zones, w, getattr(mission_options, "anchor", None))
                              if zones else ([], []))
    shaping = safety.shaping()
    sc = Scenario(world=w, start=s, goal=g,
                  description=sc.description if sc else f"real data: {scenario}")
    title = f"formation — {scenario}" + (f", flight level {agl:g} m" if agl else "")
    from .. import progress

    with output.progress():
        progress.step("the formation flight", 0.75)
        config = FormationConfig(n_followers=followers, shape=shape, dist=dist,
                                 leader_speed=speed, follower_speed=follower_speed,
                                 cycle=cycle, grey=grey)
        result, summary = fly_and_summarise(
            sc, config=config, level=flight_level,
            **({} if shaping is None else {"shaping": shaping}))
        progress.step("building one mission per UAV", 0.05)
        missions, files = export_formation(result, MISSION_FORMATS, mission_options,
                                           fences=fences)
        summary = {"scenario": scenario, "world": world_summary(w), **summary,
                   "missions": {n: m.summary() for n, m in missions.items()},
                   "safety": _safety(result, missions, flight_level, fences, fence_warnings)}
        progress.step("writing the missions", 0.05)
        write_exports(outdir, files)
        progress.step("figures, tables" + (" and the report" if output.report else ""), 0.15)
        with progress.span("", 1.0):    # _write_case's steps divide this part
            _write_case(outdir, result, summary, title=title, gif=gif, frames=frames,
                        report=output.report, subtitle=sc.description)
    output.summary("FM² formation",
                   {**summary_rows(summary), **_timing_rows(missions),
                    **_safety_rows(summary["safety"]), **world_rows(w)}, summary)
    if not result.completed:
        raise typer.Exit(EXIT_PLANNING)


def _safety(result, missions: dict[str, Any], level, fences, fence_warnings) -> dict[str, Any]:
    """summary.json 'safety': :func:`~fm2uav.analysis.safety.safety_summary` of every UAV's
    flown trajectory and its mission's legs (and the geofence count with zones)."""
    import numpy as np

    from ..analysis.known_ground import check_ground
    from ..analysis.safety import safety_summary

    out: dict[str, Any] = {}
    tracks = result.tracks or ()
    for i, name in enumerate(result.names):
        wps = missions[name].waypoints
        tr = tracks[i] if i < len(tracks) else None  # what {name}_path.* hold
        out[name] = safety_summary(
            result.world, np.asarray(result.positions[:, i] if tr is None else tr.path,
                                     dtype=float),
            requested=None if level is None else level.agl,
            phase=None if tr is None or tr.profile is None else tr.profile.phase,
            waypoints=wps.points_m, waypoint_indices=wps.indices,
            terrain_frame=wps.frame == 10, waypoint_agl=wps.agl, level=level)
        check_ground(result.world, out[name], what=f"the {name}'s path")
    if getattr(result.world, "zones", ()):
        out["geofence"] = {"fences": len(fences), "warnings": list(fence_warnings)}
    return out


def _safety_rows(safety: dict[str, Any]) -> dict[str, str]:
    """One printed row per UAV: lowest AGL along its legs, no-fly zone entries."""
    rows = {}
    for name, s in safety.items():
        if name == "geofence":
            continue
        parts = []
        if s.get("legs"):
            parts.append(f"lowest AGL along the legs {s['legs']['min_m']:.1f} m")
        if s.get("zones"):
            parts.append(f"{len(s['zones']['path_entries'])} no-fly zone entries")
        bad = [k for k, c in s.get("checks", {}).items() if not c.get("ok", True)]
        if bad:
            parts.append("limits NOT met: " + ", ".join(bad))
        parts += [f"warning: {w}" for w in s.get("warnings", ())]
        if parts:
            rows[f"safety {name}"] = "; ".join(parts)
    return rows


def _timing_rows(missions: dict[str, Any]) -> dict[str, str]:
    """One printed row per UAV mission: items, route time vs planned, start hold."""
    rows = {}
    for n, m in missions.items():
        t = m.summary()["timing"]
        rows[f"mission {n}"] = (f"{m.summary()['items']} items, route "
                                f"{t['mission_route_s']:.0f} s (planned {t['planned_s']:.0f} s), "
                                f"start hold {t['start_hold_s']:.1f} s")
    return rows


@handle_errors
@output_options("out/formation-thesis", json_help="Print the results as JSON.",
                report_help="Also write report.html (per case and comparing them).")
def reproduce_formation_cmd(
    seed: int = typer.Option(0, help="Seed of the fissure terrain."),
    gif: bool = typer.Option(True, "--gif/--no-gif", help="Write the animations."),
    output: Output = None,
) -> None:
    """``fm2uav reproduce formation``: :func:`~fm2uav.experiments.formation.reproduce_formation`,
    one folder per case, table.md."""
    from ..experiments.formation import THESIS_CASES, reproduce_formation, thesis_markdown
    from ..scenarios import get_scenario
    from ..io.outdir import OutputDir


    out, report = output.out, output.report
    root = output.dir(["table.md", "summary.json"] + ([REPORT] if report else []))
    for case in THESIS_CASES:
        OutputDir(out / case.folder, force=output.force).check(_outputs(gif, report))
    subtitle = get_scenario("fissure", seed=seed).description
    from .. import progress

    with output.progress():
        def write(case, result, summary) -> None:  # each case's folder as soon as it flew
            with progress.span("writing its folder", 0.0):   # the case's time is its flight
                _write_case(OutputDir(out / case.folder, force=output.force), result,
                            summary, title=case.title, gif=gif, frames=60, report=report,
                            subtitle=subtitle)

        run = reproduce_formation(seed, on_case=write)
    lines = thesis_markdown(run)
    write_text(root, "table.md", lines)
    write_json(root, "summary.json", run.summaries)
    if report:
        from ..viz.formation import thesis_report_html

        write_text(root, REPORT, thesis_report_html(
            run, ["table.md", "summary.json"] + [f"{c.folder}/" for c in run.cases]))
    if output.as_json:
        print_summary("", run.summaries, as_json=True, quiet=output.quiet)
    elif not output.quiet:
        from ._common import console

        console.print(lines.rstrip("\n"), markup=False, highlight=False)  # verbatim
        console.print(f"outputs in {out}/", markup=False, highlight=False)
    if not run.completed:
        raise typer.Exit(EXIT_PLANNING)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``formation`` and ``reproduce formation``."""
    app.command("formation", help=FORMATION_HELP)(formation_cmd)
    reproduce_app.command("formation", help=REPRODUCE_HELP)(reproduce_formation_cmd)
