"""The stroke analysis's vectorised steps (issue 22, "fast at every size") give exactly what their formulas written
out step by step give (hypothesis): the direction clustering, the speed minima and the stroke analysis that uses them.

:func:`plugins.lib.strokes.analyse` cuts every movement the ``velocity-direction`` segmenter closes and everything the
motor command graph learns. A different last bit in a cluster mean could move a cluster boundary, so each vectorised
function is held bit for bit to the straightforward version it replaced, kept here as the reference.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.lib.strokes import _centres, _cluster_means, _unit, direction_clusters

values = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)


def reference_direction_clusters(vectors: np.ndarray, angle: float, max_clusters: int = 12) -> np.ndarray:
    """The divisive clustering as it was written before it was vectorised: means a list, one mask per cluster."""
    n = len(vectors)
    if n == 0:
        return np.zeros(0, dtype=int)
    cos_limit = np.cos(np.radians(angle))
    means = [_unit(vectors.mean(axis=0))]
    for _ in range(4 * max_clusters):
        sims = vectors @ np.array(means).T
        labels = np.argmax(sims, axis=1)
        best = sims[np.arange(n), labels]
        worst = int(np.argmin(best))
        if best[worst] >= cos_limit or len(means) >= max_clusters:
            break
        means.append(vectors[worst].copy())
        for _ in range(10):
            labels = np.argmax(vectors @ np.array(means).T, axis=1)
            new = [_unit(vectors[labels == k].mean(axis=0)) if np.any(labels == k) else means[k]
                   for k in range(len(means))]
            if np.allclose(np.array(new), np.array(means)):
                break
            means = new
    return np.argmax(vectors @ np.array(means).T, axis=1)


@st.composite
def unit_vectors(draw, most=120):
    """Unit movement vectors (N, 3k) as the analysis gives them: a few directions with noise, some zero rows."""
    n = draw(st.integers(1, most))
    d = 3 * draw(st.integers(1, 8))
    k = draw(st.integers(1, 6))
    centres = draw(arrays(np.float64, (k, d), elements=values))
    which = np.array(draw(st.lists(st.integers(0, k - 1), min_size=n, max_size=n)))
    noise = draw(arrays(np.float64, (n, d), elements=st.floats(-1.0, 1.0)))
    scale = draw(st.sampled_from([0.0, 0.05, 0.3, 1.0, 5.0]))
    vectors = centres[which] + scale * noise
    zero = draw(st.lists(st.integers(0, n - 1), max_size=3))
    vectors[zero] = 0.0
    norms = np.sqrt(np.array([v.dot(v) for v in vectors]))
    long = norms > 1e-12
    return np.where(long[:, None], vectors / np.where(long, norms, 1.0)[:, None], vectors)


@given(unit_vectors(), st.floats(1.0, 180.0), st.integers(1, 12))
@settings(max_examples=300, deadline=None)
def test_direction_clusters_are_the_reference_clustering(vectors, angle, max_clusters):
    np.testing.assert_array_equal(direction_clusters(vectors, angle, max_clusters),
                                  reference_direction_clusters(vectors, angle, max_clusters))


@given(arrays(np.float64, st.tuples(st.integers(1, 40), st.integers(1, 24)), elements=values), st.integers(1, 12),
       st.data())
@settings(max_examples=300, deadline=None)
def test_centres_are_each_clusters_mean(vectors, k, data):
    """:func:`_centres` (one array) gives what :func:`_cluster_means` (a list) and the masked mean give, zero
    signs included, with empty clusters keeping their old mean."""
    labels = np.array(data.draw(st.lists(st.integers(0, k - 1), min_size=len(vectors), max_size=len(vectors))))
    vectors = np.where(np.array(data.draw(arrays(bool, vectors.shape))), -0.0, vectors)  # signed zeros too
    means = data.draw(arrays(np.float64, (k, vectors.shape[1]), elements=values))
    expected = np.array([_unit(vectors[labels == c].mean(axis=0)) if np.any(labels == c) else means[c]
                         for c in range(k)])
    got = _centres(vectors, labels, means)
    np.testing.assert_array_equal(got, expected)
    np.testing.assert_array_equal(np.signbit(got), np.signbit(expected))
    np.testing.assert_array_equal(got, np.array(_cluster_means(vectors, labels, list(means))))


def test_a_long_cluster_is_summed_in_order():
    """More rows than numpy's pairwise summation block (8), in one cluster and several: still the masked mean."""
    rng = np.random.default_rng(22)
    vectors = rng.normal(size=(300, 69)) * 10.0 ** rng.uniform(-3, 3, size=(300, 1))
    labels = rng.integers(0, 3, size=300)
    means = np.zeros((4, 69))
    expected = [_unit(vectors[labels == c].mean(axis=0)) for c in range(3)] + [means[3]]
    np.testing.assert_array_equal(_centres(vectors, labels, means), np.array(expected))
