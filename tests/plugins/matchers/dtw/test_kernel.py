"""The dtw matcher's fast paths (issue 22) give dtaidistance's numbers and the Match of the plain computation.

- :func:`plugins.matchers.dtw.warp_all` compiled by numba (every template in one call) is dtaidistance's
  ``distance_ndim`` bit for bit, and so is its plain-Python reference.
- ``DTW.match`` with the compiled warp, with dtaidistance one template at a time (early abandoning), and the plain
  computation before both (:func:`frame_distance` of the whole series to every whole template) give the same
  movement, confidence, details and ranked candidates; the coordinates that are 0 everywhere (the root's) left out
  change nothing.
"""

from __future__ import annotations

import numpy as np
import pytest
from dtaidistance import dtw_cc
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.matchers import dtw as dtw_module
from plugins.matchers.dtw import frame_distance, warp_all
from tests.plugins.matchers.dtw.test_abandoning import _dtw_matcher as _matcher
from toolkit import Motion

kernel = dtw_module._kernel()
needs_numba = pytest.mark.skipif(kernel is None, reason="numba is not installed")


def _side_by_side(templates):
    starts = np.cumsum([0] + [len(t) for t in templates]).astype(np.int64)
    return np.ascontiguousarray(np.concatenate(templates).T), starts


def _random_set(rng, count, dims, longest, scale, zeros):
    series = rng.normal(size=(int(rng.integers(1, longest + 1)), dims)) * scale
    templates = [rng.normal(size=(int(rng.integers(1, longest + 1)), dims)) * scale for _ in range(count)]
    if zeros:  # coordinates 0 everywhere, as the root's are
        series[:, :zeros] = 0.0
        for t in templates:
            t[:, :zeros] = 0.0
    return series, [np.ascontiguousarray(t) for t in templates]


@needs_numba
@settings(max_examples=120, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), count=st.integers(1, 6), dims=st.integers(1, 70),
       longest=st.integers(1, 60), scale=st.sampled_from([1e-3, 1.0, 1e3]), zeros=st.integers(0, 3))
def test_the_compiled_warp_is_dtaidistances_distance_bit_for_bit(seed, count, dims, longest, scale, zeros):
    rng = np.random.default_rng(seed)
    series, templates = _random_set(rng, count, dims, longest, scale, min(zeros, dims))
    columns, starts = _side_by_side(templates)
    got = kernel(series, columns, starts, np.empty(count))
    assert got.tolist() == [dtw_cc.distance_ndim(series, t) for t in templates]


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), count=st.integers(1, 3), dims=st.integers(1, 9))
def test_the_plain_python_reference_is_dtaidistances_distance_too(seed, count, dims):
    rng = np.random.default_rng(seed)
    series, templates = _random_set(rng, count, dims, 8, 1.0, 0)
    columns, starts = _side_by_side(templates)
    got = warp_all(series, columns, starts, np.empty(count))
    assert got.tolist() == [dtw_cc.distance_ndim(series, t) for t in templates]


def _plain(matcher, motion):
    """The computation before the fast paths: every whole series warped by dtaidistance, the Match built from it."""
    series = matcher._series(motion.filled().positions)
    distances = np.array([frame_distance(series, t, matcher.params["window"]) for t in matcher.templates])
    best = int(np.argmin(distances))
    labels = matcher.labels
    others = [d for d, lab in zip(distances, labels) if lab != labels[best]]
    runner_up = min(others) if others else np.inf
    nearest: dict[str, float] = {}
    for d, lab in sorted(zip(distances.tolist(), labels)):
        nearest.setdefault(lab, float(d))
    confidence = float(1.0 - distances[best] / runner_up) if np.isfinite(runner_up) and runner_up > 0 else 1.0
    return (labels[best], max(0.0, confidence), {"distance": float(distances[best]), "runner_up": float(runner_up)},
            tuple(nearest.items()))


def _answer(match):
    return match.movement, match.confidence, match.details, match.candidates


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), count=st.integers(1, 10), movements=st.integers(1, 4),
       parts=st.integers(2, 6), stride=st.integers(1, 3), near=st.booleans(), hidden=st.booleans(),
       window=st.sampled_from([0.0, 0.0, 0.3]), rooted=st.booleans())
def test_match_is_the_plain_computation_with_and_without_the_compiled_warp(
        seed, count, movements, parts, stride, near, hidden, window, rooted):
    rng = np.random.default_rng(seed)
    labels = [f"m{i}" for i in rng.integers(0, movements, count)]
    templates = [rng.normal(size=(int(rng.integers(1, 30)), parts, 3)) for _ in labels]
    if near:  # examples close to each other and to the segment: ties and little to abandon
        templates = [t * 0.01 + 1.0 for t in templates]
    positions = templates[0][: max(1, len(templates[0]) - 2)] + rng.normal(size=(1, parts, 3)) * 0.05
    if rooted:  # root-relative, as the watching loop hands them: the root's coordinates are 0 everywhere
        templates = [t - t[:, :1] for t in templates]
        positions = positions - positions[:, :1]
    visible = np.ones(positions.shape[:2], dtype=bool)
    if hidden:
        visible &= rng.random(visible.shape) > 0.3
        visible[0, 0] = True
    motion = Motion(positions, 30.0, tuple(f"p{i}" for i in range(parts)), visible)
    matcher = _matcher(labels, [t[::stride].reshape(len(t[::stride]), -1) for t in templates], stride=stride,
                       window=window)
    expected = _plain(matcher, motion)
    assert _answer(matcher.match(motion)) == expected
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(dtw_module, "_kernel", lambda: None)  # dtaidistance, one template at a time
        assert _answer(_matcher(labels, matcher.templates, stride=stride, window=window).match(motion)) == expected


def test_the_root_coordinates_are_left_out_only_when_the_segment_has_them_at_zero_too():
    rng = np.random.default_rng(5)
    templates = [rng.normal(size=(12, 9)) for _ in range(3)]
    for t in templates:
        t[:, :3] = 0.0
    matcher = _matcher(["a", "b", "c"], templates, stride=1)
    prepared = matcher._prepared()
    assert prepared.dropped.tolist() == [0, 1, 2] and prepared.kept.tolist() == list(range(3, 9))
    positions = rng.normal(size=(7, 3, 3))  # the first part is not at 0: nothing may be left out
    motion = Motion(positions, 30.0, ("r", "a", "b"))
    assert _answer(matcher.match(motion)) == _plain(matcher, motion)
