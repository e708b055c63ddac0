"""The stroke analysis's vectorised steps (issue 22) give exactly what the per-vector formulas give (hypothesis).

:func:`plugins.lib.strokes.analyse` cuts every movement the ``velocity-direction`` segmenter closes and everything the
motor command graph learns; its unit vectors and the direction clustering's cluster means are computed at once. A
different last bit could move a cluster boundary, so they are held to the formulas they replace, bit for bit.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.lib.strokes import _cluster_means, _unit, _units, direction_clusters

values = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)


@st.composite
def movement_vectors(draw):
    n = draw(st.integers(1, 80))
    d = 3 * draw(st.integers(1, 8))
    vectors = draw(arrays(np.float64, (n, d), elements=values))
    zero = draw(st.lists(st.integers(0, n - 1), max_size=3))  # still frames: no direction
    vectors[zero] = 0.0
    return vectors


@given(movement_vectors())
@settings(max_examples=200, deadline=None)
def test_unit_vectors_at_once_are_each_vectors_unit(vectors):
    np.testing.assert_array_equal(_units(vectors), np.array([_unit(v) for v in vectors]))


@given(movement_vectors(), st.integers(1, 12), st.data())
@settings(max_examples=200, deadline=None)
def test_cluster_means_at_once_are_each_clusters_mean(vectors, k, data):
    labels = np.array(data.draw(st.lists(st.integers(0, k - 1), min_size=len(vectors), max_size=len(vectors))))
    means = [data.draw(arrays(np.float64, vectors.shape[1], elements=values)) for _ in range(k)]
    expected = [_unit(vectors[labels == c].mean(axis=0)) if np.any(labels == c) else means[c] for c in range(k)]
    got = _cluster_means(vectors, labels, means)
    assert len(got) == k
    for a, b in zip(got, expected):
        np.testing.assert_array_equal(a, b)


def test_directions_that_turn_fall_into_clusters():
    """The clustering still does its job: a movement right, then up (each 45 degrees from their mean), is two
    clusters at 30 degrees, split where it turns."""
    right = np.tile([1.0, 0.0, 0.0], (10, 1))
    up = np.tile([0.0, 1.0, 0.0], (10, 1))
    labels = direction_clusters(np.concatenate([right, up]), 30.0)
    assert len(set(labels[:10])) == 1 and len(set(labels[10:])) == 1 and labels[0] != labels[-1]
