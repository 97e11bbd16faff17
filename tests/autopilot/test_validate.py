"""Every firmware rule has a case that triggers it: a table of minimal missions, each breaking
one rule of :mod:`fm2uav.autopilot.validate` or of a firmware module
(:mod:`fm2uav.autopilot.firmware.px4`, ``ardupilot``, any new one), and a meta-test that every
``Problem(...)`` the validators can return is produced by a case of the table (so a new rule
without a case fails here).

**Adding a rule** (a new ``Problem(index, "code", "message")`` in ``validate.py`` or in a
module of ``autopilot/firmware/``): add one :class:`Case` to :data:`CASES` — the firmware and
airframe, a one-line ``build`` that breaks only that rule in the valid base mission of the
airframe (:func:`base`), the code and a regex of the message; ``also`` lists the codes that
cannot help firing with it (a landing as the first item is also a missing takeoff), and
``severity="warning"`` for a rule that warns (the meta-test reads the severity from the call
too). Write the code as a string literal in the ``Problem(...)`` call (the meta-test reads it
from the source). The flight rules of ``autopilot/firmware/flight_rules.py`` (speeds, fixed-wing
climb-out, loiters, legs, landing) are rules like the others: each has its case here.
"""

from __future__ import annotations

import ast
import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

import pytest

from fm2uav.autopilot import validate as validate_module
from fm2uav.autopilot.geofence import FenceCircle, FencePolygon
from fm2uav.autopilot.items import MissionItem
from fm2uav.autopilot.validate import check_mission, validate_mission
from fm2uav.errors import MissionError

HOME_ALT = 500.0  # m AMSL, the ground under the start
LAT, LON = 47.3977, 8.5456


def _wp(k: int, alt: float = 60.0, command: int = 16, frame: int = 3, **kw) -> MissionItem:
    """A position item ``k`` x 200 m east of home (frame 3: above home)."""
    return MissionItem.at(command, frame, LAT, LON + k * 0.00265, alt, **kw)


#: Cruise speed of the base missions [m/s]: a multirotor's ground speed, and a fixed-wing /
#: VTOL airspeed inside both firmwares' ranges (PX4 FW_AIRSPD_MIN..MAX 10..20, ArduPlane
#: AIRSPEED_MIN..MAX 9..22), slow enough that the 40 m take-off climb (40 m x 15 / 5 m/s
#: TECS climb = 120 m, + the turn distance) ends before the first waypoint 200 m ahead.
CRUISE = {"multirotor": 8.0, "fixed_wing": 15.0, "vtol": 15.0}
#: The speed type each firmware takes on the airframe: ground speed 1 (multirotor), 0 airspeed.
SPEED_TYPE = {"multirotor": 1.0, "fixed_wing": 0.0, "vtol": 0.0}


def base(vehicle: str = "multirotor") -> list[MissionItem]:
    """A mission every firmware accepts and flies as planned on ``vehicle``: takeoff, the
    cruise speed before the first waypoint, waypoints 200 m apart in a straight line with a
    camera switched on and off between them, then the airframe's usual end (fixed-wing:
    PX4's landing pattern, a loiter down to 40 m, 2.6 deg glide to the touchdown)."""
    takeoff = 84 if vehicle == "vtol" else 22
    items = [_wp(0, 40.0, command=takeoff),
             MissionItem.do(178, SPEED_TYPE[vehicle], CRUISE[vehicle], -1.0),
             _wp(1),
             MissionItem.do(206, 25.0, 0.0, 1.0),
             _wp(2),
             MissionItem.do(206, 0.0),
             _wp(3)]
    if vehicle == "fixed_wing":
        # loiter (80 m radius) 40 m above the touchdown, which lies 880 m further east
        return items + [MissionItem.do(189), _wp(4, 40.0, command=31, p2=80.0, p4=0.0),
                        _wp(8.4, 0.0, command=21)]
    return items + [_wp(3, 0.0, command=85 if vehicle == "vtol" else 21)]


def _at(items: list[MissionItem], i: int, **changes) -> list[MissionItem]:
    out = list(items)
    out[i] = replace(out[i], **changes)
    return out


def _param(items: list[MissionItem], i: int, k: int, value: float) -> list[MissionItem]:
    p = list(items[i].params)
    p[k] = value
    return _at(items, i, params=tuple(p))


def _index(items: list[MissionItem], command: int, nth: int = 0) -> int:
    return [i for i, it in enumerate(items) if it.command == command][nth]


def _w1(vehicle: str = "multirotor") -> int:
    """Index of the first waypoint of the base mission (after the cruise speed)."""
    return _index(base(vehicle), 16)


def _later_speed(vehicle: str, kind: float, speed: float) -> list[MissionItem]:
    """The base mission with one more DO_CHANGE_SPEED after its second waypoint (the cruise
    speed before the first one stays valid: only the added command breaks a rule)."""
    items = base(vehicle)
    k = _index(items, 16, 1) + 1
    return items[:k] + [MissionItem.do(178, kind, speed, -1.0)] + items[k:]


def _north(k: float, north_m: float, alt: float = 60.0, command: int = 16) -> MissionItem:
    """A waypoint ``k`` x 200 m east of home and ``north_m`` north of that."""
    return MissionItem.at(command, 3, LAT + north_m / 111195.0, LON + k * 0.00265, alt)


def _rtl_end(items: list[MissionItem]) -> list[MissionItem]:
    """The mission with its landing (pattern) replaced by an RTL."""
    first_end = next(i for i, it in enumerate(items) if it.command in (189, 21, 85)
                     and i > 0)
    return items[:first_end] + [MissionItem.do(20)]


_SQUARE = FencePolygon(points=[(LAT - 0.001, LON + 0.002), (LAT + 0.001, LON + 0.002),
                               (LAT + 0.001, LON + 0.0035), (LAT - 0.001, LON + 0.0035)],
                       inclusion=False, name="stadium")


@dataclass(frozen=True)
class Case:
    """One rule broken by one minimal mission."""

    code: str  #: the Problem code expected
    match: str  #: regex found in the Problem's message
    build: Callable[[], list[MissionItem]]  #: the mission (after home)
    firmware: str = "px4"
    vehicle: str = "multirotor"
    also: frozenset = frozenset()  #: codes that cannot help firing with it
    fences: tuple = ()
    home_alt: float | None = HOME_ALT
    severity: str = "error"  #: the rule's severity ("warning": it flies, with a deviation)
    home_latlon: tuple | None = None  #: where a fixed-wing launches (None: the take-off item)

    @property
    def id(self) -> str:
        return f"{self.firmware}-{self.vehicle}-{self.code}-{self.match[:24]}"

    def problems(self, firmware: str | None = None):
        return validate_mission(self.build(), firmware or self.firmware, vehicle=self.vehicle,
                                home_alt=self.home_alt, fences=self.fences,
                                home_latlon=self.home_latlon)


MR, FW, VT = "multirotor", "fixed_wing", "vtol"
NAN = math.nan

#: The table: every rule, one minimal mission breaking it (more where a rule has two ways in).
CASES: list[Case] = [
    # ---------------------------------------------------------------- every firmware
    Case("empty", "has no items", lambda: []),
    Case("param-nan", r"param2 is nan; only param4", lambda: _param(base(), _w1(), 1, NAN)),
    Case("param-nan", r"param4 is nan; it is not a yaw",
         lambda: _param(base(), _index(base(), 178), 3, NAN)),
    Case("param-nan", r"param4 is inf; it is not a yaw",
         lambda: _param(base(), _w1(), 3, math.inf)),
    Case("param-nan", r"DO_LAND_START \(189\): param6 is nan",
         lambda: _param(base(FW), _index(base(FW), 189), 5, NAN), vehicle=FW),
    Case("latlon", r"latitude/longitude \(nan, ", lambda: _param(base(), _w1(), 4, NAN)),
    Case("latlon", r"latitude/longitude \(91.0, ", lambda: _param(base(), _w1(), 4, 91.0)),
    Case("latlon-zero", "are 0, 0",
         lambda: _param(_param(base(), _w1(), 4, 0.0), _w1(), 5, 0.0)),
    Case("alt", "altitude is nan", lambda: _param(base(), _w1(), 6, NAN)),
    # the added speed command has a type no firmware knows (2: climb speed on ArduCopter);
    # validate.py's and the firmware's speed rule both name it, under the same code
    Case("speed-type", r"speed type \(param1\) 2 is not 0", lambda: _later_speed(MR, 2.0, 8.0)),
    Case("speed", r"speed \(param2\) 0 m/s must be > 0", lambda: _later_speed(MR, 1.0, 0.0)),
    Case("trigger", "trigger distance -5 m must be >= 0",
         lambda: _param(base(), _index(base(), 206), 0, -5.0)),
    Case("no-takeoff", r"must be NAV_TAKEOFF .* got NAV_WAYPOINT", lambda: base()[1:]),
    Case("no-takeoff", r"got none", lambda: [MissionItem.do(178, 1.0, 5.0, -1.0)],
         also=frozenset({"no-end"})),
    Case("takeoff-alt", r"takeoff altitude is -1.00 m above home",
         lambda: _param(base(), 0, 6, -1.0)),
    Case("takeoff-alt", r"takeoff altitude is 0.00 m above home",  # AMSL takeoff at home
         lambda: _at(_param(base(), 0, 6, HOME_ALT), 0, frame=0)),
    Case("no-end", r"must end with .*not NAV_WAYPOINT .*outputs.end", lambda: base()[:-1]),
    Case("trigger-on", "still triggering",
         lambda: [it for it in base() if not (it.command == 206 and it.params[0] == 0)]),
    Case("fence-inside", r"NAV_WAYPOINT \(16\) lies inside the exclusion fence 'stadium'",
         base, fences=(_SQUARE,)),
    Case("fence-inside", r"lies inside the exclusion fence 'tower'", base,
         fences=(FenceCircle(center=(LAT, LON + 0.00265 * 3), radius=30.0, inclusion=False,
                             name="tower"),)),
    Case("fence-outside", r"NAV_WAYPOINT \(16\) lies outside the inclusion fence 'area'", base,
         fences=(FencePolygon(points=[(LAT - 0.01, LON - 0.01), (LAT + 0.01, LON - 0.01),
                                      (LAT + 0.01, LON + 0.0060), (LAT - 0.01, LON + 0.0060)],
                              inclusion=True, name="area"),)),
    Case("fence-outside", r"lies outside the inclusion fence 'circle'", base,
         fences=(FenceCircle(center=(LAT, LON), radius=450.0, inclusion=True, name="circle"),)),
    # ---------------------------------------------------------------- PX4
    Case("px4-command", r"NAV_LOITER_TURNS \(18\) is not a mission command PX4 accepts",
         lambda: _at(base(), _w1(), command=18,
                     params=(0, 0, 0, 0, *base()[_w1()].params[4:]))),
    Case("px4-command", r"NAV_VTOL_LAND \(85\) .*VTOL items need a VTOL airframe",
         lambda: _at(base(), len(base()) - 1, command=85)),
    Case("px4-terrain-frame", r"uses MAV_FRAME_GLOBAL_TERRAIN_ALT; PX4 does not fly .*"
                              r"--frame amsl", lambda: _at(base(), _w1(), frame=10)),
    Case("px4-frame", r"uses 1; PX4 takes frames 0 and 3 only",
         lambda: _at(base(), _w1(), frame=1)),
    Case("px4-frame", r"DO_CHANGE_SPEED \(178\) must use MAV_FRAME_MISSION \(2\) on PX4",
         lambda: _at(base(), _index(base(), 178), frame=3)),
    Case("px4-land-start", "more than one DO_LAND_START",
         lambda: base(FW)[:-3] + [MissionItem.do(189)] + base(FW)[-3:], vehicle=FW),
    Case("px4-land-start", "must come before the landing approach item",
         lambda: base(FW)[:-3] + base(FW)[-2:] + [MissionItem.do(189)], vehicle=FW,
         also=frozenset({"no-end"})),
    Case("px4-land-before-rtl", "DO_LAND_START before an RTL",
         lambda: base(FW)[:-2] + [MissionItem.do(20)] + base(FW)[-2:], vehicle=FW),
    Case("px4-starts-landing", "starts with a landing", lambda: base()[-1:] + base()[1:],
         also=frozenset({"no-takeoff"})),
    Case("px4-landing-required", r"PX4 fixed-wing missions need a landing .*MIS_TKO_LAND_REQ",
         lambda: _rtl_end(base(FW)), vehicle=FW),
    Case("px4-landing-required", r"PX4 vtol missions need a landing",
         lambda: _rtl_end(base(VT)), vehicle=VT),
    Case("px4-fw-approach", "has no approach item before it",
         lambda: [MissionItem.do(189), _wp(8.4, 0.0, command=21)], vehicle=FW,
         also=frozenset({"no-takeoff"})),
    Case("px4-fw-approach", r"approached from NAV_TAKEOFF \(22\); PX4 takes only",
         lambda: [base(FW)[0], MissionItem.do(189), _wp(8.4, 0.0, command=21)], vehicle=FW),
    Case("px4-fw-approach", r"the approach item is -10.0 m above the landing point",
         lambda: _param(base(FW), len(base(FW)) - 1, 6, 50.0), vehicle=FW),
    # a touchdown inside the loiter circle is also an exit from the loiter inside its circle
    # (the flight rule fw-loiter-exit: the item after a NAV_LOITER_TO_ALT lies inside it)
    Case("px4-fw-approach", r"the landing point is \d+ m from the loiter centre, inside its "
                            r"900 m radius",
         lambda: _param(base(FW), len(base(FW)) - 2, 1, 900.0), vehicle=FW,
         also=frozenset({"fw-loiter-exit"})),
    # PX4's flight rule bounds the glide by FW_LND_ANG too (fw-landing: the sink limit and
    # FW_LND_ANG), so a glide steeper than FW_LND_ANG breaks both
    Case("px4-fw-glide-slope", r"glide slope is [\d.]+ deg, steeper than FW_LND_ANG = 5 deg",
         lambda: _param(base(FW), len(base(FW)) - 2, 6, 160.0), vehicle=FW,
         also=frozenset({"fw-landing"})),
    # ---------------------------------------------------------------- ArduPilot
    Case("ardupilot-command", r"NAV_LOITER_TO_ALT \(31\) is not a mission command ArduPilot "
                              r"Copter flies",
         lambda: _at(base(), _w1(), command=31, params=(0, 0, 0, 0, *base()[_w1()].params[4:])),
         firmware="ardupilot"),
    Case("ardupilot-frame", r"uses frame 1; ArduPilot missions take frames 0, 3 and 10",
         lambda: _at(base(), _w1(), frame=1), firmware="ardupilot"),
    Case("ardupilot-terrain-takeoff", r"NAV_TAKEOFF \(22\) in the terrain frame.*#20142",
         lambda: _at(base(), 0, frame=10), firmware="ardupilot"),
    # ---------------------------------------------------------------- flight rules: speeds
    # (firmware/flight_rules.py; ranges PX4 FW_AIRSPD_MIN..MAX 10..20, ArduPlane 9..22 m/s)
    Case("speed-type", r"speed type 0: PX4 takes the ground speed \(1\) on a multirotor",
         lambda: _later_speed(MR, 0.0, 8.0)),
    Case("speed-type", r"speed type 1: ArduPilot takes the airspeed \(0\) on a fixed-wing: "
                       r"speed type 1 \(ground speed\) sets MIN_GROUNDSPEED",
         lambda: _later_speed(FW, 1.0, 15.0), firmware="ardupilot", vehicle=FW),
    Case("speed-type", r"speed type 2: ArduPilot takes the ground speed \(1\) on a multirotor: "
                       r"speed types 2/3 set ArduCopter's climb",  # a type common rules know
         lambda: _later_speed(MR, 2.0, 8.0), firmware="ardupilot"),
    # 9.5 m/s: below PX4's FW_AIRSPD_MIN 10, a speed ArduPlane would take
    Case("speed-range", r"DO_CHANGE_SPEED 9.5 m/s: it is outside the airframe's range "
                        r"10 .. 20 m/s", lambda: _param(base(FW), 1, 1, 9.5), vehicle=FW),
    # 23 m/s: above ArduPlane's AIRSPEED_MAX 22, which it ignores (on a VTOL, whose cruise
    # does not climb out on a NAV_TAKEOFF, so the faster climb-out is not a second rule)
    Case("speed-range", r"DO_CHANGE_SPEED 23 m/s: ArduPilot ignores an airspeed outside "
                        r"AIRSPEED_MIN 9 .. AIRSPEED_MAX 22 m/s",
         lambda: _param(base(VT), 1, 1, 23.0), firmware="ardupilot", vehicle=VT),
    Case("no-cruise-speed", r"no DO_CHANGE_SPEED before the first waypoint: PX4 flies "
                            r"MPC_XY_CRUISE",  # the cruise speed after the first waypoint
         lambda: [base()[i] for i in (0, 2, 1, *range(3, len(base())))], severity="warning"),
    Case("no-cruise-speed", r"ArduPilot flies AIRSPEED_CRUISE",  # no speed command at all
         lambda: [it for it in base(FW) if it.command != 178], firmware="ardupilot",
         vehicle=FW, severity="warning"),
    # ---------------------------------------------------------------- flight rules: fixed-wing
    # launched 200 m south of the take-off item: the climb heads north, the first waypoint
    # lies 200 m east of the take-off item, 45° off that course seen from the launch
    Case("fw-climb-out", r"the first waypoint lies 45° off the take-off course", lambda: base(FW),
         vehicle=FW, home_latlon=(LAT - 200 / 111195.0, LON)),
    # a take-off to 60 m: 60 m x 15 / 5 m/s = 180 m of climb + 33 m of turn > 199 m
    Case("fw-climb-out", r"the first waypoint is 199 m from the launch, but climbing 60 m at "
                         r"5 m/s \(FW_T_CLMB_MAX\) and 15 m/s takes 180 m plus 33 m",
         lambda: _param(base(FW), 0, 6, 60.0), vehicle=FW),
    Case("fw-climb-out", r"the first waypoint is 10 m below the take-off altitude",
         lambda: _param(base(FW), _w1(FW), 6, 30.0), vehicle=FW),
    # a 10 m loiter: PX4's turn radius at 15 m/s and FW_R_LIM 50 deg is 19 m
    Case("fw-loiter-radius", r"NAV_LOITER_TO_ALT \(31\): a 10 m loiter at 15 m/s is tighter "
                             r"than the turn radius 19 m \(FW_R_LIM 50°\)",
         lambda: _param(base(FW), len(base(FW)) - 2, 1, 10.0), vehicle=FW),
    # ArduPlane: the touchdown 878 m from the centre of a 900 m loiter (no PX4 approach rule)
    Case("fw-loiter-exit", r"NAV_LAND \(21\) is 878 m from the loiter centre, inside its 900 m "
                           r"circle: ArduPlane leaves the loiter by altitude only",
         lambda: _param(base(FW), len(base(FW)) - 2, 1, 900.0), firmware="ardupilot",
         vehicle=FW),
    # the second waypoint, 199 m after the first, with a 250 m acceptance radius (param2):
    # ArduPlane is within it as it reaches the first one
    Case("fw-skipped-waypoint", r"NAV_WAYPOINT \(16\) is 199 m after the previous waypoint: "
                                r"ArduPlane reaches the previous one 0 m before it, already "
                                r"within 250 m of this one",
         lambda: _param(base(FW), _index(base(FW), 16, 1), 1, 250.0), firmware="ardupilot",
         vehicle=FW),
    # a waypoint 40 m north of the first: PX4 turns 90° onto that leg (19 m) and counts the
    # waypoint reached 33 m before it
    Case("fw-short-leg", r"the 40 m leg to NAV_WAYPOINT \(16\) is shorter than the 53 m PX4 "
                         r"flies on it \(19 m to turn 90°",
         lambda: (lambda b: b[:_w1(FW) + 1] + [_north(1, 40.0)] + b[_w1(FW) + 1:])(base(FW)),
         vehicle=FW, severity="warning"),
    # ArduPlane landing 60 m north of a waypoint 15 m up, after a 90° turn onto the approach:
    # 23 m to turn + 61 m of turn distance > 60 m (glide 14°, within its 19.5°)
    Case("fw-landing", r"the landing approach is 60 m long, shorter than the 84 m ArduPlane "
                       r"needs to turn 90° onto it",
         lambda: base(FW)[:-3] + [_wp(4, 15.0), _north(4, 60.0, 0.0, command=21)],
         firmware="ardupilot", vehicle=FW),
    # ArduPlane: loiter at 400 m over the touchdown, 400 m over the 876 m glide (24.6°) >
    # asin(5 / 15) = 19.5°
    Case("fw-landing", r"the landing glide slope is 24.6°, steeper than the 19.5° ArduPlane "
                       r"can hold at 15 m/s \(TECS_SINK_MAX 5 m/s\)",
         lambda: _param(base(FW), len(base(FW)) - 2, 6, 400.0), firmware="ardupilot",
         vehicle=FW),
]


@pytest.mark.parametrize("firmware", ["px4", "ardupilot", "generic"])
@pytest.mark.parametrize("vehicle", [MR, FW, VT])
def test_the_base_missions_are_valid(firmware, vehicle):
    items = base(vehicle)
    assert validate_mission(items, firmware, vehicle=vehicle, home_alt=HOME_ALT) == []
    assert {178, 206} <= {it.command for it in items}  # the DO rules are reached
    check_mission(items, firmware, vehicle=vehicle, home_alt=HOME_ALT)


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.id)
def test_each_rule_fires_alone_on_its_case(case):
    problems = case.problems()
    codes = {p.code for p in problems}
    assert case.code in codes, [str(p) for p in problems]
    assert codes <= {case.code} | case.also, f"other rules fire too: {[str(p) for p in problems]}"
    hits = [p for p in problems if p.code == case.code and re.search(case.match, p.message)]
    assert hits, [p.message for p in problems]
    assert {p.severity for p in hits} == {case.severity}, [(p.severity, str(p)) for p in hits]
    options = dict(vehicle=case.vehicle, home_alt=case.home_alt, fences=case.fences,
                   home_latlon=case.home_latlon)
    if any(p.is_error for p in problems):
        with pytest.raises(MissionError,
                           match=f"{case.firmware} would reject or misfly this mission"):
            check_mission(case.build(), case.firmware, **options)
    else:  # a warning alone: the mission is exported, the warning returned for the summary
        assert case.severity == "warning"
        assert [p.code for p in check_mission(case.build(), case.firmware, **options)] == \
            [p.code for p in problems]


@pytest.mark.parametrize("case", [c for c in CASES if c.firmware != "generic"],
                         ids=lambda c: c.id)
def test_generic_rejects_what_either_firmware_rejects(case):
    assert case.code in {p.code for p in case.problems("generic")}


# ---------------------------------------------------------------- the meta-test


@dataclass(frozen=True)
class Site:
    """A ``Problem(...)`` call in the validators' source: where, its code, its message, its
    severity."""

    where: str
    code: str
    pattern: re.Pattern
    severity: str = "error"


def _pattern(node: ast.AST) -> str:
    """A regex every message built by ``node`` (a str, an f-string, a concatenation) matches."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return re.escape(node.value)
    if isinstance(node, ast.JoinedStr):
        return "".join(_pattern(v) if isinstance(v, ast.Constant) else "(?s:.*?)"
                       for v in node.values)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        return _pattern(node.left) + _pattern(node.right)
    return "(?s:.*?)"


def _codes(node: ast.AST, where: str) -> list[str]:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    if isinstance(node, ast.IfExp):
        return _codes(node.body, where) + _codes(node.orelse, where)
    raise AssertionError(f"{where}: the code of this Problem is not a string literal; write it "
                         "as one (tests/autopilot/test_validate.py reads the codes from the "
                         "source)")


def _severity(node: ast.AST | None, where: str) -> str:
    if node is None:
        return "error"  # Problem's default
    if isinstance(node, ast.Constant) and node.value in ("error", "warning"):
        return node.value
    raise AssertionError(f"{where}: the severity of this Problem is not a literal \"error\" or "
                         "\"warning\"; write it as one (the meta-test reads it from the source)")


def rule_sites() -> list[Site]:
    """Every ``Problem(index, code, message[, severity])`` in validate.py and
    autopilot/firmware/*.py (the firmware profiles and their flight rules)."""
    root = Path(validate_module.__file__).parent
    files = [root / "validate.py", *sorted((root / "firmware").glob("*.py"))]
    sites = []
    for f in files:
        for node in ast.walk(ast.parse(f.read_text())):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id == "Problem"):
                continue
            where = f"{f.relative_to(root.parent.parent)}:{node.lineno}"
            names = ("index", "code", "message", "severity")
            args = dict(zip(names, node.args))
            args.update({k.arg: k.value for k in node.keywords})
            assert len(node.args) + len(node.keywords) in (3, 4) and set(args) <= set(names) \
                and {"index", "code", "message"} <= set(args), \
                f"{where}: Problem(index, code, message[, severity]) expected"
            severity = _severity(args.get("severity"), where)
            for code in _codes(args["code"], where):
                sites.append(Site(where, code, re.compile(_pattern(args["message"])), severity))
    return sites


def test_the_validators_are_where_the_meta_test_looks():
    sites = rule_sites()
    assert len(sites) >= 45
    assert {"px4-fw-glide-slope", "ardupilot-terrain-takeoff", "no-takeoff"} <= \
        {s.code for s in sites}
    # the flight rules (flyable): speeds and fixed-wing geometry, errors and warnings
    flight = {s.code: s.severity for s in sites if "flight_rules.py" in s.where}
    assert {"speed-type", "speed-range", "fw-climb-out", "fw-loiter-radius", "fw-loiter-exit",
            "fw-skipped-waypoint", "fw-landing"} <= set(flight)
    assert flight["no-cruise-speed"] == flight["fw-short-leg"] == "warning"


def test_every_rule_of_the_validators_has_a_case_in_the_table():
    produced = [(c.code, p.message, p.severity) for c in CASES for p in c.problems()
                if p.code == c.code]
    missing = [f"{s.where} {s.code!r} ({s.severity}) /{s.pattern.pattern}/"
               for s in rule_sites()
               if not any(code == s.code and sev == s.severity and s.pattern.fullmatch(msg)
                          for code, msg, sev in produced)]
    assert not missing, ("rules without a case in tests/autopilot/test_validate.py CASES "
                         "(add a minimal mission that breaks each):\n" + "\n".join(missing))


# ---------------------------------------------------------------- thresholds at their edges
def _px4_fw(items):
    return [p for p in validate_mission(items, "px4", vehicle=FW, home_alt=HOME_ALT)
            if p.code.startswith("px4-fw")]


def test_a_landing_approached_level_with_it_is_refused():
    level = _param(base(FW), len(base(FW)) - 1, 6, 40.0)  # touchdown at the loiter's height
    (p,) = _px4_fw(level)
    assert p.code == "px4-fw-approach" and "is 0.0 m above the landing point" in p.message


def test_the_glide_slope_limit_is_fw_lnd_ang_to_a_tenth_of_a_degree():
    items = base(FW)
    # touchdown 880 m east of the loiter centre (80 m radius): slope = atan(rel / 876.4 m)
    flat = math.sqrt(880.0 ** 2 - 80.0 ** 2)
    for deg, fires in ((4.9, False), (5.3, True)):
        rel = flat * math.tan(math.radians(deg))
        got = _px4_fw(_param(items, len(items) - 2, 6, rel))
        assert [p.code for p in got] == (["px4-fw-glide-slope"] if fires else []), deg


def test_the_glide_slope_runs_from_the_loiter_circle_not_its_centre():
    """A loiter of radius r, d from the touchdown: the glide starts where the vehicle leaves
    the circle, sqrt(d² - r²) from the touchdown."""
    items = _param(base(FW), len(base(FW)) - 2, 1, 300.0)  # loiter radius 300 m
    items[-1] = _wp(6.5, 0.0, command=21)  # 500 m east of the loiter centre
    (p,) = _px4_fw(items)  # 40 m over 400 m: 5.7 deg (over 500 m it would be 4.6 deg)
    assert p.code == "px4-fw-glide-slope" and "is 5.7 deg" in p.message

