"""Line of sight wherever the objects lie (Buchsbaum & Blumberg 2005, §6.1.2): Morris turns his head toward what he
wants (the look-at layer), and Max reads the line of sight from the head and nose he perceives."""

from __future__ import annotations

import numpy as np
import pytest

from plugins.bench.behaviour import BEHAVIOUR_CONDITIONS, REACH, SIDE, _draw, _run_episode, behaviour_benchmark
from tests.conftest import CHARACTERS
from toolkit import create_plugin_manager, load_scenario


@pytest.fixture(scope="module")
def pm():
    return create_plugin_manager(autoload=False)


def _reach_identified(pm, *, layer: bool):
    scenario = load_scenario(CHARACTERS / "scenarios" / "cheese_side_ball_front.toml", pm)
    if not layer:
        for actor in scenario.world.actors.values():
            actor.character.layer = None
    world = scenario.run()
    return world, next(b for b in world.behaviours("max") if b.movement == "reach")


def test_cheese_to_the_side_ball_in_front(pm):
    """Hungry Morris looks at the cheese at his side while he reaches: Max concludes hunger and the cheese."""
    world, reach = _reach_identified(pm, layer=True)
    assert [r.object for _, r in world.actors["morris"].performed] == ["cheese", "cheese"]
    assert reach.known and reach.details["line_of_sight"] == "cheese"
    assert reach.path == ("satisfy_hunger", "get", "reach") and reach.object == "cheese"
    assert reach.motivation == ("hunger",)


def test_without_the_look_at_max_goes_by_his_habits(pm):
    """The failure the look-at removes: a head that does not turn looks straight ahead, over the ball in front (it
    lies 24 degrees below his gaze, read in 3D) and far from the cheese at his side: nothing is in his line of sight,
    and Max goes by his habits (he reaches to play more often than to eat): play, the ball."""
    _, reach = _reach_identified(pm, layer=False)
    assert reach.details["line_of_sight"] is None and reach.details["in_sight"] == {}
    assert reach.path == ("play", "get", "reach") and reach.object == "ball"


@pytest.mark.parametrize("seed", range(8))
def test_objects_placed_at_random_within_reach(pm, seed):
    """Food and a toy anywhere within Morris's reach on his front side (``likeme bench behaviour``'s random-placement
    condition, seeded): Max identifies the object and the motivation of Morris's first behaviour."""
    item = _draw(np.random.default_rng(1000 + seed), "random-placement")
    for position in item["positions"].values():
        x, _, z = position
        distance = float(np.hypot(x, z - 1.6))
        assert REACH[0] <= distance <= REACH[1] and abs(np.degrees(np.arctan2(x, 1.6 - z))) <= SIDE
    row = _run_episode(item, pm)
    assert row["true_object"] == item["wanted"]
    assert row["identified"] and row["line_of_sight"] == item["wanted"]
    assert row["identified_object"] == row["true_object"]
    assert row["path"][0] == row["true_path"][0]  # the motivation: the top-level tuple


def test_the_bench_is_the_same_whatever_runs_it(pm):
    """``likeme bench behaviour --jobs 2`` gives exactly the figures and episodes of one process."""
    one = behaviour_benchmark(pm, episodes=1, seed=3, conditions=("line-of-sight", "random-placement"))
    two = behaviour_benchmark(pm, episodes=1, seed=3, conditions=("line-of-sight", "random-placement"), jobs=2)
    assert one["conditions"] == two["conditions"] and one["episodes"] == two["episodes"]
    assert [r["condition"] for r in one["episodes"]] == ["line-of-sight", "random-placement"]
    # a condition left out leaves the others' episodes as they were
    every = behaviour_benchmark(pm, episodes=1, seed=3)
    assert [r["condition"] for r in every["episodes"]] == list(BEHAVIOUR_CONDITIONS)
    assert [every["episodes"][0], every["episodes"][3]] == one["episodes"]
