"""The firmware profiles by name: :data:`PROFILES`, :func:`firmware_profile`.

Importing this module builds the profiles (:mod:`~fm2uav.autopilot.firmware.px4`,
:mod:`~fm2uav.autopilot.firmware.ardupilot` and :data:`GENERIC`); the names alone, which the
mission file's schema and the command line check, are in
:mod:`~fm2uav.autopilot.firmware.names` and load nothing.
"""

from __future__ import annotations

from ...errors import InputError
from .ardupilot import ARDUPILOT
from .names import FIRMWARES, check_vehicle
from .profile import FirmwareProfile, both
from .px4 import PX4

__all__ = ["GENERIC", "PROFILES", "FIRMWARE_TYPES", "firmware_profile", "supported_commands"]

#: MAV_AUTOPILOT_GENERIC: a mission both PX4 and ArduPilot accept.
GENERIC = both("generic", (PX4, ARDUPILOT), mav_autopilot=0)
#: Firmware name → profile.
PROFILES: dict[str, FirmwareProfile] = {p.name: p for p in (PX4, ARDUPILOT, GENERIC)}
if tuple(PROFILES) != FIRMWARES:  # the light list the mission schema and the CLI read
    raise ImportError(f"fm2uav.autopilot.firmware.names.FIRMWARES {FIRMWARES} differs from "
                      f"the profiles {tuple(PROFILES)}: add the new firmware's name there")
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


def supported_commands(firmware: str, vehicle: str) -> frozenset[int]:
    """``MAV_CMD`` ids the firmware flies in a mission on that airframe."""
    profile = firmware_profile(firmware)
    return profile.commands[check_vehicle(vehicle)]
