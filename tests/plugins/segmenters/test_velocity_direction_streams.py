"""velocity-direction at movement level on hand-built streams of a person gesturing (issue 36), with the observer
template's settings (``characters/observers/recordings.toml``, ``[segmenters.velocity-direction]``): a stance change
between two gestures, a tracker's jitter of 1 cm at 30 frames/s, a gesture that holds a pose half-way, two gestures
with 0.3 s of rest between them; and the pieces it is made of (:mod:`plugins.segmenters.velocity_direction.speed`,
:mod:`plugins.segmenters.velocity_direction.rests`)."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.bench.metrics import segmentation_scores
from plugins.segmenters.velocity_direction import VelocityDirection
from plugins.segmenters.velocity_direction.rests import Rests, straight
from plugins.segmenters.velocity_direction.speed import Jitter, line_speeds, line_weights, speed_noise
from tests.conftest import CHARACTERS
from tests.plugins.segmenters.test_velocity_direction import _in_blocks, _Stepped
from tests.fixtures.gesture_streams import FPS, bowing, hold, move, point, reach, stance, stream, wave

TEMPLATE = tomllib.loads((CHARACTERS / "observers" / "recordings.toml").read_text())["segmenters"][
    "velocity-direction"]
"""What ``--segmenter velocity-direction`` gets from the observer template."""
A, B = stance("down"), stance("clasped", wide=0.15)  # two stances: arms hanging; hands clasped, feet wider


def scores(pieces, tracker=0.0, seed=0, size=1.0, **params):
    """Segmentation scores of the template (``params`` replacing some of its settings) on ``pieces`` with
    ``tracker`` metres of jitter."""
    motion, truth = stream(pieces, jitter=tracker, seed=seed, size=size)
    found = VelocityDirection(**{**TEMPLATE, **params}).segment(motion)
    return segmentation_scores([(s.start, s.end) for s in found], truth, tolerance=0.25 * FPS)


@given(seed=st.integers(0, 1000), rest=st.floats(0.3, 0.8), size=st.sampled_from([0.2, 1.0, 1.3]),
       jitter=st.sampled_from([0.0, 0.01]))
@settings(max_examples=12, deadline=None)
def test_a_stance_change_between_two_gestures(seed, rest, size, jitter):
    """A wave from one stance, a shift to another (hands clasped, feet wider) held ``rest`` seconds, a point from
    there: two movements, each within 0.25 s of where it begins and ends; the shift is no movement and the new stance
    swallows nothing after it. On a mouse-sized body (0.2) and a large one alike (body units)."""
    pieces = [("rest", [hold(A, 1.0)]), ("movement", wave(A)), ("rest", [hold(A, rest)]),
              ("shift", [move(A, B, 0.6)]), ("rest", [hold(B, rest)]), ("movement", point(B)),
              ("rest", [hold(B, rest)]), ("movement", wave(B)), ("rest", [hold(B, 1.0)])]
    s = scores(pieces, tracker=jitter * size, seed=seed, size=size)
    assert s["f1"] == 1.0 and s["within"] == 1.0, s


def test_the_papers_end_reports_the_shift_and_a_hold_away_from_rest_keeps_going_without_the_stance_rules():
    """The same stream with the paper's end (any rest ends a movement) reports the shift of stance as a movement."""
    pieces = [("rest", [hold(A, 1.0)]), ("movement", wave(A)), ("rest", [hold(A, 0.5)]),
              ("shift", [move(A, B, 0.6)]), ("rest", [hold(B, 0.5)]), ("movement", point(B)), ("rest", [hold(B, 1.0)])]
    assert scores(pieces, end="still")["precision"] == pytest.approx(2 / 3)
    assert scores(pieces)["f1"] == 1.0


@given(seed=st.integers(0, 1000))
@settings(max_examples=8, deadline=None)
def test_jitter_of_a_centimetre_at_30_frames_a_second(seed):
    """Four gestures between rests of 0.8 s, every part jittering by 1 cm (a Kinect's tracker): every movement
    found, within 0.25 s."""
    pieces = [("rest", [hold(A, 1.0)]), ("movement", wave(A)), ("rest", [hold(A, 0.8)]), ("movement", point(A)),
              ("rest", [hold(A, 0.8)]), ("movement", bowing(A)), ("rest", [hold(A, 0.8)]),
              ("movement", point(A, hold_s=0.5)), ("rest", [hold(A, 1.0)])]
    assert scores(pieces, tracker=0.01, seed=seed)["f1"] == 1.0
    assert scores(pieces, tracker=0.02, seed=seed)["f1"] >= 0.85  # twice that: still most of them


def test_the_line_fit_and_the_measured_jitter_are_what_hold_under_jitter():
    """The rest speed in body units alone (no ``noise``, ``window`` or ``jitter``) finds nothing at 1 cm of jitter
    (the jitter at rest is faster than it); the measured jitter alone (no ``noise``) finds every movement; at 5 cm the
    template without the line fit and the measured jitter falls apart, with them most movements are found."""
    pieces = [("rest", [hold(A, 1.0)])] + [p for _ in range(4) for p in (("movement", point(A)),
                                                                            ("rest", [hold(A, 0.8)]))]

    def f1(tracker, **params):
        return np.mean([scores(pieces, tracker=tracker, seed=seed, **params)["f1"] for seed in range(3)])

    assert f1(0.01, noise=0.0, window=0.0, jitter=0.0) < 0.5
    assert f1(0.01, noise=0.0) == 1.0
    assert f1(0.05, window=0.0, jitter=0.0) < 0.5
    assert f1(0.05) >= 0.8


@given(hold_s=st.floats(0.3, 1.5), seed=st.integers(0, 1000), jitter=st.sampled_from([0.0, 0.01]))
@settings(max_examples=12, deadline=None)
def test_a_gesture_that_holds_a_pose_half_way_is_one_movement(hold_s, seed, jitter):
    """A point held ``hold_s`` seconds and a bow held as long, each coming back to the rest: one movement each (the
    paper's end cuts each in two at its hold)."""
    pieces = [("rest", [hold(A, 1.0)]), ("movement", point(A, hold_s=hold_s)), ("rest", [hold(A, 0.8)]),
              ("movement", bowing(A, hold_s=hold_s)), ("rest", [hold(A, 1.0)])]
    s = scores(pieces, tracker=jitter, seed=seed)
    assert s["f1"] == 1.0 and s["within"] == 1.0, s
    assert scores(pieces, tracker=jitter, seed=seed, end="still")["precision"] <= 0.5


@given(gap=st.floats(0.3, 0.5), seed=st.integers(0, 1000), jitter=st.sampled_from([0.0, 0.01]))
@settings(max_examples=12, deadline=None)
def test_two_gestures_with_a_third_of_a_second_of_rest_between_them(gap, seed, jitter):
    """A wave, ``gap`` seconds (from 0.3) of rest, a point: two movements, not one."""
    pieces = [("rest", [hold(A, 1.0)]), ("movement", wave(A)), ("rest", [hold(A, gap)]), ("movement", point(A)),
              ("rest", [hold(A, 1.0)])]
    s = scores(pieces, tracker=jitter, seed=seed)
    assert s["f1"] == 1.0 and s["within"] == 1.0, s


# -- the pieces -------------------------------------------------------------------------------------------------


@given(st.integers(2, 40), st.floats(-5, 5), st.floats(-5, 5), st.floats(1, 240))
def test_the_line_weights_give_a_lines_slope(frames, slope, offset, fps):
    t = np.arange(frames) / fps
    assert float(line_weights(frames, fps) @ (offset + slope * t)) == pytest.approx(slope, abs=1e-9)


def test_line_speeds_take_the_fastest_part_and_skip_parts_not_seen():
    rows = np.zeros((6, 6))
    rows[:, 0] = np.arange(6) * 0.1  # part 1 along x at 0.1 a frame
    rows[:, 4] = np.arange(6) * 0.2  # part 2 along y at 0.2 a frame
    w = line_weights(3, 30.0)
    assert np.allclose(line_speeds(rows, w), 6.0)
    rows[2, 3:] = np.nan  # part 2 not seen once: the windows over frame 2 count part 1 alone
    assert np.allclose(line_speeds(rows, w), [3.0, 3.0, 3.0, 6.0])
    rows[:, :3] = np.nan
    assert np.isnan(line_speeds(rows, w)[:3]).all()


@pytest.mark.parametrize("sigma", [0.002, 0.01, 0.03])
def test_the_jitter_is_measured_whether_the_person_moves_or_not(sigma):
    """White noise of ``sigma`` on a part standing still and on one moving smoothly: measured within 15 %; and the
    speed it alone gives a part standing still is what :func:`speed_noise` says."""
    rng = np.random.default_rng(1)
    t = np.arange(600) / FPS
    still = np.zeros((600, 3))
    moving = np.stack([0.3 * np.sin(2 * t), 0.2 * np.cos(3 * t), 0.1 * t], axis=1)
    rows = np.concatenate([still, moving], axis=1) + rng.normal(0, sigma, (600, 6))
    jitter = Jitter(2, floor=300, every=15)
    assert jitter.update(rows)[-1] == pytest.approx(sigma, rel=0.15)
    w = line_weights(6, FPS)
    rms = np.sqrt(np.mean(line_speeds(rng.normal(0, sigma, (5000, 3)), w) ** 2))
    assert rms == pytest.approx(float(speed_noise(sigma, w)), rel=0.05)


def test_the_jitter_of_a_block_is_its_frames_one_by_one():
    rows = np.random.default_rng(2).normal(0, 0.01, (100, 6))
    one, blocks = Jitter(2, 40, 7), Jitter(2, 40, 7)
    expected = np.concatenate([one.update(rows[i : i + 1]) for i in range(100)])
    assert np.array_equal(np.concatenate([blocks.update(rows[a:b]) for a, b in ((0, 1), (1, 33), (33, 100))]),
                          expected)


def test_a_straight_shift_an_arc_and_a_gesture_out_and_back():
    t = np.linspace(0, 1, 30)[:, None]
    line = np.concatenate([t * [0.5, 0, 0], t * [0, 0.3, 0]], axis=1)  # two parts each on a straight line
    assert straight(line, 0.02)
    arc = np.concatenate([0.5 * np.hstack([np.sin(t * np.pi / 2), 1 - np.cos(t * np.pi / 2), 0 * t])] * 2, axis=1)
    assert straight(arc, 0.02)  # a quarter circle bows out by a fifth of its chord
    out_and_back = np.concatenate([np.sin(t * np.pi) * [0.5, 0, 0], 0 * line[:, 3:]], axis=1)
    assert not straight(out_and_back, 0.02)
    rests = Rests(radius=0.02)
    assert rests.shift(line) and not rests.shift(out_and_back) and not rests.shift(line[:1].repeat(5, axis=0))
    assert rests.leaves(out_and_back) and not rests.leaves(line[:3] * 0.1)


def test_hubs_holds_and_returns():
    rests = Rests(radius=0.05, stance=5)
    a, b = np.zeros(6), np.full(6, 0.5)
    rests.began(a, 0.05)
    assert rests.at_hub(a + 0.01) and not rests.at_hub(b)
    rests.hold(10, b)
    rests.left(20)
    window = np.concatenate([np.zeros((10, 6)), np.repeat(b[None], 10, 0), np.linspace(b, b + 0.4, 10),
                             np.linspace(b + 0.4, b, 10)])
    assert rests.returned(b + 0.01, 0, window) == 0
    assert rests.returned(b + 0.01, 0, window[:22]) is None  # not left yet: a hand fidgeting at the hold
    short = Rests(radius=0.05, stance=15)
    short.began(a, 0.05)
    short.hold(10, b)
    short.left(20)
    assert short.returned(b, 0, window) is None  # a pause shorter than a stance


def slow_gestures():
    """Four gestures performed three times slower than usual (a wave over 4.8 s, a bow over 4.2 s) between rests of
    0.8 s: their hands move at about a tenth of a metre a second, below what a tracker's jitter of 1 cm makes a still
    hand seem to move over a 0.2 s line fit."""
    return [("rest", [hold(A, 1.0)]), ("movement", wave(A, seconds=4.8)), ("rest", [hold(A, 0.8)]),
            ("movement", point(A, seconds=3.6)), ("rest", [hold(A, 0.8)]), ("movement", bowing(A, seconds=4.2)),
            ("rest", [hold(A, 0.8)]), ("movement", point(A, seconds=3.6, hold_s=0.5)), ("rest", [hold(A, 1.0)])]


@given(seed=st.integers(0, 1000))
@settings(max_examples=4, deadline=None)
def test_slow_gestures_under_a_centimetre_of_jitter_are_found_by_the_stretched_line_fit(seed):
    """Slow gestures at 1 cm of jitter at 30 frames/s: the template (``stretch``: the line fit lengthened to 1/3 s
    where the measured jitter hides the rest speed) finds every one; the 0.2 s fit alone (``stretch = 0``) loses
    some, the jitter's floor being above their hands' speed; clean, both find every one."""
    pieces = slow_gestures()
    assert scores(pieces, tracker=0.01, seed=seed)["f1"] == 1.0
    assert scores(pieces, tracker=0.0, seed=seed)["f1"] == 1.0
    assert scores(pieces, tracker=0.0, seed=seed, stretch=0.0)["f1"] == 1.0


def test_without_the_stretch_slow_gestures_are_cut_late_under_a_centimetre_of_jitter():
    """The same slow gestures with the 0.2 s line fit alone: the onset by position still finds each one, but where
    the jitter's floor hides their hands' speed, so their boundaries fall far from where they are (over eight seeds,
    fewer than a third within 0.25 s, against more than half with the stretch)."""
    def within(**params):
        return np.mean([scores(slow_gestures(), tracker=0.01, seed=seed, **params)["within"] for seed in range(8)])

    assert within(stretch=0.0) < 0.33 < 0.5 < within()


def test_longer_fits_double_up_to_the_stretch_and_lower_the_jitters_speed():
    """The line fit lengthened by doubling to ``stretch`` frames (then ``stretch`` itself), each with its middle's
    delay; none when ``stretch`` is no longer; each doubling lowers the jitter's speed by about 2^1.5."""
    from plugins.segmenters.velocity_direction.speed import longer_fits

    assert [(len(w), lag) for w, lag in longer_fits(6, 12, 30.0)] == [(12, 5)]
    assert [(len(w), lag) for w, lag in longer_fits(6, 30, 30.0)] == [(12, 5), (24, 11), (30, 14)]
    assert longer_fits(6, 6, 30.0) == [] and longer_fits(6, 0, 30.0) == []
    ratio = speed_noise(0.01, line_weights(6, 30.0)) / speed_noise(0.01, longer_fits(6, 12, 30.0)[0][0])
    assert ratio == pytest.approx(2**1.5, rel=0.1)


def slow_rise():
    """A reach forward, then the arm rising slowly for 3 s (the hand at about a tenth of a metre a second, below
    what a tracker's jitter of 2 cm lets a 1/3 s line fit tell from rest, for longer than ``rest.settle``), and
    back down; then a wave."""
    out, up = reach(A, "right", [-0.25, 0.45, 0.65]), reach(A, "right", [-0.25, 0.75, 0.55])
    return [("rest", [hold(A, 1.0)]), ("movement", [move(A, out, 0.6), move(out, up, 3.0), move(up, A, 0.6)]),
            ("rest", [hold(A, 1.0)]), ("movement", wave(A)), ("rest", [hold(A, 1.0)])]


def test_a_slow_rise_under_two_centimetres_of_jitter_is_no_rest():
    """The slow rise under 2 cm of jitter seems a rest to the line fit, but it drifts away from where it began (the
    hand farther than twice ``rest.radius``): no rest, so ``rest.settle`` does not end the movement there; it ends
    where the arm comes back down, within 0.25 s, on every seed. Clean, the same."""
    for seed in range(10):
        s = scores(slow_rise(), tracker=0.02, seed=seed)
        assert s["f1"] == 1.0 and s["within"] == 1.0, (seed, s)
    assert scores(slow_rise())["within"] == 1.0


def test_a_hold_that_drifts_is_still_no_longer():
    """``Rests.still``: a pose is still where the hold under way began until some part is farther than the radius
    from where it was there, or than the tracker's jitter allows (``near``) where that is larger; with no hold under
    way (none, or the last one left) every pose is."""
    rests = Rests(radius=0.05)
    pose = np.zeros(6)
    assert rests.still(pose + 1.0)  # no hold
    rests.hold(10, pose)
    assert rests.still(pose + np.array([0.0, 0.0, 0.0, 0.045, 0.0, 0.0]))  # one part 4.5 cm away: still there
    assert not rests.still(pose + np.array([0.0, 0.0, 0.0, 0.06, 0.0, 0.0]))  # 6 cm: drifted
    assert rests.still(pose + np.array([0.0, 0.0, 0.0, 0.06, 0.0, 0.0]), near=0.08)  # within the jitter's margin
    assert not rests.still(pose + np.array([0.0, 0.0, 0.0, 0.09, 0.0, 0.0]), near=0.08)
    assert rests.still(pose + np.array([np.nan, 0.0, 0.0, 0.01, 0.0, 0.0]))  # a part not seen is not counted
    rests.left(20)
    assert rests.still(pose + 1.0)  # the hold was left: nothing to drift from


def test_at_a_hub_no_part_has_left_it():
    """``Rests.at_hub``: near a hub on average (eq. 1's mean within the radius) and no part farther than twice the
    radius (or the jitter's margin, if larger): a hand 12 cm out with the other parts home has left the rest, though
    the mean over the parts is within the radius."""
    rests = Rests(radius=0.05)
    rests.began(np.zeros(12), 0.05)
    hand_out = np.zeros(12)
    hand_out[9] = 0.12  # one part of four 12 cm away: mean 3 cm
    assert rests.at_hub(np.full(12, 0.01))
    assert not rests.at_hub(hand_out)
    assert rests.at_hub(hand_out, near=0.15)  # a tracker that jitters that much cannot tell
    hidden = hand_out.copy()
    hidden[:3] = np.nan  # a part not seen is not counted
    assert not rests.at_hub(hidden)


@given(seed=st.integers(0, 1000), cuts=st.lists(st.integers(1, 60), min_size=1, max_size=8))
@settings(max_examples=8, deadline=None)
def test_a_drifting_hold_walked_is_its_frames_stepped(seed, cuts):
    """The slow rise under 2 cm of jitter, where holds drift and count again: the block walked (only the frames
    where something can happen stepped) closes the same segments at the same frames as every frame stepped,
    whatever the packet sizes."""
    walked, stepped = walked_and_stepped(stream(slow_rise(), jitter=0.02, seed=seed)[0], cuts,
                                         lambda seg: (seg._drift, seg._frame))
    assert walked == stepped
    assert walked[-1][0] > 0  # a hold drifted


def walked_and_stepped(motion, cuts, state):
    """The template on ``motion`` pushed in blocks of ``cuts`` frames, walked (:class:`VelocityDirection`) and with
    every frame stepped (:class:`_Stepped`): for each, the segments closed (with the frame that closed them), the
    onsets, what ``flush`` closes and ``state(segmenter)`` after it."""
    visible = np.isfinite(motion.positions[..., 0])
    results = []
    for kind in (VelocityDirection, _Stepped):
        seg = kind(**TEMPLATE)
        seg.reset(motion.parts, FPS)
        got, since = _in_blocks(seg, motion.positions, visible, cuts)
        results.append((got, since, seg.flush(), state(seg)))
    return results
