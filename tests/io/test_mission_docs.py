"""The defaults docs/operator.md states for missions are the code's (no hand-copied figures)."""

from pathlib import Path

from fm2uav.autopilot import ExportOptions
from fm2uav.autopilot.build import DEFAULT_CLIMB, DEFAULT_DESCENT, DEFAULT_MIN_SPEED
from fm2uav.io.mission import AirframeSpec, OutputSpec
from fm2uav.autopilot.validate import PX4_FW_LND_ANG

DOC = (Path(__file__).resolve().parents[2] / "docs" / "operator.md").read_text()


def _g(v: float) -> str:
    return f"{v:g}"


def test_landing_pattern_defaults_in_the_guide():
    o = ExportOptions()
    assert f"`land_slope_deg` = {_g(o.land_slope_deg)}°" in DOC
    assert f"`FW_LND_ANG`, default {_g(PX4_FW_LND_ANG)}°" in DOC
    assert o.max_land_slope_deg == PX4_FW_LND_ANG
    assert f"from a loiter {_g(o.land_approach_agl)} m above" in DOC
    assert f"({_g(o.loiter_radius)} m radius" in DOC


def test_speed_and_flight_time_defaults_in_the_guide():
    assert (f"multirotor {_g(DEFAULT_CLIMB['multirotor'])} / {_g(DEFAULT_DESCENT['multirotor'])}, "
            f"fixed-wing {_g(DEFAULT_CLIMB['fixed_wing'])} / {_g(DEFAULT_DESCENT['fixed_wing'])}"
            ) in DOC
    assert ExportOptions().speed_hysteresis == 2 and "allows two steps more" in DOC
    assert f"multirotor {_g(DEFAULT_MIN_SPEED)} m/s" in DOC
    assert f"| `airframe.reserve` | 0 ≤ r < 1 (share of the endurance kept) | " \
           f"{_g(AirframeSpec().reserve)} |" in DOC
    assert f"| `outputs.speed_step` | 0 < step ≤ 20 m/s | {_g(OutputSpec().speed_step)} |" in DOC


def test_the_files_the_guide_lists_are_the_ones_its_run_writes():
    """Section 1 lists the files of `fm2uav run examples/jacksboro_tff.yaml`: exactly the
    example's outputs.formats (path.kmz was listed while the example did not write it)."""
    import re

    from fm2uav.cli.cmd_run import output_names
    from fm2uav.io.mission import load_mission

    section = DOC.split("## 1.", 1)[1].split("## 2.", 1)[0]
    assert "fm2uav run examples/jacksboro_tff.yaml" in section
    table = section.split("| file | what it is |", 1)[1].split("\n\n", 1)[0]
    listed = {name for row in table.splitlines()[2:]
              for name in re.findall(r"`([^`]+)`", row.split("|")[1])}
    example = Path(__file__).resolve().parents[2] / "examples" / "jacksboro_tff.yaml"
    from fm2uav.io.exports import RETURN_FILES

    returns = set(RETURN_FILES.values())  # beside every export; rally files only with rally points
    assert listed - returns == set(output_names(load_mission(example).outputs.formats))
    assert returns <= listed
