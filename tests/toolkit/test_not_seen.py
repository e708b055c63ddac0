"""Parts not seen (NaN, hidden, never seen yet) are not visible, never a crash (the project's rule for bad frames).

A part a segmenter or matcher watches may be missing when a movement begins: never seen until the middle of it,
hidden and held where it was last seen, NaN in a raw row, or not seen at all. Each segmenter and the dtw matcher
treats it as not visible.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.strokes import StrokeCriteria, analyse, held
from plugins.segmenters.velocity_direction import VelocityDirection
from tests.conftest import CHARACTERS
from tests.toolkit.test_robustness import stream as morris_stream
from tests.plugins.segmenters.test_velocity_direction import stroke_sequence
from toolkit import Motion, Segment, create_plugin_manager, load_character
from toolkit.motion import fill_hidden

PARTS = ("root", "wrist", "hand")


def three_parts(seed: int, n_strokes: int = 3):
    """Stroke sequences of the wrist with a hand that follows it 10 cm to the side: poses (F, 3, 3), the truth."""
    rng = np.random.default_rng(seed)
    motion, truth = stroke_sequence(rng, n_strokes, noise=0.002)
    poses = np.concatenate([motion.positions, motion.positions[:, 1:] + [0.1, 0.0, 0.0]], axis=1)
    return poses, truth, motion.fps


def streamed(poses, visible):
    """Poses as the watching loop hands them to a segmenter: hidden parts held where last seen
    (:func:`toolkit.motion.fill_hidden`), NaN before they were first seen (the future is not known yet)."""
    out = fill_hidden(poses, visible)
    out[np.cumsum(visible, axis=0) == 0] = np.nan
    return out


def assert_valid(segments, n_frames):
    """Segments ordered, disjoint, non-empty and inside a stream of ``n_frames`` frames."""
    for s in segments:
        assert 0 <= s.start < s.end <= n_frames
    for a, b in zip(segments, segments[1:]):
        assert a.end <= b.start


def pushed(seg, poses, visible, fps):
    seg.reset(PARTS, fps)
    return [s for f in range(len(poses)) for s in seg.push(poses[f], visible[f])] + seg.flush()


def blocked(seg, poses, visible, fps, cuts):
    seg.reset(PARTS, fps)
    got, at = [], 0
    for n in [*cuts, len(poses)]:
        closed, since = seg.push_block(poses[at : at + n], visible[at : at + n])
        assert len(since) == len(poses[at : at + n])
        got.extend(s for _, s in closed)
        at += n
        if at >= len(poses):
            break
    return got + seg.flush()


def test_a_part_first_seen_in_the_middle_of_a_movement_is_no_crash():
    """The regression: the hand, watched, is first seen ten frames into the first movement. Its working memory
    began with NaN rows and ``savgol_filter`` raised ``ValueError: array must not contain infs or NaNs``."""
    poses, truth, fps = three_parts(3)
    visible = np.ones(poses.shape[:2], dtype=bool)
    visible[: truth[0][0] + 10, 2] = False
    poses = streamed(poses, visible)
    assert np.isnan(poses[truth[0][0] + 5, 2]).all()
    for params in ({}, {"smooth": 0.2, "min_stroke": 0.1}, {"level": "movement"}):
        segments = pushed(VelocityDirection(**params), poses, visible, fps)
        assert segments and abs(segments[0].start - truth[0][0]) <= 3  # the wrist still shows the onset
        assert_valid(segments, len(poses))
        assert blocked(VelocityDirection(**params), poses, visible, fps, [7, 30]) == segments


def test_a_part_never_seen_adds_nothing():
    """A chosen part never seen gives the segments of the other parts alone."""
    poses, truth, fps = three_parts(11)
    visible = np.ones(poses.shape[:2], dtype=bool)
    visible[:, 2] = False
    poses = streamed(poses, visible)
    watched = pushed(VelocityDirection(parts=["wrist", "hand"]), poses, visible, fps)
    alone = pushed(VelocityDirection(parts=["wrist"]), poses, visible, fps)
    assert watched == alone and len(alone) >= len(truth)


def test_the_stroke_analysis_holds_what_it_does_not_see():
    """``analyse`` of a window with NaN is ``analyse`` of the window held as the conventions hold hidden parts; a
    window of numbers is analysed as it is."""
    poses, truth, fps = three_parts(5)
    window = poses[truth[0][0] - 3 : truth[-1][1] + 3, 1:].reshape(-1, 6)
    assert held(window) is window or np.array_equal(held(window), window)
    gappy = window.copy()
    gappy[:20, 3:] = np.nan  # the hand not seen yet
    gappy[40:45, :3] = np.nan  # the wrist lost (raw NaN rows, not held)
    filled = held(gappy)
    assert np.array_equal(filled[:20, 3:], np.repeat(window[20:21, 3:], 20, axis=0))
    assert np.array_equal(filled[40:45, :3], np.repeat(window[39:40, :3], 5, axis=0))
    assert np.isfinite(filled).all()
    assert analyse(gappy, fps, StrokeCriteria()).breaks == analyse(filled, fps, StrokeCriteria()).breaks
    assert held(np.full((6, 3), np.nan)).tolist() == np.zeros((6, 3)).tolist()
    assert analyse(np.full((30, 6), np.nan), fps).breaks == []


@st.composite
def masks(draw):
    """A stream (poses, visible, fps) with random visibility: each part first seen at a random frame (or never),
    hidden for random runs (held where last seen), and raw NaN rows (bad frames, not held)."""
    seed = draw(st.integers(0, 10_000))
    poses, _, fps = three_parts(seed, draw(st.integers(1, 3)))
    n = len(poses)
    visible = np.ones((n, len(PARTS)), dtype=bool)
    for p in range(len(PARTS)):
        first = draw(st.one_of(st.just(0), st.integers(0, n), st.just(n)))  # n: never seen
        visible[:first, p] = False
        for _ in range(draw(st.integers(0, 3))):
            a = draw(st.integers(0, n - 1))
            visible[a : a + draw(st.integers(1, 40)), p] = False
    poses = streamed(poses, visible)
    for _ in range(draw(st.integers(0, 3))):  # bad frames: NaN or infinite, as they came
        a = draw(st.integers(0, n - 1))
        rows = slice(a, a + draw(st.integers(1, 10)))
        poses[rows, draw(st.integers(0, len(PARTS) - 1))] = draw(st.sampled_from([np.nan, np.inf]))
        visible[rows] = False
    return poses, visible, fps


@given(stream=masks(), cuts=st.lists(st.integers(1, 40), min_size=1, max_size=8),
       params=st.sampled_from([{}, {"parts": ["wrist", "hand"]}, {"level": "movement"},
                               {"units": "body", "noise": 2.0, "pause": 0.3}, {"max_movement": 1.0}]))
@settings(max_examples=60, deadline=None)
def test_random_visibility_is_no_crash_and_gives_valid_segments(stream, cuts, params):
    """Whatever is seen when: push and push_block raise nothing, give the same segments, and the segments are
    ordered, disjoint and inside the stream."""
    poses, visible, fps = stream
    one = pushed(VelocityDirection(**params), poses, visible, fps)
    assert_valid(one, len(poses))
    assert blocked(VelocityDirection(**params), poses, visible, fps, cuts) == one


# -- every segmenter and the dtw matcher: parts not seen when a movement begins

SEGMENTERS = ("hub-threshold", "ruptures", "velocity-direction")
BEGINNINGS = ("hidden", "nan-marked-visible", "inf-marked-visible", "never-seen", "nothing-seen")


@pytest.fixture(scope="module")
def watchers():
    pm = create_plugin_manager(autoload=False)
    morris = load_character(CHARACTERS / "morris.toml", pm)
    max_ = {s: load_character(CHARACTERS / "max.toml", pm, override={"segmenter": {"plugin": s}, "matcher": {"plugin": "dtw"}})
            for s in SEGMENTERS}
    return morris, max_


def begun_unseen(positions, case):
    """Morris's stream with parts not seen as its first movement begins (frame 20; 15 frames): held-NaN hidden
    hands and feet, NaN or infinite values marked visible (a raw bad frame), parts never seen, or nothing seen."""
    poses, visible = positions.copy(), np.ones(positions.shape[:2], dtype=bool)
    hands = slice(5, None)
    if case == "hidden":
        poses[:35, hands], visible[:35, hands] = np.nan, False
    elif case == "nan-marked-visible":
        poses[:35, hands] = np.nan
    elif case == "inf-marked-visible":
        poses[18:25, 3] = np.inf
    elif case == "never-seen":
        poses[:, 2:6], visible[:, 2:6] = np.nan, False
    else:
        poses[18:30], visible[18:30] = np.nan, False
    return poses, visible


@pytest.mark.parametrize("case", BEGINNINGS)
@pytest.mark.parametrize("segmenter", SEGMENTERS)
def test_parts_not_seen_as_a_movement_begins_are_not_visible(watchers, segmenter, case):
    """No exception; push frame by frame and push_block agree; the segments are valid and the same as with the bad
    values marked not visible; dtw matches each segment (and a slice that begins with nothing seen) with one of
    the observer's movements or none."""
    morris, max_ = watchers
    character = max_[segmenter]
    poses, visible = begun_unseen(morris_stream(morris, ["wave", "jump", "sit"], 1), case)
    parts = morris.body.parts

    def segments(poses, visible):
        seg = character.segmenter
        seg.reset(parts, 30.0)
        one = [s for f in range(len(poses)) for s in seg.push(poses[f], visible[f])] + seg.flush()
        seg.reset(parts, 30.0)
        closed, _ = seg.push_block(poses, visible)
        assert [s for _, s in closed] + seg.flush() == one
        return one

    found = segments(poses, visible)
    assert_valid(found, len(poses))
    bad = ~np.isfinite(poses).all(axis=2)
    assert segments(np.where(bad[..., None], np.nan, poses), visible & ~bad) == found
    if segmenter == "hub-threshold" and case != "never-seen":
        assert len(found) == 3  # the wave, the jump and the sitting down, whatever was missed as the wave began
    for s in [*found, Segment(0, 40, 30.0)]:
        match = character.matcher.match(Motion(poses[s.start : s.end], 30.0, parts, visible[s.start : s.end]))
        assert match.movement is None or match.movement in character.motor.movements()
        assert 0.0 <= match.confidence <= 1.0
