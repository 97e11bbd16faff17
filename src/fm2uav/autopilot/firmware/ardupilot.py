"""ArduPilot: the mission commands and frames of Copter, Plane and QuadPlane, as a profile.

Sources: ArduPilot wiki "Mission Commands", the commands handled by
``ArduCopter/mode_auto.cpp`` and ``ArduPlane/commands_logic.cpp``. The commands
of the vehicle (Copter has no ``NAV_LOITER_TO_ALT``, ``DO_LAND_START`` or VTOL
items; VTOL items need a QuadPlane); position items in frame 0, 3 or 10 (and
5/6/11) — ArduPilot flies terrain-frame items from its terrain database
(``TERRAIN_ENABLE``), so a terrain-following plan is written in that frame; no
``NAV_TAKEOFF`` in the terrain frame (ArduPilot issue #20142: the altitude
target jumps when the terrain under the vehicle differs from the takeoff point's).
"""

from __future__ import annotations

from collections.abc import Sequence

from ..items import FRAME_TERRAIN, TAKEOFF_COMMANDS, VTOL_COMMANDS, MissionItem
from .flight_rules import fixed_wing_rules, speed_rules
from .navigation import FixedWingNav, SpeedCommand
from .profile import FirmwareProfile, Problem

__all__ = ["ARDUPILOT", "COPTER_COMMANDS", "PLANE_COMMANDS", "POSITION_FRAMES", "VEHICLE_NAMES",
           "PLANE_NAV", "PLANE_SPEED", "COPTER_SPEED", "check"]

#: ArduCopter mode_auto.cpp and ArduPlane commands_logic.cpp (ArduPilot wiki lists).
COPTER_COMMANDS = frozenset({
    16, 17, 18, 19, 20, 21, 22, 93, 112, 114, 115, 177, 178, 179, 183, 201, 203, 205, 206,
})
PLANE_COMMANDS = frozenset({
    16, 17, 18, 19, 20, 21, 22, 31, 84, 85, 93, 112, 114, 177, 178, 179, 183, 189, 201,
    203, 205, 206, 3000,
})
#: MAV_FRAMEs of position items.
POSITION_FRAMES = frozenset({0, 3, 5, 6, 10, 11})
#: Airframe kind → the ArduPilot vehicle that flies it.
VEHICLE_NAMES = {"multirotor": "Copter", "fixed_wing": "Plane", "vtol": "QuadPlane"}


def check(items: Sequence[MissionItem], vehicle: str, **_: object) -> list[Problem]:
    """The problems ArduPilot would reject or misfly in ``items`` on a ``vehicle`` (module
    docstring)."""
    out: list[Problem] = []
    allowed = ARDUPILOT.commands[vehicle]
    kind = VEHICLE_NAMES[vehicle]
    for i, it in enumerate(items):
        if it.command not in allowed:
            out.append(Problem(i, "ardupilot-command", f"{it.name} is not a mission command "
                               f"ArduPilot {kind} flies"))
        if it.has_position and it.frame not in POSITION_FRAMES:
            out.append(Problem(i, "ardupilot-frame", f"{it.name} uses frame {it.frame}; "
                               "ArduPilot missions take frames 0, 3 and 10"))
        if it.command in TAKEOFF_COMMANDS and it.frame in (FRAME_TERRAIN, 11):
            out.append(Problem(i, "ardupilot-terrain-takeoff", f"{it.name} in the terrain "
                               "frame: ArduPilot's altitude target jumps when the terrain "
                               "under the vehicle differs from the takeoff point's (ArduPilot "
                               "issue #20142); write the takeoff above home (frame 3)"))
    return out


#: ArduPlane's navigation defaults (ArduPlane/config.h, Parameters.cpp, AP_L1_Control,
#: AP_TECS): WP_RADIUS 90 m, WP_LOITER_RAD 60 m, ROLL_LIMIT_DEG 45, NAVL1_PERIOD 17 s,
#: NAVL1_DAMPING 0.75, TECS_CLMB_MAX / TECS_SINK_MAX 5 m/s, AIRSPEED_MIN 9,
#: AIRSPEED_CRUISE 12, AIRSPEED_MAX 22 m/s, TKOFF_ALT 50 m.
PLANE_NAV = FixedWingNav(
    label="ArduPlane", acceptance_radius=90.0, loiter_radius=60.0, bank_limit_deg=45.0,
    guidance_period=17.0, guidance_damping=0.75, climb_rate=5.0, sink_rate=5.0,
    airspeed_min=9.0, airspeed_cruise=12.0, airspeed_max=22.0, takeoff_pitch_deg=15.0,
    takeoff_alt=50.0, turn_distance_rule="l1", landing_slope_max_deg=None,
    names={"acceptance_radius": "WP_RADIUS", "loiter_radius": "WP_LOITER_RAD",
           "bank_limit_deg": "ROLL_LIMIT_DEG", "guidance_period": "NAVL1_PERIOD",
           "guidance_damping": "NAVL1_DAMPING", "climb_rate": "TECS_CLMB_MAX",
           "sink_rate": "TECS_SINK_MAX", "airspeed_min": "AIRSPEED_MIN",
           "airspeed_cruise": "AIRSPEED_CRUISE", "airspeed_max": "AIRSPEED_MAX",
           "takeoff_alt": "TKOFF_ALT"},
    sources=("https://ardupilot.org/plane/docs/parameters.html#wp-radius",
             "https://ardupilot.org/plane/docs/navigation-tuning.html (L1 controller)",
             "https://ardupilot.org/plane/docs/common-mavlink-mission-command-messages-mav_cmd"
             ".html",
             "https://ardupilot.org/plane/docs/automatic-landing.html",
             "libraries/AP_L1_Control/AP_L1_Control.cpp (turn_distance, L1 distance)",
             "ArduPlane/commands_logic.cpp (do_takeoff, verify_nav_wp, verify_loiter_to_alt, "
             "do_change_speed)"),
)
#: ArduPlane's DO_CHANGE_SPEED (Plane::do_change_speed): type 0 sets the target airspeed,
#: and only between AIRSPEED_MIN and AIRSPEED_MAX (else it is ignored); type 1 sets
#: MIN_GROUNDSPEED, not the speed flown.
PLANE_SPEED = SpeedCommand(
    speed_type=0, accepted=(0,), ignored_outside=True,
    other_type="speed type 1 (ground speed) sets MIN_GROUNDSPEED on ArduPlane, not the speed "
               "flown",
    default="AIRSPEED_CRUISE",
    source="ArduPlane/commands_logic.cpp Plane::do_change_speed")
#: ArduCopter's DO_CHANGE_SPEED (ModeAuto::do_change_speed): types 0 and 1 set the
#: horizontal speed (WPNAV_SPEED), 2 the climb and 3 the descent speed.
COPTER_SPEED = SpeedCommand(
    speed_type=1, accepted=(0, 1), ignored_outside=False,
    other_type="speed types 2/3 set ArduCopter's climb/descent speed, not the horizontal speed",
    default="WPNAV_SPEED",
    source="ArduCopter/mode_auto.cpp ModeAuto::do_change_speed")

ARDUPILOT = FirmwareProfile(
    name="ardupilot",
    mav_autopilot=3,  # MAV_AUTOPILOT_ARDUPILOTMEGA
    commands={"multirotor": COPTER_COMMANDS, "fixed_wing": PLANE_COMMANDS - VTOL_COMMANDS,
              "vtol": PLANE_COMMANDS},
    position_frames=POSITION_FRAMES,
    terrain_frame=True,
    landing_required=frozenset(),
    rules=(check, speed_rules({"multirotor": COPTER_SPEED, "fixed_wing": PLANE_SPEED,
                               "vtol": PLANE_SPEED}, PLANE_NAV, "ArduPilot"),
           fixed_wing_rules(PLANE_NAV, "ArduPlane")),
    fixed_wing_nav=PLANE_NAV,
    change_speed={"multirotor": COPTER_SPEED, "fixed_wing": PLANE_SPEED, "vtol": PLANE_SPEED},
)
