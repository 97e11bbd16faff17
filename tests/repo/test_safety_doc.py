"""The measured table of docs/safety.md is what the code gives today.

Regenerate with ``.venv/bin/python -m tests.repo.test_safety_doc`` (prints the table).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from pyproj import Transformer
from scipy import ndimage

DOC = Path(__file__).resolve().parents[2] / "docs" / "safety.md"
BEGIN, END = "<!-- safety-table:begin -->", "<!-- safety-table:end -->"
HEADER = ("| scenario | agl [m] | cruise min | p5 | median | max | within ±5 m | "
          "path min (inner) | cruise legs min | waypoints | clearance |")


def _ground(name, world):
    if name == "jacksboro":
        from fm2uav.scenarios.jacksboro import jacksboro_dem

        z, (west, south, east, north) = jacksboro_dem()
        rows, cols = z.shape
        tr = Transformer.from_crs(world.crs, "EPSG:4326", always_xy=True)

        def g(x, y):
            lon, lat = tr.transform(np.asarray(x, float), np.asarray(y, float))
            c = (np.asarray(lon) - west) / (east - west) * cols - 0.5
            r = (north - np.asarray(lat)) / (north - south) * rows - 0.5
            return ndimage.map_coordinates(z, [r, c], order=1, mode="nearest")
        return g

    def g(x, y):
        return ndimage.map_coordinates(world.terrain, [(np.asarray(x) - world.origin[0]) /
                                                       world.spacing[0],
                                                       (np.asarray(y) - world.origin[1]) /
                                                       world.spacing[1]],
                                       order=1, mode="nearest")
    return g


def table_rows():
    from fm2uav.autopilot.legs import refine_legs
    from fm2uav.autopilot.thin import thin_indices
    from fm2uav.planning import FlightLevel, plan
    from fm2uav.scenarios import get_scenario

    rows = []
    for name in ("open-field", "jacksboro"):
        sc = get_scenario(name)
        g = _ground(name, sc.world)
        for agl in (100.0, 120.0, 150.0):
            p = plan(sc.world, sc.start, sc.goal, level=FlightLevel(agl=agl))
            h = p.path[:, 2] - g(p.path[:, 0], p.path[:, 1])
            c = p.phase == "cruise"
            idx = thin_indices(p.path, 5.0)
            idx, _ = refine_legs(idx, p.path, p.world, required=p.profile.required)
            legs = []
            for a, b in zip(idx[:-1], idx[1:]):
                if c[a] and c[b]:
                    n = max(int(np.ceil(np.hypot(*(p.path[b, :2] - p.path[a, :2])) / 1.0)), 1)
                    legs.append(p.path[a] + np.linspace(0, 1, n + 1)[:, None] *
                                (p.path[b] - p.path[a]))
            legs = np.concatenate(legs)
            hl = legs[:, 2] - g(legs[:, 0], legs[:, 1])
            hc = h[c]
            rows.append([name, f"{agl:.0f}", f"{hc.min():.1f}", f"{np.percentile(hc, 5):.1f}",
                         f"{np.median(hc):.1f}", f"{hc.max():.1f}",
                         f"{100 * np.mean(np.abs(hc - agl) <= 5):.0f} %", f"{h[1:-1].min():.1f}",
                         f"{hl.min():.1f}", str(len(idx)), f"{p.clearance:.1f}"])
    return rows


def table_markdown(rows) -> str:
    sep = "|" + "---|" * (HEADER.count("|") - 1)
    return "\n".join([HEADER, sep] + ["| " + " | ".join(r) + " |" for r in rows])


def test_doc_table_matches_a_fresh_run():
    text = DOC.read_text()
    m = re.search(re.escape(BEGIN) + r"\n(.*?)\n" + re.escape(END), text, re.S)
    assert m, "docs/safety.md lost its table markers"
    assert m.group(1).strip() == table_markdown(table_rows()).strip()


if __name__ == "__main__":
    print(table_markdown(table_rows()))
