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


# -- habits learned from acting (§6.1, §6.1.2) ------------------------------------------------------------------


def acts_then_watches(**max_drives):
    """The scenario max_acts_then_watches run, with Max's drives set first; (world, Max's action system, the behaviour
    he identified in Morris's reach)."""
    pm = create_plugin_manager(autoload=False)
    world = load_scenario(CHARACTERS / "scenarios" / "max_acts_then_watches.toml", pm).world
    system = world.actors["max"].character.action
    assert system.correspondence == {} and not system.transitions  # no prior experience
    for name, level in max_drives.items():
        system.drives[name].level = level
    world.run(duration=12.5)
    (reach,) = [b for b in world.behaviours("max") if b.movement == "reach"]
    assert reach.known and reach.details["line_of_sight"] is None  # the screen hides Morris's head: ambiguous
    return world, system, reach


def test_max_concludes_play_after_he_has_played_himself():
    world, system, reach = acts_then_watches()
    assert [r.movement for _, r in world.actors["max"].performed] == ["reach", "dance", "reach", "dance"]
    # his own acting filled his maps
    assert system.correspondence["reach"] == {("play", "get", "reach"): 2}
    assert system.correspondence["dance"] == {("play", "play_with"): 2}
    assert system.transitions[("reach", "play_with")] == 2 and system.transitions[("play_with", "reach")] == 1
    assert reach.path == ("play", "get", "reach") and reach.object == "ball"
    assert reach.prediction == ("dance the ball",)


def test_before_acting_max_concludes_otherwise():
    """The same scenario, but Max does not want to play: he does nothing, knows no habit, and goes by the order of
    his own hierarchy (hunger first): his conclusion is not the one he reaches after playing."""
    world, system, reach = acts_then_watches(play=0.0)
    assert world.actors["max"].performed == [] and system.correspondence == {}
    assert reach.path == ("satisfy_hunger", "get", "reach") and reach.object == "cheese"


def test_max_concludes_hunger_after_he_has_eaten_himself():
    """Hungry instead of playful, Max eats his own cheese first; now he reads Morris's reach as hunger."""
    world, system, reach = acts_then_watches(play=0.0, hunger=0.9)
    assert [r.movement for _, r in world.actors["max"].performed] == ["reach", "eat"]
    assert system.correspondence["reach"] == {("satisfy_hunger", "get", "reach"): 1}
    assert reach.path == ("satisfy_hunger", "get", "reach") and reach.object == "cheese"


# -- drive competition with two live drives --------------------------------------------------------------------


def two_drives(hunger, play, temperature, seed=0):
    """Max alone with a cheese and a ball within reach, both drives above their thresholds."""
    from toolkit import WorldObject
    from toolkit.runtime import World

    pm = create_plugin_manager(autoload=False)
    world = World(fps=30, pm=pm)
    max_ = world.add_actor(load_character(CHARACTERS / "max.toml", pm,
                                          override={"action": {"temperature": temperature, "seed": seed}}), "max")
    world.add_object(WorldObject("cheese", "cheese", (0.08, 0.40, 0.32), radius=0.04))
    world.add_object(WorldObject("ball", "ball", (-0.08, 0.35, 0.32), radius=0.04))
    system = max_.character.action
    system.drives["hunger"].level, system.drives["play"].level = hunger, play
    return world, max_, system


def test_the_stronger_drive_always_wins_at_temperature_0():
    world, max_, system = two_drives(0.8, 0.6, 0.0)
    assert {system.decide(max_, world)[0][0] for _ in range(50)} == {"satisfy_hunger"}
    world, max_, system = two_drives(0.5, 0.7, 0.0)
    assert {system.decide(max_, world)[0][0] for _ in range(50)} == {"play"}


def test_the_stronger_drive_wins_more_often_at_temperature_above_0():
    world, max_, system = two_drives(0.8, 0.6, 0.2)
    wins = [system.decide(max_, world)[0][0] for _ in range(400)]
    hunger = wins.count("satisfy_hunger")
    assert wins.count("play") > 0  # both are live contenders
    # exp(0.8 / 0.2) : exp(0.6 / 0.2) is e : 1, about 0.73 of the draws
    assert 0.6 < hunger / len(wins) < 0.85
    world, max_, system = two_drives(0.6, 0.8, 0.2)
    wins = [system.decide(max_, world)[0][0] for _ in range(400)]
    assert 0.6 < wins.count("play") / len(wins) < 0.85


def test_satisfying_one_drive_lets_the_other_win():
    """Both drives live, hunger the stronger: Max eats first; eating satisfies hunger and play wins the next
    competition (the motivational subsystem stays active until its drive is satisfied, then the other takes over)."""
    world, max_, system = two_drives(0.9, 0.6, 0.0)
    world.run(until_idle=True, tail=1.0, max_duration=30.0)
    performed = [(r.movement, r.object) for _, r in max_.performed]
    assert performed[:4] == [("reach", "cheese"), ("eat", "cheese"), ("reach", "ball"), ("dance", "ball")]
    assert system.drives["hunger"].level < 0.3 and system.drives["play"].level < 0.3
    tops = [name for _, event, name, _ in system.log if event == "began" and name in system.hierarchy.top]
    assert tops[:2] == ["satisfy_hunger", "play"]
