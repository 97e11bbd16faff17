"""Auto-tuning of the flight-level parameters against an airframe's limits.

The seeds leave the choice of p1/p2 to the designer ("future work": relate the
parameters to the UAV's kinematics). :func:`tune` searches a grid of
``(p1, p2, α, β)``, plans each, and measures on the path

* the flight-level deviation: mean |z − (terrain + agl)| over the *whole* path
  [m] (transitions included — a path that never reaches the level is not
  rewarded);
* the largest climb/descent angle [deg] and the smallest horizontal turn
  radius [m], both on the path resampled every ``ds`` metres (default two
  horizontal cells, the scale at which an FM² path is meaningful).

A candidate is *feasible* if its max climb angle is within the airframe's and
its min turn radius is at least the airframe's. The best candidate is the
feasible one with the smallest deviation. The report also lists the Pareto
front of all candidates over (deviation ↓, max climb ↓, min turn radius ↑):
the trade-off between following the terrain and flying smoothly that the seeds
describe.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import progress
from .flight_level import flight_level_deviation
from .profiles import path_profiles
from ..errors import InputError, PlanningError
from ..world import World
from ..planning import FlightLevel, Plan, PlanOptions, Shaping, plan
from ..vehicles.airframes import AirframeLimits, FixedWing, Multirotor, get_airframe

__all__ = ["TuneResult", "tune", "as_limits", "DEFAULT_GRID", "MAX_TUNE_PLANS"]

#: Default search grid.
DEFAULT_GRID: dict[str, tuple[float, ...]] = {
    "p1": (0.3, 0.5, 0.8),
    "p2": (0.6, 0.8, 1.0, 1.3, 1.5, 2.0, 2.5),
    "saturation": (1.0,),
    "exponent": (1.0,),
}


def as_limits(limits: Any) -> AirframeLimits:
    """The :class:`~fm2uav.vehicles.airframes.AirframeLimits` (SI) of ``limits``: the
    limits themselves, an airframe or a preset name (its ``limits()``), or a mapping
    ``{"max_climb": rad, "min_turn_radius": m}``.

    Raises
    ------
    InputError
        Anything else, or bad values.
    """
    if isinstance(limits, AirframeLimits):
        return limits
    if isinstance(limits, (str, FixedWing, Multirotor)):
        return get_airframe(limits).limits()
    if isinstance(limits, dict):
        try:
            return AirframeLimits(limits["max_climb"], limits["min_turn_radius"])
        except KeyError as exc:
            raise InputError(
                f"airframe limits need 'max_climb' [rad] and 'min_turn_radius' [m], missing {exc}"
            ) from None
    raise InputError(
        "airframe_limits must be AirframeLimits(max_climb [rad], min_turn_radius [m]) (e.g. "
        "AirframeLimits.from_degrees(30, 60)), an airframe or preset name, or a mapping with "
        f"those keys, got {limits!r}"
    )


@dataclass
class TuneResult:
    """What :func:`tune` found.

    Attributes
    ----------
    rows : list of dict
        One row per candidate: p1, p2, saturation, exponent, deviation_m,
        within (share of all points within one cell of the level), climb_max_deg,
        min_turn_radius_m, length_m, feasible, error (None or why planning failed).
    best : dict or None
        The feasible row with the smallest deviation (None if none is feasible).
    best_plan : Plan or None
        Its plan.
    pareto : list of dict
        Non-dominated rows over (deviation ↓, climb ↓, turn radius ↑), sorted by
        deviation.
    limits : AirframeLimits
    """

    rows: list[dict[str, Any]]
    best: dict[str, Any] | None
    best_plan: Plan | None = field(repr=False)
    pareto: list[dict[str, Any]]
    limits: AirframeLimits

    def table(self, rows: list[dict[str, Any]] | None = None) -> str:
        """Markdown table of ``rows`` (default: the Pareto front)."""
        rows = self.pareto if rows is None else rows
        head = ("p1", "p2", "α", "β", "mean |dev| m", "within ±1 cell", "max climb °",
                "min turn radius m", "feasible")
        out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for r in rows:
            out.append(
                f"| {r['p1']:g} | {r['p2']:g} | {r['saturation']:g} | {r['exponent']:g} | "
                f"{r['deviation_m']:.1f} | {100 * r['within']:.0f} % | {r['climb_max_deg']:.1f} | "
                f"{r['min_turn_radius_m']:.0f} | {'yes' if r['feasible'] else 'no'} |"
            )
        return "\n".join(out)

    def markdown(self, title: str) -> str:
        """The tuning report (``tune_table.md``): the Pareto front and every candidate.

        ``title`` is the heading's text, e.g. ``"Auto-tuning — open-field, agl 150 m"``.
        """
        md = [f"# {title}", "",
              "## Pareto front (deviation ↓, max climb ↓, min turn radius ↑)", "",
              self.table(), "", "## All candidates", "", self.table(self.rows), ""]
        if self.best is None:
            md.insert(2, "**No candidate keeps the limits**; the Pareto front shows the closest.\n")
        return "\n".join(md)

    def payload(self) -> dict[str, Any]:
        """JSON-ready result (``tune.json``): limits [deg, m], best row, Pareto front, rows."""
        return {"limits": {"max_climb_deg": round(self.limits.max_climb_deg, 9),
                           "min_turn_radius_m": self.limits.min_turn_radius},
                "best": self.best, "pareto": self.pareto, "rows": self.rows}

    def summary_rows(self) -> dict[str, Any]:
        """Printable ``{label: value}`` rows of the result (what ``fm2uav tune`` prints)."""
        b = self.best
        return {
            "candidates": len(self.rows),
            "feasible": sum(r["feasible"] for r in self.rows),
            "best": ("none keeps the limits" if b is None else
                     f"p1={b['p1']:g} p2={b['p2']:g} α={b['saturation']:g} β={b['exponent']:g}: "
                     f"mean|dev| {b['deviation_m']:.1f} m, max climb {b['climb_max_deg']:.1f}°, "
                     f"min turn radius {b['min_turn_radius_m']:.0f} m"),
            "pareto front": len(self.pareto),
        }


def _pareto(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    ok = [r for r in rows if r["error"] is None]
    keys = np.array([[r["deviation_m"], r["climb_max_deg"], -r["min_turn_radius_m"]] for r in ok])
    front = []
    for i, r in enumerate(ok):
        dominated = np.any(np.all(keys <= keys[i], axis=1) & np.any(keys < keys[i], axis=1))
        if not dominated:
            front.append(r)
    return sorted(front, key=lambda r: r["deviation_m"])


def _grid_values(name: str, values: Any, lo: float, hi: float | None) -> tuple[float, ...]:
    vals = tuple(float(v) for v in np.atleast_1d(np.asarray(values, dtype=float)))
    if not vals:
        raise InputError(f"grid '{name}' is empty")
    for v in vals:
        if not np.isfinite(v) or v <= lo or (hi is not None and v > hi):
            rng = f"({lo:g}, {hi:g}]" if hi is not None else f"> {lo:g}"
            raise InputError(f"grid '{name}' values must be {rng}, got {v!r}")
    return vals


#: Most grid combinations of one :func:`tune` (each is an FM² plan).
MAX_TUNE_PLANS = 2000


def _tune_grid(grid: dict[str, Any] | None) -> tuple[tuple[float, ...], ...]:
    """The p1, p2, saturation and exponent values of the search (``grid`` over the defaults)."""
    g = dict(DEFAULT_GRID)
    for k, v in (grid or {}).items():
        if k not in DEFAULT_GRID:
            raise InputError(f"unknown grid key {k!r}; use {sorted(DEFAULT_GRID)}")
        g[k] = v
    p1s = _grid_values("p1", g["p1"], 0.0, None)
    p2s = _grid_values("p2", g["p2"], 0.0, None)
    sats = _grid_values("saturation", g["saturation"], 0.0, 1.0)
    exps = _grid_values("exponent", g["exponent"], 0.0, None)
    n = len(p1s) * len(p2s) * len(sats) * len(exps)
    if n > MAX_TUNE_PLANS:  # refused before the first plan, with what it would take
        raise InputError(
            f"the tuning grid has {n} combinations ({len(p1s)} p1 x {len(p2s)} p2 x "
            f"{len(sats)} saturation x {len(exps)} exponent values), one FM² plan each "
            f"(~1-10 s); the limit is {MAX_TUNE_PLANS}: give fewer values (CLI --p1, --p2, "
            "--saturation, --exponent)")
    return p1s, p2s, sats, exps


def _measure(row: dict[str, Any], world: World, pl: Plan, agl: float, step: float,
             limits: Any) -> None:
    """Fill ``row`` with the plan's flight-level deviation [m], climb [deg], turn radius [m],
    length [m] and whether it is feasible for ``limits``."""
    fl = flight_level_deviation(world, pl.path, agl)
    pr = path_profiles(pl.path, ds=step).summary()
    row.update(
        error=None,
        deviation_m=fl.mean_dev_all_m,
        within=fl.within_all,
        climb_max_deg=pr["climb_max_deg"],
        min_turn_radius_m=pr["min_turn_radius_m"],
        length_m=float(pl.length),
        inside_terrain=fl.inside_terrain,
    )
    row["feasible"] = bool(
        row["climb_max_deg"] <= limits.max_climb_deg + 1e-9
        and row["min_turn_radius_m"] >= limits.min_turn_radius - 1e-9
        and fl.inside_terrain == 0
    )


@progress.stage()
def tune(
    world: World,
    start: Any,
    goal: Any,
    airframe_limits: Any,
    level: FlightLevel,
    *,
    grid: dict[str, Any] | None = None,
    ds: float | None = None,
    shaping: Shaping = Shaping(),
    options: PlanOptions = PlanOptions(),
) -> TuneResult:
    """Search p1/p2 (and α/β) for the terrain-following path an airframe can fly.

    Parameters
    ----------
    world : World
        3D world.
    start, goal : sequence of float
        World points [m].
    airframe_limits : AirframeLimits, airframe, preset name or dict
        Max climb angle [rad] and min turn radius [m] (see :func:`as_limits`).
    level : FlightLevel
        The flight level; its ``p1`` and ``p2`` are replaced by the grid's
        values, the rest (``agl``, ``band``, ``mode``, ...) is kept.
    grid : dict, optional
        Values to try for ``p1``, ``p2``, ``saturation``, ``exponent``; missing
        keys take :data:`DEFAULT_GRID`. Pairs with ``p2 <= p1`` are skipped
        (they do not clarify the level).
    ds : float, optional
        Resampling step of the profiles [m]; default two horizontal cells.
    shaping : Shaping, optional
        Shaping of W; its ``saturation`` and ``exponent`` are replaced by the
        grid's values (method, walls, saturation_distance kept).
    options : PlanOptions, optional
        Passed to :func:`~fm2uav.planning.plan` (order, step).

    Returns
    -------
    TuneResult

    Raises
    ------
    InputError
        Bad limits, grid or objects.
    PlanningError
        Bad start/goal or flight level (raised by the first plan).

    Examples
    --------
    >>> import fm2uav
    >>> sc = fm2uav.scenarios.open_field()
    >>> lim = fm2uav.AirframeLimits.from_degrees(30.0, 60.0)
    >>> res = tune(sc.world, sc.start, sc.goal, lim, fm2uav.FlightLevel(agl=150.0),
    ...            grid={"p1": [0.5], "p2": [0.8, 1.3]})
    >>> len(res.rows)
    2
    """
    if not isinstance(level, FlightLevel):
        raise InputError(f"level must be a fm2uav.FlightLevel, got {type(level).__name__}; "
                         "e.g. FlightLevel(agl=150.0)")
    if not isinstance(shaping, Shaping):
        raise InputError(f"shaping must be a fm2uav.Shaping, got {type(shaping).__name__}")
    limits = as_limits(airframe_limits)
    p1s, p2s, sats, exps = _tune_grid(grid)
    step = float(ds) if ds is not None else 2.0 * max(world.spacing[:2])
    if not (np.isfinite(step) and step > 0):
        raise InputError(f"ds must be > 0 metres, got {ds!r}")
    rows, plans = [], []
    cases = [c for c in itertools.product(sats, exps, p1s, p2s) if c[3] > c[2]]
    for sat, beta, p1, p2 in progress.each(
            cases, lambda c: f"p1 = {c[2]:g}, p2 = {c[3]:g}, α = {c[0]:g}, β = {c[1]:g}"):
        row: dict[str, Any] = {"p1": p1, "p2": p2, "saturation": sat, "exponent": beta}
        pl = _plan_row(row, world, start, goal,
                       dataclasses.replace(shaping, saturation=sat, exponent=beta),
                       dataclasses.replace(level, p1=p1, p2=p2, heights="fm2"), options,
                       first=not rows)
        if pl is not None:
            _measure(row, world, pl, level.agl, step, limits)
        rows.append(row)
        plans.append(pl)
    if not rows:
        raise InputError("the grid has no pair with p2 > p1; widen it")
    return _tune_result(rows, plans, limits)


def _plan_row(row: dict[str, Any], world: World, start: Any, goal: Any, shaping: Shaping,
              level: FlightLevel, options: PlanOptions, *, first: bool) -> Plan | None:
    """The plan of one grid point (Algorithm 2 itself is tuned: the FM² heights, not the
    final profile), or None with ``row`` marked as failed.

    Raises
    ------
    PlanningError
        From the ``first`` plan: bad start/goal/agl, not the parameters.
    """
    try:
        return plan(world, start, goal, shaping=shaping, level=level, options=options)
    except PlanningError as exc:
        if first:
            raise
        row.update(error=str(exc), feasible=False, deviation_m=np.inf, within=0.0,
                   climb_max_deg=90.0, min_turn_radius_m=0.0, length_m=np.nan)
        return None


def _tune_result(rows: list[dict[str, Any]], plans: list[Plan | None], limits: Any
                 ) -> TuneResult:
    """The :class:`TuneResult` of the grid: the feasible row of least deviation, the front."""
    feas = [i for i, r in enumerate(rows) if r["feasible"]]
    best_i = min(feas, key=lambda i: rows[i]["deviation_m"]) if feas else None
    return TuneResult(
        rows=rows,
        best=rows[best_i] if best_i is not None else None,
        best_plan=plans[best_i] if best_i is not None else None,
        pareto=_pareto(rows),
        limits=limits,
    )
