"""``returns.geojson``: the safe returns of a mission on a map (RFC 7946, lon/lat/alt).

A FeatureCollection, every altitude in metres above the world's vertical datum
(normally mean sea level), as the mission's own GeoJSON:

* ``home`` and each rally point (``kind: "rally"``): Points on the ground, with the
  rally point's written altitude and site facts;
* ``return from waypoint k``: the FM² way back from waypoint ``k`` (LineString, as
  timed: thinned to 1 m), with ``to``, ``time_s`` (landing included), ``length_m``;
* ``point of no return`` (Point) and ``return from the point of no return``
  (LineString) when the route has one.

Written from the mission's :class:`~fm2uav.autopilot.safe_return.ReturnsReport`;
:func:`read_returns` reads it back (the tests' independent checks start there).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..world.geo import to_lonlat

__all__ = ["returns_document", "write_returns", "read_returns"]


def _c(row: Any) -> list[float]:
    return [round(float(row[0]), 9), round(float(row[1]), 9), round(float(row[2]), 3)]


def _line(world: Any, anchor: Any, path: np.ndarray) -> list[list[float]]:
    return [_c(r) for r in to_lonlat(world, np.asarray(path, dtype=float), anchor=anchor)]


def returns_document(mission: Any) -> dict[str, Any]:
    """The FeatureCollection of a mission's returns (module docstring)."""
    rep = mission.returns
    world, anchor = mission.world, mission.options.anchor
    feats: list[dict[str, Any]] = []
    h = mission.waypoints.home
    feats.append({"type": "Feature", "properties": {"name": "home", "kind": "home"},
                  "geometry": {"type": "Point", "coordinates": [round(h[1], 9), round(h[0], 9),
                                                                round(h[2], 3)]}})
    alts = rep.firmware.rally_altitudes if rep.firmware is not None else {}
    for r in rep.rally:
        g = to_lonlat(world, [[r.point[0], r.point[1], r.ground]], anchor=anchor)[0]
        feats.append({"type": "Feature",
                      "properties": {"name": r.name, "kind": "rally", "chosen_by": r.chosen_by,
                                     "alt_relative_to_home_m": alts.get(r.name),
                                     "approach_agl_m": r.agl, **r.facts},
                      "geometry": {"type": "Point", "coordinates": _c(g)}})
    share = (rep.time / rep.endurance_s) if rep.endurance_s else None
    for i, w in enumerate(rep.samples.waypoint):
        if w < 0 or len(rep.paths[i]) < 2:
            continue
        props = {"name": f"return from waypoint {int(w)}", "kind": "return",
                 "waypoint": int(w), "to": rep.to[i], "time_s": round(float(rep.time[i]), 2),
                 "length_m": round(float(rep.length[i]), 2),
                 "t_mission_s": round(float(rep.samples.time[i]), 2)}
        if share is not None:
            props["battery_share"] = round(float(share[i]), 4)
        feats.append({"type": "Feature", "properties": props,
                      "geometry": {"type": "LineString",
                                   "coordinates": _line(world, anchor, rep.paths[i])}})
    pnr = rep.pnr
    if pnr.get("reached") and "point_m" in pnr:
        at = rep.pnr_path[:1] if rep.pnr_path is not None and len(rep.pnr_path) else \
            np.asarray([pnr["point_m"]])
        feats.append({"type": "Feature",
                      "properties": {"name": "point of no return", "kind": "pnr",
                                     **{k: v for k, v in pnr.items() if k != "point_m"}},
                      "geometry": {"type": "Point", "coordinates": _line(world, anchor, at)[0]}})
        if rep.pnr_path is not None and len(rep.pnr_path) >= 2:
            feats.append({"type": "Feature",
                          "properties": {"name": "return from the point of no return",
                                         "kind": "pnr-return", **pnr["return"]},
                          "geometry": {"type": "LineString",
                                       "coordinates": _line(world, anchor, rep.pnr_path)}})
    return {"type": "FeatureCollection", "features": feats}


def write_returns(fh: IO[str], mission: Any) -> dict[str, Any]:
    """Write :func:`returns_document`; returns the document."""
    doc = returns_document(mission)
    json.dump(doc, fh, indent=1, allow_nan=False)
    fh.write("\n")
    return doc


def read_returns(file: str | Path) -> dict[str, Any]:
    """The features of a ``returns.geojson`` by name: ``{name: (properties, coordinates)}``."""
    doc = json.loads(Path(file).read_text())
    return {f["properties"]["name"]: (f["properties"], f["geometry"]["coordinates"])
            for f in doc.get("features", [])}
