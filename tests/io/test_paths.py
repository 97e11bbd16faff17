"""Path CSVs: read by column name whatever the spreadsheet wrote (BOM, quotes, ';', units),
refused with the line and column when they cannot be read as metres."""

from __future__ import annotations

import io

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.io import read_path_csv, write_path_csv
from fm2uav.io.path_header import read_path_header, read_path_w

XYZ = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])


def _csv(tmp_path, text: str | bytes, name: str = "p.csv"):
    p = tmp_path / name
    (p.write_bytes if isinstance(text, bytes) else p.write_text)(text)
    return p


@pytest.mark.parametrize("text", [
    "x_m,y_m,z_m\n1,2,3\n4,5,6\n7,8,9\n",
    "y_m,x_m,z_m\n2,1,3\n5,4,6\n8,7,9\n",                       # another order: by name
    "z,y,x\n3,2,1\n6,5,4\n9,8,7\n",
    "\ufeffx_m,y_m,z_m\n1,2,3\n4,5,6\n7,8,9\n",                  # Excel's "CSV UTF-8" BOM
    '"X [m]","Y [m]","Z [m]"\n"1","2","3"\n4,5,6\n7,8,9\n',      # quotes and units
    "x (m);y (m);z (m)\n1;2;3\n4;5;6\n7;8;9\n",                  # ';' (decimal-comma locales)
    "x\ty\tz\n1\t2\t3\n4\t5\t6\n7\t8\t9\n",
    "# crs=EPSG:32630\n\nx_m,y_m,z_m,speed\n1,2,3,0.5\n4,5,6,1\n\n7,8,9,1\n",
    "1,2,3\n4,5,6\n7,8,9\n",                                    # no header: by position
])
def test_spreadsheet_variants_read_the_same_path(tmp_path, text):
    np.testing.assert_allclose(read_path_csv(_csv(tmp_path, text)), XYZ)


def test_bom_file_as_excel_writes_it(tmp_path):
    p = _csv(tmp_path, b"\xef\xbb\xbfy_m,x_m,z_m\r\n2,1,3\r\n5,4,6\r\n8,7,9\r\n")
    np.testing.assert_allclose(read_path_csv(p), XYZ)


def test_round_trip_with_every_column_fm2uav_writes(tmp_path):
    buf = io.StringIO()
    write_path_csv(buf, XYZ, np.array([0.2, 0.5, 1.0]), comment="crs=EPSG:32630",
                   floor=np.array([-np.inf, 30.0, -np.inf]))
    p = _csv(tmp_path, "\ufeff" + buf.getvalue())
    np.testing.assert_allclose(read_path_csv(p), XYZ, atol=1e-6)
    np.testing.assert_allclose(read_path_w(p), [0.2, 0.5, 1.0])
    assert read_path_header(p)["crs"] == "EPSG:32630"


@pytest.mark.parametrize("text, fragment", [
    ("lon,lat,alt\n-3.7,40.3,100\n-3.6,40.4,100\n", "read in world metres (x_m, y_m"),
    ("lon,lat,alt\n-3.7,40.3,100\n-3.6,40.4,100\n", "lon/lat degrees are not read"),
    ("x_m,north,z_m\n1,2,3\n4,5,6\n", "no y column"),
    ("east,north\n1,2\n3,4\n", "no x column"),
    ("x_m,y_m,z_m,heading\n1,2,3,4\n4,5,6,7\n", "unknown column 'heading'"),
    ("x_m,x_m,y_m\n1,2,3\n4,5,6\n", "appears twice"),
    ("x_m,y_m,z_m\n1,2,3\n4,5\n", "line 3: 2 values where the first row has 3"),
    ("x_m,y_m,z_m\n1,2,3\n4,five,6\n", "line 3: y_m = 'five' is not a number"),
    ("x_m,y_m,z_m\n1,2,3\n4,inf,6\n", "line 3: y_m = 'inf' is not a finite number"),
    ("x_m,y_m,z_m\n1,2,3\n", "at least 2 points, got 1"),
    ("x_m,y_m,z_m\n", "at least 2 points, got 0"),
    ("# only a comment\n\n", "is empty"),
    ("1\n2\n3\n", "has 1 column"),
])
def test_unreadable_paths_are_refused_naming_line_and_column(tmp_path, text, fragment):
    with pytest.raises(InputError) as err:
        read_path_csv(_csv(tmp_path, text))
    assert fragment in str(err.value) and "\n" not in str(err.value)


def test_a_speed_column_with_text_names_its_line(tmp_path):
    p = _csv(tmp_path, "x_m,y_m,speed\n1,2,0.5\n3,4,fast\n")
    with pytest.raises(InputError, match="line 3: the 'speed' column has a non-numeric value"):
        read_path_w(p)
