"""Summary rows of a plan's mission and safety figures (printed by the CLI, shown by
the app and the reports)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["plan_rows", "world_rows", "mission_rows", "energy_rows", "safety_rows",
           "ground_rows"]


def mission_rows(mission: Any) -> dict[str, str]:
    """Printed summary rows of a built mission (frame, home, end, items, flight, warnings)."""
    s = mission.summary()
    h = s["home"]
    rows = {
        "autopilot mission": f"{s['firmware']} {s['vehicle']}, {s['items']} items, "
                             f"{s['waypoints']} waypoints, ends with {s['end']}",
        "altitude frame": f"{s['frame']['name']} (MAVLink frame {s['frame']['mav_frame']})",
        "home lat, lon, alt": f"{h['lat']:.7f}, {h['lon']:.7f}, {h['alt_amsl_m']:.1f} m AMSL "
                              f"({h['source']})",
        "flight": f"{s['flight']['flight_distance_m'] / 1000:.2f} km, "
                  f"{s['flight']['flight_time_s'] / 60:.1f} min",
    }
    rows.update(energy_rows(s.get("energy")))
    if s["speed_changes"]["items"]:
        rows["speed changes"] = (f"{s['speed_changes']['items']} "
                                 f"({', '.join(f'{v:g}' for v in s['speed_changes']['speeds_mps'])}"
                                 " m/s)")
    for k, w in enumerate(s["warnings"]):
        rows[f"warning {k + 1}"] = w
    return rows


def energy_rows(e: dict[str, Any] | None) -> dict[str, str]:
    """Printed rows of a mission's energy figures (:func:`fm2uav.autopilot.energy.mission_energy`):
    the energy and time against the battery, the model, the wind, the point of no return."""
    if not e:
        return {}
    if e["energy_wh"] is None:
        used = "cannot be flown in this wind"
    else:
        used = (f"{e['energy_wh']:.1f} Wh, {e['time_s'] / 60:.1f} min of {e['battery_wh']:g} Wh "
                f"({e['usable_wh']:.1f} Wh usable with a {100 * e['reserve']:.0f} % reserve): "
                f"{'OK' if e['ok'] else 'NOT ENOUGH'}")
    rows = {"energy": used,
            "power model": f"{e['model']} ({e['model_kind']}, {e['hover_or_cruise_power_w']:g} W "
                           f"{'hover' if e['model_kind'] == 'multirotor' else 'cruise'}; "
                           f"{e['model_source']})"}
    if e.get("wind"):
        w = e["wind"]
        rows["wind"] = (f"{w['speed_mps']:g} m/s from {w['from_deg']:g}°" if "speed_mps" in w
                        else f"gridded, up to {w['max_speed_mps']:g} m/s") + (
            f"; ground speed {e['groundspeed_mps'][0]:g}–{e['groundspeed_mps'][1]:g} m/s, "
            f"airspeed {e['airspeed_mps'][0]:g}–{e['airspeed_mps'][1]:g} m/s"
            if e.get("groundspeed_mps") else "")
    if "no_return_waypoint" in e:
        rows["point of no return"] = f"waypoint {e['no_return_waypoint']}: {e['no_return_note']}"
    return rows


def safety_rows(safety: dict[str, Any]) -> dict[str, str]:
    """Printed / report rows of :func:`fm2uav.analysis.safety.safety_summary`."""
    rows: dict[str, str] = {}
    hag = safety.get("height_above_ground", {})

    def fig(f: dict[str, Any]) -> str:
        band = f.get("within_band")
        share = "" if band is None else f", {100 * band:.0f} % within ±{f['band_m']:g} m"
        return (f"min {f['min_m']:.1f}, p5 {f['p5_m']:.1f}, median {f['median_m']:.1f}, "
                f"max {f['max_m']:.1f}{share}")
    if "cruise" in hag:
        rows["height above ground, cruise [m]"] = fig(hag["cruise"])
    if "path" in hag:
        low = hag["path"]
        rows["height above ground, whole path [m]"] = (
            fig(low) + f"; lowest at ({', '.join(f'{v:.0f}' for v in low['lowest_point_m'])}) m")
    legs = safety.get("legs")
    if legs:
        lc = legs.get("cruise", legs)
        rows["lowest AGL along the legs [m]"] = (f"{legs['min_m']:.1f} (cruise legs "
                                                 f"{lc['min_m']:.1f})")
    if "clearance_m" in safety:
        rows["clearance to the surface [m]"] = f"{safety['clearance_m']:.1f}"
    rows.update(ground_rows(safety))
    z = safety.get("zones")
    if z:
        near = min(z["distance_m"].values()) if z["distance_m"] else float("inf")
        rows["no-fly zones"] = (f"{z['count']}, nearest {near:.0f} m away, "
                                f"{len(z['path_entries'])} entries")
    bad = [k for k, c in safety.get("checks", {}).items() if not c.get("ok", True)]
    if bad:
        rows["limits NOT met"] = ", ".join(bad)
    return rows


def plan_rows(p: Any) -> dict[str, Any]:
    """The printed summary rows every planning command shows of a plan."""
    rows = {
        "start [m]": np.round(p.start, 1).tolist(),
        "goal [m]": np.round(p.goal, 1).tolist(),
        "length [m]": f"{p.length:.1f}",
        "clearance [m]": f"{p.clearance:.1f}",
    }
    w = (getattr(p, "params", None) or {}).get("wind")
    if w:
        g = w["groundspeed_mps"]
        rows["route in the wind"] = (
            (f"{w['time_s'] / 60:.1f} min" if w["time_s"] is not None else "no headway")
            + f" at up to {w['airspeed_mps']:g} m/s airspeed"
            + (f", ground speed {g[0]:g}–{g[1]:g} m/s" if g else "")
            + f"; {w['refused_nodes']} nodes refused (wind ≥ safe airspeed)")
    return rows


def world_rows(world: Any) -> dict[str, str]:
    """Printed summary rows about a data world (nothing for a built-in scenario)."""
    g = getattr(world, "georef", None)
    if g is None:
        return {}
    rows = {"CRS": f"{g.name}" + (f" — {g.reprojection}" if g.reprojection else ""),
            "vertical": g.vertical}
    for s in g.sources:
        d = s.details
        if s.role == "dem":
            rows["grid"] = (f"{' x '.join(str(n) for n in world.shape)} nodes, cells "
                            f"{d.get('cell_size', world.spacing[0]):g} m ({d.get('cell_size_rule', '')}), "
                            f"dz {d.get('dz', world.spacing[2]):g} m ({d.get('dz_rule', '')})")
            if d.get("filled_nodes"):
                rows["filled nodata"] = f"{d['filled_nodes']} columns"
        if s.role == "buildings":
            hr = d.get("height_rule", {})
            rows["buildings"] = (
                f"{d.get('buildings', 0)}: {hr.get('height', 0)} from height, "
                f"{hr.get('building:levels', 0)} from building:levels x "
                f"{d.get('metres_per_level', 3.0):g} m, {hr.get('default_height', 0)} from "
                f"--default-height" + (f"; left out: {d['skipped']}" if d.get("skipped") else "")
                + (f"; {d['outside_map']} outside the map" if d.get("outside_map") else ""))
            if "grid" not in rows:
                rows["grid"] = (f"{' x '.join(str(n) for n in world.shape)} nodes, cells "
                                f"{world.spacing[0]:g} m, dz {world.spacing[2]:g} m")
    rows["sources"] = ", ".join(f"{Path(s.path).name} (sha256 {s.sha256[:12]})"
                                for s in g.sources if s.sha256)
    return rows


def ground_rows(safety: dict[str, Any]) -> dict[str, str]:
    """Printed / report rows of the known/unknown ground split and the DEM resolution
    (:mod:`fm2uav.analysis.known_ground`)."""
    rows: dict[str, str] = {}
    g = safety.get("ground")
    if g:
        m, f = g["measured"], g["filled"]
        km = lambda v: f"{v / 1000:.2f} km"  # noqa: E731
        parts = [f"measured {km(m['length_m'])} ({100 * m['share']:.0f} %)"]
        for src in g.get("sources", [])[1:]:
            parts[0] += f"; of it from the fill DEM {src['dem']}: {km(src['length_m'])}"
        parts.append(f"FILLED (unknown, heights invented) {km(f['length_m'])} "
                     f"({100 * f['share']:.0f} %)" if f["length_m"] > 0 else "filled 0 km")
        rows["ground under the path"] = ", ".join(parts)
        if f["length_m"] > 0:
            for name, part in (("over measured ground", m), ("over FILLED ground", f)):
                hag = part.get("height_above_ground")
                if not hag:
                    continue
                band = hag.get("within_band")
                share = "" if band is None else f", {100 * band:.0f} % within ±{hag['band_m']:g} m"
                clr = f", clearance {part['clearance_m']:.1f}" if "clearance_m" in part else ""
                rows[f"height above ground {name} [m]"] = (
                    f"min {hag['min_m']:.1f}, median {hag['median_m']:.1f}{share}{clr}"
                    + (" (against invented ground)" if part is f else ""))
        legs = (safety.get("legs") or {}).get("ground")
        if legs and legs.get("filled_min_m") is not None:
            rows["lowest AGL along the legs, measured / FILLED ground [m]"] = (
                f"{legs['measured_min_m'] if legs['measured_min_m'] is not None else '-'} / "
                f"{legs['filled_min_m']}")
    r = safety.get("dem_resolution")
    if r:
        rows["DEM resolution"] = (
            f"{r['pixel_m']:.0f} m pixels, slope p95 {r['slope_p95_deg']:.0f}°: up to "
            f"{r['hidden_relief_m']:.0f} m of relief can hide between pixels ("
            + ("ok" if r["ok"] else "TOO COARSE") + f" for {r['agl_m']:g} m above ground"
            + ("" if r["ok"] or not r.get("needed_pixel_m") else
               f"; needs pixels of <= {r['needed_pixel_m']:.0f} m") + ")")
    return rows
