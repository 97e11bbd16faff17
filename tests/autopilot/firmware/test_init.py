"""The firmware profiles: every airframe known to each, generic = what both firmwares accept,
unknown names refused naming the option."""

from __future__ import annotations

import pytest

from fm2uav.autopilot.firmware import (
    ARDUPILOT,
    FIRMWARE_TYPES,
    FIRMWARES,
    GENERIC,
    PROFILES,
    PX4,
    VEHICLES,
    check_vehicle,
    firmware_profile,
    supported_commands,
)
from fm2uav.autopilot.items import VTOL_COMMANDS
from fm2uav.errors import InputError


def test_every_profile_knows_every_airframe_and_its_mav_autopilot():
    assert FIRMWARES == ("px4", "ardupilot", "generic") == tuple(PROFILES)
    assert FIRMWARE_TYPES == {"px4": 12, "ardupilot": 3, "generic": 0}
    for p in PROFILES.values():
        assert set(p.commands) == set(VEHICLES) and p.rules
        for v in ("multirotor", "fixed_wing"):
            assert not p.commands[v] & VTOL_COMMANDS  # VTOL items need a VTOL airframe


def test_generic_is_what_both_firmwares_accept_with_both_rule_sets():
    for v in VEHICLES:
        assert GENERIC.commands[v] == PX4.commands[v] & ARDUPILOT.commands[v]
    assert GENERIC.position_frames == PX4.position_frames & ARDUPILOT.position_frames
    assert GENERIC.rules == PX4.rules + ARDUPILOT.rules
    assert GENERIC.landing_required == {"fixed_wing", "vtol"} == PX4.landing_required
    assert not GENERIC.terrain_frame and ARDUPILOT.terrain_frame and not PX4.terrain_frame
    assert 18 not in supported_commands("px4", "multirotor")  # NAV_LOITER_TURNS
    assert 31 not in supported_commands("ardupilot", "multirotor")  # Copter: no LOITER_TO_ALT


def test_unknown_names_are_refused_naming_the_option():
    with pytest.raises(InputError, match=r"firmware must be one of px4, ardupilot, generic, "
                                         r"got 'inav' .*--firmware"):
        firmware_profile("inav")
    with pytest.raises(InputError, match=r"vehicle must be one of .*got 'rover' .*--vehicle"):
        check_vehicle("rover")
    assert firmware_profile("px4") is PX4
