"""A tracker's jitter filtered out of a motion known whole (plugins.lib.lowpass)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.lowpass import MOVEMENT_BAND, low_passed
from toolkit import Motion


def _motion(n=300, fps=30.0, jitter=0.0, seed=0):
    t = np.arange(n)[:, None] / fps
    positions = np.zeros((n, 3, 3))
    positions[:, 0] = np.array([0.0, 1.0, 0.0]) + t * [0.0, 0.0, 1.2]  # the root walking on at 1.2 m/s
    positions[:, 1, 0] = 0.2 * np.sin(2 * np.pi * 3.0 * t[:, 0])  # a hand waving at 3 Hz
    positions[:, 2] = 0.5  # a part held still
    positions += np.random.default_rng(seed).normal(0.0, jitter, positions.shape)
    return Motion(positions, fps, ["root", "hand", "still"])


def test_movement_in_the_band_passes_and_jitter_is_filtered():
    clean = _motion()
    out = low_passed(clean)
    middle = slice(30, -30)
    np.testing.assert_allclose(out.positions[:, 0], clean.positions[:, 0], atol=1e-6)  # a straight line passes
    wave = out.positions[middle, 1, 0].std() / clean.positions[middle, 1, 0].std()
    assert 0.995 < wave <= 1.0  # a 3 Hz wave within half a percent
    noisy = low_passed(_motion(jitter=0.02, seed=1))
    left = (noisy.positions[:, 2] - 0.5).std() / 0.02
    assert 0.45 < left < 0.7  # about the share of the band below the cut-off: sqrt(6 / 15) = 0.63


def test_hidden_frames_stay_hidden_and_kept_parts_are_untouched():
    noisy = _motion(jitter=0.02)
    positions = noisy.positions.copy()
    positions[100:140, 1] = np.nan  # the hand lost for 40 frames
    positions[:, 2] = np.nan  # a part never seen
    out = low_passed(Motion(positions, noisy.fps, noisy.parts), keep=np.array([True, False, False]))
    assert not out.visible[100:140, 1].any() and np.isnan(out.positions[100:140, 1]).all()
    assert out.visible[:100, 1].all() and out.visible[140:, 1].all()
    assert not out.visible[:, 2].any()
    assert np.array_equal(out.positions[:, 0], noisy.positions[:, 0])  # kept as it is


def test_what_has_no_band_to_filter_comes_back_as_it_is():
    slow = _motion(fps=2 * MOVEMENT_BAND, jitter=0.01)  # nothing above the cut-off
    short = _motion(n=20, jitter=0.01)
    assert low_passed(slow) is slow and low_passed(short) is short


@settings(max_examples=30, deadline=None)
@given(n=st.integers(25, 200), fps=st.sampled_from([24.0, 30.0, 60.0, 120.0]), seed=st.integers(0, 2**16),
       hidden=st.floats(0.0, 0.5))
def test_the_filter_never_makes_a_frame_seen_nor_moves_a_part_beyond_its_reach(n, fps, seed, hidden):
    rng = np.random.default_rng(seed)
    positions = rng.uniform(-1.0, 1.0, (n, 4, 3))
    positions[rng.random((n, 4)) < hidden] = np.nan
    motion = Motion(positions, fps, ["a", "b", "c", "d"])
    out = low_passed(motion)
    assert np.array_equal(out.visible, motion.visible)
    assert np.isfinite(out.positions[out.visible]).all()
    assert np.abs(out.positions[out.visible]).max() <= 2.0  # a Butterworth's overshoot stays within its ringing


PROFILE = """
[profile]
name = "person"
units = "metre"
up = "+y"

[parts]
{parts}

[facing]
root = "hips"
left = "l_hip"
right = "r_hip"
"""


def test_a_repertoire_keeps_the_filtered_world_beside_each_clip_and_rebuilds_from_the_motions_as_given(tmp_path):
    """A clip's world positions are those its pose was found from (bridged, low-passed), so its travel and turning
    carry no more of a tracker's jitter than its pose; a repertoire built again with other hub settings starts from
    the motions as they were given, not from the filtered ones (filtered twice, a clip would change)."""
    from plugins.lib.clip_repertoire import clip_repertoire
    from tests.fixtures.skeletons import NAMES, human
    from toolkit.recordings.profile import load_profile

    (tmp_path / "person.toml").write_text(PROFILE.format(parts="\n".join(f'{n} = "{n}"' for n in NAMES)))
    profile = load_profile(tmp_path / "person.toml")
    rng = np.random.default_rng(1)
    given = [Motion(human(m, 90) + rng.normal(0.0, 0.01, (90, len(NAMES), 3)), 30.0, NAMES) for m in ("bow", "wave")]
    repertoire = clip_repertoire(given, ["bow", "wave"], profile)
    for clip, motion in zip(repertoire.clips, given):
        np.testing.assert_array_equal(clip.motion.world, low_passed(motion).positions)
    assert all(a is b for a, b in zip(repertoire.worlds, given))
    there_and_back = repertoire.with_hubs(0.2, 0.5).with_hubs(repertoire.hub_radius, 0.3)
    assert there_and_back.hub_share == 0.3
    for a, b in zip(repertoire.clips, there_and_back.clips):
        np.testing.assert_array_equal(a.motion.positions, b.motion.positions)
        np.testing.assert_array_equal(a.motion.world, b.motion.world)
