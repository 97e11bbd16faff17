"""``fm2uav plan``: one FM² path on a built-in scenario."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import typer

from ..planning import plan as plan_path
from ..world.scenarios import SCENARIOS, get_scenario
from ._common import OutputDir, handle_errors, parse_point, print_summary, to_jsonable

PLAN_FILES = ("path.csv", "plan.png", "summary.json")


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``plan`` command."""

    @app.command(
        "plan",
        help=(
            "Plan one FM² path on a built-in scenario and write path.csv, plan.png and "
            "summary.json.\n\n"
            "Examples:\n\n"
            "  fm2uav plan --scenario open-field --out out/plan\n\n"
            "  fm2uav plan --start 20,20,20 --goal 100,80,30 --cells --exponent 0.5 --out out/b\n\n"
            f"Scenarios: {', '.join(SCENARIOS)}."
        ),
    )
    @handle_errors
    def plan_cmd(
        scenario: str = typer.Option("open-field", help="Built-in scenario name."),
        start: str | None = typer.Option(
            None, help="Start x,y,z in metres (or cells with --cells). Default: the scenario's."
        ),
        goal: str | None = typer.Option(
            None, help="Goal x,y,z in metres (or cells with --cells). Default: the scenario's."
        ),
        cells: bool = typer.Option(False, "--cells", help="Read --start/--goal as grid cells."),
        saturation: float = typer.Option(1.0, help="Saturation α in (0, 1]."),
        exponent: float = typer.Option(1.0, help="Exponent β > 0 on W (thesis' adjustment)."),
        order: int = typer.Option(2, help="Fast Marching order, 1 or 2."),
        seed: int = typer.Option(0, help="Seed of the scenario's random relief."),
        out: Path = typer.Option(Path("out/plan"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
    ) -> None:
        sc = get_scenario(scenario, seed=seed)
        world = sc.world
        outdir = OutputDir(out, force=force)
        outdir.check(PLAN_FILES)

        def point(text: str | None, default: np.ndarray, what: str) -> np.ndarray:
            if text is None:
                return default
            p = parse_point(text, world.ndim, what)
            return world.to_world(p) if cells else p

        p = plan_path(
            world,
            point(start, sc.start, "start"),
            point(goal, sc.goal, "goal"),
            saturation=saturation,
            exponent=exponent,
            order=order,
        )
        from ..io import write_path_csv
        from ..viz import plan_figure

        summary = {"scenario": scenario, **p.summary()}
        fig = plan_figure(p, title=f"FM² plan — {scenario}")
        tmp_png = outdir.target("plan.png")
        fig.savefig(tmp_png, dpi=110)
        with outdir.open("path.csv") as fh:
            write_path_csv(fh, p.path, p.speed)
        outdir.commit(tmp_png, "plan.png")
        with outdir.open("summary.json") as fh:
            json.dump(to_jsonable(summary), fh, indent=2)
        rows = {
            "scenario": scenario,
            "start [m]": np.round(p.start, 1).tolist(),
            "goal [m]": np.round(p.goal, 1).tolist(),
            "length [m]": f"{p.length:.1f}",
            "clearance [m]": f"{p.clearance:.1f}",
            "min W on path": f"{p.speed.min():.3f}",
            "timings [ms]": ", ".join(f"{k} {v * 1e3:.1f}" for k, v in p.timings.items()),
        }
        print_summary("FM² plan", rows if not as_json else summary, as_json=as_json,
                      quiet=quiet, files=outdir.written)
