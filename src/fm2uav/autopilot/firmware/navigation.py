"""How a firmware navigates a mission, as data: guidance, acceptance, climb and speed limits.

A :class:`FixedWingNav` holds the numbers a fixed-wing autopilot flies a mission
with — its waypoint acceptance (ArduPlane ``WP_RADIUS``, PX4 ``NAV_ACC_RAD``),
the lateral guidance that sets where a turn starts (ArduPlane's L1 controller
``NAVL1_PERIOD`` / ``NAVL1_DAMPING``, PX4's NPFG ``NPFG_PERIOD`` /
``NPFG_DAMPING``), the bank limit that sets the turn radius (``ROLL_LIMIT_DEG``,
``FW_R_LIM``), the loiter radius (``WP_LOITER_RAD``, ``NAV_LOITER_RAD``), the total
energy controller's climb and sink limits (``TECS_CLMB_MAX`` / ``TECS_SINK_MAX``,
``FW_T_CLMB_MAX`` / ``FW_T_SINK_MAX``) and the airspeed range a ``DO_CHANGE_SPEED``
may command (``AIRSPEED_MIN`` .. ``AIRSPEED_MAX``, ``FW_AIRSPD_MIN`` ..
``FW_AIRSPD_MAX``) — each firmware's defaults in its own module
(:data:`fm2uav.autopilot.firmware.ardupilot.PLANE_NAV`,
:data:`fm2uav.autopilot.firmware.px4.FW_NAV`), the airframe's own numbers laid
over them by :meth:`FixedWingNav.with_airframe`.

The formulas are the firmware's (ArduPilot ``libraries/AP_L1_Control``):

* L1 distance ``L1 = (1/π) ζ T V`` (damping ζ, period T, ground speed V);
* turn distance (where a waypoint counts as reached before it):
  ``min(WP_RADIUS, L1) · min(Δψ, 90°) / 90°`` for a turn of Δψ at the waypoint
  (``AP_L1_Control::turn_distance``), or when the aircraft crosses the line
  through the waypoint perpendicular to the leg (ArduPlane ``verify_nav_wp``,
  "Passed waypoint");
* coordinated turn radius ``R = V² / (g tan φ_max)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from ...errors import InputError

__all__ = ["G", "AirframeNav", "FixedWingNav", "SpeedCommand", "merge_nav", "merge_speed"]

#: Standard gravity [m/s²].
G = 9.80665


@dataclass(frozen=True)
class SpeedCommand:
    """What a firmware does with ``DO_CHANGE_SPEED`` (178) on one airframe.

    Attributes
    ----------
    speed_type : int
        The param1 written: 0 airspeed (fixed-wing), 1 ground speed (multirotor).
    accepted : tuple of int
        The param1 values it takes as the horizontal speed (ArduCopter: 0 and 1).
    ignored_outside : bool
        Whether a speed outside the airframe's range is ignored (ArduPlane: only
        ``AIRSPEED_MIN`` <= speed <= ``AIRSPEED_MAX`` is taken, ``Plane::do_change_speed``).
    other_type : str
        What the other speed type does instead (for the validator's message).
    default : str
        The parameter it flies without a ``DO_CHANGE_SPEED`` (``AIRSPEED_CRUISE``,
        ``WPNAV_SPEED``, ...).
    source : str
        Where the rule is written.
    """

    speed_type: int
    accepted: tuple[int, ...] = ()
    ignored_outside: bool = False
    other_type: str = ""
    default: str = "its default speed"
    source: str = ""


@dataclass(frozen=True)
class AirframeNav:
    """The airframe's own navigation numbers, laid over a firmware's defaults (None: the
    firmware's default; mission file ``airframe:`` keys / CLI flags).

    Attributes
    ----------
    cruise : float or None
        Cruise (forward) airspeed [m/s] (``airframe.cruise_speed``).
    minimum, maximum : float or None
        Airspeed range [m/s] (``airframe.min_speed`` / ``max_speed``).
    bank_deg : float or None
        Bank limit [deg] (``airframe.max_bank``).
    climb_rate, sink_rate : float or None
        Climb and sink limits [m/s] (``airframe.climb_rate`` / ``descent_rate``).
    """

    cruise: float | None = None
    minimum: float | None = None
    maximum: float | None = None
    bank_deg: float | None = None
    climb_rate: float | None = None
    sink_rate: float | None = None


@dataclass(frozen=True)
class FixedWingNav:
    """A fixed-wing autopilot's navigation numbers (module docstring), SI units.

    Attributes
    ----------
    label : str
        ``"ArduPlane"``, ``"PX4 fixed-wing"``.
    acceptance_radius : float
        Waypoint radius [m] (``WP_RADIUS``; PX4 ``NAV_ACC_RAD``).
    loiter_radius : float
        Default loiter radius [m] (``WP_LOITER_RAD``; ``NAV_LOITER_RAD``).
    bank_limit_deg : float
        Bank limit of the navigation [deg] (``ROLL_LIMIT_DEG``; ``FW_R_LIM``).
    guidance_period : float
        Period of the lateral guidance [s] (``NAVL1_PERIOD``; ``NPFG_PERIOD``).
    guidance_damping : float
        Its damping (``NAVL1_DAMPING``; ``NPFG_DAMPING``).
    climb_rate, sink_rate : float
        TECS climb and sink limits [m/s] (``TECS_CLMB_MAX`` / ``TECS_SINK_MAX``;
        ``FW_T_CLMB_MAX`` / ``FW_T_SINK_MAX``).
    airspeed_min, airspeed_cruise, airspeed_max : float
        The airspeeds [m/s] (``AIRSPEED_MIN`` / ``AIRSPEED_CRUISE`` /
        ``AIRSPEED_MAX``; ``FW_AIRSPD_MIN`` / ``FW_AIRSPD_TRIM`` / ``FW_AIRSPD_MAX``).
    takeoff_pitch_deg : float
        Minimum pitch of the ``NAV_TAKEOFF`` climb [deg] (param1 written).
    takeoff_alt : float
        Height of the straight take-off climb before a loiter climb [m] (``TKOFF_ALT``).
    turn_distance_rule : {"l1", "switch"}
        Where a waypoint counts as reached: ``l1`` (ArduPlane,
        ``AP_L1_Control::turn_distance``): ``min(WP_RADIUS, L1) · min(Δψ, 90°)/90°``;
        ``switch`` (PX4: the larger of ``NAV_ACC_RAD`` and the guidance's switch
        distance, whatever the turn).
    landing_slope_max_deg : float or None
        Steepest glide slope of a landing approach [deg] (PX4 ``FW_LND_ANG``); None:
        only the sink limit bounds it (ArduPlane: ``V sin θ`` <= ``TECS_SINK_MAX``).
    names : dict
        Attribute → the firmware's parameter name (for messages).
    sources : tuple of str
        The documentation pages and source files of the numbers and rules.
    """

    label: str
    acceptance_radius: float
    loiter_radius: float
    bank_limit_deg: float
    guidance_period: float
    guidance_damping: float
    climb_rate: float
    sink_rate: float
    airspeed_min: float
    airspeed_cruise: float
    airspeed_max: float
    takeoff_pitch_deg: float = 15.0
    takeoff_alt: float = 50.0
    turn_distance_rule: str = "l1"
    landing_slope_max_deg: float | None = None
    names: dict[str, str] = field(default_factory=dict, compare=False)
    sources: tuple[str, ...] = field(default=(), compare=False)

    def __post_init__(self) -> None:
        for name in ("acceptance_radius", "loiter_radius", "guidance_period", "guidance_damping",
                     "climb_rate", "sink_rate", "airspeed_min", "airspeed_cruise",
                     "airspeed_max", "takeoff_alt"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"{self.param(name)} must be a number > 0, got {v!r}")
        if not 5.0 <= self.bank_limit_deg <= 85.0:
            raise InputError(f"{self.param('bank_limit_deg')} must be in [5, 85] degrees, got "
                             f"{self.bank_limit_deg!r}")
        if not self.airspeed_min <= self.airspeed_cruise <= self.airspeed_max:
            raise InputError(
                f"fixed-wing speeds must satisfy min <= cruise <= max, got "
                f"{self.param('airspeed_min')} {self.airspeed_min:g}, "
                f"{self.param('airspeed_cruise')} {self.airspeed_cruise:g}, "
                f"{self.param('airspeed_max')} {self.airspeed_max:g} m/s")

    def param(self, attr: str) -> str:
        """The firmware's name of an attribute (the attribute's own name if unknown)."""
        return self.names.get(attr, attr)

    # ---------------------------------------------------------------- geometry
    def turn_radius(self, speed: float | None = None) -> float:
        """Coordinated turn radius ``V² / (g tan φ_max)`` [m] at ``speed`` (default cruise)."""
        v = self.airspeed_cruise if speed is None else float(speed)
        return v * v / (G * math.tan(math.radians(self.bank_limit_deg)))

    def l1_distance(self, speed: float | None = None) -> float:
        """Look-ahead of the lateral guidance ``(1/π) ζ T V`` [m] (``AP_L1_Control``)."""
        v = self.airspeed_cruise if speed is None else float(speed)
        return self.guidance_damping * self.guidance_period * v / math.pi

    def turn_distance(self, turn_deg: float, speed: float | None = None,
                      radius: float | None = None) -> float:
        """How far before a waypoint it counts as reached [m], for a turn of ``turn_deg``.

        ``radius`` overrides the acceptance radius (a ``NAV_WAYPOINT``'s param2 > 0,
        which ArduPlane uses as is, without the L1 limit or the angle scaling).
        """
        if radius is not None and radius > 0:
            return float(radius)
        if self.turn_distance_rule == "switch":
            return max(self.acceptance_radius, self.l1_distance(speed))
        d90 = min(self.acceptance_radius, self.l1_distance(speed))
        return d90 * min(abs(float(turn_deg)), 90.0) / 90.0

    def turn_on_distance(self, turn_deg: float, speed: float | None = None) -> float:
        """Distance past a waypoint before the aircraft is on the next leg [m].

        A fly-by turn of Δψ with radius R ends ``R tan(Δψ/2)`` past the corner
        (Δψ <= 90°); beyond 90° the aircraft swings wide of the corner by
        ``R (1 + tan((Δψ − 90°)/2))`` (2R for a reversal).
        """
        r = self.turn_radius(speed)
        a = min(abs(float(turn_deg)), 180.0)
        if a <= 90.0:
            return r * math.tan(math.radians(a) / 2)
        return r * (1.0 + math.tan(math.radians(a - 90.0) / 2))

    def max_glide_deg(self, speed: float | None = None) -> float:
        """Steepest glide slope [deg]: ``asin(sink / V)``, and the firmware's own limit."""
        v = self.airspeed_cruise if speed is None else float(speed)
        sink = math.degrees(math.asin(min(self.sink_rate / v, 1.0)))
        return sink if self.landing_slope_max_deg is None else min(sink,
                                                                   self.landing_slope_max_deg)

    def climb_distance(self, height: float, speed: float | None = None) -> float:
        """Horizontal distance to climb ``height`` [m] at the TECS climb limit [m]."""
        v = self.airspeed_cruise if speed is None else float(speed)
        return max(float(height), 0.0) * v / self.climb_rate

    # ---------------------------------------------------------------- the airframe
    def for_airframe(self, airframe: AirframeNav | None) -> FixedWingNav:
        """:meth:`with_airframe` from an :class:`AirframeNav` (None: these defaults)."""
        if airframe is None:
            return self
        return self.with_airframe(cruise=airframe.cruise, minimum=airframe.minimum,
                                  maximum=airframe.maximum, bank_deg=airframe.bank_deg,
                                  climb_rate=airframe.climb_rate, sink_rate=airframe.sink_rate)

    def with_airframe(self, *, cruise: float | None = None, minimum: float | None = None,
                      maximum: float | None = None, bank_deg: float | None = None,
                      climb_rate: float | None = None, sink_rate: float | None = None
                      ) -> FixedWingNav:
        """These defaults with the airframe's own numbers (None: keep the firmware's).

        A cruise speed outside the default range widens it (the airframe is configured
        for its own cruise speed: ``AIRSPEED_MIN``/``MAX`` must enclose it).
        """
        lo = self.airspeed_min if minimum is None else float(minimum)
        hi = self.airspeed_max if maximum is None else float(maximum)
        cr = self.airspeed_cruise if cruise is None else float(cruise)
        if minimum is None:
            lo = min(lo, cr)
        if maximum is None:
            hi = max(hi, cr)
        return replace(
            self, airspeed_min=lo, airspeed_max=hi, airspeed_cruise=cr,
            bank_limit_deg=self.bank_limit_deg if bank_deg is None else float(bank_deg),
            climb_rate=self.climb_rate if climb_rate is None else float(climb_rate),
            sink_rate=self.sink_rate if sink_rate is None else float(sink_rate))

    def summary(self) -> dict[str, object]:
        """JSON-friendly numbers with the firmware's parameter names."""
        return {
            "firmware": self.label,
            "turn_radius_m": round(self.turn_radius(), 1),
            "l1_distance_m": round(self.l1_distance(), 1),
            self.param("acceptance_radius"): self.acceptance_radius,
            self.param("loiter_radius"): self.loiter_radius,
            self.param("bank_limit_deg"): self.bank_limit_deg,
            self.param("climb_rate"): self.climb_rate,
            self.param("sink_rate"): self.sink_rate,
            self.param("airspeed_min"): self.airspeed_min,
            self.param("airspeed_cruise"): self.airspeed_cruise,
            self.param("airspeed_max"): self.airspeed_max,
        }


def merge_nav(navs: tuple[FixedWingNav, ...]) -> FixedWingNav | None:
    """The numbers every one of ``navs`` flies (generic profile): the larger radii and
    look-ahead, the smaller bank, climb and sink, the common airspeed range."""
    navs = tuple(n for n in navs if n is not None)
    if not navs:
        return None
    if len(navs) == 1:
        return navs[0]
    lo = max(n.airspeed_min for n in navs)
    hi = min(n.airspeed_max for n in navs)
    cr = min(max(max(n.airspeed_cruise for n in navs), lo), hi)
    return FixedWingNav(
        label=" + ".join(n.label for n in navs),
        acceptance_radius=max(n.acceptance_radius for n in navs),
        loiter_radius=max(n.loiter_radius for n in navs),
        bank_limit_deg=min(n.bank_limit_deg for n in navs),
        guidance_period=max(n.guidance_period for n in navs),
        guidance_damping=max(n.guidance_damping for n in navs),
        climb_rate=min(n.climb_rate for n in navs),
        sink_rate=min(n.sink_rate for n in navs),
        airspeed_min=lo, airspeed_cruise=cr, airspeed_max=max(hi, lo),
        takeoff_pitch_deg=max(n.takeoff_pitch_deg for n in navs),
        takeoff_alt=max(n.takeoff_alt for n in navs),
        turn_distance_rule=("switch" if any(n.turn_distance_rule == "switch" for n in navs)
                            else "l1"),
        landing_slope_max_deg=min((n.landing_slope_max_deg for n in navs
                                   if n.landing_slope_max_deg is not None), default=None),
        names={k: " / ".join(dict.fromkeys(n.param(k) for n in navs))
               for k in navs[0].names},
        sources=tuple(s for n in navs for s in n.sources),
    )


def merge_speed(commands: tuple[SpeedCommand, ...]) -> SpeedCommand:
    """A speed command every firmware of ``commands`` takes (generic profile): their
    speed type (they agree), ignored outside the range if any one ignores it."""
    first = commands[0]
    types = {c.speed_type for c in commands}
    if len(types) != 1:
        raise ValueError(f"the firmwares disagree on the DO_CHANGE_SPEED type: {sorted(types)}")
    accepted = set.intersection(*(set(c.accepted or (c.speed_type,)) for c in commands))
    return SpeedCommand(speed_type=first.speed_type, accepted=tuple(sorted(accepted)),
                        ignored_outside=any(c.ignored_outside for c in commands),
                        other_type="; ".join(dict.fromkeys(c.other_type for c in commands
                                                           if c.other_type)),
                        default=" / ".join(dict.fromkeys(c.default for c in commands)),
                        source="; ".join(dict.fromkeys(c.source for c in commands if c.source)))
