"""The firmware parameters a mission sets: ``mission.param``, checked before it is written.

Each :class:`~fm2uav.autopilot.firmware.profile.Param` comes from a firmware's
return model (:mod:`fm2uav.autopilot.returns`): the return altitude in every
version's spelling and unit (ArduCopter ``RTL_ALT`` in cm and ``RTL_ALT_M`` in m;
ArduPlane ``ALT_HOLD_RTL`` in cm and ``RTL_ALTITUDE`` in m; PX4
``RTL_RETURN_ALT`` in m), the behaviour the altitude was checked for (no cone,
altitude above home, the return type), rally settings, and the settings that make
the return follow the mission when no altitude is safe. A firmware version that
does not know a name skips its line (MAVProxy and Mission Planner report an unknown
parameter), so one file serves every version. The file format is
:mod:`fm2uav.io.params`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from ..errors import MissionError
from .firmware.profile import Param

__all__ = ["ParamSet", "param_set"]

#: MAVLink PARAM_SET param_id: at most 16 characters.
_NAME = re.compile(r"^[A-Z][A-Z0-9_]{0,15}$")


@dataclass(frozen=True)
class ParamSet:
    """Parameters of one mission, with the header lines of their file.

    Attributes
    ----------
    params : tuple of Param
    header : tuple of str
        Comment lines (what the file is, for which firmware and airframe).
    """

    params: tuple[Param, ...]
    header: tuple[str, ...] = ()

    def as_dict(self) -> dict[str, float]:
        """``{name: value}`` in the firmware's units."""
        return {p.name: p.value for p in self.params}


def param_set(params: Any, *, header: Any = ()) -> ParamSet:
    """A checked :class:`ParamSet`.

    Raises
    ------
    MissionError
        A name MAVLink cannot carry (upper case, at most 16 characters), a value that
        is not finite, or one name with two values (a bug in a return model).
    """
    seen: dict[str, Param] = {}
    for p in params:
        if not _NAME.match(p.name):
            raise MissionError(f"parameter name {p.name!r} is not a MAVLink param_id "
                               "(upper case, at most 16 characters)")
        if not math.isfinite(float(p.value)):
            raise MissionError(f"parameter {p.name} = {p.value!r} is not a finite number")
        old = seen.get(p.name)
        if old is not None and float(old.value) != float(p.value):
            raise MissionError(f"parameter {p.name} set twice: {old.value:g} ({old.why}) and "
                               f"{p.value:g} ({p.why})")
        seen.setdefault(p.name, p)
    return ParamSet(tuple(seen.values()), tuple(str(h) for h in header))
