"""plugins.lib.style: a movement's held posture and amplitude, measured over a segment or a take (issue 18)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.lib.style import extent, frequency, mean_posture, rescale, stillness, take_means


def test_the_mean_posture_is_each_parts_mean_over_the_frames_it_is_seen():
    poses = np.array([[[0.0, 0, 0], [1, 1, 1]], [[2.0, 0, 0], [9, 9, 9]], [[4.0, 0, 0], [3, 3, 3]]])
    visible = np.array([[True, True], [True, False], [True, True]])
    assert mean_posture(poses, visible) == pytest.approx(np.array([[2.0, 0, 0], [2, 2, 2]]))
    never = mean_posture(poses, np.array([[True, False]] * 3))
    assert np.isnan(never[1]).all() and never[0] == pytest.approx([2.0, 0, 0])


def test_the_extent_is_the_rms_distance_from_the_mean_posture_over_every_seen_frame_and_part():
    """One part still, one swinging 1 m either side: distances 0, 0, 1, 1, so the extent is sqrt(1/2)."""
    poses = np.array([[[0.0, 0, 0], [1.0, 0, 0]], [[0.0, 0, 0], [-1.0, 0, 0]]])
    assert extent(poses, np.ones((2, 2), bool)) == pytest.approx(np.sqrt(0.5))
    assert extent(poses, np.zeros((2, 2), bool)) == 0.0


def test_rescale_is_the_ratio_to_the_reference_within_the_limit():
    assert rescale(1.0, 1.5, 2.0) == pytest.approx(1.5)
    assert rescale(1.0, 10.0, 2.0) == 2.0
    assert rescale(10.0, 1.0, 2.0) == 0.5
    assert rescale(0.0, 1.0, 2.0) == 1.0 and rescale(1.0, np.nan, 2.0) == 1.0


def test_take_means_gives_each_node_its_takes_posture_and_a_hub_its_own_pose():
    poses = np.array([[[0.0, 0, 0]], [[1.0, 0, 0]], [[3.0, 0, 0]], [[7.0, 0, 0]]])
    posture, size = take_means(poses, [np.array([1, 2])])
    assert posture[:, 0, 0] == pytest.approx([0.0, 2.0, 2.0, 7.0])
    assert size == pytest.approx([0.0, 1.0, 1.0, 0.0])


poses = arrays(float, st.tuples(st.integers(2, 12), st.integers(1, 5), st.just(3)),
               elements=st.floats(-2, 2, allow_nan=False))


@settings(max_examples=50, deadline=None)
@given(poses, st.data())
def test_centred_poses_do_not_change_when_a_constant_offset_is_added_to_each_part(x, data):
    """A posture held through the whole segment (an offset per part) cancels once each part is centred on its mean."""
    offset = data.draw(arrays(float, (x.shape[1], 3), elements=st.floats(-1, 1, allow_nan=False)))
    visible = data.draw(arrays(bool, x.shape[:2]))
    mean, moved = mean_posture(x, visible), mean_posture(x + offset, visible)
    seen = visible.any(axis=0)
    assert np.allclose((x - mean)[:, seen], (x + offset - moved)[:, seen], atol=1e-9)
    assert extent(x + offset, visible) == pytest.approx(extent(x, visible), abs=1e-9)


@settings(max_examples=50, deadline=None)
@given(poses, st.floats(0.1, 10))
def test_the_extent_scales_with_the_movement_about_its_posture_and_rescaling_undoes_it(x, c):
    visible = np.ones(x.shape[:2], bool)
    mean = mean_posture(x, visible)
    big = mean + (x - mean) * c
    size = extent(x, visible)
    assert extent(big, visible) == pytest.approx(c * size, abs=1e-9)
    if 1e-2 < c * size < 1e2:  # the rescaled amplitude is the reference, whatever the amplitude, within the limit
        assert extent(big, visible) * rescale(extent(big, visible), 1.0, 100.0) == pytest.approx(1.0)


def test_stillness_is_one_minus_each_parts_movement_over_the_most_moving_parts():
    """Part 0 still, part 1 swinging 1 m either side, part 2 half as far: stillness 1, 0 and 1/2."""
    poses = np.array([[[0.0, 0, 0], [1.0, 0, 0], [0, 0.5, 0]], [[0.0, 0, 0], [-1.0, 0, 0], [0, -0.5, 0]]])
    assert stillness(poses, np.ones((2, 3), bool)) == pytest.approx([1.0, 0.0, 0.5])
    assert stillness(np.zeros((3, 2, 3)), np.ones((3, 2), bool)) == pytest.approx([1.0, 1.0])


@settings(max_examples=50, deadline=None)
@given(poses, st.floats(0.1, 10), st.data())
def test_stillness_does_not_change_with_a_held_offset_or_the_movements_size(x, c, data):
    offset = data.draw(arrays(float, (x.shape[1], 3), elements=st.floats(-1, 1, allow_nan=False)))
    visible = np.ones(x.shape[:2], bool)
    assume(extent(x, visible) > 1e-3)  # a movement, not rounding
    mean = mean_posture(x, visible)
    assert stillness(mean + (x - mean) * c + offset, visible) == pytest.approx(stillness(x, visible), abs=1e-6)


def test_the_frequency_is_the_rms_step_speed_over_the_extent():
    """One part steps 0, 1, 0, 1 (m) at 10 samples a second: every step is 1 m, 10 m/s; its extent about its mean
    (0.5) is 0.5 m, so 20 per second. A part seen at one end of a step only leaves that step out."""
    x = np.zeros((4, 1, 3))
    x[[1, 3], 0, 0] = 1.0
    assert frequency(x, np.ones((4, 1), bool), 10.0) == pytest.approx(20.0)
    assert frequency(np.zeros((4, 1, 3)), np.ones((4, 1), bool), 10.0) == 0.0  # nothing moves
    assert frequency(x[:1], np.ones((1, 1), bool), 10.0) == 0.0  # no step
    seen = np.array([[True], [True], [False], [True]])  # steps 0-1 only; extent over frames 0, 1, 3 (mean 2/3)
    assert frequency(x, seen, 10.0) == pytest.approx(10.0 / extent(x, seen))


@settings(max_examples=50, deadline=None)
@given(poses, st.floats(0.1, 10), st.data())
def test_the_frequency_does_not_change_with_the_size_or_a_held_posture_and_scales_with_the_rate(x, c, data):
    """The same movement larger or smaller about any posture, or from another held posture, has the same frequency;
    the same samples taken twice as often (the movement twice as fast) have twice the frequency."""
    assume(extent(x, np.ones(x.shape[:2], bool)) > 1e-3)
    offset = data.draw(arrays(float, (x.shape[1], 3), elements=st.floats(-1, 1, allow_nan=False)))
    visible = np.ones(x.shape[:2], bool)
    f = frequency(x, visible, 10.0)
    assert frequency(x * c + offset, visible, 10.0) == pytest.approx(f, rel=1e-9)
    assert frequency(x, visible, 20.0) == pytest.approx(2 * f, rel=1e-12)
