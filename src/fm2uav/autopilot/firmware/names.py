"""The names of the firmwares and airframes, without their profiles (light: nothing to build).

The mission file's schema (:mod:`fm2uav.io.mission`) and the command line check a
firmware or airframe name against these before any profile is built; the profiles
themselves are in :mod:`~fm2uav.autopilot.firmware.registry`, which refuses to load when
its names and :data:`FIRMWARES` differ.
"""

from __future__ import annotations

from ...errors import InputError

__all__ = ["FIRMWARES", "VEHICLES", "VEHICLE_TYPES", "check_vehicle"]

#: Firmware names the checkers know (mission file ``airframe.firmware``, CLI ``--firmware``),
#: in the order of :data:`fm2uav.autopilot.firmware.registry.PROFILES`.
FIRMWARES = ("px4", "ardupilot", "generic")
#: Airframe kinds the profiles know (mission file ``airframe.type``, CLI ``--vehicle``).
VEHICLES = ("multirotor", "fixed_wing", "vtol")
#: Airframe kind → MAV_TYPE (``.plan`` ``vehicleType``).
VEHICLE_TYPES = {"fixed_wing": 1, "multirotor": 2, "vtol": 22}


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
