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
