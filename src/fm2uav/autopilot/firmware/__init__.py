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

A new firmware is one module here defining its profile, its name in
:data:`~fm2uav.autopilot.firmware.names.FIRMWARES` (read by the mission schema and the
command line without building a profile) and one entry in :data:`PROFILES`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..._lazy import lazy_names
from .names import FIRMWARES, VEHICLE_TYPES, VEHICLES, check_vehicle

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562): the names above build nothing
    from .ardupilot import ARDUPILOT
    from .profile import FirmwareProfile, Problem, Rule, both
    from .px4 import PX4
    from .registry import FIRMWARE_TYPES, GENERIC, PROFILES, firmware_profile, supported_commands

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

__getattr__, __dir__ = lazy_names(__name__, {
    "PX4": ".px4", "ARDUPILOT": ".ardupilot",
    "FirmwareProfile": ".profile", "Problem": ".profile", "Rule": ".profile", "both": ".profile",
    "PROFILES": ".registry", "GENERIC": ".registry", "FIRMWARE_TYPES": ".registry",
    "firmware_profile": ".registry", "supported_commands": ".registry",
})
