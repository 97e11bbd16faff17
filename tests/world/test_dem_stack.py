"""DEMs in priority order (issue 25 deliverable 2): a 5 m survey with lakes over a 30 m
national model in another CRS, a country-shaped DEM over its neighbour's — which DEM
measures each point, checked against an independent reading of the files."""

from __future__ import annotations

import numpy as np
import pytest
import rasterio
from pyproj import Transformer
from rasterio.transform import from_origin

from fm2uav import World
from fm2uav.errors import InputError
from fm2uav.world.dem import GeodataWarning
from fm2uav.world.load import WorldSpec, load_world

from . import dem_cases as dc

# the survey: 5 m pixels, UTM 32N, a 2 x 1.5 km patch inside the national model
SX0, SY1 = 585000.0, 5052000.0
SURVEY_COLS, SURVEY_ROWS, SURVEY_PX = 400, 300, 5.0
INV = Transformer.from_crs("EPSG:32632", "EPSG:4326", always_xy=True)
FWD = Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)


def _survey(path, lakes=True):
    t = from_origin(SX0, SY1, SURVEY_PX, SURVEY_PX)
    c, r = np.meshgrid(np.arange(SURVEY_COLS) + 0.5, np.arange(SURVEY_ROWS) + 0.5)
    lon, lat = INV.transform(*(t * (c, r)))
    z = dc.country_ground(lon, lat)
    if lakes:  # lidar returns nothing from water: two NaN lakes
        z[40:90, 50:140] = np.nan
        z[200:260, 300:380] = np.nan
    return dc.write(path, z, "EPSG:32632", t, nodata=np.nan)


def _national(path, offset=0.0):
    """30 m lon/lat model over the whole area (1 arc-second)."""
    t, lon, lat = dc.lonlat_grid(10.02, 45.65, 1 / 3600, 400, 600)
    return dc.write(path, dc.country_ground(lon, lat) + offset, "EPSG:4326", t)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("stack")
    return {"survey": _survey(d / "survey.tif"), "national": _national(d / "national.tif"),
            "national+40": _national(d / "national40.tif", 40.0),
            "country": dc.country(d / "country.tif"), "neighbour": dc.neighbour(d / "nb.tif"),
            "far": dc.svalbard(d / "far.tif"), "dir": d}


def _expected_source(files_in_order, world, x, y):
    """Independently: the index of the first file measuring each point, -1 for none."""
    pts = np.column_stack([x, y])
    out = np.full(len(x), -1)
    for k, f in enumerate(files_in_order):
        m = dc.measured_mask(f, world, pts) & (out < 0)
        out[m] = k
    return out


def _sample(tif, world, x, y):
    from scipy import ndimage

    with rasterio.open(tif) as ds:
        z = ds.read(1).astype(float)
        inv = ~ds.transform
        crs = ds.crs.to_wkt()
    px, py = Transformer.from_crs(world.crs, crs, always_xy=True).transform(x, y)
    col, row = inv * (np.asarray(px), np.asarray(py))
    return ndimage.map_coordinates(np.nan_to_num(z, nan=-1e9), [row - 0.5, col - 0.5], order=1,
                                   mode="nearest")


def test_a_survey_with_lakes_over_a_national_model(files):
    with pytest.raises(Exception, match="nodata/NaN under"):
        World.from_dem(files["survey"], 10.0)
    w = World.from_dem(files["survey"], 10.0, fill=[files["national"]])
    assert not w.filled.any()  # the lakes are measured by the national model
    dem, fill = w.georef.sources
    assert dem.role == "dem" and fill.role == "dem_fill" and fill.details["priority"] == 2
    assert fill.details["measured_nodes"] > 0 and dem.details["measured_nodes"] > 0
    assert dem.details["measured_nodes"] + fill.details["measured_nodes"] == w.filled.size
    rng = np.random.default_rng(0)
    b = w.bounds
    x = rng.uniform(b[0, 0], b[0, 1], 3000)
    y = rng.uniform(b[1, 0], b[1, 1], 3000)
    src = w.ground_source(x, y)
    want = _expected_source([files["survey"], files["national"]], w, x, y)
    np.testing.assert_array_equal(src, want)
    assert (src == 0).sum() > 2000 and (src == 1).sum() > 100
    h = w.ground_height(x, y)
    for k, f in enumerate([files["survey"], files["national"]]):
        np.testing.assert_allclose(h[src == k], _sample(f, w, x[src == k], y[src == k]),
                                   atol=1e-3)


def test_a_datum_step_between_the_dems_is_said(files):
    with pytest.warns(GeodataWarning, match=r"lies \+40\.0 m \(median\) from the DEM .*"
                                            r"different vertical datums"):
        w = World.from_dem(files["survey"], 10.0, fill=[files["national+40"]])
    assert w.georef.sources[1].details["offset_to_dem_m"] == pytest.approx(40.0, abs=0.5)


def test_the_country_and_its_neighbour(files):
    w0 = World.from_dem(files["country"], 120.0, nodata="fill")
    w = World.from_dem(files["country"], 120.0, fill=[files["neighbour"]])
    assert w0.filled.any() and not w.filled.any()
    assert w.bounds.tolist()[:2] == w0.bounds.tolist()[:2]  # the map is the country's raster
    rng = np.random.default_rng(1)
    b = w.bounds
    x = rng.uniform(b[0, 0], b[0, 1], 3000)
    y = rng.uniform(b[1, 0], b[1, 1], 3000)
    np.testing.assert_array_equal(
        w.ground_source(x, y), _expected_source([files["country"], files["neighbour"]], w, x, y))
    # without the neighbour, the same points are unknown ground exactly where the country's
    # own pixels do not measure them
    np.testing.assert_array_equal(w0.ground_filled(x, y),
                                  ~dc.measured_mask(files["country"], w0, np.column_stack([x, y])))


def test_with_a_bbox_the_map_spans_every_dem(files):
    # a box larger than the survey: the national model carries the map beyond it
    box = (10.05, 45.58, 10.14, 45.62)
    w = World.from_dem(files["survey"], 20.0, fill=[files["national"]], bbox=box)
    x0, y0 = FWD.transform(box[0], box[1])
    assert w.bounds[0, 0] < SX0 - 1000 and not w.filled.any()
    assert (w.ground_source(*w.to_world([[1, 1, 0]])[0, :2]) == 1)


def test_a_fill_dem_elsewhere_is_refused_naming_the_key(files):
    with pytest.raises(InputError, match=r"world.dem_fill \(CLI --dem-fill\) number 1, the DEM "
                                         r"far.tif, does not overlap the map"):
        World.from_dem(files["survey"], 10.0, fill=[files["far"]])


def test_the_mission_keys(files, tmp_path):
    spec = WorldSpec.model_validate({"dem": "survey.tif", "dem_fill": ["national.tif"],
                                     "cell_size": 10.0},
                                    context={"base_dir": str(files["dir"])})
    assert spec.fill_sources() == [str(files["dir"] / "national.tif")]
    assert "gaps from national.tif" in spec.describe()
    w = load_world(spec)
    assert not w.filled.any() and w.ground is not None and len(w.ground.layers) == 2
    # tiles as one priority level: the national model cut in two halves
    with rasterio.open(files["national"]) as ds:
        z, t = ds.read(1), ds.transform
    a = dc.write(tmp_path / "west.tif", z[:, :300], "EPSG:4326", t)
    b = dc.write(tmp_path / "east.tif", z[:, 300:], "EPSG:4326",
                 t * rasterio.Affine.translation(300, 0))
    spec = WorldSpec.model_validate({"dem": str(files["survey"]),
                                     "dem_fill": [[str(a), str(b)]], "cell_size": 10.0})
    w2 = load_world(spec)
    np.testing.assert_allclose(w2.terrain, w.terrain, atol=1e-3)
    with pytest.raises(ValueError, match="empty list of tiles"):
        WorldSpec.model_validate({"dem": str(files["survey"]), "dem_fill": [[]]})
