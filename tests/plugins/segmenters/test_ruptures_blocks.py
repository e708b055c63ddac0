"""The ruptures segmenter takes a block of poses at once (issue 22): the same segments, reported at the same frames,
as pushing them one by one, whatever the cuts between blocks and however often the window fills."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.segmenters.ruptures_segmenter import RupturesSegmenter

PARTS = ("root", "a", "b", "c")


def _stream(rng, pieces, hidden):
    """Stretches of different still poses with noise (change points between them), root at 0."""
    blocks = []
    for _ in range(pieces):
        pose = rng.normal(size=(1, len(PARTS), 3))
        blocks.append(pose + rng.normal(size=(int(rng.integers(10, 60)), len(PARTS), 3)) * 0.02)
    poses = np.concatenate(blocks)
    poses[:, 0] = 0.0
    visible = np.ones(poses.shape[:2], dtype=bool)
    if hidden:
        visible &= rng.random(visible.shape) > 0.2
        poses[~visible] = np.nan  # what a hidden part may hold
    return poses, visible


def _one_by_one(segmenter, poses, visible):
    segmenter.reset(PARTS, 30.0)
    out, holds = [], []
    for f in range(len(poses)):
        out.extend((f, s) for s in segmenter.push(poses[f], visible[f]))
        holds.append(segmenter.holds_since)
    return out, holds, segmenter.flush()


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 6), window=st.sampled_from([0.0, 1.0, 2.5, 60.0]),
       cuts=st.lists(st.integers(1, 400), max_size=6), hidden=st.booleans(), stride=st.integers(1, 2))
def test_a_block_pushed_at_once_is_its_frames_pushed_one_by_one(seed, pieces, window, cuts, hidden, stride):
    rng = np.random.default_rng(seed)
    poses, visible = _stream(rng, pieces, hidden)
    params = {"window": window, "stride": stride, "min_length": 0.2}
    expected, holds, flushed = _one_by_one(RupturesSegmenter(**params), poses, visible)
    segmenter = RupturesSegmenter(**params)
    segmenter.reset(PARTS, 30.0)
    got = []
    edges = [0, *sorted(c for c in cuts if c < len(poses)), len(poses)]
    for a, b in zip(edges, edges[1:]):
        closed, since = segmenter.push_block(poses[a:b], visible[a:b])
        got.extend((a + i, s) for i, s in closed)
        assert (since == -1).all()
        assert segmenter.holds_since == (holds[b - 1] if b > a else segmenter.holds_since)
    assert got == expected
    assert segmenter.flush() == flushed
    assert segmenter.holds_since is None


def test_the_poses_pushed_are_copied():
    rng = np.random.default_rng(1)
    poses, visible = _stream(rng, 3, False)
    segmenter = RupturesSegmenter(window=0.0)
    segmenter.reset(PARTS, 30.0)
    block = poses.copy()
    segmenter.push_block(block, visible)
    block[:] = 0.0  # the watching loop reuses its working memory
    reference = RupturesSegmenter(window=0.0)
    reference.reset(PARTS, 30.0)
    reference.push_block(poses, visible)
    assert segmenter.flush() == reference.flush()
