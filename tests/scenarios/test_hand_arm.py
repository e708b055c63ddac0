"""Kopp & Graeser 2006, §4.2 and Fig. 3: subsystems moving at once, and the way back to the last correct node.

The hand-arm games (``characters/scenarios/hand_arm_games.toml``): Moritz reaches forward while closing his left
hand, twice, then reaches with an open hand. Max follows the left wrist and the left hand each in its own motor
command graph and imitates both at once. Beside them: a deviation on the second edge of a known path (only the rest
is learned, from the node between the two) and the motor command graph's way back after an interrupted imitation.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from plugins.lib.guiding_stroke import GuidingStroke
from tests.conftest import CHARACTERS, play_recording_postures
from toolkit import Motion, create_plugin_manager, load_character
from toolkit.watching import feed

GAMES = CHARACTERS / "scenarios" / "hand_arm_games.toml"


def _play(path, **override):
    return play_recording_postures(path, "max", **override)


@pytest.fixture(scope="module")
def games():
    return _play(GAMES)


def _recognised(world):
    return world.events_of("movement_recognised", "max")


def _segments(world):
    max_ = world.actors["max"]
    return [(max_.watch_start + e.data["segment"].start, max_.watch_start + e.data["segment"].end)
            for e in world.events_of("segment_found", "max")]


def test_game_1_both_subsystems_are_learned_and_imitated_at_once(games):
    first, back = (e.data["match"] for e in _recognised(games)[:2])
    assert first.movement == "left_wrist:e1+left_hand:e2"
    assert first.details["learned"] == ["left_wrist:e1", "left_hand:e2"]
    assert first.details["subsystems"] == {"left_wrist": "left_wrist:e1", "left_hand": "left_hand:e2"}
    assert back.details["learned"] == ["left_wrist:e3", "left_hand:e4"]
    motor = games.actors["max"].character.motor
    assert motor.together[first.movement] == ["left_wrist:e1", "left_hand:e2"]
    # Max's wrist and fingers move in the same frames while he imitates the first movement
    max_ = games.actors["max"]
    started = next(e for e in games.events_of("imitation_started", "max"))
    poses = games.postures[started.frame - 1: started.frame + 40]
    wrist = np.linalg.norm(np.diff(poses[:, max_.body.index("left_wrist")], axis=0), axis=1)
    fingers = np.abs(np.diff(poses[:, motor.subsystems["left_hand"]], axis=0)).max(axis=(1, 2))
    moving = (wrist > 1e-4), (fingers > 1e-4)
    assert moving[0].sum() > 15 and moving[1].sum() > 15
    assert (moving[0] & moving[1]).sum() >= 0.8 * min(moving[0].sum(), moving[1].sum())


def test_game_2_both_are_predicted_and_imitated_together_before_moritz_has_finished(games):
    segments = _segments(games)
    for k in (2, 3):  # the reach and the way back
        event = _recognised(games)[k]
        match = event.data["match"]
        assert event.data["segment"] is None  # committed early
        assert set(match.details["subsystems"]) == {"left_wrist", "left_hand"}
        assert match.movement == "+".join(p for s in ("left_wrist", "left_hand") for p in match.details["subsystems"][s]["path"])
        assert 0.1 < match.decided_at / (segments[k][1] - segments[k][0]) < 0.6
        started = [e for e in games.events_of("imitation_started", "max") if segments[k][0] <= e.frame < segments[k][1]]
        assert started and started[0].data["request"].movement == match.movement


def test_game_3_only_the_wrist_moves_and_only_the_wrist_is_imitated(games):
    reach, back = (e.data["match"] for e in _recognised(games)[4:6])
    assert (reach.movement, back.movement) == ("left_wrist:e1", "left_wrist:e3")
    assert "subsystems" not in reach.details
    motor = games.actors["max"].character.motor
    assert motor.graphs["left_wrist"].number_of_edges() == 2 and motor.graphs["left_hand"].number_of_edges() == 2
    assert motor.active == {"left_wrist": "hub", "right_wrist": "hub", "left_hand": "hub", "right_hand": "hub"}
    idx = motor.subsystems["left_hand"]
    max_ = games.actors["max"]
    np.testing.assert_allclose(max_.local_pose()[idx], motor.rest[idx], atol=np.radians(5))  # his hand stayed open


def test_with_together_off_only_the_first_subsystem_to_move_is_followed():
    world = _play(GAMES, together=False)
    motor = world.actors["max"].character.motor
    assert motor.graphs["left_wrist"].number_of_edges() == 2
    assert motor.graphs["left_hand"].number_of_edges() == 0
    assert not motor.together


def test_movements_performed_together_are_saved_and_loaded(games, tmp_path):
    motor = games.actors["max"].character.motor
    path = tmp_path / "max.json"
    path.write_text(json.dumps(motor.get_state()))
    fresh = load_character("max_learner", create_plugin_manager(autoload=False)).motor
    fresh.set_state(json.loads(path.read_text()))
    assert fresh.together == motor.together
    name = next(iter(motor.together))
    assert name in fresh.movements()
    np.testing.assert_allclose(fresh.perform(name).positions, motor.perform(name).positions, atol=1e-5)
    for subsystem in ("left_wrist", "left_hand"):
        motor.move_to(subsystem, "hub")


def test_a_deviation_on_the_second_edge_of_a_path_learns_only_the_rest_from_the_node_between():
    character = load_character("max_learner", create_plugin_manager(autoload=False))
    motor, matcher, body = character.motor, character.matcher, character.body
    w = body.index("left_wrist")
    rest = motor.rest[w]
    a, b = rest + [0.0, 0.2, 0.12], rest + [0.0, 0.2, 0.12] + [0.22, 0.0, 0.0]
    first = motor.learn("left_wrist", "hub", [GuidingStroke(rest, a, 0.6)])
    second = motor.learn("left_wrist", motor.edge(first).target, [GuidingStroke(a, b, 0.6)])
    known = motor.add_sequence([first, second])
    middle = motor.edge(first).target
    # Moritz goes along the first edge, then up instead of out to the side
    fps = 30.0
    up = GuidingStroke(a, a + [0.0, 0.2, 0.0], 0.6)
    path = np.concatenate([GuidingStroke(rest, a, 0.6).trajectory(fps), up.trajectory(fps)[1:]])
    root = motor.rest[body.root_index]
    frames = np.repeat((motor.rest - root)[None], len(path), axis=0)
    frames[:, w] = path - root
    answers = list(feed(matcher, Motion(frames, fps, body.parts)))
    commit = next(m for m in answers if m is not None)
    assert commit.movement == known and commit.path == (first, second)
    stop = next(m for m in answers if m is not None and m.details.get("stop"))
    assert stop.details["return_to"] == middle and motor.active["left_wrist"] == middle
    learned = matcher.conclude(None)
    assert learned.details["from"] == middle and learned.details["deviated"]
    assert len(learned.details["learned"]) == 1
    new = learned.details["learned"][0]
    assert motor.edge(new).source == middle  # from the node between, not from the hub
    np.testing.assert_allclose(motor.edge(new).commands[0].target, a + [0.0, 0.2, 0.0], atol=0.02)
    assert [first, new] in motor.sequences.values()  # the right part and the new one, as one movement


def test_an_interrupted_motion_goes_back_to_the_motor_state_the_others_to_their_ends():
    motor = load_character("max_learner", create_plugin_manager(autoload=False)).motor
    body = motor.body
    w, hand = body.index("left_wrist"), motor.subsystems["left_hand"]
    rest = motor.rest
    reach = motor.learn("left_wrist", "hub", [GuidingStroke(rest[w], rest[w] + [0.0, 0.3, 0.2], 1.0)])
    fist = rest[hand] + np.radians([50.0, 60.0, 0.0])
    from plugins.lib.hand_transition import HandTransition

    close = motor.learn("left_hand", "hub", [HandTransition(np.stack([s, e]), np.array([0.0, 1.0]))
                                             for s, e in zip(rest[hand], fist)])
    both = motor.add_together([reach, close])
    motion = motor.perform(both)
    assert motor.active["left_wrist"] != "hub" and motor.active["left_hand"] != "hub"
    stopped = motion.positions[12]
    motor.move_to("left_wrist", "hub")  # the matcher found the wrist wrong: back to its last correct node
    back = motor.interrupt(12, stopped, fps=30.0)
    assert back.n_frames == 13
    np.testing.assert_allclose(back.positions[0], stopped)
    np.testing.assert_allclose(back.positions[-1, w], rest[w], atol=1e-9)  # the wrist is back in its hub
    np.testing.assert_allclose(back.positions[-1, hand], fist, atol=1e-9)  # the hand was right: it closes
    steps = np.linalg.norm(np.diff(back.positions[:, w], axis=0), axis=1)
    assert steps.argmax() in range(4, 9)  # bell-shaped: fastest in the middle
    assert motor.interrupt(0, back.positions[-1], fps=30.0) is None  # already there
