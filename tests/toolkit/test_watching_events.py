"""The watching loop gives a streaming matcher the rows between two eventful frames at once
(toolkit.watching._eventful): the frames where a segment closes or the onset changes, and the frame before each,
are visited one by one; between two of them the onset does not change."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from toolkit.watching import _eventful


def test_the_frames_around_closes_and_onset_changes_and_the_ends():
    onsets = [-1, -1, 2, 2, 2, 2, 2, 2, -1, -1, 10, 10]
    assert _eventful([(8, "segment")], onsets, 12) == [0, 1, 2, 7, 8, 9, 10, 11]
    assert _eventful([], [5] * 6, 6) == [0, 5]
    assert _eventful([(0, "s")], [-1], 1) == [0]


@given(st.lists(st.integers(-1, 3), min_size=1, max_size=60), st.data())
def test_between_two_eventful_frames_nothing_happens(onsets, data):
    n = len(onsets)
    closes = sorted(data.draw(st.sets(st.integers(0, n - 1), max_size=5)))
    frames = _eventful([(i, None) for i in closes], onsets, n)
    assert frames[0] == 0 and frames[-1] == n - 1 and frames == sorted(set(frames))
    for a, b in zip(frames, frames[1:]):
        skipped = range(a + 1, b)
        assert not any(i in closes or i + 1 in closes for i in skipped)  # a close and the frame before it visited
        assert all(onsets[i] == onsets[b] for i in skipped)  # the skipped rows are followed with b's onset
