"""``fm2uav app``: the local web application (a map in the browser)."""

from __future__ import annotations

from pathlib import Path

import typer

from ._common import handle_errors
from .options import WorldFlags, world_options

APP_HELP = (
    "Open the planning map in the browser: a local web app on 127.0.0.1 (nothing is "
    "reachable from other machines). Load a DEM (and buildings), click start, goal and "
    "via points on the map, draw no-fly zones, set the height above ground and the "
    "airframe, plan, see the route coloured by height above ground with its profile, and "
    "download mission.plan, mission.waypoints, KML, GeoJSON and the report; save the "
    "session as a mission file that `fm2uav run` plans again to the same files. Runs "
    "until Ctrl-C.\n\n"
    "Examples:\n\n"
    "  fm2uav app --dem terrain.tif\n\n"
    "  fm2uav app --dem terrain.tif --buildings osm.geojson --port 8800\n\n"
    "  fm2uav app --mission examples/jacksboro_geotiff.yaml --no-browser\n\n"
    "The world options are those of `fm2uav plan`."
)


def initial_mission(world: WorldFlags, mission_file: Path | None, agl: float) -> dict:
    """The mission document the page starts with: ``--mission`` (its paths made
    absolute) with the world flags applied, or the world flags alone."""
    from ..io.mission import load_mission

    overrides = world.overrides() or {}
    for key in ("dem", "buildings"):
        v = overrides.get(key)
        if v is not None:
            overrides[key] = ([str(Path(p).resolve()) for p in v] if isinstance(v, list)
                              else str(Path(v).resolve()))
    if mission_file is None:
        world.spec()  # the flags' errors, as fm2uav plan says them
        return {"version": 1, "name": "mission", "world": overrides,
                "planner": {"agl": agl}}
    from ..app.session import file_refs

    m = load_mission(mission_file, world_overrides=overrides or None)  # errors as fm2uav run
    doc = m.model_dump(mode="json", by_alias=True, exclude_defaults=True)
    doc = {"version": 1, **doc}
    for keys, ref in file_refs(doc):  # the jobs' mission files live elsewhere: absolute paths
        target = doc
        for k in keys[:-1]:
            target = target[k]
        target[keys[-1]] = str(Path(ref).resolve())
    return doc


@handle_errors
@world_options
def app_cmd(
    port: int = typer.Option(8765, help="TCP port on 127.0.0.1 (0: a free one)."),
    no_browser: bool = typer.Option(False, "--no-browser",
                                    help="Do not open the browser; only print the URL."),
    mission: Path | None = typer.Option(
        None, "--mission", help="Start from this mission file (YAML, as `fm2uav run` takes).",
        show_default=False),
    agl: float = typer.Option(60.0, help="Height above ground (m) the page starts with."),
    folder: Path = typer.Option(
        Path("out/app"), "--dir", help="Session folder: uploaded files and every plan's "
        "mission file and outputs."),
    world: WorldFlags = None,
) -> None:
    """``fm2uav app``: the starting mission from the flags, then serve until Ctrl-C."""
    from ..app import serve
    from ._common import console

    doc = initial_mission(world, mission, agl)
    save_to = (mission if mission is not None else folder / "mission.yaml").resolve()

    def announce(url: str) -> None:
        console.print(f"fm2uav app: {url}  (Ctrl-C stops it)", highlight=False, soft_wrap=True)

    try:
        serve(doc, folder=folder, mission_path=save_to, port=port,
              open_browser=not no_browser, announce=announce)
    except KeyboardInterrupt:  # Ctrl-C is how the app stops: reported, exit 0
        from ..io._stops import stop_reported

        stop_reported()


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``app`` command."""
    app.command("app", help=APP_HELP)(app_cmd)
