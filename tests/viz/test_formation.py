"""Formation figures and the GIF of a flight (viz/formation.py)."""

from fm2uav import FormationConfig
from fm2uav.missions.formation import fly_formation
from fm2uav.viz.formation import (
    formation_animation,
    formation_metrics_figure,
    formation_paths_figure,
    formation_profiles_figure,
)


def test_figures_and_gif(corridor, tmp_path):
    r = fly_formation(corridor, (50.0, 200.0, 60.0), (550.0, 200.0, 60.0),
                      config=FormationConfig(dist=20.0, leader_speed=8.0, clearance=20.0))
    for make in (formation_paths_figure, formation_profiles_figure, formation_metrics_figure):
        fig = make(r)
        assert len(fig.axes) >= 2
    gif = formation_animation(r, tmp_path / "a.gif", max_frames=4, dpi=40)
    data = gif.read_bytes()
    assert data[:6] in (b"GIF87a", b"GIF89a")


def test_gif_frames_are_the_full_redraw_s_pixels(corridor, tmp_path, monkeypatch):
    """The GIF's frames (the still part drawn once, the moving artists over it) are, pixel for
    pixel, what a full redraw of each frame gives (matplotlib's PillowWriter: savefig per
    frame); the file holds every frame at the frame rate, looping."""
    import io

    import numpy as np
    from PIL import Image

    from fm2uav.viz import formation as vf

    r = fly_formation(corridor, (50.0, 200.0, 60.0), (550.0, 200.0, 60.0),
                      config=FormationConfig(dist=20.0, leader_speed=8.0, clearance=20.0))
    made = {}
    save = vf._save_gif

    def spy(fig, draw, frames, path, *, fps, dpi):
        made.update(fig=fig, draw=draw, frames=list(frames), dpi=dpi)
        save(fig, draw, frames, path, fps=fps, dpi=dpi)

    monkeypatch.setattr(vf, "_save_gif", spy)
    gif = formation_animation(r, tmp_path / "a.gif", fps=5, max_frames=6, dpi=40)
    fig, draw, frames, dpi = made["fig"], made["draw"], made["frames"], made["dpi"]
    assert len(frames) == 6
    fast = vf.gif_frames(fig, draw, frames, dpi=dpi)
    full = []
    for k in frames:
        draw(k)
        buf = io.BytesIO()
        fig.savefig(buf, format="rgba", dpi=dpi)
        full.append(np.frombuffer(buf.getbuffer(), np.uint8).reshape(fast[0].size[::-1] + (4,)))
    assert len({a.tobytes() for a in full}) == 6  # the frames differ: the check can fail
    for a, b in zip(fast, full):
        assert np.array_equal(np.asarray(a), b)
    with Image.open(gif) as im:
        assert im.n_frames == 6 and im.info["duration"] == 200 and im.info["loop"] == 0
