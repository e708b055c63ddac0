"""§5.1's line across the body from several left/right pairs (the hips and the shoulders): each pair's across vector
counts by its length, so a tracker's jitter turns the combined line less than it turns the short pair alone."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.root_frame import RecordingFacing, across, facing_heading, root_relative
from toolkit.body import Body, Facing
from toolkit.motion import local_to_world

PARTS = ("root", "left_hip", "right_hip", "left_shoulder", "right_shoulder", "toes", "toe_tip")


def _body(pairs: int, *, forward: bool = True) -> Body:
    also = (("left_shoulder", "right_shoulder"),) if pairs == 2 else ()
    return Body(PARTS, "root", Facing("left_hip", "right_hip", "toe_tip" if forward else None,
                                      "toes" if forward else None, also))


def _standing(twist: float = 0.0) -> np.ndarray:
    """Hips 13 cm apart and shoulders 34 cm apart (the Bandai-Namco skeleton's widths), facing +z with the left at
    +x; the shoulders turned by ``twist`` radians about the spine (a punch), the toe tip 4 cm ahead of the toes."""
    c, s = np.cos(twist), np.sin(twist)
    return np.array([[0.0, 0.95, 0.0], [0.065, 0.95, 0.0], [-0.065, 0.95, 0.0],
                     [0.17 * c, 1.45, -0.17 * s], [-0.17 * c, 1.45, 0.17 * s], [0.1, 0.0, 0.08], [0.1, 0.0, 0.12]])


def _angle(a, b):
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


def test_the_combined_line_is_the_pairs_across_vectors_each_weighed_by_its_length():
    world = np.zeros((1, len(PARTS), 3))
    world[0, 1], world[0, 2] = [0.1, 1.0, 0.0], [0.0, 0.9, 0.0]  # hips: across (0.1, 0, 0), a step down ignored
    world[0, 3], world[0, 4] = [0.0, 1.5, 0.3], [0.0, 1.5, 0.0]  # shoulders: across (0, 0, 0.3)
    line, seen = across(world, np.ones((1, len(PARTS)), bool), _body(2))
    expected = (0.1 * np.array([0.1, 0.0, 0.0]) + 0.3 * np.array([0.0, 0.0, 0.3])) / 0.4
    np.testing.assert_allclose(line[0], expected)
    assert seen[0]
    # the heading is the line's horizontal perpendicular: the shoulders' 0.3 m count nine times the hips' 0.1 m
    heading = facing_heading(world, np.ones((1, len(PARTS)), bool), _body(2, forward=False))
    assert heading[0] == pytest.approx(np.arctan2(-expected[2], expected[0]))


def test_a_hidden_pair_is_left_out_and_no_pair_seen_is_no_facing():
    world = local_to_world(_standing(0.4), np.zeros(3), 0.0)[None].repeat(3, axis=0)
    visible = np.ones((3, len(PARTS)), bool)
    visible[0, 3] = False  # a shoulder hidden: the hips alone
    visible[1, 1] = False  # a hip hidden: the shoulders alone
    visible[2, [1, 4]] = False  # one of each: nothing across the body (and no forward marker without it)
    found = facing_heading(world, visible, _body(2, forward=False))
    assert found[0] == pytest.approx(facing_heading(world[0], visible[0], _body(1, forward=False)))
    assert found[1] == pytest.approx(0.4)  # the shoulders turned 0.4 rad to the left of the hips' facing
    assert np.isnan(found[2])


def test_one_pair_gives_the_same_bits_as_the_paper_s_knees():
    rng = np.random.default_rng(0)
    world = local_to_world(_standing(), np.array([1.0, 0.0, -2.0]), 0.3)[None] + rng.normal(0, 0.02, (200, 7, 3))
    visible = rng.random((200, 7)) > 0.1
    one = _body(1)
    line, seen = across(world, visible, one)
    np.testing.assert_array_equal(line, world[:, 1] - world[:, 2])
    np.testing.assert_array_equal(seen, visible[:, 1] & visible[:, 2])


@settings(max_examples=60, deadline=None)
@given(turn=st.floats(-np.pi, np.pi), start=st.floats(-np.pi, np.pi), twist=st.floats(-0.6, 0.6),
       x=st.floats(-5, 5), z=st.floats(-5, 5))
def test_a_rigid_body_turned_by_any_angle_turns_its_facing_by_that_angle(turn, start, twist, x, z):
    local = _standing(twist)
    visible = np.ones(len(PARTS), bool)
    body = _body(2)
    before = facing_heading(local_to_world(local, np.array([x, 0.0, z]), start), visible, body)
    after = facing_heading(local_to_world(local, np.array([z, 0.0, x]), start + turn), visible, body)
    assert _angle(after - before, turn) < 1e-9


def test_two_pairs_turn_less_under_a_tracker_s_jitter_than_the_hips_alone():
    """2 cm of jitter on every coordinate: the hips' 13 cm alone turn the facing by about 12 degrees a frame; with
    the shoulders' 34 cm beside them the error is about sqrt(0.13² / (0.13² + 0.34²)) = 0.36 of that (the
    inverse-variance weighing), and the running median over a second keeps the ratio."""
    rng = np.random.default_rng(7)
    heading = 2.5
    world = local_to_world(_standing(), np.array([0.5, 0.0, 1.0]), heading)[None] + rng.normal(0, 0.02, (3000, 7, 3))
    visible = np.ones((3000, len(PARTS)), bool)
    errors = {}
    for pairs in (1, 2):
        raw = facing_heading(world, visible, _body(pairs), RecordingFacing(30))
        smoothed = RecordingFacing(30).headings(raw)
        errors[pairs] = np.median(_angle(raw, heading)), np.median(_angle(smoothed, heading))
    assert np.degrees(errors[1][0]) > 8  # the hips alone: the jitter the issue measured
    assert errors[2][0] < 0.5 * errors[1][0] and errors[2][1] < 0.6 * errors[1][1]


def test_root_relative_poses_of_a_turning_body_with_two_pairs():
    """The transform with two pairs: a body turning in place is seen in its own frame, the hips' local positions
    recovered (the combined line is the rest pose's, turned)."""
    frames = 40
    local = _standing(0.2)
    headings = np.linspace(0.0, 3.0, frames)
    world = np.stack([local_to_world(local, np.zeros(3), h) for h in headings])
    pose, mask, _, found = root_relative(world, None, _body(2))
    rest = facing_heading(local, np.ones(len(PARTS), bool), _body(2))
    assert mask.all()
    assert _angle(found - headings, rest).max() < 1e-9
    np.testing.assert_allclose(pose[:, 1:3], pose[:1, 1:3].repeat(frames, axis=0), atol=1e-9)


def test_the_forward_marker_still_turns_a_mirrored_recording_round_with_two_pairs():
    local = _standing(0.1)
    mirrored = local * np.array([-1.0, 1.0, 1.0])  # a mirrored recording: its left on the right, the toe tip ahead
    found = facing_heading(mirrored, np.ones(len(PARTS), bool), _body(2))
    plain = facing_heading(local, np.ones(len(PARTS), bool), _body(2))
    assert _angle(found, -plain) < 1e-9  # mirrored in x: the facing the marker says, not the flipped line's
