"""The additions to fm2uav.viz.report used by the mission commands, on tiny worlds."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from fm2uav import World
from fm2uav.viz.report import join_polylines, report_html


def _traces(html: str, div_id: str) -> dict[str, dict]:
    m = re.search(r'Plotly\.newPlot\(\s*"' + div_id + r'",\s*', html)
    data, _ = json.JSONDecoder().raw_decode(html, m.end())
    return {t.get("name"): t for t in data}


def _arr(v):
    if isinstance(v, dict) and "bdata" in v:
        import base64

        return np.frombuffer(base64.b64decode(v["bdata"]), dtype=np.dtype(v["dtype"]))
    return np.array([np.nan if x is None else x for x in v], dtype=float)


@pytest.fixture(scope="module")
def slope():
    """Ground rising 0.1 m per metre in x: 21 x 11 nodes of 10 m."""
    h = np.repeat((np.arange(21) * 1.0)[:, None], 11, axis=1)   # 0..20 m
    return World.from_heightmap(h, 10.0, 10, name="slope")


def test_join_polylines_exact():
    j = join_polylines([[[0, 0], [1, 0]], [[5, 5], [6, 6], [7, 7]]])
    assert j.shape == (6, 2)
    np.testing.assert_array_equal(j[[0, 1, 3, 4, 5]], [[0, 0], [1, 0], [5, 5], [6, 6], [7, 7]])
    assert np.isnan(j[2]).all()
    with pytest.raises(ValueError):
        join_polylines([])


def test_ideal_level_styles_overlays_and_tables(slope):
    p = np.column_stack([np.linspace(0, 200, 21), np.full(21, 50.0), np.full(21, 40.0)])
    html = report_html(
        slope, {"planned": p, "flown": p + [0, 1, 0]},
        styles={"flown": {"dash": "dash"}}, ideal_agl={"planned": 30.0},
        overlays={"area": [[0, 0], [100, 0], [np.nan, np.nan], [0, 100], [100, 100]]},
        tables={"Cases": [{"case": "a", "x [m]": 1.5}, {"case": "b", "y": "<b>"}]})
    prof = _traces(html, "fm2uav-profiles")
    # ideal altitude = ground under the path + 30 m; ground = x / 10 on this slope
    np.testing.assert_allclose(_arr(prof["planned ideal (30 m AGL)"]["y"]),
                               p[:, 0] / 10.0 + 30.0, atol=1e-9)
    np.testing.assert_allclose(_arr(prof["planned AGL"]["y"]), 40.0 - p[:, 0] / 10.0, atol=1e-9)
    assert "flown ideal (30 m AGL)" not in prof
    assert prof["flown altitude"]["line"]["dash"] == "dash"
    assert "planned W" not in prof and "W (speed share)" not in html  # no speeds: no W panel
    scene = _traces(html, "fm2uav-scene")
    assert scene["flown"]["line"]["dash"] == "dash"
    area = scene["area"]
    x, y, z = (_arr(area[k]) for k in "xyz")
    gap = np.isnan(x)
    assert gap.sum() == 1 and np.isnan(z[gap]).all()
    # draped: densified to the 10 m grid, lifted max(2, dz / 2) = 5 m over the ground x / 10
    assert (~gap).sum() == 22
    np.testing.assert_allclose(z[~gap], x[~gap] / 10.0 + 5.0, atol=1e-9)
    # the result table: headers are the union of the keys, values escaped
    assert "<h2>Cases</h2>" in html and "<th>x [m]</th>" in html and "&lt;b&gt;" in html


def test_paths_without_a_world():
    p = np.column_stack([np.linspace(0, 100, 11), np.zeros(11), np.linspace(10, 30, 11)])
    html = report_html(None, {"planned": p}, title="bare")
    prof = _traces(html, "fm2uav-profiles")
    assert set(prof) == {"planned altitude"}
    assert "terrain" not in _traces(html, "fm2uav-scene")
    assert "none given (paths only)" in html
    with pytest.raises(ValueError, match="one dimension"):
        report_html(None, {"a": p, "b": p[:, :2]})


def test_notes_come_first_and_the_path_over_filled_ground_is_drawn(slope):
    from fm2uav.viz.overlays import FILLED_PATH_NAME, filled_path_overlay

    h = np.zeros((30, 20))
    filled = np.zeros((30, 20), bool)
    filled[10:20, :] = True
    w = World.from_heightmap(h, 10.0, 6).with_fields(filled=filled)
    path = np.column_stack([np.linspace(0, 290, 59), np.full(59, 95.0), np.full(59, 30.0)])
    ov = filled_path_overlay(w, path)
    pts = ov[FILLED_PATH_NAME]["points"]
    on = pts[np.isfinite(pts[:, 0])]
    assert on[:, 0].min() >= 90.0 - 5.0 - 1e-9 and on[:, 0].max() <= 200.0 + 1e-9
    html = report_html(w, {"FM² path": path}, overlays=ov,
                       notes=["the path flies 0.10 km of 0.29 km over <filled> ground"])
    assert html.index('id="fm2uav-warnings"') < html.index("fm2uav-scene")
    assert "over &lt;filled&gt; ground" in html  # escaped
    assert FILLED_PATH_NAME in _traces(html, "fm2uav-scene")
    assert 'id="fm2uav-warnings"' not in report_html(w, {"FM² path": path})
    assert filled_path_overlay(World.from_heightmap(h, 10.0, 6), path) == {}


def test_3d_view_keeps_the_relief_and_draws_buildings_apart():
    """Terrain with a building: the relief stays coloured as terrain, the building is its own
    grey surface standing on the ground (walls down to it), nothing elsewhere."""
    x = np.arange(31)[:, None] * 10.0
    h = 40.0 + 0.2 * x + np.zeros((31, 21))
    ground = World.from_heightmap(h, 10.0, 20)
    occ = np.array(ground.occupancy)
    occ[12:16, 8:12, :15] = True                   # roof at 140 m
    w = ground.with_fields(occupancy=occ)
    p = np.column_stack([np.linspace(0, 300, 11), np.full(11, 30.0), np.full(11, 150.0)])
    scene = _traces(report_html(w, {"a": p}), "fm2uav-scene")
    terrain, blocks = scene["terrain"], scene["obstacles"]
    def grid(v):
        if isinstance(v, dict):      # plotly's typed array: base64 data and its shape
            shape = [int(n) for n in str(v["shape"]).split(",")]
            return _arr(v).astype(float).reshape(shape)
        return np.array([[np.nan if c is None else c for c in row] for row in v], float)

    tz = grid(terrain["z"])                           # (ny, nx)
    np.testing.assert_allclose(tz, h.T, atol=1e-9)
    bz = grid(blocks["z"])
    assert np.all(bz[8:12, 12:16] == 140.0)          # the roof
    ring = np.isfinite(bz) & (bz < 140.0)
    np.testing.assert_allclose(bz[ring], h.T[ring])  # its walls end on the ground
    assert ring.sum() == 6 * 6 - 4 * 4 and np.isfinite(bz).sum() == 36
