"""The forward model (Kopp & Graeser 2006, §4.4, Fig. 3) on a motor command graph small enough to work out by hand.

One subsystem, both wrists; two edges leave the hub: ``out`` moves the left wrist 30 cm to the side, ``up`` 30 cm
up, each a straight guiding stroke of one second (minimum-jerk profile); the right wrist holds still. A demonstration
that follows ``out`` has moved its left wrist ``d`` from the start after a path of length ``L ≈ d``: ``out``
predicts it exactly, ``up`` predicts the point ``L`` above the start, ``sqrt(L² + d²) ≈ d·√2`` away (the largest
over the two wrists). ``up`` drops out once that passes ``threshold`` (5 cm),
and ``out``, the one left, is committed to (response facilitation).
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.lib.guiding_stroke import GuidingStroke
from toolkit import Motion, load_character
from toolkit.watching import feed

ARMS = """
[character]
name = "Arms"

[body]
parts = ["root", "head", "left_wrist", "right_wrist"]
root = "root"
facing = { left = "left_wrist", right = "right_wrist", forward = "head" }

[motor]
plugin = "motor-command-graph"
rest = "rest"
subsystems = { wrists = ["left_wrist", "right_wrist"] }
hands = false
arms = []

[motor.poses.rest]
root = [0.0, 1.0, 0.0]
head = [0.0, 1.6, 0.1]
left_wrist = [0.25, 0.9, 0.05]
right_wrist = [-0.25, 0.9, 0.05]

[matcher]
plugin = "forward-model"
"""

FPS = 30.0
THRESHOLD = 0.05


@pytest.fixture
def arms(write, pm):
    character = load_character(write("arms.toml", ARMS), pm)
    motor = character.motor
    left, right = motor.rest[2], motor.rest[3]
    hold = GuidingStroke(right, right, 1.0)
    character.out = motor.learn("wrists", "hub", [GuidingStroke(left, left + [0.3, 0.0, 0.0], 1.0), hold])
    character.up = motor.learn("wrists", "hub", [GuidingStroke(left, left + [0.0, 0.3, 0.0], 1.0), hold])
    return character


def demonstration(character, left_path: np.ndarray) -> Motion:
    """The left wrist along ``left_path`` (n, 3) in the body frame, everything else at rest; root-relative."""
    rest = character.motor.rest
    frames = np.repeat(rest[None], len(left_path), axis=0)
    frames[:, 2] = left_path
    return Motion(frames - rest[0], FPS, character.body.parts)


def stroke_path(start: np.ndarray, chord, duration: float = 1.0) -> np.ndarray:
    return GuidingStroke(start, start + np.asarray(chord, dtype=float), duration).trajectory(FPS)


def test_the_candidates_errors_are_the_distance_of_each_prediction_from_what_is_seen(arms):
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0]))
    answers = list(feed(arms.matcher, demo))
    trace = arms.matcher.inspect()["trace"]
    moved = np.linalg.norm(demo.positions[:, 2] - demo.positions[0, 2], axis=1)
    checked = 0
    for frame, errors in trace:
        if (arms.out,) in errors:  # it predicts what it is shown (the observed path length is measured on positions
            assert errors[(arms.out,)] < 0.01  # averaged over three frames, a little short of the true one)
        if (arms.up,) in errors and moved[frame] > 0.01:
            assert errors[(arms.up,)] == pytest.approx(np.sqrt(2) * moved[frame], rel=0.1)
            checked += 1
    assert checked >= 3
    # up drops out on the first frame its error passes the threshold, and is not predicted after
    up = [(frame, errors[(arms.up,)]) for frame, errors in trace if (arms.up,) in errors]
    assert up[-1][1] > THRESHOLD and all(error <= THRESHOLD for _, error in up[:-1])
    # then out is the one left: committed at once, on that frame, at the speed it was shown
    commit = next(a for a in answers if a is not None)
    assert commit.path == (arms.out,) and commit.decided_at == up[-1][0] + 1
    assert commit.details["speed"] == pytest.approx(1.0, abs=0.1)
    assert commit.decided_at < 0.5 * demo.n_frames


def test_a_faster_demonstration_is_recognised_at_its_speed(arms):
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0], duration=0.5))
    commit = next(a for a in feed(arms.matcher, demo) if a is not None)
    assert commit.path == (arms.out,) and commit.details["speed"] == pytest.approx(2.0, rel=0.10)


def test_a_deviation_after_committing_stops_it_and_returns_to_the_last_correct_node(arms):
    """Out along the side for half the stroke, then up: committed to ``out``, then the prediction runs on to the side
    while the wrist goes up, and the imitation is stopped; the rest is learned from the hub."""
    first = stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0])[: int(0.5 * FPS)]
    then = stroke_path(first[-1], [0.0, 0.2, 0.0], duration=0.6)
    demo = demonstration(arms, np.concatenate([first, then[1:]]))
    answers = [a for a in feed(arms.matcher, demo) if a is not None]
    commit, stop = answers[0], next(a for a in answers if a.details.get("stop"))
    assert commit.path == (arms.out,) and not commit.details.get("stop")
    assert stop.details["return_to"] == "hub" and arms.motor.active_node("wrists") == "hub"
    learned = arms.matcher.conclude(demo)
    assert learned.details["deviated"] and learned.details["from"] == "hub"
    new = learned.details["learned"]
    assert arms.motor.edge(new[0]).source == "hub"
    np.testing.assert_allclose(arms.motor.edge(new[-1]).commands[0].target, demo.positions[-1, 2] + arms.motor.rest[0],
                               atol=0.02)


def test_a_movement_no_edge_predicts_is_learned_as_a_new_edge(arms):
    """Inwards and down, 135 degrees from both edges: both candidates drop on the same frame, nothing is committed,
    and the inverse model learns one stroke from the hub to a new node where the wrist stopped."""
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [-0.2, -0.2, 0.0]))
    assert all(a is None for a in feed(arms.matcher, demo))
    learned = arms.matcher.conclude(demo)
    assert learned.details["learned"] and learned.details["from"] == "hub" and not learned.details["deviated"]
    edge = arms.motor.edge(learned.details["learned"][-1])
    assert edge.target != "hub" and len(learned.details["learned"]) == 1
    np.testing.assert_allclose(edge.commands[0].target, arms.motor.rest[2] + [-0.2, -0.2, 0.0], atol=0.01)
    assert arms.motor.active_node("wrists") == edge.target


def test_a_candidate_drops_out_at_the_papers_threshold_whatever_the_others_do(arms):
    errors = {("a",): 0.001, ("b",): 0.045, ("c",): 0.055}
    assert arms.matcher._survivors(errors) == {("a",): 0.001, ("b",): 0.045}
    arms.matcher.params = {**arms.matcher.params, "threshold": 0.06}
    assert arms.matcher._survivors(errors) == errors


def test_a_demonstration_seen_at_rest_begins_at_the_hub_not_where_the_last_movement_ended(arms):
    """After ``out`` the wrists' subsystem is in ``out``'s end node. A demonstration that begins at rest (the body
    went back without being followed) begins at the hub: a movement's end is off the hub by the movement, 30 cm
    here. Seen at ``out``'s end, it begins there."""
    motor = arms.motor
    end = motor.edge(arms.out).target
    rest = motor.rest[2]
    arms.matcher.params = {**arms.matcher.params, "learn": False}
    for start, expected in ((rest + [0.0, 0.02, 0.0], "hub"), (rest + [0.3, 0.02, 0.0], end)):
        motor.reset()
        motor.move_to("wrists", end)
        list(feed(arms.matcher, demonstration(arms, stroke_path(start, [0.0, 0.2, 0.0]))))
        assert arms.matcher.inspect()["start_node"] == expected
