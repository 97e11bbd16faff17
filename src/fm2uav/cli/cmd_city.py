"""``fm2uav reproduce city``: thesis ch. 3 — FM² in the 15-building city, Dubins check, RRT."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import typer

from ._common import OutputDir, handle_errors, print_summary, to_jsonable

CITY_FILES = (
    "table.csv", "table.md", "rrt.csv", "summary.json", "low_paths.png", "high_paths.png",
    "speed_profiles.png", "rrt.png",
) + tuple(f"{m}_W{e:g}.csv" for m in ("low", "high") for e in (1, 0.5, 0.25))


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
            "paths, and FM² vs OMPL RRT / RRT-Connect / RRT* on the low mission.\n\n"
            "Example:  fm2uav reproduce city --out out/city"
        ),
    )
    @handle_errors
    def city_cmd(
        seed: int = typer.Option(0, help="Seed of the city layout (and OMPL)."),
        airframe: str = typer.Option("disco", help="Airframe preset flown."),
        tolerance: float = typer.Option(5.0, help="Largest admissible separation [m]."),
        rrt: bool = typer.Option(True, "--rrt/--no-rrt", help="Run the RRT comparison."),
        rrt_time: float = typer.Option(5.0, help="Time cap of RRT / RRT-Connect [s]."),
        rrtstar_time: float = typer.Option(1.0, help="Planning time of RRT* [s]."),
        out: Path = typer.Option(Path("out/city"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
    ) -> None:
        from ..analysis.feasibility_compare import (
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
        outdir.check(CITY_FILES)
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
                   "thesis_separation_m", "separation_mean_m", "length_m", "plan_s", "feasible"]
        text = "## Safety and separation distances (Tables 3.1/3.2)\n\n" + _md_table(rows, md_cols)
        for mission in ("low", "high"):
            mc = [c for c in cases if c.mission == mission]
            fig = city_cases_figure(mc, mc[0].world3,
                                    title=f"city, {mission} altitude — FM² planned vs Dubins "
                                          f"flown ({af.name})")
            tmp = outdir.target(f"{mission}_paths.png")
            fig.savefig(tmp, dpi=90)
            outdir.commit(tmp, f"{mission}_paths.png")
        prof = {f"{c.mission} W^{c.exponent:g}": (
            np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(c.path3, axis=0), axis=1))]),
            c.plan.speed) for c in cases}
        fig = speed_profiles_figure(prof, title="velocity profiles along the paths (Fig. 3.4)")
        tmp = outdir.target("speed_profiles.png")
        fig.savefig(tmp, dpi=100)
        outdir.commit(tmp, "speed_profiles.png")
        rrt_rows: list[dict] = []
        if rrt:
            rrt_rows, art = rrt_comparison(missions["low"], "low", af, time_limit=rrt_time,
                                           rrtstar_time=rrtstar_time, tolerance=tolerance,
                                           seed=seed)
            with outdir.open("rrt.csv") as fh:
                wr = csv.DictWriter(fh, fieldnames=list(rrt_rows[0]))
                wr.writeheader()
                wr.writerows(rrt_rows)
            sc = missions["low"]
            fig = rrt_figure(horizontal_slice(sc.world, float(sc.start[2])), art["rrt"],
                             art["fm2"].plan.path, title="low-altitude mission: FM² vs OMPL (Fig. 3.5)")
            tmp = outdir.target("rrt.png")
            fig.savefig(tmp, dpi=90)
            outdir.commit(tmp, "rrt.png")
            text += ("\n## FM² vs RRT, low altitude (thesis: FM² 1.2 s, RRT 5 s)\n\n"
                     + _md_table(rrt_rows, ["planner", "time_s", "length_m", "clearance_m",
                                            "min_radius_m", "separation_max_m", "feasible"]))
        with outdir.open("table.md") as fh:
            fh.write(text)
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
