"""The user's own files that the docs' commands name, made for the doc runs
(tests/repo/docs_run.py), and the producers of quoted outputs that need several runs.

* :data:`FILES`: file name (as the docs write it, relative to the workspace) → a function
  writing such a file there. A doc command that names ``country.tif`` gets one: the
  country-shaped DEM of tests/world/dem_cases.py. Add a line here when a doc names a new file.
* :data:`OVERRIDES`: files of the repository's ``examples/`` replaced in the workspace by a
  smaller equivalent, each with its reason (the documented command runs verbatim on them).
* :data:`PRODUCERS`: ``@name`` in an ``output`` marker → a function returning the text that
  the quoted block must be found in.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from tests.world import dem_cases as dc
from tests.world import geodata_data as gd

#: The town DEM: gentle ground (240-275 m) around the OSM buildings, UTM 32N, 30 m pixels.
TOWN = (10.095, 45.575, 10.145, 45.625)


def town_dem(path: Path) -> Path:
    from pyproj import Transformer
    from rasterio.transform import from_origin

    fwd = Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)
    inv = Transformer.from_crs("EPSG:32632", "EPSG:4326", always_xy=True)
    x0, y0 = fwd.transform(TOWN[0], TOWN[1])
    x1, y1 = fwd.transform(TOWN[2], TOWN[3])
    res = 30.0
    cols, rows = int((x1 - x0) / res), int((y1 - y0) / res)
    t = from_origin(x0, y1, res, res)
    c, r = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    lon, lat = inv.transform(*(t * (c, r)))
    z = 250.0 + 15.0 * np.sin((lon - 10.1) * 250.0) * np.cos((lat - 45.6) * 180.0) \
        + 200.0 * (lat - 45.575)
    return gd._write(path, z, "EPSG:32632", t)


def osm_buildings(path: Path) -> Path:
    """OpenStreetMap-style footprints in lon/lat (RFC 7946): 3 x 4 blocks in the town, some
    with ``height``, some with ``building:levels``, most with neither."""
    feats = []
    for i in range(3):
        for j in range(4):
            lon, lat = 10.1155 + 0.0025 * i, 45.5965 + 0.0022 * j
            dx, dy = 0.00026, 0.00014
            props = {"building": "yes"}
            if (i + j) % 5 == 0:
                props["height"] = "14 m"
            elif (i + j) % 5 == 1:
                props["building:levels"] = "4"
            ring = [[lon - dx, lat - dy], [lon + dx, lat - dy], [lon + dx, lat + dy],
                    [lon - dx, lat + dy], [lon - dx, lat - dy]]
            feats.append({"type": "Feature", "properties": props,
                          "geometry": {"type": "Polygon", "coordinates": [ring]}})
    path.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))
    return path


def field_kml(path: Path) -> Path:
    """A survey area drawn in Google Earth (KML, lon/lat) on the town DEM."""
    ring = [(10.1030, 45.6050), (10.1095, 45.6046), (10.1100, 45.6092), (10.1036, 45.6097)]
    coords = " ".join(f"{lo},{la},0" for lo, la in ring + ring[:1])
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2">'
        "<Document><Placemark><name>field</name><Polygon><outerBoundaryIs><LinearRing>"
        f"<coordinates>{coords}</coordinates></LinearRing></outerBoundaryIs></Polygon>"
        "</Placemark></Document></kml>\n")
    return path


def field_map_metres(path: Path) -> Path:
    """A survey area on the built-in coverage map, in the map's metres (a GeoJSON without CRS
    on a synthetic map is read in its metres, docs/operator.md)."""
    ring = [[250.0, 200.0], [700.0, 180.0], [760.0, 520.0], [300.0, 560.0], [250.0, 200.0]]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "field"},
         "geometry": {"type": "Polygon", "coordinates": [ring]}}]}))
    return path


def spiky_dem(path: Path) -> Path:
    """A UTM 30N relief with one pixel 2000 m below its neighbours (a data error)."""
    from tests.e2e.conftest import relief, write_dem

    z = relief()
    z[12, 12] = -2000.0
    return write_dem(path, z)


def no_height(path: Path) -> Path:
    """One building footprint (lon/lat) with neither ``height`` nor ``building:levels``."""
    ring = [[10.12, 45.60], [10.1204, 45.60], [10.1204, 45.6003], [10.12, 45.6003], [10.12, 45.60]]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"building": "yes"},
         "geometry": {"type": "Polygon", "coordinates": [ring]}}]}))
    return path


def airports(path: Path) -> Path:
    """A no-fly polygon near the default anchor (lon/lat)."""
    ring = [[-3.770, 40.328], [-3.766, 40.328], [-3.766, 40.331], [-3.770, 40.331],
            [-3.770, 40.328]]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "airport"},
         "geometry": {"type": "Polygon", "coordinates": [ring]}}]}))
    return path


def danger_kml(path: Path) -> Path:
    ring = [(-3.760, 40.336), (-3.757, 40.336), (-3.757, 40.338), (-3.760, 40.338)]
    coords = " ".join(f"{lo},{la},0" for lo, la in ring + ring[:1])
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2">'
        "<Document><Placemark><name>danger</name><Polygon><outerBoundaryIs><LinearRing>"
        f"<coordinates>{coords}</coordinates></LinearRing></outerBoundaryIs></Polygon>"
        "</Placemark></Document></kml>\n")
    return path


#: A sweep of the same kind as examples/sweeps/city2d_small.yaml, small enough for a test:
#: 1 pair, alpha and beta in {0.5, 1.0} (4 FM² plans) against the Dubins reference.
LIGHT_SWEEP = """\
# examples/sweeps/city2d_small.yaml, made small for the doc run (tests/repo/docs_data.py)
scenario: city2d
cell: 2.0
pairs: 1
pair_seed: 0
alpha: {start: 0.5, stop: 1.0, step: 0.5}
beta: {start: 0.5, stop: 1.0, step: 0.5}
models: [dubins]
xi: 10.0
results: results.csv
"""


def huge_sweep(path: Path) -> Path:
    """docs/sweeps.md: a sweep refused for its size (10^17 cases)."""
    path.write_text("pairs: 1000\nalpha: {start: 1.0e-7, stop: 1, step: 1.0e-7}\n"
                    "beta: {start: 1e-7, stop: 1, step: 1e-7}\n")
    return path


def light_sweep(path: Path) -> Path:
    path.write_text(LIGHT_SWEEP)
    return path


def addresses(path: Path) -> Path:
    """docs/operator.md section 11: delivery addresses on the built-in 2D city (lon/lat at
    the default anchor): 40 seeded points of its free streets, one on a building, one off
    the map."""
    from fm2uav.scenarios import get_scenario
    from fm2uav.world.geo import to_lonlat

    w = get_scenario("city2d").world
    free = np.argwhere(~w.occupancy)
    rng = np.random.default_rng(27)
    pts = w.to_world(free[rng.choice(len(free), 40, replace=False)].astype(float))
    built = w.to_world(np.argwhere(w.occupancy)[0].astype(float))
    pts = np.vstack([pts, built, [-60.0, 20.0]])
    ll = to_lonlat(w, pts)
    rows = [f"{lo:.8f},{la:.8f},addr-{k + 1:02d}" for k, (lo, la) in enumerate(ll[:, :2])]
    path.write_text("lon,lat,id\n" + "\n".join(rows) + "\n")
    return path


FILES = {
    "addresses.csv": addresses,
    "country.tif": dc.country,
    "neighbour_90m.tif": dc.neighbour,
    "coast.tif": gd.topo_bathy,
    "other.tif": gd.topo_bathy,
    "dem.tif": town_dem,
    "terrain.tif": town_dem,
    "osm.geojson": osm_buildings,
    "field.kml": field_kml,
    "field.geojson": field_map_metres,
    "srtm_voids.tif": dc.srtm_voids,
    "spiky.tif": spiky_dem,
    "map.tif": dc.rgb,
    "noheight.geojson": no_height,
    "airports.geojson": airports,
    "danger.kml": danger_kml,
    "sweep.yaml": light_sweep,
    "huge.yaml": huge_sweep,
}

#: examples/ files replaced in the workspace, and why.
OVERRIDES = {
    # 400 FM² plans and 12 reference paths take about a minute on 2 cores; the documented
    # commands (`fm2uav sweep examples/sweeps/city2d_small.yaml ...`) run verbatim on 4 plans
    "examples/sweeps/city2d_small.yaml": light_sweep,
}


def mission_errors(ws) -> str:
    """docs/operator.md section 7: the mission-file errors quoted there, each from an
    ``m.yaml`` holding that mistake (``fm2uav run m.yaml`` in a folder of its own)."""
    from typer.testing import CliRunner

    from fm2uav.cli import app

    cases = {
        "saturation": "world: {scenario: open-field}\nplanner: {saturation: 1.5}\n",
        "scenario": "world: {scenario: moon}\n",
        "crs": "world: {dem: dem.tif}\nstart: {lon: 1, lat: 1, agl: 50}\n"
               "goal: {lon: 1.01, lat: 1.01, agl: 50}\n",
        "lon": "world: {scenario: open-field}\nstart: {lon: 200, lat: 40, agl: 100}\n",
    }
    out = []
    import os

    for name, text in cases.items():
        d = ws.path / "mission-errors" / name
        d.mkdir(parents=True, exist_ok=True)
        (d / "m.yaml").write_text(text)
        if name == "crs":
            import warnings

            import rasterio
            import rasterio.errors

            from tests.e2e.conftest import relief

            z = relief().astype("float32")
            with warnings.catch_warnings():  # no CRS, no transform: the point of the case
                warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
                with rasterio.open(d / "dem.tif", "w", driver="GTiff", height=z.shape[0],
                                   width=z.shape[1], count=1, dtype="float32") as f:
                    f.write(z, 1)
        old = os.getcwd()
        os.chdir(d)
        try:
            res = CliRunner(env={"COLUMNS": "4000"}).invoke(app, ["run", "m.yaml", "--out", "o"])
        finally:
            os.chdir(old)
        out.append(res.output)
    return "\n".join(out)


PRODUCERS = {"mission-errors": mission_errors}
