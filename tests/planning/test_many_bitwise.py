"""plan_many gives the bytes it gave before its descent and figures were made faster
(issue 27 deliverable 5): every route's path, w, length, clearance and altitude profile,
every failure's reason and message, on one thread and on two.

The digests in ``data/golden_many.json`` were written by the code of commit ad6df06
(``tests/planning/golden_many.py``): 2D city blocks (orders 1 and 2, walls), 3D
obstacles, terrain with a flight level. Where numpy runs AVX-512 loops the routes are
planned in a child Python with them off (tests/planning/golden_numpy.py says why).
"""

from __future__ import annotations

import json

import pytest

from .golden_many import DATA, cases, run_case
from .golden_numpy import Computed

GOLDEN = json.loads(DATA.read_text())
THREADS = [1, 2]
#: every call of this module, computed in one child where numpy runs AVX-512 loops
RUN = Computed(run_case, "tests.planning.golden_many:run_case",
               [((name,), {"threads": t}) for name in sorted(GOLDEN) for t in THREADS]
               + [(("2d_city",), {"step": 0.45})])


def test_the_golden_file_pins_every_case_with_routes_and_failures():
    assert sorted(GOLDEN) == sorted(cases())
    for name, digests in GOLDEN.items():
        assert len(digests) == len(cases()[name][2]), name
        routes = [d for d in digests if not d.startswith("fail:")]
        assert len(routes) >= 50 and all(len(d) == 64 for d in routes), name
        assert len(set(routes)) == len(routes), name  # distinct routes, not placeholders
    assert any(d.startswith("fail:") for d in GOLDEN["2d_city"])


@pytest.mark.parametrize("threads", THREADS)
@pytest.mark.parametrize("name", sorted(GOLDEN))
def test_plan_many_gives_the_golden_bytes(name, threads):
    got = RUN(name, threads=threads)
    bad = [k for k, (a, b) in enumerate(zip(got, GOLDEN[name])) if a != b]
    assert not bad, f"{len(bad)} routes differ, first at start {bad[:5]}"
    assert len(got) == len(GOLDEN[name])


def test_a_changed_route_fails_the_comparison():
    # the comparison can fail: a shorter descent step gives other paths
    got = RUN("2d_city", step=0.45)
    routes = [k for k, d in enumerate(GOLDEN["2d_city"]) if not d.startswith("fail:")]
    assert all(got[k] != GOLDEN["2d_city"][k] for k in routes)
