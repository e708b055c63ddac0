"""A tracker's short gaps bridged in a motion known whole (plugins.lib.gaps)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.gaps import BRIDGE, bridged
from toolkit import Motion


def _line(n=40, parts=2, fps=30.0):
    t = np.arange(n)[:, None, None] / fps
    positions = np.concatenate([t * [[1.0, 0.5, -2.0]], np.sin(t * [[1.0, 2.0, 3.0]])], axis=1)[:, :parts]
    return Motion(positions, fps, [f"p{i}" for i in range(parts)])


def _hide(motion, part, rows):
    positions = motion.positions.copy()
    positions[rows, part] = np.nan
    return Motion(positions, motion.fps, motion.parts)


def test_a_short_gap_is_the_straight_line_between_its_sightings_and_seen():
    clean = _line()
    gap = bridged(_hide(clean, 0, slice(10, 20)))  # 10 frames: a third of a second
    assert gap.visible.all()
    np.testing.assert_allclose(gap.positions[:, 0], clean.positions[:, 0])  # part 0 moves in a straight line
    np.testing.assert_array_equal(gap.positions[:, 1], clean.positions[:, 1])


def test_a_gap_at_an_end_or_longer_than_the_bridge_stays_hidden():
    clean = _line(n=60)
    long = int(BRIDGE * 30) + 1
    hidden = _hide(_hide(clean, 0, slice(0, 5)), 1, slice(20, 20 + long))
    out = bridged(hidden)
    assert not out.visible[:5, 0].any() and not out.visible[20 : 20 + long, 1].any()
    assert out.visible[5:, 0].all()


def test_nothing_hidden_is_the_motion_itself():
    clean = _line()
    assert bridged(clean) is clean


@settings(max_examples=40, deadline=None)
@given(start=st.integers(1, 30), length=st.integers(1, 15), part=st.integers(0, 1))
def test_a_bridged_gap_lies_between_its_two_sightings(start, length, part):
    clean = _line()
    out = bridged(_hide(clean, part, slice(start, start + length)))
    end = start + length
    if end >= len(clean.positions):
        assert not out.visible[start:, part].any()
        return
    a, b = clean.positions[start - 1, part], clean.positions[end, part]
    for k, row in enumerate(range(start, end), 1):
        t = k / (length + 1)
        np.testing.assert_allclose(out.positions[row, part], (1 - t) * a + t * b)


def test_a_motion_known_whole_is_bridged_before_its_body_frame_is_found(tmp_path):
    """A repertoire's clip and a demonstration learned as a take (plugins.lib.clip_repertoire.root_relative_motion):
    a hand lost for a sixth of a second moves on along its line in the body's frame, as if it had been seen."""
    from plugins.lib.clip_repertoire import root_relative_motion
    from tests.conftest import STICK_PARTS, write_stick_profile
    from toolkit.recordings.profile import load_profile

    body = load_profile(write_stick_profile(tmp_path)).body
    n = 40
    stand = {"root": [0, 1, 0], "head": [0, 1.6, 0.05], "lk": [0.1, 0.5, 0], "rk": [-0.1, 0.5, 0], "hand": [0.3, 1, 0.2],
             "lf": [0.1, 0, 0], "rf": [-0.1, 0, 0]}
    positions = np.repeat(np.array([stand[p] for p in STICK_PARTS], dtype=float)[None], n, axis=0)
    hand = STICK_PARTS.index("hand")
    positions[:, hand] += np.arange(n)[:, None] / 30 * [0.0, 0.6, 0.3]  # raised along a line
    clean = Motion(positions, 30.0, list(STICK_PARTS))
    lost = _hide(clean, hand, slice(10, 15))
    whole, bridged_ = root_relative_motion(clean, body), root_relative_motion(lost, body)
    assert bridged_.visible[:, hand].all()
    np.testing.assert_allclose(bridged_.positions[:, hand], whole.positions[:, hand], atol=1e-9)
