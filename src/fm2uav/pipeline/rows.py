"""Summary rows of a plan's mission and safety figures (printed by the CLI, shown by
the app and the reports)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["plan_rows", "world_rows", "mission_rows", "energy_rows", "safety_rows",
           "ground_rows", "returns_rows", "mission_figures", "coverage_figures"]


def mission_rows(mission: Any) -> dict[str, str]:
    """Printed summary rows of a built mission (frame, home, end, items, flight, warnings)."""
    s = mission.summary()
    h = s["home"]
    rows = {
        "autopilot mission": f"{s['firmware']} {s['vehicle']}, {s['items']} items, "
                             f"{s['waypoints']} waypoints, ends with {s['end']}",
        "altitude frame": f"{s['frame']['name']} (MAVLink frame {s['frame']['mav_frame']})",
        "home lat, lon, alt": f"{h['lat']:.7f}, {h['lon']:.7f}, "
                              + ("altitude above sea level unknown" if h["alt_amsl_m"] is None
                                 else f"{h['alt_amsl_m']:.1f} m AMSL") + f" ({h['source']})",
        "flight": f"{s['flight']['flight_distance_m'] / 1000:.2f} km, "
                  f"{s['flight']['flight_time_s'] / 60:.1f} min",
    }
    rows.update(energy_rows(s.get("energy")))
    sc = s["speed_changes"]
    kind = "airspeed" if sc.get("speed_type") == 0 else "ground speed"
    rows["speeds"] = (f"DO_CHANGE_SPEED {kind} {', '.join(f'{v:g}' for v in sc['speeds_mps'])} "
                      f"m/s ({sc['items']} item{'s' if sc['items'] != 1 else ''}, from "
                      f"{sc.get('from', 'the forward speed')})")
    co = s.get("climb_out")
    if co and co.get("mode") in ("straight", "loiter"):
        how = (f"climb in a {co['loiter_radius_m']:g} m loiter to {co['loiter_alt_m']:g} m"
               if co["mode"] == "loiter" else
               f"first waypoint {co['first_waypoint_m']:g} m ahead")
        rows["fixed-wing climb-out"] = (
            f"launch on course {co['course_deg']:g}° (the take-off item's direction), climb "
            f"straight to {co['takeoff_alt_m']:g} m above home in {co['climb_distance_m']:g} "
            f"m, then {how}")
    t = s.get("terrain")
    if t:
        beyond = t.get("nodes_beyond_dem", 0)
        edge = (f"; {100 * beyond / t['nodes']:.0f} % of the nodes lie beyond the DEM (its "
                "edge heights, not measured)" if beyond and t.get("nodes") else "")
        if t.get("nodes_over_filled_ground"):
            edge += (f"; {t['nodes_over_filled_ground']} nodes over FILLED ground (heights "
                     "invented)")
        rows["terrain files"] = (f"{', '.join('terrain/' + f for f in t['files'])} "
                                 f"({t['blocks']} blocks, {t['spacing_m']} m): {t['load']}; "
                                 f"{t['without']}{edge}")
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
        rows["point of no return (battery, straight returns)"] = (
            f"waypoint {e['no_return_waypoint']}: {e['no_return_note']}")
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
    for k, w in enumerate(safety.get("warnings", ())):
        rows[f"safety warning {k + 1}"] = w
    return rows


def plan_rows(p: Any) -> dict[str, Any]:
    """The printed summary rows every planning command shows of a plan."""
    import numpy as np

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
            def rule(key: str) -> str:  # why the size was chosen, when the loader says
                return f" ({d[key]})" if d.get(key) else ""
            rows["grid"] = (f"{' x '.join(str(n) for n in world.shape)} nodes, cells "
                            f"{d.get('cell_size', world.spacing[0]):g} m{rule('cell_size_rule')}, "
                            f"dz {d.get('dz', world.spacing[2]):g} m{rule('dz_rule')}")
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
    sources = ", ".join(f"{Path(s.path).name} (sha256 {s.sha256[:12]})"
                        for s in g.sources if s.sha256)
    if sources:  # a built-in scenario's data carry no checksum
        rows["sources"] = sources
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


def returns_rows(info: dict[str, Any]) -> dict[str, str]:
    """Printed / report rows of the safe returns (``returns`` of the summary)."""
    r = info.get("returns")
    if not r:
        return {}
    rows: dict[str, str] = {}
    w = r["worst"]
    if w.get("time_s") is not None:
        rows["longest way back"] = (f"{w['time_s'] / 60:.1f} min to {w['to']} from "
                                    f"{w['distance_m'] / 1000:.2f} km along the route")
    rally = [d for d in r["destinations"] if d.get("name") != "home"]
    if rally:
        rows["rally points"] = ", ".join(
            f"{d['name']} ({d.get('chosen_by', 'user')}) {d.get('lon', 0):.5f}, "
            f"{d.get('lat', 0):.5f}" for d in rally)
    p = r["point_of_no_return"]
    budget = {"energy": "battery", "endurance": "endurance"}.get(p.get("budget", ""), "")
    label = "point of no return" + (f" ({budget} binds; FM² ways back)" if budget else "")
    if not p.get("computed"):
        rows["point of no return"] = "not computed: " + p.get("why", "")
    elif p.get("reached"):
        rows[label] = (f"{p['distance_m'] / 1000:.2f} km along the route "
                       f"(after waypoint {p['after_waypoint']}, "
                       f"{p['t_mission_s'] / 60:.1f} min)"
                       + (" — BEFORE the route's end" if p["passed_before_end"] else ""))
    else:
        margin = (f"{p['smallest_margin_s'] / 60:.1f} min" if "smallest_margin_s" in p
                  else f"{p['smallest_margin_wh']:.1f} Wh")
        rows[label] = f"none on the route (smallest margin {margin})"
    if p.get("model"):
        rows["point of no return: model"] = p["model"]
    fw = r.get("firmware")
    if fw:
        alts = "; ".join(
            f"{m['firmware']} {m['return_altitude_m']:g} m" if m["feasible"] else
            f"{m['firmware']}: no safe altitude" for m in fw["models"])
        rows["firmware return"] = (alts + f" (>= {fw['min_agl_m']:g} m above the surface on "
                                   f"{fw['start_points']['count']} straight lines)")
    if r.get("mission_carries_safe_return"):
        rows["safe return in the mission"] = str(r["mission_carries_safe_return"])
    return rows


def _km(m: float) -> str:
    return f"{m / 1000:.2f} km" if m >= 1000 else f"{m:.0f} m"


def _minutes(s: float) -> str:
    m, sec = divmod(int(round(s)), 60)
    return f"{m} min {sec:02d} s" if m < 60 else f"{m // 60} h {m % 60:02d} min"


def _place(world: Any, point_m: Any, anchor: Any = None) -> str:
    import numpy as np

    from ..viz.report import latlon_text
    from ..world.geo import to_lonlat

    q = np.asarray(to_lonlat(world, np.asarray(point_m, dtype=float)[:2], anchor=anchor),
                   dtype=float)
    return latlon_text(float(q[0]), float(q[1]))


def mission_figures(length_m: float, mission: Any, safety: dict[str, Any], world: Any, *,
                    anchor: Any = None) -> dict[str, str]:
    """The operator's figures of a mission, first in its report beside the map: how long,
    how long in time (and energy, when the mission has it), where it takes off, how high
    above the ground (lowest, where), the nearest no-fly zone, filled ground.

    Every number comes from the built mission (:meth:`MissionExport.summary`) and the
    safety figures (:func:`fm2uav.analysis.safety.safety_summary`), as ``summary.json``
    records them.
    """
    s = mission.summary()
    fl = s["flight"]
    out = {"route length": _km(float(length_m)),
           "flight time": f"{_minutes(fl['flight_time_s'])} ({_km(fl['flight_distance_m'])} "
                          "with take-off and landing)"}
    for key, label in (("energy_wh", "energy"), ("energy_Wh", "energy")):
        if fl.get(key) is not None:
            out[label] = f"{fl[key]:.0f} Wh"
    if fl.get("endurance_s"):
        out["endurance"] = (f"{100 * fl['flight_time_s'] / fl['endurance_s']:.0f} % of "
                            f"{fl['endurance_s'] / 60:.0f} min"
                            + ("" if fl.get("ok", True) else " — NOT ENOUGH"))
    h = s["home"]
    out["take-off (home)"] = (f"{_place_ll(h['lon'], h['lat'])}, {h['alt_amsl_m']:.0f} m AMSL")
    out["mission"] = (f"{s['waypoints']} waypoints, {s['items']} items — {s['firmware']} "
                      f"{s['vehicle']}, altitudes {s['frame']['name']} (MAVLink frame "
                      f"{s['frame']['mav_frame']}), ends with {s['end']}")
    out.update(_height_figures(safety, world, anchor))
    z = safety.get("zones")
    if z:
        if z["distance_m"]:
            name, d = min(z["distance_m"].items(), key=lambda kv: kv[1])
            out["nearest no-fly zone"] = f"{d:.0f} m ({name})"
        if z["path_entries"]:
            out["ZONE ENTERED"] = ", ".join(sorted({e["zone"] for e in z["path_entries"]}))
    bad = [k for k, c in safety.get("checks", {}).items() if not c.get("ok", True)]
    if bad:
        out["limits NOT met"] = ", ".join(bad)
    return out


def _place_ll(lon: float, lat: float) -> str:
    from ..viz.report import latlon_text

    return latlon_text(float(lon), float(lat))


def _height_figures(safety: dict[str, Any], world: Any, anchor: Any) -> dict[str, str]:
    """Lowest / highest height above the ground (whole path and cruise), where; clearance
    to roofs; the length over filled (unknown) ground."""
    out: dict[str, str] = {}
    hag = safety.get("height_above_ground", {})
    path = hag.get("path")
    if path and path.get("n"):
        where = ""
        if "lowest_point_m" in path:
            at = float(path.get("lowest_at_m", 0.0))
            where = (f", {'at the start' if at < 1.0 else f'{_km(at)} along the route'} "
                     f"({_place(world, path['lowest_point_m'], anchor)})")
        out["lowest above ground"] = f"{path['min_m']:.0f} m{where}"
        cruise = hag.get("cruise")
        if cruise and cruise.get("n") and abs(cruise["min_m"] - path["min_m"]) >= 0.5:
            out["lowest above ground, cruise"] = f"{cruise['min_m']:.0f} m"
        out["highest above ground"] = f"{path['max_m']:.0f} m"
    surf = safety.get("height_above_surface", {}).get("path")
    if surf and surf.get("n"):
        out["lowest above roofs / ground"] = f"{surf['min_m']:.0f} m"
    if "clearance_m" in safety:
        out["clearance to terrain and buildings"] = f"{safety['clearance_m']:.0f} m"
    g = safety.get("ground")
    if g and g["filled"]["length_m"] > 0:
        f = g["filled"]
        out["over FILLED ground (unknown)"] = (f"{_km(f['length_m'])} ({100 * f['share']:.0f} %"
                                               " of the route): heights there are invented")
    return out


def coverage_figures(cp: Any, shots: Any, mission: Any, *, photos: int,
                     camera: Any = None) -> dict[str, str]:
    """The survey's figures for its report: area, photos, ground sample distance, bands,
    spacing, coverage and the camera trigger distance."""
    cam = mission.info.get("camera", {})
    area = float(cp.zigzag.area.area)
    out = {"survey area": f"{area / 1e4:.1f} ha ({area / 1e6:.3f} km²)",
           "photos": f"{photos} (one every {shots.trigger_distance:.0f} m along the bands)",
           "bands": f"{cp.zigzag.n_bands}, {cp.zigzag.spacing:.0f} m apart, steering angle "
                    f"{cp.zigzag.angle_deg:.1f}°",
           "covered": f"{100 * cp.coverage:.1f} % of the area"}
    if cam.get("gsd_cm_per_px") is not None:
        out["ground sample distance"] = f"{cam['gsd_cm_per_px']:.2f} cm/px"
    else:
        out["ground sample distance"] = "not known: no camera given (--camera)"
    if camera is not None:
        across, along = camera.footprint(float(cp.level.agl))
        out["photo footprint"] = f"{across:.0f} m × {along:.0f} m on the ground"
    if cam.get("side_overlap") is not None:
        out["overlap side / front"] = (f"{100 * float(cam['side_overlap']):.0f} % / "
                                       f"{100 * float(cam.get('front_overlap', 0)):.0f} %")
    return out
