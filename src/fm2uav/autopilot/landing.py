"""A fixed-wing landing pattern: ``DO_LAND_START`` + ``NAV_LOITER_TO_ALT`` + ``NAV_LAND``.

The aircraft descends in a loiter behind the touchdown to the approach height,
leaves it on the tangent that points at the touchdown (ArduPlane's
``verify_loiter_to_alt``: altitude reached, then heading toward the next item;
PX4 likewise for a ``NAV_LOITER_TO_ALT`` before a ``NAV_LAND``) and glides to it:
ArduPlane's glide slope runs from the previous item to the ``NAV_LAND`` point
(``AP_Landing`` ``setup_landing_glide_slope``), PX4's from the loiter tangent at no
more than ``FW_LND_ANG``. The geometry, from the firmware's navigation numbers
(:class:`~fm2uav.autopilot.firmware.navigation.FixedWingNav`):

* the loiter radius is at least 1.2 turn radii at the approach speed (a tighter
  circle is flown wider than the pattern's);
* the glide slope is no steeper than the sink limit holds, ``asin(TECS_SINK_MAX /
  V)``, nor than ``FW_LND_ANG`` on PX4 — and no steeper than asked
  (``land_slope_deg``);
* the straight approach is at least two L1 distances long, so the aircraft is
  on the runway line well before the flare; a longer one raises the loiter.

``DO_LAND_START`` marks the sequence for ArduPlane's ``RTL_AUTOLAND`` and PX4's
mission landing.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .firmware.navigation import FixedWingNav
from .items import (
    CMD_DO_LAND_START,
    CMD_NAV_LAND,
    CMD_NAV_LOITER_TO_ALT,
    FRAME_RELATIVE,
    FRAME_TERRAIN,
    MissionItem,
)
from .placing import ItemPlacer, inside_xy

__all__ = ["landing_pattern", "loiter_radius"]


def loiter_radius(requested: float, nav: FixedWingNav | None, speed: float | None = None
                  ) -> float:
    """A loiter radius the aircraft flies: ``requested``, at least 1.2 turn radii [m]."""
    if nav is None:
        return float(requested)
    return max(float(requested), math.ceil(1.2 * nav.turn_radius(speed)))


def landing_pattern(geo: ItemPlacer, touchdown: np.ndarray, heading: np.ndarray, frame: int, *,
                    radius: float, approach_agl: float, slope_deg: float,
                    nav: FixedWingNav | None, label: str
                    ) -> tuple[list[MissionItem], dict[str, Any], list[str]]:
    """The items of a landing along ``heading`` at ``touchdown`` (module docstring).

    Returns
    -------
    items : list of MissionItem
        ``DO_LAND_START``, ``NAV_LOITER_TO_ALT``, ``NAV_LAND`` (altitudes above home
        when the route is in the terrain frame).
    info : dict
        Touchdown altitude, approach height, glide slope, run, loiter radius, lowest
        clearance of the approach over the DEM.
    warnings : list of str
    """
    r = loiter_radius(radius, nav)
    slope = float(slope_deg)
    notes: list[str] = []
    if nav is not None and slope > nav.max_glide_deg():
        slope = round(nav.max_glide_deg(), 1)
        notes.append(f"glide slope lowered to {slope:g}° (the sink limit at "
                     f"{nav.airspeed_cruise:g} m/s)")
    h = float(approach_agl)
    run = h / math.tan(math.radians(slope))
    if nav is not None and run < 2.0 * nav.l1_distance():
        run = 2.0 * nav.l1_distance()
        h = run * math.tan(math.radians(slope))
        notes.append(f"approach lengthened to {run:.0f} m (two L1 distances) at "
                     f"{h:.0f} m")
    d = math.hypot(run, r)
    centre = touchdown - heading * d
    g_td = float(geo.ground(touchdown)[0])
    f = FRAME_RELATIVE if frame == FRAME_TERRAIN else frame  # altitudes above the touchdown
    items = [
        MissionItem.do(CMD_DO_LAND_START, label=f"{label}: landing start"),
        geo.item(CMD_NAV_LOITER_TO_ALT, f, centre, g_td + h, label=f"{label}: approach loiter",
                 p1=1.0, p2=r, p4=0.0),
        geo.item(CMD_NAV_LAND, f, touchdown, g_td, label=f"{label}: touchdown"),
    ]
    warnings: list[str] = []
    s = np.linspace(0.0, run, 64)
    line = touchdown[None, :] - heading[None, :] * s[:, None]
    phi = np.linspace(0.0, 2 * math.pi, 72, endpoint=False)
    circle = centre[None, :] + r * np.column_stack([np.cos(phi), np.sin(phi)])
    pts = np.vstack([line, circle])
    info: dict[str, Any] = {"touchdown_alt_amsl_m": round(items[2].alt_amsl or 0.0, 2),
                            "approach_agl_m": round(h, 1), "glide_slope_deg": slope,
                            "approach_run_m": round(run, 1), "loiter_radius_m": r}
    if notes:
        info["adjusted"] = notes
    inside = inside_xy(geo.world, pts)
    if not inside.all():
        warnings.append(f"{label}: the landing approach ({d:.0f} m back from the touchdown, "
                        f"{r:.0f} m loiter) leaves the map: its terrain is not checked")
    if inside.any():
        glide = np.concatenate([g_td + s * math.tan(math.radians(slope)),
                                np.full(len(circle), g_td + h)])
        clear = glide - geo.ground(pts)
        check = inside & (glide - g_td >= 10.0)
        if check.any():
            worst = float(clear[check].min())
            info["approach_min_clearance_m"] = round(worst, 1)
            if worst < 10.0:
                warnings.append(f"{label}: the landing approach passes only {worst:.1f} m above "
                                "the ground (DEM): check the landing site, or change "
                                "land_approach_agl / land_slope_deg")
    return items, info, warnings
