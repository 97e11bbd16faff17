"""KML and KMZ export (3D, for Google Earth).

A Document with the path as an absolute-altitude LineString (extruded to the
ground, so the flight height is visible as a curtain), the thinned waypoints
as a second line, and start/goal Placemarks. KML coordinates are
``lon,lat,alt`` with alt in metres above mean sea level. A world whose altitude
above sea level is unknown (buildings without a DEM or a ground elevation,
:func:`fm2uav.world.geo.amsl_known`) is written ``relativeToGround`` instead,
alt the height above the ground. A KMZ is the same document zipped as
``doc.kml`` (the KML 2.2 convention for the main file).
"""

from __future__ import annotations

import io
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import IO, Any
from xml.sax.saxutils import escape

import numpy as np

from ..errors import InputError
from ..world.geo import Anchor, amsl_known, to_lonlat

__all__ = ["kml_document", "write_kml", "write_kmz", "read_kml_path"]

_NS = "http://www.opengis.net/kml/2.2"


def _coord_text(geo: np.ndarray) -> str:
    return " ".join(f"{lo:.9f},{la:.9f},{al:.3f}" for lo, la, al in geo)


def _line(name: str, style: str, geo: np.ndarray, extrude: bool, mode: str = "absolute"
          ) -> str:
    return (
        f"<Placemark><name>{escape(name)}</name><styleUrl>#{style}</styleUrl>"
        f"<LineString><extrude>{int(extrude)}</extrude><tessellate>0</tessellate>"
        f"<altitudeMode>{mode}</altitudeMode><coordinates>{_coord_text(geo)}</coordinates>"
        "</LineString></Placemark>"
    )


def _point(name: str, geo: np.ndarray, mode: str = "absolute") -> str:
    return (
        f"<Placemark><name>{escape(name)}</name><Point><altitudeMode>{mode}</altitudeMode>"
        f"<coordinates>{_coord_text(geo[None])}</coordinates></Point></Placemark>"
    )


def _geo(world: Any, points: np.ndarray, anchor: Anchor | None) -> tuple[np.ndarray, str]:
    """lon, lat, alt of world points and the KML altitude mode: absolute (AMSL), or
    relativeToGround with the height above the ground where the datum is unknown."""
    geo = to_lonlat(world, points, anchor=anchor)
    if points.shape[1] == 3 and not amsl_known(world):
        g = np.asarray(world.ground_height(points[:, 0], points[:, 1]), dtype=float)
        return np.column_stack([geo[:, :2], points[:, 2] - g]), "relativeToGround"
    return geo, "absolute"


def kml_document(
    path_m: Any,
    world: Any,
    *,
    anchor: Anchor | None = None,
    waypoints_m: Any = None,
    name: str = "fm2uav mission",
    description: str = "",
) -> str:
    """The KML text of a path (see the module docstring); ``description`` goes into
    the Document's ``<description>`` (mission facts, warnings)."""
    p = np.asarray(path_m, dtype=float)
    if p.ndim != 2 or len(p) < 2:
        raise InputError(f"path must be an (N, 2|3) array with N >= 2, got shape {p.shape}")
    geo, mode = _geo(world, p, anchor)
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<kml xmlns="{_NS}"><Document><name>{escape(name)}</name>'
        + (f"<description>{escape(description)}</description>" if description else ""),
        '<Style id="path"><LineStyle><color>ff1e1ee6</color><width>3</width></LineStyle>'
        "<PolyStyle><color>401e1ee6</color></PolyStyle></Style>",
        '<Style id="waypoints"><LineStyle><color>ff00d7ff</color><width>2</width></LineStyle>'
        "</Style>",
        _line("path", "path", geo, extrude=True, mode=mode),
    ]
    if waypoints_m is not None:
        wgeo, _ = _geo(world, np.asarray(waypoints_m, dtype=float), anchor)
        parts.append(_line("waypoints", "waypoints", wgeo, extrude=False, mode=mode))
    parts += [_point("start", geo[0], mode), _point("goal", geo[-1], mode), "</Document></kml>"]
    return "\n".join(parts) + "\n"


def write_kml(fh: IO[str], path_m: Any, world: Any, **options: Any) -> str:
    """Write :func:`kml_document` to an open text file; returns the text."""
    text = kml_document(path_m, world, **options)
    fh.write(text)
    return text


def write_kmz(fh: IO[bytes], path_m: Any, world: Any, **options: Any) -> str:
    """Write :func:`kml_document` zipped as ``doc.kml`` to an open binary file."""
    text = kml_document(path_m, world, **options)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("doc.kml", text)
    fh.write(buf.getvalue())
    return text


def read_kml_path(file: str | Path, name: str = "path") -> np.ndarray:
    """``(N, 3)`` lon, lat, alt of the LineString Placemark called ``name`` (KML or KMZ)."""
    file = Path(file)
    from .. import _validate as _v

    _v.input_file(file, "KML/KMZ file")  # no folder / named pipe (would block)
    try:
        if zipfile.is_zipfile(file):
            with zipfile.ZipFile(file) as z:
                kml = next((n for n in z.namelist() if n.lower().endswith(".kml")), None)
                if kml is None:
                    raise InputError(f"{file}: a KMZ without a .kml file inside")
                root = ET.fromstring(z.read(kml))
        else:
            root = ET.parse(file).getroot()
    except (OSError, ET.ParseError, zipfile.BadZipFile) as exc:
        raise InputError(f"{file}: cannot read KML: {exc}") from None
    ns = {"k": _NS}
    for pm in root.iter(f"{{{_NS}}}Placemark"):
        if pm.findtext("k:name", namespaces=ns) == name:
            text = pm.findtext("k:LineString/k:coordinates", namespaces=ns)
            if text:
                return np.array([[float(v) for v in t.split(",")] for t in text.split()])
    raise InputError(f"{file}: no LineString Placemark named {name!r}")
