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

__all__ = ["Session", "dump_mission", "file_refs"]


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
