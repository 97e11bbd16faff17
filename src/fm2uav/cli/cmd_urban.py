"""``fm2uav reproduce urban``: thesis §4.4 — flight levels among the city's buildings."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from ._common import OutputDir, handle_errors, print_summary, progress, to_jsonable

URBAN_FILES = ("table.md", "summary.json") + tuple(f"case{i + 1}.csv" for i in range(6))


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``reproduce urban``."""

    @reproduce_app.command(
        "urban",
        help=(
            "Thesis §4.4: flight levels in the 15-building city — levels 23/30/37 with "
            "p1 = 0.2, p2 = 0.8 and level 30 with (p1, p2) = (0.47, 0.53), (0.45, 0.55), "
            "(0.5, 1.5), from (60, 10, 40) to (20, 75, 20) cells → table.md (share on the "
            "level, climbs, x-y route changes, clearance, warm planning time), summary.json "
            "and one path CSV per case.\n\n"
            "Example:\n\n"
            "  fm2uav reproduce urban --out out/urban"
        ),
    )
    @handle_errors
    def urban_cmd(
        seed: int = typer.Option(
            None, help="City seed (default: the first whose buildings keep 20 m from the "
            "thesis' start and goal)."),
        out: Path = typer.Option(Path("out/urban"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
    ) -> None:
        from ..experiments.urban import reproduce_urban, urban_markdown
        from ..io import write_path_csv

        outdir = OutputDir(out, force=force)
        outdir.check(URBAN_FILES)
        with progress(enabled=not (quiet or as_json)) as step:
            run = reproduce_urban(seed, on_step=step)
            step("writing the table and paths")
            for i, p in enumerate(run.plans):
                with outdir.open(f"case{i + 1}.csv") as fh:
                    write_path_csv(fh, p.path, p.w)
            with outdir.open("table.md") as fh:
                fh.write("# Thesis §4.4 — flight levels in the city\n\n" + urban_markdown(run)
                         + "\n")
        summary = {"seed": run.seed, "start_m": run.start, "goal_m": run.goal, "cases": run.rows}
        with outdir.open("summary.json") as fh:
            json.dump(to_jsonable(summary), fh, indent=2)
        show = {f"level {r['level']} (p1={r['p1']:g}, p2={r['p2']:g})":
                f"on level {r['within_all']:.0%}, max climb {r['climb_max_deg']:.0f}°, "
                f"clearance {r['clearance_m']:.1f} m" for r in run.rows}
        print_summary(f"thesis §4.4 urban flight levels (city seed {run.seed})",
                      summary if as_json else show, as_json=as_json, quiet=quiet,
                      files=outdir.written)
