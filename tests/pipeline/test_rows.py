"""fm2uav.pipeline.rows: the printed rows say what the summary says (issue 25: the 120 m
advice, a home whose altitude above sea level is unknown)."""

from types import SimpleNamespace

from fm2uav.pipeline.rows import mission_rows, safety_rows


def _mission(alt):
    return SimpleNamespace(summary=lambda: {
        "firmware": "px4", "vehicle": "multirotor", "items": 8, "waypoints": 7, "end": "land",
        "frame": {"name": "relative" if alt is None else "amsl",
                  "mav_frame": 3 if alt is None else 0},
        "home": {"lat": 40.3790621, "lon": -3.7060042, "alt_amsl_m": alt, "source": "ground"},
        "flight": {"flight_distance_m": 540.0, "flight_time_s": 120.0},
        "speed_changes": {"items": 0, "speeds_mps": []}, "warnings": ["w"]})


def test_home_altitude_unknown_is_said_never_printed_as_a_number():
    assert mission_rows(_mission(None))["home lat, lon, alt"] == (
        "40.3790621, -3.7060042, altitude above sea level unknown (ground)")
    assert mission_rows(_mission(650.0))["home lat, lon, alt"] == (
        "40.3790621, -3.7060042, 650.0 m AMSL (ground)")


def test_every_safety_warning_gets_a_row():
    rows = safety_rows({"warnings": ["the path flies up to 130.0 m above the ground", "b"]})
    assert rows["safety warning 1"] == "the path flies up to 130.0 m above the ground"
    assert rows["safety warning 2"] == "b"
    assert not any(k.startswith("safety warning") for k in safety_rows({"warnings": []}))
