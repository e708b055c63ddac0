"""Max concludes from what he perceived, never from the world (issue 19; Buchsbaum & Blumberg 2005, §6.1, §7.3.1).

The lying world: while Max's action system interprets and answers what he saw, the world's object table,
``objects_at`` and Morris's true pose lie (or raise). His conclusions must be exactly those of an honest run.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest

from plugins.action.hierarchical import Hierarchical
from tests.conftest import CHARACTERS
from toolkit import create_plugin_manager, load_scenario
from toolkit import Motion
from toolkit.sightings import Sightings

SCENARIOS = sorted(p.stem for p in (CHARACTERS / "scenarios").glob("*.toml") if "[[objects]]" in p.read_text())


def run(name):
    pm = create_plugin_manager(autoload=False)
    world = load_scenario(CHARACTERS / "scenarios" / f"{name}.toml", pm).run()
    return world, world.behaviours("max")


class GroundTruth(AssertionError):
    """Raised when the action system reads the world's ground truth about another actor."""


class LyingObjects(dict):
    """An object table that refuses to be read."""

    def _refuse(self, *args, **kwargs):
        raise GroundTruth("read the world's objects")

    __getitem__ = __iter__ = __len__ = __contains__ = get = items = keys = values = _refuse


class Refusing:
    """Anything read of it is a :class:`GroundTruth` error."""

    def __init__(self, what):
        object.__setattr__(self, "_what", what)

    def __getattr__(self, name):
        raise GroundTruth(f"read {self._what}: .{name}")

    def __iter__(self):
        raise GroundTruth(f"read {self._what}")

    def __bool__(self):
        raise GroundTruth(f"read {self._what}")


def lying(method):
    """``method`` of the action system, called while the world lies about its objects and the target's pose, and
    refuses to say what the target is, does or did."""

    def wrapped(self, actor, target, *args):
        world = actor.world
        objects, position, heading = world.objects, target.position.copy(), target.heading
        world.objects = LyingObjects()
        world.objects_at = lambda frame: (_ for _ in ()).throw(GroundTruth("read objects_at"))
        target.world_pose = lambda: (_ for _ in ()).throw(GroundTruth("read the target's true pose"))
        target.local_pose = lambda: (_ for _ in ()).throw(GroundTruth("read the target's true pose"))
        target.position, target.heading = position + np.array([5.0, 3.0, -7.0]), heading + 2.0  # a lie, if read
        character, performing, performed = target.character, target.performing, target.performed
        target.character = Refusing("the target's own character (his drives, his choices, his body)")
        target.performing, target.performed = Refusing("what the target is doing"), Refusing("what the target did")
        try:
            wrapped.calls += 1
            return method(self, actor, target, *args)
        finally:
            world.objects, target.position, target.heading = objects, position, heading
            target.character, target.performing, target.performed = character, performing, performed
            del world.objects_at, target.world_pose, target.local_pose

    wrapped.calls = 0
    return wrapped


@functools.lru_cache(maxsize=None)
def honest_run(name):
    """What Max concludes in scenario ``name`` when nothing lies (run once per test session and worker)."""
    return run(name)[1]


@pytest.mark.parametrize("name", SCENARIOS)
def test_max_concludes_the_same_when_the_world_lies(monkeypatch, name):
    honest = honest_run(name)
    interpret, respond = lying(Hierarchical.interpret), lying(Hierarchical.respond)
    monkeypatch.setattr(Hierarchical, "interpret", interpret)
    monkeypatch.setattr(Hierarchical, "respond", respond)
    _, lied_to = run(name)
    assert interpret.calls > 0 and respond.calls > 0  # the lie was told
    assert lied_to == honest
    assert honest  # there was something to conclude


def lying_names(method):
    """``method`` of the perception, called while the world's objects carry names and kinds that lie (a cheese
    called "o3", of kind "rock"): only where they are, how big and what colour is true."""

    def wrapped(self, observer, target, world, *args):
        target.world_pose()  # the pose Morris shows this frame, his head turned to what he wants, before the lie
        objects = world.objects
        world.objects = {f"o{i}": dataclasses.replace(o, name=f"o{i}", kind="rock")
                         for i, o in enumerate(objects.values())}
        try:
            wrapped.calls += 1
            return method(self, observer, target, world, *args)
        finally:
            world.objects = objects

    wrapped.calls = 0
    return wrapped


@pytest.mark.parametrize("name", SCENARIOS)
def test_max_sees_objects_by_their_look_never_by_their_names_or_kinds(monkeypatch, name):
    """B&B §4.2: Max knows an object by its colour and its size as seen; while he looks, the world's names and kinds
    of its objects lie, and he concludes exactly what he concludes when they do not."""
    from plugins.perception.rendered_vision import RenderedVision

    perceive, in_view = lying_names(RenderedVision.perceive), lying_names(RenderedVision.in_view)
    monkeypatch.setattr(RenderedVision, "perceive", perceive)
    monkeypatch.setattr(RenderedVision, "in_view", in_view)
    _, lied_to = run(name)
    assert perceive.calls > 0
    assert lied_to == honest_run(name) and lied_to


def test_the_lying_world_would_catch_a_reader(monkeypatch):
    """The check itself: an interpret that reads the world's objects fails under the lie."""

    def peeking(self, actor, target, segment, match, world):
        return None if "cheese" in world.objects else None

    monkeypatch.setattr(Hierarchical, "interpret", lying(peeking))
    with pytest.raises(Exception, match="read the world's objects"):
        run("hungry_morris")


def test_sightings_remember_last_seen_positions_and_forget_gone_objects():
    s = Sightings(fps=10.0, keep=1.0)
    s.record(0, 0.0, {"cheese": [0, 0.4, 1]}, {"cheese": "cheese"}, {"cheese": 0.04})
    s.record(1, 0.0, {})  # hidden: still where it was last seen
    assert set(s.at(1)) == {"cheese"} and s.at(1)["cheese"].row == 0 and s.at(1)["cheese"].kind == "cheese"
    assert s.at(-1) == {}  # never seen before row 0: it does not exist
    s.record(2, 0.0, {}, missed=["cheese"])  # missed a moment after it was seen: it may have been carried off
    assert set(s.at(2)) == {"cheese"}
    for row in range(3, 7):  # missed for more than CARRIED (0.5 s): gone from then on
        s.record(row, 0.0, {}, missed=["cheese"])
    assert s.at(6) == {} and set(s.at(5)) == {"cheese"} and set(s.at(1)) == {"cheese"}
    s.record(7, 0.0, {"cheese": [0, 0.3, 1]})  # seen again
    assert np.allclose(s.at(7)["cheese"].position, [0, 0.3, 1])


def test_sightings_are_bounded_and_keep_each_objects_last_sighting():
    s = Sightings(fps=10.0, keep=1.0)
    s.record(0, 0.0, {"ball": [1, 0, 1]})
    for row in range(1, 500):
        s.record(row, 0.1, {"cheese": [0, 0.4, 1]})
    assert s.size <= 2 * 10 + 2  # about keep seconds of rows, not 500
    assert np.allclose(s.at(499)["ball"].position, [1, 0, 1])  # seen long ago: still where it was last seen
    assert s.heading(499) == pytest.approx(0.1)


# -- Fig. 13: ranked candidates -------------------------------------------------------------------------------------


def test_path_search_ranks_the_runner_up_as_the_best_path_without_the_winner(write, pm):
    """The second candidate is what path search answers when the first movement is not in the graph at all."""
    from tests.plugins.matchers.path_search.stick import STICK, observed
    from toolkit import load_character

    stick = load_character(write("stick.toml", STICK + "candidates = 1\n[matcher.distance]\nmax_distance = 0.2\n"), pm)
    up, front = observed(stick, "raise"), observed(stick, "reach")  # the hand goes up and forward, more up
    seen = Motion(0.55 * up.positions + 0.45 * front.positions, up.fps, up.parts, up.visible)
    match = stick.matcher.match(seen)
    (first, d1), (second, d2) = match.candidates
    assert first == match.movement == "raise" and d1 == pytest.approx(match.details["mean_distance"])
    assert second == "reach" and d2 > d1
    without = STICK.replace('[motor.movements.raise]\nkeys = [{ pose = "stand", at = 0.0 }, { pose = "up", at = 0.5 }, '
                            '{ pose = "stand", at = 1.0 }]\n', "")
    assert without != STICK
    alone = load_character(write("reach_only.toml", without + "[matcher.distance]\nmax_distance = 0.2\n"), pm).matcher.match(seen.onto(stick.body.parts))
    assert alone.movement == "reach" and d2 == pytest.approx(alone.details["mean_distance"])
    plain = load_character(write("plain.toml", STICK + "[matcher.distance]\nmax_distance = 0.2\n"), pm).matcher.match(seen)
    assert plain.movement == "raise" and plain.candidates == ()  # by default the best only


def test_dtw_ranks_every_movement_by_its_nearest_example(write, pm):
    from tests.plugins.matchers.path_search.stick import STICK, observed
    from toolkit import load_character

    stick = load_character(write("stick.toml", STICK.replace('plugin = "path-search"', 'plugin = "dtw"')), pm)
    match = stick.matcher.match(observed(stick, "reach", offset=(0.0, 0.02, 0.0)))
    names = [m for m, _ in match.candidates]
    distances = [d for _, d in match.candidates]
    assert names[0] == match.movement == "reach" and sorted(names) == ["raise", "reach"]
    assert distances == sorted(distances) and distances[0] == pytest.approx(match.details["distance"])


def test_close_candidates_are_those_within_the_margin_of_the_best():
    from plugins.action.behaviour_identification import MARGIN, close_candidates
    from toolkit import Match

    match = Match("reach", 0.5, candidates=(("reach", 0.010), ("jump", 0.010 * (1 + MARGIN) - 1e-6), ("point", 0.02)))
    assert close_candidates(match) == ["reach", "jump"]
    assert close_candidates(Match("reach", 0.5)) == ["reach"]  # no ranking: the movement alone
    assert close_candidates(match, margin=0.0) == ["reach"]


# -- what Max perceived ---------------------------------------------------------------------------------------------


def test_max_perceives_morris_the_cheese_where_it_lay_and_then_in_his_hand():
    """§6.1.1 from perception: at the reach's start the cheese lies where Max saw it and nobody holds it; at the
    eat's start Max saw it in Morris's hand (it came there and moves with the hand); once eaten it is gone."""
    from plugins.action.behaviour_identification import perceived_objects, perceived_target

    world, _ = run("hungry_morris")
    max_, morris = world.actors["max"], world.actors["morris"]
    reach, eat = (e.data["segment"] for e in world.events_of("segment_found", "max"))
    before = perceived_objects(max_, morris, reach.start, reach.end - 1)
    assert set(before) == {"cheese"} and before["cheese"].held_by is None and before["cheese"].kind == "cheese"
    assert np.allclose(before["cheese"].position, [0.08, 0.40, 1.26], atol=0.015)  # where it lay, as a camera sees
    during = perceived_objects(max_, morris, eat.start, eat.end - 1)
    assert during["cheese"].held_by == "morris"
    assert "cheese" not in max_.sightings.at(max_.memory.n - 1)  # eaten: not where Max should see it
    him = perceived_target(max_, morris, reach.start)
    root = him.world_pose()[him.body.root_index]
    assert np.allclose(root, [0.0, 0.30, 1.6], atol=0.02) and him.id == "morris"
    assert abs(np.cos(him.heading - np.pi)) > 0.99  # he faces Max (180 degrees)


def test_sightings_may_begin_at_a_later_row():
    s = Sightings(fps=10.0, start=50)
    s.record(50, 1.0, {"ball": [1, 0, 1]})
    assert set(s.at(50)) == {"ball"} and s.at(49) == {} and s.heading(50) == 1.0
    with pytest.raises(ValueError, match="in order"):
        s.record(52, 1.0, {})
