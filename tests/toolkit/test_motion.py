"""The data model: motions, poses, bodies and the frame conventions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from toolkit import Body, ConfigError, Facing, Motion, Pose
from toolkit.motion import concatenate, facing_vector, local_to_world, world_to_local

PARTS = ("root", "a", "b")
finite = st.floats(-10, 10, allow_nan=False, allow_infinity=False)


def test_non_finite_coordinates_are_not_visible():
    pos = np.zeros((3, 3, 3))
    pos[1, 2, 0] = np.nan
    pos[2, 0, 1] = np.inf
    m = Motion(pos, 30, PARTS)
    assert m.visible.tolist() == [[True, True, True], [True, True, False], [False, True, True]]
    assert m.visible_fraction() == pytest.approx(7 / 9)


def test_given_mask_is_combined_with_finiteness():
    pos = np.zeros((2, 3, 3))
    pos[0, 0] = np.nan
    m = Motion(pos, 30, PARTS, visible=np.array([[True, False, True], [True, True, True]]))
    assert m.visible.tolist() == [[False, False, True], [True, True, True]]


def test_shape_errors_are_reported():
    with pytest.raises(ValueError, match=r"expected \(frames, 3, 3\)"):
        Motion(np.zeros((4, 2, 3)), 30, PARTS)
    with pytest.raises(ValueError, match="fps"):
        Motion(np.zeros((4, 3, 3)), 0, PARTS)
    with pytest.raises(ValueError, match="visible has shape"):
        Motion(np.zeros((4, 3, 3)), 30, PARTS, visible=np.ones((3, 3), bool))


def test_empty_and_one_frame_motions():
    empty = Motion(np.zeros((0, 3, 3)), 30, PARTS)
    assert empty.n_frames == 0 and empty.duration == 0 and empty.visible_fraction() == 0.0
    one = Motion(np.ones((1, 3, 3)), 30, PARTS)
    assert one.duration == pytest.approx(1 / 30)
    assert one.pose(0)["a"].tolist() == [1, 1, 1]


def test_root_relative_hides_frames_without_root():
    pos = np.arange(2 * 3 * 3, dtype=float).reshape(2, 3, 3)
    pos[1, 0] = np.nan
    rel = Motion(pos, 10, PARTS).root_relative("root")
    np.testing.assert_allclose(rel.positions[0, 0], 0)
    np.testing.assert_allclose(rel.positions[0, 2], pos[0, 2] - pos[0, 0])
    assert not rel.visible[1].any()


def test_slice_select_concatenate():
    pos = np.random.default_rng(0).normal(size=(10, 3, 3))
    m = Motion(pos, 25, PARTS)
    joined = concatenate([m.slice(0, 4), m.slice(4)])
    np.testing.assert_array_equal(joined.positions, pos)
    assert m.select(["b", "root"]).parts == ("b", "root")
    np.testing.assert_array_equal(m.select(["b"]).positions[:, 0], pos[:, 2])
    with pytest.raises(ValueError):
        concatenate([m, Motion(pos, 30, PARTS)])


@settings(max_examples=60, deadline=None)
@given(
    points=arrays(float, (4, 3), elements=finite),
    position=arrays(float, 3, elements=finite),
    heading=st.floats(-7, 7, allow_nan=False),
)
def test_world_local_round_trip(points, position, heading):
    world = local_to_world(points, position, heading)
    np.testing.assert_allclose(world_to_local(world, position, heading), points, atol=1e-9)
    # rotation keeps distances and the vertical axis
    np.testing.assert_allclose(np.linalg.norm(world - position, axis=1), np.linalg.norm(points, axis=1), atol=1e-9)
    np.testing.assert_allclose(world[:, 1] - position[1], points[:, 1], atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(
    points=arrays(float, (5, 2, 3), elements=finite),
    headings=arrays(float, 5, elements=st.floats(-4, 4)),
    positions=arrays(float, (5, 3), elements=finite),
)
def test_per_frame_placement_matches_single_frames(points, headings, positions):
    batch = local_to_world(points, positions, headings)
    for f in range(5):
        np.testing.assert_allclose(batch[f], local_to_world(points[f], positions[f], headings[f]), atol=1e-9)
    np.testing.assert_allclose(world_to_local(batch, positions, headings), points, atol=1e-9)


def test_heading_zero_faces_plus_z_and_left_is_plus_x():
    np.testing.assert_allclose(facing_vector(0.0), [0, 0, 1])
    # a point in front of and to the left of a character facing +x (heading 90 degrees)
    world = local_to_world(np.array([[1.0, 0.0, 2.0]]), np.zeros(3), np.pi / 2)
    np.testing.assert_allclose(world, [[2.0, 0.0, -1.0]], atol=1e-12)


def test_pose_checks_shape():
    with pytest.raises(ValueError):
        Pose(np.zeros((2, 3)), np.ones(2, bool), PARTS)


def test_body_lookups_and_errors():
    body = Body(PARTS, "root", Facing("a", "b"), bones=[("root", "a")], colours={"a": "#ff0000"})
    assert body.n_parts == 3 and body.root_index == 0
    assert body.indices(["b", "a"]).tolist() == [2, 1]
    assert body.bone_indices().tolist() == [[0, 1]]
    with pytest.raises(ConfigError, match=r"unknown body part 'z'.*available: root, a, b"):
        body.index("z")
    with pytest.raises(ConfigError, match="duplicate part names"):
        Body(("a", "a"), "a", Facing("a", "a"))
    with pytest.raises(ConfigError, match=r"key facing.left: unknown body part 'knee'"):
        Body(PARTS, "root", Facing("knee", "b"))


@pytest.mark.parametrize(
    "table, message",
    [
        ({"parts": "root", "root": "root", "facing": {}}, r"key parts: missing or invalid; expected a list of part names"),
        ({"parts": ["r"], "root": 3, "facing": {}}, r"key root: missing or invalid; expected the name of the root part"),
        ({"parts": ["r"], "root": "r", "facing": {"left": "r"}}, r"key facing.right: missing or invalid"),
        ({"parts": ["r"], "root": "r", "facing": {"left": "r", "right": "r", "up": "r"}}, r"key facing.up: unknown key 'up'"),
        ({"parts": ["r"], "root": "r", "facing": {"left": "r", "right": "r"}, "colours": {"r": "red"}}, r"key colours: invalid"),
        ({"parts": ["r"], "root": "r", "facing": {"left": "r", "right": "r"}, "bones": [["r"]]}, r"key bones: invalid"),
        ({"parts": ["r"], "root": "r", "facing": {"left": "r", "right": "r"}, "size": 1}, r"key size: unknown key 'size'.*available: bones, colours"),
    ],
)
def test_body_from_config_errors(table, message):
    with pytest.raises(ConfigError, match=message):
        Body.from_config(table)
