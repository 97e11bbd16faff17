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
from .profile import FirmwareProfile, Problem

__all__ = ["ARDUPILOT", "COPTER_COMMANDS", "PLANE_COMMANDS", "POSITION_FRAMES", "VEHICLE_NAMES",
           "check"]

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


ARDUPILOT = FirmwareProfile(
    name="ardupilot",
    mav_autopilot=3,  # MAV_AUTOPILOT_ARDUPILOTMEGA
    commands={"multirotor": COPTER_COMMANDS, "fixed_wing": PLANE_COMMANDS - VTOL_COMMANDS,
              "vtol": PLANE_COMMANDS},
    position_frames=POSITION_FRAMES,
    terrain_frame=True,
    landing_required=frozenset(),
    rules=(check,),
)
