"""MAVLink mission items: the commands and frames fm2uav writes, one item type.

Every mission format (QGroundControl ``.plan``, ``QGC WPL 110``) is written from
one list of :class:`MissionItem`, so the formats cannot disagree. Numbers are
those of MAVLink's ``common.xml`` (``MAV_CMD``, ``MAV_FRAME``):

==========================  ====  ===============================================
command                     id    params used (p1..p4; p5..p7 = lat, lon, alt)
==========================  ====  ===============================================
``NAV_WAYPOINT``            16    p1 hold [s], p4 yaw [deg] (NaN: keep heading)
``NAV_LOITER_UNLIM``        17    p3 radius [m] (0: firmware default), p4 yaw
``NAV_RETURN_TO_LAUNCH``    20    none (frame 2)
``NAV_LAND``                21    p4 yaw (NaN)
``NAV_TAKEOFF``             22    p1 minimum pitch [deg] (fixed-wing), p4 yaw (NaN)
``NAV_LOITER_TO_ALT``       31    p1 heading required, p2 radius [m], p4 exit
``NAV_VTOL_TAKEOFF``        84    p2 transition heading mode, p4 yaw (NaN)
``NAV_VTOL_LAND``           85    p4 yaw (NaN)
``DO_CHANGE_SPEED``         178   p1 speed type (0 air, 1 ground), p2 speed [m/s],
                                  p3 throttle (-1: no change) (frame 2)
``DO_LAND_START``           189   none (frame 2): marks the start of a landing
``DO_SET_CAM_TRIGG_DIST``   206   p1 distance [m] (0: stop), p3 trigger once now
==========================  ====  ===============================================

Frames: ``MAV_FRAME_GLOBAL`` (0, altitude above mean sea level),
``MAV_FRAME_MISSION`` (2, no position: DO commands and RTL),
``MAV_FRAME_GLOBAL_RELATIVE_ALT`` (3, above home), ``MAV_FRAME_GLOBAL_TERRAIN_ALT``
(10, above the terrain under the item).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

__all__ = [
    "FRAME_GLOBAL",
    "FRAME_MISSION",
    "FRAME_RELATIVE",
    "FRAME_TERRAIN",
    "FRAME_NAMES",
    "CMD_NAV_WAYPOINT",
    "CMD_NAV_LOITER_UNLIM",
    "CMD_NAV_LOITER_TURNS",
    "CMD_NAV_LOITER_TIME",
    "CMD_NAV_RETURN_TO_LAUNCH",
    "CMD_NAV_LAND",
    "CMD_NAV_TAKEOFF",
    "CMD_NAV_LOITER_TO_ALT",
    "CMD_NAV_VTOL_TAKEOFF",
    "CMD_NAV_VTOL_LAND",
    "CMD_DO_JUMP",
    "CMD_DO_CHANGE_SPEED",
    "CMD_DO_LAND_START",
    "CMD_DO_SET_CAM_TRIGG_DIST",
    "COMMAND_NAMES",
    "POSITION_COMMANDS",
    "TAKEOFF_COMMANDS",
    "END_COMMANDS",
    "VTOL_COMMANDS",
    "MissionItem",
    "command_name",
    "distance_m",
]

#: MAV_FRAME_GLOBAL: altitude above mean sea level.
FRAME_GLOBAL = 0
#: MAV_FRAME_MISSION: not a coordinate frame (commands without a position).
FRAME_MISSION = 2
#: MAV_FRAME_GLOBAL_RELATIVE_ALT: altitude above home.
FRAME_RELATIVE = 3
#: MAV_FRAME_GLOBAL_TERRAIN_ALT: altitude above the terrain under the item.
FRAME_TERRAIN = 10

FRAME_NAMES = {
    0: "MAV_FRAME_GLOBAL",
    2: "MAV_FRAME_MISSION",
    3: "MAV_FRAME_GLOBAL_RELATIVE_ALT",
    5: "MAV_FRAME_GLOBAL_INT",
    6: "MAV_FRAME_GLOBAL_RELATIVE_ALT_INT",
    10: "MAV_FRAME_GLOBAL_TERRAIN_ALT",
    11: "MAV_FRAME_GLOBAL_TERRAIN_ALT_INT",
}

CMD_NAV_WAYPOINT = 16
CMD_NAV_LOITER_UNLIM = 17
CMD_NAV_LOITER_TURNS = 18
CMD_NAV_LOITER_TIME = 19
CMD_NAV_RETURN_TO_LAUNCH = 20
CMD_NAV_LAND = 21
CMD_NAV_TAKEOFF = 22
CMD_NAV_LOITER_TO_ALT = 31
CMD_NAV_VTOL_TAKEOFF = 84
CMD_NAV_VTOL_LAND = 85
CMD_DO_JUMP = 177
CMD_DO_CHANGE_SPEED = 178
CMD_DO_LAND_START = 189
CMD_DO_SET_CAM_TRIGG_DIST = 206

COMMAND_NAMES = {
    16: "NAV_WAYPOINT",
    17: "NAV_LOITER_UNLIM",
    18: "NAV_LOITER_TURNS",
    19: "NAV_LOITER_TIME",
    20: "NAV_RETURN_TO_LAUNCH",
    21: "NAV_LAND",
    22: "NAV_TAKEOFF",
    31: "NAV_LOITER_TO_ALT",
    84: "NAV_VTOL_TAKEOFF",
    85: "NAV_VTOL_LAND",
    93: "NAV_DELAY",
    112: "CONDITION_DELAY",
    114: "CONDITION_DISTANCE",
    115: "CONDITION_YAW",
    177: "DO_JUMP",
    178: "DO_CHANGE_SPEED",
    179: "DO_SET_HOME",
    183: "DO_SET_SERVO",
    189: "DO_LAND_START",
    201: "DO_SET_ROI",
    203: "DO_DIGICAM_CONTROL",
    205: "DO_MOUNT_CONTROL",
    206: "DO_SET_CAM_TRIGG_DIST",
    214: "DO_SET_CAM_TRIGG_INTERVAL",
    530: "SET_CAMERA_MODE",
    2000: "IMAGE_START_CAPTURE",
    2001: "IMAGE_STOP_CAPTURE",
    3000: "DO_VTOL_TRANSITION",
}

#: Commands whose params 5..7 are a position (latitude, longitude, altitude).
POSITION_COMMANDS = frozenset({16, 17, 18, 19, 21, 22, 31, 84, 85})
#: A mission's first navigation item.
TAKEOFF_COMMANDS = frozenset({22, 84})
#: A mission's last navigation item: RTL, land, VTOL land or loiter for ever.
END_COMMANDS = frozenset({20, 21, 85, 17})
#: Commands only a VTOL airframe flies (VTOL takeoff / land, transition).
VTOL_COMMANDS = frozenset({84, 85, 3000})


def command_name(command: int) -> str:
    """``"NAV_WAYPOINT (16)"`` for 16; ``"MAV_CMD 1234"`` for unknown ids."""
    name = COMMAND_NAMES.get(int(command))
    return f"{name} ({int(command)})" if name else f"MAV_CMD {int(command)}"


def distance_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Great-circle distance [m] (haversine, mean Earth radius)."""
    r = 6371008.8
    p1, p2 = math.radians(lat1), math.radians(lat2)
    dp, dl = p2 - p1, math.radians(lon2 - lon1)
    a = math.sin(dp / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return 2 * r * math.asin(min(1.0, math.sqrt(a)))


def _num(v: Any) -> float:
    return float("nan") if v is None else float(v)


@dataclass(frozen=True)
class MissionItem:
    """One MAVLink mission item (``MISSION_ITEM``: command, frame, 7 params).

    Attributes
    ----------
    command : int
        ``MAV_CMD`` id.
    frame : int
        ``MAV_FRAME`` id (2 for commands without a position).
    params : tuple of 7 float
        param1..param4, then latitude [deg], longitude [deg], altitude [m]
        (in ``frame``). NaN where the protocol means "unset" (QGC writes
        ``null``, WPL writes ``nan``).
    autocontinue : bool
        Go on with the next item when this one completes.
    agl : float or None
        Height above the ground (the DEM, bilinear) of a position item [m], for
        reports and QGC's altitude display; None for items without a position.
    alt_amsl : float or None
        Altitude above mean sea level of a position item [m].
    label : str
        What the item is for (``"takeoff"``, ``"via 1"``, ``"band 3 start"``, ...).
    """

    command: int
    frame: int
    params: tuple[float, float, float, float, float, float, float]
    autocontinue: bool = True
    agl: float | None = None
    alt_amsl: float | None = None
    label: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        p = tuple(_num(v) for v in self.params)
        if len(p) != 7:
            raise ValueError(f"a mission item has 7 params, got {len(p)}")
        object.__setattr__(self, "params", p)
        object.__setattr__(self, "command", int(self.command))
        object.__setattr__(self, "frame", int(self.frame))

    @classmethod
    def at(cls, command: int, frame: int, lat: float, lon: float, alt: float, *,
           p1: float = 0.0, p2: float = 0.0, p3: float = 0.0, p4: float = math.nan,
           agl: float | None = None, alt_amsl: float | None = None,
           label: str = "") -> MissionItem:
        """A position item at ``lat``, ``lon`` [deg] and ``alt`` [m in ``frame``]."""
        return cls(command, frame, (p1, p2, p3, p4, lat, lon, alt), agl=agl,
                   alt_amsl=alt_amsl, label=label)

    @classmethod
    def do(cls, command: int, p1: float = 0.0, p2: float = 0.0, p3: float = 0.0,
           p4: float = 0.0, *, label: str = "") -> MissionItem:
        """A command without a position (frame 2, params 5..7 = 0)."""
        return cls(command, FRAME_MISSION, (p1, p2, p3, p4, 0.0, 0.0, 0.0), label=label)

    @property
    def has_position(self) -> bool:
        """Whether params 5..7 are a position."""
        return self.command in POSITION_COMMANDS

    @property
    def lat(self) -> float:
        """Latitude [deg] (param5)."""
        return self.params[4]

    @property
    def lon(self) -> float:
        """Longitude [deg] (param6)."""
        return self.params[5]

    @property
    def alt(self) -> float:
        """Altitude in the item's frame [m] (param7)."""
        return self.params[6]

    @property
    def name(self) -> str:
        """Command name with its id, e.g. ``"NAV_TAKEOFF (22)"``."""
        return command_name(self.command)

    def with_label(self, label: str) -> MissionItem:
        """The same item with another label."""
        return replace(self, label=label)
