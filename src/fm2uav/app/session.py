"""The app's working folder: uploaded files, the jobs' mission files and outputs, saving.

A session lives in one folder (``fm2uav app --dir``, default ``out/app``)::

    data/            files uploaded from the browser (DEMs, buildings, zones, areas)
    jobs/<id>/       mission.yaml the job ran (``fm2uav run`` input) and out/ (its outputs)

The page edits a mission document in the schema of mission files
(:mod:`fm2uav.io.mission`, data files named by absolute paths). Saving writes it
as YAML to the path the operator chose and copies the uploaded files it uses
beside it (named relative to it), so that ``fm2uav run SAVED.yaml`` plans the
same mission, from any folder, and writes the same ``.plan``.
"""

from __future__ import annotations

import copy
import re
import shutil
from pathlib import Path
from typing import Any

__all__ = ["Session", "dump_mission", "file_refs", "zones_geojson", "cover_command"]

#: Mission-file ``airframe:`` / ``outputs:`` keys → the command line's mission flags.
EXPORT_FLAGS = {"firmware": "firmware", "type": "vehicle", "frame": "frame", "end": "end",
                "thin_tolerance": "thin", "speed_changes": "speed_changes",
                "cruise_speed": "cruise_speed", "hover_speed": "hover_speed",
                "endurance": "endurance", "reserve": "reserve"}
#: The cover fields of the page → ``fm2uav cover`` flags.
COVER_FLAGS = ("agl", "spacing", "side_overlap", "front_overlap", "trigger_distance",
               "min_agl", "max_agl", "saturation_distance", "seed")


def dump_mission(doc: dict[str, Any]) -> str:
    """A mission document as YAML text (keys in the document's order; floats exact)."""
    import yaml

    return ("# fm2uav mission file written by `fm2uav app`; plan it with: fm2uav run FILE\n"
            + yaml.safe_dump(doc, sort_keys=False, allow_unicode=True, width=100))


def file_refs(doc: dict[str, Any]) -> list[tuple[list[Any], str]]:
    """``(key path, file)`` of every data file a mission document names.

    world.dem (one or a list), world.buildings, no_fly_zones entries (text or
    ``file:``) and operating_area.
    """
    out: list[tuple[list[Any], str]] = []
    world = doc.get("world") or {}
    dem = world.get("dem")
    if isinstance(dem, str):
        out.append((["world", "dem"], dem))
    elif isinstance(dem, list):
        out += [(["world", "dem", k], d) for k, d in enumerate(dem) if isinstance(d, str)]
    if isinstance(world.get("buildings"), str):
        out.append((["world", "buildings"], world["buildings"]))
    for k, z in enumerate(doc.get("no_fly_zones") or ()):
        if isinstance(z, str):
            out.append((["no_fly_zones", k], z))
        elif isinstance(z, dict) and isinstance(z.get("file"), str):
            out.append((["no_fly_zones", k, "file"], z["file"]))
    area = doc.get("operating_area")
    if isinstance(area, str):
        out.append((["operating_area"], area))
    elif isinstance(area, dict) and isinstance(area.get("file"), str):
        out.append((["operating_area", "file"], area["file"]))
    return out


def zones_geojson(entries: list[Any]) -> tuple[dict[str, Any] | None, list[str]]:
    """The page's drawn zones (mission-file entries with ``lonlat: true``) as one GeoJSON
    document for ``--no-fly`` (polygons; circles as points with a ``radius``), and the
    zone files among the entries."""
    feats, files = [], []
    for z in entries or ():
        if isinstance(z, str) or (isinstance(z, dict) and "file" in z):
            files.append(z if isinstance(z, str) else z["file"])
            continue
        props = {k: z[k] for k in ("name", "floor", "ceiling", "reference", "buffer")
                 if z.get(k) is not None}
        if "circle" in z:
            props["radius"] = z["circle"]["radius"]
            geom = {"type": "Point", "coordinates": list(z["circle"]["center"])}
        else:
            ring = [list(p) for p in z["polygon"]]
            geom = {"type": "Polygon", "coordinates": [ring + [ring[0]]]}
        feats.append({"type": "Feature", "properties": props, "geometry": geom})
    return ({"type": "FeatureCollection", "features": feats} if feats else None), files


def _flag(key: str) -> str:
    return "--" + key.replace("_", "-")


def _text(v: Any) -> str:
    return repr(float(v)) if isinstance(v, float) else str(v)


def cover_command(world: dict[str, Any], cover: dict[str, Any], export: dict[str, Any],
                  zones: list[str], camera: list[float] | None) -> list[str]:
    """The ``fm2uav cover`` arguments of a coverage job, run in its folder (files
    ``area.geojson``, ``zones.geojson``; outputs into ``out``)."""
    argv = ["fm2uav", "cover"]
    for key, v in world.items():
        if v is None or v is False:
            continue
        if key == "dem":
            for d in ([v] if isinstance(v, str) else v):
                argv += ["--dem", d]
        elif key == "bbox":
            argv += ["--bbox", ",".join(_text(float(x)) for x in v)]
        elif v is True:
            argv.append(_flag(key))
        else:
            argv += [_flag(key), _text(v)]
    argv += ["--area", "area.geojson"]
    for key in COVER_FLAGS:
        if cover.get(key) is not None:
            argv += [_flag(key), _text(cover[key])]
    if camera is not None:
        argv += ["--camera", ",".join(_text(v) for v in camera)]
    for z in zones:
        argv += ["--no-fly", z]
    for key, v in export.items():
        if key == "speed_changes":
            argv.append("--speed-changes" if v else "--no-speed-changes")
        else:
            argv += [_flag(key), _text(v)]
    return argv + ["--report", "--out", "out"]


def _set(doc: Any, keys: list[Any], value: Any) -> None:
    for k in keys[:-1]:
        doc = doc[k]
    doc[keys[-1]] = value


class Session:
    """The folder of one app session (see the module docstring).

    Parameters
    ----------
    root : path
        The session folder (created).
    mission : dict
        The mission document the page starts with.
    mission_path : path
        Where "Save" writes by default.
    """

    def __init__(self, root: str | Path, mission: dict[str, Any], mission_path: str | Path
                 ) -> None:
        self.root = Path(root).resolve()
        self.data = self.root / "data"
        self.jobs = self.root / "jobs"
        for d in (self.data, self.jobs):
            d.mkdir(parents=True, exist_ok=True)
        self.mission = mission
        self.mission_path = Path(mission_path).resolve()

    def upload(self, name: str, content: bytes) -> Path:
        """Store an uploaded file in ``data/`` (a safe name; an existing one is replaced)."""
        safe = re.sub(r"[^A-Za-z0-9._-]+", "_", Path(name).name).lstrip(".") or "upload"
        path = self.data / safe
        path.write_bytes(content)
        return path

    def job_files(self, job_id: str, doc: dict[str, Any]) -> tuple[Path, Path]:
        """Write the job's mission file; returns ``(mission file, output folder)``."""
        folder = self.jobs / job_id
        folder.mkdir(parents=True, exist_ok=True)
        mission_file = folder / "mission.yaml"
        mission_file.write_text(dump_mission(doc), encoding="utf-8")
        return mission_file, folder / "out"

    def cover_job(self, job_id: str, body: dict[str, Any]) -> dict[str, Any]:
        """Write a coverage job's files (``area.geojson``, ``zones.geojson``, the mission's
        world) and return the worker's payload with the equivalent command line."""
        import json
        import shlex

        from ..errors import InputError

        folder = self.jobs / job_id
        folder.mkdir(parents=True, exist_ok=True)
        doc = body.get("mission") or {}
        area = body.get("area")
        if not isinstance(area, list) or len(area) < 3:
            raise InputError("draw the survey area first (Survey panel: Draw area)")
        ring = [list(map(float, p)) for p in area]
        (folder / "area.geojson").write_text(json.dumps({
            "type": "FeatureCollection", "features": [{
                "type": "Feature", "properties": {"name": "survey area"},
                "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}]}))
        zones_doc, zone_files = zones_geojson(doc.get("no_fly_zones") or [])
        zones = list(zone_files)
        if zones_doc is not None:
            (folder / "zones.geojson").write_text(json.dumps(zones_doc))
            zones.insert(0, "zones.geojson")
        cover = dict(body.get("cover") or {})
        camera = cover.pop("camera", None)
        export = {EXPORT_FLAGS[k]: v for part in ("airframe", "outputs")
                  for k, v in (doc.get(part) or {}).items() if k in EXPORT_FLAGS}
        world = dict(doc.get("world") or {})
        argv = cover_command(world, cover, export, zones, camera)
        return {"world": world, "area": str(folder / "area.geojson"),
                "zones": [str(folder / z) for z in zones], "cover": {**cover, "camera": camera},
                "export": export, "out": str(folder / "out"), "folder": str(folder),
                "command": f"cd {shlex.quote(str(folder))} && "
                           + " ".join(shlex.quote(a) for a in argv)}

    def save(self, doc: dict[str, Any], target: str | Path) -> Path:
        """Write ``doc`` to ``target`` with the uploaded files it names copied beside it.

        Files uploaded into this session are copied next to the mission file and
        named by their file name; other files keep their absolute path.

        Raises
        ------
        InputError
            ``target`` is a folder or its folder cannot be written.
        """
        from ..errors import InputError

        target = Path(target).expanduser()
        if not target.is_absolute():
            target = Path.cwd() / target
        if target.suffix.lower() not in (".yaml", ".yml"):
            raise InputError(f"save as {target}: a mission file ends in .yaml or .yml")
        if target.is_dir():
            raise InputError(f"save as {target}: it is a folder; give a file name such as "
                             f"{target / 'mission.yaml'}")
        target.parent.mkdir(parents=True, exist_ok=True)
        out = copy.deepcopy(doc)
        for keys, ref in file_refs(doc):
            p = Path(ref)
            if p.is_absolute() and p.parent == self.data and p.is_file():
                dest = target.parent / p.name
                if dest.resolve() != p.resolve():
                    shutil.copyfile(p, dest)
                _set(out, keys, p.name)
        tmp = target.with_name(f".{target.name}.tmp")
        tmp.write_text(dump_mission(out), encoding="utf-8")
        tmp.replace(target)
        return target
