"""The wind march's face solve at late times: within a few ulps of the exact root.

The update of a node from a face of its stencil solves ``V |p| + w . p = 1`` for the
node's time ``u``, ``p`` the gradient the face's vertex times give (``p = M ((u_i - u)
i_i)``, ``M`` the face's ``E^-T``). Far from the source every time is large and the face's
times differ little: solved in ``u`` itself, the quadratic's coefficients are of the size
of ``u`` and cancel (the order-2 update's failure fixed in session 41,
``test_kernels_update.py``). :func:`fm2uav.eikonal._wind_kernels._face2` / ``_face3`` solve
in ``u - U0`` from a reference ``U0`` the caller takes at the node; these tests hold them to
that, against the root computed in 60-digit decimals from the same inputs. (The source
ball's factored update, :func:`fm2uav.eikonal._sources._factored_update`, needs no such
test: it solves for the factor ``T / T0`` of times counted from the source, never offset.)
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext

import numpy as np
import pytest

from fm2uav.eikonal import _wind_kernels as wk


def _exact(fm, us, scales, V, w, digits=60):
    """The larger root ``u`` of ``V |p| + w . p = 1``, ``p = M ((u_i - u) i_i)``, in
    ``digits``-digit decimals (``fm`` the face's ``E^-T``, ``us`` its vertex times [s],
    ``scales`` their ``i_i``, ``V`` the airspeed and ``w`` the wind [m/s])."""
    with localcontext() as ctx:
        ctx.prec = digits
        n = len(us)
        M = [[Decimal(float(fm[0, r, c])) for c in range(n)] for r in range(n)]
        ref = Decimal(us[0])
        i = [Decimal(s) for s in scales]
        r = [(Decimal(u) - ref) * s for u, s in zip(us, i)]
        a = [sum(M[k][c] * i[c] for c in range(n)) for k in range(n)]
        b = [sum(M[k][c] * r[c] for c in range(n)) for k in range(n)]
        Vd = Decimal(V)
        wd = [Decimal(x) for x in w[:n]]
        wa = sum(x * y for x, y in zip(wd, a))
        wb = sum(x * y for x, y in zip(wd, b))
        one = 1 - wb
        alpha = Vd * Vd * sum(x * x for x in a) - wa * wa
        beta = Vd * Vd * sum(x * y for x, y in zip(a, b)) + one * wa
        gamma = Vd * Vd * sum(x * x for x in b) - one * one
        return ref + (beta + (beta * beta - alpha * gamma).sqrt()) / alpha


def _face(ndim, rng, big):
    """A face of the 2D or 3D stencil (vertex offsets of one octant, spacings 0.5-2 m), a
    plane wave through it at ``big`` seconds and a wind of up to half the airspeed: ``(fm,
    vertex times, scales, V, w)``."""
    h = rng.uniform(0.5, 2.0, ndim)
    sign = rng.choice([-1.0, 1.0], ndim)
    # the face's vertices: an axis neighbour, then diagonals (the octant's corner last)
    E = np.zeros((ndim, ndim))
    for c in range(ndim):
        E[: c + 1, c] = 1.0
    E = E[rng.permutation(ndim)] * (sign * h)[:, None]
    fm = np.linalg.inv(E).T[None]
    V = rng.uniform(2.0, 20.0)
    w = rng.uniform(-0.5, 0.5, 3) * V / math.sqrt(3.0)
    w[ndim:] = 0.0
    # the wave arrives from inside the face: its ground velocity -E lam (lam > 0)
    lam = rng.uniform(0.2, 1.0, ndim)
    v = -(E @ lam)
    # the plane wave whose characteristic is v: n along v - w (|V n + w| parallel to v)
    # solved as the unit n with V n + w = s v for some s > 0
    vv = v / np.linalg.norm(v)
    wv = w[:ndim] @ vv
    wperp = w[:ndim] - wv * vv
    s = wv + math.sqrt(V * V - wperp @ wperp)
    n = (s * vv - w[:ndim]) / V
    grad = n / (V + w[:ndim] @ n)  # |grad| V + w . grad = 1
    # order 2 scales a vertex's difference by 3/2 (its value extrapolated from two nodes)
    scales = [float(x) for x in rng.choice([1.0, 1.5], ndim)]
    us = [big + float(grad @ E[:, c]) / scales[c] for c in range(ndim)]
    return fm, us, scales, V, w


def _solve(fm, us, scales, V, w, U0):
    if len(us) == 2:
        return wk._face2(fm, 0, us[0], scales[0], us[1], scales[1], U0, 0.0, 0.0, V, w[0],
                         w[1])[0]
    return wk._face3(fm, 0, us[0], scales[0], us[1], scales[1], us[2], scales[2], U0, 0.0,
                     0.0, 0.0, V, w[0], w[1], w[2])[0]


def _worst(ndim, big, reference):
    """The largest error [ulps of the root] over 200 faces, each solved from the reference
    ``reference(us)`` (the caller's: the smallest vertex time), and how many roots fell in
    their faces."""
    rng = np.random.default_rng(int(big) + ndim)
    worst = 0.0
    solved = 0
    for _ in range(200):
        fm, us, scales, V, w = _face(ndim, rng, big)
        got = _solve(fm, us, scales, V, w, reference(us))
        if got == math.inf:
            continue
        solved += 1
        exact = float(_exact(fm, us, scales, V, w))
        worst = max(worst, abs(got - exact) / math.ulp(exact))
    return worst, solved


@pytest.mark.parametrize("ndim", [2, 3])
@pytest.mark.parametrize("big", [1e2, 1e3, 1e4])
def test_the_face_solve_is_exact_to_a_few_ulps_at_late_times(ndim, big):
    worst, solved = _worst(ndim, big, min)
    assert solved >= 190, solved
    assert worst <= 8.0, worst


@pytest.mark.parametrize("ndim", [2, 3])
def test_without_the_reference_late_times_lose_digits(ndim):
    """The same faces solved in ``u`` itself (``U0 = 0``): at ``1e4`` s the root is off by
    thousands of ulps -- what the reference is for, and what the test above would catch."""
    worst, solved = _worst(ndim, 1e4, lambda us: 0.0)
    assert solved >= 190, solved
    assert worst > 1000.0, worst
