"""Choosing the steering angle: the seeds' Differential Evolution and checks of it.

* :func:`differential_evolution` — DE exactly as the seeds (paper 003 §IV,
  thesis eqs. 5.5–5.8): Np = 20 individuals, F = 0.8, CR = 0.7, 30
  generations, α in [1°, 89°]; initial population uniform in the bounds;
  donor ``v = x_r1 + F (x_r2 − x_r3)`` with r1, r2, r3 distinct and ≠ i;
  crossover (eq. 5.7, one gene) ``u = v`` if ``Cr_rand < 100·CR`` else
  ``u = x``; a trial leaving the bounds is re-drawn uniformly in them; greedy
  selection ``x ← u`` if ``f(u) < f(x)`` (eq. 5.8). Seeded with a numpy
  Generator. (Eq. 5.5 writes the initial draw as ``α_max·τ``, which can fall
  below the stated lower bound of 1°; we draw in the bounds.)
* :func:`sweep` — brute force over a dense grid of angles (verification).
* :func:`scipy_de` — :func:`scipy.optimize.differential_evolution` with the
  same settings, for comparison.

Every result keeps all the evaluated (α, cost) pairs, whose min / max /
median / mean are the columns of the seeds' Table 5.1.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import InputError
from .cost import ZigzagCost

__all__ = [
    "AngleSearch",
    "DESettings",
    "differential_evolution",
    "sweep",
    "scipy_de",
    "optimise_angle",
    "SEEDS_BOUNDS_DEG",
    "FULL_BOUNDS_DEG",
]

#: The seeds' search range of the steering angle [deg].
SEEDS_BOUNDS_DEG = (1.0, 89.0)
#: Every band direction once [deg] (α and α + 180° give the same lines).
FULL_BOUNDS_DEG = (0.0, 180.0)


@dataclass(frozen=True, eq=False)
class AngleSearch:
    """Result of a steering-angle search.

    Attributes
    ----------
    method : str
        ``"de"`` (the seeds' DE), ``"sweep"`` or ``"scipy-de"``.
    angle : float
        Best steering angle α [rad].
    cost : float
        C(α) at the best angle [m].
    evaluated_deg : ndarray
        Every evaluated angle [deg], in order (for DE: the initial population
        then each generation's trial vectors).
    evaluated_cost : ndarray
        C at each evaluated angle [m].
    bounds_deg : tuple of float
        Search range [deg].
    seconds : float
        Wall time of the search [s].
    params : dict
        Settings (Np, F, CR, generations, seed, step, ...).
    """

    method: str
    angle: float
    cost: float
    evaluated_deg: np.ndarray = field(repr=False)
    evaluated_cost: np.ndarray = field(repr=False)
    bounds_deg: tuple[float, float] = (1.0, 89.0)
    seconds: float = 0.0
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def angle_deg(self) -> float:
        """Best steering angle [deg]."""
        return math.degrees(self.angle)

    @property
    def evaluations(self) -> int:
        """Number of evaluated angles."""
        return int(self.evaluated_cost.size)

    def stats(self) -> dict[str, float]:
        """Table 5.1 columns over the evaluated angles.

        ``min_cost``/``min_alpha`` (best), ``max_cost``/``max_alpha`` (worst),
        ``median_cost``/``median_alpha`` and ``mean_cost``/``mean_alpha``
        (medians and means of each column); costs in m, angles in deg.
        """
        c, a = self.evaluated_cost, self.evaluated_deg
        i, j = int(np.argmin(c)), int(np.argmax(c))
        return {
            "min_cost": float(c[i]), "min_alpha": float(a[i]),
            "max_cost": float(c[j]), "max_alpha": float(a[j]),
            "median_cost": float(np.median(c)), "median_alpha": float(np.median(a)),
            "mean_cost": float(np.mean(c)), "mean_alpha": float(np.mean(a)),
        }


def _bounds(bounds_deg) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in bounds_deg)
    except (TypeError, ValueError):
        raise InputError(f"bounds must be (low, high) degrees, got {bounds_deg!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise InputError(f"bounds must be finite with low < high (degrees), got {bounds_deg!r}")
    return lo, hi


def _objective(area, spacing) -> ZigzagCost:
    return area if isinstance(area, ZigzagCost) else ZigzagCost.of(area, spacing)


@dataclass(frozen=True)
class DESettings:
    """The settings of a Differential Evolution, the same for :func:`differential_evolution`
    and :func:`scipy_de` (defaults: the seeds').

    Attributes
    ----------
    population : int
        Np (>= 4). Default 20.
    F : float
        Mutation factor in (0, 2]. Default 0.8.
    CR : float
        Crossover probability in [0, 1]. Default 0.7.
    generations : int
        Number of generations (>= 0). Default 30.

    Raises
    ------
    InputError
        A value outside its range.
    """

    population: int = 20
    F: float = 0.8
    CR: float = 0.7
    generations: int = 30

    def __post_init__(self) -> None:
        population, generations = self.population, self.generations
        if int(population) != population or population < 4:
            raise InputError(f"population must be an integer >= 4, got {population!r}")
        if int(generations) != generations or generations < 0:
            raise InputError(f"generations must be an integer >= 0, got {generations!r}")
        if not (0 < self.F <= 2):
            raise InputError(f"F must be in (0, 2], got {self.F!r}")
        if not (0 <= self.CR <= 1):
            raise InputError(f"CR must be in [0, 1], got {self.CR!r}")

    def params(self, seed: Any) -> dict[str, Any]:
        """The settings and the seed as :attr:`AngleSearch.params`."""
        return {"population": int(self.population), "F": float(self.F), "CR": float(self.CR),
                "generations": int(self.generations),
                "seed": seed if not isinstance(seed, np.random.Generator) else "generator"}


def differential_evolution(
    area,
    spacing: float | None = None,
    *,
    settings: DESettings = DESettings(),
    bounds_deg: tuple[float, float] = SEEDS_BOUNDS_DEG,
    seed: int | np.random.Generator | None = 0,
) -> AngleSearch:
    """Best steering angle by the seeds' Differential Evolution.

    Parameters
    ----------
    area : Polygon, GeoJSON dict, (k, 2) vertices or ZigzagCost
        The area [m] (or a prepared objective, then ``spacing`` is ignored).
    spacing : float
        Band spacing D [m].
    settings : DESettings, optional
        Np, F, CR and the number of generations. Default the seeds'.
    bounds_deg : (float, float), optional
        Range of α [deg]. Default the seeds' (1, 89); (0, 180) searches every
        band direction.
    seed : int or numpy.random.Generator, optional
        Randomness; same seed → same result. Default 0.

    Returns
    -------
    AngleSearch
    """
    t0 = time.perf_counter()
    f = _objective(area, spacing)
    lo, hi = _bounds(bounds_deg)
    F, CR = settings.F, settings.CR
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    npop = int(settings.population)
    x = lo + (hi - lo) * rng.random(npop)
    fx = np.array([f(v) for v in x])
    hist_a, hist_c = [x.copy()], [fx.copy()]
    others = np.array([[j for j in range(npop) if j != i] for i in range(npop)])
    for _ in range(int(settings.generations)):
        u = x.copy()
        fu = fx.copy()
        for i in range(npop):
            r1, r2, r3 = others[i][rng.choice(npop - 1, 3, replace=False)]
            v = x[r1] + F * (x[r2] - x[r3])
            if rng.random() * 100.0 < 100.0 * CR:
                ui = v
                if ui < lo or ui > hi:
                    ui = lo + (hi - lo) * rng.random()
                u[i] = ui
                fu[i] = f(ui)
        better = fu < fx
        x[better] = u[better]
        fx[better] = fu[better]
        hist_a.append(u)
        hist_c.append(fu)
    ea, ec = np.concatenate(hist_a), np.concatenate(hist_c)
    k = int(np.argmin(fx))
    return AngleSearch(
        method="de", angle=math.radians(float(x[k])), cost=float(fx[k]),
        evaluated_deg=ea, evaluated_cost=ec, bounds_deg=(lo, hi),
        seconds=time.perf_counter() - t0, params=settings.params(seed),
    )


def sweep(
    area,
    spacing: float | None = None,
    *,
    step_deg: float = 0.1,
    bounds_deg: tuple[float, float] = SEEDS_BOUNDS_DEG,
) -> AngleSearch:
    """Best steering angle by brute force on a grid ``step_deg`` apart (bounds included)."""
    t0 = time.perf_counter()
    f = _objective(area, spacing)
    lo, hi = _bounds(bounds_deg)
    if not (np.isfinite(step_deg) and step_deg > 0):
        raise InputError(f"step_deg must be > 0 degrees, got {step_deg!r}")
    n = int(math.floor((hi - lo) / step_deg + 1e-9)) + 1
    if n > 10_000_000:
        raise InputError(f"step_deg = {step_deg:g} gives {n} angles; use a larger step")
    a = lo + step_deg * np.arange(n)
    if a[-1] < hi - 1e-9 and bounds_deg != FULL_BOUNDS_DEG:
        a = np.append(a, hi)
    if (lo, hi) == FULL_BOUNDS_DEG:
        a = a[a < hi]  # 180° repeats 0°
    c = f(a)
    k = int(np.argmin(c))
    return AngleSearch(
        method="sweep", angle=math.radians(float(a[k])), cost=float(c[k]),
        evaluated_deg=a, evaluated_cost=c, bounds_deg=(lo, hi),
        seconds=time.perf_counter() - t0, params={"step_deg": float(step_deg)},
    )


def scipy_de(
    area,
    spacing: float | None = None,
    *,
    settings: DESettings = DESettings(),
    bounds_deg: tuple[float, float] = SEEDS_BOUNDS_DEG,
    seed: int | None = 0,
) -> AngleSearch:
    """Best steering angle by :func:`scipy.optimize.differential_evolution` (rand/1/bin,
    same Np, F, CR and generations, no polishing, no early stop)."""
    from scipy.optimize import differential_evolution as _de

    t0 = time.perf_counter()
    f = _objective(area, spacing)
    lo, hi = _bounds(bounds_deg)
    seen_a: list[float] = []
    seen_c: list[float] = []

    def fun(v):
        c = f(float(v[0]))
        seen_a.append(float(v[0]))
        seen_c.append(c)
        return c

    res = _de(fun, [(lo, hi)], strategy="rand1bin", maxiter=int(settings.generations),
              popsize=int(settings.population), mutation=float(settings.F),
              recombination=float(settings.CR), seed=seed, polish=False, tol=0.0, atol=0.0,
              init="random")
    return AngleSearch(
        method="scipy-de", angle=math.radians(float(res.x[0])), cost=float(res.fun),
        evaluated_deg=np.array(seen_a), evaluated_cost=np.array(seen_c),
        bounds_deg=(lo, hi), seconds=time.perf_counter() - t0, params=settings.params(seed),
    )


def optimise_angle(area, spacing: float, *, method: str = "de", **kwargs: Any) -> AngleSearch:
    """Dispatch to :func:`differential_evolution` (``"de"``), :func:`sweep` or :func:`scipy_de`."""
    table = {"de": differential_evolution, "sweep": sweep, "scipy-de": scipy_de}
    key = str(method).lower().replace("_", "-")
    if key not in table:
        raise InputError(f"unknown angle search {method!r}; use one of {', '.join(table)}")
    return table[key](area, spacing, **kwargs)
