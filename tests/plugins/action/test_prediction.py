"""Buchsbaum & Blumberg 2005, §7.4: predicting what another will do next from the success context of the behaviour
identified and the observer's own transition map (plugins/action/prediction.py)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from plugins.action.prediction import imagine, predict, success_context
from tests.conftest import CHARACTERS
from toolkit import WorldObject, create_plugin_manager, load_character, load_scenario
from toolkit.runtime import World

REACH_HUNGER = ("satisfy_hunger", "get", "reach")
REACH_PLAY = ("play", "get", "reach")


def setting(observer_file=CHARACTERS / "max.toml", tmp_path=None, extra=""):
    """Morris with a cheese and a ball within reach in front of him; the observer's action system (Max or a variant
    written from ``extra`` TOML over max.toml)."""
    pm = create_plugin_manager(autoload=False)
    if extra:
        observer_file = tmp_path / "variant.toml"
        observer_file.write_text(f'[character]\nname = "Variant"\nextends = "{CHARACTERS / "max.toml"}"\n{extra}')
    world = World(fps=30, pm=pm)
    morris = world.add_actor(load_character(CHARACTERS / "morris.toml", pm), "morris")
    observer = world.add_actor(load_character(observer_file, pm), "max", position=(0, 0, 2))
    world.add_object(WorldObject("cheese", "cheese", (0.1, 0.4, 0.3), radius=0.04))
    world.add_object(WorldObject("ball", "ball", (-0.1, 0.3, 0.3), radius=0.04))
    return world, morris, observer.character.action


def then(world):
    return SimpleNamespace(objects=world.objects_at(world.frame))


def test_after_a_reach_for_food_eat_after_a_reach_for_a_toy_dance():
    """The success context of reach is holding the object: holding the cheese makes eating possible (hunger), holding
    the ball makes playing with it possible (play)."""
    world, morris, system = setting()
    assert predict(system, morris, REACH_HUNGER, "cheese", then(world)) == ("eat the cheese",)
    assert predict(system, morris, REACH_PLAY, "ball", then(world)) == ("dance the ball",)
    assert world.objects["cheese"].held_by is None  # imagined, not done


def test_the_imagined_world_is_the_one_where_the_success_context_holds():
    world, morris, system = setting()
    triggers = success_context(system, REACH_HUNGER)
    assert [t.name for t in triggers] == ["holding"]
    objects = imagine(triggers, morris, world.objects, "cheese", system.beliefs)
    assert objects["cheese"].held_by == "morris" and objects["ball"].held_by is None
    assert world.objects["cheese"].held_by is None
    # eat has no success context of its own, nor has satisfy hunger: nothing to imagine, nothing predicted
    assert success_context(system, ("satisfy_hunger", "eat")) == []
    assert predict(system, morris, ("satisfy_hunger", "eat"), "cheese", then(world)) == ()


def test_a_character_with_another_success_context_predicts_otherwise(tmp_path):
    """A character for whom reaching succeeds when the object is *not* held (he reaches to push things about)
    imagines the cheese still free, where he would not eat it but reach for it again."""
    pusher = '[action.tuples.reach]\nuntil = [{ trigger = "not-holding" }]\n'
    world, morris, system = setting(tmp_path=tmp_path, extra=pusher)
    assert predict(system, morris, REACH_HUNGER, "cheese", then(world)) == ("reach the cheese",)
    # and one whose get and reach have no success context predicts nothing
    aimless = '[action.tuples.reach]\nuntil = []\n[action.tuples.get]\nuntil = []\n'
    world, morris, system = setting(tmp_path=tmp_path, extra=aimless)
    assert predict(system, morris, REACH_HUNGER, "cheese", then(world)) == ()


SNIFF = '''
[action.tuples.satisfy_hunger]
children = ["get", "eat", "sniff"]

[action.tuples.sniff]
movement = "nod"
can = [{ trigger = "holding" }]
'''


def test_the_transition_map_orders_the_candidates(tmp_path):
    """Two tuples are possible once Morris holds the cheese (eat it or sniff at it): the observer's own habits, what
    he did after reaching, put one first."""
    world, morris, system = setting(tmp_path=tmp_path, extra=SNIFF)
    assert predict(system, morris, REACH_HUNGER, "cheese", then(world)) == ("eat the cheese", "nod the cheese")
    system.transitions[("reach", "sniff")] += 3
    assert predict(system, morris, REACH_HUNGER, "cheese", then(world)) == ("nod the cheese", "eat the cheese")
    system.transitions[("reach", "eat")] += 5
    assert predict(system, morris, REACH_HUNGER, "cheese", then(world)) == ("eat the cheese", "nod the cheese")


def test_behaviour_identification_predicts_from_the_success_context():
    """In hungry_morris Max predicts the eat; in the fumble scenario too, after each reach."""
    pm = create_plugin_manager(autoload=False)
    world = load_scenario(CHARACTERS / "scenarios" / "fumble.toml", pm).run()
    reaches = [b for b in world.behaviours("max") if b.movement == "reach"]
    assert len(reaches) == 2 and all(b.prediction == ("eat the cheese",) for b in reaches)


@pytest.mark.parametrize("obj", [None, "nothing-here"])
def test_no_object_no_prediction(obj):
    world, morris, system = setting()
    assert predict(system, morris, REACH_HUNGER, obj, then(world)) == ()
