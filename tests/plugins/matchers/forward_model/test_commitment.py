"""Commitment, deviation and prediction again from the last correct node (:mod:`plugins.matchers.forward_model.
commitment`; K&G §4.4, Fig. 3).

A demonstration that begins like ``out`` and then goes up: committed to ``out``, the imitation stopped when they part,
the subsystem back at the last correct node (the hub) and the rest learned from there. After a deviation the rows seen
since the last correct node are followed again by a new track; that replay follows the track incrementally (its rows
gathered once each, its path lengths kept), and gives the answers and traces of the replay that gathers the rows and
sums their path lengths whole at every row, on Fig. 3's games.
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.matchers.forward_model.observation import Observation
from tests.plugins.matchers.forward_model.helpers import FPS, both_ways, demonstration, play_fig3_games, stroke_path
from toolkit.watching import feed


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


def _play(monkeypatch, incremental: bool):
    used = []
    leading = Observation.leading

    def counted(self, memory):
        answer = leading(self, memory) if incremental else False
        used.append(answer)
        return answer

    monkeypatch.setattr(Observation, "leading", counted)

    matches, seen = play_fig3_games(lambda view: (view["frames"], view["trace"], view["committed"],
                                                  view["committed_path"], view["committed_at"], view["deviated_at"]))
    return matches, seen, used


@pytest.fixture(scope="module")
def plays():
    return both_ways(_play)  # incremental, then whole


def test_the_replay_follows_the_new_track_incrementally(plays):
    (_, _, used), _ = plays
    assert any(used)  # replayed rows were a leading view of the working memory, kept and walked


def test_the_incremental_replay_gives_the_same_answers_and_traces_to_the_bit(plays):
    (matches, seen, _), (matches_whole, seen_whole, _) = plays
    assert any(m[4].find("deviated") >= 0 for m in matches)  # a deviation was predicted again
    assert matches == matches_whole
    assert seen == seen_whole
