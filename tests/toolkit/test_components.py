"""The values that flow between components: typed fields through which matchers and segmenters explain themselves."""

from __future__ import annotations

import pytest

from toolkit import Match, Segment
from toolkit.components import Behaviour, Matcher, MovementRequest


def test_an_unknown_answer_says_why_in_typed_fields():
    match = Match.unknown("too far from every path", nearest="bow", score=0.08, threshold=0.03,
                          measure="mean pose distance", details={"votes": {"bow": 3}})
    assert not match.known and match.confidence == 0.0 and match.decided_at is None
    assert (match.reason, match.nearest, match.score, match.threshold) == ("too far from every path", "bow", 0.08, 0.03)
    assert match.measure == "mean pose distance" and match.details == {"votes": {"bow": 3}}
    assert not match.stop


def test_a_plain_unknown_explains_nothing():
    match = Match.unknown()
    assert (match.reason, match.nearest, match.score, match.threshold, match.measure) == ("", None, None, None, "")
    assert match.details == {} and match.candidates == ()


def test_a_stop_is_a_typed_field_not_a_detail():
    assert Match("wave", stop=True, reason="deviation").stop
    assert not Match("wave", details={"stop": True}).stop


def test_a_segment_says_why_it_ends_when_its_segmenter_says():
    assert Segment(0, 10, 30.0).reason == ""
    segment = Segment(3, 10, 30.0, "back near a hub pose")
    assert segment.reason == "back near a hub pose" and segment.n_frames == 7
    with pytest.raises(ValueError):
        Segment(5, 5, 30.0, "empty")


def test_what_a_behaviour_taught_and_how_it_was_answered_are_typed():
    behaviour = Behaviour(True, "eat", learned={"ice_cream": "food"})
    assert behaviour.learned == {"ice_cream": "food"} and Behaviour(False).learned == {}
    assert MovementRequest("shrug", response="shrug").response == "shrug" and MovementRequest("jump").response == ""


def test_a_matcher_reports_no_details_unless_it_names_them():
    assert Matcher.report_details == ()
