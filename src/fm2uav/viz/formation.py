"""Figures and animation of a leader–follower formation flight (thesis Figs 6.5–6.8).

Drawing only: every number comes from a
:class:`~fm2uav.missions.formation.FormationResult`.

* :func:`formation_paths_figure` — top view of the paths on the terrain with
  the real (red) and desired (green) triangles at regular times (Fig. 6.5 a /
  6.7 a) and the leader's velocity map ``W`` at its flight height with the UAVs
  as obstacles (Fig. 6.5 b / 6.7 b);
* :func:`formation_profiles_figure` — altitude of each UAV against the ideal
  path and the terrain profile (Figs 6.6 / 6.8);
* :func:`formation_metrics_figure` — smallest inter-UAV distance, formation
  shape error and grey levels over time;
* :func:`formation_animation` — GIF (matplotlib ``PillowWriter``), or MP4 when
  ffmpeg is installed and the file name ends in ``.mp4``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib
import numpy as np
from matplotlib import animation
from matplotlib.colors import LightSource
from matplotlib.figure import Figure

from ..geometry import arc_length
from ._finish import finish

if TYPE_CHECKING:
    from ..experiments.formation import ThesisRun
    from ..missions.formation import FormationResult

__all__ = [
    "formation_paths_figure",
    "formation_profiles_figure",
    "formation_metrics_figure",
    "formation_animation",
    "gif_frames",
    "formation_report_html",
    "thesis_report_html",
    "MAX_FRAMES",
    "check_frames",
]

#: Most frames of a formation animation (each is a drawn figure, ~0.1 MB in a GIF).
MAX_FRAMES = 1000

#: One colour per UAV (leader first).
COLOURS = ("crimson", "royalblue", "darkorange", "seagreen", "purple", "teal", "olive")


def _colour(i: int) -> str:
    return COLOURS[i % len(COLOURS)]


def _extent(world) -> tuple[float, float, float, float]:
    b = world.bounds
    return (b[0, 0], b[0, 1], b[1, 0], b[1, 1])


def _terrain_background(ax, world) -> None:
    if world.terrain is not None:
        ls = LightSource(azdeg=315, altdeg=45)
        rgb = ls.shade(world.terrain.T, cmap=matplotlib.colormaps["gist_earth"], vert_exag=2.0,
                       dx=world.spacing[0], dy=world.spacing[1], blend_mode="soft")
        ax.imshow(rgb, origin="lower", extent=_extent(world), aspect="equal")
    else:
        ax.imshow(world.occupancy.sum(axis=2).T, origin="lower", extent=_extent(world),
                  cmap="Greys", aspect="equal")


def _polygon(points_xy: np.ndarray) -> np.ndarray:
    """Closed outline leader → followers → leader (x, y)."""
    return np.vstack([points_xy, points_xy[:1]])


def _snapshot_samples(result: FormationResult, count: int) -> np.ndarray:
    return np.unique(np.linspace(0, len(result.times) - 1, count).round().astype(int))


def _cycle_of_sample(result: FormationResult, k: int) -> int:
    c = int(np.searchsorted(result.cycle_start, result.times[k], side="right")) - 1
    return int(np.clip(c, 0, len(result.cycle_start) - 1))


def formation_paths_figure(
    result: FormationResult, *, snapshots: int = 8, title: str | None = None
) -> Figure:
    """Top view of the formation flight (thesis Fig. 6.5 / 6.7).

    Parameters
    ----------
    result : FormationResult
    snapshots : int
        Number of times at which the real (red) and desired (green, the partial
        goals) formations are drawn.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    world = result.world
    pos = result.positions
    fig = Figure(figsize=(15, 5.8))
    axes = fig.subplots(1, 2)
    ax = axes[0]
    _terrain_background(ax, world)
    for i, name in enumerate(result.names):
        ax.plot(pos[:, i, 0], pos[:, i, 1], color=_colour(i), lw=1.6, label=name)
    for k in _snapshot_samples(result, snapshots):
        c = _cycle_of_sample(result, k)
        goal_poly = _polygon(result.partial_goals[c][:, :2])
        real_poly = _polygon(pos[k][:, :2])
        ax.plot(goal_poly[:, 0], goal_poly[:, 1], color="lime", lw=1.0, alpha=0.9)
        ax.plot(real_poly[:, 0], real_poly[:, 1], color="red", lw=1.2)
        ax.plot(*pos[k, 0, :2], "^", color="red", ms=6, mec="k")
    ax.plot([], [], color="red", lw=1.2, label="real formation")
    ax.plot([], [], color="lime", lw=1.0, label="partial goals")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("(a) paths and formations over the terrain")
    ax.legend(loc="upper left", fontsize=7)

    # (b) the leader's W at its (median) height, the other UAVs as obstacles
    ax = axes[1]
    lp = result.leader_plan
    kz = int(np.clip(np.round(np.median(world.to_index(pos[:, 0])[:, 2])), 0,
                     world.shape[2] - 1))
    Wz = lp.W[:, :, kz]
    im = ax.imshow(Wz.T, origin="lower", extent=_extent(world), cmap="gray", vmin=0,
                   vmax=max(float(Wz.max()), 1e-9), aspect="equal")
    fig.colorbar(im, ax=ax, fraction=0.035, pad=0.02, label="W (leader)")
    radius = float(result.params["safety_radius"])
    theta = np.linspace(0, 2 * np.pi, 40)
    for k in _snapshot_samples(result, snapshots):
        for i in range(1, result.n_uav):
            x, y = pos[k, i, :2]
            ax.fill(x + radius * np.cos(theta), y + radius * np.sin(theta), color="k", alpha=0.8)
        ax.plot(*pos[k, 0, :2], "^", color="red", ms=6, mec="w")
    ax.plot(pos[:, 0, 0], pos[:, 0, 1], color="red", lw=1.0)
    ax.set_xlabel("x [m]")
    ax.set_title(f"(b) W from the leader's perspective, layer z = "
                 f"{world.origin[2] + kz * world.spacing[2]:.0f} m (followers = obstacles)")
    s = result.summary()
    sub = (f"{result.shape.name}, dist {result.dist:g} m · min separation "
           f"{s['min_separation_m']:.1f} m (bound {result.dist / 2:g}) · mission "
           f"{s['mission_time_s']:.0f} s · computed in {s['timings_s']['total']:.2f} s")
    return finish(fig, title, sub)


def formation_profiles_figure(result: FormationResult, *, title: str | None = None) -> Figure:
    """Altitude of each UAV against the ideal path and the terrain (Figs 6.6 / 6.8).

    The ideal path is ``terrain + agl`` for a UAV flying at a level, the
    leader's FM² path for a free leader, and the leader's altitude at the same
    time for a free follower.
    """
    world = result.world
    pos = result.positions
    n = result.n_uav
    fig = Figure(figsize=(10, 2.6 * n))
    axes = fig.subplots(n, 1, sharex=False, squeeze=False)
    b = world.bounds
    for i in range(n):
        ax = axes[i, 0]
        p = pos[:, i, :]
        s = arc_length(p)
        ground = world.surface_height(p[:, 0], p[:, 1])
        ax.fill_between(s, b[2, 0], ground, color="saddlebrown", alpha=0.5, label="terrain")
        agl = result.agl[i]
        if agl is not None:
            ideal, label = ground + agl, f"ideal (terrain + {agl:g} m)"
        elif i == 0:
            ideal, label = None, None
            lp = result.leader_plan.path
            sl = arc_length(lp)
            ax.plot(sl, lp[:, 2], "--", color="k", lw=1, label="ideal (FM² plan)")
        else:
            ideal, label = pos[:, 0, 2], "ideal (leader's height)"
        if ideal is not None:
            ax.plot(s, ideal, "--", color="k", lw=1, label=label)
        ax.plot(s, p[:, 2], color=_colour(i), lw=1.8, label=f"{result.names[i]} altitude")
        ax.set_ylim(b[2, 0], b[2, 1])
        ax.set_ylabel("z [m]")
        ax.set_title(f"({chr(97 + i)}) {result.names[i]}", fontsize=10, loc="left")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=7)
    axes[-1, 0].set_xlabel("distance flown [m]")
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def formation_metrics_figure(result: FormationResult, *, title: str | None = None) -> Figure:
    """Smallest inter-UAV distance, shape error and grey levels over time."""
    fig = Figure(figsize=(10, 7.5))
    axes = fig.subplots(3, 1, sharex=True)
    t = result.times
    ax = axes[0]
    ax.plot(t, result.min_distance, color="k", lw=1.5, label="smallest inter-UAV distance")
    ax.axhline(result.dist / 2, color="red", ls="--", lw=1, label="bound dist/2")
    ax.axhline(2 * result.dist, color="grey", ls=":", lw=1, label="nominal 2·dist")
    ax.set_ylabel("[m]")
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper right", fontsize=7)
    ax.grid(alpha=0.3)
    ax = axes[1]
    ax.plot(t, result.shape_error_norm, color="purple", lw=1.5)
    ax.set_ylabel("shape error / (2·dist)")
    ax.grid(alpha=0.3)
    ax = axes[2]
    for j in range(result.grey.shape[1]):
        ax.step(result.cycle_start, result.grey[:, j], where="post", color=_colour(j + 1),
                label=result.names[j + 1])
    ax.set_ylabel("grey level B")
    ax.set_ylim(-0.05, 1.05)
    ax.set_xlabel("time [s]")
    ax.legend(loc="lower right", fontsize=7)
    ax.grid(alpha=0.3)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def check_frames(max_frames: Any) -> int:
    """``max_frames`` of :func:`formation_animation` as an int in [1, :data:`MAX_FRAMES`].

    Raises
    ------
    InputError
        Not an integer >= 1, or more than :data:`MAX_FRAMES` (names ``--frames``).
    """
    from .. import _validate as v
    from ..errors import InputError

    n = v.integer(max_frames, "max_frames", minimum=1, where=(None, "--frames"))
    if n > MAX_FRAMES:
        raise InputError(f"max_frames = {n} would draw {n} figures (a GIF of ~{n * 0.1:.3g} "
                         f"MB); the limit is {MAX_FRAMES} frames (CLI: --frames)")
    return n


def formation_animation(
    result: FormationResult,
    filename: str | Path,
    *,
    fps: int = 10,
    max_frames: int = 120,
    dpi: int = 80,
) -> Path:
    """Write an animation of the flight (top view, trails, real and desired formation).

    Parameters
    ----------
    result : FormationResult
    filename : str or Path
        Output file; ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).
    fps : int
        Frames per second.
    max_frames : int
        Frames are evenly spread over the flight, at most this many.
    dpi : int
        Resolution.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    fm2uav.InputError
        Unknown extension, or ``.mp4`` without ffmpeg.
    """
    from ..errors import InputError

    max_frames = check_frames(max_frames)
    path = Path(filename)
    suffix = "".join(path.suffixes[-1:]).lower()
    if suffix == ".mp4" and not animation.FFMpegWriter.isAvailable():
        raise InputError("writing .mp4 needs ffmpeg, which is not installed; use a .gif name")
    if suffix not in (".gif", ".mp4"):
        raise InputError(f"animation file must end in .gif or .mp4, got {path.name!r}")
    world = result.world
    pos = result.positions
    frames = _snapshot_samples(result, max_frames)
    fig = Figure(figsize=(7.5, 6))
    ax = fig.subplots()
    _terrain_background(ax, world)
    trails = [ax.plot([], [], color=_colour(i), lw=1.2)[0] for i in range(result.n_uav)]
    goal_line, = ax.plot([], [], color="lime", lw=1.0)
    real_line, = ax.plot([], [], color="red", lw=1.4)
    dots = ax.scatter(pos[0, :, 0], pos[0, :, 1], c=[_colour(i) for i in range(result.n_uav)],
                      s=30, edgecolors="k", zorder=5)
    label = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=8,
                    bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none"})
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"{result.shape.name} formation — red: real, green: partial goals", fontsize=9)
    fig.tight_layout()

    def draw(k: int):
        c = _cycle_of_sample(result, k)
        for i, line in enumerate(trails):
            line.set_data(pos[: k + 1, i, 0], pos[: k + 1, i, 1])
        g = _polygon(result.partial_goals[c][:, :2])
        r = _polygon(pos[k][:, :2])
        goal_line.set_data(g[:, 0], g[:, 1])
        real_line.set_data(r[:, 0], r[:, 1])
        dots.set_offsets(pos[k, :, :2])
        label.set_text(f"t = {result.times[k]:.0f} s   min distance "
                       f"{result.min_distance[k]:.0f} m   shape error "
                       f"{result.shape_error[k]:.0f} m")
        return (*trails, goal_line, real_line, dots, label)

    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".gif":
        _save_gif(fig, draw, frames, path, fps=fps, dpi=dpi)
        return path
    anim = animation.FuncAnimation(fig, draw, frames=frames, blit=False)
    anim.save(str(path), writer=animation.FFMpegWriter(fps=fps), dpi=dpi)
    return path


def gif_frames(fig: Figure, draw: Any, frames: Any, *, dpi: int) -> list[Any]:
    """The frames of an animation as RGBA Pillow images, the figure's still part drawn once.

    ``draw(k)`` updates the figure for frame ``k`` and returns the artists it changed (as
    for :class:`matplotlib.animation.FuncAnimation`). The figure is drawn once with those
    artists left out (axes, ticks, labels, the terrain: what every frame shares); each frame
    is that background with its artists drawn over it, in their order — the same picture as
    a full redraw wherever no still artist lies above a changing one, at a fraction of the
    cost (a full redraw lays out every tick label again, ~75 % of a formation GIF's time).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    frames = list(frames)
    changing = draw(frames[0]) if frames else ()
    for a in changing:
        a.set_animated(True)
    try:
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
        size = canvas.get_width_height()
        images = []
        for k in frames:
            artists = draw(k)
            canvas.restore_region(background)
            for a in sorted(artists, key=lambda a: a.get_zorder()):
                fig.draw_artist(a)
            images.append(Image.frombuffer("RGBA", size, bytes(canvas.buffer_rgba()), "raw",
                                           "RGBA", 0, 1))
    finally:
        for a in changing:
            a.set_animated(False)
    return images


def _save_gif(fig: Figure, draw: Any, frames: Any, path: Path, *, fps: int, dpi: int) -> None:
    """Write :func:`gif_frames` as a looping GIF at ``fps`` (as matplotlib's PillowWriter)."""
    images = gif_frames(fig, draw, frames, dpi=dpi)
    images[0].save(path, save_all=True, append_images=images[1:], duration=int(1000 / fps),
                   loop=0)


def _duration(seconds: float) -> str:
    """``"2 min 41 s"`` (``"41 s"`` under a minute)."""
    m, s = divmod(int(round(seconds)), 60)
    return f"{m} min {s:02d} s" if m else f"{s} s"


def formation_report_html(result: FormationResult, summary: dict[str, Any], *, title: str,
                          subtitle: str, files: list[str]) -> str:
    """report.html of one formation flight: every UAV's track, the leader's FM² plan.

    ``summary`` is :func:`fm2uav.experiments.formation.fly_and_summarise`'s.
    """
    from ..experiments.formation import summary_rows
    from .report import report_html

    r = result
    paths = {name: r.positions[:, i] for i, name in enumerate(r.names)}
    lengths = r.path_lengths()
    per_uav = [{"uav": name, "flight level [m AGL]": "free" if agl is None else agl,
                "flown [m]": round(float(lengths[i]), 1),
                **summary["level_keeping"].get(name, {})}
               for i, (name, agl) in enumerate(zip(r.names, r.agl))]
    from .report import path_figures

    figures = {
        "UAVs": f"{len(r.names)} ({', '.join(r.names)}), shape {summary['shape']}, "
                f"{summary['dist_m']:g} m apart",
        "mission time (simulated)": _duration(float(summary["mission_time_s"])),
        "closest two UAVs": f"{summary['min_separation_m']:.1f} m (bound "
                            f"{summary['separation_bound_m']:g} m)",
        "reached the goal / formation settled": (
            f"{'yes' if summary['completed'] else 'NO'} / "
            f"{'yes' if summary['settled'] else 'NO'}"),
        **path_figures(r.world, paths),
    }
    return report_html(
        r.world, paths, title=title, subtitle=subtitle, figures=figures,
        ideal_agl={name: agl for name, agl in zip(r.names, r.agl) if agl is not None},
        overlays={"leader FM² plan": {"points": r.leader_plan.path, "color": "#333333",
                                      "dash": "dot", "width": 2}},
        params={**r.params, "shape": summary["shape"], "dist [m]": summary["dist_m"]},
        metrics=summary_rows(summary), tables={"UAVs": per_uav}, files=files)


def thesis_report_html(run: ThesisRun, files: list[str]) -> str:
    """report.html comparing the thesis' formation cases: the three leaders and the table."""
    from ..experiments.formation import thesis_table
    from .report import report_html

    sc = run.scenario
    names = {c.folder: c.title for c in run.cases}
    # a case flown on another relief (case 1: scaled to a 36-cell top) is drawn over this
    # one's terrain: say so, its own report.html shows it over the terrain it flew
    other = [names[f] for f, c_sc in run.scenarios.items()
             if f in names and c_sc.description != sc.description]
    note = (f"; drawn over the as-built relief, which {', '.join(other)} did not fly over "
            "(see its folder)" if other else "")
    return report_html(
        sc.world,
        {f"{names[f]} — leader": r.positions[:, 0] for f, r in run.flights.items()},
        title=f"Thesis ch. 6 formations: the leaders of the {len(run.cases)} cases",
        subtitle=f"{sc.description} — each case's own report.html is in its folder{note}",
        ideal_agl={f"{names[f]} — leader": r.agl[0] for f, r in run.flights.items()
                   if r.agl[0] is not None},
        params={"seed": run.seed, "cases": ", ".join(names)},
        metrics={f"{f}: min separation [m]": s["min_separation_m"]
                 for f, s in run.summaries.items()},
        tables={"Results (thesis ch. 6)": thesis_table(run)},
        files=files)
