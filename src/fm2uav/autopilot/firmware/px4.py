"""PX4: the mission commands, frames and rules of its mission checks, as a profile.

Sources: ``MavlinkMissionManager::parse_mavlink_mission_item`` in
``src/modules/mavlink/mavlink_mission.cpp`` and ``FeasibilityChecker`` in
``src/modules/navigator/MissionFeasibility/``. Position items in
``MAV_FRAME_GLOBAL`` (0) or ``MAV_FRAME_GLOBAL_RELATIVE_ALT`` (3) (or their
``_INT`` forms 5/6) only — frame 10 is ``MAV_MISSION_UNSUPPORTED_FRAME``, so a
terrain-following plan is written in AMSL; commands without a position (RTL,
DO_*) in ``MAV_FRAME_MISSION`` (2); only the commands the feasibility checker
accepts (``NAV_LOITER_TURNS`` is not one); VTOL items only on VTOL airframes;
fixed-wing and VTOL missions must contain a landing (``MIS_TKO_LAND_REQ``
defaults to 2 for both); at most one ``DO_LAND_START``, never before an RTL
item, and before the landing approach; a fixed-wing ``NAV_LAND`` approached
from a ``NAV_WAYPOINT`` or ``NAV_LOITER_TO_ALT`` above it, outside that
loiter's radius, with a glide slope no steeper than ``FW_LND_ANG`` (default 5 deg).

**Returns** (:data:`MC_RETURN`, :data:`FW_RETURN`; PX4 user guide "Return Mode
(Generic Vehicle)", ``src/modules/navigator/rtl.cpp`` ``computeReturnAltitude`` and
``rtl_direct.cpp``): the vehicle climbs over its position to the return altitude
(a fixed-wing in a loiter there: ``setLoiterToAltMissionItem`` at the current
position), flies straight to the destination at that altitude and descends there
to ``RTL_DESCEND_ALT``. Without the cone (``RTL_CONE_ANG`` = 0) the return
altitude is ``max(current altitude, destination altitude + RTL_RETURN_ALT)``:
``RTL_RETURN_ALT`` (m) is "above destination (e.g. home, safe point, landing
pattern)". The destination: ``RTL_TYPE`` 0 (multicopter default) "the closest
rally point or home"; 1 (fixed-wing and VTOL default) "a rally point or the start
of a mission landing pattern (whichever is closest)", home when there is neither.
Mission-based: ``RTL_TYPE`` 2 "uses the mission path": in mission mode the mission
is continued fast-forward to its landing (``DO_LAND_START`` ... ``NAV_LAND``),
skipping non-position items; outside mission mode the vehicle first flies
straight to the closest mission waypoint.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..items import (
    CMD_DO_LAND_START,
    CMD_NAV_LAND,
    CMD_NAV_LOITER_TO_ALT,
    CMD_NAV_RETURN_TO_LAUNCH,
    CMD_NAV_VTOL_LAND,
    CMD_NAV_WAYPOINT,
    FRAME_GLOBAL,
    FRAME_MISSION,
    FRAME_NAMES,
    FRAME_RELATIVE,
    FRAME_TERRAIN,
    VTOL_COMMANDS,
    MissionItem,
    distance_m,
)
from .flight_rules import fixed_wing_rules, speed_rules
from .navigation import FixedWingNav, SpeedCommand
from .profile import VEHICLES, AltitudeParam, FirmwareProfile, Param, Problem, ReturnModel

__all__ = ["PX4", "COMMANDS", "POSITION_FRAMES", "FW_LND_ANG", "MC_RETURN", "FW_RETURN",
           "FW_NAV", "FW_SPEED", "MC_SPEED", "check"]

#: PX4 FeasibilityChecker::checkMissionItemValidity (the commands fm2uav may meet).
COMMANDS = frozenset({
    16, 17, 19, 20, 21, 22, 31, 84, 85, 93, 177, 178, 179, 189, 201, 203, 205, 206,
    214, 530, 2000, 2001, 2500, 2501, 3000,
})
#: MAV_FRAMEs of position items (mavlink_mission.cpp).
POSITION_FRAMES = frozenset({0, 3, 5, 6})
#: PX4's default maximum fixed-wing landing slope, FW_LND_ANG [deg].
FW_LND_ANG = 5.0


def _amsl(item: MissionItem, home_alt: float | None) -> float | None:
    """AMSL altitude of a position item from what is uploaded (frame + param 7); the
    terrain frame needs the ground, known only from the item's ``alt_amsl`` record."""
    if item.frame in (FRAME_GLOBAL, 5):
        return item.alt
    if item.frame in (FRAME_RELATIVE, 6):
        return None if home_alt is None else item.alt + home_alt
    return item.alt_amsl


def check(items: Sequence[MissionItem], vehicle: str, *, home_alt: float | None,
          max_land_slope_deg: float = FW_LND_ANG, **_: object) -> list[Problem]:
    """The problems PX4 would reject or misfly in ``items`` on a ``vehicle`` (module docstring)."""
    out: list[Problem] = []
    allowed = PX4.commands[vehicle]
    for i, it in enumerate(items):
        if it.command not in allowed:
            why = (" (VTOL items need a VTOL airframe)" if it.command in VTOL_COMMANDS else "")
            out.append(Problem(i, "px4-command", f"{it.name} is not a mission command PX4 "
                               f"accepts on a {vehicle}{why}"))
        if it.has_position and it.frame not in POSITION_FRAMES:
            hint = ("PX4 does not fly terrain-frame mission items (mavlink_mission.cpp answers "
                    "MAV_MISSION_UNSUPPORTED_FRAME); use outputs.frame: amsl or auto "
                    "(--frame amsl), which writes AMSL altitudes from the DEM"
                    if it.frame in (FRAME_TERRAIN, 11) else "PX4 takes frames 0 and 3 only")
            out.append(Problem(i, "px4-terrain-frame" if it.frame in (10, 11) else "px4-frame",
                               f"{it.name} uses {FRAME_NAMES.get(it.frame, it.frame)}; {hint}"))
        if not it.has_position and it.frame != FRAME_MISSION:
            out.append(Problem(i, "px4-frame", f"{it.name} must use MAV_FRAME_MISSION (2) on PX4 "
                               f"(got frame {it.frame})"))
    land_start = [i for i, it in enumerate(items) if it.command == CMD_DO_LAND_START]
    lands = [i for i, it in enumerate(items) if it.command in (CMD_NAV_LAND, CMD_NAV_VTOL_LAND)]
    if len(land_start) > 1:
        out.append(Problem(land_start[1], "px4-land-start", "more than one DO_LAND_START; "
                           "PX4 allows one"))
    rtls = [i for i, it in enumerate(items) if it.command == CMD_NAV_RETURN_TO_LAUNCH]
    if land_start and any(r > land_start[0] for r in rtls):
        out.append(Problem(land_start[0], "px4-land-before-rtl", "DO_LAND_START before an "
                           "RTL item is rejected by PX4"))
    if land_start and (not lands or land_start[0] > lands[-1] - 1):
        out.append(Problem(land_start[0], "px4-land-start", "DO_LAND_START must come before "
                           "the landing approach item and its NAV_LAND"))
    if lands and lands[0] == 0:
        out.append(Problem(0, "px4-starts-landing", "the mission starts with a landing"))
    if vehicle in PX4.landing_required and not lands:
        out.append(Problem(None, "px4-landing-required", f"PX4 {vehicle.replace('_', '-')} "
                           "missions need a landing (MIS_TKO_LAND_REQ defaults to 2): use "
                           "outputs.end: land or rtl (--end), which add one"))
    if vehicle == "fixed_wing":
        for i in lands:
            out += _fw_landing(items, i, home_alt, max_land_slope_deg)
    return out


def _fw_landing(items: Sequence[MissionItem], i: int, home_alt: float | None,
                    max_slope_deg: float) -> list[Problem]:
    land = items[i]
    prev = next((items[k] for k in range(i - 1, -1, -1) if items[k].has_position), None)
    if prev is None:
        return [Problem(i, "px4-fw-approach", "NAV_LAND has no approach item before it")]
    if prev.command not in (CMD_NAV_WAYPOINT, CMD_NAV_LOITER_TO_ALT):
        return [Problem(i, "px4-fw-approach", f"NAV_LAND is approached from {prev.name}; PX4 "
                        "takes only NAV_WAYPOINT or NAV_LOITER_TO_ALT")]
    a_land, a_prev = _amsl(land, home_alt), _amsl(prev, home_alt)
    if a_land is None or a_prev is None:
        return []
    rel = a_prev - a_land
    if not rel > 0:
        return [Problem(i, "px4-fw-approach", f"the approach item is {rel:.1f} m above the "
                        "landing point; it must be above it")]
    d = distance_m(prev.lat, prev.lon, land.lat, land.lon)
    if prev.command == CMD_NAV_LOITER_TO_ALT:
        r = abs(prev.params[1])
        if d <= r:
            return [Problem(i, "px4-fw-approach", f"the landing point is {d:.0f} m from the "
                            f"loiter centre, inside its {r:.0f} m radius")]
        d = math.sqrt(d * d - r * r)
    slope = math.degrees(math.atan2(rel, d))
    if slope > max_slope_deg + 0.1:
        return [Problem(i, "px4-fw-glide-slope", f"the landing glide slope is {slope:.1f} deg, "
                        f"steeper than FW_LND_ANG = {max_slope_deg:g} deg")]
    return []


_SOURCES = (
    "https://docs.px4.io/main/en/flight_modes/return.html",
    "src/modules/navigator/rtl.cpp (computeReturnAltitude)",
    "src/modules/navigator/rtl_direct.cpp (CLIMBING: loiter to altitude at the position)",
)
_ALT = (AltitudeParam("RTL_RETURN_ALT", 1.0, "m", "every version"),)
_NO_CONE = Param("RTL_CONE_ANG", 0, "no cone: the checked return altitude holds from "
                 "everywhere, also close to the destination")
_MISSION = (Param("RTL_TYPE", 2, "mission path: in a mission the vehicle continues it "
                  "fast-forward to its landing, which carries the planned safe return"),)
_NOTE = ("PX4: RTL_TYPE = 2 makes Return follow the mission to its landing (in mission mode; "
         "from another mode it first flies straight to the closest mission waypoint)")
#: PX4's return of a multicopter (module docstring).
MC_RETURN = ReturnModel(
    label="PX4 multicopter", climb="vertical", above="keep", reference="destination",
    destinations="home_rally", rally_altitude="ground", altitude=_ALT, min_m=0.0,
    settings=(Param("RTL_TYPE", 0, "home/rally point return: straight to the closest of home "
                    "and the rally points, as checked"), _NO_CONE),
    mission_return=_MISSION, mission_note=_NOTE, sources=_SOURCES,
)
#: PX4's return of a fixed-wing or VTOL (module docstring).
FW_RETURN = ReturnModel(
    label="PX4 fixed-wing", climb="vertical", above="keep", reference="destination",
    destinations="landing_rally", rally_altitude="ground", altitude=_ALT, min_m=0.0,
    settings=(Param("RTL_TYPE", 1, "mission landing / rally point return: straight to the "
                    "closest of the rally points and the mission landing, as checked"),
              _NO_CONE),
    mission_return=_MISSION, mission_note=_NOTE, sources=_SOURCES,
)
#: PX4's fixed-wing navigation defaults (parameter reference): NAV_ACC_RAD 10 m,
#: NAV_LOITER_RAD 80 m, FW_R_LIM 50 deg, NPFG_PERIOD 10 s, NPFG_DAMPING 0.7,
#: FW_T_CLMB_MAX / FW_T_SINK_MAX 5 m/s, FW_AIRSPD_MIN 10, FW_AIRSPD_TRIM 15,
#: FW_AIRSPD_MAX 20 m/s, FW_LND_ANG 5 deg. A waypoint counts as reached within the larger
#: of NAV_ACC_RAD and the guidance's switch distance (Navigator::get_acceptance_radius).
FW_NAV = FixedWingNav(
    label="PX4 fixed-wing", acceptance_radius=10.0, loiter_radius=80.0, bank_limit_deg=50.0,
    guidance_period=10.0, guidance_damping=0.7, climb_rate=5.0, sink_rate=5.0,
    airspeed_min=10.0, airspeed_cruise=15.0, airspeed_max=20.0, takeoff_pitch_deg=15.0,
    takeoff_alt=50.0, turn_distance_rule="switch", landing_slope_max_deg=FW_LND_ANG,
    names={"acceptance_radius": "NAV_ACC_RAD", "loiter_radius": "NAV_LOITER_RAD",
           "bank_limit_deg": "FW_R_LIM", "guidance_period": "NPFG_PERIOD",
           "guidance_damping": "NPFG_DAMPING", "climb_rate": "FW_T_CLMB_MAX",
           "sink_rate": "FW_T_SINK_MAX", "airspeed_min": "FW_AIRSPD_MIN",
           "airspeed_cruise": "FW_AIRSPD_TRIM", "airspeed_max": "FW_AIRSPD_MAX",
           "takeoff_alt": "MIS_TAKEOFF_ALT"},
    sources=("https://docs.px4.io/main/en/advanced_config/parameter_reference.html",
             "https://docs.px4.io/main/en/flight_modes_fw/mission.html",
             "https://docs.px4.io/main/en/flight_modes_fw/takeoff.html",
             "src/modules/navigator/navigator_main.cpp (get_acceptance_radius)"),
)
#: PX4's DO_CHANGE_SPEED: the navigator sets the cruising speed from param2 (airspeed on a
#: fixed-wing, ground speed on a multicopter, as MAVLink's speed type names them).
FW_SPEED = SpeedCommand(speed_type=0, accepted=(0,), ignored_outside=False,
                        default="FW_AIRSPD_TRIM",
                        source="PX4 navigator (VEHICLE_CMD_DO_CHANGE_SPEED)")
MC_SPEED = SpeedCommand(speed_type=1, accepted=(1,), ignored_outside=False,
                        default="MPC_XY_CRUISE",
                        source="PX4 navigator (VEHICLE_CMD_DO_CHANGE_SPEED)")

PX4 = FirmwareProfile(
    name="px4",
    mav_autopilot=12,  # MAV_AUTOPILOT_PX4
    commands={v: COMMANDS if v == "vtol" else COMMANDS - VTOL_COMMANDS for v in VEHICLES},
    position_frames=POSITION_FRAMES,
    terrain_frame=False,
    landing_required=frozenset({"fixed_wing", "vtol"}),  # MIS_TKO_LAND_REQ = 2
    rules=(check, speed_rules({"multirotor": MC_SPEED, "fixed_wing": FW_SPEED, "vtol": FW_SPEED},
                              FW_NAV, "PX4"),
           fixed_wing_rules(FW_NAV, "PX4")),
    fixed_wing_nav=FW_NAV,
    change_speed={"multirotor": MC_SPEED, "fixed_wing": FW_SPEED, "vtol": FW_SPEED},
    returns={"multirotor": (MC_RETURN,), "fixed_wing": (FW_RETURN,), "vtol": (FW_RETURN,)},
)
