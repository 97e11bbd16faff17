"""Parameter objects of the planner: :class:`Shaping`, :class:`FlightLevel`, :class:`PlanOptions`.

One spelling everywhere: :func:`fm2uav.plan`, ``plan_coverage``, ``fly_formation``,
``tune``, the mission file's ``planner:`` section and the CLI flags all build
these objects, and the field names are the mission-file keys (``planner.<field>``)
and the CLI flags (``--<field>`` with ``_`` written ``-``). Each object checks
itself when it is made (through :mod:`fm2uav._validate`) and raises
:class:`~fm2uav.errors.InputError` naming the mission-file key and the CLI flag.

Examples
--------
>>> from fm2uav import FlightLevel, InputError, Shaping
>>> Shaping(exponent=2.0).exponent
2.0
>>> try:
...     FlightLevel(agl=-5)
... except InputError as exc:
...     print(exc)
agl must be a finite number > 0 m, got -5 (mission file: planner.agl; CLI: --agl)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import TYPE_CHECKING, Any, Literal

from .. import _validate as v
from ..errors import InputError

if TYPE_CHECKING:  # numpy only where a speed map is given: the command line checks these
    import numpy as np  # objects before numpy loads

__all__ = [
    "Shaping",
    "FlightLevel",
    "PlanOptions",
    "FLIGHT_LEVEL_MODES",
    "SHAPING_METHODS",
    "STORAGE_MODES",
    "planner_objects",
    "planner_keys",
    "UPPER",
    "plan_params",
]

#: Accepted values of :attr:`FlightLevel.mode`.
FLIGHT_LEVEL_MODES = ("capped", "literal")
#: Accepted values of ``FlightLevel.heights``.
FLIGHT_LEVEL_HEIGHTS = ("ground", "fm2")
#: Accepted values of :attr:`Shaping.method`.
SHAPING_METHODS = ("edt", "fmm")
#: Accepted values of :attr:`PlanOptions.storage`.
STORAGE_MODES = ("auto", "full", "regional")


#: Upper bounds of the planner's numbers, the same in Python, the mission file
#: (:class:`fm2uav.io.mission.PlannerSpec`) and on the command line: beyond them a value is
#: a typo (``--agl 1e308``), never a plan.
UPPER = {"exponent": 10.0, "saturation_distance": 100_000.0, "agl": 5000.0, "p1": 10.0,
         "p2": 10.0, "band": 5000.0, "tolerance": 1000.0, "min_agl": 5000.0,
         "max_agl": 5000.0}


def _upper(obj: Any, name: str, unit: str = "") -> None:
    """Refuse ``obj.name`` above :data:`UPPER` (names the key and the flag)."""
    value = getattr(obj, name)
    if value is not None and value > UPPER[name]:
        u = f" {unit}" if unit else ""
        raise InputError(f"{name} = {value:g}{u} is too large; allowed: at most "
                         f"{UPPER[name]:g}{u}{v.where_text(_where(name))}")


def _where(name: str) -> tuple[str, str]:
    """(mission-file key, CLI flag) of a planner field."""
    return f"planner.{name}", "--" + name.replace("_", "-")


def _set(obj: Any, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


@dataclass(frozen=True)
class Shaping:
    """How the velocity map W is made from the obstacles (thesis §2.2, Sensors 2022).

    ``W = min(d / d_sat, 1) ** exponent`` with ``d`` the distance to the
    nearest obstacle [m] and ``d_sat = saturation · max(d)``, or
    ``d_sat = saturation_distance`` when that is given.

    Attributes
    ----------
    saturation : float
        α in (0, 1]: the share of the map's largest obstacle distance beyond
        which W = 1. Default 1 (no saturation).
    exponent : float
        β > 0: > 1 darkens the map (paths further from obstacles), < 1
        lightens it. Default 1.
    saturation_distance : float or None
        [m] > 0: W = 1 from this distance to the obstacles on (overrides
        ``saturation``), so the margin means the same on any map size. When it
        exceeds the map's largest obstacle distance, W stays below 1
        everywhere (``W = d / d_sat``). Default None.
    method : {"edt", "fmm"}
        Distance to the obstacles: exact transform, or Fast Marching from the
        obstacles as in the seeds. Default "edt".
    walls : bool
        Treat the map border as an obstacle. Default False.
    """

    saturation: float = 1.0
    exponent: float = 1.0
    saturation_distance: float | None = None
    method: Literal["edt", "fmm"] = "edt"
    walls: bool = False

    def __post_init__(self) -> None:
        _set(self, "saturation", v.in_range(
            self.saturation, "saturation", 0.0, 1.0, low_open=True, where=_where("saturation"),
            hint="α is the share of the largest obstacle distance beyond which W = 1"))
        _set(self, "exponent", v.positive(self.exponent, "exponent", where=_where("exponent")))
        _set(self, "saturation_distance", v.optional(
            v.positive, self.saturation_distance, "saturation_distance", unit="m",
            where=_where("saturation_distance")))
        v.choice(self.method, SHAPING_METHODS, "method", where=_where("method"))
        _set(self, "walls", v.flag(self.walls, "walls", where=_where("walls")))
        _upper(self, "exponent")
        _upper(self, "saturation_distance", "m")

    @property
    def shapes(self) -> bool:
        """Whether anything is applied to the normalised distance (else W = d / max d)."""
        return (self.saturation != 1.0 or self.exponent != 1.0
                or self.saturation_distance is not None)


@dataclass(frozen=True)
class FlightLevel:
    """A terrain-following constraint: thesis Algorithm 2 (exponents p1/p2 on W).

    The cells ``agl`` metres above the ground (or roofs) are clarified with
    ``p1``, all other cells darkened with ``p2`` (see
    :mod:`fm2uav.planning.flight_level`).

    Attributes
    ----------
    agl : float
        Requested height above the ground [m], > 0.
    p1 : float
        Exponent on the flight-level cells, > 0 (< 1 clarifies). Default 0.5.
    p2 : float
        Exponent on all other cells, > 0 (> p1 darkens them). Default 1.3.
    band : float
        Half-width [m] of the clarified band around the level, >= 0. Default 0
        (the seeds' single layer).
    graded : bool
        Blend the exponent from p1 at the level to p2 at the band edge.
        Default False.
    mode : {"capped", "literal"}
        How Algorithm 2 reads W: "capped" (default) caps each column at W of
        its level node so the level is the brightest cell; "literal"
        exponentiates W as is (kept for comparison, docs/tff.md).
    tolerance : float
        [m] >= 0: the cruise part of the path should never be below
        ``agl - tolerance``. Default 2.
    min_agl : float or None
        [m] >= 0: hard floor above the ground for the whole path except the
        take-off and landing points. Must be <= ``agl``. Default None.
    max_agl : float or None
        [m] > 0: hard ceiling above the ground (e.g. 120 m). Must be >=
        ``agl``. Default None.
    max_climb, max_descent : float
        [deg] in (0, 90]: steepest flight-path angle up / down of the final
        altitude profile. Default 45.
    heights : {"ground", "fm2"}
        Where the path's heights come from. "ground" (default): the final
        altitude profile, ``agl`` above the continuous ground along the FM²
        route within the limits above (:mod:`fm2uav.planning.altitude`).
        "fm2": the FM² geodesic's own heights on the grid's flight layer (the
        seeds' result, for reproducing and tuning Algorithm 2; up to a cell
        below the request and blind to the ground between nodes).
    """

    agl: float
    p1: float = 0.5
    p2: float = 1.3
    band: float = 0.0
    graded: bool = False
    mode: Literal["capped", "literal"] = "capped"
    tolerance: float = 2.0
    min_agl: float | None = None
    max_agl: float | None = None
    max_climb: float = 45.0
    max_descent: float = 45.0
    heights: Literal["ground", "fm2"] = "ground"

    def __post_init__(self) -> None:
        _set(self, "agl", v.positive(self.agl, "agl", unit="m", where=_where("agl")))
        for name in ("max_climb", "max_descent"):
            _set(self, name, v.in_range(getattr(self, name), name, 0.0, 90.0, low_open=True,
                                        unit="deg", where=_where(name)))
        for name in ("p1", "p2"):
            _set(self, name, v.in_range(
                getattr(self, name), name, 0.0, None, low_open=True, where=_where(name),
                hint="p1 < 1 clarifies the level, p2 > p1 darkens the rest, e.g. p1=0.5, p2=1.3"))
        _set(self, "band", v.non_negative(self.band, "band", unit="m", where=_where("band")))
        _set(self, "graded", v.flag(self.graded, "graded", where=_where("graded")))
        v.choice(self.mode, FLIGHT_LEVEL_MODES, "mode", where=_where("mode"))
        v.choice(self.heights, FLIGHT_LEVEL_HEIGHTS, "heights", where=_where("heights"))
        _set(self, "tolerance", v.non_negative(
            self.tolerance, "tolerance", unit="m", where=_where("tolerance")))
        _set(self, "min_agl", v.optional(
            v.non_negative, self.min_agl, "min_agl", unit="m", where=_where("min_agl")))
        _set(self, "max_agl", v.optional(
            v.positive, self.max_agl, "max_agl", unit="m", where=_where("max_agl")))
        for name, unit in (("agl", "m"), ("p1", ""), ("p2", ""), ("band", "m"),
                           ("tolerance", "m"), ("min_agl", "m"), ("max_agl", "m")):
            _upper(self, name, unit)
        if self.min_agl is not None and self.min_agl > self.agl:
            raise InputError(
                f"agl = {self.agl:g} m is below min_agl = {self.min_agl:g} m (the altitude "
                f"floor); raise agl or lower min_agl (mission file: planner.agl, "
                f"planner.min_agl; CLI: --agl, --min-agl)")
        if self.max_agl is not None and self.agl > self.max_agl:
            raise InputError(
                f"agl = {self.agl:g} m is above max_agl = {self.max_agl:g} m (the altitude "
                f"ceiling); lower agl to at most {self.max_agl:g} m or raise max_agl (mission "
                f"file: planner.agl, planner.max_agl; CLI: --agl, --max-agl)")
        if self.min_agl is not None and self.max_agl is not None \
                and self.min_agl >= self.max_agl:
            raise InputError(
                f"min_agl = {self.min_agl:g} m is not below max_agl = {self.max_agl:g} m; "
                "lower min_agl or raise max_agl (mission file: planner.min_agl, "
                "planner.max_agl; CLI: --min-agl, --max-agl)")


#: Smallest geodesic step [cells]: finer steps do not change the path measurably but
#: multiply the descent's work (1e-9 took minutes).
MIN_STEP = 0.01


@dataclass(frozen=True, eq=False)
class PlanOptions:
    """How :func:`fm2uav.plan` computes, beyond the shaping and the flight level.

    Attributes
    ----------
    order : {1, 2}
        Order of both Fast Marching runs. Default 2.
    step : float
        Geodesic step in cells of the finest axis, in [0.01, 1]. Default 0.5.
    speed_map : ndarray or None
        Use this velocity map (one value per node, 0 = impassable) instead of
        computing one; the shaping and the flight level are then ignored. The
        hook for extra shaping (other UAVs, custom costs). Default None.
    storage : {"auto", "full", "regional"}
        How the plan holds the map. "full": one 3D grid of the whole world
        (W, T: ~40 bytes per node). "regional": coarse-to-fine for maps too big
        for that (a coarse plan over the whole map, then full-resolution plans in
        windows along its route; needs a 3D terrain world and a flight level;
        :mod:`fm2uav.planning.regional`). "auto" (default): "regional" when the
        full grid would take more than
        :data:`fm2uav.planning.regional.FULL_PLAN_MEMORY_SHARE` of this machine's
        memory and the world allows it, else "full".
    threads : int or None
        Threads of the Fast Marching runs (``>= 1``); None (default): the
        environment variable ``FM2UAV_THREADS``, else every core. Grids of 1 M
        nodes or more march in parallel at order 1 and 2 (order 1: the same times
        to round-off, order 2: bit for bit); see :func:`fm2uav.eikonal.fast_marching`.
        The distance transform of W and the march's set-up on grids of 2 M nodes or
        more run on as many (the same values bit for bit).
    """

    order: Literal[1, 2] = 2
    step: float = 0.5
    speed_map: np.ndarray | None = None
    storage: Literal["auto", "full", "regional"] = "auto"
    threads: int | None = None

    def __post_init__(self) -> None:
        _set(self, "order", v.integer(self.order, "order", where=_where("order")))
        v.choice(self.order, (1, 2), "order", where=_where("order"))
        # below 0.01 cells the descent only multiplies its work (issue 17: step 1e-9 ran for
        # minutes); see MIN_STEP
        _set(self, "step", v.in_range(self.step, "step", MIN_STEP, 1.0,
                                      where=_where("step"), hint="the geodesic step in cells"))
        if self.speed_map is not None:
            import numpy as np

            try:
                W = np.asarray(self.speed_map, dtype=float)
            except (TypeError, ValueError):
                raise InputError(
                    f"speed_map must be a numeric array (one speed per node), got "
                    f"{type(self.speed_map).__name__}") from None
            _set(self, "speed_map", W)
        v.choice(self.storage, STORAGE_MODES, "storage", where=_where("storage"))
        if self.threads is not None:
            _set(self, "threads", v.integer(self.threads, "threads", minimum=1,
                                            where=_where("threads")))


_CLASSES = (Shaping, FlightLevel, PlanOptions)


def planner_keys() -> dict[str, tuple[str, ...]]:
    """Field names of each parameter object: ``{"Shaping": (...), ...}``."""
    return {cls.__name__: tuple(f.name for f in fields(cls)) for cls in _CLASSES}


def planner_objects(
    values: Mapping[str, Any],
) -> tuple[Shaping, FlightLevel | None, PlanOptions]:
    """Build the three objects from one flat mapping of planner keys.

    The mapping is a mission file's ``planner:`` section or the CLI options:
    its keys are the field names of :class:`Shaping`, :class:`FlightLevel` and
    :class:`PlanOptions` (they are distinct). Keys whose value is None take
    the default. A flight level is made when ``agl`` is given; flight-level
    keys without ``agl`` are an error.

    Raises
    ------
    InputError
        Unknown key, a flight-level key without ``agl``, or a bad value.

    Examples
    --------
    >>> s, lv, o = planner_objects({"exponent": 2.0, "agl": 60, "p2": 1.5, "order": 1})
    >>> s.exponent, lv.agl, lv.p2, o.order
    (2.0, 60.0, 1.5, 1)
    """
    given = {k: val for k, val in dict(values).items() if val is not None}
    keys = planner_keys()
    parts: list[dict[str, Any]] = [{} for _ in _CLASSES]
    for k, val in given.items():
        for i, cls in enumerate(_CLASSES):
            if k in keys[cls.__name__]:
                parts[i][k] = val
                break
        else:
            known = ", ".join(n for names in keys.values() for n in names)
            raise InputError(f"unknown planner key {k!r}; allowed: {known}")
    shaping_kw, level_kw, options_kw = parts
    level = None
    if "agl" in level_kw:
        level = FlightLevel(**level_kw)
    elif level_kw:
        first = sorted(level_kw)[0]
        key, flag_ = _where(first)
        raise InputError(
            f"{first} is a flight-level setting but no agl is given; add agl (mission file: "
            f"planner.agl; CLI: --agl) or drop {first} ({key} / {flag_})")
    return Shaping(**shaping_kw), level, PlanOptions(**options_kw)


def plan_params(shaping: Shaping, level: FlightLevel | None, options: PlanOptions) -> dict[str, Any]:
    """Flat JSON-friendly record of the planner's parameters (``Plan.params``).

    The field names of the objects (one spelling): ``saturation``, ...,
    ``order``, ``step``, ``custom_speed_map`` and, with a level, ``agl``, ``p1``,
    ``p2``, ``band``, ... ``max_descent``. With a custom speed map the level
    was not applied and is left out.
    """
    custom = options.speed_map is not None
    out: dict[str, Any] = asdict(shaping)
    out.update(order=int(options.order), step=float(options.step), custom_speed_map=custom)
    if level is not None and not custom:
        out.update(asdict(level))
    return out
