"""The ruptures segmenter's RBF bandwidth from a bounded, evenly spaced sample: ruptures' own value on short streams,
the same change points on the project's generated streams, and no n x n matrix on long ones."""

from __future__ import annotations

import numpy as np
import pytest
from ruptures.costs import CostRbf

import plugins.segmenters.ruptures_segmenter as module
from plugins.segmenters.ruptures_segmenter import RupturesSegmenter, rbf_gamma
from toolkit import Motion
from toolkit.bvh import read_bvh


def _piecewise(n_pieces: int, frames: int, parts: int = 3, seed: int = 0) -> Motion:
    """A motion whose parts jump to a new place (and jitter around it) every ``frames`` frames."""
    rng = np.random.default_rng(seed)
    centres = rng.normal(0, 0.4, (n_pieces, parts, 3))
    positions = np.repeat(centres, frames, axis=0) + rng.normal(0, 0.03, (n_pieces * frames, parts, 3))
    return Motion(positions, 30.0, [f"p{i}" for i in range(parts)])


def _segments(motion: Motion, **params) -> list[tuple[int, int]]:
    return [(s.start, s.end) for s in RupturesSegmenter(**params).segment(motion)]


@pytest.mark.parametrize("n, d", [(2, 1), (50, 3), (700, 9), (2000, 33)])
def test_up_to_the_sample_size_the_bandwidth_is_ruptures_own(n, d):
    x = np.random.default_rng(n).normal(size=(n, d)) * np.arange(1, d + 1)
    assert rbf_gamma(x) == CostRbf().fit(x).gamma


def test_a_constant_stream_gets_ruptures_fallback_bandwidth():
    x = np.ones((30, 4))
    assert rbf_gamma(x) == CostRbf().fit(x).gamma == 1.0


def test_a_long_stream_uses_evenly_spaced_frames_only():
    x = np.random.default_rng(3).normal(size=(9001, 4))
    assert rbf_gamma(x, sample=1001) == CostRbf().fit(x[::9]).gamma


def _without_subsample(monkeypatch):
    """The segmenter as it was: ruptures computes the bandwidth from all pairs (``gamma=None``)."""
    monkeypatch.setattr(module, "rbf_gamma", lambda x: None)


@pytest.mark.parametrize("pieces, frames, stride", [(4, 90, 2), (6, 400, 2), (5, 1400, 3)])
def test_the_same_change_points_as_the_bandwidth_from_all_pairs(monkeypatch, pieces, frames, stride):
    motion = _piecewise(pieces, frames, seed=pieces)
    new = _segments(motion, stride=stride)
    _without_subsample(monkeypatch)
    old = _segments(motion, stride=stride)
    assert new == old
    assert len(new) == pieces


def test_the_same_segments_on_generated_streams(monkeypatch, tmp_path):
    from toolkit.cli import main

    main(["bench", "make-data", str(tmp_path / "gen")])
    files = sorted((tmp_path / "gen" / "streams").glob("*.bvh"))
    assert files
    motions = []
    for f in files:
        bvh = read_bvh(f)
        names = bvh.names
        motions.append(Motion(bvh.positions() / 100.0, bvh.fps, names))
    new = [_segments(m) for m in motions]
    _without_subsample(monkeypatch)
    assert new == [_segments(m) for m in motions]
