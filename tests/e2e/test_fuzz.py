"""Hypothesis fuzzing across layers (derandomized: a fixed seed; ``FM2UAV_FUZZ=slow`` for many
more examples). Two kinds of properties:

* **valid, reachable inputs** are drawn as such (free start and goal nodes in one connected
  component, polygons that are simple, spacings the area admits, documents a user could
  write), so every example reaches the property: the call must succeed and its result keep the
  invariants (endpoints exact, no point in an obstacle or below the ground, the bands cover the
  area, the values read are the values written);
* **anything else** must be refused with the right error: an :class:`~fm2uav.errors.InputError`
  or planning error in one line that names what was wrong (the field, its mission-file key and
  CLI flag, the file), never another exception — and when something odd is accepted, it must
  be read faithfully.
"""

from __future__ import annotations

import math

import numpy as np
import yaml
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy import ndimage

from fm2uav import FlightLevel, PlanOptions, Shaping, World, plan
from fm2uav.errors import Fm2uavError, InputError, PointError, UnreachableError

from .conftest import FUZZ

finite = st.floats(allow_nan=False, allow_infinity=False, width=32)
anything_number = st.one_of(finite, st.just(float("nan")), st.just(float("inf")),
                            st.just(-float("inf")), st.integers(-10**6, 10**6),
                            st.text(max_size=3), st.none(), st.booleans())


def _one_line(exc: Exception) -> str:
    msg = str(exc)
    assert msg and "\n" not in msg, f"not a one-line message: {msg!r}"
    return msg


# ---------------------------------------------------------------- planning: valid inputs
@st.composite
def worlds_with_a_route(draw, ndim: int):
    """A world and two free nodes of one face-connected component of free nodes (the Fast
    Marching neighbours), as points jittered less than a quarter cell off the nodes."""
    shape = tuple(draw(st.integers(4, 22 if ndim == 2 else 10)) for _ in range(ndim))
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    occ = rng.random(shape) < draw(st.floats(0.0, 0.35))
    labels, n = ndimage.label(~occ)  # face connectivity
    assume(n > 0)
    sizes = np.bincount(labels.ravel())[1:]
    big = int(np.argmax(sizes)) + 1
    assume(sizes[big - 1] >= 2)
    nodes = np.argwhere(labels == big)
    i, j = draw(st.lists(st.integers(0, len(nodes) - 1), min_size=2, max_size=2, unique=True))
    spacing = draw(st.sampled_from([1.0, 0.5, 2.0, (1.0, 2.0, 0.7)[:ndim], (0.3, 0.7, 1.1)[:ndim]]))
    sp = np.broadcast_to(np.asarray(spacing, float), (ndim,))
    jitter = [np.array([draw(st.floats(-0.24, 0.24)) for _ in range(ndim)]) for _ in range(2)]
    pts = []
    for node, jit in zip((nodes[i], nodes[j]), jitter):
        p = (node + jit) * sp
        pts.append(np.clip(p, 0.0, (np.asarray(shape) - 1) * sp))
    return World(occ, spacing=spacing), pts[0], pts[1]


def _assert_path_free(world, p):
    cells = np.floor(world.to_index(p.path) + 0.5).astype(int)
    cells = np.clip(cells, 0, np.asarray(world.shape) - 1)
    assert not world.occupancy[tuple(cells.T)].any(), "a path point lies in an obstacle"


def _assert_a_valid_path(world, p, start, goal):
    np.testing.assert_allclose(p.path[0], start, atol=1e-9)
    np.testing.assert_allclose(p.path[-1], goal, atol=1e-9)
    assert np.all(np.isfinite(p.path))
    _assert_path_free(world, p)
    seg = np.linalg.norm(np.diff(p.path, axis=0), axis=1)
    assert p.length == np.float64(p.length) and abs(p.length - seg.sum()) <= 1e-6 * (1 + seg.sum())
    assert p.length >= np.linalg.norm(np.asarray(goal) - start) - 1e-9
    assert np.all((p.w >= 0) & (p.w <= 1 + 1e-12))


@FUZZ
@given(case=worlds_with_a_route(2), exponent=st.floats(0.05, 10.0),
       saturation=st.floats(0.01, 1.0), order=st.sampled_from([1, 2]),
       step=st.floats(0.01, 1.0))
def test_plan_2d_between_connected_free_points_always_succeeds(case, exponent, saturation,
                                                               order, step):
    world, start, goal = case
    p = plan(world, start, goal, shaping=Shaping(saturation=saturation, exponent=exponent),
             options=PlanOptions(order=order, step=step))
    _assert_a_valid_path(world, p, start, goal)


@FUZZ
@given(case=worlds_with_a_route(3), exponent=st.floats(0.1, 10.0))
def test_plan_3d_between_connected_free_points_always_succeeds(case, exponent):
    world, start, goal = case
    p = plan(world, start, goal, shaping=Shaping(exponent=exponent))
    _assert_a_valid_path(world, p, start, goal)


# ---------------------------------------------------------------- planning: bad points
@FUZZ
@given(nx=st.integers(6, 20), ny=st.integers(3, 16), data=st.data())
def test_points_cut_off_blocked_or_off_the_map_are_refused_as_such(nx, ny, data):
    """A wall across the map: a goal behind it is unreachable, a point on it is in an obstacle,
    a point beyond the map is outside; each refused with its own error, naming the point."""
    occ = np.zeros((nx, ny), bool)
    wall = data.draw(st.integers(2, nx - 3))
    occ[wall] = True
    world = World(occ, spacing=1.0)
    left = [data.draw(st.floats(0.0, wall - 1.0)), data.draw(st.floats(0.0, ny - 1.0))]
    right = [data.draw(st.floats(wall + 1.0, nx - 1.0)), data.draw(st.floats(0.0, ny - 1.0))]
    try:
        plan(world, left, right)
    except UnreachableError as exc:
        _one_line(exc)
    else:
        raise AssertionError("a goal behind a full wall was reached")
    on_wall = [float(wall), data.draw(st.floats(0.0, ny - 1.0))]
    outside = [data.draw(st.floats(-1e6, -1.0) | st.floats(nx + 1.0, 1e6)),
               data.draw(st.floats(0.0, ny - 1.0))]
    for bad, which in ((on_wall, "goal"), (outside, "goal")):
        try:
            plan(world, left, bad)
        except PointError as exc:
            assert which in _one_line(exc)
        else:
            raise AssertionError(f"goal {bad} accepted")
    try:
        plan(world, outside, left)
    except PointError as exc:
        assert "start" in _one_line(exc)
    else:
        raise AssertionError(f"start {outside} accepted")


def _strict_point(v) -> bool:
    return (isinstance(v, list) and len(v) == 2
            and all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in v)
            and all(0.0 <= c <= 7.0 for c in v))


@FUZZ
@given(start=st.lists(anything_number, min_size=0, max_size=4),
       goal=st.lists(anything_number, min_size=0, max_size=4))
def test_plan_points_of_any_shape(start, goal):
    """Points inside the free 8 x 8 map always plan; anything refused is refused in one line
    naming start or goal; anything accepted is read as written."""
    w = World(np.zeros((8, 8), bool), spacing=1.0)
    same = _strict_point(start) and _strict_point(goal) and \
        np.array_equal(np.round(start), np.round(goal))
    try:
        p = plan(w, start, goal)
    except Fm2uavError as exc:
        msg = _one_line(exc)
        assert not (_strict_point(start) and _strict_point(goal)) or same, msg
        assert "start" in msg or "goal" in msg, msg
        return
    np.testing.assert_allclose(p.path[0], np.asarray(start, dtype=float), atol=1e-9)
    np.testing.assert_allclose(p.path[-1], np.asarray(goal, dtype=float), atol=1e-9)


# ---------------------------------------------------------------- parameter objects
def _number(v):
    """The finite float a value stands for, or None (bools are not numbers)."""
    if isinstance(v, bool):
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def _ok(v, low, high=None, *, low_open=True):
    f = _number(v)
    return f is not None and (f > low if low_open else f >= low) and (high is None or f <= high)


SHAPING_RULES = {
    "saturation": lambda v: _ok(v, 0.0, 1.0),
    "exponent": lambda v: _ok(v, 0.0),
    "saturation_distance": lambda v: v is None or _ok(v, 0.0),
    "method": lambda v: v in ("edt", "fmm"),
    "walls": lambda v: isinstance(v, bool),
}
LEVEL_RULES = {
    "agl": lambda v: _ok(v, 0.0),
    "p1": lambda v: _ok(v, 0.0), "p2": lambda v: _ok(v, 0.0),
    "band": lambda v: _ok(v, 0.0, low_open=False),
    "graded": lambda v: isinstance(v, bool),
    "mode": lambda v: v in ("capped", "literal"),
    "tolerance": lambda v: _ok(v, 0.0, low_open=False),
    "min_agl": lambda v: v is None or _ok(v, 0.0, low_open=False),
    "max_agl": lambda v: v is None or _ok(v, 0.0),
}


def _check_object(cls, kw, rules, cross=lambda kw: []):
    """Build ``cls(**kw)``: accepted iff every field meets its documented rule (and the
    cross-field rules); the values kept are the numbers given; a refusal is one line naming a
    field that breaks a rule, with its mission-file key and CLI flag."""
    bad = [k for k, v in kw.items() if not rules[k](v)]
    if not bad:
        bad = cross(kw)
    try:
        obj = cls(**kw)
    except InputError as exc:
        msg = _one_line(exc)
        assert bad, f"{cls.__name__}({kw}) refused: {msg}"
        assert any(f"planner.{k}" in msg and "--" + k.replace("_", "-") in msg for k in bad), \
            (bad, msg)
        return None
    assert not bad, f"{cls.__name__}({kw}) accepted though {bad} break their rules"
    for k, v in kw.items():
        got = getattr(obj, k)
        want = _number(v) if _number(v) is not None and not isinstance(v, str) or \
            isinstance(got, float) else v
        assert got == want or (got is None and v is None), (k, v, got)
    return obj


@FUZZ
@given(kw=st.fixed_dictionaries({}, optional={
    "saturation": anything_number, "exponent": anything_number,
    "saturation_distance": anything_number, "method": st.sampled_from(["edt", "fmm", "x", ""]),
    "walls": anything_number}))
def test_shaping_any_values(kw):
    _check_object(Shaping, kw, SHAPING_RULES)


@FUZZ
@given(kw=st.fixed_dictionaries({
    "saturation": st.floats(0.0, 1.0, exclude_min=True), "exponent": st.floats(0.01, 10.0),
    "saturation_distance": st.none() | st.floats(0.1, 1e5),
    "method": st.sampled_from(["edt", "fmm"]), "walls": st.booleans()}))
def test_shaping_valid_values_are_kept(kw):
    assert _check_object(Shaping, kw, SHAPING_RULES) is not None


def _level_cross(kw):
    agl, lo, hi = (_number(kw.get(k)) for k in ("agl", "min_agl", "max_agl"))
    bad = []
    if lo is not None and lo > agl:
        bad += ["min_agl"]
    if hi is not None and agl > hi:
        bad += ["max_agl"]
    if lo is not None and hi is not None and lo >= hi:
        bad += ["min_agl", "max_agl"]
    return bad


@FUZZ
@given(kw=st.fixed_dictionaries({"agl": anything_number}, optional={
    "p1": anything_number, "p2": anything_number, "band": anything_number,
    "graded": anything_number, "mode": st.sampled_from(["capped", "literal", "x"]),
    "tolerance": anything_number, "min_agl": anything_number, "max_agl": anything_number}))
def test_flight_level_any_values(kw):
    _check_object(FlightLevel, kw, LEVEL_RULES, _level_cross)


@FUZZ
@given(agl=st.floats(1.0, 500.0), data=st.data())
def test_flight_level_valid_values_are_kept(agl, data):
    kw = {"agl": agl, "p1": data.draw(st.floats(0.05, 3.0)), "p2": data.draw(st.floats(0.05, 3.0)),
          "band": data.draw(st.floats(0.0, 100.0)), "graded": data.draw(st.booleans()),
          "mode": data.draw(st.sampled_from(["capped", "literal"])),
          "min_agl": data.draw(st.none() | st.floats(0.0, agl)),
          "max_agl": data.draw(st.none() | st.floats(agl, 2 * agl + 1.0))}
    assume(kw["min_agl"] is None or kw["max_agl"] is None or kw["min_agl"] < kw["max_agl"])
    assert _check_object(FlightLevel, kw, LEVEL_RULES, _level_cross) is not None


# ---------------------------------------------------------------- coverage bands
@st.composite
def simple_polygons(draw):
    """Star-shaped (so simple) polygons: sorted angles, radii 40-100 % of R, anywhere."""
    n = draw(st.integers(3, 10))
    gaps = np.array(draw(st.lists(st.floats(0.2, 1.0), min_size=n, max_size=n)))
    angles = draw(st.floats(0.0, 6.3)) + 2 * math.pi * np.cumsum(gaps) / gaps.sum()
    r0 = draw(st.floats(50.0, 3000.0))
    radii = r0 * np.array(draw(st.lists(st.floats(0.4, 1.0), min_size=n, max_size=n)))
    cx, cy = draw(st.floats(-1e4, 1e4)), draw(st.floats(-1e4, 1e4))
    return [(cx + r * math.cos(a), cy + r * math.sin(a)) for a, r in zip(angles, radii)]


@FUZZ
@given(pts=simple_polygons(), share=st.floats(0.02, 0.5), angle=st.floats(-7.0, 7.0))
def test_coverage_bands_cover_any_simple_area(pts, share, angle):
    """The bands D apart, flown with a footprint D wide, cover the whole area; the bands lie
    within D/2 of it; the zigzag path is finite and joins the bands in order."""
    import shapely
    from shapely.geometry import Polygon

    from fm2uav.missions.coverage.area import as_area, check_spacing
    from fm2uav.missions.coverage.bands import zigzag

    area = as_area(Polygon(pts))
    hull = np.asarray(area.convex_hull.exterior.coords)
    diameter = np.sqrt(((hull[:, None] - hull[None]) ** 2).sum(-1)).max()
    d = check_spacing(area, share * diameter)
    zz = zigzag(area, d, angle)
    strips = shapely.unary_union([b.buffer(d / 2 * (1 + 1e-6), cap_style="flat")
                                  for b in zz.bands()])
    missed = area.difference(strips).area
    assert missed <= 1e-6 * area.area, f"{missed:.3g} m² of {area.area:.3g} m² not covered"
    for b in zz.bands():
        assert area.buffer(d / 2 * (1 + 1e-6)).covers(b)
    s = np.sort(zz.band_s)
    np.testing.assert_allclose(np.diff(s), d, rtol=1e-9, atol=1e-9 * d)
    path = zz.path()
    assert np.all(np.isfinite(path))
    np.testing.assert_allclose(path[0], zz.starts[0], atol=1e-6 * d)
    np.testing.assert_allclose(path[-1], zz.ends[-1], atol=1e-6 * d)


@st.composite
def polygons(draw):
    n = draw(st.integers(3, 8))
    return [(draw(st.floats(-50, 2000)), draw(st.floats(-50, 2000))) for _ in range(n)]


@FUZZ
@given(pts=polygons(), spacing=st.floats(0.01, 5000.0), angle=st.floats(-360.0, 360.0))
def test_coverage_any_area_and_spacing_is_refused_in_one_line_or_built(pts, spacing, angle):
    """Any polygon (self-intersecting, degenerate) and any band spacing: one-line InputError
    naming the area or D, or a zigzag with finite points."""
    from shapely.geometry import Polygon

    from fm2uav.missions.coverage.area import as_area, check_spacing
    from fm2uav.missions.coverage.bands import zigzag

    try:
        area = as_area(Polygon(pts))
        d = check_spacing(area, spacing)
        zz = zigzag(area, d, angle)
    except InputError as exc:
        msg = _one_line(exc)
        assert "area" in msg or "spacing" in msg or "polygon" in msg, msg
        return
    assert np.all(np.isfinite(zz.path(step=max(d, 1.0))))


# ---------------------------------------------------------------- mission files
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
    """Any document: a mission, or one line naming the file (and the key when there is one)."""
    from fm2uav.io.mission import parse_mission

    try:
        m = parse_mission(doc, source="fuzz.yaml")
        m.plan_objects()
    except InputError as exc:
        assert "fuzz.yaml" in _one_line(exc)


@st.composite
def valid_missions(draw):
    """Mission documents a user could write on a built-in scenario."""
    doc: dict = {"version": 1, "world": {"scenario": "open-field"}}
    if draw(st.booleans()):
        doc["name"] = draw(st.text(min_size=1, max_size=12).filter(str.strip))
    planner = {}
    if draw(st.booleans()):
        planner["saturation"] = draw(st.floats(0.05, 1.0))
    if draw(st.booleans()):
        planner["exponent"] = draw(st.floats(0.1, 10.0))
    if draw(st.booleans()):
        planner["order"] = draw(st.sampled_from([1, 2]))
    if draw(st.booleans()):
        planner["agl"] = draw(st.floats(20.0, 300.0))
        planner["p1"] = draw(st.floats(0.1, 1.0))
        planner["p2"] = draw(st.floats(1.0, 3.0))
    if planner:
        doc["planner"] = planner
    if draw(st.booleans()):
        doc["airframe"] = {"firmware": draw(st.sampled_from(["px4", "ardupilot", "generic"])),
                           "type": draw(st.sampled_from(["multirotor", "fixed_wing", "vtol"]))}
    return doc


@FUZZ
@given(doc=valid_missions())
def test_valid_mission_documents_are_read_as_written(doc, tmp_path_factory):
    """A valid document written as YAML reads back to the values it holds (through the file
    reader, the parser and the planner objects)."""
    from fm2uav.io.mission import load_mission

    f = tmp_path_factory.mktemp("v") / "m.yaml"
    f.write_text(yaml.safe_dump(doc, allow_unicode=True), encoding="utf-8")
    m = load_mission(f)
    shaping, level, options = m.plan_objects()
    planner = doc.get("planner", {})
    assert shaping.saturation == planner.get("saturation", 1.0)
    assert shaping.exponent == planner.get("exponent", 1.0)
    assert options.order == planner.get("order", 2)
    if "agl" in planner:
        assert (level.agl, level.p1, level.p2) == (planner["agl"], planner["p1"], planner["p2"])
    else:
        assert level is None
    if "name" in doc:
        assert m.name == doc["name"]


@FUZZ
@given(text=st.text(max_size=80))
def test_mission_text(tmp_path_factory, text):
    """Any text in a mission file: a mission or one line naming the file."""
    from fm2uav.io.mission import load_mission

    f = tmp_path_factory.mktemp("m") / "m.yaml"
    f.write_text(text, encoding="utf-8")
    try:
        load_mission(f)
    except InputError as exc:
        assert "m.yaml" in _one_line(exc)


@FUZZ
@given(doc=st.dictionaries(_key, _value, min_size=1, max_size=4), dup=_key)
def test_duplicate_keys_always_refused(tmp_path_factory, doc, dup):
    """A duplicated top-level key is refused whatever the document holds."""
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


# ---------------------------------------------------------------- terrain following
@st.composite
def terrain_worlds(draw):
    nx, ny = draw(st.integers(8, 20)), draw(st.integers(8, 20))
    nz = draw(st.integers(14, 20))
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    ground = np.cumsum(rng.normal(0.0, draw(st.floats(0.0, 2.0)), (nx, ny)), axis=0)
    ground = np.clip(ground - ground.min(), 0.0, nz / 2 - 1)
    z = np.arange(nz, dtype=float)
    occ = z[None, None, :] <= ground[:, :, None]
    return World(occ, spacing=(10.0, 10.0, 5.0), terrain=ground * 5.0)


@FUZZ
@given(world=terrain_worlds(), data=st.data(), agl=st.floats(11.0, 25.0),
       p2=st.floats(0.5, 3.0))
def test_terrain_following_plans_stay_out_of_the_ground(world, data, agl, p2):
    """Terrain-following plans between two points ``agl`` (more than two 5 m cells) above
    random relief, with room above the highest ground: they succeed, start and end where asked, no point lies below the
    continuous surface, and the cruise keeps the floor ``agl - tolerance``."""
    hi = (np.asarray(world.shape) - 1) * np.asarray(world.spacing)
    pts = []
    for _ in range(2):
        x = data.draw(st.floats(0.0, float(hi[0])))
        y = data.draw(st.floats(0.0, float(hi[1])))
        pts.append([x, y, float(world.ground_height(x, y)) + agl])
    assume(np.hypot(pts[1][0] - pts[0][0], pts[1][1] - pts[0][1]) > 15.0)  # distinct nodes
    level = FlightLevel(agl=agl, p2=p2)
    p = plan(world, pts[0], pts[1], level=level)
    np.testing.assert_allclose(p.path[[0, -1]], pts, atol=1e-6)
    surface = np.asarray(world.surface_height(p.path[:, 0], p.path[:, 1]), dtype=float)
    below = p.path[:, 2] < surface - 1e-6
    assert not below.any(), (f"{int(below.sum())} path point(s) below the ground, worst "
                             f"{float((surface - p.path[:, 2]).max()):.3f} m")
    cruise = p.phase == "cruise"
    if cruise.any():
        h = p.path[cruise, 2] - np.asarray(world.ground_height(p.path[cruise, 0],
                                                               p.path[cruise, 1]))
        assert h.min() >= agl - level.tolerance - 1e-6, h.min()
