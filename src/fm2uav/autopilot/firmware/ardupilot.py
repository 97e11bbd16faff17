"""ArduPilot: the mission commands and frames of Copter, Plane and QuadPlane, as a profile.

Sources: ArduPilot wiki "Mission Commands", the commands handled by
``ArduCopter/mode_auto.cpp`` and ``ArduPlane/commands_logic.cpp``. The commands
of the vehicle (Copter has no ``NAV_LOITER_TO_ALT``, ``DO_LAND_START`` or VTOL
items; VTOL items need a QuadPlane); position items in frame 0, 3 or 10 (and
5/6/11) — ArduPilot flies terrain-frame items from its terrain database
(``TERRAIN_ENABLE``), so a terrain-following plan is written in that frame; no
``NAV_TAKEOFF`` in the terrain frame (ArduPilot issue #20142: the altitude
target jumps when the terrain under the vehicle differs from the takeoff point's).
Copter and Plane both keep ``DO_LAND_START`` (189) and ``DO_RETURN_PATH_START``
(188) as markers of a mission's landing and return path (ArduPilot wiki "Using
DO_RETURN_PATH_START Mission Command", copied to the Plane and Copter wikis).

**Returns** (:data:`COPTER_RETURN`, :data:`PLANE_RETURN`, used by
:mod:`fm2uav.autopilot.returns`):

* Copter RTL (``ArduCopter/mode_rtl.cpp`` ``compute_return_target``; wiki
  "RTL Mode"): the return target is the closest of home and the rally points
  (``AP_Rally::calc_best_rally_or_home_location``; home competes only with
  ``RALLY_INCL_HOME`` = 1, a far rally point only within ``RALLY_LIMIT_KM``, 0 =
  no limit); the target altitude above home is ``max(rally altitude, RTL_ALT,
  current altitude + RTL_CLIMB_MIN)``, reduced near the target by the cone
  ``RTL_CONE_SLOPE`` (0 disables it) and never below the current altitude; the
  vehicle climbs over its position first, flies straight to the target at that
  altitude, then descends (``RTL_ALT_FINAL`` = 0: lands). ``RTL_ALT`` is in
  centimetres up to Copter 4.6; Copter 4.7 renamed it ``RTL_ALT_M`` in metres
  (ArduPilot PR #31970, "SI param conversion for RTL and LAND parameters").
  ``RTL_ALT_TYPE`` = 1 (terrain) follows the terrain database, and falls back to
  above home when the data are missing ("RTL: no terrain data, using
  alt-above-home"), so it is not what fm2uav sets.
* Plane RTL (wiki "RTL Mode", Plane parameter ``RTL_ALTITUDE``): "When initiated
  below RTL_ALTITUDE, Plane will immediately climb at maximum allowable rate to
  reach that altitude, if above, it will descend in a linear manner versus
  distance to home, reaching that altitude at the home loiter point";
  ``RTL_ALTITUDE`` (m, relative to home) since Plane 4.5, ``ALT_HOLD_RTL`` (cm)
  before; "if not returning home, the rally point altitude is used".
* Mission-based returns: ``DO_RETURN_PATH_START`` marks a return path; "the
  vehicle would return to the mission path, proceed to the waypoint after the
  DO_LAND_START tag and LAND"; "In Plane, set RTL_AUTOLAND to 4 to use this. In
  Copter, set any failsafe action to DO_LAND_START" (``FS_THR_ENABLE`` /
  ``BATT_FS_LOW_ACT`` = 6, "Auto DO_LAND_START or RTL"; the AUTO RTL flight mode,
  27, does the same on a switch). Copter's SmartRTL (``FS_*`` 4/5) retraces the
  flown path instead, but falls back to RTL (or a landing in place) when its path
  memory (``SRTL_POINTS``) is full.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..items import FRAME_TERRAIN, TAKEOFF_COMMANDS, VTOL_COMMANDS, MissionItem
from .flight_rules import fixed_wing_rules, speed_rules
from .navigation import FixedWingNav, SpeedCommand
from .profile import AltitudeParam, FirmwareProfile, Param, Problem, ReturnModel

__all__ = ["ARDUPILOT", "COPTER_COMMANDS", "PLANE_COMMANDS", "POSITION_FRAMES",
           "VEHICLE_NAMES", "COPTER_RETURN", "PLANE_RETURN", "PLANE_NAV", "PLANE_SPEED",
           "COPTER_SPEED", "check"]

#: ArduCopter mode_auto.cpp and ArduPlane commands_logic.cpp (ArduPilot wiki lists).
COPTER_COMMANDS = frozenset({
    16, 17, 18, 19, 20, 21, 22, 93, 112, 114, 115, 177, 178, 179, 183, 188, 189, 201, 203,
    205, 206,
})
PLANE_COMMANDS = frozenset({
    16, 17, 18, 19, 20, 21, 22, 31, 84, 85, 93, 112, 114, 177, 178, 179, 183, 188, 189, 201,
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


_SOURCES = (
    "ArduCopter/mode_rtl.cpp (compute_return_target)",
    "https://ardupilot.org/copter/docs/rtl-mode.html",
    "https://ardupilot.org/plane/docs/rtl-mode.html",
    "https://ardupilot.org/copter/docs/common-rally-points.html",
    "https://ardupilot.org/plane/docs/common-do-return-path-start.html",
    "ArduPilot PR #31970 (Copter 4.7: RTL_ALT -> RTL_ALT_M)",
)
_RALLY = (
    Param("RALLY_INCL_HOME", 1, "home competes with the rally points: the closest one is the "
          "return target, as checked"),
    Param("RALLY_LIMIT_KM", 0, "no distance limit: the closest rally point is always a "
          "candidate, as checked"),
)
#: ArduCopter's RTL (module docstring).
COPTER_RETURN = ReturnModel(
    label="ArduCopter", climb="vertical", above="keep", reference="home",
    destinations="home_rally", rally_altitude="transit",
    altitude=(AltitudeParam("RTL_ALT", 100.0, "cm", "Copter 4.6 and older"),
              AltitudeParam("RTL_ALT_M", 1.0, "m", "Copter 4.7 and newer")),
    min_m=2.0, max_m=3000.0,
    settings=(Param("RTL_ALT_TYPE", 0, "return altitude above home (terrain following "
                    "falls back to above home without terrain data)"),
              Param("RTL_CONE_SLOPE", 0, "no cone: the checked return altitude holds from "
                    "everywhere, also close to home")),
    rally_settings=_RALLY,
    mission_return=(Param("FS_THR_ENABLE", 6, "radio failsafe: Auto DO_LAND_START or RTL "
                          "(joins the mission's planned return)"),
                    Param("BATT_FS_LOW_ACT", 6, "low battery: Auto DO_LAND_START or RTL "
                          "(joins the mission's planned return)")),
    return_path_start=True,
    mission_note="ArduCopter: a failsafe with action 6 (Auto DO_LAND_START) rejoins the "
                 "mission at its closest point after DO_RETURN_PATH_START and flies it to the "
                 "landing; use the AUTO RTL flight mode (27) instead of RTL on the RTL switch — "
                 "RTL mode itself still flies the straight line",
    sources=_SOURCES,
)
#: ArduPlane's (and QuadPlane's) RTL (module docstring).
PLANE_RETURN = ReturnModel(
    label="ArduPlane", climb="along", above="glide", reference="home",
    destinations="home_rally", rally_altitude="transit",
    altitude=(AltitudeParam("ALT_HOLD_RTL", 100.0, "cm", "Plane 4.4 and older"),
              AltitudeParam("RTL_ALTITUDE", 1.0, "m", "Plane 4.5 and newer")),
    min_m=0.0, max_m=None,
    rally_settings=_RALLY,
    mission_return=(Param("RTL_AUTOLAND", 4, "RTL goes directly to the landing sequence via "
                          "DO_RETURN_PATH_START: it rejoins the mission's planned return"),),
    return_path_start=True,
    mission_note="ArduPlane: RTL_AUTOLAND = 4 makes RTL (and every failsafe that triggers "
                 "it) rejoin the mission at its closest point after DO_RETURN_PATH_START and "
                 "fly it to the DO_LAND_START landing",
    sources=_SOURCES,
)
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
    returns={"multirotor": (COPTER_RETURN,), "fixed_wing": (PLANE_RETURN,),
             "vtol": (PLANE_RETURN,)},
)
