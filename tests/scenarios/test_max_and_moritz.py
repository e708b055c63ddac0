"""Kopp & Graeser 2006, §5: the three imitation games between Max and Moritz, and the forward model's properties."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CHARACTERS, play_recording_postures
from toolkit import create_plugin_manager, load_character


@pytest.fixture(scope="module")
def games():
    return play_recording_postures(CHARACTERS / "scenarios" / "imitation_games.toml")


def _segments(world):
    max_ = world.actors["max"]
    return [(max_.watch_start + e.data["segment"].start, max_.watch_start + e.data["segment"].end)
            for e in world.events_of("segment_found", "max")]


def test_six_demonstrated_movements_are_found(games):
    assert len(_segments(games)) == 6  # out and back, three times


def test_game_1_true_imitation_of_the_movement_and_its_return(games):
    recognised = games.events_of("movement_recognised", "max")
    first, back = recognised[0].data["match"], recognised[1].data["match"]
    assert first.details["learned"] == ["left_wrist:e1"] and first.details["from"] == "hub" and first.details["to"] == "n1"
    assert first.details["candidates"] == []  # Max knew nothing yet
    assert back.details["learned"] == ["left_wrist:e2"] and back.details["to"] == "hub"
    performed = [r.movement for _, r in games.actors["max"].performed]
    assert performed[:2] == ["left_wrist:e1", "left_wrist:e2"]  # he carries out what he learned


def test_game_2_facilitated_until_it_deviates_then_learns_the_new_branch(games):
    recognised = games.events_of("movement_recognised", "max")
    segments = _segments(games)
    early = recognised[2]
    assert early.data["segment"] is None and early.data["match"].movement == "left_wrist:e1"
    assert early.data["match"].details["candidates"] == ["left_wrist:e1"]
    assert early.frame < segments[2][1]  # he started imitating before Moritz finished
    stopped = [e for e in games.events_of("imitation_stopped", "max") if e.data["reason"] == "deviation"]
    assert len(stopped) == 1 and segments[2][0] < stopped[0].frame < segments[2][1]
    branch = recognised[3].data["match"]
    assert branch.details["deviated"] and branch.details["from"] == "hub"  # back to the last correct node
    assert branch.details["learned"][0] == "left_wrist:e3"
    back = recognised[4].data["match"]
    assert back.details["to"] == "hub"


def test_after_the_deviation_max_moves_back_to_the_last_correct_node_before_imitating_the_branch(games):
    max_ = games.actors["max"]
    wrist = games.postures[:, max_.body.index("left_wrist")]
    hub = max_.character.motor.graphs["left_wrist"].nodes["hub"]["state"][0]
    # no jumps anywhere: he stops where he is and moves back, and every movement starts where he stands
    assert np.linalg.norm(np.diff(wrist, axis=0), axis=1).max() < 0.05
    stopped = next(e for e in games.events_of("imitation_stopped", "max") if e.data["reason"] == "deviation")
    assert 0.1 < stopped.data["returning"] < 1.5
    at_stop = wrist[stopped.frame - 1]
    assert np.linalg.norm(at_stop - hub) > 0.1  # he had gone some way along the wrong edge
    branch = next(e for e in games.events_of("imitation_started", "max") if e.frame > stopped.frame)
    assert branch.data["request"].movement == games.events_of("movement_recognised", "max")[3].data["match"].movement
    returned = stopped.frame + round(stopped.data["returning"] * games.fps)
    assert branch.frame >= returned  # the branch waits for the way back
    np.testing.assert_allclose(wrist[returned - 2], hub, atol=1e-6)  # he is at the hub, the last correct node
    way = wrist[stopped.frame - 1: returned - 1]
    assert np.all(np.diff(np.linalg.norm(way - hub, axis=1)) <= 1e-9)  # straight back, never farther away


def test_game_3_waits_between_two_candidates_then_imitates_at_once(games):
    recognised = games.events_of("movement_recognised", "max")
    segments = _segments(games)
    third = recognised[5]
    match = third.data["match"]
    assert third.data["segment"] is None  # committed before the segment ended
    assert match.details["candidates"] == ["left_wrist:e1", "left_wrist:e3"]
    assert match.path[0] == "left_wrist:e3"  # the front movement dropped out
    fraction = match.decided_at / (segments[4][1] - segments[4][0])
    assert 0.2 < fraction < 0.9
    started = [e for e in games.events_of("imitation_started", "max") if segments[4][0] <= e.frame < segments[4][1]]
    assert started, "the imitation starts while Moritz is still moving"
    assert recognised[6].data["segment"] is None  # the way back is known too: facilitated


def test_the_graph_after_the_games_and_where_max_ends_up(games):
    motor = games.actors["max"].character.motor
    left = motor.graphs["left_wrist"]
    assert set(left.nodes) == {"hub", "n1", "n2", "n3"}
    edges = sorted((a, b) for a, b, _ in left.edges)
    assert edges == [("hub", "n1"), ("hub", "n2"), ("n1", "hub"), ("n2", "n3"), ("n3", "hub")]
    assert motor.graphs["right_wrist"].number_of_edges() == 0
    assert motor.active == {"left_wrist": "hub", "right_wrist": "hub", "left_hand": "hub", "right_hand": "hub"}
    assert motor.graphs["left_hand"].number_of_edges() == 0  # Moritz's hands stayed relaxed
    # Max's wrist is back at rest, as Moritz's is
    max_ = games.actors["max"]
    np.testing.assert_allclose(max_.local_pose()[max_.body.index("left_wrist")], motor.rest[max_.body.index("left_wrist")], atol=0.05)


def test_a_familiar_movement_at_another_speed_is_recognised_not_learned_again(write):
    from tests.plugins.matchers.forward_model.test_speed import _world

    world = _world(write, "left_front")
    edges = world.actors["max"].character.motor.graphs["left_wrist"].number_of_edges()
    moritz = world.actors["moritz"]
    moritz.character.action.plan.append("left_front")  # again, twice as fast
    moritz.character.action.params = {**moritz.character.action.params, "speed": 2.0}
    world.run(6.0)
    assert world.actors["max"].character.motor.graphs["left_wrist"].number_of_edges() == edges
    fast = world.events_of("movement_recognised", "max")[-2].data["match"]
    assert fast.movement == "left_wrist:e1" and fast.details["speed"] == pytest.approx(2.0, rel=0.10)
    imitated = [e.data["request"] for e in world.events_of("imitation_started", "max") if e.data["request"].movement == fast.movement]
    assert imitated[-1].speed == pytest.approx(fast.details["speed"])  # re-parameterised in speed, not learned again


def test_learned_motor_commands_are_saved_and_loaded(games, tmp_path):
    from toolkit.state import load_state, save_state

    path = tmp_path / "max.json"
    save_state(games.actors["max"].character, path)
    pm = create_plugin_manager(autoload=False)
    fresh = load_character(CHARACTERS / "max_learner.toml", pm)
    load_state(fresh, path)
    assert fresh.motor.get_state() == games.actors["max"].character.motor.get_state()
    assert fresh.motor.sequences == games.actors["max"].character.motor.sequences
