"""§5.1: root-relative coordinates with the facing from the nose against the knees."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.root_frame import HeadingFilter, facing_heading, smooth_heading, to_root_relative
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


def _marker_body(forward_offset):
    """Hips 13 cm apart facing +z (left at +x), a root between them, a marker ``forward_offset`` m ahead of its own
    behind part (toes seen from toes, as a profile may give them)."""
    from toolkit.body import Body, Facing

    body = Body(("root", "left_hip", "right_hip", "toes", "toe_tip"), "root",
                Facing("left_hip", "right_hip", forward="toe_tip", behind="toes"))
    local = np.array([[0.0, 0.9, 0.0], [0.065, 0.9, 0.0], [-0.065, 0.9, 0.0], [0.1, 0.0, 0.05],
                      [0.1, 0.0, 0.05 + forward_offset]])
    return body, local


@pytest.mark.parametrize("offset", [0.0, 0.02])
def test_a_tracker_jitter_does_not_flip_the_facing_a_marker_on_the_line_gives(offset):
    """1 cm of jitter at every joint: a marker at its behind part (0) or 2 cm ahead of it lies on either side of the
    line from frame to frame; the hips' left and right give the facing. It turns half round in a rare frame (the
    marker 2.3 jitters behind), which the running median over a second leaves out (before: every other frame)."""
    body, local = _marker_body(offset)
    rng = np.random.default_rng(3)
    heading = 0.7
    world = local_to_world(local, np.array([1.0, 0.0, 2.0]), heading)[None] + rng.normal(0, 0.01, (2000, 5, 3))
    found = facing_heading(world, np.ones((2000, 5), bool), body)
    error = np.abs(np.angle(np.exp(1j * (found - heading))))
    assert np.mean(error > np.pi / 2) < 0.02 and np.median(error) < 0.1
    smoothed = smooth_heading(found, 30)
    assert np.abs(np.angle(np.exp(1j * (smoothed - heading)))).max() < 0.1


@pytest.mark.parametrize("offset, turned", [(-0.03, False), (-0.05, True), (-0.2, True)])
def test_a_marker_well_behind_the_line_turns_the_facing_round(offset, turned):
    """B&B §5.1's nose is "always somewhat in front of the body": a marker behind the hips' line by more than a
    quarter of their distance (3.25 cm here) says the recording's left and right are the other way round."""
    body, local = _marker_body(0.0)
    local[4, 2] = offset  # the marker itself, seen from the root (no behind part seen)
    visible = np.ones(5, bool)
    visible[3] = False
    found = facing_heading(local_to_world(local, np.zeros(3), 0.0), visible, body)
    assert abs(np.angle(np.exp(1j * (found - (np.pi if turned else 0.0))))) < 1e-9


@pytest.mark.parametrize("window", ["recording", "stream"])
def test_the_markers_side_is_the_windows_vote_not_each_frames(window):
    """2 cm of jitter on each joint at 30 frames/s, hips 13 cm apart, a marker at its behind part (toes seen from
    toes): the marker lies more than the margin behind the line in about one frame in eight, which each frame on its
    own takes for a recording's left and right the other way round. Put to the vote of the facing's window (a second), the
    marker never turns it, and the facing stays within the hips' jitter of the truth, as a marker-less profile's."""
    from plugins.lib.root_frame import RecordingFacing, marker_behind, root_relative

    body, local = _marker_body(0.0)
    rng = np.random.default_rng(5)
    heading, n = 0.7, 600
    world = local_to_world(local, np.array([1.0, 0.0, 2.0]), heading)[None] + rng.normal(0, 0.02, (n, 5, 3))
    seen = np.ones((n, 5), bool)
    flags = marker_behind(world, seen, body)
    assert 0.03 < np.nanmean(flags) < 0.2  # each frame's own marker: turned round in these frames
    own = np.abs(np.angle(np.exp(1j * (facing_heading(world, seen, body) - heading))))
    assert np.mean(own > np.pi / 2) == np.nanmean(flags)
    from toolkit.body import Body, Facing

    plain = Body(body.parts, "root", Facing("left_hip", "right_hip"))  # the same hips, no marker
    windows = [RecordingFacing(30) if window == "recording" else HeadingFilter(30) for _ in range(2)]
    found = root_relative(world, seen, body, windows[0])[3]
    assert np.array_equal(found, root_relative(world, seen, plain, windows[1])[3])
    error = np.abs(np.angle(np.exp(1j * (found - heading))))
    assert error.max() < 0.35 and np.median(error) < 0.1


@pytest.mark.parametrize("window", ["recording", "stream"])
def test_a_mirrored_recording_stays_turned_round_where_its_marker_is_hidden(window):
    """A marker 20 cm behind the line in every frame it is seen (a recording's left and right swapped): the window's
    vote turns the facing round in every frame of a recording, and of a stream once half a window has voted (the
    median then follows within another half), also in the frames the marker is hidden (each frame on its own would
    go by the swapped hips there)."""
    from plugins.lib.root_frame import RecordingFacing, root_relative

    body, local = _marker_body(0.0)
    local[4, 2] = -0.2
    n = 90
    world = np.repeat(local_to_world(local, np.zeros(3), 0.0)[None], n, axis=0)
    seen = np.ones((n, 5), bool)
    seen[40:50, 4] = False
    smoothing = RecordingFacing(30) if window == "recording" else HeadingFilter(30)
    found = root_relative(world, seen, body, smoothing)[3]
    assert np.allclose(np.abs(found[0 if window == "recording" else 30 :]), np.pi)
    assert np.allclose(facing_heading(world, seen, body)[40:50], 0.0)  # each frame on its own: not turned


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


@settings(max_examples=60, deadline=None)
@given(window=st.integers(1, 12), seed=st.integers(0, 2**16), cuts=st.lists(st.integers(0, 40), max_size=5))
def test_a_block_of_facing_estimates_filters_as_one_estimate_at_a_time(window, seed, cuts):
    """HeadingFilter.update_many (a block of frames) gives what update gives frame by frame, whatever the blocks:
    NaN estimates are skipped, angles near +-pi are unwrapped around the newest estimate."""
    rng = np.random.default_rng(seed)
    headings = np.angle(np.exp(1j * (np.pi + np.cumsum(rng.normal(0, 0.3, 40)))))
    headings[rng.random(40) < 0.25] = np.nan
    one = HeadingFilter(window)
    expected = np.array([one.update(h) for h in headings])
    block = HeadingFilter(window)
    edges = [0, *sorted(set(cuts)), 40]
    got = np.concatenate([block.update_many(headings[a:b]) for a, b in zip(edges, edges[1:])])
    np.testing.assert_allclose(got, expected, atol=1e-12, equal_nan=True)
    finite = headings[np.isfinite(headings)]
    if len(finite):  # the first estimate comes through unchanged; before it there is no facing
        first = int(np.flatnonzero(np.isfinite(headings))[0])
        assert np.isnan(expected[:first]).all() and expected[first] == pytest.approx(finite[0])


@settings(max_examples=50, deadline=None)
@given(facing=st.floats(-3.14, 3.14), start=st.integers(0, 27), flipped=st.integers(1, 3),
       noise=st.floats(0.0, 0.05), seed=st.integers(0, 1000))
def test_a_run_of_estimates_flipped_by_half_a_turn_does_not_turn_the_clip(facing, start, flipped, noise, seed):
    """A stride puts the toe tip behind its toes for a few frames, flipping the estimate by π: the centred median
    over a window holds the facing wherever it lies (across ±π too), before, during and after the flipped run (at
    the clip's ends the window is cut to 8 estimates, so runs of up to 3 are outvoted everywhere)."""
    rng = np.random.default_rng(seed)
    estimates = facing + rng.uniform(-noise, noise, 30)
    estimates[start:start + flipped] += np.pi
    estimates = np.angle(np.exp(1j * estimates))
    smoothed = smooth_heading(estimates, 15)
    assert np.abs(np.angle(np.exp(1j * (smoothed - facing)))).max() <= noise + 1e-9


def test_smoothing_leaves_frames_without_an_estimate_in_their_window_unknown():
    estimates = np.r_[np.full(10, np.nan), 0.5, 0.6, np.full(10, np.nan)]
    smoothed = smooth_heading(estimates, 5)
    assert np.isnan(smoothed[:8]).all() and np.isnan(smoothed[14:]).all()
    assert np.allclose(smoothed[8:14], [0.5, 0.55, 0.55, 0.55, 0.55, 0.6])


def test_a_flipped_newest_estimate_does_not_split_the_stream_at_half_a_turn():
    """Streaming, the newest estimate flipped by π must not be the reference the others are unwrapped around: they
    would fall either side of ±π with their noise and the median would land on the flip."""
    rng = np.random.default_rng(3)
    filt = HeadingFilter(11)
    filt.update_many(rng.uniform(-0.02, 0.02, 10))
    assert abs(filt.update(np.pi - 0.01)) < 0.05
