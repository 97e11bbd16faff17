"""Worlds from pictures and ROS map_server maps (exact pixel -> node cases)."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from fm2uav.errors import InputError, WorldError
from fm2uav.world.images import occupancy_from_pixels, world_from_image, world_from_ros_map


def _pgm(path, rows):
    Image.fromarray(np.asarray(rows, dtype=np.uint8), mode="L").save(path)
    return path


def test_pixels_to_ix_iy_orientation():
    # row 0 = top of the map; a black pixel at the top-left is node (0, ny-1)
    px = np.full((3, 4), 255, float)
    px[0, 0] = 0
    occ = occupancy_from_pixels(px)
    assert occ.shape == (4, 3)
    assert occ[0, 2] and occ.sum() == 1


def test_ros_trinary_thresholds_and_unknown(tmp_path):
    # p = (255 - x) / 255: 0 -> 1.0 occupied, 254 -> 0.004 free, 128 -> 0.498 unknown
    _pgm(tmp_path / "m.pgm", [[0, 254, 128]])
    (tmp_path / "m.yaml").write_text(
        "image: m.pgm\nresolution: 0.05\norigin: [-1.0, 2.0, 0.0]\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n"
    )
    w = world_from_ros_map(tmp_path / "m.yaml")
    assert w.shape == (3, 1)
    assert w.occupancy[:, 0].tolist() == [True, False, True]  # unknown is an obstacle
    w_free = world_from_ros_map(tmp_path / "m.yaml", unknown="free")
    assert w_free.occupancy[:, 0].tolist() == [True, False, False]
    # pixel centres: origin + res/2
    assert w.origin == pytest.approx((-1.0 + 0.025, 2.0 + 0.025))
    assert w.spacing == pytest.approx((0.05, 0.05))


def test_ros_negate_and_raw(tmp_path):
    _pgm(tmp_path / "n.png", [[0, 255]])
    (tmp_path / "n.yaml").write_text("image: n.png\nresolution: 1\norigin: [0, 0, 0]\nnegate: 1\n")
    assert world_from_ros_map(tmp_path / "n.yaml").occupancy[:, 0].tolist() == [False, True]
    _pgm(tmp_path / "r.pgm", [[0, 100, 255, 10]])
    (tmp_path / "r.yaml").write_text("image: r.pgm\nresolution: 1\norigin: [0, 0, 0]\nmode: raw\n")
    assert world_from_ros_map(tmp_path / "r.yaml").occupancy[:, 0].tolist() == [False, True, True, False]


def test_ros_map_plans(tmp_path):
    from fm2uav import plan

    img = np.full((20, 30), 254, np.uint8)
    img[:, 14:16] = 0
    img[2:5, 14:16] = 254  # a gap near the top of the picture (large y)
    _pgm(tmp_path / "wall.pgm", img)
    (tmp_path / "wall.yaml").write_text("image: wall.pgm\nresolution: 0.5\norigin: [0, 0, 0]\n")
    w = world_from_ros_map(tmp_path / "wall.yaml")
    p = plan(w, (2.0, 2.0), (13.0, 2.0))
    assert p.path[:, 1].max() > 7.0  # had to go up through the gap


@pytest.mark.parametrize(
    "yaml_text, fragment",
    [
        ("image: m.pgm\nresolution: 0.05\n", "lacks the key(s) origin"),
        ("image: m.pgm\nresolution: -1\norigin: [0,0,0]\n", "resolution must be a positive"),
        ("image: m.pgm\nresolution: 1\norigin: [0,0,0.5]\n", "yaw 0.5 is not 0"),
        ("image: m.pgm\nresolution: 1\norigin: [0,0,0]\nfree_thresh: 2\n", "free_thresh must be a number in [0, 1]"),
        ("image: m.pgm\nresolution: 1\norigin: [0,0,0]\nmode: weird\n", "mode must be"),
        ("image: nothere.pgm\nresolution: 1\norigin: [0,0,0]\n", "no such file"),
        ("- just\n- a list\n", "must be a mapping"),
        ("image: [unclosed\n", "not valid YAML"),
    ],
)
def test_ros_map_bad_input(tmp_path, yaml_text, fragment):
    _pgm(tmp_path / "m.pgm", [[0, 254]])
    (tmp_path / "m.yaml").write_text(yaml_text)
    with pytest.raises(InputError, match=None) as exc:
        world_from_ros_map(tmp_path / "m.yaml")
    assert fragment in str(exc.value)


def test_image_world_and_errors(tmp_path):
    rgb = np.full((2, 3, 3), 255, np.uint8)
    rgb[1, 2] = (10, 10, 10)
    Image.fromarray(rgb, mode="RGB").save(tmp_path / "c.png")
    w = world_from_image(tmp_path / "c.png", 2.0)
    assert w.occupancy.tolist() == [[False, False], [False, False], [True, False]]
    assert w.origin == pytest.approx((1.0, 1.0))
    (tmp_path / "bad.png").write_bytes(b"not an image")
    with pytest.raises(InputError, match="not an image"):
        world_from_image(tmp_path / "bad.png", 1.0)
    with pytest.raises(InputError, match="resolution"):
        world_from_image(tmp_path / "c.png", 0)
    with pytest.raises(InputError, match="not a regular file"):
        world_from_image(tmp_path, 1.0)
    Image.fromarray(np.zeros((2, 2), np.uint8), mode="L").save(tmp_path / "black.png")
    with pytest.raises(WorldError, match="no free pixel"):
        world_from_image(tmp_path / "black.png", 1.0)


def test_world_classmethods(tmp_path):
    from fm2uav import World

    _pgm(tmp_path / "m.pgm", [[0, 254]])
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 1\norigin: [0, 0, 0]\n")
    assert World.from_ros_map(tmp_path / "m.yaml").shape == (2, 1)
    assert World.from_image(tmp_path / "m.pgm", 1.0).occupancy[:, 0].tolist() == [True, False]
