"""The two segmenters and the two matchers in all four pairings, on the same demonstration (Morris's movements)."""

from __future__ import annotations

import pytest

from tests.conftest import CHARACTERS
from toolkit import create_plugin_manager, load_scenario

MOVES = ["wave", "jump", "wave", "jump", "reach", "wave"]

PAIRINGS = {
    ("hub-threshold", "path-search"): ("max.toml", {}),
    ("velocity-direction", "path-search"): ("max.toml", {"segmenter": {"plugin": "velocity-direction", "level": "movement"}}),
    ("hub-threshold", "forward-model"): ("max_mouse_learner.toml", {}),
    ("velocity-direction", "forward-model"): ("max_mouse_learner.toml", {"segmenter": {"plugin": "velocity-direction", "level": "movement"}}),
}


@pytest.mark.parametrize("pairing", list(PAIRINGS), ids=lambda p: " x ".join(p))
def test_every_pairing_runs_on_the_same_input(watch_scene, pairing):
    character, override = PAIRINGS[pairing]
    tables = '[actors.override.perception]\nplugin = "motion-capture"\n' + "".join(
        f"[actors.override.{table}]\n" + "".join(f'{k} = "{v}"\n' for k, v in values.items())
        for table, values in override.items()
    )
    scene = watch_scene(MOVES, tables, watcher=CHARACTERS / character)
    world = load_scenario(scene, create_plugin_manager(autoload=False)).run()
    max_ = world.actors["max"].character
    assert (max_.segmenter.name, max_.matcher.name) == pairing
    segments = world.events_of("segment_found", "max")
    if pairing[0] == "hub-threshold":
        assert len(segments) == len(MOVES)
    else:  # the sensory memory also ends a movement at a hold: the reach (out, hold, back) comes in two
        assert len(MOVES) <= len(segments) <= len(MOVES) + 1
    names = [e.data["match"].movement for e in world.events_of("movement_recognised", "max")]
    assert names and all(n is None or n in max_.motor.movements() for n in names)
    if pairing == ("hub-threshold", "path-search"):
        assert names == MOVES
    elif pairing[1] == "path-search":
        assert names.count("wave") == 3 and names.count("jump") == 2
    else:  # learned by watching: the repeated movements are recognised as what was learned the first time
        first = {m: names[MOVES.index(m)] for m in ("wave", "jump")}
        assert first["wave"] != first["jump"]
        assert names.count(first["wave"]) >= 2
