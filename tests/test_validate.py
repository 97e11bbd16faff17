"""fm2uav._validate: YAML 1.2 scalars, the input log, a deleted current folder, seeds."""

from __future__ import annotations

import os

import pytest

from fm2uav import _validate as v
from fm2uav.errors import InputError


@pytest.mark.parametrize("text, value", [
    ("5e-1", 0.5), ("1e3", 1000.0), ("-2.5E+2", -250.0), (".5", 0.5), ("3.", 3.0),
    ("+12", 12), ("010", 10), ("0o17", 15), ("0x1F", 31), ("-0", 0),
    (".inf", float("inf")), ("-.Inf", float("-inf")),
    ("true", True), ("False", False), ("null", None), ("~", None),
    # YAML 1.1 would read these as booleans, a date, a sexagesimal int or an octal: text
    ("yes", "yes"), ("no", "no"), ("on", "on"), ("off", "off"), ("y", "y"),
    ("2024-01-01", "2024-01-01"), ("1:30", "1:30"), ("1_000", "1_000"), ("0b101", "0b101"),
])
def test_yaml_plain_scalars_follow_the_1_2_core_schema(text, value):
    got = v.load_yaml(f"a: {text}\n", "config", source="<text>")["a"]
    assert got == value and type(got) is type(value)


def test_yaml_nan_is_a_float_and_quoted_numbers_stay_text():
    doc = v.load_yaml("a: .nan\nb: '5e-1'\nc: \"1\"\n", "config", source="<text>")
    assert doc["a"] != doc["a"] and doc["b"] == "5e-1" and doc["c"] == "1"


def test_yaml_file_with_a_byte_order_mark(tmp_path):
    p = tmp_path / "m.yaml"
    p.write_bytes("\ufeffname: t\nx: 5e-1\n".encode("utf-8"))
    assert v.load_yaml(p, "mission") == {"name": "t", "x": 0.5}


def test_read_text_drops_the_byte_order_mark(tmp_path):
    p = tmp_path / "a.csv"
    p.write_bytes(b"\xef\xbb\xbfx_m,y_m\n1,2\n")
    assert v.read_text(p, "path file").startswith("x_m")


def test_input_log_notes_every_file_checked_and_only_inside_a_log(tmp_path):
    f = tmp_path / "dem.tif"
    f.write_text("x")
    v.input_file(f, "the DEM")  # no log open: nothing recorded, nothing fails
    assert v.noted_inputs() is None
    with v.input_log() as log:
        v.input_file(f, "the DEM", where=("world.dem", "--dem"))
        with v.input_log() as inner:  # nested: the same list
            v.note_input(tmp_path / "zones.geojson", "a zone file")
            v.note_input(f, "noted twice")
        assert inner is log
        with pytest.raises(InputError):
            v.input_file(tmp_path / "missing.tif", "the DEM")  # missing files are noted too
    assert [(p.name, w) for p, w in log] == [
        ("dem.tif", "the DEM (mission file: world.dem; CLI: --dem)"),
        ("zones.geojson", "a zone file"), ("missing.tif", "the DEM")]
    assert v.noted_inputs() is None


@pytest.fixture
def in_deleted_folder(tmp_path):
    here = os.getcwd()
    gone = tmp_path / "gone"
    gone.mkdir()
    os.chdir(gone)
    gone.rmdir()
    yield tmp_path
    os.chdir(here)


def test_a_deleted_current_folder_is_named_for_relative_paths(in_deleted_folder):
    with pytest.raises(InputError, match="the current folder no longer exists.*cd into an "
                       "existing folder"):
        v.input_file("m.yaml", "mission file")
    assert v.cwd_gone("m.yaml") and v.cwd_gone(in_deleted_folder / "m.yaml") is None
    with pytest.raises(InputError, match="m.yaml not found"):  # an absolute path: as usual
        v.input_file(in_deleted_folder / "m.yaml", "mission file")


@pytest.mark.parametrize("value", [-1, 2**63, 1.5, True, "3"])
def test_seed_value_refuses_what_numpy_cannot_seed(value):
    with pytest.raises(InputError, match="seed"):
        v.seed_value(value, where=(None, "--seed"))


def _laughs(levels: int, width: int = 9) -> str:
    lines = ['a0: &a0 [' + ", ".join(['"lol"'] * width) + ']']
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * width) + "]"
              for i in range(1, levels)]
    return "\n".join(lines) + "\n"


def test_a_billion_laughs_file_is_refused_before_anything_walks_it():
    with pytest.raises(InputError, match=r"expands to 4.41e\+09 values through its aliases"):
        v.load_yaml(_laughs(10), "mission", source="bomb.yaml")
    small = v.load_yaml(_laughs(3, 3), "mission", source="ok.yaml")  # a few aliases: fine
    assert small["a2"] == [[["lol"] * 3] * 3] * 3


@pytest.mark.parametrize("text", ["a: &x [1, *x]\n", "a: &x {b: *x}\n"])
def test_a_document_that_contains_itself_is_refused(text):
    with pytest.raises(InputError, match="refers to itself through an alias"):
        v.load_yaml(text, "mission", source="loop.yaml")
