"""Hands (Kopp & Graeser 2006, §3, §4.1-4.3): fingers as joint angles, hand transitions, the hand motor command graphs,
segmentation at angular-velocity minima, and the hand games (a fist learned, recognised at another speed, a via posture)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.guiding_stroke import progress
from plugins.lib.hand_transition import HandTransition
from plugins.lib.inverse_model import transitions_from_segment
from plugins.motor.motor_command_graph import command_from_dict
from plugins.segmenters.velocity_direction import VelocityDirection
from tests.conftest import CHARACTERS
from toolkit import Body, ConfigError, create_plugin_manager, load_character, load_scenario

FPS = 30.0
FINGERS = ["left_thumb", "left_index", "left_middle", "left_ring", "left_little"]


@pytest.fixture(scope="module")
def pm():
    return create_plugin_manager(autoload=False)


@pytest.fixture(scope="module")
def games(pm):
    return load_scenario(CHARACTERS / "scenarios" / "hand_games.toml", pm).run()


# -- the body and its key poses ------------------------------------------------------------------------------------


def _body(**hands):
    table = {"parts": ["root", "l", "r", "left_wrist", "f1", "f2"], "root": "root", "facing": {"left": "l", "right": "r"},
             "hands": hands or {"left_hand": {"wrist": "left_wrist", "fingers": ["f1", "f2"]}}}
    return Body.from_config(table)


def test_a_hand_makes_its_fingers_angle_parts_carried_by_the_wrist():
    body = _body()
    assert body.angle_parts == ("f1", "f2")
    assert body.angle_mask.tolist() == [False, False, False, False, True, True]
    assert body.carriers.tolist() == [0, 1, 2, 3, 3, 3]


@pytest.mark.parametrize("hands, key", [
    ({"left_hand": {"wrist": "left_wrist", "fingers": ["f1", "nope"]}}, "hands.left_hand.fingers"),
    ({"left_hand": {"wrist": "elbow", "fingers": ["f1"]}}, "hands.left_hand.wrist"),
    ({"left_hand": {"wrist": "left_wrist", "fingers": ["left_wrist"]}}, "hands.left_hand.fingers"),
    ({"left_hand": {"wrist": "left_wrist"}}, "hands.left_hand"),
    ({"a": {"wrist": "left_wrist", "fingers": ["f1"]}, "b": {"wrist": "left_wrist", "fingers": ["f1"]}}, "hands.b.fingers"),
])
def test_a_bad_hand_names_its_key(hands, key):
    with pytest.raises(ConfigError) as err:
        _body(**hands)
    assert key in str(err.value)


def test_key_poses_give_finger_angles_in_degrees_and_shift_moves_positions_only(pm):
    moritz = load_character("moritz", pm)
    rest, fist = moritz.motor.key_poses["rest"], moritz.motor.key_poses["left_fist"]
    index = moritz.body.index("left_index")
    np.testing.assert_allclose(rest[index], np.radians([20.0, 25.0, 5.0]))
    np.testing.assert_allclose(fist[index], np.radians([85.0, 95.0, 0.0]))
    from plugins.motor.key_poses import parse_poses

    table = {"rest": {p: (v.tolist() if not moritz.body.angle_mask[i] else np.degrees(v).tolist())
                      for i, (p, v) in enumerate(zip(moritz.body.parts, rest))},
             "up": {"base": "rest", "shift": [0.0, 0.1, 0.0]}}
    poses = parse_poses(table, moritz.body)
    moved = np.abs(poses["up"] - poses["rest"]).max(axis=1) > 1e-9
    assert moved.tolist() == (~moritz.body.angle_mask).tolist()
    with pytest.raises(ConfigError, match="degrees"):
        parse_poses({"rest": {**table["rest"], "left_index": [1.0, 2.0]}}, moritz.body)


def test_a_subsystem_that_mixes_fingers_and_positions_is_refused(pm):
    with pytest.raises(ConfigError) as err:
        load_character("max_learner", pm, override={"motor": {"subsystems": {"mixed": ["left_wrist", "left_index"]}}})
    assert "subsystems.mixed" in str(err.value) and "fingers" in str(err.value)


# -- hand transitions and the inverse model ---------------------------------------------------------------------------


@st.composite
def transitions(draw):
    """A random transition whose key postures are seen on frames (the segmenter's break points are frames)."""
    m = draw(st.integers(2, 4))
    keys = np.array([[draw(st.floats(-0.3, 1.6)) for _ in range(3)] for _ in range(m)])
    frames = np.concatenate([[0], np.cumsum([draw(st.integers(9, 30)) for _ in range(m - 1)])])
    peak = draw(st.floats(0.3, 0.7))
    duration = frames[-1] / FPS
    times = duration * progress(frames / frames[-1], peak, 0.0)  # on the curve's clock
    return HandTransition(keys, times, peak), frames


@settings(max_examples=40, deadline=None)
@given(case=transitions())
def test_transition_to_trajectory_to_inverse_model_gives_the_transition_back(case):
    transition, frames = case
    angles = transition.trajectory(FPS)
    assert np.allclose(angles[0], transition.start) and np.allclose(angles[-1], transition.target)
    np.testing.assert_allclose(angles[frames], transition.keys, atol=1e-6)  # each key posture seen on its frame
    (back,) = transitions_from_segment(angles[:, None, :], FPS, frames[1:-1])
    np.testing.assert_allclose(back.keys, transition.keys, atol=1e-6)
    assert np.abs(back.trajectory(FPS) - angles).max() < 0.01  # radians
    assert command_from_dict(json.loads(json.dumps(back.to_dict()))) == back


@pytest.mark.filterwarnings("error")
def test_a_key_a_subnormal_angle_away_from_the_last_gives_a_finite_curve_without_a_warning():
    """Hypothesis draws angles such as 5e-324 rad; scipy's PCHIP overflows the reciprocal of that slope (to the right
    limit, a zero derivative) and warned. The curve is finite, passes through every key and stays monotone."""
    keys = np.array([[0.0, 0.0, 0.0], [5e-324, 0.0, 0.0], [1.0, 0.5, 0.0]])
    hand = HandTransition(keys, np.array([0.0, 0.3, 1.0]), 0.5)
    angles = hand.trajectory(FPS)
    assert np.isfinite(angles).all()
    np.testing.assert_array_equal(hand.curve(hand.times), keys)
    assert (np.diff(angles[:, 0]) >= -1e-12).all()  # monotone between monotone keys (rounding at 1e-324 aside)


def test_the_angular_velocity_is_bell_shaped_and_dips_at_a_via_posture_where_the_fingers_turn():
    straight = HandTransition(np.radians([[20, 25, 5], [85, 95, 0]]), np.array([0.0, 1.0]), 0.5)
    t = np.linspace(0.0, 1.0, 201)
    speed = np.linalg.norm(np.gradient(straight.position(t), t, axis=0), axis=1)
    assert speed[0] < 0.02 * speed.max() and speed[-1] < 0.02 * speed.max() and 95 <= np.argmax(speed) <= 105
    turning = HandTransition(np.radians([[20, 25, 5], [0, 0, 30], [85, 95, 0]]), np.array([0.0, 0.5, 1.0]), 0.5)
    speed = np.linalg.norm(np.gradient(turning.position(t), t, axis=0), axis=1)
    via = int(np.argmin(np.abs(turning.position(t) - turning.keys[1]).sum(axis=1)))
    assert speed[via] < 0.1 * speed.max() and 60 < via < 140  # the fingers open, stop, and close
    assert straight.retimed(2.0).position(1.0).tolist() == straight.position(0.5).tolist()


def test_the_segmenter_finds_the_via_posture_at_the_angular_velocity_minimum():
    keys = np.radians([[[20, 25, 5]] * 5, [[0, 0, 50], [0, 0, 15], [0, 0, 0], [0, 0, -12], [0, 0, -25]],
                       [[85, 95, 0]] * 5])  # open wide, then a fist
    frames = np.array([0, 18, 39])
    times = 1.3 * progress(frames / 39, 0.5, 0.0)
    hand = [HandTransition(keys[:, j], times, 0.5) for j in range(5)]
    angles = np.stack([h.trajectory(FPS) for h in hand], axis=1)  # (N, 5, 3); the open hand on frame 18
    rng = np.random.default_rng(3)
    noisy = angles + rng.normal(0.0, 0.003, angles.shape)
    segmenter = VelocityDirection()
    segmenter.reset([f"f{j}" for j in range(5)], FPS)
    breaks = segmenter.analyse(noisy.reshape(len(noisy), -1)).breaks
    assert len(breaks) == 1 and abs(breaks[0] - 18) <= 2
    back = transitions_from_segment(noisy, FPS, breaks)
    assert max(np.abs(b.trajectory(FPS)[: len(angles)] - angles[:, j]).max() for j, b in enumerate(back)) < 0.05


# -- perception ----------------------------------------------------------------------------------------------------


def test_finger_angles_pass_through_perception_seen_with_their_wrist(pm):
    from plugins.perception.motion_capture import MotionCapture

    moritz = load_character("moritz", pm)
    body = moritz.body
    pose = moritz.motor.rest_pose().copy()
    angles = body.angle_mask
    from toolkit.motion import local_to_world

    world = local_to_world(pose, np.array([1.0, 0.0, 2.0]), np.pi / 3)
    world[angles] = pose[angles]
    perception = MotionCapture()
    perception.reset(FPS)
    percept = perception.perceive_pose(world, None, body, 0.0)
    np.testing.assert_allclose(percept.pose[angles], pose[angles])
    assert percept.visible.all()
    hidden = world.copy()
    hidden[body.index("left_wrist")] = np.nan
    hidden[body.index("right_index")] = np.nan  # a bad finger value is not seen, never a crash
    perception.reset(FPS)
    percept = perception.perceive_pose(hidden, None, body, 0.0)
    unseen = {body.parts[i] for i in np.flatnonzero(~percept.visible)}
    assert unseen == {"left_wrist", *FINGERS, "right_index"}


def test_synthetic_vision_sees_the_fingers_of_a_hand_it_sees(pm):
    from toolkit import World

    world = World(fps=FPS, pm=pm)
    moritz = world.add_actor(load_character("moritz", pm), "moritz", (0.0, 0.0, 2.0), np.pi)
    max_ = world.add_actor(load_character("max_learner", pm, override={"perception": {"plugin": "synthetic-vision"}}),
                           "max", (0.0, 0.0, 0.0), 0.0)
    max_.character.perception.reset(world.fps)
    percept = max_.character.perception.perceive(max_, moritz, world)
    body = moritz.body
    wrists = {h.wrist: h.fingers for h in body.hands.values()}
    for wrist, fingers in wrists.items():
        idx = body.indices(fingers)
        assert (percept.visible[idx] == percept.visible[body.index(wrist)]).all()
        if percept.visible[body.index(wrist)]:
            np.testing.assert_allclose(percept.pose[idx], moritz.local_pose()[idx])
    assert percept.visible[body.index("left_wrist")]


# -- the hand games ------------------------------------------------------------------------------------------------


def _recognised(world):
    return [e.data["match"] for e in world.events_of("movement_recognised", "max")]


def _segments(world):
    max_ = world.actors["max"]
    return [(max_.watch_start + e.data["segment"].start, max_.watch_start + e.data["segment"].end)
            for e in world.events_of("segment_found", "max")]


def test_game_1_max_learns_the_fist_and_its_return_by_true_imitation(games):
    first, back = _recognised(games)[:2]
    assert first.details["learned"] == ["left_hand:e1"] and first.details["candidates"] == []
    assert (first.details["from"], first.details["to"]) == ("hub", "n1")
    assert back.details["learned"] == ["left_hand:e2"] and back.details["to"] == "hub"
    fist = games.actors["moritz"].character.motor.key_poses["left_fist"]
    motor = games.actors["max"].character.motor
    node = motor.graphs["left_hand"].nodes["n1"]["state"]
    assert np.abs(node - fist[motor.subsystems["left_hand"]]).max() < np.radians(5)  # the fist, within 5 degrees


def test_game_2_the_slower_fist_is_recognised_early_and_retimed_not_learned_again(games):
    recognised = games.events_of("movement_recognised", "max")
    segments = _segments(games)
    slow, back = recognised[2], recognised[3]
    assert slow.data["segment"] is None and slow.data["match"].movement == "left_hand:e1"
    assert slow.frame < segments[2][1]  # imitating before Moritz's hand is closed
    assert slow.data["match"].details["progress"] < 0.5
    assert slow.data["match"].details["speed"] < 0.9  # slower than the command he learned
    assert back.data["match"].movement == "left_hand:e2" and back.data["segment"] is None
    started = [e for e in games.events_of("imitation_started", "max") if segments[2][0] <= e.frame < segments[2][1]]
    assert started and started[0].data["request"].speed == pytest.approx(slow.data["match"].details["speed"])


def test_game_3_the_fist_fails_and_a_new_edge_with_a_via_posture_is_learned(games):
    grab = _recognised(games)[4]
    assert grab.details["candidates"] == ["left_hand:e1"]  # the fist predicted it at first
    assert grab.details["learned"] == ["left_hand:e3"] and (grab.details["from"], grab.details["to"]) == ("hub", "n1")
    motor = games.actors["max"].character.motor
    commands = motor.edge("left_hand:e3").commands
    assert len(commands) == 5 and all(len(c.keys) == 3 for c in commands)  # start, the via posture, the fist
    hook = games.actors["moritz"].character.motor.key_poses["left_hook"][motor.subsystems["left_hand"]]
    assert np.abs(np.stack([c.keys[1] for c in commands]) - hook).max() < np.radians(15)
    assert _recognised(games)[5].movement == "left_hand:e2"  # and the way back is the one he knows


def test_the_hand_graph_after_the_games_and_where_max_ends_up(games):
    motor = games.actors["max"].character.motor
    hand = motor.graphs["left_hand"]
    assert set(hand.nodes) == {"hub", "n1"}
    assert sorted((a, b) for a, b, _ in hand.edges) == [("hub", "n1"), ("hub", "n1"), ("n1", "hub")]
    assert all(g.number_of_edges() == 0 for name, g in motor.graphs.items() if name != "left_hand")
    assert motor.active["left_hand"] == "hub"
    max_ = games.actors["max"]
    idx = motor.subsystems["left_hand"]
    np.testing.assert_allclose(max_.local_pose()[idx], motor.rest[idx], atol=np.radians(5))
    performed = [r.movement for _, r in max_.performed]
    assert performed == ["left_hand:e1", "left_hand:e2", "left_hand:e1", "left_hand:e2", "left_hand:e3", "left_hand:e2"]


def test_learned_hand_commands_are_saved_and_loaded(games, pm, tmp_path):
    motor = games.actors["max"].character.motor
    active = dict(motor.active)
    path = tmp_path / "max.json"
    path.write_text(json.dumps(motor.get_state()))
    fresh = load_character("max_learner", pm).motor
    fresh.set_state(json.loads(path.read_text()))
    for name in ("left_hand:e1", "left_hand:e2", "left_hand:e3"):
        a, b = motor.edge(name), fresh.edge(name)
        assert (a.subsystem, a.source, a.target) == (b.subsystem, b.source, b.target)
        t = np.linspace(0.0, a.commands[0].duration, 17)
        for x, y in zip(a.commands, b.commands):
            np.testing.assert_allclose(x.position(t), y.position(t), atol=1e-5)
    # the games' world is shared by this module's tests and performing moves Max's hand to n1: put back as it was
    posture = motor._state.copy()
    try:
        assert fresh.perform("left_hand:e3").n_frames == motor.perform("left_hand:e3").n_frames
    finally:
        motor.active.update(active)
        motor._state = posture
    assert motor.active == active and motor.active["left_hand"] == "hub"  # what the graph test reads, in any order
