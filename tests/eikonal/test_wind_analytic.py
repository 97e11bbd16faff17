"""Convergence of the wind march on analytic wind fields (``wind_cases.py``).

The cases and their exact times are documented in ``wind_cases.py``; the table
in docs/eikonal.md ("Wind") is its full output (one more grid per case). Errors
are over the nodes at least 0.1 m from the source; rates between grids whose
spacing halves.
"""

from __future__ import annotations

import numpy as np
import pytest

from .wind_cases import CASES, DOC, measure, rates, shear_extremal, shear_times, table_in_doc


@pytest.fixture(scope="module")
def rows():
    """Every (case, order) of the fast grids, measured once for this module."""
    out = {}
    for (name, ndim) in CASES:
        if ndim == 3:
            continue  # the 3D grids large enough for a rate are in the slow tests
        for order in (1, 2):
            out[(name, ndim, order)] = measure(name, ndim, order)
    return out


@pytest.mark.parametrize("name", ["constant", "spiral", "shear"])
def test_order2_is_second_order(rows, name):
    r = rows[(name, 2, 2)]
    max_rates = rates([x.err_max for x in r])
    l1_rates = rates([x.err_l1 for x in r])
    assert max_rates[-1] >= 1.8, max_rates
    assert l1_rates[-1] >= 1.8, l1_rates
    assert all(x.reopened == 0 for x in r)  # |w| / V <= 0.5 < 1/sqrt(2): causal


@pytest.mark.parametrize("name", ["constant", "spiral", "shear", "strong crosswind"])
def test_order1_is_first_order(rows, name):
    r = rows[(name, 2, 1)]
    for rate in rates([x.err_max for x in r])[-2:] + rates([x.err_l1 for x in r])[-2:]:
        assert 0.9 <= rate <= 1.3


@pytest.mark.parametrize("name", ["constant", "spiral", "shear"])
def test_order2_beats_order1(rows, name):
    fine1, fine2 = rows[(name, 2, 1)][-1], rows[(name, 2, 2)][-1]
    assert fine2.err_max < fine1.err_max / 3  # measured 3.5 - 5.3 at 161^2


def test_strong_crosswind_corrects_labels_and_converges(rows):
    # |w| / V = 0.9 > 1/sqrt(2): every node is non-acute, order 2 falls back to 1
    for order in (1, 2):
        r = rows[("strong crosswind", 2, order)]
        assert all(x.reopened > 0 for x in r)
        assert r[-1].err_max < 0.011  # 161^2: h = 1/160 m
    assert [x.err_max for x in rows[("strong crosswind", 2, 2)]] == \
        [x.err_max for x in rows[("strong crosswind", 2, 1)]]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["constant", "spiral"])
def test_3d_rates(name):
    r1 = measure(name, 3, 1)
    r2 = measure(name, 3, 2)
    assert rates([x.err_max for x in r1])[-1] >= 0.9  # 41^3 -> 81^3
    assert r2[-1].err_max < r1[-1].err_max / 1.5
    assert r2[-1].err_max < r2[-2].err_max / 5  # pre-asymptotic: 41^3 has a 2-cell ball


@pytest.mark.parametrize("name", ["constant", "spiral"])
def test_3d_converges(name):
    r = measure(name, 3, 1)[:2]  # 21^3, 41^3
    assert r[1].err_max < r[0].err_max and r[1].err_l1 < r[0].err_l1


def test_shear_extremals_solve_the_ode():
    # the closed-form extremals of the shear current against a fine RK4 integration of
    # x' = cos th + s y, y' = sin th, th' = -s cos^2 th (V = 1, s = 0.5)
    for th0, t_end in [(0.7, 1.3), (2.5, 1.1), (-1.5, 0.9), (1.5707, 0.9)]:
        z = np.array([0.0, 0.0, th0])
        n = 4000
        dt = t_end / n

        def f(z):
            return np.array([np.cos(z[2]) + 0.5 * z[1], np.sin(z[2]), -0.5 * np.cos(z[2]) ** 2])

        for _ in range(n):
            k1 = f(z)
            k2 = f(z + dt / 2 * k1)
            k3 = f(z + dt / 2 * k2)
            k4 = f(z + dt * k3)
            z = z + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        x, y = shear_extremal(np.tan(th0), t_end, np.sign(np.cos(th0)))
        np.testing.assert_allclose([x, y], z[:2], atol=1e-10)


def test_shear_times_recover_a_known_extremal():
    x, y = shear_extremal(np.array([0.3, -2.0]), np.array([0.8, 0.6]), np.array([1.0, -1.0]))
    t = shear_times(x, y, np.array([0.75, 0.65]), np.array([0.0, 3.0]))
    np.testing.assert_allclose(t, [0.8, 0.6], rtol=1e-10)


def test_docs_table_lists_every_case():
    table = table_in_doc(DOC.read_text())
    for (name, ndim), (_, sizes, more) in CASES.items():
        for order in (1, 2):
            for n in sizes + more:
                grid = "×".join([str(n)] * ndim)
                assert f"| {name} {ndim}D | {order} | {grid} |" in table, (name, ndim, order, n)


def test_docs_table_matches_a_fresh_run(rows):
    # the fast grids' rows must agree with docs/eikonal.md to the printed digits
    table = table_in_doc(DOC.read_text())
    lines = {tuple(c.strip() for c in line.strip("|").split("|")[:3]): line
             for line in table.splitlines()[2:]}
    checked = 0
    for (name, ndim, order), r in rows.items():
        for row in r:
            key = (f"{name} {ndim}D", str(order), "×".join([str(row.n)] * ndim))
            cells = [c.strip() for c in lines[key].strip("|").split("|")]
            assert abs(float(cells[4]) / row.err_max - 1) < 0.01, (key, cells[4], row.err_max)
            assert abs(float(cells[5]) / row.err_l1 - 1) < 0.01, (key, cells[5], row.err_l1)
            assert int(cells[8]) == row.reopened, key
            checked += 1
    assert checked == 24
