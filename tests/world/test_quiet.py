"""Library warnings on the DEM path: captured, said once in our words or not at all."""

from __future__ import annotations

import logging
import warnings

import pytest

from fm2uav.world.quiet import GeodataWarning, library_warnings


def test_library_noise_is_dropped_ours_kept_once_and_gdal_said_once():
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with library_warnings("the DEM x.tif"):
            warnings.warn("You will likely lose important projection information", UserWarning)
            warnings.warn("All-NaN slice encountered", RuntimeWarning)
            warnings.warn("ours", GeodataWarning)
            warnings.warn("ours", GeodataWarning)
            for _ in range(3):
                logging.getLogger("rasterio._env").warning("TIFFReadDirectory: bad tag %d", 1)
            logging.getLogger("rasterio._env").warning("another message")
    msgs = [(w.category, str(w.message)) for w in seen]
    assert (GeodataWarning, "ours") in msgs and len(msgs) == 2
    gdal = [m for c, m in msgs if m.startswith("GDAL had to work around")]
    assert gdal == ["GDAL had to work around something reading the DEM x.tif: TIFFReadDirectory: "
                    "bad tag 1; another message; the data were read, but check the file "
                    "(gdalinfo FILE)"]
    assert logging.getLogger("rasterio").propagate  # left as it was


def test_our_warnings_still_come_when_the_block_fails():
    with pytest.warns(GeodataWarning, match="said before the error"):
        with pytest.raises(ValueError):
            with library_warnings("the DEM x.tif"):
                warnings.warn("said before the error", GeodataWarning)
                raise ValueError("refused")
