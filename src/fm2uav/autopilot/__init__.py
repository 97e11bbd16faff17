"""The mission as the autopilot sees it: MAVLink items, firmware rules, legs, fences.

:func:`build_mission` turns a planned path into the one list of MAVLink items
(:class:`MissionItem`, :mod:`fm2uav.autopilot.items`) every mission file is
written from: takeoff, waypoints (:mod:`~fm2uav.autopilot.waypoints`:
altitudes per frame, Douglas–Peucker thinning in :mod:`~fm2uav.autopilot.thin`,
straight legs checked against the world in :mod:`~fm2uav.autopilot.legs`),
speeds, camera triggers and the end (RTL / landing / loiter), checked by the
validator (:mod:`~fm2uav.autopilot.validate`) against the firmware's profile
(:mod:`~fm2uav.autopilot.firmware`: one module per firmware, what it flies kept
as data). Geofences from the world's zones: :mod:`~fm2uav.autopilot.geofence`.
This layer computes; it reads and writes no file (the formats are :mod:`fm2uav.io`).
"""

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562)
    from .build import (
        ENDS,
        CameraPlan,
        ExportOptions,
        MissionExport,
        build_mission,
        speed_commands,
        start_holds,
    )
    from .firmware import (
        FIRMWARES,
        PROFILES,
        VEHICLES,
        FirmwareProfile,
        Problem,
        firmware_profile,
        supported_commands,
    )
    from .geofence import (
        Fence,
        FenceCircle,
        FencePolygon,
        as_fences,
        fences_from_world,
        zone_fences,
    )
    from .items import MissionItem, command_name
    from .legs import refine_legs
    from .thin import thin_indices, thin_path
    from .validate import check_mission, validate_mission
    from .waypoints import FRAMES, Waypoints, altitude_profile, mission_waypoints, resolve_frame

#: Where each public name lives: ``import fm2uav.autopilot.items`` (what the rally and
#: mission-file readers need) loads none of the mission builder's imports (numba, shapely).
__getattr__, __dir__ = lazy_names(__name__, {
    "ENDS": ".build",
    "CameraPlan": ".build",
    "ExportOptions": ".build",
    "MissionExport": ".build",
    "build_mission": ".build",
    "speed_commands": ".build",
    "start_holds": ".build",
    "FIRMWARES": ".firmware",
    "PROFILES": ".firmware",
    "VEHICLES": ".firmware",
    "FirmwareProfile": ".firmware",
    "Problem": ".firmware",
    "firmware_profile": ".firmware",
    "supported_commands": ".firmware",
    "Fence": ".geofence",
    "FenceCircle": ".geofence",
    "FencePolygon": ".geofence",
    "as_fences": ".geofence",
    "fences_from_world": ".geofence",
    "zone_fences": ".geofence",
    "MissionItem": ".items",
    "command_name": ".items",
    "refine_legs": ".legs",
    "thin_indices": ".thin",
    "thin_path": ".thin",
    "check_mission": ".validate",
    "validate_mission": ".validate",
    "FRAMES": ".waypoints",
    "Waypoints": ".waypoints",
    "altitude_profile": ".waypoints",
    "mission_waypoints": ".waypoints",
    "resolve_frame": ".waypoints",
})

__all__ = [
    # building
    "build_mission",
    "ExportOptions",
    "MissionExport",
    "CameraPlan",
    "speed_commands",
    "start_holds",
    "ENDS",
    # items
    "MissionItem",
    "command_name",
    # waypoints and legs
    "Waypoints",
    "mission_waypoints",
    "altitude_profile",
    "resolve_frame",
    "FRAMES",
    "thin_path",
    "thin_indices",
    "refine_legs",
    # firmware profiles and rules
    "FIRMWARES",
    "PROFILES",
    "VEHICLES",
    "FirmwareProfile",
    "firmware_profile",
    "Problem",
    "validate_mission",
    "check_mission",
    "supported_commands",
    # geofences
    "Fence",
    "FencePolygon",
    "FenceCircle",
    "fences_from_world",
    "as_fences",
    "zone_fences",
]
