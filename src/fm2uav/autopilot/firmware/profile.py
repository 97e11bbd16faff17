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
from typing import Literal

from .names import VEHICLE_TYPES, VEHICLES
from .navigation import FixedWingNav, SpeedCommand, merge_nav, merge_speed

__all__ = ["VEHICLES", "VEHICLE_TYPES", "Problem", "Rule", "Param", "AltitudeParam",
           "ReturnModel", "FirmwareProfile", "both"]


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
class Param:
    """A firmware parameter fm2uav writes (``mission.param``), with the reason.

    Attributes
    ----------
    name : str
        The parameter's name as the firmware spells it.
    value : float
        In the firmware's own unit.
    why : str
        One line: what it makes the firmware do (written as the line's comment).
    """

    name: str
    value: float
    why: str


@dataclass(frozen=True)
class AltitudeParam:
    """The parameter that holds a return altitude, in one firmware version's spelling.

    Attributes
    ----------
    name : str
        e.g. ``RTL_ALT`` (ArduCopter 4.6 and older, cm) or ``RTL_ALT_M`` (4.7+, m).
    per_metre : float
        Its units per metre (100 for centimetres).
    unit : str
        ``"cm"`` or ``"m"``.
    versions : str
        Which firmware versions know this name (a version that does not skips the
        line: MAVProxy and Mission Planner report it as an unknown parameter).
    """

    name: str
    per_metre: float
    unit: str
    versions: str


@dataclass(frozen=True)
class ReturnModel:
    """How one firmware's return mode flies on one airframe, as data (written down from the
    firmware's documentation and flight code; the page of each rule is in ``sources``).

    A return starts where the vehicle is, at its altitude ``z0``, and ends over a
    destination at the return altitude ``A`` (the parameter above ``reference``):

    Attributes
    ----------
    label : str
        ``"ArduCopter"``, ``"ArduPlane"``, ``"PX4 multicopter"``, ...
    climb : {"vertical", "along"}
        Below ``A``: climb over the start point first (``vertical``: Copter, and PX4
        also for fixed-wing, which climbs in a loiter over the start point), or climb
        at the airframe's climb gradient while flying home (``along``: ArduPlane,
        "will immediately climb at maximum allowable rate").
    above : {"keep", "glide"}
        Above ``A``: fly home at the current altitude (``keep``) or descend linearly
        with the distance to reach ``A`` over the destination (``glide``: ArduPlane).
    reference : {"home", "destination"}
        ``A`` is measured above home (ArduPilot) or above the destination's own
        altitude (PX4 ``RTL_RETURN_ALT``: "above destination (e.g. home, safe point,
        landing pattern)").
    destinations : {"home_rally", "landing_rally"}
        Where it returns: the closest of home and the rally points, or (PX4
        fixed-wing / VTOL, ``RTL_TYPE`` 1) the closest of the rally points and the
        start of the mission's landing (home when there is neither).
    rally_altitude : {"transit", "ground"}
        What a rally point's altitude means: the altitude flown to it (ArduPilot:
        "transit / loiter altitude relative to home") or the destination's own
        height (PX4: the return altitude is measured above it).
    altitude : tuple of AltitudeParam
        The return altitude's parameter in every version's spelling.
    min_m, max_m : float or None
        The parameter's range [m] (None: no bound documented).
    settings : tuple of Param
        Written with the altitude: the behaviour the altitude was checked for.
    rally_settings : tuple of Param
        Written when the mission has rally points.
    mission_return : tuple of Param
        Written when no return altitude is safe: they make the firmware's return
        follow the mission's planned safe return instead.
    return_path_start : bool
        The mission-based return marks the route with ``DO_RETURN_PATH_START`` (188)
        right after the takeoff (ArduPilot), so that a return rejoins the mission at
        its closest point and flies it on to the landing.
    mission_note : str
        How that mission-based return is used on this firmware.
    sources : tuple of str
        The documentation pages and source files the rules come from.
    """

    label: str
    climb: Literal["vertical", "along"]
    above: Literal["keep", "glide"]
    reference: Literal["home", "destination"]
    destinations: Literal["home_rally", "landing_rally"]
    rally_altitude: Literal["transit", "ground"]
    altitude: tuple[AltitudeParam, ...]
    min_m: float | None = None
    max_m: float | None = None
    settings: tuple[Param, ...] = ()
    rally_settings: tuple[Param, ...] = ()
    mission_return: tuple[Param, ...] = ()
    return_path_start: bool = False
    mission_note: str = ""
    sources: tuple[str, ...] = ()


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
    returns : mapping of str to tuple of ReturnModel
        Airframe kind → how the firmware's return mode flies it (one model per
        firmware; the generic profile holds both, every one must be safe).
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
    returns: Mapping[str, tuple[ReturnModel, ...]] = field(default_factory=dict)
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
        returns={v: tuple(m for p in profiles for m in p.returns.get(v, ())) for v in VEHICLES},
        fixed_wing_nav=merge_nav(tuple(p.fixed_wing_nav for p in profiles
                                       if p.fixed_wing_nav is not None)),
        change_speed={v: merge_speed(tuple(p.change_speed[v] for p in profiles
                                           if v in p.change_speed))
                      for v in VEHICLES if any(v in p.change_speed for p in profiles)},
    )
