"""Speed re-parameterisation (Kopp & Graeser 2006, §4.4) and its off switch (the paper's baseline).

"If the demonstrated movement is in principle familiar to Max but now performed with a different speed, the
predictions of the corresponding forward model (or edge) will not be correct. That is, movements with different
execution speeds would be learned as separate edges by the algorithm in Fig. 3. One solution to this problem is to map
the length of the movement seen so far onto the trajectory predicted by a forward model, yielding the time parameter at
which the corresponding motor command (with the speed demonstrated at first) would have produced a movement of the
same length. From this, the speed difference can be calculated and used to re-parameterize the motor command."

Max learns one of Moritz's movements (out, hold, back) at its own speed, then Moritz performs it again at known speed
factors (his key frames played that much faster): the factor Max measures must be within 10% of the true one
(:mod:`plugins.matchers.forward_model.speed`).
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.lib.guiding_stroke import GuidingStroke
from tests.conftest import CHARACTERS
from tests.plugins.matchers.forward_model.helpers import ARMS, demonstration, stroke_path
from toolkit import Motion, create_plugin_manager, load_character, load_scenario
from toolkit.watching import feed

SPEEDS = (0.6, 1.0, 1.5, 2.0)


def _world(write, movement: str, **matcher):
    scene = write(
        "speed.toml",
        f"""
        [scenario]
        name = "speeds"
        [[actors]]
        character = "{CHARACTERS / 'moritz.toml'}"
        position = [0.0, 0.0, 2.0]
        heading = 180.0
        [actors.override.action]
        plugin = "script"
        movements = ["{movement}"]
        [[actors]]
        character = "{CHARACTERS / 'max_learner.toml'}"
        watch = "moritz"
        """,
    )
    world = load_scenario(scene, create_plugin_manager(autoload=False)).run()
    max_ = world.actors["max"].character
    max_.matcher.params = {**max_.matcher.params, **matcher}
    return world


def _again(world, movement: str, speed: float):
    """Moritz performs ``movement`` again at ``speed``; the recognitions and imitations of that demonstration."""
    moritz = world.actors["moritz"]
    first = len(world.events)
    moritz.character.action.plan.append(movement)
    moritz.character.action.params = {**moritz.character.action.params, "speed": speed}
    world.run(6.0 / min(speed, 1.0))
    events = world.events[first:]
    recognised = [e.data["match"] for e in events if e.kind == "movement_recognised" and e.actor == "max"]
    imitated = [e.data["request"] for e in events if e.kind == "imitation_started" and e.actor == "max"]
    return recognised, imitated


@pytest.fixture(scope="module", params=["left_front", "left_fist"])
def shown(request, tmp_path_factory):
    """Per speed factor, what Max recognised and imitated of the movement shown again at that speed."""
    folder = tmp_path_factory.mktemp("speed")

    def write(name, text):
        import textwrap

        path = folder / name
        path.write_text(textwrap.dedent(text).lstrip(), encoding="utf-8")
        return path

    world = _world(write, request.param)
    graphs = world.actors["max"].character.motor.graphs
    edges = sum(g.number_of_edges() for g in graphs.values())
    results = {}
    for speed in SPEEDS:
        results[speed] = _again(world, request.param, speed)
    return request.param, results, edges, sum(g.number_of_edges() for g in graphs.values())


@pytest.mark.parametrize("speed", SPEEDS)
def test_the_speed_of_a_familiar_movement_is_measured_within_ten_percent(shown, speed):
    movement, results, _, _ = shown
    recognised, imitated = results[speed]
    assert len(recognised) == 2  # out and back, each recognised (early: response facilitation)
    for match in recognised:
        assert "learned" not in match.details
        assert match.details["speed"] == pytest.approx(speed, rel=0.10), (movement, match.path)
    # each imitation is performed at the speed measured (re-parameterised, not learned again)
    assert [r.speed for r in imitated] == pytest.approx([m.details["speed"] for m in recognised])


def test_nothing_is_learned_at_any_speed(shown):
    _, _, before, after = shown
    assert after == before


def test_off_a_familiar_movement_at_another_speed_is_learned_as_new(write):
    """The paper's baseline (``reparameterise = false``): edges predict at the speed they were learned."""
    world = _world(write, "left_front", reparameterise=False)
    graph = world.actors["max"].character.motor.graphs["left_wrist"]
    edges = graph.number_of_edges()
    same, _ = _again(world, "left_front", 1.0)  # at the speed it was learned: recognised, as with it on
    assert [m.path for m in same] == [("left_wrist:e1",), ("left_wrist:e2",)]
    assert all("learned" not in m.details and m.details["speed"] == 1.0 for m in same)
    assert graph.number_of_edges() == edges
    fast, _ = _again(world, "left_front", 2.0)  # twice as fast: not predicted, learned anew
    assert len(fast) == 2 and all(m.details.get("learned") for m in fast)  # out and back, both new edges
    assert graph.number_of_edges() == edges + 2


def test_with_it_on_the_same_is_recognised(write):
    world = _world(write, "left_front")
    graph = world.actors["max"].character.motor.graphs["left_wrist"]
    edges = graph.number_of_edges()
    fast, _ = _again(world, "left_front", 2.0)
    assert [m.path for m in fast] == [("left_wrist:e1",), ("left_wrist:e2",)]
    assert graph.number_of_edges() == edges


@pytest.mark.parametrize("speed", SPEEDS)
def test_a_command_written_by_hand_is_timed_by_its_own_commands(write, pm, speed):
    """An edge with no demonstration of its own (``Edge.shown`` is None): the speed is measured against its
    commands; the demonstration is the command itself played ``speed`` times as fast."""
    character = load_character(write("arms.toml", ARMS), pm)
    motor = character.motor
    left, right = motor.rest[2], motor.rest[3]
    stroke = GuidingStroke(left, left + [0.3, 0.1, 0.1], 1.0, 0.4)
    out = motor.learn("wrists", "hub", [stroke, GuidingStroke(right, right, 1.0)])
    motor.learn("wrists", "hub", [GuidingStroke(left, left + [0.0, 0.3, 0.0], 1.0), GuidingStroke(right, right, 1.0)])
    assert motor.edge(out).shown is None
    path = stroke.retimed(1.0 / speed).trajectory(30.0)
    frames = np.repeat(motor.rest[None], len(path), axis=0)
    frames[:, 2] = path
    commit = next(a for a in feed(character.matcher, Motion(frames - motor.rest[0], 30.0, character.body.parts))
                  if a is not None)
    assert commit.path == (out,) and commit.details["speed"] == pytest.approx(speed, rel=0.10)


def test_a_faster_demonstration_is_recognised_at_its_speed(arms):
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0], duration=0.5))
    commit = next(a for a in feed(arms.matcher, demo) if a is not None)
    assert commit.path == (arms.out,) and commit.details["speed"] == pytest.approx(2.0, rel=0.10)
