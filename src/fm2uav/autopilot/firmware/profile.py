"""What fm2uav knows about an autopilot firmware, as data: :class:`FirmwareProfile`.

The idea of QGroundControl's ``FirmwarePlugin`` (``APMFirmwarePlugin``,
``PX4FirmwarePlugin``) and its ``MavCmdInfo*.json`` files: what differs between
firmwares is kept in one object per firmware (:mod:`fm2uav.autopilot.firmware.px4`,
:mod:`~fm2uav.autopilot.firmware.ardupilot`), not in ``if firmware == ...``
branches. The mission builder and the validator ask the profile.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

from .navigation import FixedWingNav, SpeedCommand, merge_nav, merge_speed

__all__ = ["VEHICLES", "VEHICLE_TYPES", "Problem", "Rule", "FirmwareProfile", "both"]

#: Airframe kinds the profiles know (mission file ``airframe.type``, CLI ``--vehicle``).
VEHICLES = ("multirotor", "fixed_wing", "vtol")
#: Airframe kind → MAV_TYPE (``.plan`` ``vehicleType``).
VEHICLE_TYPES = {"fixed_wing": 1, "multirotor": 2, "vtol": 22}


@dataclass(frozen=True)
class Problem:
    """One reason a firmware would reject a mission.

    Attributes
    ----------
    index : int or None
        0-based index of the offending item in the list (None: the whole mission).
    code : str
        Short identifier, e.g. ``"px4-terrain-frame"``.
    message : str
        What is wrong and how to fix it.
    severity : {"error", "warning"}
        ``error``: the firmware rejects or misflies the mission (the export stops);
        ``warning``: it flies it with a deviation the message quantifies.
    """

    index: int | None
    code: str
    message: str
    severity: str = "error"

    @property
    def is_error(self) -> bool:
        """Whether the firmware rejects or misflies the mission (else: a warning that the
        mission flies, with the deviation the message says)."""
        return self.severity == "error"

    def __str__(self) -> str:
        return self.message if self.index is None else f"item {self.index}: {self.message}"


#: A firmware's own mission rule: ``rule(items, vehicle, home_alt=..., max_land_slope_deg=...)``
#: returns the problems that firmware would reject ([] = none).
Rule = Callable[..., list[Problem]]


@dataclass(frozen=True)
class FirmwareProfile:
    """One autopilot firmware as the mission builder and the validator see it.

    Attributes
    ----------
    name : str
        ``"px4"``, ``"ardupilot"``, ... (mission file ``airframe.firmware``, CLI
        ``--firmware``).
    mav_autopilot : int
        ``MAV_AUTOPILOT`` id (``.plan`` ``firmwareType``).
    commands : mapping of str to frozenset of int
        Airframe kind (:data:`VEHICLES`) → the ``MAV_CMD`` ids the firmware flies
        in a mission on it.
    position_frames : frozenset of int
        ``MAV_FRAME`` ids its position items may use.
    terrain_frame : bool
        Whether it flies mission items in ``MAV_FRAME_GLOBAL_TERRAIN_ALT`` (10):
        frame ``auto`` of a terrain-following plan is then ``terrain``, else ``amsl``.
    landing_required : frozenset of str
        Airframe kinds whose missions must contain a landing (PX4
        ``MIS_TKO_LAND_REQ``): an RTL end is followed by a landing at home.
    rules : tuple of Rule
        The firmware's own mission rules, run after the rules of every firmware
        (:func:`fm2uav.autopilot.validate.validate_mission`).
    fixed_wing_nav : FixedWingNav or None
        How it navigates a fixed-wing mission (acceptance, guidance, turn radius,
        climb, airspeeds; :mod:`fm2uav.autopilot.firmware.navigation`).
    change_speed : mapping of str to SpeedCommand
        Airframe kind → what its ``DO_CHANGE_SPEED`` means (speed type, range).
    """

    name: str
    mav_autopilot: int
    commands: Mapping[str, frozenset[int]]
    position_frames: frozenset[int]
    terrain_frame: bool
    landing_required: frozenset[str]
    rules: tuple[Rule, ...]
    fixed_wing_nav: FixedWingNav | None = None
    change_speed: Mapping[str, SpeedCommand] = field(default_factory=dict)


def both(name: str, profiles: Sequence[FirmwareProfile], *, mav_autopilot: int) -> FirmwareProfile:
    """A profile every one of ``profiles`` accepts: the commands and frames they share,
    the landings any of them requires, all their rules (``MAV_AUTOPILOT_GENERIC``)."""
    return FirmwareProfile(
        name=name,
        mav_autopilot=mav_autopilot,
        commands={v: frozenset.intersection(*(p.commands[v] for p in profiles))
                  for v in VEHICLES},
        position_frames=frozenset.intersection(*(p.position_frames for p in profiles)),
        terrain_frame=all(p.terrain_frame for p in profiles),
        landing_required=frozenset.union(*(p.landing_required for p in profiles)),
        rules=tuple(r for p in profiles for r in p.rules),
        fixed_wing_nav=merge_nav(tuple(p.fixed_wing_nav for p in profiles
                                       if p.fixed_wing_nav is not None)),
        change_speed={v: merge_speed(tuple(p.change_speed[v] for p in profiles
                                           if v in p.change_speed))
                      for v in VEHICLES if any(v in p.change_speed for p in profiles)},
    )
