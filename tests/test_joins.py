"""Takes joined through a rest (plugins.bench.joins): the rest rule, the placement, the transition, the join."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from plugins.bench.fuzz import _hand_bvh
from plugins.bench.joins import at_rest, join, minimum_jerk, placed, transition
from toolkit.bvh import parse_bvh


def take(held: int = 10):
    """The fuzzer's small hand-written take (12 frames of movement), its first and last frames held ``held``
    frames."""
    bvh = parse_bvh(_hand_bvh())
    bvh.values = np.concatenate([np.repeat(bvh.values[:1], held, axis=0), bvh.values,
                                 np.repeat(bvh.values[-1:], held, axis=0)])
    return bvh


def test_minimum_jerk_goes_from_none_to_all_symmetrically():
    s = minimum_jerk(9)
    assert np.all(np.diff(s) > 0) and 0 < s[0] < 0.05 and 0.95 < s[-1] < 1
    assert np.allclose(s + s[::-1], 1.0)
    assert len(minimum_jerk(0)) == 0


def test_a_take_held_at_both_ends_is_at_rest_and_one_in_motion_is_not():
    assert at_rest(take(10))
    assert not at_rest(take(0))  # 12 frames: too short to look at 0.3 s at each end
    moving = take(10)
    moving.values[:10, 0] = np.linspace(0.0, 30.0, 10)  # the root slides... (centroid-relative: no change)
    assert at_rest(moving)
    moving.values[:10, 14] = np.linspace(0.0, 40.0, 10)  # ...but an arm that turns (its Z rotation) is not at rest
    assert not at_rest(moving)


@given(st.floats(-3.0, 3.0), st.floats(-100.0, 100.0), st.floats(-100.0, 100.0))
def test_a_take_is_placed_where_the_last_pose_stands_and_facing_its_way(yaw, dx, dz):
    from scipy.spatial.transform import Rotation

    bvh = take(2)
    pose = bvh.positions()[0]
    centre = pose.mean(axis=0) * [1, 0, 1]
    after = Rotation.from_euler("y", yaw).apply(pose - centre) + centre + [dx, 0.0, dz]  # the same pose, elsewhere
    values = placed(bvh, bvh.values, after)
    moved = bvh.__class__(bvh.joints, bvh.frame_time, values).positions()
    assert np.allclose(moved[0], after, atol=1e-6)
    # the whole take moved rigidly: distances between joints are kept in every frame
    d = lambda x: np.linalg.norm(x[:, :, None] - x[:, None], axis=-1)  # noqa: E731
    assert np.allclose(d(moved), d(bvh.positions()), atol=1e-6)


def test_the_transition_goes_straight_from_one_pose_to_the_other():
    bvh = take(2)
    start, end = bvh.values[0], bvh.values[-1].copy()
    end[0] += 50.0  # and the root 50 units along x
    frames = transition(bvh, start, end, 15)
    poses = bvh.__class__(bvh.joints, bvh.frame_time, np.concatenate([start[None], frames, end[None]])).positions()
    centroid = poses.mean(axis=1)
    share = np.concatenate([[0.0], minimum_jerk(15), [1.0]])
    assert np.allclose(centroid, centroid[0] + share[:, None] * (centroid[-1] - centroid[0]), atol=1e-6)
    step = np.linalg.norm(np.diff(poses, axis=0), axis=-1).max(axis=1)
    assert step.max() < 0.25 * np.linalg.norm(poses[-1] - poses[0], axis=-1).max()  # no jump on the way


def test_a_join_holds_the_last_pose_moves_and_holds_the_next_first_pose():
    a, b = take(10), take(10)
    b.values[:, 6:] += 5.0  # another stance: every joint's rotation 5 degrees more
    values, rows = join([a, b], ["one", "two"], [(4, 6)], [9], lead=3, tail=2)
    assert rows == [(3, 3 + a.n_frames, "one"), (3 + a.n_frames + 19, 3 + a.n_frames + 19 + b.n_frames, "two")]
    assert len(values) == rows[-1][1] + 2
    assert np.array_equal(values[rows[0][0]:rows[0][1]], a.values)
    assert np.array_equal(values[: 3], np.repeat(a.values[:1], 3, axis=0))
    held = values[rows[0][1] : rows[0][1] + 4]
    assert np.array_equal(held, np.repeat(a.values[-1:], 4, axis=0))
    second = values[rows[1][0] : rows[1][1]]
    assert np.array_equal(values[rows[1][0] - 6 : rows[1][0]], np.repeat(second[:1], 6, axis=0))
    assert np.allclose(second[:, 6:], b.values[:, 6:], atol=1e-6) or not np.allclose(second[:, 6:], a.values[:, 6:])


def test_a_root_without_six_channels_cannot_be_placed():
    from toolkit import ConfigError
    from toolkit.bvh import BVH, Joint

    bvh = BVH([Joint("hips", -1, (0.0, 0.0, 0.0), ("Xrotation", "Yrotation", "Zrotation")),
               Joint("end", 0, (0.0, 1.0, 0.0), (), True)], 1 / 30, np.zeros((3, 3)), "flat.bvh")
    with pytest.raises(ConfigError, match="flat.bvh.*three position and three rotation"):
        placed(bvh, bvh.values, np.zeros((2, 3)))
