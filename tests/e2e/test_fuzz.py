"""Hypothesis fuzzing (derandomized: a fixed seed; ``FM2UAV_FUZZ=slow`` for many more
examples): worlds, points, parameters, coverage polygons and mission files. Only
Fm2uavError subclasses may escape, and no path point may lie in an obstacle."""

from __future__ import annotations

import numpy as np
import yaml
from hypothesis import assume, given
from hypothesis import strategies as st

from fm2uav import FlightLevel, PlanOptions, Shaping, World, plan
from fm2uav.errors import Fm2uavError

from .conftest import FUZZ

finite = st.floats(allow_nan=False, allow_infinity=False, width=32)
anything_number = st.one_of(finite, st.just(float("nan")), st.just(float("inf")),
                            st.just(-float("inf")), st.integers(-10**6, 10**6),
                            st.text(max_size=3), st.none(), st.booleans())


@st.composite
def worlds2d(draw):
    nx = draw(st.integers(3, 24))
    ny = draw(st.integers(3, 24))
    bits = draw(st.lists(st.booleans(), min_size=nx * ny, max_size=nx * ny))
    occ = np.array(bits, bool).reshape(nx, ny)
    spacing = draw(st.sampled_from([1.0, 0.5, 2.0, (1.0, 2.0), (0.3, 0.7)]))
    return World(occ, spacing=spacing)


@st.composite
def worlds3d(draw):
    nx, ny, nz = (draw(st.integers(3, 12)) for _ in range(3))
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    occ = rng.random((nx, ny, nz)) < draw(st.floats(0.0, 0.5))
    return World(occ, spacing=draw(st.sampled_from([1.0, (1.0, 1.0, 0.5)])))


def _point(world, data):
    hi = (np.asarray(world.shape) - 1) * np.asarray(world.spacing)
    lo = -0.2 * hi
    return [data.draw(st.floats(float(a), float(b) * 1.2 + 0.5, allow_nan=False))
            for a, b in zip(lo, hi)]


def _assert_path_free(world, p):
    cells = np.floor(world.to_index(p.path) + 0.5).astype(int)
    cells = np.clip(cells, 0, np.asarray(world.shape) - 1)
    assert not world.occupancy[tuple(cells.T)].any(), "a path point lies in an obstacle"


@FUZZ
@given(world=worlds2d(), data=st.data(),
       exponent=st.floats(0.05, 10.0), saturation=st.floats(0.01, 1.0),
       order=st.sampled_from([1, 2]), step=st.floats(0.01, 1.0))
def test_plan_2d_only_fm2uav_errors_and_free_paths(world, data, exponent, saturation, order,
                                                   step):
    start, goal = _point(world, data), _point(world, data)
    try:
        p = plan(world, start, goal, shaping=Shaping(saturation=saturation, exponent=exponent),
                 options=PlanOptions(order=order, step=step))
    except Fm2uavError:
        return
    _assert_path_free(world, p)
    assert np.all(np.isfinite(p.path)) and p.length >= 0


@FUZZ
@given(world=worlds3d(), data=st.data(), exponent=st.floats(0.1, 10.0))
def test_plan_3d_only_fm2uav_errors_and_free_paths(world, data, exponent):
    start, goal = _point(world, data), _point(world, data)
    try:
        p = plan(world, start, goal, shaping=Shaping(exponent=exponent))
    except Fm2uavError:
        return
    _assert_path_free(world, p)


@FUZZ
@given(start=st.lists(anything_number, min_size=0, max_size=4),
       goal=st.lists(anything_number, min_size=0, max_size=4))
def test_plan_points_of_any_shape(start, goal):
    w = World(np.zeros((8, 8), bool), spacing=1.0)
    try:
        plan(w, start, goal)
    except Fm2uavError:
        pass


@FUZZ
@given(kw=st.fixed_dictionaries({}, optional={
    "saturation": anything_number, "exponent": anything_number,
    "saturation_distance": anything_number, "method": st.text(max_size=4),
    "walls": anything_number}))
def test_shaping_any_values(kw):
    try:
        Shaping(**kw)
    except Fm2uavError:
        pass


@FUZZ
@given(kw=st.fixed_dictionaries({"agl": anything_number}, optional={
    "p1": anything_number, "p2": anything_number, "band": anything_number,
    "graded": anything_number, "mode": st.text(max_size=8), "tolerance": anything_number,
    "min_agl": anything_number, "max_agl": anything_number}))
def test_flight_level_any_values(kw):
    try:
        FlightLevel(**kw)
    except Fm2uavError:
        pass


@st.composite
def polygons(draw):
    n = draw(st.integers(3, 8))
    pts = [(draw(st.floats(-50, 2000)), draw(st.floats(-50, 2000))) for _ in range(n)]
    return pts


@FUZZ
@given(pts=polygons(), spacing=st.floats(0.01, 5000.0), angle=st.floats(-360.0, 360.0))
def test_coverage_area_and_spacing(pts, spacing, angle):
    """Any polygon (self-intersecting, degenerate, outside the map) and any band spacing:
    an Fm2uavError or a valid zigzag with finite points."""
    from shapely.geometry import Polygon

    from fm2uav.missions.coverage.area import as_area, check_spacing
    from fm2uav.missions.coverage.bands import zigzag

    try:
        area = as_area(Polygon(pts))
        d = check_spacing(area, spacing)
        zz = zigzag(area, d, angle)
    except Fm2uavError:
        return
    assert np.all(np.isfinite(zz.path(step=max(d, 1.0))))


_key = st.sampled_from(["version", "name", "world", "start", "goal", "planner", "airframe",
                        "outputs", "via", "scenario", "agl", "x"])
_scalar = st.one_of(st.none(), st.booleans(), st.integers(-1000, 1000), finite,
                    st.text(max_size=6))
_value = st.recursive(_scalar, lambda c: st.one_of(st.lists(c, max_size=3),
                                                   st.dictionaries(_key, c, max_size=3)),
                      max_leaves=8)


@FUZZ
@given(doc=st.dictionaries(_key, _value, max_size=6))
def test_mission_documents(doc):
    from fm2uav.io.mission import parse_mission

    try:
        m = parse_mission(doc, source="fuzz.yaml")
        m.plan_kwargs()
    except Fm2uavError:
        pass


@FUZZ
@given(text=st.text(max_size=80))
def test_mission_text(tmp_path_factory, text):
    from fm2uav.io.mission import load_mission

    f = tmp_path_factory.mktemp("m") / "m.yaml"
    f.write_text(text, encoding="utf-8")
    try:
        load_mission(f)
    except Fm2uavError:
        pass


@FUZZ
@given(doc=st.dictionaries(_key, _value, min_size=1, max_size=4), dup=_key)
def test_duplicate_keys_always_refused(tmp_path_factory, doc, dup):
    """A duplicated top-level key is refused whatever the document holds."""
    from fm2uav.errors import InputError
    from fm2uav.io.mission import load_mission

    body = yaml.safe_dump(doc, default_flow_style=False)
    assume(not body.startswith(("-", "[", "{")) and body.strip() not in ("", "{}"))
    text = f"{dup}: 1\n{body}{dup}: 2\n"
    f = tmp_path_factory.mktemp("d") / "m.yaml"
    f.write_text(text)
    try:
        load_mission(f)
    except InputError as exc:
        assert "duplicate key" in str(exc)
    else:
        raise AssertionError("duplicate key accepted")


@st.composite
def terrain_worlds(draw):
    nx, ny = draw(st.integers(8, 20)), draw(st.integers(8, 20))
    nz = draw(st.integers(10, 20))
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    ground = np.cumsum(rng.normal(0.0, draw(st.floats(0.0, 2.0)), (nx, ny)), axis=0)
    ground = np.clip(ground - ground.min(), 0.0, nz / 2)
    z = np.arange(nz, dtype=float)
    occ = z[None, None, :] <= ground[:, :, None]
    return World(occ, spacing=(10.0, 10.0, 5.0), terrain=ground * 5.0)


@FUZZ
@given(world=terrain_worlds(), data=st.data(), agl=st.floats(5.0, 60.0),
       p2=st.floats(0.5, 3.0))
def test_terrain_following_plans_stay_out_of_the_ground(world, data, agl, p2):
    """Terrain-following plans on random relief: an Fm2uavError or a path whose points all
    lie in free nodes (the final altitude profile included)."""
    hi = (np.asarray(world.shape) - 1) * np.asarray(world.spacing)
    pts = []
    for _ in range(2):
        x = data.draw(st.floats(0.0, float(hi[0])))
        y = data.draw(st.floats(0.0, float(hi[1])))
        pts.append([x, y, float(world.ground_height(x, y)) + agl])
    try:
        p = plan(world, pts[0], pts[1], level=FlightLevel(agl=agl, p2=p2))
    except Fm2uavError:
        return
    # the heights follow the continuous ground (bilinear), so the obstacle here is the
    # continuous surface, not the nearest grid node
    surface = np.asarray(world.surface_height(p.path[:, 0], p.path[:, 1]), dtype=float)
    below = p.path[:, 2] < surface - 1e-6
    assert not below.any(), (f"{int(below.sum())} path point(s) below the ground, worst "
                             f"{float((surface - p.path[:, 2]).max()):.3f} m")
