"""``fm2uav formation`` / ``fm2uav reproduce formation``: leader–follower flights (thesis ch. 6)."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np
import typer

from ..world.scenarios import SCENARIOS, get_scenario
from ._common import OutputDir, handle_errors, parse_point, print_summary, to_jsonable

FIGURES = ("paths.png", "profiles.png", "metrics.png")
TABLES = ("trajectories.csv", "metrics.csv", "cycles.csv", "summary.json")
ANIMATION = "formation.gif"

#: Thesis ch. 6 wall times of the whole formation planning (Matlab) [s].
THESIS_TIMES = {"case1": 130.6, "case2": 135.6}


def _write_trajectories(fh, result) -> None:
    w = csv.writer(fh)
    w.writerow(["time_s", "uav", "x_m", "y_m", "z_m"])
    for k, t in enumerate(result.times):
        for i, name in enumerate(result.names):
            x, y, z = result.positions[k, i]
            w.writerow([f"{t:.3f}", name, f"{x:.3f}", f"{y:.3f}", f"{z:.3f}"])


def _write_metrics(fh, result) -> None:
    w = csv.writer(fh)
    w.writerow(["time_s", "min_distance_m", "shape_error_m", "shape_error_norm"])
    for t, d, e, en in zip(result.times, result.min_distance, result.shape_error,
                           result.shape_error_norm):
        w.writerow([f"{t:.3f}", f"{d:.3f}", f"{e:.3f}", f"{en:.4f}"])


def _write_cycles(fh, result) -> None:
    w = csv.writer(fh)
    nf = result.grey.shape[1]
    head = ["cycle", "time_s", "compute_ms"]
    head += [f"grey_f{j + 1}" for j in range(nf)]
    for name in result.names:
        tag = name.replace(" ", "")
        head += [f"goal_{tag}_x_m", f"goal_{tag}_y_m", f"goal_{tag}_z_m", f"held_{tag}"]
    w.writerow(head)
    for c, t in enumerate(result.cycle_start):
        row: list[Any] = [c, f"{t:.3f}", f"{result.compute_s[c] * 1e3:.3f}"]
        row += [f"{b:.3f}" for b in result.grey[c]]
        for i in range(result.n_uav):
            row += [f"{v:.3f}" for v in result.partial_goals[c, i]] + [int(result.held[c, i])]
        w.writerow(row)


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


def _run_case(outdir: OutputDir, sc, *, title: str, gif: bool, frames: int, **kw: Any):
    from ..missions.formation import fly_formation, inside_terrain

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
        fig = make(result, title=title)
        tmp = outdir.target(name)
        fig.savefig(tmp, dpi=100)
        import matplotlib.pyplot as plt

        plt.close(fig)
        outdir.commit(tmp, name)
    for name, writer in zip(TABLES[:3], (_write_trajectories, _write_metrics, _write_cycles)):
        with outdir.open(name, "w") as fh:
            writer(fh, result)
    with outdir.open("summary.json") as fh:
        json.dump(to_jsonable(summary), fh, indent=2)
    if gif:
        tmp = outdir.target(ANIMATION)
        formation_animation(result, tmp, max_frames=frames)
        outdir.commit(tmp, ANIMATION)
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
            "formation.gif.\n\n"
            "Examples:\n\n"
            "  fm2uav formation --scenario fissure --out out/formation\n\n"
            "  fm2uav formation --scenario fissure --level 7 --out out/formation-l7\n\n"
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
    ) -> None:
        from ..errors import InputError

        sc = get_scenario(scenario, seed=seed)
        world = sc.world
        if agl is not None and level is not None:
            raise InputError("give either --agl (metres) or --level (cells), not both")
        if level is not None:
            agl = float(level) * world.spacing[2]
        outdir = OutputDir(out, force=force)
        outdir.check(FIGURES + TABLES + ((ANIMATION,) if gif else ()))

        def point(text: str | None, default: np.ndarray, what: str) -> np.ndarray:
            if text is None:
                return default
            p = parse_point(text, world.ndim, what)
            return world.to_world(p) if cells else p

        sc = type(sc)(world=world, start=point(start, sc.start, "start"),
                      goal=point(goal, sc.goal, "goal"), description=sc.description)
        title = f"formation — {scenario}" + (f", flight level {agl:g} m" if agl else "")
        result, summary = _run_case(
            outdir, sc, title=title, gif=gif, frames=frames, n_followers=followers,
            shape=shape, dist=dist, leader_speed=speed, follower_speed=follower_speed,
            cycle=cycle, agl=agl, p1=p1, p2=p2, grey=grey,
        )
        summary = {"scenario": scenario, **summary}
        print_summary("FM² formation", summary if as_json else _rows(summary), as_json=as_json,
                      quiet=quiet, files=outdir.written)
        if not result.completed:
            raise typer.Exit(1)

    @reproduce_app.command(
        "formation",
        help=(
            "Thesis ch. 6: the triangle formation across the fissure without (case 1) and with "
            "(case 2) the flight level 7 cells; case 2 is run with the thesis' p1 = 1, p2 = 0.5 "
            "and with the planner's p1 = 0.5, p2 = 1.5. Writes one folder per case and "
            "table.md comparing our times with the thesis' 130.6 s / 135.6 s (Matlab).\n\n"
            "Example:  fm2uav reproduce formation --out out/formation-thesis"
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
        root.check(["table.md", "summary.json"])
        for folder, *_ in cases:
            OutputDir(out / folder, force=force).check(
                FIGURES + TABLES + ((ANIMATION,) if gif else ()))
        results = {}
        lines = [
            "| case | our time [s] | thesis [s] | min separation [m] (≥ 30) | inside terrain | "
            "max / final shape error [m] | min grey | leader on level | cycle median [ms] |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        for folder, title, kw, thesis_key in cases:
            _, s = _run_case(OutputDir(out / folder, force=force), sc, title=title, gif=gif,
                             frames=60, **kw)
            results[folder] = s
            lead = s["level_keeping"].get("leader", {}).get("within_1_cell", "-")
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
        if as_json:
            print_summary("", results, as_json=True, quiet=quiet)
        elif not quiet:
            from ._common import console

            console.print("\n".join(lines))
            console.print(f"outputs in {out}/")
