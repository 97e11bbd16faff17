"""``fm2uav reproduce city``: thesis ch. 3 — FM² in the 15-building city, Dubins check, RRT."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import typer

from ._common import OutputDir, handle_errors, print_summary, progress, to_jsonable

CITY_FILES = (
    "table.csv", "table.md", "rrt.csv", "summary.json", "low_paths.png", "high_paths.png",
    "speed_profiles.png", "rrt.png",
) + tuple(f"{m}_W{e:g}.csv" for m in ("low", "high") for e in (1, 0.5, 0.25))


REPORT = "report.html"


def _report(cases, rrt_paths: dict, rows: list[dict], rrt_rows: list[dict], *, af,
            seed: int, tolerance: float, files: list[str]) -> str:
    """report.html: FM² paths of both missions, their Dubins-flown tracks, the RRT paths."""
    from ..viz.report import join_polylines, report_html

    paths = {f"FM² {c.mission} W^{c.exponent:g}": c.path3 for c in cases}
    speeds = {f"FM² {c.mission} W^{c.exponent:g}": c.plan.speed for c in cases}
    paths.update(rrt_paths)
    flown = join_polylines([c.report.tracking.trajectory for c in cases])
    cols = ["mission", "exponent", "safety_m", "thesis_safety_m", "separation_max_m",
            "thesis_separation_m", "length_m", "plan_s", "feasible"]
    return report_html(
        cases[0].world3, paths, speeds=speeds,
        title="Thesis ch. 3: FM² in the city, Dubins-flown, vs RRT",
        subtitle=f"low- and high-altitude missions with W^1, W^1/2, W^1/4 flown by the "
                 f"{af.name}; OMPL planners on the low mission",
        overlays={f"flown tracks ({af.name})": {"points": flown, "color": "#222222",
                                               "dash": "dash", "width": 2}},
        params={"seed": seed, "airframe": af.name, "tolerance [m]": tolerance},
        metrics={f"{r['mission']} W^{r['exponent']:g}": (
            f"safety {r['safety_m']} m, separation {r['separation_max_m']} m, "
            f"{'feasible' if r['feasible'] else 'INFEASIBLE'}") for r in rows},
        tables={"Safety and separation distances (Tables 3.1/3.2)":
                [{c: r[c] for c in cols} for r in rows],
                "FM² vs RRT, low altitude": rrt_rows},
        files=files)


def _md_table(rows: list[dict], cols: list[str]) -> str:
    head = "| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n"
    return head + "".join("| " + " | ".join(str(r[c]) for c in cols) + " |\n" for r in rows)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``reproduce city``."""

    @reproduce_app.command(
        "city",
        help=(
            "Thesis ch. 3: low- and high-altitude missions in the 15-building city with W^1, "
            "W^1/2, W^1/4, each flown by a Dubins airplane → table of safety and separation "
            "distances next to Tables 3.1/3.2, velocity profiles (Fig. 3.4), planned vs flown "
            "paths, and FM² vs OMPL RRT / RRT-Connect / RRT* on the low mission; with --report "
            "an interactive report.html of all paths.\n\n"
            "Examples:\n\n"
            "  fm2uav reproduce city --out out/city\n\n"
            "  fm2uav reproduce city --rrt-time 2 --report --out out/city-report"
        ),
    )
    @handle_errors
    def city_cmd(
        seed: int = typer.Option(0, help="Seed of the city layout (and OMPL)."),
        airframe: str = typer.Option("disco", help="Airframe preset flown."),
        tolerance: float = typer.Option(5.0, help="Largest admissible separation (m)."),
        rrt: bool = typer.Option(True, "--rrt/--no-rrt", help="Run the RRT comparison."),
        rrt_time: float = typer.Option(5.0, help="Time cap of RRT / RRT-Connect (s)."),
        rrtstar_time: float = typer.Option(1.0, help="Planning time of RRT* (s)."),
        out: Path = typer.Option(Path("out/city"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
        report: bool = typer.Option(
            False, "--report", help="Also write report.html (interactive, self-contained)."),
    ) -> None:
        from ..experiments.city import (
            THESIS_TIMES_S,
            city_missions,
            city_table,
            horizontal_slice,
            rrt_comparison,
        )
        from ..io import write_path_csv
        from ..vehicles import get_airframe
        from ..viz.feasibility import city_cases_figure, rrt_figure, speed_profiles_figure

        af = get_airframe(airframe)
        outdir = OutputDir(out, force=force)
        outdir.check(CITY_FILES + ((REPORT,) if report else ()))
        with progress(enabled=not (quiet or as_json)) as step:
            step("planning both missions with W^1, W^1/2, W^1/4 and flying them")
            cases = city_table(seed, af, tolerance=tolerance)
            rows = [c.row() for c in cases]
            missions = city_missions(seed)
            for c in cases:
                with outdir.open(f"{c.mission}_W{c.exponent:g}.csv") as fh:
                    write_path_csv(fh, c.path3, c.plan.speed)
            cols = list(rows[0])
            with outdir.open("table.csv") as fh:
                wr = csv.DictWriter(fh, fieldnames=cols)
                wr.writeheader()
                wr.writerows(rows)
            md_cols = ["mission", "exponent", "safety_m", "thesis_safety_m", "separation_max_m",
                       "thesis_separation_m", "separation_mean_m", "length_m", "plan_s",
                       "feasible"]
            text = ("## Safety and separation distances (Tables 3.1/3.2)\n\n"
                    + _md_table(rows, md_cols))
            step("drawing the figures")
            for mission in ("low", "high"):
                mc = [c for c in cases if c.mission == mission]
                fig = city_cases_figure(
                    mc, mc[0].world3,
                    title=f"city, {mission} altitude — FM² planned vs Dubins flown ({af.name})")
                tmp = outdir.target(f"{mission}_paths.png")
                fig.savefig(tmp, dpi=90)
                outdir.commit(tmp, f"{mission}_paths.png")
            prof = {f"{c.mission} W^{c.exponent:g}": (
                np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(c.path3, axis=0),
                                                                axis=1))]),
                c.plan.speed) for c in cases}
            fig = speed_profiles_figure(prof, title="velocity profiles along the paths (Fig. 3.4)")
            tmp = outdir.target("speed_profiles.png")
            fig.savefig(tmp, dpi=100)
            outdir.commit(tmp, "speed_profiles.png")
            rrt_rows: list[dict] = []
            rrt_paths: dict[str, np.ndarray] = {}
            if rrt:
                step("FM² vs OMPL RRT / RRT-Connect / RRT* (low mission)")
                rrt_rows, art = rrt_comparison(missions["low"], "low", af, time_limit=rrt_time,
                                               rrtstar_time=rrtstar_time, tolerance=tolerance,
                                               seed=seed)
                with outdir.open("rrt.csv") as fh:
                    wr = csv.DictWriter(fh, fieldnames=list(rrt_rows[0]))
                    wr.writeheader()
                    wr.writerows(rrt_rows)
                sc = missions["low"]
                fig = rrt_figure(horizontal_slice(sc.world, float(sc.start[2])), art["rrt"],
                                 art["fm2"].plan.path,
                                 title="low-altitude mission: FM² vs OMPL (Fig. 3.5)")
                tmp = outdir.target("rrt.png")
                fig.savefig(tmp, dpi=90)
                outdir.commit(tmp, "rrt.png")
                text += ("\n## FM² vs RRT, low altitude (thesis: FM² 1.2 s, RRT 5 s)\n\n"
                         + _md_table(rrt_rows, ["planner", "time_s", "length_m", "clearance_m",
                                                "min_radius_m", "separation_max_m", "feasible"]))
                z = float(sc.start[2])
                for r in art["rrt"].values():
                    p = r.path if r.path.shape[1] == 3 else np.column_stack(
                        [r.path, np.full(len(r.path), z)])
                    rrt_paths[f"{r.planner} low (+ shortcut)"] = p
            with outdir.open("table.md") as fh:
                fh.write(text)
            if report:
                step("writing report.html")
                html = _report(cases, rrt_paths, rows, rrt_rows, af=af, seed=seed,
                               tolerance=tolerance, files=list(CITY_FILES))
                with outdir.open(REPORT) as fh:
                    fh.write(html)
        summary = {"seed": seed, "airframe": af.summary(), "table": rows, "rrt": rrt_rows,
                   "thesis_times_s": THESIS_TIMES_S}
        with outdir.open("summary.json") as fh:
            json.dump(to_jsonable(summary), fh, indent=2)
        show = {
            f"{r['mission']} W^{r['exponent']:g}": (
                f"safety {r['safety_m']:.1f} m (thesis {r['thesis_safety_m']}), separation "
                f"{r['separation_max_m']:.2f} m (thesis {r['thesis_separation_m']}), "
                f"{'feasible' if r['feasible'] else 'INFEASIBLE'}")
            for r in rows
        }
        for r in rrt_rows:
            show[r["planner"]] = (f"{r['time_s'] * 1e3:.0f} ms, length {r['length_m']:.0f} m, "
                                  f"clearance {r['clearance_m']:.1f} m, "
                                  f"{'feasible' if r['feasible'] else 'INFEASIBLE'}")
        print_summary(f"thesis ch. 3 city (seed {seed}, {af.name})",
                      summary if as_json else show, as_json=as_json, quiet=quiet,
                      files=outdir.written)
