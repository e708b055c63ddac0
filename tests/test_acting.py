"""Acting with the hierarchical action system (Buchsbaum & Blumberg 2005, §6, §6.2): do-until contexts control the
action tuples, failed children are retried a bounded number of times, drives compete."""

from __future__ import annotations

import pytest

from tests.conftest import CHARACTERS
from toolkit import ConfigError, create_plugin_manager, load_character, load_scenario


def scenario(name, **reach):
    """The scenario ``name`` loaded (not run); ``reach`` overrides attributes of Morris's reach tuple."""
    pm = create_plugin_manager(autoload=False)
    world = load_scenario(CHARACTERS / "scenarios" / f"{name}.toml", pm).world
    for key, value in reach.items():
        setattr(world.actors["morris"].character.action.hierarchy.tuples["reach"], key, value)
    return world


def events(system, *kinds):
    return [(event, name) for _, event, name, _ in system.log if not kinds or event in kinds]


def test_get_persists_until_holding_then_eat_follows():
    """§6.2: the reach misses; get (until holding) stays active and reaches again; holding ends get; eat follows."""
    world = scenario("fumble")
    world.run(until_idle=True, tail=1.0)
    morris = world.actors["morris"]
    system = morris.character.action
    assert [r.movement for _, r in morris.performed] == ["reach", "reach", "eat"]
    assert events(system) == [
        ("began", "satisfy_hunger"), ("began", "get"), ("began", "reach"),
        ("failed", "reach"),  # the first reach missed: get is still active and decides its child again
        ("began", "reach"), ("succeeded", "reach"),
        ("succeeded", "get"),  # its success context (holding) holds: get ends, satisfy_hunger decides again
        ("began", "eat"), ("succeeded", "eat"),
        ("succeeded", "satisfy_hunger"),  # hunger satisfied
    ]
    assert "cheese" not in world.objects and system.drives["hunger"].level < 0.3
    assert system.active == ()


def test_without_misses_the_same_scenario_reaches_once():
    world = scenario("fumble", chance=1.0)
    world.run(until_idle=True, tail=1.0)
    assert [r.movement for _, r in world.actors["morris"].performed] == ["reach", "eat"]


@pytest.mark.parametrize("retries", [0, 1, 2, 4])
def test_a_tuple_gives_up_after_its_retries(retries):
    """A grasp that never works: get reaches 1 + retries times, gives up on the cheese, and nothing loops forever."""
    world = scenario("fumble", chance=0.0)
    system = world.actors["morris"].character.action
    system.hierarchy.tuples["get"].retries = retries
    world.run(until_idle=True, tail=1.0, max_duration=60.0)
    assert world.time < 30.0  # it stopped by itself: every actor idle
    assert [r.movement for _, r in world.actors["morris"].performed] == ["reach"] * (1 + retries)
    assert ("gave up", "get") in events(system)
    assert "cheese" in world.objects and system.active == ()
    # satisfy hunger has nothing else to do with the cheese and gives up on it too: it is not chosen again
    assert ("satisfy_hunger", "cheese") in system._given_up
    assert system.decide(world.actors["morris"], world) is None


def test_a_new_object_after_giving_up_is_tried():
    """Giving up is for one object: a second cheese in reach is got and eaten."""
    from toolkit import WorldObject

    world = scenario("fumble", chance=0.0)
    system = world.actors["morris"].character.action
    system.hierarchy.tuples["get"].retries = 0
    world.run(duration=3.0)
    assert ("gave up", "get") in events(system)
    system.hierarchy.tuples["reach"].chance = 1.0
    world.add_object(WorldObject("cheese_2", "cheese", (-0.05, 0.40, 1.28), radius=0.04))
    world.run(until_idle=True, tail=1.0, max_duration=30.0)
    performed = [(r.movement, r.object) for _, r in world.actors["morris"].performed]
    assert performed[-2:] == [("reach", "cheese_2"), ("eat", "cheese_2")]
    assert "cheese_2" not in world.objects


@pytest.mark.parametrize("tuple_, key, value, fragment", [
    ("reach", "chance", 1.5, "chance"),
    ("reach", "chance", "often", "chance"),
    ("get", "chance", 0.5, "only a leaf"),
    ("get", "retries", -1, "retries"),
    ("get", "retries", 1.5, "retries"),
    ("reach", "retries", 2, "only a tuple with children"),
])
def test_bad_chance_or_retries_is_a_clear_error(tmp_path, tuple_, key, value, fragment):
    value_text = f'"{value}"' if isinstance(value, str) else str(value)
    path = tmp_path / "c.toml"
    path.write_text(f'[character]\nname = "C"\nextends = "{CHARACTERS / "max.toml"}"\n'
                    f"[action.tuples.{tuple_}]\n{key} = {value_text}\n")
    with pytest.raises(ConfigError) as err:
        load_character(path, create_plugin_manager(autoload=False))
    assert fragment in str(err.value) and key in str(err.value)
