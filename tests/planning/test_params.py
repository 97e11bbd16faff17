"""Parameter objects (planning/params.py) and the shared checks (fm2uav._validate)."""

import dataclasses

import numpy as np
import pytest

from fm2uav import FlightLevel, InputError, PlanOptions, Shaping
from fm2uav import _validate as v
from fm2uav.planning.params import planner_keys, planner_objects


def test_defaults_are_the_agreed_interface():
    assert Shaping() == Shaping(1.0, 1.0, None, "edt", False)
    lv = FlightLevel(agl=60)
    assert (lv.agl, lv.p1, lv.p2, lv.band, lv.graded, lv.mode, lv.tolerance) == (
        60.0, 0.5, 1.3, 0.0, False, "capped", 2.0)
    assert lv.min_agl is None and lv.max_agl is None
    o = PlanOptions()
    assert (o.order, o.step, o.speed_map) == (2, 0.5, None)
    # canonical types: ints become floats where the field is a number
    assert isinstance(FlightLevel(agl=60).agl, float) and isinstance(Shaping(exponent=2).exponent, float)


def test_objects_are_frozen_and_replace_validates_again():
    s = Shaping(exponent=2.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.exponent = 3.0  # type: ignore[misc]
    assert dataclasses.replace(s, exponent=0.5).exponent == 0.5
    with pytest.raises(InputError, match="exponent"):
        dataclasses.replace(s, exponent=-1.0)


@pytest.mark.parametrize(
    "make, key, flag",
    [
        (lambda: Shaping(saturation=0.0), "planner.saturation", "--saturation"),
        (lambda: Shaping(saturation=1.5), "planner.saturation", "--saturation"),
        (lambda: Shaping(exponent=float("nan")), "planner.exponent", "--exponent"),
        (lambda: Shaping(saturation_distance=-3), "planner.saturation_distance",
         "--saturation-distance"),
        (lambda: Shaping(method="fast"), "planner.method", "--method"),
        (lambda: Shaping(walls=1), "planner.walls", "--walls"),
        (lambda: FlightLevel(agl=0), "planner.agl", "--agl"),
        (lambda: FlightLevel(agl="high"), "planner.agl", "--agl"),
        (lambda: FlightLevel(agl=60, p1=0), "planner.p1", "--p1"),
        (lambda: FlightLevel(agl=60, p2=float("inf")), "planner.p2", "--p2"),
        (lambda: FlightLevel(agl=60, band=-1), "planner.band", "--band"),
        (lambda: FlightLevel(agl=60, mode="cap"), "planner.mode", "--mode"),
        (lambda: FlightLevel(agl=60, tolerance=-0.5), "planner.tolerance", "--tolerance"),
        (lambda: FlightLevel(agl=60, min_agl=-1), "planner.min_agl", "--min-agl"),
        (lambda: FlightLevel(agl=60, max_agl=0), "planner.max_agl", "--max-agl"),
        (lambda: FlightLevel(agl=150, max_agl=120), "planner.agl", "--agl"),
        (lambda: FlightLevel(agl=50, min_agl=80), "planner.agl", "--agl"),
        (lambda: PlanOptions(order=3), "planner.order", "--order"),
        (lambda: PlanOptions(order=1.5), "planner.order", "--order"),
        (lambda: PlanOptions(step=0), "planner.step", "--step"),
        (lambda: PlanOptions(step=2), "planner.step", "--step"),
    ],
)
def test_bad_values_name_the_mission_key_and_the_flag(make, key, flag):
    with pytest.raises(InputError) as err:
        make()
    msg = str(err.value)
    assert key in msg and flag in msg and "\n" not in msg


def test_planner_objects_from_one_flat_mapping():
    s, lv, o = planner_objects({"saturation": 0.5, "agl": 80, "band": 15.0, "graded": True,
                                "order": 1, "step": 0.25, "walls": None})
    assert s == Shaping(saturation=0.5)
    assert lv == FlightLevel(agl=80, band=15.0, graded=True)
    assert (o.order, o.step) == (1, 0.25)
    assert planner_objects({})[1] is None
    with pytest.raises(InputError, match="agl_band"):
        planner_objects({"agl_band": 5.0})
    with pytest.raises(InputError, match="no agl"):
        planner_objects({"p2": 1.5})
    names = [n for ns in planner_keys().values() for n in ns]
    assert len(names) == len(set(names))  # one spelling, no key in two objects


def test_speed_map_becomes_a_float_array():
    o = PlanOptions(speed_map=[[1, 0], [1, 1]])
    assert o.speed_map.dtype == float and o.speed_map.shape == (2, 2)
    with pytest.raises(InputError, match="speed_map"):
        PlanOptions(speed_map=object())


def test_validate_helpers():
    assert v.positive(3, "x") == 3.0
    assert v.non_negative(0, "x") == 0.0
    assert v.in_range(1.0, "a", 0, 1, low_open=True) == 1.0
    assert v.integer(2.0, "n") == 2 and v.flag(np.bool_(True), "f") is True
    assert v.optional(v.positive, None, "x") is None
    np.testing.assert_array_equal(v.point((1, 2, 3), 3, "start"), [1.0, 2.0, 3.0])
    assert v.where_text(("planner.agl", "--agl")) == " (mission file: planner.agl; CLI: --agl)"
    assert v.where_text((None, "--agl")) == " (CLI: --agl)"
    for bad in (lambda: v.number(True, "x"), lambda: v.positive(0, "x"),
                lambda: v.in_range(1.0, "a", 0, 1, high_open=True),
                lambda: v.integer(1.5, "n"), lambda: v.integer(0, "n", minimum=1),
                lambda: v.choice("c", ("a", "b"), "m"), lambda: v.flag("yes", "f"),
                lambda: v.point((1, 2), 3, "goal"), lambda: v.point((1, np.nan, 2), 3, "goal")):
        with pytest.raises(InputError):
            bad()


def test_upper_bounds_are_the_mission_files():
    """One spelling, one range: the library's upper bounds are PlannerSpec's `le`."""
    from fm2uav.io.mission import PlannerSpec
    from fm2uav.planning.params import UPPER

    for name, hi in UPPER.items():
        les = [m.le for m in PlannerSpec.model_fields[name].metadata
               if getattr(m, "le", None) is not None]
        assert les == [hi], name


@pytest.mark.parametrize("kw, flag", [({"agl": 1e308}, "--agl"), ({"agl": 100, "p2": 11},
                                                                     "--p2"),
                                      ({"saturation_distance": 1e6}, "--saturation-distance")])
def test_values_beyond_the_upper_bounds_are_refused(kw, flag):
    from fm2uav.errors import InputError
    from fm2uav.planning.params import planner_objects

    with pytest.raises(InputError, match=f"too large.*CLI: {flag}"):
        planner_objects(kw)
