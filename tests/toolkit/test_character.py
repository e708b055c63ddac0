"""Character files: composition, extends, and errors that name file, key, expected and available."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CHARACTERS, STICK
from toolkit import ConfigError, PluginError, load_character
from toolkit.config.search import merge_tables
from toolkit.config.toml import find_key_line

BODY = STICK


def test_builtin_characters_compose(pm):
    max_ = load_character(CHARACTERS / "max.toml", pm)
    morris = load_character(CHARACTERS / "morris.toml", pm)
    assert max_.name == "Max" and morris.name == "Morris"
    assert len(max_.body.parts) >= 10
    assert set(morris.motor.movements()) - set(max_.motor.movements()) == {"windmill"}  # a movement Max lacks
    assert morris.files[1] == (CHARACTERS / "max.toml").resolve()
    assert max_.action.name == morris.action.name == "hierarchical"
    assert "ice_cream" in morris.action.beliefs and "ice_cream" not in max_.action.beliefs
    # Morris is Max with some movements changed: his cover face takes longer
    assert morris.motor.perform("cover_face").duration > max_.motor.perform("cover_face").duration + 0.5
    np.testing.assert_allclose(morris.motor.perform("point").positions, max_.motor.perform("point").positions)
    assert morris.motor.perform("wave").n_frames < max_.motor.perform("wave").n_frames  # he waves faster
    stages = [stage for stage, _ in max_.pipeline()]
    assert stages == ["perceive", "correspond", "segment", "match", "interpret", "respond"]


def test_character_by_name_on_the_search_path(pm):
    assert load_character("max", pm).name == "Max"


def test_extends_merges_tables_and_replaces_component_on_plugin_change(pm, write):
    write("stick.toml", BODY + '\n[action]\nplugin = "script"\nmovements = ["bob"]\npause = 2.0\n')
    child = write(
        "child.toml",
        """
        [character]
        name = "Child"
        extends = "stick.toml"

        [motor.poses.bob]
        shift = [0.0, -0.4, 0.0]

        [action]
        plugin = "imitation"
        """,
    )
    c = load_character(child, pm)
    assert c.name == "Child"
    assert c.action.name == "imitation" and "pause" not in c.config["action"]
    assert c.motor.key_poses["bob"][0, 1] == pytest.approx(0.6)  # shift replaced, base kept


def test_merge_tables_is_deep_and_does_not_mutate():
    base = {"a": {"b": 1, "c": {"d": 2}}, "l": [1]}
    over = {"a": {"c": {"e": 3}}, "l": [2]}
    assert merge_tables(base, over) == {"a": {"b": 1, "c": {"d": 2, "e": 3}}, "l": [2]}
    assert base == {"a": {"b": 1, "c": {"d": 2}}, "l": [1]}


def _fails(pm, path, pattern):
    with pytest.raises(ConfigError, match=pattern) as info:
        load_character(path, pm)
    assert "\n" not in str(info.value)
    return info.value


def test_unknown_plugin_lists_registered_names(pm, write):
    path = write("c.toml", BODY + '\n[segmenter]\nplugin = "hub-treshold"\n')
    err = _fails(pm, path, r"c.toml:\d+: key segmenter.plugin: unknown segmenter 'hub-treshold'; expected the name of a registered segmenter; available: ")
    lines = path.read_text().splitlines()
    assert err.key == ("segmenter", "plugin") and lines[err.line - 1] == 'plugin = "hub-treshold"'


def test_unknown_action_system_lists_the_builtins(pm, write):
    path = write("c.toml", BODY + '\n[action]\nplugin = "hierarchicl"\n')
    _fails(pm, path, r"key action.plugin: unknown action system 'hierarchicl'.*available: hierarchical, imitation, script")


def test_syntax_error_names_line_and_column(pm, write):
    path = write("c.toml", BODY.replace('root = "root"', 'root = "root'))
    err = _fails(pm, path, r"c.toml:6:\d+: TOML syntax error")
    assert err.line == 6


def test_wrong_parameter_type_names_the_key(pm, write):
    path = write("c.toml", BODY + '\n[action]\nplugin = "script"\npause = "long"\n')
    _fails(pm, path, r"c.toml:\d+: key action.pause: wrong type str \(value 'long'\); expected a number")


def test_unknown_parameter_lists_the_parameters(pm, write):
    path = write("c.toml", BODY + '\n[action]\nplugin = "script"\npuase = 1.0\n')
    _fails(pm, path, r"key action.puase: unknown parameter 'puase' for action system 'script'.*available: exclude, movements, no_repeat, pause, random, seed, speed, start")


def test_unknown_movement_reference_lists_movements(pm, write):
    path = write("c.toml", BODY + '\n[action]\nplugin = "script"\nmovements = ["bob", "jump"]\n')
    _fails(pm, path, r"key action.movements\[1\]: unknown movement 'jump'; expected a movement of this character; available: bob")


def test_unknown_pose_in_a_movement(pm, write):
    path = write("c.toml", BODY.replace('{ pose = "bob", at = 0.5 }', '{ pose = "bop", at = 0.5 }'))
    _fails(pm, path, r"key motor.movements.bob.keys\[1\].pose: unknown pose 'bop'.*available: stand, bob")


def test_movement_must_start_and_end_in_a_hub(pm, write):
    path = write("c.toml", BODY.replace('{ pose = "stand", at = 1.0 }', '{ pose = "bob", at = 1.0 }'))
    _fails(pm, path, r"key motor.movements.bob.keys: movement must end in a hub pose, not 'bob'.*available: stand")


def test_decreasing_key_times(pm, write):
    path = write("c.toml", BODY.replace("at = 1.0", "at = 0.4"))
    _fails(pm, path, r"key motor.movements.bob.keys: key times \[0.0, 0.5, 0.4\] are not increasing")


def test_unknown_part_in_a_pose(pm, write):
    path = write("c.toml", BODY.replace("shift = [0.0, -0.2, 0.0]", "shift = [0.0, -0.2, 0.0]\nnoze = [0, 1, 0]"))
    _fails(pm, path, r"key motor.poses.bob.noze: unknown key 'noze'; expected a body part or base/shift/offset; available: root, head")


def test_pose_base_cycle(pm, write):
    path = write("c.toml", BODY + '\n[motor.poses.a]\nbase = "b"\n[motor.poses.b]\nbase = "a"\n')
    _fails(pm, path, r"pose base cycle")


def test_missing_tables_and_keys(pm, write):
    _fails(pm, write("a.toml", '[character]\nname = "A"\n'), r"key body: missing \[body\] table")
    _fails(pm, write("b.toml", BODY.replace('name = "Stick"', "")), r"key character.name: missing or invalid; expected a non-empty string")
    _fails(pm, write("c.toml", BODY.replace('plugin = "keyframe"', "")), r"key motor.plugin: missing or invalid plugin name.*available: keyframe")
    _fails(pm, write("d.toml", BODY + "\n[sensors]\nx = 1\n"), r"key sensors: unknown table 'sensors'; expected a character table; available: character, body, motor")
    _fails(pm, write("e.toml", BODY.replace('[character]\n', '[character]\ncolour = "grey"\n')), r"key character.colour: unknown key")


def test_extends_errors(pm, write):
    _fails(pm, write("a.toml", BODY.replace('name = "Stick"', 'name = "A"\nextends = "nobody"')), r"a.toml: key character.extends: cannot find 'nobody'.*available: .*max")
    write("x.toml", BODY.replace('name = "Stick"', 'name = "X"\nextends = "y.toml"'))
    write("y.toml", BODY.replace('name = "Stick"', 'name = "Y"\nextends = "x.toml"'))
    _fails(pm, write("z.toml", BODY.replace('name = "Stick"', 'name = "Z"\nextends = "x.toml"')), r"extends cycle: z.toml -> x.toml -> y.toml -> x.toml")


def test_missing_file(pm, tmp_path):
    _fails(pm, tmp_path / "nope.toml", r"cannot find")


def test_component_crash_is_a_plugin_error(pm, write, scripted):
    path = write("c.toml", BODY + '\n[segmenter]\nplugin = "scripted-cuts"\ncuts = [[0, "x"]]\n')
    load_character(path, pm)  # cuts are read on reset, not at load
    # a component whose attach fails with a non-likeme exception is reported with its name
    path = write("d.toml", BODY + '\n[matcher]\nplugin = "early-commit"\nafter = 3\n')
    character = load_character(path, pm)
    assert character.matcher.params["after"] == 3
    from toolkit import hookimpl

    class Boom:
        @hookimpl
        def likeme_character_composed(self, character):
            raise RuntimeError("no")

    pm.register(Boom(), name="boom")
    with pytest.raises(PluginError, match="likeme_character_composed: RuntimeError: no"):
        load_character(path, pm)


def test_find_key_line(write):
    path = write("k.toml", BODY)
    assert find_key_line(path, ("motor", "poses", "bob", "shift")) == 20
    assert find_key_line(path, ("body", "facing", "left")) == 7
    assert find_key_line(path, ("nothing",)) is None


def test_find_key_line_reads_quoted_and_dotted_keys_as_toml_does(write):
    path = write("q.toml", '''[files."*.bvh"]
scale = 2

[parts]
"left hand" = "LHand"
a.b = [
  1,
  [2, 3],
]
[[takes]]
name = 'x'  # a comment
[ 'odd.name' . inner ]
deep = 1
''')
    assert find_key_line(path, ("files", "*.bvh", "scale")) == 2
    assert find_key_line(path, ("files", "*.bvh")) == 1
    assert find_key_line(path, ("parts", "left hand")) == 5
    assert find_key_line(path, ("parts", "a", "b")) == 6
    assert find_key_line(path, ("takes", 0, "name")) == 11
    assert find_key_line(path, ("odd.name", "inner", "deep")) == 13
    assert find_key_line(path, ("parts", "missing")) == 4  # the nearest table written
    assert find_key_line(path, ("odd",)) is None  # a quoted dot is not a table
