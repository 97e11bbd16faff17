"""α–β sweep of FM² against curvature-penalised references (seed 004, §3).

For each start/goal pair, FM² is run for every saturation α and exponent β of
a grid (the seed: α, β ∈ 0.02:0.02:1, 2500 pairs) and its path compared with
the Dubins, elastica and Reeds–Shepp-forward reference paths of the same pair
by the discrete Fréchet distance and the area between the curves. The
distance transform is computed once per map (``plan`` reuses
:func:`fm2uav.planning.base_velocity`, cached on the world); only the shaping
and the second wave (T) change across the sweep.

Pure functions over arrays; the parallel runner lives in
:mod:`fm2uav.experiments.runner`, the figures in :mod:`fm2uav.viz.sweep`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy import fft, optimize

from ..errors import Fm2uavError, InputError
from ..planning import PlanOptions, Shaping, plan
from ..world import World
from ..analysis.similarity import area_between_curves, frechet_distance
from ..geometry import arc_length, menger_curvature, resample_path
from ..world.clearance import clearance_profile

__all__ = [
    "parameter_grid",
    "compare_paths",
    "sweep_alpha_row",
    "distance_matrix",
    "best_parameters",
    "NEAR_BEST_TOLERANCE",
    "near_best",
    "valley",
    "smooth_dct",
    "curvature_profile",
    "min_clearance",
    "summarise_sweep",
    "METRICS",
]

#: Similarity measures of the sweep (column prefixes of the results).
METRICS = ("frechet", "area")


def parameter_grid(start: float = 0.02, stop: float = 1.0, step: float = 0.02) -> np.ndarray:
    """``start:step:stop`` inclusive (Matlab style), rounded to 10 decimals.

    >>> parameter_grid(0.25, 1.0, 0.25).tolist()
    [0.25, 0.5, 0.75, 1.0]
    """
    if not (0 < start <= stop and step > 0):
        raise InputError(f"need 0 < start <= stop and step > 0, got {start}, {stop}, {step}")
    n = int(math.floor((stop - start) / step + 1e-9)) + 1
    return np.round(start + step * np.arange(n), 10)


def resample_references(references: Mapping[str, np.ndarray], ds: float) -> dict[str, np.ndarray]:
    """Each reference resampled every ``ds`` metres (:func:`~fm2uav.geometry.resample_path`),
    as :func:`compare_paths` compares them: a sweep does it once per pair, not per case."""
    return {model: resample_path(ref, ds) for model, ref in references.items()}


def compare_paths(
    path: np.ndarray, references: Mapping[str, np.ndarray], *, ds: float = 1.0,
    resampled: bool = False,
) -> dict[str, float]:
    """Fréchet distance [m] and area between curves [m²] to each reference.

    Both curves are resampled every ``ds`` metres first, so the discrete
    Fréchet distance does not depend on how densely each planner samples;
    ``resampled=True`` says the references already are
    (:func:`resample_references` with the same ``ds``).
    Keys: ``frechet_<model>``, ``area_<model>``.
    """
    p = resample_path(path, ds)
    refs = references if resampled else resample_references(references, ds)
    out: dict[str, float] = {}
    for model, r in refs.items():
        out[f"frechet_{model}"] = frechet_distance(p, r)
        out[f"area_{model}"] = area_between_curves(p, r)
    return out


def sweep_alpha_row(
    world: World,
    start: Sequence[float],
    goal: Sequence[float],
    alpha: float,
    betas: Sequence[float],
    references: Mapping[str, np.ndarray],
    *,
    ds: float = 1.0,
    order: int = 2,
    resampled: bool = False,
) -> list[dict[str, Any]]:
    """FM² for one α and every β of a row, compared with the references.

    Each (α, β) is one case: its row holds ``alpha, beta, status`` ("ok" or
    "error"), ``error`` (message), ``fm2_time_s`` (plan wall time [s]),
    ``length_m``, ``clearance_m`` and the :func:`compare_paths` metrics.
    A failing case is recorded with its error and does not stop the others.
    ``resampled``: the references are already :func:`resample_references` of ``ds``.
    """
    rows = []
    for beta in betas:
        row: dict[str, Any] = {"alpha": float(alpha), "beta": float(beta), "status": "ok", "error": ""}
        try:
            t0 = time.perf_counter()
            p = plan(world, start, goal,
                     shaping=Shaping(saturation=float(alpha), exponent=float(beta)),
                     options=PlanOptions(order=order))
            row["fm2_time_s"] = time.perf_counter() - t0
            row["length_m"] = p.length
            row["clearance_m"] = p.clearance
            row.update(compare_paths(p.path, references, ds=ds, resampled=resampled))
        except (Fm2uavError, ValueError, FloatingPointError) as exc:
            row["status"] = "error"
            row["error"] = f"{type(exc).__name__}: {exc}"
        rows.append(row)
    return rows


def distance_matrix(
    columns: Mapping[str, np.ndarray],
    column: str,
    alphas: np.ndarray,
    betas: np.ndarray,
    *,
    reduce: str = "mean",
) -> np.ndarray:
    """``(len(alphas), len(betas))`` matrix of a result column over the pairs.

    Parameters
    ----------
    columns : mapping of str to ndarray
        Result columns (at least ``alpha``, ``beta``, ``status`` and
        ``column``), one entry per case.
    column : str
        E.g. ``"frechet_dubins"``.
    alphas, betas : ndarray
        The grid.
    reduce : {"mean", "median", "max"}
        How the pairs are combined. Cases that failed count as ``inf``, so a
        cell is finite only if every pair succeeded there.
    """
    a = np.asarray(columns["alpha"], dtype=float)
    b = np.asarray(columns["beta"], dtype=float)
    ok = np.asarray(columns["status"]) == "ok"
    v = np.where(ok, np.asarray(columns[column], dtype=float), np.inf)
    ia = np.searchsorted(np.asarray(alphas), np.round(a, 10))
    ib = np.searchsorted(np.asarray(betas), np.round(b, 10))
    inside = (ia < len(alphas)) & (ib < len(betas))
    ia, ib, v = ia[inside], ib[inside], v[inside]
    inside = np.isclose(np.asarray(alphas)[ia], a[inside]) & np.isclose(np.asarray(betas)[ib], b[inside])
    ia, ib, v = ia[inside], ib[inside], v[inside]
    fn = {"mean": np.mean, "median": np.median, "max": np.max}.get(reduce)
    if fn is None:
        raise InputError(f"reduce must be mean, median or max, got {reduce!r}")
    out = np.full((len(alphas), len(betas)), np.nan)
    flat = ia * len(betas) + ib
    order = np.argsort(flat, kind="stable")
    flat, v = flat[order], v[order]
    bounds = np.flatnonzero(np.diff(flat)) + 1
    for idx, vals in zip(np.split(flat, bounds), np.split(v, bounds)):
        if len(idx):
            out.flat[idx[0]] = fn(vals) if np.all(np.isfinite(vals)) else np.inf
    return out


def best_parameters(matrix: np.ndarray, alphas: np.ndarray, betas: np.ndarray) -> dict[str, float]:
    """The (α, β) of the smallest finite entry of a distance matrix."""
    m = np.where(np.isfinite(matrix), matrix, np.inf)
    if not np.isfinite(m).any():
        raise InputError("the distance matrix has no finite entry (every case failed)")
    i, j = np.unravel_index(int(np.argmin(m)), m.shape)
    return {"alpha": float(alphas[i]), "beta": float(betas[j]), "value": float(m[i, j])}


#: Relative tolerance of the near-best set: (α, β) within 1 % of the best distance.
NEAR_BEST_TOLERANCE = 0.01


def near_best(matrix: np.ndarray, alphas: np.ndarray, betas: np.ndarray, *,
              tolerance: float = NEAR_BEST_TOLERANCE) -> dict[str, Any]:
    """The (α, β) whose distance is within ``tolerance`` of the best: the flat valley.

    The argmin of a flat valley moves with the grid step and the pairs; the set of
    near-best parameters does not (much). Returns ``tolerance``, ``threshold``
    (``best · (1 + tolerance)``), ``count``, the extent ``alpha_min``, ``alpha_max``,
    ``beta_min``, ``beta_max``, ``share`` (count over the finite cells) and ``points``
    (list of ``(α, β)``, ordered by distance).

    >>> m = np.array([[1.0, 1.005], [1.02, np.inf]])
    >>> r = near_best(m, np.array([0.1, 0.2]), np.array([0.5, 0.6]))
    >>> r["count"], r["beta_max"], r["points"]
    (2, 0.6, [(0.1, 0.5), (0.1, 0.6)])
    """
    if not tolerance >= 0:
        raise InputError(f"near-best tolerance must be >= 0, got {tolerance!r}")
    m = np.where(np.isfinite(matrix), matrix, np.inf)
    if not np.isfinite(m).any():
        raise InputError("the distance matrix has no finite entry (every case failed)")
    best = float(m.min())
    thr = best * (1.0 + tolerance) if best >= 0 else best * (1.0 - tolerance)
    ia, ib = np.nonzero(m <= thr)
    order = np.argsort(m[ia, ib], kind="stable")
    ia, ib = ia[order], ib[order]
    a = np.asarray(alphas, dtype=float)[ia]
    b = np.asarray(betas, dtype=float)[ib]
    return {"tolerance": float(tolerance), "threshold": thr, "count": int(len(ia)),
            "share": float(len(ia) / np.isfinite(m).sum()),
            "alpha_min": float(a.min()), "alpha_max": float(a.max()),
            "beta_min": float(b.min()), "beta_max": float(b.max()),
            "points": [(float(x), float(y)) for x, y in zip(a, b)]}


def valley(matrix: np.ndarray, alphas: np.ndarray, betas: np.ndarray) -> dict[str, Any]:
    """The valley of a distance matrix: the best β for every α.

    Returns ``alpha``, ``beta_best``, ``value`` arrays and the Spearman rank
    correlation between α and the best β (its sign and size show how the two
    parameters are coupled; 0 = independent).
    """
    m = np.where(np.isfinite(matrix), matrix, np.inf)
    rows = np.isfinite(m).any(axis=1)
    j = np.argmin(m[rows], axis=1)
    a = np.asarray(alphas)[rows]
    bb = np.asarray(betas)[j]
    vals = m[rows][np.arange(len(j)), j]
    rho = float("nan")
    if len(a) > 2 and np.ptp(bb) > 0:
        from scipy.stats import spearmanr

        rho = float(spearmanr(a, bb).statistic)
    return {"alpha": a, "beta_best": bb, "value": vals, "spearman": rho}


def smooth_dct(y: np.ndarray, s: float | None = None) -> np.ndarray:
    """Penalised least-squares smoothing with the DCT (Garcia 2010, seed ref. [28]).

    ``ŷ = IDCT(Γ · DCT(y))`` with ``Γ_k = 1 / (1 + s λ_k²)``,
    ``λ_k = -2 + 2 cos(k π / n)``. With ``s=None`` the smoothing parameter
    minimises the generalised cross-validation score (unsupervised, as in
    the seed's DCT-PLS).
    """
    y = np.asarray(y, dtype=float)
    n = y.size
    if n < 3:
        return y.copy()
    lam = -2.0 + 2.0 * np.cos(np.arange(n) * np.pi / n)
    Y = fft.dct(y, norm="ortho")

    def fit(log_s: float):
        gamma = 1.0 / (1.0 + 10.0**log_s * lam**2)
        return gamma, fft.idct(gamma * Y, norm="ortho")

    def gcv(log_s: float) -> float:
        gamma, yh = fit(log_s)
        rss = float(np.sum((yh - y) ** 2))
        tr = float(np.sum(gamma))
        return rss / n / (1.0 - tr / n) ** 2

    if s is None:
        res = optimize.minimize_scalar(gcv, bounds=(-6.0, 8.0), method="bounded")
        log_s = float(res.x)
    else:
        if not s > 0:
            raise InputError(f"s must be > 0, got {s!r}")
        log_s = math.log10(s)
    return fit(log_s)[1]


def curvature_profile(path: np.ndarray, *, ds: float = 1.0, smooth: bool = True) -> dict[str, np.ndarray]:
    """Curvature along a 2D path resampled every ``ds`` metres.

    Returns ``s`` (arc length [m] of the interior points), ``kappa`` (raw
    signed curvature [1/m], Menger magnitude with the turn's sign) and, with
    ``smooth``, ``kappa_smooth`` (:func:`smooth_dct`).
    """
    p = resample_path(path, ds)
    if len(p) < 3:
        z = np.zeros(0)
        return {"s": z, "kappa": z, "kappa_smooth": z}
    k = menger_curvature(p)
    a = p[1:-1] - p[:-2]
    b = p[2:] - p[1:-1]
    k = k * np.sign(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    s = arc_length(p)[1:-1]  # at the interior points, where the curvature is
    out = {"s": s, "kappa": k}
    if smooth:
        out["kappa_smooth"] = smooth_dct(k)
    return out


def min_clearance(world: World, path: np.ndarray) -> float:
    """Smallest distance from a path to an obstacle node [m] (Table 4)."""
    return float(clearance_profile(world, path).min())


def _best_paths(world: World, starts: np.ndarray, goals: np.ndarray,
                references: Mapping[tuple[int, str], Mapping[str, Any]], model: str,
                best: Mapping[str, Any], order: int) -> list[tuple[np.ndarray, np.ndarray] | None]:
    """Per pair, ``(fm2_path, ref_path)`` [m] at the best (α, β); None without a reference or plan."""
    pairs: list[tuple[np.ndarray, np.ndarray] | None] = []
    for k in range(len(starts)):
        ref = references.get((k, model), {})
        if ref.get("error", "x") or "path" not in ref:
            pairs.append(None)
            continue
        try:
            p = plan(world, starts[k], goals[k],
                     shaping=Shaping(saturation=best["alpha"], exponent=best["beta"]),
                     options=PlanOptions(order=order))
        except Fm2uavError:
            pairs.append(None)
            continue
        pairs.append((p.path, np.asarray(ref["path"])))
    return pairs


def _timing_table(columns: Mapping[str, np.ndarray], models: Sequence[str],
                  references: Mapping[tuple[int, str], Mapping[str, Any]],
                  n_pairs: int) -> dict[str, Any]:
    """Table 1: total reference search time [s] per model, FM²'s (sum of per-pair medians), ratios."""
    fm2_t = 0.0
    ok = np.asarray(columns["status"]) == "ok"
    for k in range(n_pairs):
        sel = ok & (np.asarray(columns["pair"]) == k)
        if sel.any():
            fm2_t += float(np.median(np.asarray(columns["fm2_time_s"])[sel]))
    timing: dict[str, Any] = {"fm2_s": fm2_t, "pairs": n_pairs}
    for model in models:
        ts = [references[(k, model)].get("time_s", np.nan) for k in range(n_pairs)
              if (k, model) in references]
        t = float(np.nansum(ts)) if ts else float("nan")
        timing[f"{model}_s"] = t
        timing[f"{model}_ratio"] = t / fm2_t if fm2_t > 0 else float("nan")
    return timing


def summarise_sweep(
    world: World,
    starts: np.ndarray,
    goals: np.ndarray,
    columns: Mapping[str, np.ndarray],
    alphas: np.ndarray,
    betas: np.ndarray,
    models: Sequence[str],
    references: Mapping[tuple[int, str], Mapping[str, Any]],
    *,
    ds: float = 1.0,
    order: int = 2,
) -> dict[str, Any]:
    """Tables 1–4 of the seed from sweep results, plus the best-match paths.

    Returns a dict with:

    * ``matrices[metric][model]``: mean-over-pairs distance matrices;
    * ``best[metric][model]``: ``{alpha, beta, value}`` (Tables 2 and 3);
    * ``valley[metric][model]``: best β per α and its Spearman correlation;
    * ``near_best[metric][model]``: the (α, β) within 1 % of the best and their extent
      (:func:`near_best`); ``best[metric][model]["near_best"]`` repeats the extent
      (count, α and β ranges) without the points;
    * ``timing``: Table 1 — total reference search time over the pairs per
      model and FM²'s (sum over pairs of the median plan time over the grid),
      with their ratios;
    * ``clearance[model]``: Table 4 — mean over pairs of the smallest distance
      to obstacles [m] of the reference paths and of FM² at the best area
      (α, β);
    * ``paths[metric][model]``: list over pairs of ``(fm2_path, ref_path)`` at
      the best (α, β) (None where a case failed);
    * ``curvature[metric][model]``: curvature profiles (reference and FM²) of
      the first pair.
    """
    n_pairs = len(starts)
    out: dict[str, Any] = {"matrices": {}, "best": {}, "valley": {}, "near_best": {},
                           "paths": {}, "curvature": {}}
    for metric in METRICS:
        out["matrices"][metric], out["best"][metric], out["valley"][metric] = {}, {}, {}
        out["near_best"][metric] = {}
        out["paths"][metric], out["curvature"][metric] = {}, {}
        for model in models:
            col = f"{metric}_{model}"
            if col not in columns:
                continue
            m = distance_matrix(columns, col, alphas, betas)
            out["matrices"][metric][model] = m
            if not np.isfinite(m).any():
                continue
            best = best_parameters(m, alphas, betas)
            near = near_best(m, alphas, betas)
            best["near_best"] = {k: v for k, v in near.items() if k != "points"}
            out["best"][metric][model] = best
            out["near_best"][metric][model] = near
            out["valley"][metric][model] = valley(m, alphas, betas)
            pairs = _best_paths(world, starts, goals, references, model, best, order)
            out["paths"][metric][model] = pairs
            first = next((pp for pp in pairs if pp is not None), None)
            if first is not None:
                out["curvature"][metric][model] = {
                    "reference": curvature_profile(first[1], ds=ds),
                    "fm2": curvature_profile(first[0], ds=ds),
                }

    out["timing"] = _timing_table(columns, models, references, n_pairs)

    # Table 4: clearance at the best area match
    clear: dict[str, Any] = {}
    for model in models:
        pairs = out["paths"].get("area", {}).get(model)
        if not pairs:
            continue
        done = [pp for pp in pairs if pp is not None]
        if not done:
            continue
        clear[model] = {
            "alpha": out["best"]["area"][model]["alpha"],
            "beta": out["best"]["area"][model]["beta"],
            "reference_m": float(np.mean([min_clearance(world, r) for _, r in done])),
            "fm2_m": float(np.mean([min_clearance(world, f) for f, _ in done])),
        }
    out["clearance"] = clear
    return out
