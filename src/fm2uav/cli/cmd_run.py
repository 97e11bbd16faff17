"""``fm2uav run MISSION.yaml``: plan a mission file and write its exports and report.

Also holds :func:`plan_outputs`, the writer of a plan's output files shared by
``fm2uav plan`` and ``fm2uav run``.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import typer

from ._common import OutputDir, handle_errors, print_summary, progress, to_jsonable

#: Output format → file name, for every format a command can write.
OUTPUT_FILES = {
    "csv": "path.csv",
    "geojson": "path.geojson",
    "kml": "path.kml",
    "plan": "mission.plan",
    "wpl": "mission.waypoints",
    "html": "report.html",
    "png": "plan.png",
    "json": "summary.json",
}


def output_names(formats: Sequence[str]) -> list[str]:
    """File names of the given output formats (for ``OutputDir.check``)."""
    return [OUTPUT_FILES[f] for f in formats]


def plan_outputs(
    outdir: OutputDir,
    plan: Any,
    formats: Sequence[str],
    options: Any,
    *,
    title: str,
    subtitle: str = "",
    summary: dict[str, Any] | None = None,
    step: Callable[[str], None] = lambda message: None,
) -> dict[str, Any]:
    """Write the requested outputs of a plan into ``outdir`` (atomically each).

    Parameters
    ----------
    outdir : OutputDir
    plan : fm2uav.Plan
    formats : sequence of str
        Keys of :data:`OUTPUT_FILES`.
    options : fm2uav.io.ExportOptions
        Waypoint thinning, frame, anchor, airframe.
    title, subtitle : str
        Of the HTML report and PNG figure.
    summary : dict, optional
        Extra entries of ``summary.json``.

    Returns
    -------
    dict
        The summary (plan numbers, waypoints, home, files).
    """
    from ..io import EXPORT_FILES, export_writers

    exports = [f for f in formats if f in EXPORT_FILES]
    step("geo-referencing and thinning waypoints")
    writers, wps = export_writers(plan, exports, options)
    info = {
        **(summary or {}),
        **plan.summary(),
        "waypoints": len(wps),
        "mavlink_frame": wps.frame,
        "home_lat_lon_alt": [round(v, 9) for v in wps.home],
        "thin_tolerance_m": options.tolerance,
    }
    for f in exports:
        name = EXPORT_FILES[f]
        step(f"writing {name}")
        with outdir.open(name) as fh:
            writers[name](fh)
    if "html" in formats:
        from ..viz.report import plan_report

        step("writing report.html")
        params = {**plan.params, "waypoint tolerance [m]": options.tolerance,
                  "MAVLink frame": {3: "3 (relative to home)", 10: "10 (above terrain)"}
                  .get(wps.frame, wps.frame)}
        metrics = {
            "length [m]": round(float(plan.length), 1),
            "clearance [m]": (round(float(plan.clearance), 2) if np.isfinite(plan.clearance)
                              else "inf"),
            "min W on path": round(float(plan.speed.min()), 4),
            "path points": len(plan.path),
            "waypoints": len(wps),
            "home (lat, lon, alt)": [round(v, 7) for v in wps.home],
            "planning time [s]": round(float(plan.timings.get("total", 0.0)), 3),
        }
        html = plan_report(plan, title=title, subtitle=subtitle,
                           waypoints={"FM² path": wps.points_m}, params=params,
                           metrics=metrics, files=output_names(formats))
        with outdir.open("report.html", mode="w") as fh:
            fh.write(html)
    if "png" in formats:
        from ..viz import plan_figure

        step("writing plan.png")
        fig = plan_figure(plan, title=title)
        tmp = outdir.target("plan.png")
        try:
            fig.savefig(tmp, dpi=110)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
        outdir.commit(tmp, "plan.png")
    if "json" in formats:
        with outdir.open("summary.json") as fh:
            json.dump(to_jsonable({**info, "files": [str(p.name) for p in outdir.written]
                                   + ["summary.json"]}), fh, indent=2)
    return info


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``run`` command."""

    @app.command(
        "run",
        help=(
            "Plan the mission described by a YAML file and write its outputs: path.csv, "
            "path.geojson, path.kml, mission.plan (QGroundControl), mission.waypoints "
            "(MAVLink QGC WPL 110), report.html (interactive), plan.png and summary.json "
            "— as listed under outputs.formats.\n\n"
            "Examples:\n\n"
            "  fm2uav run examples/open_field_tff.yaml\n\n"
            "  fm2uav run examples/jacksboro_tff.yaml --out out/jacksboro --force\n\n"
            "See docs/operator.md for the mission file format."
        ),
    )
    @handle_errors
    def run_cmd(
        mission_file: Path = typer.Argument(..., help="Mission YAML file.", show_default=False),
        out: Path | None = typer.Option(
            None, help="Output directory. Default: the mission's outputs.dir, else "
            "out/<mission file name>."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
    ) -> None:
        from ..io.mission import load_mission
        from ..planning import plan as plan_path

        mission = load_mission(mission_file)
        target = out or Path(mission.outputs.dir or Path("out") / mission_file.stem)
        outdir = OutputDir(target, force=force)
        formats = list(dict.fromkeys(mission.outputs.formats))
        outdir.check(output_names(formats))
        with progress(enabled=not (quiet or as_json)) as step:
            step("building the world")
            rm = mission.resolve()
            step("planning (FM²)")
            p = plan_path(rm.world, rm.start, rm.goal, **mission.plan_kwargs())
            world_desc = (mission.world.scenario or Path(mission.world.dem or
                                                          mission.world.buildings or "").name)
            info = plan_outputs(
                outdir, p, formats, mission.export_options(),
                title=f"{mission.name}", subtitle=f"{world_desc} — {mission.description}"
                if mission.description else world_desc,
                summary={"mission": mission.name, "mission_file": str(mission_file),
                         "world": world_desc},
                step=step,
            )
        rows = {
            "mission": mission.name,
            "world": world_desc,
            "start [m]": np.round(p.start, 1).tolist(),
            "goal [m]": np.round(p.goal, 1).tolist(),
            "length [m]": f"{p.length:.1f}",
            "clearance [m]": f"{p.clearance:.1f}",
            "waypoints": f"{info['waypoints']} (MAVLink frame {info['mavlink_frame']})",
            "home lat, lon, alt": ", ".join(f"{v:.7f}" for v in info["home_lat_lon_alt"][:2])
            + f", {info['home_lat_lon_alt'][2]:.1f} m",
            "time [s]": f"{p.timings['total']:.2f}",
        }
        print_summary("fm2uav run", rows if not as_json else {**info, "out": str(target)},
                      as_json=as_json, quiet=quiet, files=outdir.written)
