"""The subsystems followed (:mod:`plugins.matchers.forward_model.tracks`): the candidates' prediction errors, the
drop-out at ``threshold`` and the commitment to the one left (Kopp & Graeser 2006, §4.4, Fig. 3), on a motor command
graph small enough to work out by hand.

One subsystem, both wrists; two edges leave the hub: ``out`` moves the left wrist 30 cm to the side, ``up`` 30 cm
up, each a straight guiding stroke of one second (minimum-jerk profile); the right wrist holds still. A demonstration
that follows ``out`` has moved its left wrist ``d`` from the start after a path of length ``L ≈ d``: ``out``
predicts it exactly, ``up`` predicts the point ``L`` above the start, ``sqrt(L² + d²) ≈ d·√2`` away (the largest
over the two wrists). ``up`` drops out once that passes ``threshold`` (5 cm), and ``out``, the one left, is committed
to (response facilitation).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.plugins.matchers.forward_model.helpers import THRESHOLD, demonstration, stroke_path
from toolkit.watching import feed


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


def test_a_candidate_drops_out_at_the_papers_threshold_whatever_the_others_do(arms):
    errors = {("a",): 0.001, ("b",): 0.045, ("c",): 0.055}
    assert arms.matcher.tracking.survivors(errors) == {("a",): 0.001, ("b",): 0.045}
    arms.matcher.params = {**arms.matcher.params, "threshold": 0.06}
    assert arms.matcher.tracking.survivors(errors) == errors


def test_a_demonstration_seen_at_rest_begins_at_the_hub_not_where_the_last_movement_ended(arms):
    """After ``out`` the wrists' subsystem is in ``out``'s end node. A demonstration that begins at rest (the body
    went back without being followed) begins at the hub: a movement's end is off the hub by the movement, 30 cm
    here. Seen at ``out``'s end, it begins there."""
    motor = arms.motor
    end = motor.edge(arms.out).target
    rest = motor.rest[2]
    for start, expected in ((rest + [0.0, 0.02, 0.0], "hub"), (rest + [0.3, 0.02, 0.0], end)):
        motor.reset()
        motor.move_to("wrists", end)
        list(feed(arms.matcher, demonstration(arms, stroke_path(start, [0.0, 0.2, 0.0]))))
        assert arms.matcher.inspect()["start_node"] == expected
