"""velocity-direction's onsets found by position (issue 36, K&G §4.1 on a noisy tracker), with the observer template's
settings: a movement slower than a tracker's jitter lets a line fit show is found where some part leaves the pose the
demonstrator rests in; a rest at a hub is one no part has left."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.segmenters.velocity_direction import VelocityDirection
from tests.fixtures.gesture_streams import bowing, hold, point, stream
from tests.plugins.segmenters.test_velocity_direction_streams import A, scores, walked_and_stepped


def slow_bow():
    """A bow over 8 s (the head at about 0.2 m/s at most, the chest slower: below the speed a tracker's jitter of
    1 cm makes a still part seem to move over a third of a second), held 0.5 s at the bottom; then a point."""
    return [("rest", [hold(A, 1.0)]), ("movement", bowing(A, seconds=8.0, hold_s=0.5)), ("rest", [hold(A, 1.0)]),
            ("movement", point(A)), ("rest", [hold(A, 1.0)])]


@pytest.mark.parametrize("tracker", [0.01, 0.02])
def test_a_bow_slower_than_the_jitter_lets_a_line_fit_show_is_found_by_position(tracker):
    """The slow bow under 1 and 2 cm of jitter: the speed never rises above the jitter's floor for long, but the
    head and chest leave the standing pose by tens of centimetres: both movements are found on every seed (the speed
    alone lost the bow on half the seeds at 1 cm and on all at 2 cm). Its slow turn at the bottom, held within the
    jitter's margin for longer than ``rest.settle``, may cut it in two: the F1 over the seeds is at least 0.8."""
    found = [scores(slow_bow(), tracker=tracker, seed=seed) for seed in range(8)]
    assert all(s["recall"] == 1.0 for s in found), [s["recall"] for s in found]
    assert np.mean([s["f1"] for s in found]) >= 0.8, [s["f1"] for s in found]
    assert scores(slow_bow())["f1"] == 1.0  # clean, the speed finds it


def test_without_the_rest_end_nothing_is_found_by_position():
    """The onset by position needs the demonstrator's rest (``end = "rest"``): with the paper's end (any rest ends a
    movement) the slow bow under 2 cm of jitter is lost to the jitter's floor, as it was before."""
    found = [scores(slow_bow(), tracker=0.02, seed=seed, end="still")["recall"] for seed in range(4)]
    assert max(found) < 1.0, found


@given(seed=st.integers(0, 10_000), cuts=st.lists(st.integers(1, 60), min_size=1, max_size=8),
       tracker=st.sampled_from([0.01, 0.02]))
@settings(max_examples=12, deadline=None)
def test_onsets_by_position_walked_are_their_frames_stepped(seed, cuts, tracker):
    """The slow bow under jitter, where movements begin by position: the block walked (only the frames where
    something can happen stepped; the frames where a part leaves the rest pose found for the block at once) closes
    the same segments at the same frames, reports the same onsets and leaves the same state as every frame stepped,
    whatever the packet sizes."""
    walked, stepped = walked_and_stepped(
        stream(slow_bow(), jitter=tracker, seed=seed)[0], cuts,
        lambda seg: (seg._departure.away, None if seg._departure.pose is None else seg._departure.pose.tolist(),
                     seg._frame))
    assert walked == stepped
