"""Error messages that name only the flags of the command being run.

The library names the fix of an error twice, for both ways in: the mission-file
key and the CLI flag — ``world.bbox (CLI --bbox W,S,E,N)``, ``planner.max_agl
(--max-agl)``, ``(mission file: planner.agl; CLI: --agl)``. Not every command
has every flag (``fm2uav run`` takes the flight level from the mission file,
``fm2uav export --mission`` has no world flags), so
:func:`~fm2uav.cli._common.handle_errors` passes each message through
:func:`for_command` with the flags of the command that raised it:

* a flag the command lacks is dropped where the message also names its key:
  inside a parenthesis of flags (``(CLI --bbox W,S,E,N)``, ``(--max-agl)``,
  ``CLI: --agl, --min-agl``: the flag with its value; an empty parenthesis goes)
  and in ``key / --flag``;
* anywhere else it becomes its mission-file key (:data:`FLAG_KEYS`);
* flags the command has are left as they are.

``tests/cli/test_flags.py`` walks every message in ``src/`` that names a flag and
checks, for each command that can raise it, that what the user reads names only
that command's flags.
"""

from __future__ import annotations

import re
from collections.abc import Collection

__all__ = ["FLAG_KEYS", "FLAG", "FOREIGN_FLAGS", "for_command", "flags_in"]

#: A flag in running text (``--max-agl``; not ``--`` alone).
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9]*(?:-[a-z0-9]+)*")

#: Flags of other programs that messages name (``gdalwarp --config ...``): left alone.
FOREIGN_FLAGS = frozenset({"--config"})

#: CLI flag → the mission-file key that sets the same thing (docs/operator.md §6).
FLAG_KEYS = {
    # world
    "--scenario": "world.scenario", "--seed": "world.seed", "--anchor": "world.anchor",
    "--dem": "world.dem", "--buildings": "world.buildings", "--bbox": "world.bbox",
    "--sea-level": "world.sea_level", "--cell-size": "world.cell_size", "--dz": "world.dz",
    "--ceiling": "world.ceiling", "--nodata": "world.nodata",
    "--nodata-value": "world.nodata_value", "--crs": "world.crs",
    "--default-height": "world.default_height", "--allow-filled": "world.allow_filled",
    # points and route
    "--start": "start", "--goal": "goal", "--via": "via", "--return": "return",
    # planner
    "--saturation": "planner.saturation", "--exponent": "planner.exponent",
    "--saturation-distance": "planner.saturation_distance", "--order": "planner.order",
    "--agl": "planner.agl", "--p1": "planner.p1", "--p2": "planner.p2",
    "--band": "planner.band", "--graded": "planner.graded", "--mode": "planner.mode",
    "--min-agl": "planner.min_agl", "--max-agl": "planner.max_agl", "--step": "planner.step",
    "--storage": "planner.storage", "--threads": "planner.threads",
    # zones
    "--no-fly": "no_fly_zones",
    # airframe
    "--vehicle": "airframe.type", "--firmware": "airframe.firmware",
    "--cruise-speed": "airframe.cruise_speed", "--hover-speed": "airframe.hover_speed",
    "--min-speed": "airframe.min_speed", "--endurance": "airframe.endurance",
    "--reserve": "airframe.reserve",
    # safe returns
    "--rally": "rally", "--rally-file": "rally", "--return-min-agl": "returns.min_agl",
    "--strict": "returns.strict", "--returns": "returns.enabled",
    "--no-returns": "returns.enabled",
    # energy and wind
    "--power": "airframe.power", "--battery": "airframe.battery", "--wind": "wind",
    "--wind-file": "wind.file",
    # outputs
    "--out": "outputs.dir", "--frame": "outputs.frame", "--end": "outputs.end",
    "--speed-changes": "outputs.speed_changes", "--thin": "outputs.thin_tolerance",
    "--format": "outputs.formats",
}


_PAREN = re.compile(r"\s*\(([^()]*)\)")
# the separator before a flag in a list of flags (each item: a flag and its value words)
_ITEMS = re.compile(r"(,\s*|\s*/\s*|\s+or\s+|\s+)(?=--[a-z])")
_CLI = re.compile(r"^\W*(CLI\W*)?$")  # what is left of "CLI: " without its flags
_CLI_TAIL = re.compile(r"[\s,;:/]*(\bCLI\b\W*)?$")  # ", CLI " before flags that are gone
_KEY = r"[a-z_]+(?:\.[a-z_]+)+|no_fly_zones|start|goal"
_KEY_SLASH_FLAG = re.compile(rf"({_KEY})\s*/\s*({FLAG.pattern})")
_FLAG_SLASH_KEY = re.compile(rf"({FLAG.pattern})\s*/\s*({_KEY})(?![\w.])")
_KEY_TWICE = re.compile(rf"(?<![\w.])({_KEY}) \(\1\)")


def flags_in(text: str) -> list[str]:
    """The flags of fm2uav named in ``text``, in order (with repeats; not
    :data:`FOREIGN_FLAGS`)."""
    return [f for f in FLAG.findall(text) if f not in FOREIGN_FLAGS]


def _drop_items(segment: str, accepted: Collection[str]) -> str:
    """``segment`` of a parenthesis (``CLI: --a X, --b``, ``world.crs, --crs``) without the
    flags it lists that are not accepted, each with its value words; "" if nothing is left."""
    first = next(m for m in FLAG.finditer(segment) if m.group(0) not in FOREIGN_FLAGS)
    head, rest = segment[:first.start()], segment[first.start():]
    parts = _ITEMS.split(rest)  # item, separator, item, ...
    items, seps = parts[0::2], parts[1::2]
    kept: list[str] = []
    for k, item in enumerate(items):
        if all(f in accepted or f in FOREIGN_FLAGS for f in flags_in(item)):
            if kept:
                kept.append(seps[k - 1])
            kept.append(item)
    if kept:
        return head + "".join(kept)
    return "" if _CLI.match(head) else _CLI_TAIL.sub("", head)


def _parenthesis(match: re.Match[str], accepted: Collection[str]) -> str:
    whole, inner = match.group(0), match.group(1)
    if all(f in accepted for f in flags_in(inner)):
        return whole
    out = []
    for seg in inner.split(";"):
        if flags_in(seg):
            seg = _drop_items(seg, accepted)
            if not seg.strip():
                continue
        out.append(seg)
    if not out:
        return ""
    lead = whole[:len(whole) - len(whole.lstrip())]
    return f"{lead}({';'.join(out).strip()})"


def for_command(message: str, accepted: Collection[str]) -> str:
    """``message`` as the user of a command with the flags ``accepted`` should read it.

    Parameters
    ----------
    message : str
        An error or warning text.
    accepted : collection of str
        The command's flags (``--out``, ``--no-fly``, ...).

    Returns
    -------
    str
        The message without the flags the command lacks (see the module docstring).

    Examples
    --------
    >>> m = "crop it with world.bbox (CLI --bbox W,S,E,N) or raise planner.max_agl (--max-agl)"
    >>> for_command(m, {"--max-agl"})
    'crop it with world.bbox or raise planner.max_agl (--max-agl)'
    >>> for_command("give --agl too", {"--out"})
    'give planner.agl too'
    """
    if all(f in accepted for f in flags_in(message)):
        return message
    text = _KEY_SLASH_FLAG.sub(lambda m: m.group(0) if m.group(2) in accepted else m.group(1),
                               message)
    text = _FLAG_SLASH_KEY.sub(lambda m: m.group(0) if m.group(1) in accepted else m.group(2),
                               text)
    text = _PAREN.sub(lambda m: _parenthesis(m, accepted), text)
    text = FLAG.sub(lambda m: m.group(0) if m.group(0) in accepted or m.group(0) in FOREIGN_FLAGS
                    else FLAG_KEYS.get(m.group(0), m.group(0)), text)

    return _KEY_TWICE.sub(r"\1", text)

