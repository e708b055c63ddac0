"""The comparisons matchers share (plugins.matchers.comparison): eq. 1 on poses, and shape, motion and carry."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.lib.pose_distance import pose_distance
from plugins.matchers.comparison import HORIZON, Frames, Motion, Poses, sequence_size

FPS = 30.0


def arm(hand: np.ndarray) -> np.ndarray:
    """A body of five parts (root, head, two knees, a hand), the hand at ``hand`` (n, 3), root-relative."""
    n = len(hand)
    body = np.array([[0.0, 0.0, 0.0], [0.0, 0.6, 0.1], [0.1, -0.5, 0.0], [-0.1, -0.5, 0.0], [0.3, 0.0, 0.0]])
    poses = np.repeat(body[None], n, axis=0)
    poses[:, 4] = hand
    return poses


def wave(n: int = 60, height: float = 0.4, cycles: float = 3.0) -> np.ndarray:
    """The hand held up at ``height`` and swung side to side ``cycles`` times."""
    t = np.linspace(0.0, 1.0, n)
    return np.stack([0.3 + 0.15 * np.sin(2 * np.pi * cycles * t), np.full(n, height), np.zeros(n)], axis=1)


def raise_(n: int = 60, top: float = 0.4) -> np.ndarray:
    """The hand lifted from the hip to ``top`` and lowered again."""
    t = np.linspace(0.0, 1.0, n)
    return np.stack([np.full(n, 0.3), top * np.sin(np.pi * t), np.zeros(n)], axis=1)


def seen(n: int, parts: int = 5) -> np.ndarray:
    return np.ones((n, parts), dtype=bool)


def mean_cost(comparison, a: np.ndarray, b: np.ndarray, size: float | None = None) -> float:
    """The mean cost of two sequences of the same length aligned frame by frame (``size``: the body size both are
    measured in; ``None``: each its own)."""
    fa = comparison.frames(a, seen(len(a)), FPS, size=size)
    fb = comparison.frames(b, seen(len(b)), FPS, size=size)
    return float(np.mean(np.diag(comparison.costs(fa, fb))))


@settings(max_examples=60)
@given(arrays(np.float64, (4, 5, 3), elements=st.floats(-2, 2)), arrays(np.float64, (6, 5, 3), elements=st.floats(-2, 2)),
       arrays(np.bool_, (4, 5)), arrays(np.bool_, (6, 5)))
def test_poses_costs_are_eq_1_over_the_parts_seen_in_both(a, b, va, vb):
    """Every pair of frames: eq. 1 (pose_distance) over the parts seen in both; no part in both: 0."""
    comparison = Poses()
    costs = comparison.costs(comparison.frames(a, va, FPS), comparison.frames(b, vb, FPS))
    for i in range(len(a)):
        for j in range(len(b)):
            both = va[i] & vb[j]
            expected = float(pose_distance(a[i], b[j], both)) if both.any() else 0.0
            assert costs[i, j] == pytest.approx(expected, abs=1e-12)


@settings(max_examples=60)
@given(arrays(np.float64, (5, 4, 6), elements=st.floats(-3, 3)), arrays(np.float64, (7, 4, 6), elements=st.floats(-3, 3)),
       arrays(np.bool_, (5, 4)), arrays(np.bool_, (7, 4)), arrays(np.float64, (5, 5), elements=st.floats(-2, 2)),
       arrays(np.float64, (7, 5), elements=st.floats(-2, 2)), arrays(np.bool_, (5,)), arrays(np.bool_, (7,)))
def test_motion_costs_are_the_root_mean_square_over_the_parts_seen_in_both(a, b, va, vb, ca, cb, ka, kb):
    """The matrix products give, for every pair, the root of the mean over the parts seen in both of each part's
    squared difference plus the carries' (where both are known), computed here pair by pair."""
    costs = Motion().costs(Frames(a, va, ca, ka), Frames(b, vb, cb, kb))
    for i in range(len(a)):
        for j in range(len(b)):
            both = va[i] & vb[j]
            carry = float(((ca[i] - cb[j]) ** 2).sum()) if ka[i] and kb[j] else 0.0
            parts = ((a[i] - b[j]) ** 2).sum(axis=1)[both] + carry
            expected = float(parts.mean()) if both.any() else 0.0
            # compared squared: the products' rounding (|a|^2 + |b|^2 - 2ab, about 1e-13 here) becomes about 3e-7
            # after the root where two frames nearly coincide
            assert costs[i, j] ** 2 == pytest.approx(expected, abs=1e-9)


def test_a_hand_held_higher_through_the_whole_movement_costs_nothing_more():
    """Shape is each part about its own mean over the sequence: a wave made 20 cm higher is the same wave (in one
    body size), where eq. 1 on positions sees the 20 cm at every frame."""
    low, high = arm(wave(height=0.3)), arm(wave(height=0.5))
    assert mean_cost(Motion(), low, high, size=0.5) == pytest.approx(0.0, abs=1e-9)
    assert mean_cost(Poses(), low, high) == pytest.approx(0.2 / 5)


def test_the_same_movement_by_a_larger_body_costs_nothing():
    """Lengths are in the sequence's own body size: a body 1.5 times larger making the same movement 1.5 times
    larger compares at zero."""
    poses = arm(wave())
    assert mean_cost(Motion(), poses, 1.5 * poses) == pytest.approx(0.0, abs=1e-9)
    assert sequence_size(1.5 * poses, seen(len(poses))) == pytest.approx(1.5 * sequence_size(poses, seen(len(poses))))


def test_a_wave_and_a_raise_at_the_same_height_differ_by_their_motion():
    """A wave with the hand held up and a raise to the same height: seen by motion (velocities), the wave's
    reversals differ from the raise's one rise and fall; a wave is nearer another wave of other speed and height
    than the raise."""
    motion = Motion()
    slow_low = arm(wave(n=90, height=0.35, cycles=3))
    fast_high = arm(wave(n=60, height=0.45, cycles=3))
    lift = arm(raise_(n=60, top=0.45))

    def nearest_mean(a, b):  # each frame of a to its nearest frame of b: a tempo-free summary
        fa, fb = motion.frames(a, seen(len(a)), FPS), motion.frames(b, seen(len(b)), FPS)
        return float(motion.costs(fa, fb).min(axis=1).mean())

    assert nearest_mean(slow_low, fast_high) < 0.5 * nearest_mean(slow_low, lift)


def test_motion_is_velocity_times_the_horizon_in_body_sizes():
    """A part moving at a steady 0.5 m/s along x: its motion feature is 0.5 * HORIZON over the body size."""
    n = 30
    hand = np.stack([0.3 + 0.5 * np.arange(n) / FPS, np.zeros(n), np.zeros(n)], axis=1)
    poses = arm(hand)
    frames = Motion().frames(poses, seen(n), FPS, size=0.5)
    assert frames.parts[n // 2, 4, 3:] == pytest.approx([0.5 * HORIZON / 0.5, 0.0, 0.0], abs=1e-9)
    assert frames.parts[n // 2, 0, 3:] == pytest.approx([0.0, 0.0, 0.0], abs=1e-9)


def test_a_turn_is_carried_by_every_part():
    """Two sequences alike in every part but one turning a quarter turn by its end: the carry's chord
    (cos - 1, sin) sets them apart, and more so at the end."""
    n = 30
    poses = arm(wave(n=n))
    travel = np.zeros((n, 3))
    straight = Motion().frames(poses, seen(n), FPS, travel=travel, heading=np.zeros(n))
    turning = Motion().frames(poses, seen(n), FPS, travel=travel, heading=np.linspace(0.0, np.pi / 2, n))
    costs = np.diag(Motion().costs(straight, turning))
    assert costs[0] == pytest.approx(0.0, abs=1e-12)
    assert costs[-1] == pytest.approx(np.sqrt(2.0), rel=1e-9)  # the chord of a quarter turn at one body size
    assert np.all(np.diff(costs) >= -1e-12)


def test_the_carry_counts_only_where_both_know_it():
    """Where one sequence does not know where its body goes (no world positions), the carry is left out."""
    n = 10
    poses = arm(wave(n=n))
    known = Motion().frames(poses, seen(n), FPS, travel=np.ones((n, 3)), heading=np.ones(n))
    unknown = Motion().frames(poses, seen(n), FPS)
    assert not unknown.carried.any()
    # the same poses: 0 up to the root of a rounding in |x|^2 + |y|^2 - 2 x.y (a few 1e-9 with OpenBLAS 0.3.31);
    # the carry counted would add its travel, a quarter of a second of a metre a second over the body size
    assert np.diag(Motion().costs(known, unknown)) == pytest.approx(np.zeros(n), abs=1e-7)


def test_standing_still_is_the_distance_to_no_motion_at_all():
    """still(): for motion, each frame's distance to every feature zero; a body that holds still has none."""
    n = 20
    still_body = arm(np.tile([0.3, 0.0, 0.0], (n, 1)))
    frames = Motion().frames(still_body, seen(n), FPS)
    assert Motion().still(frames) == pytest.approx(np.zeros(n), abs=1e-12)
    moving = Motion().frames(arm(wave(n=n)), seen(n), FPS)
    zero = Frames(np.zeros_like(moving.parts), moving.seen, np.zeros_like(moving.carry), moving.carried)
    assert Motion().still(moving) == pytest.approx(np.diag(Motion().costs(moving, zero)))


def test_poses_still_is_eq_1_to_the_mean_pose():
    poses = arm(wave(n=12))
    frames = Poses().frames(poses, seen(12), FPS)
    mean = poses.mean(axis=0)
    assert Poses().still(frames) == pytest.approx([float(pose_distance(p, mean, None)) for p in poses])


def test_hidden_parts_take_no_part_and_a_frame_with_nothing_seen_costs_nothing():
    poses = arm(wave(n=8))
    visible = seen(8)
    visible[:, 4] = False
    visible[3] = False
    frames = Motion().frames(poses, visible, FPS)
    other = Motion().frames(poses + 0.5, seen(8), FPS)
    costs = Motion().costs(frames, other)
    assert costs[3] == pytest.approx(np.zeros(8))
    assert np.isfinite(costs).all()


@settings(max_examples=60)
@given(n=st.integers(1, 12), parts=st.integers(1, 6), seed=st.integers(0, 2**16), hide=st.booleans())
def test_a_sequence_seen_throughout_has_the_size_of_its_masked_median(n, parts, seed, hide):
    """:func:`sequence_size` takes the plain median where every part is seen in every frame; the same number as the
    median over the frames each part is seen in (odd and even counts alike), and where parts are hidden the
    median is over the frames they are seen in."""
    from plugins.lib.body_size import body_scale

    rng = np.random.default_rng(seed)
    poses = rng.normal(size=(n, parts, 3))
    visible = rng.random((n, parts)) > 0.4 if hide else np.ones((n, parts), dtype=bool)
    expected = np.array([np.median(poses[visible[:, p], p], axis=0) if visible[:, p].any() else np.full(3, np.nan)
                         for p in range(parts)])
    assert sequence_size(poses, visible) == float(body_scale(expected))
