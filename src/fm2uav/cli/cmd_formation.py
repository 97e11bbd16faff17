"""``fm2uav formation`` / ``fm2uav reproduce formation``: leader–follower flights (thesis ch. 6)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import typer

from ..scenarios import SCENARIOS, get_scenario
from ._common import (
    EXIT_PLANNING,
    OutputDir,
    handle_errors,
    parse_point,
    print_summary,
    progress,
    to_jsonable,
)

FIGURES = ("paths.png", "profiles.png", "metrics.png")
TABLES = ("trajectories.csv", "metrics.csv", "cycles.csv", "summary.json")
ANIMATION = "formation.gif"
REPORT = "report.html"

#: Thesis ch. 6 wall times of the whole formation planning (Matlab) [s].
THESIS_TIMES = {"case1": 130.6, "case2": 135.6}


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


def _level_keeping(result) -> dict[str, Any]:
    """Share of each UAV's flight within one cell of its flight level (analysis)."""
    from ..analysis.flight_level import flight_level_deviation

    out = {}
    for name, agl, i in zip(result.names, result.agl, range(result.n_uav)):
        if agl is None:
            continue
        rep = flight_level_deviation(result.world, result.positions[:, i], agl)
        out[name] = {"within_1_cell": round(rep.within, 3),
                     "mean_dev_m": round(rep.mean_dev_m, 2),
                     "min_agl_m": round(rep.min_agl_m, 2)}
    return out


def _outputs(gif: bool, report: bool) -> tuple[str, ...]:
    return FIGURES + TABLES + ((ANIMATION,) if gif else ()) + ((REPORT,) if report else ())


def _report(result, summary: dict[str, Any], *, title: str, subtitle: str,
            files: list[str]) -> str:
    """report.html of one formation flight: every UAV's track, the leader's FM² plan."""
    from ..viz.report import report_html

    r = result
    paths = {name: r.positions[:, i] for i, name in enumerate(r.names)}
    lengths = r.path_lengths()
    per_uav = [{"uav": name, "flight level [m AGL]": "free" if agl is None else agl,
                "flown [m]": round(float(lengths[i]), 1),
                **summary["level_keeping"].get(name, {})}
               for i, (name, agl) in enumerate(zip(r.names, r.agl))]
    return report_html(
        r.world, paths, title=title, subtitle=subtitle,
        ideal_agl={name: agl for name, agl in zip(r.names, r.agl) if agl is not None},
        overlays={"leader FM² plan": {"points": r.leader_plan.path, "color": "#333333",
                                      "dash": "dot", "width": 2}},
        params={**r.params, "shape": summary["shape"], "dist [m]": summary["dist_m"]},
        metrics=_rows(summary), tables={"UAVs": per_uav}, files=files)


def _run_case(outdir: OutputDir, sc, *, title: str, gif: bool, frames: int,
              report: bool = False, subtitle: str = "",
              step: Callable[[str], None] = lambda message: None, **kw: Any):
    from ..missions.formation import fly_formation, inside_terrain

    step(f"{title}: flying the formation (FM² re-planning every cycle)")
    result = fly_formation(sc.world, sc.start, sc.goal, **kw)
    summary = result.summary()
    summary["inside_terrain_samples"] = int(inside_terrain(result.world, result.positions).sum())
    summary["level_keeping"] = _level_keeping(result)
    from ..viz.formation import (
        formation_animation,
        formation_metrics_figure,
        formation_paths_figure,
        formation_profiles_figure,
    )

    for name, make in zip(FIGURES, (formation_paths_figure, formation_profiles_figure,
                                    formation_metrics_figure)):
        step(f"{title}: writing {name}")
        fig = make(result, title=title)
        tmp = outdir.target(name)
        fig.savefig(tmp, dpi=100)
        outdir.commit(tmp, name)
    _write_tables(outdir, result)
    with outdir.open("summary.json") as fh:
        json.dump(to_jsonable(summary), fh, indent=2)
    if gif:
        step(f"{title}: writing {ANIMATION}")
        tmp = outdir.target(ANIMATION)
        formation_animation(result, tmp, max_frames=frames)
        outdir.commit(tmp, ANIMATION)
    if report:
        step(f"{title}: writing {REPORT}")
        html = _report(result, summary, title=title, subtitle=subtitle,
                       files=list(_outputs(gif, False)))
        with outdir.open(REPORT) as fh:
            fh.write(html)
    return result, summary


def _rows(summary: dict[str, Any]) -> dict[str, Any]:
    return {
        "completed / settled": f"{summary['completed']} / {summary['settled']}",
        "mission time [s]": summary["mission_time_s"],
        "cycles": summary["cycles"],
        "min separation [m]": (f"{summary['min_separation_m']:.1f} "
                               f"(bound {summary['separation_bound_m']:g})"),
        "samples inside terrain": summary["inside_terrain_samples"],
        "shape error max / final [m]": (f"{summary['max_shape_error_m']:.1f} / "
                                        f"{summary['final_shape_error_m']:.1f}"),
        "min grey level": summary["min_grey"],
        "on the level (±1 cell)": ", ".join(
            f"{k} {v['within_1_cell']:.0%}" for k, v in summary["level_keeping"].items()) or "-",
        "cycle [ms] median / p95 / max": "{median} / {p95} / {max}".format(**summary["cycle_ms"]),
        "computed in [s]": summary["timings_s"]["total"],
    }


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``formation`` and ``reproduce formation``."""

    @app.command(
        "formation",
        help=(
            "Fly a leader–follower formation with FM² (thesis ch. 6) and write trajectories.csv, "
            "metrics.csv, cycles.csv, summary.json, paths.png, profiles.png, metrics.png and "
            "formation.gif (and with --report an interactive report.html).\n\n"
            "Examples:\n\n"
            "  fm2uav formation --scenario fissure --out out/formation\n\n"
            "  fm2uav formation --scenario fissure --level 7 --report --out out/formation-l7\n\n"
            "  fm2uav formation --shape v --followers 4 --dist 45 --no-gif --out out/v4\n\n"
            f"Scenarios: {', '.join(SCENARIOS)}."
        ),
    )
    @handle_errors
    def formation_cmd(
        scenario: str = typer.Option("fissure", help="Built-in scenario name."),
        start: str | None = typer.Option(None, help="Leader start x,y,z (m) (cells with --cells)."),
        goal: str | None = typer.Option(None, help="Leader goal x,y,z (m) (cells with --cells)."),
        cells: bool = typer.Option(False, "--cells", help="Read --start/--goal as grid cells."),
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
        out: Path = typer.Option(Path("out/formation"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
        report: bool = typer.Option(
            False, "--report", help="Also write report.html (interactive, self-contained)."),
    ) -> None:
        from ..errors import InputError

        sc = get_scenario(scenario, seed=seed)
        world = sc.world
        if agl is not None and level is not None:
            raise InputError("give either --agl (metres) or --level (cells), not both")
        if level is not None:
            agl = float(level) * world.spacing[2]
        outdir = OutputDir(out, force=force)
        outdir.check(_outputs(gif, report))

        def point(text: str | None, default: np.ndarray, what: str) -> np.ndarray:
            if text is None:
                return default
            p = parse_point(text, world.ndim, what)
            return world.to_world(p) if cells else p

        sc = type(sc)(world=world, start=point(start, sc.start, "start"),
                      goal=point(goal, sc.goal, "goal"), description=sc.description)
        title = f"formation — {scenario}" + (f", flight level {agl:g} m" if agl else "")
        with progress(enabled=not (quiet or as_json)) as step:
            result, summary = _run_case(
                outdir, sc, title=title, gif=gif, frames=frames, report=report,
                subtitle=sc.description, step=step, n_followers=followers,
                shape=shape, dist=dist, leader_speed=speed, follower_speed=follower_speed,
                cycle=cycle, agl=agl, p1=p1, p2=p2, grey=grey,
            )
        summary = {"scenario": scenario, **summary}
        print_summary("FM² formation", summary if as_json else _rows(summary), as_json=as_json,
                      quiet=quiet, files=outdir.written)
        if not result.completed:
            raise typer.Exit(EXIT_PLANNING)

    @reproduce_app.command(
        "formation",
        help=(
            "Thesis ch. 6: the triangle formation across the fissure without (case 1) and with "
            "(case 2) the flight level 7 cells; case 2 is run with the thesis' p1 = 1, p2 = 0.5 "
            "and with the planner's p1 = 0.5, p2 = 1.5. Writes one folder per case and "
            "table.md comparing our times with the thesis' 130.6 s / 135.6 s (Matlab); with "
            "--report also report.html per case and one comparing the cases.\n\n"
            "Examples:\n\n"
            "  fm2uav reproduce formation --out out/formation-thesis\n\n"
            "  fm2uav reproduce formation --no-gif --report --out out/formation-report"
        ),
    )
    @handle_errors
    def reproduce_formation(
        seed: int = typer.Option(0, help="Seed of the fissure terrain."),
        gif: bool = typer.Option(True, "--gif/--no-gif", help="Write the animations."),
        out: Path = typer.Option(Path("out/formation-thesis"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the results as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
        report: bool = typer.Option(
            False, "--report", help="Also write report.html (per case and comparing them)."),
    ) -> None:
        sc = get_scenario("fissure", seed=seed)
        dz = sc.world.spacing[2]
        cases = [
            ("case1", "case 1: no flight level", {}, "case1"),
            ("case2-thesis-p", "case 2: level 7, p1 = 1, p2 = 0.5 (thesis)",
             {"agl": 7 * dz, "p1": 1.0, "p2": 0.5}, "case2"),
            ("case2", "case 2: level 7, p1 = 0.5, p2 = 1.5",
             {"agl": 7 * dz, "p1": 0.5, "p2": 1.5}, "case2"),
        ]
        root = OutputDir(out, force=force)
        root.check(["table.md", "summary.json"] + ([REPORT] if report else []))
        for folder, *_ in cases:
            OutputDir(out / folder, force=force).check(_outputs(gif, report))
        results, flights, table = {}, {}, []
        lines = [
            "| case | our time [s] | thesis [s] | min separation [m] (≥ 30) | inside terrain | "
            "max / final shape error [m] | min grey | leader on level | cycle median [ms] |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        with progress(enabled=not (quiet or as_json)) as step:
            for folder, title, kw, thesis_key in cases:
                flights[folder], results[folder] = _run_case(
                    OutputDir(out / folder, force=force), sc, title=title, gif=gif, frames=60,
                    report=report, subtitle=sc.description, step=step, **kw)
        for folder, title, kw, thesis_key in cases:
            s = results[folder]
            lead = s["level_keeping"].get("leader", {}).get("within_1_cell", "-")
            table.append({
                "case": title, "our time [s]": s["timings_s"]["total"],
                "thesis [s]": THESIS_TIMES[thesis_key],
                "min separation [m] (≥ 30)": s["min_separation_m"],
                "inside terrain": s["inside_terrain_samples"],
                "max / final shape error [m]": f"{s['max_shape_error_m']:.0f} / "
                                               f"{s['final_shape_error_m']:.0f}",
                "min grey": s["min_grey"], "leader on level": lead,
                "cycle median [ms]": s["cycle_ms"]["median"], "completed": s["completed"]})
            lines.append(
                f"| {title} | {s['timings_s']['total']:.2f} | {THESIS_TIMES[thesis_key]} | "
                f"{s['min_separation_m']:.1f} | {s['inside_terrain_samples']} | "
                f"{s['max_shape_error_m']:.0f} / {s['final_shape_error_m']:.0f} | "
                f"{s['min_grey']} | {lead} | {s['cycle_ms']['median']} |"
            )
        with root.open("table.md") as fh:
            fh.write("\n".join(lines) + "\n")
        with root.open("summary.json") as fh:
            json.dump(to_jsonable(results), fh, indent=2)
        if report:
            from ..viz.report import report_html

            names = {folder: title for folder, title, *_ in cases}
            html = report_html(
                sc.world,
                {f"{names[f]} — leader": r.positions[:, 0] for f, r in flights.items()},
                title="Thesis ch. 6 formations: the leaders of the three cases",
                subtitle=f"{sc.description} — each case's own report.html is in its folder",
                ideal_agl={f"{names[f]} — leader": r.agl[0] for f, r in flights.items()
                           if r.agl[0] is not None},
                params={"seed": seed, "cases": ", ".join(names)},
                metrics={f"{f}: min separation [m]": s["min_separation_m"]
                         for f, s in results.items()},
                tables={"Results (thesis ch. 6)": table},
                files=["table.md", "summary.json"] + [f"{f}/" for f in names])
            with root.open(REPORT) as fh:
                fh.write(html)
        if as_json:
            print_summary("", results, as_json=True, quiet=quiet)
        elif not quiet:
            from ._common import console

            console.print("\n".join(lines))
            console.print(f"outputs in {out}/")
        if not all(s["completed"] for s in results.values()):
            raise typer.Exit(EXIT_PLANNING)
