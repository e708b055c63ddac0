"""Timed key poses and the keyframe motor system."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.motor.key_poses import interpolate
from tests.conftest import CHARACTERS
from toolkit import load_character


@settings(max_examples=40, deadline=None)
@given(
    keys=arrays(float, (4, 2, 3), elements=st.floats(-1, 1, allow_subnormal=False)),
    steps=st.lists(st.integers(1, 20), min_size=3, max_size=3),
)
def test_interpolation_passes_through_every_key_and_never_overshoots(keys, steps):
    fps = 30.0
    frames = np.concatenate([[0], np.cumsum(steps)])
    times = frames / fps
    motion = interpolate(keys, times, ("a", "b"), fps=fps)
    assert motion.n_frames == frames[-1] + 1
    np.testing.assert_allclose(motion.positions[frames], keys, atol=1e-9)
    lo, hi = keys.min(axis=0), keys.max(axis=0)
    assert np.all(motion.positions >= lo - 1e-9) and np.all(motion.positions <= hi + 1e-9)


def test_speed_changes_the_number_of_frames_not_the_path(pm):
    max_ = load_character(CHARACTERS / "max.toml", pm)
    slow = max_.motor.perform("jump", fps=30)
    fast = max_.motor.perform("jump", fps=30, speed=2.0)
    assert abs(fast.n_frames - (slow.n_frames - 1) / 2 - 1) <= 1
    np.testing.assert_allclose(fast.positions[0], slow.positions[0])
    np.testing.assert_allclose(fast.positions[-1], slow.positions[-1])


def test_every_movement_starts_and_ends_in_the_rest_pose(pm):
    for name in ("max", "morris"):
        c = load_character(CHARACTERS / f"{name}.toml", pm)
        rest = c.motor.rest_pose()
        for movement in c.motor.movements():
            m = c.motor.perform(movement, fps=30)
            np.testing.assert_allclose(m.positions[0], rest, atol=1e-12, err_msg=f"{name} {movement}")
            np.testing.assert_allclose(m.positions[-1], rest, atol=1e-12, err_msg=f"{name} {movement}")
            assert m.visible.all()


def test_jump_lifts_the_root(pm):
    max_ = load_character(CHARACTERS / "max.toml", pm)
    jump = max_.motor.perform("jump", fps=30)
    root = max_.body.root_index
    assert jump.positions[:, root, 1].max() > max_.motor.rest_pose()[root, 1] + 0.2
