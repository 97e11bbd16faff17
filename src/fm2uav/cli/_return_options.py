"""The safe-return flags of ``fm2uav plan`` and ``fm2uav run``, defined once.

``--rally LON,LAT[,AGL]`` (repeatable) or ``--rally auto[:K]``, ``--rally-file FILE``,
``--return-min-agl M``, ``--strict``, ``--returns/--no-returns``: the names of the
mission file's ``rally:`` and ``returns:`` keys (for ``fm2uav run`` the flags add to
or override the file's). :meth:`ReturnFlags.options` builds the
:class:`~fm2uav.autopilot.safe_return.ReturnOptions` once the world is known.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated, Any

import typer

from .options import option_group

__all__ = ["ReturnFlags", "return_options"]

_P = "Safe returns"

RallyOpt = Annotated[list[str] | None, typer.Option(
    "--rally", rich_help_panel=_P, show_default=False, metavar="LON,LAT[,AGL]|auto[:K]",
    help="A rally point: LON,LAT (degrees) and optionally its approach height above the "
         "ground (m), repeatable; or auto[:K] to let the planner choose K (default 3) open, "
         "reachable places that bound the worst way back (mission file rally:).")]
RallyFileOpt = Annotated[Path | None, typer.Option(
    "--rally-file", rich_help_panel=_P, show_default=False, metavar="FILE",
    help="Rally points from a file: GeoJSON/KML/GPKG/SHP points (property agl: approach "
         "height) or CSV lon,lat[,agl] (mission file rally: FILE).")]
MinAglOpt = Annotated[float | None, typer.Option(
    "--return-min-agl", rich_help_panel=_P, show_default=False,
    help="Lowest height (m) above the surface of the firmware's straight return lines "
         "(returns.min_agl). Default: --min-agl, else the cruise floor (agl - tolerance).")]
StrictOpt = Annotated[bool, typer.Option(
    "--strict", rich_help_panel=_P,
    help="Fail (exit 1, nothing written) when the mission passes its point of no return "
         "before its end (returns.strict).")]
ReturnsOpt = Annotated[bool | None, typer.Option(
    "--returns/--no-returns", rich_help_panel=_P, show_default=False,
    help="Compute the safe returns: ways back, point of no return, rally points, firmware "
         "return settings (mission.param) (returns.enabled). Default: on.")]


@dataclass(frozen=True)
class ReturnFlags:
    """The safe-return flags as given."""

    rally: list[str] | None = None
    rally_file: Path | None = None
    return_min_agl: float | None = None
    strict: bool = False
    enabled: bool | None = None

    def check(self) -> None:
        """Refuse a malformed ``--rally`` before any work (InputError naming it)."""
        for text in self.rally or ():  # the rally reader only for a --rally given
            from ..io.rally import parse_rally_text

            parse_rally_text(text)
        if self.return_min_agl is not None and not self.return_min_agl >= 0:
            from ..errors import InputError

            raise InputError(f"--return-min-agl must be >= 0 m, got {self.return_min_agl:g}")

    def options(self, world: Any, *, base: Any = None, anchor: Any = None,
                crs: str | None = None) -> Any:
        """The :class:`~fm2uav.autopilot.safe_return.ReturnOptions`: ``base`` (a mission
        file's, default the defaults) with the flags given, rally sites in metres.

        Raises
        ------
        InputError
            A ``--rally`` value that is neither LON,LAT[,AGL] nor auto[:K]; an
            unreadable ``--rally-file``.
        """
        from ..autopilot.safe_return import ReturnOptions
        from ..io.rally import parse_rally_text, read_rally_sites
        from ..world.geo import from_lonlat

        opt = base if base is not None else ReturnOptions()
        sites = list(opt.rally)
        auto = opt.auto_rally
        for text in self.rally or ():
            v = parse_rally_text(text)
            if v[0] == "auto":
                auto = int(v[1])
                continue
            xy = from_lonlat(world, [[v[0], v[1]]], anchor=anchor)[0]
            sites.append((float(xy[0]), float(xy[1]), v[2]))
        if self.rally_file is not None:
            sites += read_rally_sites(self.rally_file, world, anchor=anchor, crs=crs)
        changes: dict[str, Any] = {"rally": tuple(sites), "auto_rally": auto}
        if self.return_min_agl is not None:
            changes["min_agl"] = float(self.return_min_agl)
        if self.strict:
            changes["strict"] = True
        if self.enabled is not None:
            changes["enabled"] = bool(self.enabled)
        return replace(opt, **changes)


#: ``@return_options``: the safe-return flags in place of the command's ``returns``
#: parameter, passed as one :class:`ReturnFlags`.
return_options = option_group("returns", [
    ("rally", RallyOpt, None), ("rally_file", RallyFileOpt, None),
    ("return_min_agl", MinAglOpt, None), ("strict", StrictOpt, False),
    ("enabled", ReturnsOpt, None),
], ReturnFlags)
