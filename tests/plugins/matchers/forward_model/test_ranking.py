"""The forward model's ranked candidates (:mod:`plugins.matchers.forward_model.ranking`; B&B Fig. 13, K&G §4.4's
candidates of Fig. 3).

``Match.candidates`` holds the movements the forward models considered in a segment with their prediction errors,
the answer first and the others best first; every movement is measured over the same frames (one that dropped out
is held at the error it dropped out with).
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.matchers.forward_model import Track
from tests.plugins.matchers.forward_model.helpers import demonstration, stroke_path
from tests.plugins.motor.test_edge_travel import PARTS, SIDE, _observer, _side_steps, clips  # noqa: F401
from toolkit import Motion
from toolkit.observe import Observer
from toolkit.watching import feed


def test_a_movement_that_dropped_out_is_held_at_the_error_it_dropped_out_with(clips):
    _, observer = _observer(clips)
    matcher = observer.matcher
    track = Track("body", 1.0, False, "hub", 0, {}, [])
    track.trace = [(0, {("a",): 1.0, ("b",): 2.0, ("c",): 0.5}), (1, {("a",): 1.0, ("a", "x"): 0.5, ("b",): 2.5}),
                   (2, {("a",): 3.0})]
    ranked = dict(matcher.ranking.ranked(track))
    assert ranked["a"] == pytest.approx((1.0 + 0.5 + 3.0) / 3)  # each frame its best path
    assert ranked["b"] == pytest.approx((2.0 + 2.5 + 2.5) / 3)
    assert ranked["c"] == pytest.approx(0.5)
    assert [m for m, _ in matcher.ranking.ranked(track)] == ["c", "a", "b"]
    answer = matcher.ranking.ranked(track, "movement a", ("a",))
    assert answer[0] == ("movement a", pytest.approx(1.5)) and [m for m, _ in answer[1:]] == ["c", "b"]


def test_an_unknown_answer_ranks_what_it_considered_and_still_names_the_nearest(clips):
    profile, observer = _observer(clips, threshold=0.001)  # the paper's drop-out, far too tight: nothing fits
    match = Observer(observer, profile.body, 30.0).classify(Motion(_side_steps(44, SIDE), 30.0, PARTS)).match
    assert not match.known and match.details["nearest"] in ("left", "right")
    errors = [e for _, e in match.candidates]
    assert errors == sorted(errors) and len(errors) == 3 and np.isfinite(errors).all()


def test_the_answer_comes_first_and_every_movement_considered_follows_by_error(arms):
    """Along ``out``: the commitment's candidates are ``out``'s movement (the answer), then ``up``, which predicted
    worse before it dropped out."""
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0]))
    commit = next(a for a in feed(arms.matcher, demo) if a is not None)
    names = [m for m, _ in commit.candidates]
    errors = [e for _, e in commit.candidates]
    assert names == [commit.movement, arms.up]
    assert errors == sorted(errors) and errors[0] < errors[1]
