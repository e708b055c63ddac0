"""Mutated character and scenario files: each either loads and runs, or fails with a documented error (issue 21).

Every ``KEY = VALUE`` line of a small scenario and its character is a place where a hostile value can go (NaN,
infinities, huge and negative numbers, wrong types, deep nesting, lists for strings); lines are also dropped or
repeated. Loading must give a :class:`~toolkit.errors.LikemeError` or a scenario that runs; never another exception.
"""

from __future__ import annotations

import re

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import STICK
from toolkit import LikemeError, create_plugin_manager, load_scenario

CHARACTER = STICK + """
[segmenter]
plugin = "hub-threshold"

[action]
plugin = "script"
movements = ["bob"]
random = 2
pause = 0.2
start = 0.1
"""

SCENARIO = """
[scenario]
name = "fuzz"
fps = 30.0
duration = 0.5
tail = 0.5
seed = 3

[[actors]]
id = "stick"
character = "stick.toml"
position = [0.0, 0.0, 1.0]
heading = 180.0

[[actors]]
id = "watcher"
character = "stick.toml"
watch = "stick"
[actors.override.action]
plugin = "script"
random = 1

[[objects]]
name = "cheese"
kind = "food"
position = [0.3, 0.4, 1.2]
radius = 0.05
colour = "#ffd700"
held_by = "stick"
properties = { held_in = "head" }
"""

HOSTILE = ["nan", "inf", "-inf", "-1", "0", "1e300", "-1e300", "100000000", "9223372036854775807", "true", '"abc"',
           '""', '["stick"]', "[]", "{}", '{ a = 1 }', "[[1, 2], [3]]", "[" * 40 + "]" * 40,
           "{a=" * 40 + "1" + "}" * 40, '"#zzzzzz"', '"stand"', '["bob", 3]', '"\\u00e9"']

pm = create_plugin_manager(autoload=False, trace=False)


def _mutate(text: str, data) -> str:
    lines = text.splitlines()
    places = [i for i, line in enumerate(lines) if re.match(r"^\s*[A-Za-z_]+\s*=", line)]
    for _ in range(data.draw(st.integers(1, 3))):
        i = data.draw(st.sampled_from(places))
        how = data.draw(st.sampled_from(["value", "value", "value", "drop", "repeat"]))
        if how == "value":
            key = lines[i].split("=", 1)[0]
            lines[i] = f"{key}= {data.draw(st.sampled_from(HOSTILE))}"
        elif how == "drop":
            lines[i] = ""
        else:
            lines[i] = lines[i] + "\n" + lines[i]
    return "\n".join(lines) + "\n"


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data(), which=st.sampled_from(["scenario", "character", "both"]))
def test_a_mutated_file_loads_and_runs_or_fails_with_a_likeme_error(tmp_path, data, which):
    scenario = _mutate(SCENARIO, data) if which in ("scenario", "both") else SCENARIO
    character = _mutate(CHARACTER, data) if which in ("character", "both") else CHARACTER
    (tmp_path / "stick.toml").write_text(character, encoding="utf-8")
    (tmp_path / "s.toml").write_text(scenario, encoding="utf-8")
    try:
        loaded = load_scenario(tmp_path / "s.toml", pm)
        loaded.world.run(0.2)
    except LikemeError as err:
        assert str(err) and "\n" not in str(err)
