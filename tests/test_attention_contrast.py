"""Attention to what tells one's own movements apart (issue 18, distinct18): :func:`part_distances` and
:func:`contrast_weights` of :mod:`plugins.lib.attention`, the rule ``path-search``'s ``contrast`` and ``rivals``
weigh the parts by."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.lib.attention import contrast_weights, part_distances
from plugins.lib.pose_distance import path_distance

DISTANCES = arrays(float, st.integers(1, 8), elements=st.floats(0.0, 5.0))


@settings(max_examples=50, deadline=None)
@given(DISTANCES, st.floats(0.0, 1.0))
def test_contrast_weights_sum_to_one_and_no_part_falls_below_the_floor(distances, share):
    w = contrast_weights(distances, share)
    p = len(distances)
    assert w.sum() == pytest.approx(1.0)
    assert (w >= (1.0 - share) / p - 1e-12).all()
    if distances.sum() > 0:  # a part that lies alike in every movement (distance 0) gets exactly the floor
        assert w[distances == 0] == pytest.approx(np.full((distances == 0).sum(), (1.0 - share) / p))
        order = np.argsort(distances, kind="stable")  # and the weights grow with the distance
        assert (np.diff(w[order]) >= -1e-12).all()


@settings(max_examples=30, deadline=None)
@given(DISTANCES, st.floats(0.01, 100.0))
def test_contrast_weights_need_no_unit(distances, scale):
    """The same body in centimetres instead of metres, or a mouse instead of a man: the same weights."""
    assert contrast_weights(distances * scale, 0.5) == pytest.approx(contrast_weights(distances, 0.5))


def test_with_nothing_to_tell_apart_or_no_share_every_part_counts_alike():
    assert contrast_weights(np.zeros(4), 0.5) == pytest.approx(np.full(4, 0.25))
    assert contrast_weights(np.array([0.0, 3.0, 1.0]), 0.0) == pytest.approx(np.full(3, 1 / 3))
    assert contrast_weights(np.array([0.0, 3.0, 1.0]), 1.0) == pytest.approx([0.0, 0.75, 0.25])
    rows = contrast_weights(np.array([[0.0, 1.0], [2.0, 2.0]]), 0.5)  # each row on its own
    assert rows == pytest.approx(np.array([[0.25, 0.75], [0.5, 0.5]]))


@settings(max_examples=30, deadline=None)
@given(arrays(float, (5, 3, 3), elements=st.floats(-1, 1)), arrays(float, (5, 3, 3), elements=st.floats(-1, 1)))
def test_the_parts_distances_average_to_eq_3_per_sample(a, b):
    """Every part seen: the mean of the parts' distances over the parts is eq. 3 over the samples per sample."""
    d = part_distances(a, b, np.ones((5, 3), dtype=bool))
    assert d.mean() == pytest.approx(path_distance(a, b, np.ones((5, 3), dtype=bool)) / 5, abs=1e-12)


def test_a_parts_distance_is_its_mean_over_the_samples_it_is_seen_in():
    a, b = np.zeros((4, 2, 3)), np.zeros((4, 2, 3))
    b[:, 0, 0] = [1.0, 2.0, 3.0, 4.0]
    b[:, 1, 1] = 5.0
    seen = np.ones((4, 2), dtype=bool)
    seen[3, 0] = False
    seen[:, 1] = False
    assert part_distances(a, b, seen) == pytest.approx([2.0, 0.0])
