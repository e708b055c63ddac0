"""§5.1: root-relative coordinates with the facing from the nose against the knees."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.root_frame import facing_heading, to_root_relative
from tests.conftest import CHARACTERS
from toolkit import load_character
from toolkit.motion import local_to_world


def _max(pm):
    return load_character(CHARACTERS / "max.toml", pm)


@settings(max_examples=50, deadline=None)
@given(heading=st.floats(-3.1, 3.1), x=st.floats(-5, 5), z=st.floats(-5, 5))
def test_heading_and_pose_are_recovered_from_world_positions(heading, x, z):
    from toolkit import create_plugin_manager

    c = _max(create_plugin_manager(autoload=False))
    local = c.motor.rest_pose()
    world = local_to_world(local, np.array([x, 0.0, z]), heading)
    visible = np.ones(len(local), bool)
    found = facing_heading(world, visible, c.body)
    assert abs(np.angle(np.exp(1j * (found - heading)))) < 1e-6
    pose, mask, root, h = to_root_relative(world, visible, c.body)
    np.testing.assert_allclose(pose, local - local[c.body.root_index], atol=1e-9)
    assert mask.all()


def test_forward_marker_resolves_swapped_knees(pm):
    c = _max(pm)
    local = c.motor.rest_pose().copy()
    li, ri = c.body.index("left_knee"), c.body.index("right_knee")
    local[[li, ri]] = local[[ri, li]]  # knees labelled the wrong way round: the nose still says where the front is
    assert abs(facing_heading(local, np.ones(len(local), bool), c.body)) < 1e-9


def test_hidden_knee_falls_back_to_root_and_nose(pm):
    c = _max(pm)
    world = local_to_world(c.motor.rest_pose(), np.zeros(3), 1.0)
    visible = np.ones(c.body.n_parts, bool)
    visible[c.body.index("left_knee")] = False
    assert abs(facing_heading(world, visible, c.body) - 1.0) < 1e-9


def test_nothing_to_go_by_gives_nan_and_hides_everything(pm):
    c = _max(pm)
    world = c.motor.rest_pose().copy()
    visible = np.ones(c.body.n_parts, bool)
    for part in ("left_knee", "nose"):
        visible[c.body.index(part)] = False
    pose, mask, root, heading = to_root_relative(world, visible, c.body)
    assert np.isnan(heading) and not mask.any() and np.isnan(pose).all()
    world[c.body.root_index] = np.nan  # the root itself is a bad value
    pose, mask, root, heading = to_root_relative(world, np.ones(c.body.n_parts, bool), c.body)
    assert not mask.any() and np.isnan(root).all()


def test_vectorised_over_frames(pm):
    c = _max(pm)
    motion = c.motor.perform("jump", fps=30)
    headings = np.linspace(-2, 2, motion.n_frames)
    world = local_to_world(motion.positions, np.zeros((motion.n_frames, 3)), headings)
    pose, mask, root, h = to_root_relative(world, motion.visible, c.body)
    np.testing.assert_allclose(h, headings, atol=1e-9)
    expected = motion.positions - motion.positions[:, c.body.root_index : c.body.root_index + 1]
    np.testing.assert_allclose(pose, expected, atol=1e-9)
