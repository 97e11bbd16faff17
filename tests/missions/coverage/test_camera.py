import pytest

from fm2uav import InputError
from fm2uav.missions.coverage import Camera, band_spacing


def test_footprint_and_spacing_analytic():
    # 1" sensor 13.2 x 8.8 mm, f = 8.8 mm, 5472 x 3648 px at 100 m:
    # GSD = 13.2e-3 * 100 / (8.8e-3 * 5472) m/px, footprint 150 x 100 m
    cam = Camera(13.2e-3, 8.8e-3, 8.8e-3, 5472, 3648)
    assert cam.gsd(100.0) == pytest.approx(13.2e-3 * 100 / (8.8e-3 * 5472))
    across, along = cam.footprint(100.0)
    assert across == pytest.approx(150.0)
    assert along == pytest.approx(100.0)
    assert band_spacing(cam, 100.0, 0.7) == pytest.approx(45.0)
    assert cam.trigger_distance(100.0, 0.8) == pytest.approx(20.0)
    portrait = Camera(13.2e-3, 8.8e-3, 8.8e-3, 5472, 3648, landscape=False)
    assert portrait.footprint(100.0) == pytest.approx((100.0, 150.0))


def test_bad_camera():
    with pytest.raises(InputError):
        Camera(0, 1e-3, 1e-3, 10, 10)
    cam = Camera(13.2e-3, 8.8e-3, 8.8e-3, 5472, 3648)
    with pytest.raises(InputError):
        cam.spacing(100.0, 1.0)
    with pytest.raises(InputError):
        cam.gsd(-1)
