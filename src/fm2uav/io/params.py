"""Parameter files, ``NAME VALUE`` a line, as Mission Planner and MAVProxy load them.

``mission.param`` holds the firmware parameters a mission sets
(:mod:`fm2uav.autopilot.params`): comment lines start with ``#`` (the header, and
before each parameter the reason for it), then ``NAME VALUE`` separated by one space,
the value in the firmware's own unit. MAVProxy's ``param load`` (pymavlink
``mavparm.MAVParmDict.load``: comments after ``#`` stripped, ``,`` or white space
between name and value) and Mission Planner's "Load from file" read this; a name the
connected firmware version does not know is reported and skipped, so one file can
carry a parameter in the spelling of every version (ArduCopter ``RTL_ALT`` in cm up
to 4.6, ``RTL_ALT_M`` in m from 4.7).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import IO, Any

from ..errors import InputError

__all__ = ["params_text", "write_params", "read_params"]


def _value(v: float) -> str:
    v = float(v)
    if v.is_integer():
        return str(int(v))
    return f"{v:.6f}".rstrip("0").rstrip(".")


def params_text(params: Any) -> str:
    """The file's text of a :class:`~fm2uav.autopilot.params.ParamSet`."""
    lines = [f"# {h}" for h in params.header]
    for p in params.params:
        lines.append(f"# {p.why}")
        lines.append(f"{p.name} {_value(p.value)}")
    return "\n".join(lines) + "\n"


def write_params(fh: IO[str], params: Any) -> int:
    """Write a :class:`~fm2uav.autopilot.params.ParamSet`; returns the number of parameters."""
    fh.write(params_text(params))
    return len(params.params)


def read_params(file: str | Path) -> dict[str, float]:
    """``{NAME: value}`` of a parameter file (``NAME VALUE`` or ``NAME,VALUE`` lines,
    ``#`` comments), as MAVProxy reads it.

    Raises
    ------
    InputError
        A line that is not a name and a number (named with its number).
    """
    file = Path(file)
    from .. import _validate as _v

    _v.input_file(file, "parameter file")
    try:
        lines = file.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{file}: cannot read: {exc}") from None
    out: dict[str, float] = {}
    for n, line in enumerate(lines, start=1):
        text = line.split("#")[0].replace(",", " ").strip()
        if not text:
            continue
        parts = text.split()
        try:
            if len(parts) != 2:
                raise ValueError
            value = float(parts[1])
            if not math.isfinite(value):
                raise ValueError
        except ValueError:
            raise InputError(f"{file}: line {n} is not 'NAME VALUE': {line!r}") from None
        out[parts[0]] = value
    return out
