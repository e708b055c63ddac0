"""Persistence: what characters learn is saved atomically with a version and loaded again; killed runs leave valid files."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import CHARACTERS, ROOT
from toolkit import ConfigError, create_plugin_manager, load_character, load_scenario
from toolkit.state import (Checkpoint, StateFile, character_state, checksum, load_state, read_state, save_state,
                           write_atomic)


@pytest.fixture(scope="module")
def learned(tmp_path_factory):
    """A world after Max learned the windmill (a new posegraph movement) and watched Morris."""
    pm = create_plugin_manager(autoload=False)
    scenario = load_scenario(CHARACTERS / "scenarios" / "learn_windmill.toml", pm)
    world = scenario.run()
    path = tmp_path_factory.mktemp("state") / "state.json"
    save_state(world, path)
    return world, path


def fresh_world():
    pm = create_plugin_manager(autoload=False)
    return load_scenario(CHARACTERS / "scenarios" / "learn_windmill.toml", pm).world


def test_save_then_load_gives_the_same_learned_state(learned):
    world, path = learned
    max_ = world.actors["max"].character
    assert "learned-1" in max_.motor.movements()
    new = fresh_world()
    assert "learned-1" not in new.actors["max"].character.motor.movements()
    load_state(new, path)
    again = new.actors["max"].character
    assert character_state(again) == character_state(max_)
    # the restored movement is recognised and can be performed
    windmill = new.actors["morris"].character.motor.perform("windmill", fps=30).root_relative("root")
    assert again.matcher.match(windmill).movement == "learned-1"
    np.testing.assert_allclose(again.motor.perform("learned-1").positions, max_.motor.perform("learned-1").positions, atol=1e-5)


def test_state_file_has_format_and_version(learned):
    _, path = learned
    data = json.loads(path.read_text())
    assert data["format"] == "likeme-state" and data["version"] == 2
    assert data["checksum"] == checksum(data) and data["checksum"].startswith("sha256:")
    assert set(data["actors"]) == {"morris", "max"}
    assert data["actors"]["max"]["character"] == "Max"


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda d: d.update(version=3), r"state.json: key version: unsupported state format version 3; expected a version this likeme reads; available: 1, 2"),
        (lambda d: d.update(format="other"), r"key format: not a likeme state file"),
        (lambda d: d["actors"].update(ghost={"character": "Ghost", "components": {}}), r"key actors.ghost: unknown actor 'ghost'.*available: morris, max"),
        (lambda d: d["actors"]["max"]["components"]["motor"].update(plugin="keyframe"), r"key actors.max.components.motor.plugin: state saved for plugin 'keyframe'; expected state of 'posegraph'"),
        (lambda d: d["actors"]["max"]["components"]["action"]["state"]["drives"].update(thirst=0.5), r"key actors.max.components.action.state.drives.thirst: unknown drive 'thirst'"),
        (lambda d: d["actors"]["max"]["components"]["motor"]["state"]["learned"]["learned-1"].update(poses=[[1, 2]]), r"invalid poses of learned movement 'learned-1'"),
    ],
)
def test_bad_state_files_are_refused_with_a_clear_message(learned, tmp_path, edit, message):
    _, path = learned
    data = json.loads(path.read_text())
    edit(data)
    data["checksum"] = checksum(data)  # signed again: the checks behind the checksum
    bad = tmp_path / "state.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(ConfigError, match=message):
        load_state(fresh_world(), bad)


def test_not_json_names_line_and_column(tmp_path):
    bad = tmp_path / "s.json"
    bad.write_text('{"format": "likeme-state",\n "version": 1,,\n}')
    with pytest.raises(ConfigError, match=r"s.json:2:\d+: not JSON"):
        read_state(bad)


def test_a_failed_write_leaves_the_old_file(tmp_path, monkeypatch):
    path = tmp_path / "s.json"
    write_atomic(path, "old\n")

    def broken(*args):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", broken)
    with pytest.raises(OSError):
        write_atomic(path, "new\n")
    assert path.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["s.json"]  # no temporary file left behind


hierarchy_states = st.fixed_dictionaries({
    "drives": st.fixed_dictionaries({"hunger": st.floats(0, 1), "play": st.floats(0, 1)}),
    "beliefs": st.dictionaries(st.sampled_from(["cheese", "ball", "ice_cream", "baton", "pear"]), st.sampled_from(["food", "toy"])),
    "correspondence": st.fixed_dictionaries({}, optional={
        "reach": st.fixed_dictionaries({}, optional={"play > get > reach": st.integers(1, 50), "satisfy_hunger > get > reach": st.integers(1, 50)}),
        "eat": st.fixed_dictionaries({}, optional={"satisfy_hunger > eat": st.integers(1, 50)}),
    }),
    "transitions": st.lists(st.tuples(st.sampled_from(["reach", "jump", "eat"]), st.sampled_from(["eat", "play_with"]), st.integers(1, 9)).map(list),
                            unique_by=lambda t: (t[0], t[1]), max_size=4),
})


@settings(max_examples=25, deadline=None)
@given(state=hierarchy_states)
def test_action_state_round_trips_through_a_file(tmp_path_factory, state):
    pm = create_plugin_manager(autoload=False)
    a = load_character(CHARACTERS / "max.toml", pm)
    a.action.set_state(state)
    path = tmp_path_factory.mktemp("h") / "max.json"
    save_state(a, path)
    b = load_character(CHARACTERS / "max.toml", pm)
    load_state(b, path)
    assert b.action.get_state() == a.action.get_state()
    assert {k: v for k, v in b.action.get_state()["correspondence"].items() if v} == {k: v for k, v in state["correspondence"].items() if v}


def test_checkpoint_saves_when_something_is_learned(tmp_path):
    pm = create_plugin_manager(autoload=False)
    scenario = load_scenario(CHARACTERS / "scenarios" / "learn_windmill.toml", pm)
    path = tmp_path / "run.json"
    checkpoint = Checkpoint(scenario.world, path, every=0)
    pm.register(checkpoint)
    world = scenario.world
    while not path.exists():
        world.step()
        assert world.frame < 30 * 10
    assert "learned-1" in read_state(path)["actors"]["max"]["components"]["motor"]["state"]["learned"]
    assert checkpoint.saves == 1


def test_run_save_and_load_from_the_command_line(tmp_path):
    state = tmp_path / "s.json"
    env = {**os.environ, "LIKEME_DISABLE_PLUGIN_AUTOLOAD": "1"}
    first = subprocess.run([sys.executable, "-m", "toolkit.cli", "run", "ice_cream", "--save", state],
                           capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)
    assert first.returncode == 0, first.stderr
    assert read_state(state)["actors"]["max"]["components"]["action"]["state"]["beliefs"]["ice_cream"] == "food"
    # a new run that loads it knows ice cream from the start: no shrug at the first reach
    second = subprocess.run([sys.executable, "-m", "toolkit.cli", "run", "ice_cream", "--load", state, "--json"],
                            capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)
    assert second.returncode == 0, second.stderr
    max_ = next(a for a in json.loads(second.stdout)["actors"] if a["id"] == "max")
    assert all(b["known"] for b in max_["watching"]["behaviours"])


def test_killing_a_saving_run_never_leaves_a_broken_state_file(tmp_path):
    """A long run that learns and checkpoints all the time, killed with SIGKILL at random moments."""
    scene = tmp_path / "long.toml"
    scene.write_text(
        f"""
[scenario]
name = "long learning run"
[[actors]]
character = "{(CHARACTERS / 'morris.toml').as_posix()}"
position = [0.0, 0.0, 1.6]
heading = 180.0
[actors.override.action]
plugin = "script"
movements = ["windmill"]
random = 300
pause = 0.2
[[actors]]
id = "max"
character = "{(CHARACTERS / 'max.toml').as_posix()}"
watch = "morris"
[actors.override.matcher]
learn = true
""",
        encoding="utf-8",
    )
    rng = np.random.default_rng(0)
    env = {**os.environ, "LIKEME_DISABLE_PLUGIN_AUTOLOAD": "1"}
    state = tmp_path / "s.json"
    loaded = 0
    for attempt in range(6):
        proc = subprocess.Popen([sys.executable, "-m", "toolkit.cli", "run", scene, "--save", state],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=ROOT)
        if attempt == 0:  # the first run lives until its first checkpoint however loaded the machine, then a while
            deadline = time.monotonic() + 120.0
            while not state.exists() and proc.poll() is None and time.monotonic() < deadline:
                time.sleep(0.05)
            time.sleep(float(rng.uniform(0.0, 1.5)))
        else:
            time.sleep(float(rng.uniform(1.5, 5.0)))
        finished = proc.poll() is not None
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        assert not finished, "the run ended before it was killed: make it longer"
        if state.exists():
            pm = create_plugin_manager(autoload=False)
            world = load_scenario(scene, pm).world
            load_state(world, state)  # loads, whatever moment it was killed at
            loaded += 1
    assert loaded > 0
    # a write cut short leaves at most a temporary file beside the state file, never a broken state file
    assert {p.name for p in tmp_path.iterdir() if not p.name.startswith(".s.json.")} == {"s.json", "long.toml"}
    # and the next save sweeps such leftovers away
    StateFile(state, loaded=state).save(state.read_text())
    assert {p.name for p in tmp_path.iterdir()} == {"s.json", "long.toml", ".s.json.lock"}
