"""Autopilot firmwares as profiles: one module per firmware, what it flies kept as data.

A :class:`FirmwareProfile` holds what differs between firmwares — its
``MAV_AUTOPILOT`` id, the mission commands it flies on each airframe, the frames
of its position items, whether it flies terrain-frame items, the airframes that
must land in a mission, and its own mission rules — so that the mission builder
(:mod:`fm2uav.autopilot.build`), the frame choice
(:func:`fm2uav.autopilot.waypoints.resolve_frame`) and the validator
(:mod:`fm2uav.autopilot.validate`) ask the profile instead of branching on the
firmware's name (QGroundControl's ``FirmwarePlugin`` / ``MavCmdInfo`` JSON idea).

* :data:`PX4` (:mod:`~fm2uav.autopilot.firmware.px4`),
* :data:`ARDUPILOT` (:mod:`~fm2uav.autopilot.firmware.ardupilot`),
* :data:`GENERIC` (``MAV_AUTOPILOT_GENERIC``): what both accept, with both sets
  of rules.

A new firmware is one module here defining its profile, and one entry in
:data:`PROFILES`.
"""

from __future__ import annotations

from ...errors import InputError
from .ardupilot import ARDUPILOT
from .profile import VEHICLE_TYPES, VEHICLES, FirmwareProfile, Problem, Rule, both
from .px4 import PX4

__all__ = [
    "PROFILES",
    "FIRMWARES",
    "FIRMWARE_TYPES",
    "VEHICLES",
    "VEHICLE_TYPES",
    "PX4",
    "ARDUPILOT",
    "GENERIC",
    "FirmwareProfile",
    "Problem",
    "Rule",
    "firmware_profile",
    "check_vehicle",
    "supported_commands",
]

#: MAV_AUTOPILOT_GENERIC: a mission both PX4 and ArduPilot accept.
GENERIC = both("generic", (PX4, ARDUPILOT), mav_autopilot=0)
#: Firmware name → profile.
PROFILES: dict[str, FirmwareProfile] = {p.name: p for p in (PX4, ARDUPILOT, GENERIC)}
#: Firmware names the checkers know.
FIRMWARES = tuple(PROFILES)
#: Firmware name → MAV_AUTOPILOT (``.plan`` ``firmwareType``).
FIRMWARE_TYPES = {name: p.mav_autopilot for name, p in PROFILES.items()}


def firmware_profile(firmware: str) -> FirmwareProfile:
    """The profile of ``firmware``.

    Raises
    ------
    InputError
        An unknown firmware, naming the mission-file key and CLI flag.
    """
    if firmware not in PROFILES:
        raise InputError(f"firmware must be one of {', '.join(FIRMWARES)}, got {firmware!r} "
                         "(mission file airframe.firmware, CLI --firmware)")
    return PROFILES[firmware]


def check_vehicle(vehicle: str) -> str:
    """``vehicle`` if it is an airframe kind the profiles know (:data:`VEHICLES`).

    Raises
    ------
    InputError
        An unknown airframe kind, naming the mission-file key and CLI flag.
    """
    if vehicle not in VEHICLES:
        raise InputError(f"vehicle must be one of {', '.join(VEHICLES)}, got {vehicle!r} "
                         "(mission file airframe.type, CLI --vehicle)")
    return vehicle


def supported_commands(firmware: str, vehicle: str) -> frozenset[int]:
    """``MAV_CMD`` ids the firmware flies in a mission on that airframe."""
    profile = firmware_profile(firmware)
    return profile.commands[check_vehicle(vehicle)]
