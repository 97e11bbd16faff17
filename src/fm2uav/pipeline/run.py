"""Run a mission file: world → FM² route → autopilot mission → output set.

:func:`run_mission` is what ``fm2uav run MISSION.yaml`` does once the options
are parsed, and what the web app's planning job does with the mission file it
wrote: one code path, so the app's downloads equal the files ``fm2uav run``
writes from the same mission file, byte for byte.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import progress
from .outputs import plan_outputs, wind_options, with_wind_on

__all__ = ["MissionRun", "run_mission", "with_zone_files"]


@dataclass(frozen=True)
class MissionRun:
    """What :func:`run_mission` planned and wrote.

    Attributes
    ----------
    mission : fm2uav.io.mission.Mission
        The validated mission.
    resolved : fm2uav.io.mission.ResolvedMission
        Its world (with the no-fly zones) and points in metres.
    route : fm2uav.missions.route.Route
        The FM² route (legs joined into ``route.plan``).
    info : dict
        The summary written to ``summary.json`` (plan, autopilot mission, safety figures).
    built : fm2uav.io.MissionExport
        The autopilot mission (items, waypoints, frame, home).
    world_name : str
        The scenario name or a description of the data.
    """

    mission: Any
    resolved: Any
    route: Any
    info: dict[str, Any]
    built: Any
    world_name: str

    @property
    def plan(self) -> Any:
        """The joined :class:`fm2uav.Plan` of the route."""
        return self.route.plan


def with_zone_files(resolved: Any, files: Sequence[str | Path]) -> Any:
    """The resolved mission with the zones of ``files`` (``--no-fly``) added to its world.

    Raises
    ------
    InputError
        A file that cannot be read, or a point inside one of its zones (named).
    """
    from ..io.zone_spec import zones_from_cli
    from ..world.zones import check_points_allowed, with_zones

    world = with_zones(resolved.world, zones_from_cli([str(f) for f in files], resolved.world))
    check_points_allowed(world, {"start": resolved.start, "goal": resolved.goal,
                                 **{f"via[{k}]": v for k, v in enumerate(resolved.via)}})
    return dataclasses.replace(resolved, world=world)


@progress.stage()
def run_mission(
    mission: Any,
    outdir: Any,
    *,
    mission_file: str | Path | None = None,
    options: Any = None,
    planner: dict[str, Any] | None = None,
    no_fly: Sequence[str | Path] = (),
    formats: Sequence[str] | None = None,
    returns: Any = None,
) -> MissionRun:
    """Plan ``mission`` and write its output set (``outputs.formats``) into ``outdir``.

    Parameters
    ----------
    mission : fm2uav.io.mission.Mission
        From :func:`fm2uav.io.mission.load_mission`.
    outdir : fm2uav.io.outdir.OutputDir
        The output set (checked for the mission's file names by the caller).
    mission_file : path, optional
        Recorded in ``summary.json``.
    options : fm2uav.io.ExportOptions, optional
        Default: ``mission.export_options()`` (the CLI passes them with its flags applied).
    planner : dict, optional
        Planner keys overriding ``mission.plan_kwargs()`` (the CLI's ``--min-agl``, ...).
    no_fly : sequence of paths, optional
        More no-fly zone files (``--no-fly``).
    formats : sequence of str, optional
        The output formats (default ``outputs.formats``; ``fm2uav run --report`` adds
        ``html``).
    returns : callable, optional
        ``returns(mission, world) -> ReturnOptions``: the safe returns asked for (the
        CLI's ``--rally``, ``--strict``, ... on the mission file's ``rally:`` /
        ``returns:``); default ``mission.return_options(world)``.

    Returns
    -------
    MissionRun

    Raises
    ------
    fm2uav.Fm2uavError
        As ``fm2uav run`` reports them: the world, a point, the planner, the
        firmware's rules (the messages name the mission-file keys).
    """
    from ..missions.route import plan_route
    from ..planning.params import planner_objects
    from ..world.load import world_summary

    options = mission.export_options() if options is None else options
    formats = list(dict.fromkeys(mission.outputs.formats if formats is None else formats))
    progress.step("building the world", 0.15)
    rm = mission.resolve()
    if no_fly:
        rm = with_zone_files(rm, no_fly)
    legs = len(rm.via) + 1 + rm.return_to_start
    progress.step("planning (FM²)" + (f", {legs} legs" if legs > 1 else ""), 0.55)
    shaping, level, popts = planner_objects({**mission.plan_kwargs(), **(planner or {})})
    options = with_wind_on(options, rm.world)
    route = plan_route(rm.world, rm.start, rm.goal, via=rm.via,
                       return_to_start=rm.return_to_start, shaping=shaping, level=level,
                       options=popts, wind=wind_options(options))
    world_name = mission.world.scenario or mission.world.describe()
    progress.step("writing the mission files", 0.3)
    ret = (returns(mission, rm.world) if returns is not None
           else mission.return_options(rm.world))
    info, built = plan_outputs(
        outdir, route.plan, formats, options, title=f"{mission.name}",
        subtitle=f"{world_name} — {mission.description}" if mission.description
        else world_name,
        summary={"mission": mission.name,
                 **({"mission_file": str(mission_file)} if mission_file is not None
                    else {}),
                 "world": {**world_summary(rm.world), "name": world_name},
                 "route": route.summary()},
        via=route.junctions[1:-1], returns=ret)
    return MissionRun(mission=mission, resolved=rm, route=route, info=info, built=built,
                      world_name=world_name)
