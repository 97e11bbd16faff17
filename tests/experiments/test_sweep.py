"""Sweep analysis: grids, distance matrices, valleys, smoothing, curvature."""

import math

import numpy as np
import pytest

from fm2uav.experiments.sweep import (
    best_parameters,
    compare_paths,
    curvature_profile,
    distance_matrix,
    parameter_grid,
    resample_references,
    smooth_dct,
    sweep_alpha_row,
    valley,
)
from fm2uav.errors import InputError
from fm2uav.scenarios.city2d import city2d_pairs, city2d_world


def test_parameter_grid_matches_matlab():
    g = parameter_grid(0.02, 1.0, 0.02)
    assert len(g) == 50 and g[0] == 0.02 and g[-1] == 1.0
    assert parameter_grid(0.04, 1.0, 0.04).tolist()[-1] == 1.0
    with pytest.raises(InputError):
        parameter_grid(0.5, 0.1, 0.1)


def _columns(alphas, betas, f, pairs=2, fail=None):
    rows = [(p, a, b) for p in range(pairs) for a in alphas for b in betas]
    cols = {
        "pair": np.array([r[0] for r in rows]),
        "alpha": np.array([r[1] for r in rows]),
        "beta": np.array([r[2] for r in rows]),
        "status": np.array(["ok"] * len(rows), dtype=object),
        "frechet_dubins": np.array([f(a, b) + p for p, a, b in rows]),
    }
    if fail is not None:
        cols["status"][fail] = "error"
    return cols


def test_distance_matrix_best_and_valley():
    alphas = parameter_grid(0.1, 1.0, 0.1)
    betas = parameter_grid(0.1, 1.0, 0.1)
    # a valley along beta = 1.1 - alpha
    f = lambda a, b: (a + b - 1.1) ** 2 + 0.01 * a  # noqa: E731
    cols = _columns(alphas, betas, f)
    m = distance_matrix(cols, "frechet_dubins", alphas, betas)
    assert m.shape == (10, 10)
    assert m[2, 3] == pytest.approx(f(0.3, 0.4) + 0.5)  # mean over pairs 0 and 1
    best = best_parameters(m, alphas, betas)
    assert (best["alpha"], best["beta"]) == (0.1, 1.0)
    v = valley(m, alphas, betas)
    assert np.allclose(v["beta_best"], np.round(1.1 - alphas, 10))
    assert v["spearman"] == pytest.approx(-1.0)


def test_failed_case_makes_cell_infinite():
    alphas = betas = parameter_grid(0.5, 1.0, 0.5)
    cols = _columns(alphas, betas, lambda a, b: a * b, fail=0)
    m = distance_matrix(cols, "frechet_dubins", alphas, betas)
    assert np.isinf(m[0, 0]) and np.isfinite(m[1, 1])
    assert best_parameters(m, alphas, betas)["alpha"] in (0.5, 1.0)


def test_smooth_dct_denoises():
    rng = np.random.default_rng(2)
    x = np.linspace(0, 4 * math.pi, 400)
    clean = np.sin(x)
    noisy = clean + rng.normal(0, 0.3, x.size)
    sm = smooth_dct(noisy)
    assert np.sqrt(np.mean((sm - clean) ** 2)) < 0.4 * np.sqrt(np.mean((noisy - clean) ** 2))
    # a straight line is kept (zero penalty on constants and nearly on linear trends)
    assert np.allclose(smooth_dct(np.full(50, 3.0)), 3.0)


def test_curvature_of_a_circle():
    t = np.linspace(0, math.pi, 500)
    circle = np.c_[20 * np.cos(t), 20 * np.sin(t)]  # counter-clockwise: left turn, +1/R
    prof = curvature_profile(circle, ds=0.5)
    assert np.median(prof["kappa"]) == pytest.approx(1 / 20, rel=1e-2)
    assert np.median(prof["kappa_smooth"]) == pytest.approx(1 / 20, rel=1e-2)
    prof = curvature_profile(circle[::-1], ds=0.5)
    assert np.median(prof["kappa"]) == pytest.approx(-1 / 20, rel=1e-2)


def test_sweep_row_records_each_case():
    w = city2d_world()
    s, g = city2d_pairs(1, 0, world=w)
    ref = np.vstack([s[0], g[0]])  # a straight "reference"
    rows = sweep_alpha_row(w, s[0], g[0], 0.5, [0.2, 0.8], {"dubins": ref})
    assert [r["status"] for r in rows] == ["ok", "ok"]
    assert rows[0]["frechet_dubins"] > 0 and rows[0]["area_dubins"] > 0
    # a case that fails (start inside a building) is recorded, not raised
    bad = np.array([200.0, 150.0])  # inside the Centre Pompidou
    rows = sweep_alpha_row(w, bad, g[0], 0.5, [0.2], {"dubins": ref})
    assert rows[0]["status"] == "error" and "PointError" in rows[0]["error"]


def test_references_resampled_once_give_the_same_metrics():
    rng = np.random.default_rng(11)
    path = np.cumsum(rng.normal(size=(40, 2)), axis=0)
    refs = {"dubins": np.cumsum(rng.normal(size=(300, 2)) * 0.2, axis=0),
            "rs": np.cumsum(rng.normal(size=(7, 2)) * 3, axis=0)}
    want = compare_paths(path, refs, ds=0.7)
    again = resample_references(refs, 0.7)
    assert compare_paths(path, again, ds=0.7, resampled=True) == want
    # resampling a resampled curve moves its points: the flag is what keeps the numbers
    assert compare_paths(path, again, ds=0.7) != want
