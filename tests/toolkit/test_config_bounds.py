"""Configuration bounded and checked where it enters (issue 21): what is not a row of ``tests/likeme/test_errors.py``.

Files, parameters and arguments: NaN and infinities refused wherever a number is expected, nesting and chains
bounded, devices refused, a byte-order mark accepted, ``--set`` checked against every plugin it reaches, an
override's error placed where the override was written, runs bounded in frames.
"""

from __future__ import annotations

import math
import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import CHARACTERS
from toolkit import ConfigError, load_character
from toolkit.config.toml import MAX_DEPTH, read_toml
from toolkit.config.settings import check_settings
from toolkit.params import Parameter

MAX = CHARACTERS / "max.toml"


# -- TOML files ---------------------------------------------------------------------------------------


def test_a_byte_order_mark_is_dropped(tmp_path, pm):
    text = MAX.read_text(encoding="utf-8")
    plain, marked = tmp_path / "plain.toml", tmp_path / "marked.toml"
    plain.write_text(text, encoding="utf-8")
    marked.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    assert read_toml(marked) == read_toml(plain)
    assert load_character(marked, pm).name == "Max"


def test_nesting_at_the_bound_is_read_and_one_deeper_is_refused(tmp_path):
    ok, deep = tmp_path / "ok.toml", tmp_path / "deep.toml"
    ok.write_text("x = " + "[" * (MAX_DEPTH - 1) + "]" * (MAX_DEPTH - 1) + "\n")  # the document is one level
    deep.write_text("x = " + "[" * MAX_DEPTH + "]" * MAX_DEPTH + "\n")
    assert "x" in read_toml(ok)
    with pytest.raises(ConfigError, match=f"deep.toml: TOML nested more than {MAX_DEPTH} levels deep"):
        read_toml(deep)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_or_a_device_is_refused_without_reading(tmp_path):
    fifo = tmp_path / "c.toml"
    os.mkfifo(fifo)  # opening it for reading would wait for a writer for ever
    with pytest.raises(ConfigError, match=r"c.toml: is a FIFO \(named pipe\), not a file; expected a regular file \(TOML file\)"):
        read_toml(fifo)
    with pytest.raises(ConfigError, match="/dev/zero: is a character device, not a file"):
        read_toml("/dev/zero")


def test_an_extends_chain_at_the_bound_loads_and_one_more_file_is_refused(tmp_path, pm):
    from toolkit.config.search import MAX_EXTENDS

    own = len(load_character(MAX, pm).files)  # max.toml and the files it extends
    front = MAX_EXTENDS - own
    for i in range(front + 1):
        parent = f"c{i + 1}.toml" if i < front else MAX.as_posix()
        (tmp_path / f"c{i}.toml").write_text(f'[character]\nname = "C{i}"\nextends = "{parent}"\n')
    character = load_character(tmp_path / "c1.toml", pm)
    assert character.name == "C1" and len(character.files) == MAX_EXTENDS
    with pytest.raises(ConfigError, match=f"key character.extends: extends chain longer than {MAX_EXTENDS} files"):
        load_character(tmp_path / "c0.toml", pm)


# -- parameters -------------------------------------------------------------------------------------------


finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
non_finite = st.sampled_from([math.nan, math.inf, -math.inf])
leaves = st.one_of(finite, st.integers(-10**6, 10**6), st.text(max_size=3), st.booleans())
nested = st.recursive(leaves, lambda inner: st.one_of(st.lists(inner, max_size=3),
                                                      st.dictionaries(st.text(max_size=3), inner, max_size=3)),
                      max_leaves=12)


def _with(value, bad, path):
    """``value`` with ``bad`` put at the position ``path`` chooses (a list element or a table value)."""
    if not path or not isinstance(value, (list, dict)) or not value:
        return [value, bad] if not isinstance(value, dict) else {**value, "bad": bad}
    keys = list(range(len(value))) if isinstance(value, list) else list(value)
    key = keys[path[0] % len(keys)]
    out = list(value) if isinstance(value, list) else dict(value)
    out[key] = _with(value[key], bad, path[1:])
    return out


@settings(max_examples=200, deadline=None)
@given(value=nested, bad=non_finite, path=st.lists(st.integers(0, 5), max_size=4))
def test_a_non_finite_number_anywhere_in_a_parameter_is_refused(value, bad, path):
    table = Parameter("table", list, [])
    given_value = _with(value, bad, path)
    given_value = given_value if isinstance(given_value, list) else [given_value]
    with pytest.raises(ConfigError, match=r"value -?(nan|inf) is not a finite number") as caught:
        table.coerce(given_value)
    key = caught.value.key
    assert key[0] == "table"
    found = given_value
    for part in key[1:]:  # the key path leads to the number refused
        found = found[part]
    assert isinstance(found, float) and not math.isfinite(found)


@settings(max_examples=200, deadline=None)
@given(value=st.lists(nested, max_size=4))
def test_finite_values_pass_unchanged(value):
    assert Parameter("table", list, []).coerce(value) == value


@pytest.mark.parametrize("text", ["nan", "inf", "-inf"])
def test_a_number_parameter_refuses_non_finite_values_even_without_bounds(text):
    with pytest.raises(ConfigError, match="is not a finite number"):
        Parameter("x", float, 0.0).coerce(float(text))


# -- --set ----------------------------------------------------------------------------------------------


def test_set_is_checked_against_every_named_plugin(pm):
    plugins = {"matcher": ["path-search", "dtw"], "segmenter": ["hub-threshold"]}
    check_settings({"matcher": {"decision": "distance"}, "segmenter": {"floor": 0.0}}, pm, plugins)  # both have it
    with pytest.raises(ConfigError, match=r"key --set.matcher.search: unknown parameter 'search' for matcher 'dtw'"):
        check_settings({"matcher": {"search": "k-best"}}, pm, plugins)
    with pytest.raises(ConfigError, match=r"key --set.matchr: unknown table 'matchr'.*available: motor, perception"):
        check_settings({"matchr": {"k": 3}}, pm, plugins)
    with pytest.raises(ConfigError, match=r"key --set.perception: no \[perception\] component to set"):
        check_settings({"perception": {"noise": 0.0}}, pm, plugins)


def test_set_naming_a_plugin_is_checked_against_that_plugin(pm):
    check_settings({"matcher": {"plugin": "dtw", "window": 0.2}}, pm, {"matcher": ["path-search"]})
    with pytest.raises(ConfigError, match=r"key --set.matcher.plugin: unknown matcher 'dtwx'"):
        check_settings({"matcher": {"plugin": "dtwx"}}, pm, {})
    with pytest.raises(ConfigError, match=r"key --set.matcher.beam.k: value 0 out of range"):
        check_settings({"matcher": {"beam": {"k": 0}}}, pm, {"matcher": ["path-search"]})


def test_a_bad_list_element_in_set_names_its_key(pm):
    with pytest.raises(ConfigError, match=r"key --set.action.movements\[1\]: wrong type int"):
        check_settings({"action": {"movements": ["bow", 3]}}, pm, {"action": ["script"]})


# -- where an override's error is reported ----------------------------------------------------------------


def test_an_override_error_is_placed_where_the_override_was_written(pm, tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text("[scenario]\nname = \"s\"\n[[actors]]\ncharacter = \"max\"\n[actors.override.matcher]\nkk = 1\n")
    with pytest.raises(ConfigError) as caught:
        load_character(MAX, pm, override={"matcher": {"kk": 1}}, override_at=(scene, ("actors", 0, "override")))
    err = caught.value
    assert err.file == scene and err.key == ("actors", 0, "override", "matcher", "kk") and err.line == 6
    # a parameter the plugin it names lacks: the override's too
    with pytest.raises(ConfigError) as caught:
        load_character(MAX, pm, override={"segmenter": {"floor": 0.0}, "matcher": {"plugin": "dtw", "k": 3}},
                       override_at=(scene, ("actors", 0, "override")))
    assert caught.value.file == scene and caught.value.key[-1] == "k"


def test_an_override_without_an_origin_is_reported_in_the_character_file(pm):
    with pytest.raises(ConfigError) as caught:
        load_character(MAX, pm, override={"matcher": {"kk": 1}})
    assert caught.value.file == MAX


# -- runs and clips ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs, message", [
    ({"duration": math.nan}, "duration must be in"),
    ({"duration": math.inf}, "duration must be in"),
    ({"until_idle": True, "tail": 1e300}, "tail must be in"),
    ({"duration": 3000.0}, "more than 432000 frames"),
])
def test_a_world_run_is_bounded(pm, kwargs, message):
    from toolkit.runtime import World

    world = World(fps=200.0, pm=pm)
    with pytest.raises(ValueError, match=message):
        world.run(**kwargs)
    assert world.frame == 0


def test_a_world_frame_rate_is_bounded(pm):
    from toolkit.runtime import MAX_FPS, World

    World(fps=MAX_FPS, pm=pm)
    with pytest.raises(ValueError, match="fps must be positive and at most 1000"):
        World(fps=1e6, pm=pm)


def test_a_movement_folder_named_like_an_example_is_refused(tmp_path):
    from plugins.lib.clip_repertoire import clip_files, example_name

    for name in ("bow", example_name("bow", 1)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "take.bvh").write_text("HIERARCHY\n")
    with pytest.raises(ConfigError, match=r"bow#2: movement name 'bow#2' contains '#'; expected movement names "
                                          r"without '#'"):
        clip_files(tmp_path)
    (tmp_path / "bow#2" / "take.bvh").unlink()
    (tmp_path / "bow#2").rmdir()
    assert list(clip_files(tmp_path)) == ["bow"]


def test_the_scenario_view_checks_object_colours_before_the_run(pm):
    """An object made in Python with a colour the renderer cannot draw fails when recording starts, not after."""
    from toolkit import load_scenario

    scenario = load_scenario("cheese_or_ball", pm)
    cheese = scenario.world.objects["cheese"]
    view = pm.registry.get("view", "scenario")()
    cheese.colour = "purplish"
    with pytest.raises(ConfigError, match="key objects.cheese.colour: unknown colour 'purplish' of object 'cheese'"):
        view.start(scenario.world)
    assert scenario.world.frame == 0
    cheese.colour = "red"  # a name the renderer knows
    view.stop(view.start(scenario.world))


@settings(max_examples=40, deadline=None)
@given(digits=st.integers(4290, 4310), line=st.integers(0, 5), sign=st.sampled_from(["", "-", "+"]),
       underscores=st.booleans())
def test_the_one_toml_reader_bounds_integers_with_their_line_and_column(digits, line, sign, underscores):
    """Every TOML a user gives (declarations, --set values, sweep grids) is read by toolkit.config.toml.loads: an
    integer of more than 4,300 digits is a NumberTooLong at its own line and column, never Python's bare ValueError;
    one of at most 4,300 digits is read as written."""
    from toolkit.config.toml import MAX_DIGITS, NumberTooLong, loads

    number = "7" * digits if not underscores else "_".join("7" * digits)
    text = "".join(f"k{i} = {i}\n" for i in range(line)) + f"big = {sign}{number}\n"
    if digits <= MAX_DIGITS:
        assert loads(text)["big"] == int(sign + "7" * digits)
    else:
        with pytest.raises(NumberTooLong) as info:
            loads(text)
        assert (info.value.digits, info.value.line, info.value.column) == (digits, line + 1, 7)
