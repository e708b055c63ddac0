"""Matcher ``stroke-warping``: each part's strokes warped onto each example's (plugins.matchers.stroke_warping)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.matchers.reversals import parts_strokes
from plugins.matchers.stroke_warping import (
    PartStrokes,
    _warp_all,
    flat_strokes,
    shares,
    strokes_still,
    warp_strokes,
)
from tests.plugins.matchers.hands import HANDS, LOW_RAISE, holding, waving
from toolkit import ConfigError, load_character

FPS = 30.0
X, Y = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])


def _observer(write, pm, table: str = "", known: str = ""):
    return load_character(write("hands.toml", HANDS + known + f'\n[matcher]\nplugin = "stroke-warping"\n{table}'), pm)


def _performed(write, pm, movement: str, speed: float = 1.0):
    """``movement`` as the demonstrator performs it (it knows the observer's movements and a few more)."""
    poses = '\n[motor.poses.ahead]\nbase = "stand"\nhand = [0.3, 1.0, 0.6]\n'
    known = LOW_RAISE + holding("reach", "ahead") + waving("long_wave", 7)
    demonstrator = load_character(write("demonstrator.toml", HANDS + known + poses), pm)
    return demonstrator.motor.perform(movement, fps=FPS, speed=speed).root_relative(demonstrator.body.root)


@pytest.mark.parametrize(("movement", "speed", "answer"), [
    ("wave", 0.25, "wave"), ("wave", 2.0, "wave"), ("long_wave", 1.0, "wave"), ("low_raise", 1.0, "raise")])
def test_tempo_swings_and_the_held_place_do_not_decide_how_a_hand_moves(write, pm, movement, speed, answer):
    """A wave four times slower or twice as fast as the example (a swing in an eighth of a second: the smoothing
    takes faster ones away), a wave of seven swings against the example's four, a raise held where the wave is
    held: each is the movement the hand makes."""
    match = _observer(write, pm, 'decision = "nearest"\n').matcher.match(_performed(write, pm, movement, speed))
    assert match.movement == answer
    assert [name for name, _ in match.candidates][0] == answer


def test_a_new_movement_is_unknown_and_a_slow_known_one_is_not(write, pm):
    """Calibrated on one example of each of three movements (leave one movement out): a reach forward at the hip's
    height, which the observer does not know, is unknown, with its nearest movement and the threshold, below 1 (a
    movement that explains a demonstration no better than standing still is never known); the wave four times slower
    is known."""
    matcher = _observer(write, pm, known=LOW_RAISE).matcher
    reach = matcher.match(_performed(write, pm, "reach"))
    assert reach.movement is None and reach.threshold < min(reach.score, 1.0) and reach.nearest == "low_raise"
    slow = matcher.match(_performed(write, pm, "wave", 0.25))
    assert slow.movement == "wave" and slow.score <= slow.threshold


def test_a_nearest_decision_never_says_unknown(write, pm):
    assert _observer(write, pm, 'decision = "nearest"\n').matcher.match(_performed(write, pm, "reach")).movement


def test_bad_settings_are_clear_errors(write, pm):
    with pytest.raises(ConfigError, match="reversal"):
        _observer(write, pm, "reversal = 0.0\n")
    with pytest.raises(ConfigError, match="unknown body part 'wrist'"):
        _observer(write, pm, 'parts = ["wrist"]\n')
    with pytest.raises(ConfigError, match="decision"):
        _observer(write, pm, 'decision = "distance"\n')


def test_a_wave_half_the_size_makes_the_same_strokes():
    """The strokes are shares of the sequence's stroke length: a hand lifted half as high that swings half as wide
    makes the same strokes as the full wave, summing to a length of 1; a raise (up and down) is far from both."""
    t = np.arange(0.0, 3.0, 1.0 / FPS)
    lift = np.clip(t / 0.5, 0.0, 1.0) * np.clip((3.0 - t) / 0.5, 0.0, 1.0)
    swing = np.where((t > 0.7) & (t < 2.2), 0.3 * np.sin(2.0 * np.pi * 2.0 * (t - 0.7)), 0.0)
    wave = np.stack([swing, lift, np.zeros_like(t)], axis=1)
    features = PartStrokes(np.array([2]), 0, np.array([1, 2]), 0.05, 0.0)  # the hand; sized by the head and hand

    def body(k):  # the root at the origin, the head still, the hand's path k times as large
        return np.stack([0 * wave, 0 * wave + [0.0, 1.6, 0.0], [0.2, 0.8, 0.0] + k * wave], axis=1)
    full, half = (features.series(body(k), FPS) for k in (1.0, 0.5))
    assert len(full[0]) == len(half[0]) > 4 and strokes_still(full) == pytest.approx(1.0)
    np.testing.assert_allclose(half[0], full[0], atol=1e-12)
    raise_ = shares(parts_strokes(np.stack([0 * t, lift, 0 * t], axis=1)[:, None], FPS, 0.05))
    assert warp_strokes(full[0], half[0]) < 1e-12 and warp_strokes(full[0], raise_[0]) > 0.5
    assert shares([np.zeros((0, 3))])[0].shape == (0, 3)  # no stroke: nothing to share


def test_warping_by_hand():
    assert warp_strokes(np.array([X, -X]), np.zeros((0, 3))) == 2.0  # nothing explains a swing and its return
    assert warp_strokes(np.array([X, -X, X]), np.array([X, -X, X])) == 0.0
    assert warp_strokes(np.array([X / 2, X / 2]), np.array([X]), merge=2) == pytest.approx(0.0)  # a stroke cut in two
    assert warp_strokes(np.array([X / 2, X / 2]), np.array([X]), merge=1) == pytest.approx(1.0)
    assert warp_strokes(np.array([X, X, X]), np.array([X]), merge=1) == 0.0  # one stroke for several like it
    # a swing and its return merged lose their length: out and back for nothing
    assert warp_strokes(np.array([Y, X, -X, -Y]), np.array([Y, -Y]), merge=3) == pytest.approx(2.0)


strokes = arrays(np.float64, st.tuples(st.integers(1, 6), st.just(3)), elements=st.floats(-2, 2))


@settings(max_examples=80, deadline=None)
@given(strokes, strokes, st.integers(1, 3), st.floats(0.1, 10.0))
def test_warping_is_symmetric_zero_on_itself_and_scales(a, b, merge, scale):
    ab = warp_strokes(a, b, merge)
    assert ab >= 0.0 and warp_strokes(a, a, merge) == pytest.approx(0.0, abs=1e-9)
    assert warp_strokes(b, a, merge) == pytest.approx(ab, rel=1e-9, abs=1e-9)
    assert warp_strokes(a * scale, b * scale, merge) == pytest.approx(ab * scale, rel=1e-9, abs=1e-9)
    out = np.empty(1)  # the reference loop, uncompiled
    _warp_all(a, np.array([0, len(a)]), b, np.array([0, len(b)]), 1, merge, out)
    assert out[0] == pytest.approx(ab, rel=1e-12, abs=1e-12)


def test_every_template_at_once_is_each_part_warped_on_its_own():
    """The compiled pass against every template (the layout of :func:`flat_strokes`, a part with no strokes among them)
    gives, for each template, the sum over the parts of each part's warping."""
    rng = np.random.default_rng(4)

    def sequence():
        return [rng.normal(size=(int(rng.integers(0, 6)), 3)) for _ in range(3)]
    demo, templates = sequence(), [sequence() for _ in range(5)]
    flat, starts = flat_strokes([demo])
    all_flat, all_starts = flat_strokes(templates)
    out = np.empty(5)
    _warp_all(flat, starts, all_flat, all_starts, 3, 2, out)
    expected = [sum(warp_strokes(a, b, 2) for a, b in zip(demo, template)) for template in templates]
    np.testing.assert_allclose(out, expected, rtol=1e-12)
