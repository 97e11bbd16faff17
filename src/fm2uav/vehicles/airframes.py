"""Airframe limits: fixed-wing (Dubins airplane) and multirotor, with named presets.

Fixed-wing (thesis ch. 3, Beard & McLain's Dubins airplane): constant cruise
speed ``V``, bank angle ``|φ| <= φ_max`` (coordinated turn, so the turn rate is
``ψ̇ = g tan φ / V`` and the minimum turn radius ``R = V² / (g tan φ_max)``),
flight-path angle ``-γ_descent <= γ <= γ_climb``. Its admissible speed runs from
the stall (minimum) speed, W = 0, to the maximum speed, W = 1 (thesis §3.2).

Multirotor: horizontal speed ``<= v_max``, acceleration ``<= a_max`` (which
bounds the turn: ``v² κ <= a_max``), vertical speed in ``[-v_descent, v_climb]``.

Presets (:data:`AIRFRAMES`) take their numbers from ArduPilot parameter files
and defaults, so each can be checked at its source (see docs/feasibility.md):

=================  =====  =====  =====  =====  =======  =======  ==========================
fixed-wing          V      Vmin   Vmax   φmax   γclimb   γdesc    source
=================  =====  =====  =====  =====  =======  =======  ==========================
``disco``           14     12     17     55°    30°      25°      ArduPilot Parrot_Disco.param
``crosswind``       20     16     29     35°    22°      25°      ArduPilot MFD_Crosswind_VTOL.param
``plane-jet``       40     25     80     70°    20°      25°      ArduPilot plane-jet.parm
=================  =====  =====  =====  =====  =======  =======  ==========================

(speeds m/s: AIRSPEED_CRUISE / AIRSPEED_MIN / AIRSPEED_MAX; φmax = ROLL_LIMIT_DEG;
γ limits = PTCH_LIM_MAX_DEG / -PTCH_LIM_MIN_DEG, the pitch limits taken as
flight-path-angle limits, i.e. zero angle of attack.)

=================  =====  =====  =======  =======  ==========================
multirotor          vmax   amax   vclimb   vdesc    source
=================  =====  =====  =======  =======  ==========================
``arducopter``      10     2.5    2.5      1.5      ArduCopter AC_WPNav defaults
=================  =====  =====  =======  =======  ==========================

Endurance
---------
Every mission's flight time is checked against an endurance (``airframe.endurance``
/ ``--endurance`` in minutes, with ``airframe.reserve`` kept back). When none is
given, the airframe type's default below is used and the summary says so
(:func:`default_endurance`): the check runs by default and warns where the reserve is
reached; it is a conservative class figure, not your vehicle's — give its own.

==============  =========  =====================================================
type / preset   endurance  rationale
==============  =========  =====================================================
multirotor      20 min     lower end of common survey multirotors: DJI Phantom 4
                           RTK is rated about 30 min, typical ArduPilot quads on a
                           4S 5000 mAh pack fly 15–25 min; rated times are flown
                           without payload or wind
fixed_wing      45 min     Parrot Disco, the smallest fixed-wing preset: rated
                           45 min by its maker
vtol            45 min     lower end of survey VTOLs (WingtraOne GEN II rated
                           59 min); hover phases cost several times cruise power
``disco``       45 min     Parrot's rated flight time
``crosswind``   45 min     the VTOL default (no rated figure in the parameter file)
``plane-jet``   15 min     model turbine jets carry fuel for about 10–15 min
``arducopter``  20 min     the multirotor default
==============  =========  =====================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from ..errors import InputError

__all__ = [
    "G",
    "DEFAULT_ENDURANCE_MIN",
    "default_endurance",
    "AirframeLimits",
    "FixedWing",
    "Multirotor",
    "Airframe",
    "AIRFRAMES",
    "get_airframe",
]

#: Standard gravity [m/s²].
G = 9.80665

#: Default endurance of each airframe type [min] (module docstring, "Endurance").
DEFAULT_ENDURANCE_MIN = {"multirotor": 20.0, "fixed_wing": 45.0, "vtol": 45.0}
_ENDURANCE_WHY = {
    "multirotor": "lower end of common survey multirotors (DJI Phantom 4 RTK rated about "
                  "30 min, ArduPilot quads 15-25 min)",
    "fixed_wing": "Parrot Disco's rated 45 min (the smallest fixed-wing preset)",
    "vtol": "lower end of survey VTOLs (WingtraOne GEN II rated 59 min)",
}


def default_endurance(vehicle: str) -> tuple[float, str]:
    """``(endurance [s], where it comes from)`` of an airframe type without its own.

    Parameters
    ----------
    vehicle : {"multirotor", "fixed_wing", "vtol"}
        The mission's airframe type (``airframe.type``), or a preset name of
        :data:`AIRFRAMES` (its own ``endurance_s``).

    Examples
    --------
    >>> default_endurance("multirotor")[0] / 60
    20.0
    """
    key = str(vehicle).strip().lower()
    preset = AIRFRAMES.get(key.replace("_", "-"))
    if preset is not None and key not in DEFAULT_ENDURANCE_MIN:
        return float(preset.endurance_s), f"preset {preset.name}: {preset.endurance_source}"
    if key not in DEFAULT_ENDURANCE_MIN:
        raise InputError(f"unknown airframe type {vehicle!r}; allowed: "
                         f"{', '.join(DEFAULT_ENDURANCE_MIN)}")
    minutes = DEFAULT_ENDURANCE_MIN[key]
    return 60.0 * minutes, (f"default for a {key.replace('_', '-')}: {minutes:g} min, "
                            f"{_ENDURANCE_WHY[key]}; give your vehicle's with "
                            "airframe.endurance (--endurance)")


def _positive(name: str, value: Any, *, allow_zero: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"airframe {name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        raise InputError(
            f"airframe {name} must be finite and {'>=' if allow_zero else '>'} 0, got {value!r}"
        )
    return v


@dataclass(frozen=True)
class AirframeLimits:
    """The geometric limits a path must keep for an airframe to fly it, in SI.

    Attributes
    ----------
    max_climb : float
        Steepest climb or descent (flight-path) angle [rad], in (0, π/2].
    min_turn_radius : float
        Tightest horizontal turn radius [m], >= 0.

    Examples
    --------
    >>> lim = AirframeLimits.from_degrees(30.0, 60.0)
    >>> round(lim.max_climb, 6), lim.min_turn_radius, round(lim.max_climb_deg, 6)
    (0.523599, 60.0, 30.0)
    >>> get_airframe("disco").limits().min_turn_radius > 0
    True
    """

    max_climb: float
    min_turn_radius: float

    def __post_init__(self) -> None:
        c = _positive("max_climb [rad]", self.max_climb)
        if c > math.pi / 2 + 1e-12:
            raise InputError(f"airframe max_climb must be at most 90 degrees (π/2 rad), got "
                             f"{c:.6g} rad = {math.degrees(c):.6g} degrees")
        object.__setattr__(self, "max_climb", c)
        object.__setattr__(self, "min_turn_radius", _positive(
            "min_turn_radius [m]", self.min_turn_radius, allow_zero=True))

    @classmethod
    def from_degrees(cls, max_climb_deg: float, min_turn_radius: float) -> AirframeLimits:
        """The limits from a climb angle in degrees (CLI, mission files) and a radius [m]."""
        try:
            deg = float(max_climb_deg)
        except (TypeError, ValueError):
            raise InputError(f"max climb must be an angle in degrees, got {max_climb_deg!r}") from None
        if not (math.isfinite(deg) and 0 < deg <= 90):
            raise InputError(f"max climb must be in (0, 90] degrees, got {max_climb_deg!r}")
        return cls(math.radians(deg), min_turn_radius)

    @property
    def max_climb_deg(self) -> float:
        """:attr:`max_climb` in degrees (for display)."""
        return math.degrees(self.max_climb)


@dataclass(frozen=True)
class FixedWing:
    """A fixed-wing UAV flown as a Dubins airplane.

    Attributes
    ----------
    name : str
        Preset or user name.
    cruise_speed : float
        Constant airspeed of the tracking simulation [m/s].
    min_speed : float
        Stall (minimum) speed [m/s]; W = 0 on the speed map.
    max_speed : float
        Maximum speed [m/s]; W = 1.
    max_bank : float
        Maximum bank angle φ_max [rad], in (0, π/2).
    max_climb : float
        Maximum flight-path angle when climbing γ_climb [rad], in (0, π/2).
    max_descent : float
        Maximum flight-path angle when descending (positive number) [rad].
    source : str
        Where the numbers come from.
    endurance_s : float
        Flight time the mission is checked against [s] (module docstring, "Endurance").
    endurance_source : str
        Where that endurance comes from.
    """

    name: str
    cruise_speed: float
    min_speed: float
    max_speed: float
    max_bank: float
    max_climb: float
    max_descent: float
    source: str = ""
    endurance_s: float = 60.0 * DEFAULT_ENDURANCE_MIN["fixed_wing"]
    endurance_source: str = "the fixed-wing default"

    kind = "fixed-wing"

    def __post_init__(self) -> None:
        for attr in ("cruise_speed", "min_speed", "max_speed"):
            object.__setattr__(self, attr, _positive(attr + " [m/s]", getattr(self, attr)))
        object.__setattr__(self, "endurance_s", _positive("endurance_s [s]", self.endurance_s))
        for attr in ("max_bank", "max_climb", "max_descent"):
            v = _positive(attr + " [rad]", getattr(self, attr))
            if v >= math.pi / 2:
                raise InputError(
                    f"airframe {attr} must be below 90 degrees, got {math.degrees(v):.3g} degrees"
                )
            object.__setattr__(self, attr, v)
        if not self.min_speed <= self.cruise_speed <= self.max_speed:
            raise InputError(
                f"airframe {self.name} speeds must satisfy min_speed <= cruise_speed <= "
                f"max_speed, got min_speed {self.min_speed:g}, cruise_speed "
                f"{self.cruise_speed:g}, max_speed {self.max_speed:g} m/s; fix the one out of "
                "order"
            )

    def turn_radius(self, speed: float | None = None) -> float:
        """Minimum turn radius ``R = V² / (g tan φ_max)`` [m] at ``speed`` (default cruise)."""
        v = self.cruise_speed if speed is None else _positive("speed [m/s]", speed)
        return v * v / (G * math.tan(self.max_bank))

    def max_turn_rate(self, speed: float | None = None) -> float:
        """Maximum turn rate ``g tan φ_max / V`` [rad/s] at ``speed`` (default cruise)."""
        v = self.cruise_speed if speed is None else _positive("speed [m/s]", speed)
        return G * math.tan(self.max_bank) / v

    def limits(self) -> AirframeLimits:
        """Path limits: the smaller of the climb and descent angles, the turn radius at cruise."""
        return AirframeLimits(min(self.max_climb, self.max_descent), self.turn_radius())

    def with_speed(self, cruise_speed: float) -> FixedWing:
        """The same airframe flown at another cruise speed [m/s] (validated).

        Raises
        ------
        InputError
            Not a number, or outside the airframe's stall .. maximum speed (names
            ``speed=`` / the CLI's ``--speed`` and the range).
        """
        v = _positive("speed [m/s] (CLI --speed)", cruise_speed)
        if not self.min_speed <= v <= self.max_speed:
            side = ("below its stall (minimum) speed" if v < self.min_speed
                    else "above its maximum speed")
            raise InputError(
                f"speed {v:g} m/s is {side} for the {self.name}; allowed: {self.min_speed:g} <= "
                f"speed <= {self.max_speed:g} m/s (speed= / CLI --speed; or another --airframe)")
        return replace(self, cruise_speed=v)

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers, angles in degrees."""
        return {
            "airframe": self.name,
            "kind": self.kind,
            "cruise_speed_mps": self.cruise_speed,
            "min_speed_mps": self.min_speed,
            "max_speed_mps": self.max_speed,
            "max_bank_deg": round(math.degrees(self.max_bank), 3),
            "max_climb_deg": round(math.degrees(self.max_climb), 3),
            "max_descent_deg": round(math.degrees(self.max_descent), 3),
            "min_turn_radius_m": round(self.turn_radius(), 3),
            "max_turn_rate_dps": round(math.degrees(self.max_turn_rate()), 3),
            "endurance_min": round(self.endurance_s / 60.0, 3),
            "endurance_source": self.endurance_source,
            "source": self.source,
        }


@dataclass(frozen=True)
class Multirotor:
    """A multirotor UAV (point mass with bounded speed and acceleration).

    Attributes
    ----------
    name : str
        Preset or user name.
    max_speed : float
        Maximum horizontal speed [m/s]; W = 1 on the speed map (W = 0: hover).
    max_accel : float
        Maximum acceleration [m/s²] (horizontal and vertical).
    max_climb_rate : float
        Maximum vertical speed up [m/s].
    max_descent_rate : float
        Maximum vertical speed down (positive number) [m/s].
    source : str
        Where the numbers come from.
    endurance_s : float
        Flight time the mission is checked against [s] (module docstring, "Endurance").
    endurance_source : str
        Where that endurance comes from.
    """

    name: str
    max_speed: float
    max_accel: float
    max_climb_rate: float
    max_descent_rate: float
    source: str = ""
    endurance_s: float = 60.0 * DEFAULT_ENDURANCE_MIN["multirotor"]
    endurance_source: str = "the multirotor default"

    kind = "multirotor"

    def __post_init__(self) -> None:
        for attr, unit in (
            ("max_speed", "m/s"),
            ("max_accel", "m/s²"),
            ("max_climb_rate", "m/s"),
            ("max_descent_rate", "m/s"),
            ("endurance_s", "s"),
        ):
            object.__setattr__(self, attr, _positive(f"{attr} [{unit}]", getattr(self, attr)))

    @property
    def cruise_speed(self) -> float:
        """Nominal speed of the tracking simulation: ``max_speed`` [m/s]."""
        return self.max_speed

    def turn_radius(self, speed: float | None = None) -> float:
        """Tightest turn radius ``v² / a_max`` [m] at ``speed`` (default max speed)."""
        v = self.max_speed if speed is None else _positive("speed [m/s]", speed, allow_zero=True)
        return v * v / self.max_accel

    def limits(self) -> AirframeLimits:
        """Path limits: any climb angle (it can climb vertically), the turn radius at max speed."""
        return AirframeLimits(math.pi / 2, self.turn_radius())

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers."""
        return {
            "airframe": self.name,
            "kind": self.kind,
            "max_speed_mps": self.max_speed,
            "max_accel_mps2": self.max_accel,
            "max_climb_rate_mps": self.max_climb_rate,
            "max_descent_rate_mps": self.max_descent_rate,
            "turn_radius_at_max_speed_m": round(self.turn_radius(), 3),
            "endurance_min": round(self.endurance_s / 60.0, 3),
            "endurance_source": self.endurance_source,
            "source": self.source,
        }


Airframe = FixedWing | Multirotor

_ARDU = "ArduPilot Tools/Frame_params"
#: Named presets (see the module docstring for the sources of the numbers).
AIRFRAMES: dict[str, Airframe] = {
    "disco": FixedWing(
        "disco", 14.0, 12.0, 17.0, math.radians(55.0), math.radians(30.0), math.radians(25.0),
        source=f"Parrot Disco, {_ARDU}/Parrot_Disco/Parrot_Disco.param (AIRSPEED_CRUISE/MIN/MAX, "
        "ROLL_LIMIT_DEG, PTCH_LIM_MAX_DEG/PTCH_LIM_MIN_DEG)",
        endurance_s=45 * 60.0, endurance_source="Parrot's rated flight time of the Disco, 45 min",
    ),
    "crosswind": FixedWing(
        "crosswind", 20.0, 16.0, 29.0, math.radians(35.0), math.radians(22.0), math.radians(25.0),
        source=f"MFD Crosswind VTOL in plane mode, {_ARDU}/QuadPlanes/MFD_Crosswind_VTOL.param "
        "(AIRSPEED_*, ROLL_LIMIT_DEG, PTCH_LIM_MAX_DEG); descent 25 deg as the other ArduPilot "
        "plane files (the file leaves PTCH_LIM_MIN_DEG unset)",
        endurance_s=45 * 60.0,
        endurance_source="the VTOL default, 45 min (the parameter file rates no flight time)",
    ),
    "plane-jet": FixedWing(
        "plane-jet", 40.0, 25.0, 80.0, math.radians(70.0), math.radians(20.0), math.radians(25.0),
        source="ArduPilot Tools/autotest/default_params/plane-jet.parm (AIRSPEED_*, ROLL_LIMIT_DEG, "
        "PTCH_LIM_MAX_DEG/PTCH_LIM_MIN_DEG)",
        endurance_s=15 * 60.0,
        endurance_source="model turbine jets carry fuel for about 10-15 min",
    ),
    "arducopter": Multirotor(
        "arducopter", 10.0, 2.5, 2.5, 1.5,
        source="ArduCopter waypoint navigation defaults, libraries/AC_WPNav (WPNAV_SPEED 1000 cm/s, "
        "WPNAV_ACCELERATION 2.5 m/s², WPNAV_SPEED_UP 250 cm/s, WPNAV_SPEED_DN 150 cm/s)",
        endurance_source="the multirotor default, 20 min",
    ),
}


def get_airframe(name: str | Airframe) -> Airframe:
    """The preset called ``name`` (an airframe object is returned unchanged).

    Raises
    ------
    InputError
        Unknown name (the message lists the presets).
    """
    if isinstance(name, (FixedWing, Multirotor)):
        return name
    key = str(name).strip().lower().replace("_", "-")
    if key not in AIRFRAMES:
        raise InputError(
            f"unknown airframe {name!r}; valid presets are: {', '.join(sorted(AIRFRAMES))}"
        )
    return AIRFRAMES[key]
